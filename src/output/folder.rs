//! One run per output folder. A run holds an OS file lock (flock) on
//! `lme-mpm.lock` (which also names its pid) so no second run writes into
//! the folder while it lives; the OS drops the lock when the process ends,
//! however it ends, so a stale file or a reused pid never blocks a folder.
//! A run lists every file it writes in `lme-mpm.manifest` before writing
//! it, and a new run first removes what the manifest lists (never anything
//! else), with any `.tmp` file a killed write left. A non-empty folder
//! that is not an lme-mpm output folder is refused.
//!
//! Last words: while a run holds a folder it keeps there the summary.json
//! a sudden end would need (`Folder::set_last_words`); `abandon_all`
//! writes those and drops the locks, for a second signal that ends the
//! process in the middle of a step. While a run saves (`Folder::saving`)
//! `abandon_all` refuses, so no signal cuts a save short.

use crate::error::{Error, Result};
use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The list of files the run in the folder wrote, one relative path a line.
pub const MANIFEST: &str = "lme-mpm.manifest";
/// Locked (flock) while a run writes into the folder; holds the pid of that run.
pub const LOCK: &str = "lme-mpm.lock";
/// A sweep's record of the run it planned for the folder (`sweep/`); a
/// run leaves it alone.
pub const SWEEP_ENTRY: &str = "sweep-run.json";

/// Files an lme-mpm run writes, for folders from versions without a
/// manifest (besides `vtk/particles_NNNNN.vtu`).
const KNOWN: &[&str] = &[
    "summary.json",
    "scene.resolved.toml",
    "probes.csv",
    "energy.csv",
    "reactions.csv",
    "particles.csv",
    "particles.pvd",
    super::checkpoint::FILE,
];

/// An output folder held by this run (the lock is released on drop).
#[derive(Debug)]
pub struct Folder {
    dir: PathBuf,
    files: BTreeSet<String>,
    lock: PathBuf,
    /// The open lock file: the flock lives as long as it does.
    _lock_file: std::fs::File,
    /// This folder's entry in `LIVE`.
    id: u64,
}

/// What a sudden end of the process writes into each folder in use.
struct Live {
    id: u64,
    dir: PathBuf,
    lock: PathBuf,
    /// summary.json's text for a sudden end (None: nothing to write yet).
    last_words: Option<String>,
    /// Saves in progress (the final outputs, a checkpoint).
    saving: u32,
}

static LIVE: std::sync::Mutex<Vec<Live>> = std::sync::Mutex::new(Vec::new());
static NEXT_ID: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

fn live() -> std::sync::MutexGuard<'static, Vec<Live>> {
    LIVE.lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// For a signal that must end the process now: refuses (false) while any
/// run saves; otherwise writes each folder's last words as its summary.json,
/// removes its lock file, and returns true (the caller then exits; the OS
/// drops the flocks). Later saves are refused (they would race the exit).
pub fn abandon_all() -> bool {
    let list = live();
    if list.iter().any(|l| l.saving > 0) {
        return false;
    }
    for l in list.iter() {
        if let Some(text) = &l.last_words {
            let _ = super::write_atomic(&l.dir.join("summary.json"), text.as_bytes());
        }
        let _ = std::fs::remove_file(&l.lock);
    }
    // The registry stays locked until the caller exits: a save that
    // would start now waits instead of racing the exit.
    std::mem::forget(list);
    true
}

/// A save in progress (see `Folder::saving`); ends on drop.
pub struct Saving {
    id: u64,
}

impl Drop for Saving {
    fn drop(&mut self) {
        if let Some(l) = live().iter_mut().find(|l| l.id == self.id) {
            l.saving = l.saving.saturating_sub(1);
        }
    }
}

impl Folder {
    /// Takes `dir` for a new run: creates it, takes the lock, and removes
    /// every file an earlier run wrote there. Refuses (exit 2) a folder held
    /// by a live run, and a non-empty folder that is not an output folder.
    pub fn create(dir: &Path) -> Result<Folder> {
        let mut f = Folder::lock(dir)?;
        let earlier = f.read_manifest()?;
        let legacy = earlier.is_none() && f.has_known_files();
        match earlier {
            Some(files) => f.files = files,
            None if legacy => f.files = f.known_files(),
            None => f.check_empty()?,
        }
        let old: Vec<String> = f.files.iter().cloned().collect();
        f.prune(|_| false, &old)?;
        f.files.clear();
        f.remove_leftovers();
        f.write_manifest()?;
        Ok(f)
    }

    /// Takes `dir` to resume the run there: takes the lock and keeps the
    /// files its manifest lists.
    pub fn resume(dir: &Path) -> Result<Folder> {
        if !dir.is_dir() {
            return Err(Error::Checkpoint(format!(
                "{}: no such folder to resume",
                dir.display()
            )));
        }
        let mut f = Folder::lock(dir)?;
        f.files = f.read_manifest()?.unwrap_or_else(|| f.known_files());
        f.remove_leftovers();
        Ok(f)
    }

