//! One row of a sweep: a run's keys, how it ended, its cost and its error
//! figures. Read from a run folder's `summary.json` (sweeps, `--collect`) or
//! made from a study's in-memory result, so both share one table, one CSV
//! and one set of charts (`report.rs`).

use super::runner::JobResult;
use crate::solver::RunStatus;
use serde::Deserialize;

/// How a run ended, as the sweep table says it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    Completed,
    Unstable,
    /// Stopped by a signal (its folder holds a checkpoint: `lme-mpm resume`).
    Interrupted,
    /// Could not run, or ended in an error (the reason says which).
    Failed,
    /// Its folder says `running`: killed, or still going.
    Running,
    /// No summary.json: never started (or refused before writing).
    Missing,
}

impl Outcome {
    pub fn as_str(self) -> &'static str {
        match self {
            Outcome::Completed => "completed",
            Outcome::Unstable => "unstable",
            Outcome::Interrupted => "interrupted",
            Outcome::Failed => "failed",
            Outcome::Running => "running",
            Outcome::Missing => "missing",
        }
    }
}

/// One run of a sweep or study.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    /// Run id (a sweep's folder name under `runs/`, a study's job label).
    pub id: String,
    /// The varied keys (a sweep) or the study's columns, in order, with this run's values.
    pub keys: Vec<(String, String)>,
    pub outcome: Outcome,
    /// Why it did not complete, in words (empty when completed).
    pub reason: String,
    /// Machine-friendly reason (summary.json's `reason_code`), if any.
    pub reason_code: String,
    /// Time reached and end time (s).
    pub t: Option<f64>,
    pub t_end: Option<f64>,
    pub steps: Option<u64>,
    /// Stepping wall time (s), outputs excluded.
    pub wall_seconds: Option<f64>,
    pub particle_steps_per_second: Option<f64>,
    pub particles: Option<u64>,
    pub bytes_per_particle: Option<f64>,
    /// e.g. `cpu (f64, 2 threads, x86-64-v3)`.
    pub backend: String,
    /// Grid spacing (m).
    pub h: Option<f64>,
    /// Error figures in the order summary.json gives them, then any
    /// measured against a reference run (`reference.rs`).
    pub errors: Vec<(String, f64)>,
    /// What the figures are measured against: `exact`, `finest run ID`,
    /// `reference` (this run is its series' reference), or empty.
    pub error_source: String,
}

impl Record {
    /// A row with nothing known but its id and keys.
    pub fn missing(id: &str, keys: Vec<(String, String)>, reason: &str) -> Record {
        Record {
            id: id.to_string(),
            keys,
            outcome: Outcome::Missing,
            reason: reason.to_string(),
            reason_code: String::new(),
            t: None,
            t_end: None,
            steps: None,
            wall_seconds: None,
            particle_steps_per_second: None,
            particles: None,
            bytes_per_particle: None,
            backend: String::new(),
            h: None,
            errors: Vec::new(),
            error_source: String::new(),
        }
    }

    pub fn completed(&self) -> bool {
        self.outcome == Outcome::Completed
    }

    pub fn key(&self, k: &str) -> Option<&str> {
        self.keys
            .iter()
            .find(|(key, _)| key == k)
            .map(|(_, v)| v.as_str())
    }

    /// Error figure `name`, if the run reports it.
    pub fn figure(&self, name: &str) -> Option<f64> {
        self.errors.iter().find(|(k, _)| k == name).map(|(_, v)| *v)
    }

    /// `completed`, or `unstable at 1.2e-5 s (left_grid)`, `failed: …`.
    pub fn status_text(&self) -> String {
        match self.outcome {
            Outcome::Completed => "completed".into(),
            Outcome::Unstable => format!(
                "unstable at {} s ({})",
                self.t.map_or("?".into(), crate::sweep::number::sig),
                if self.reason_code.is_empty() {
                    &self.reason
                } else {
                    &self.reason_code
                }
            ),
            Outcome::Interrupted => format!(
                "interrupted at {} s",
                self.t.map_or("?".into(), crate::sweep::number::sig)
            ),
            o => format!("{}: {}", o.as_str(), self.reason),
        }
    }

    /// A study job's result as a row; its tags are the keys.
    pub fn from_job(r: &JobResult) -> Record {
        let keys = r
            .job
            .tags
            .iter()
            .map(|(k, v)| (k.to_string(), v.clone()))
            .collect();
        let mut rec = Record::missing(&r.job.label, keys, "");
        match &r.outcome {
            Err(e) => {
                rec.outcome = Outcome::Failed;
                rec.reason = e.clone();
            }
            Ok(d) => {
                (rec.outcome, rec.reason, rec.reason_code) = match &d.status {
                    RunStatus::Completed => (Outcome::Completed, String::new(), String::new()),
                    RunStatus::Unstable { fault, .. } => (
                        Outcome::Unstable,
                        fault.to_string(),
                        fault.code().to_string(),
                    ),
                    RunStatus::Interrupted { .. } => {
                        (Outcome::Interrupted, String::new(), String::new())
                    }
                };
                rec.t = Some(d.t);
                rec.t_end = Some(d.t_end);
                rec.steps = Some(d.steps);
                rec.wall_seconds = Some(d.wall_seconds);
                rec.particle_steps_per_second = Some(d.particle_steps_per_second());
                rec.particles = Some(d.particles as u64);
                rec.bytes_per_particle = Some(d.bytes_per_particle);
                rec.backend = d.backend.clone();
                rec.h = Some(d.h);
                if let Some(e) = &d.errors {
                    let json = serde_json::to_string(e).expect("errors serialise");
                    rec.errors = serde_json::from_str::<Ordered>(&json)
                        .map(|o| o.0)
                        .unwrap_or_default();
                    rec.error_source = "exact".into();
                }
            }
        }
        rec
    }

