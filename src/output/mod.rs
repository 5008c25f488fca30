//! Run outputs in `--out DIR`: summary.json, probes.csv, energy.csv,
//! reactions.csv, particles.csv, VTK snapshots (.vtu + a .pvd series).
//! Every file is written to a temporary name and renamed into place, so a
//! crash never leaves a half-written file. See docs/outputs.md.

pub mod checkpoint;
pub mod csv;
pub mod folder;
pub mod summary;
pub mod vtk;

use crate::error::{Error, Result};
use std::path::Path;

/// Writes `bytes` to `path` through `path.tmp` and a rename. On failure
/// (a full disk, say) the `.tmp` file is removed and `path` is as it was.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = std::path::PathBuf::from(tmp);
    let written = std::fs::write(&tmp, bytes)
        .map_err(|e| Error::io("cannot write", &tmp, e))
        .and_then(|()| {
            std::fs::rename(&tmp, path).map_err(|e| Error::io("cannot rename into place", path, e))
        });
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written
}