    fn lock(dir: &Path) -> Result<Folder> {
        if dir.exists() && !dir.is_dir() {
            return Err(Error::Folder(format!(
                "{} is a file, not a folder",
                dir.display()
            )));
        }
        std::fs::create_dir_all(dir)
            .map_err(|e| Error::io("cannot create output folder", dir, e))?;
        let lock = dir.join(LOCK);
        // A run that ends removes its lock file; one that opened the file
        // just before may then hold a lock on a removed file: retry.
        for _ in 0..10 {
            let mut file = open_lock(&lock)?;
            match try_flock(&file) {
                Ok(true) => {}
                Ok(false) => {
                    let text = std::fs::read_to_string(&lock).unwrap_or_default();
                    let who = match text.trim().parse::<u32>() {
                        Ok(pid) => format!("lme-mpm process {pid}"),
                        Err(_) => "another lme-mpm run".to_string(),
                    };
                    return Err(Error::Folder(format!(
                        "{} is in use by {who} (it holds the lock on {}); wait for it to end",
                        dir.display(),
                        lock.display()
                    )));
                }
                Err(e) => return Err(Error::io("cannot lock", &lock, e)),
            }
            if !same_file(&file, &lock) {
                continue;
            }
            file.set_len(0)
                .and_then(|()| writeln!(file, "{}", std::process::id()))
                .map_err(|e| Error::io("cannot write", &lock, e))?;
            let id = NEXT_ID.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            live().push(Live {
                id,
                dir: dir.to_path_buf(),
                lock: lock.clone(),
                last_words: None,
                saving: 0,
            });
            return Ok(Folder {
                dir: dir.to_path_buf(),
                files: BTreeSet::new(),
                lock,
                _lock_file: file,
                id,
            });
        }
        Err(Error::Folder(format!(
            "{}: another run keeps taking the lock file {}",
            dir.display(),
            lock.display()
        )))
    }

    /// Sets the summary.json a sudden end of the process writes (see
    /// `abandon_all`).
    pub fn set_last_words(&self, summary: String) {
        if let Some(l) = live().iter_mut().find(|l| l.id == self.id) {
            l.last_words = Some(summary);
        }
    }

    /// Marks a save in progress until the guard drops: a signal then
    /// cannot end the process (`abandon_all` refuses).
    pub fn saving(&self) -> Saving {
        if let Some(l) = live().iter_mut().find(|l| l.id == self.id) {
            l.saving += 1;
        }
        Saving { id: self.id }
    }

