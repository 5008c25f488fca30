//! Run outputs in `--out DIR`: summary.json, probes.csv, energy.csv,
//! reactions.csv, particles.csv, VTK snapshots (.vtu + a .pvd series).
//! Every file is written to a temporary name and renamed into place, so a
//! crash never leaves a half-written file. See docs/outputs.md.

pub mod checkpoint;
pub mod csv;
pub mod folder;
pub mod render;
pub mod result;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_write_leaves_no_tmp_file_and_the_old_file_whole() {
        let dir = std::env::temp_dir().join(format!("lme-mpm-atomic-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("taken")).unwrap();
        // A folder where the file should go: the rename fails after the write.
        let e = write_atomic(&dir.join("taken"), b"data").unwrap_err();
        assert!(e.to_string().contains("rename"), "{e}");
        assert!(!dir.join("taken.tmp").exists());
        // A missing folder: the write itself fails.
        assert!(write_atomic(&dir.join("none").join("f.csv"), b"x").is_err());
        write_atomic(&dir.join("f.csv"), b"old").unwrap();
        assert_eq!(std::fs::read(dir.join("f.csv")).unwrap(), b"old");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