    /// A run folder's summary.json (text) as a row.
    pub fn from_summary(
        id: &str,
        keys: Vec<(String, String)>,
        json: &str,
    ) -> Result<Record, String> {
        let s: SummaryFile =
            serde_json::from_str(json).map_err(|e| format!("summary.json unreadable: {e}"))?;
        let mut rec = Record::missing(id, keys, "");
        rec.outcome = match s.status.as_str() {
            "completed" => Outcome::Completed,
            "unstable" => Outcome::Unstable,
            "interrupted" => Outcome::Interrupted,
            "running" => Outcome::Running,
            _ => Outcome::Failed,
        };
        rec.reason = match rec.outcome {
            Outcome::Running => format!(
                "summary.json still says running (pid {}): the run was killed, or is not done",
                s.pid.map_or("?".into(), |p| p.to_string())
            ),
            Outcome::Failed => s
                .error
                .clone()
                .unwrap_or_else(|| format!("status `{}`", s.status)),
            _ => s.reason.clone().unwrap_or_default(),
        };
        rec.reason_code = s.reason_code.unwrap_or_default();
        rec.t = s.t;
        rec.t_end = s.t_end;
        rec.steps = s.steps;
        rec.wall_seconds = s.wall_seconds;
        rec.particle_steps_per_second = s.particle_steps_per_second;
        rec.particles = s.particles;
        rec.bytes_per_particle = s.bytes_per_particle;
        rec.backend = s.backend.unwrap_or_default();
        rec.h = s.h;
        if let Some(e) = s.errors {
            rec.errors = e.0;
            rec.error_source = "exact".into();
        }
        Ok(rec)
    }
}

/// The parts of summary.json a sweep reads; a `running` or `failed`
/// summary has only a few of them.
#[derive(Deserialize)]
struct SummaryFile {
    status: String,
    reason: Option<String>,
    reason_code: Option<String>,
    error: Option<String>,
    pid: Option<u64>,
    t: Option<f64>,
    t_end: Option<f64>,
    steps: Option<u64>,
    wall_seconds: Option<f64>,
    particle_steps_per_second: Option<f64>,
    particles: Option<u64>,
    bytes_per_particle: Option<f64>,
    backend: Option<String>,
    h: Option<f64>,
    errors: Option<Ordered>,
}

/// A JSON object of numbers, kept in the order written (serde_json's own
/// map sorts its keys; "the first error the summary reports" needs the order).
struct Ordered(Vec<(String, f64)>);

impl<'de> Deserialize<'de> for Ordered {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visit;
        impl<'de> serde::de::Visitor<'de> for Visit {
            type Value = Ordered;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an object of error figures")
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                mut m: A,
            ) -> Result<Ordered, A::Error> {
                let mut v = Vec::new();
                while let Some((k, val)) = m.next_entry::<String, serde_json::Value>()? {
                    // serde_json writes NaN and infinities as null.
                    match val {
                        serde_json::Value::Number(n) => v.push((k, n.as_f64().unwrap_or(f64::NAN))),
                        serde_json::Value::Null => v.push((k, f64::NAN)),
                        _ => {}
                    }
                }
                Ok(Ordered(v))
            }
        }
        d.deserialize_map(Visit)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_keep_the_summary_order() {
        let json = r#"{"status":"completed","t":1.0,"errors":{"zeta":1.5,"alpha":null,"mid":2}}"#;
        let r = Record::from_summary("a", vec![], json).unwrap();
        let names: Vec<&str> = r.errors.iter().map(|(k, _)| k.as_str()).collect();
        assert_eq!(names, ["zeta", "alpha", "mid"]);
        assert!(r.figure("alpha").unwrap().is_nan());
        assert_eq!(r.figure("mid"), Some(2.0));
        assert_eq!(r.error_source, "exact");
    }

    #[test]
    fn a_running_summary_is_a_killed_run() {
        let r = Record::from_summary("a", vec![], r#"{"status":"running","pid":42}"#).unwrap();
        assert_eq!(r.outcome, Outcome::Running);
        assert!(r.reason.contains("pid 42"), "{}", r.reason);
        let r = Record::from_summary("a", vec![], r#"{"status":"failed","error":"disk full"}"#)
            .unwrap();
        assert_eq!(
            (r.outcome, r.reason.as_str()),
            (Outcome::Failed, "disk full")
        );
    }
}