    /// Removes the `.tmp` files a killed write left: of every file lme-mpm
    /// writes here (listed, or by its known name) and of the folder's own
    /// bookkeeping. Nothing writes them while the lock is held.
    fn remove_leftovers(&self) {
        let names = self
            .files
            .iter()
            .map(String::as_str)
            .chain(KNOWN.iter().copied())
            .chain([MANIFEST])
            .filter(|r| is_plain_relative(r))
            .map(|r| super::tmp_path(&self.dir.join(r)))
            .collect::<Vec<_>>();
        for p in names {
            super::remove_entry(&p);
        }
        if let Ok(rd) = std::fs::read_dir(self.dir.join("vtk")) {
            for e in rd.flatten() {
                let name = e.file_name().to_string_lossy().into_owned();
                if name.starts_with("particles_") && name.ends_with(".vtu.tmp") {
                    super::remove_entry(&e.path());
                }
            }
        }
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// `rel` inside the folder.
    pub fn path(&self, rel: &str) -> PathBuf {
        self.dir.join(rel)
    }

    /// Notes that this run writes `rel` (a path relative to the folder),
    /// before it is written, so a crash never leaves an unlisted file.
    pub fn record(&mut self, rel: &str) -> Result<()> {
        if self.files.insert(rel.to_string()) {
            self.write_manifest()?;
        }
        Ok(())
    }

    /// Removes every listed file for which `keep` is false (and its `.tmp`),
    /// from the disk and the manifest; `vtk/` goes when it is left empty.
    pub fn retain(&mut self, keep: impl Fn(&str) -> bool) -> Result<()> {
        let listed: Vec<String> = self.files.iter().cloned().collect();
        self.prune(keep, &listed)?;
        self.write_manifest()
    }

    fn prune(&mut self, keep: impl Fn(&str) -> bool, listed: &[String]) -> Result<()> {
        for rel in listed {
            if keep(rel) || !is_plain_relative(rel) {
                continue;
            }
            for p in [self.dir.join(rel), self.dir.join(format!("{rel}.tmp"))] {
                if std::fs::symlink_metadata(&p).is_err() {
                    continue; // gone already (or its folder is not one)
                }
                match std::fs::remove_file(&p) {
                    Ok(()) => {}
                    Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                    Err(e) => return Err(Error::io("cannot remove earlier output", &p, e)),
                }
            }
            self.files.remove(rel);
        }
        // Only when empty: a user's files there stay.
        let _ = std::fs::remove_dir(self.dir.join("vtk"));
        Ok(())
    }

    fn read_manifest(&self) -> Result<Option<BTreeSet<String>>> {
        let p = self.dir.join(MANIFEST);
        match std::fs::read_to_string(&p) {
            Ok(text) => Ok(Some(
                text.lines()
                    .map(str::trim)
                    .filter(|l| !l.is_empty() && !l.starts_with('#'))
                    .map(String::from)
                    .collect(),
            )),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
            Err(e) => Err(Error::io("cannot read", &p, e)),
        }
    }

    fn write_manifest(&self) -> Result<()> {
        let mut text = String::from(
            "# files written by the lme-mpm run in this folder; a new run removes them\n",
        );
        for f in &self.files {
            text.push_str(f);
            text.push('\n');
        }
        super::write_atomic(&self.dir.join(MANIFEST), text.as_bytes())
    }

    fn has_known_files(&self) -> bool {
        ["summary.json", "scene.resolved.toml"]
            .iter()
            .any(|f| self.dir.join(f).is_file())
    }

    /// Files by the names lme-mpm writes (an output folder without a manifest).
    fn known_files(&self) -> BTreeSet<String> {
        let mut out: BTreeSet<String> = KNOWN
            .iter()
            .filter(|f| self.dir.join(f).exists() || self.dir.join(format!("{f}.tmp")).exists())
            .map(|f| f.to_string())
            .collect();
        if let Ok(rd) = std::fs::read_dir(self.dir.join("vtk")) {
            for e in rd.flatten() {
                let name = e.file_name().to_string_lossy().into_owned();
                let stem = name.trim_end_matches(".tmp");
                if stem.starts_with("particles_") && stem.ends_with(".vtu") {
                    out.insert(format!("vtk/{stem}"));
                }
            }
        }
        out
    }

    /// Refuses a folder holding anything but the lock.
    fn check_empty(&self) -> Result<()> {
        let rd =
            std::fs::read_dir(&self.dir).map_err(|e| Error::io("cannot read", &self.dir, e))?;
        let others: Vec<String> = rd
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n != LOCK && n != SWEEP_ENTRY)
            .collect();
        if others.is_empty() {
            return Ok(());
        }
        Err(Error::Folder(format!(
            "{} is not empty and is not an lme-mpm output folder (no {MANIFEST}, summary.json or \
             scene.resolved.toml; it holds {}): give --out an empty or new folder",
            self.dir.display(),
            others
                .iter()
                .take(3)
                .cloned()
                .collect::<Vec<_>>()
                .join(", ")
                + if others.len() > 3 { ", ..." } else { "" }
        )))
    }
}

impl Drop for Folder {
    fn drop(&mut self) {
        // Removed while still locked (the file closes after this), so the
        // next run finds no file or a fresh one; `lock` retries if it
        // opened this one just before.
        let _ = std::fs::remove_file(&self.lock);
        live().retain(|l| l.id != self.id);
    }
}

/// A manifest line names a file inside the folder: relative, no `..`.
fn is_plain_relative(rel: &str) -> bool {
    let p = Path::new(rel);
    p.is_relative()
        && p.components()
            .all(|c| matches!(c, std::path::Component::Normal(_)))
}

/// Opens (creating) the lock file without following a link.
fn open_lock(lock: &Path) -> Result<std::fs::File> {
    let mut o = std::fs::OpenOptions::new();
    o.read(true).write(true).create(true).truncate(false);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        o.custom_flags(libc::O_NOFOLLOW | libc::O_CLOEXEC);
    }
    o.open(lock)
        .map_err(|e| Error::io("cannot write into output folder", lock, e))
}

/// Takes an exclusive flock on `file` without waiting: false when another
/// process holds it.
#[cfg(unix)]
fn try_flock(file: &std::fs::File) -> std::io::Result<bool> {
    use std::os::unix::io::AsRawFd;
    // SAFETY: flock on a file descriptor this process owns and keeps open.
    let r = unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) };
    if r == 0 {
        return Ok(true);
    }
    let e = std::io::Error::last_os_error();
    if e.raw_os_error() == Some(libc::EWOULDBLOCK) {
        Ok(false)
    } else {
        Err(e)
    }
}

/// Without flock (not unix) no lock is taken: the folder is not guarded
/// against a second run.
#[cfg(not(unix))]
fn try_flock(_file: &std::fs::File) -> std::io::Result<bool> {
    Ok(true)
}

/// Whether `path` still names the open `file` (not removed or replaced).
#[cfg(unix)]
fn same_file(file: &std::fs::File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::symlink_metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_file(_file: &std::fs::File, path: &Path) -> bool {
    path.is_file()
}
