//! Run outputs in `--out DIR`: summary.json, probes.csv, energy.csv,
//! reactions.csv, particles.csv, VTK snapshots (.vtu + a .pvd series).
//! Every file is written to a temporary name and renamed into place, so a
//! crash never leaves a half-written file. See docs/outputs.md.

pub mod checkpoint;
pub mod csv;
pub mod folder;
pub mod render;
pub mod result;
pub mod state;
pub mod summary;
pub mod vtk;

use crate::error::{Error, Result};
use std::path::Path;

/// Writes `bytes` to `path` through `path.tmp` and a rename. On failure
/// (a full disk, say) the `.tmp` file is removed and `path` is as it was.
/// The `.tmp` file is created new (O_EXCL, which never follows a link): a
/// leftover file or a link planted at its name is removed (the link
/// itself, never what it points to) and the creation retried once, so
/// nothing outside the folder is ever written.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let tmp = tmp_path(path);
    let written = create_new(&tmp)
        .and_then(|mut f| {
            use std::io::Write;
            f.write_all(bytes)
                .and_then(|()| f.flush())
                .map_err(|e| Error::io("cannot write", &tmp, e))
        })
        .and_then(|()| {
            std::fs::rename(&tmp, path).map_err(|e| Error::io("cannot rename into place", path, e))
        });
    if written.is_err() {
        remove_entry(&tmp);
    }
    written
}

/// `path` with `.tmp` appended: the name `write_atomic` writes through.
pub fn tmp_path(path: &Path) -> std::path::PathBuf {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    std::path::PathBuf::from(tmp)
}

/// Creates `path` for writing, failing rather than following a link or
/// reusing a file; whatever sits at the name (a stale `.tmp`, a planted
/// link) is unlinked first, once.
fn create_new(path: &Path) -> Result<std::fs::File> {
    let open = || {
        std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(path)
    };
    match open() {
        Ok(f) => Ok(f),
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
            remove_entry(path);
            open().map_err(|e| Error::io("cannot create", path, e))
        }
        Err(e) => Err(Error::io("cannot write", path, e)),
    }
}

/// Unlinks `path` if it is a file or a link (a link itself, not its
/// target); a folder there is left alone. Errors are ignored: the caller
/// fails on the next step if the name is still taken.
pub fn remove_entry(path: &Path) {
    if std::fs::symlink_metadata(path).is_ok_and(|m| !m.is_dir()) {
        let _ = std::fs::remove_file(path);
    }
}

/// `eprintln!` that never fails: a message or progress line must not cost
/// a run when stderr is a closed pipe or a full disk (`2>&1 | head -1`,
/// `2>/dev/full`), so write errors are ignored.
#[macro_export]
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
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

    #[cfg(unix)]
    #[test]
    fn a_link_planted_at_the_tmp_name_is_replaced_not_followed() {
        let dir = std::env::temp_dir().join(format!("lme-mpm-atomic-link-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let victim = dir.join("victim.txt");
        std::fs::write(&victim, "precious").unwrap();
        std::os::unix::fs::symlink(&victim, dir.join("f.csv.tmp")).unwrap();
        write_atomic(&dir.join("f.csv"), b"new").unwrap();
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
        assert_eq!(std::fs::read(dir.join("f.csv")).unwrap(), b"new");
        assert!(std::fs::symlink_metadata(dir.join("f.csv.tmp")).is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
