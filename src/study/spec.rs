//! What a study is to `lme-mpm study`: its name, its line of `--help`, its
//! jobs and its report, as data. Each study's file holds one `Study`
//! (`STUDY`), and `study/mod.rs` lists them once (`studies!`), from which
//! the CLI's names, `all` and the dispatch follow. A leaf under the
//! studies, so each study's file names it and not `study/mod.rs`.

use super::runner::{Job, JobResult};
use crate::error::Result;
use crate::simulation::BackendChoice;
use std::path::{Path, PathBuf};

/// A study's section (markdown) and the charts it wrote.
pub type Report = (String, Vec<PathBuf>);

/// One study of `lme-mpm study`: each study's file holds one, `STUDY`.
pub struct Study {
    /// Its name on the command line, its output folder's (`<out>/<slug>/`)
    /// and its doc section's (`study-<slug>`).
    pub slug: &'static str,
    /// Its line in `lme-mpm study --help` (no final period, as clap writes
    /// a doc comment).
    pub help: &'static str,
    /// Its runs on the backends given (`quick`: the reduced sweep).
    pub jobs: fn(quick: bool, backends: &[BackendChoice]) -> Result<Vec<Job>>,
    /// Its section (markdown) and the charts it wrote into the folder.
    pub report: fn(results: &[JobResult], dir: &Path, quick: bool) -> Result<Report>,
}
