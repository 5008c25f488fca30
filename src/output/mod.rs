//! Run outputs in `--out DIR`: summary.json, probes.csv, energy.csv,
//! reactions.csv, particles.csv, VTK snapshots (.vtu + a .pvd series).
//! Every file is written to a temporary name and renamed into place, so a
//! crash never leaves a half-written file. See docs/outputs.md.

pub mod csv;
pub mod summary;
pub mod vtk;

use crate::error::{Error, Result};
use std::path::Path;

/// Writes `bytes` to `path` through `path.tmp` and a rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = std::path::PathBuf::from(tmp);
    std::fs::write(&tmp, bytes).map_err(|e| Error::io("cannot write", &tmp, e))?;
    std::fs::rename(&tmp, path).map_err(|e| Error::io("cannot rename into place", path, e))
}
