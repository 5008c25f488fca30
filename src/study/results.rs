//! Reading a study's results: which backends ran, the results with a tag,
//! how a failed run ended, and the table/chart helpers every study's
//! report uses. A leaf under the studies, so each study's file names it
//! and not `study/mod.rs`, which runs the studies.

use super::runner::JobResult;
use crate::sweep::record::Record;

pub use super::runner::{Method, backend_slug};

/// The backends the study's runs used, in order of first appearance.
pub fn backends_of(results: &[JobResult]) -> Vec<&str> {
    tag_values(results, "backend")
}

/// The values of tag `key` among `results`, in order of first appearance.
pub fn tag_values<'a>(results: impl IntoIterator<Item = &'a JobResult>, key: &str) -> Vec<&'a str> {
    let mut v: Vec<&str> = Vec::new();
    for value in results.into_iter().filter_map(|r| r.job.tag_value(key)) {
        if !v.contains(&value) {
            v.push(value);
        }
    }
    v
}

/// The backend a study's report is about: its first job's ("cpu" if none).
pub fn main_backend(results: &[JobResult]) -> String {
    results
        .first()
        .and_then(|r| r.job.tag_value("backend"))
        .unwrap_or("cpu")
        .to_string()
}

/// The first result whose job carries every one of these (tag, value) pairs.
pub fn find_tagged<'a>(results: &'a [JobResult], tags: &[(&str, &str)]) -> Option<&'a JobResult> {
    results
        .iter()
        .find(|r| tags.iter().all(|&(k, v)| r.job.tag_value(k) == Some(v)))
}

/// The results of the jobs run on `backend`, in job order.
pub fn on_backend<'a>(results: &'a [JobResult], backend: &str) -> Vec<&'a JobResult> {
    results
        .iter()
        .filter(|r| r.job.tag_value("backend") == Some(backend))
        .collect()
}

pub use crate::sweep::report::{image, sig, table};

/// Short text for how a run ended (`unstable at 1.2e-5 s (left_grid)`),
/// the same words as a sweep's table.
pub fn failure_text(r: &JobResult) -> String {
    Record::from_job(r).status_text()
}
