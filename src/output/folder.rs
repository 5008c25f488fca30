//! One run per output folder. A run takes `lme-mpm.lock` (its pid) so no
//! second run writes into the folder while it lives, lists every file it
//! writes in `lme-mpm.manifest` before writing it, and a new run first
//! removes what the manifest lists (never anything else). A non-empty
//! folder that is not an lme-mpm output folder is refused.

use crate::error::{Error, Result};
use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The list of files the run in the folder wrote, one relative path a line.
pub const MANIFEST: &str = "lme-mpm.manifest";
/// Held while a run writes into the folder: the pid of that run.
pub const LOCK: &str = "lme-mpm.lock";

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
        let pid = std::process::id();
        for _ in 0..3 {
            match std::fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(&lock)
            {
                Ok(mut file) => {
                    writeln!(file, "{pid}").map_err(|e| Error::io("cannot write", &lock, e))?;
                    return Ok(Folder {
                        dir: dir.to_path_buf(),
                        files: BTreeSet::new(),
                        lock,
                    });
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    let text = std::fs::read_to_string(&lock).unwrap_or_default();
                    if let Ok(other) = text.trim().parse::<u32>() {
                        if other != pid && alive(other) {
                            return Err(Error::Folder(format!(
                                "{} is in use by lme-mpm process {other} (lock file {}); wait for it to end, \
                                 or remove the lock file if no such run exists",
                                dir.display(),
                                lock.display()
                            )));
                        }
                    }
                    // A stale lock (its process is gone, or it is unreadable): take it over.
                    match std::fs::remove_file(&lock) {
                        Ok(()) => {}
                        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                        Err(e) => return Err(Error::io("cannot remove stale lock", &lock, e)),
                    }
                }
                Err(e) => return Err(Error::io("cannot write into output folder", dir, e)),
            }
        }
        Err(Error::Folder(format!(
            "{}: another run keeps taking the lock file {}",
            dir.display(),
            lock.display()
        )))
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
            .filter(|n| n != LOCK)
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
        // Only our own lock (a taken-over stale one is ours too).
        let ours = std::fs::read_to_string(&self.lock)
            .is_ok_and(|t| t.trim() == std::process::id().to_string());
        if ours {
            let _ = std::fs::remove_file(&self.lock);
        }
    }
}

/// A manifest line names a file inside the folder: relative, no `..`.
fn is_plain_relative(rel: &str) -> bool {
    let p = Path::new(rel);
    p.is_relative()
        && p.components()
            .all(|c| matches!(c, std::path::Component::Normal(_)))
}

/// Whether process `pid` exists.
#[cfg(unix)]
fn alive(pid: u32) -> bool {
    let Ok(pid) = libc::pid_t::try_from(pid) else {
        return false;
    };
    // SAFETY: signal 0 sends nothing; it only checks that the process exists.
    let r = unsafe { libc::kill(pid, 0) };
    r == 0 || std::io::Error::last_os_error().raw_os_error() == Some(libc::EPERM)
}

/// Without a way to ask, a lock is assumed held.
#[cfg(not(unix))]
fn alive(_pid: u32) -> bool {
    true
}
