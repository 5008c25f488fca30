//! What a study is to `lme-mpm study`: its name, its line of `--help`, its
//! jobs and its report. Each study's file implements `Study` on a unit
//! struct of its own, and `study/mod.rs` lists them once (`studies!`), from
//! which the CLI's names, `all` and the dispatch follow. A leaf under the
//! studies, so each study's file names it and not `study/mod.rs`.

use super::runner::{Job, JobResult};
use crate::error::Result;
use crate::simulation::BackendChoice;
use std::path::{Path, PathBuf};

/// One study of `lme-mpm study`.
pub trait Study: Sync {
    /// Its name on the command line, its output folder's (`<out>/<slug>/`)
    /// and its doc section's (`study-<slug>`).
    fn slug(&self) -> &'static str;
    /// Its line in `lme-mpm study --help` (no final period, as clap writes
    /// a doc comment).
    fn help(&self) -> &'static str;
    /// Its runs on `backends` (`quick`: the reduced sweep).
    fn jobs(&self, quick: bool, backends: &[BackendChoice]) -> Result<Vec<Job>>;
    /// Its section (markdown) and the charts it wrote into `dir`.
    fn report(
        &self,
        results: &[JobResult],
        dir: &Path,
        quick: bool,
    ) -> Result<(String, Vec<PathBuf>)>;
}
