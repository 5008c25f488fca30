//! Runs a study's jobs: independent simulations spread over the cores
//! (`--jobs` worker threads, each with its own share of rayon threads), with
//! one overall progress bar. A job that goes unstable, or cannot even start,
//! is a result row, never an abort of the study.

use crate::backend::{Backend, Sample};
use crate::exact::Errors;
use crate::model::Particles;
use crate::scene::{Override, Scene};
use crate::simulation::{BackendChoice, BackendSpec, Simulation};
use crate::solver::{Observer, RunStatus, Schedule};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::borrow::Cow;
use std::collections::VecDeque;
use std::sync::Mutex;
use std::time::Instant;

/// One simulation of a study.
#[derive(Debug, Clone)]
pub struct Job {
    /// Unique within the study.
    pub label: String,
    /// Scene file text (one of `cases`, or a study's variant of one), its
    /// name, and overrides.
    pub case: Cow<'static, str>,
    pub case_name: &'static str,
    pub sets: Vec<String>,
    pub backend: BackendChoice,
    /// Columns for the results table, in order.
    pub tags: Vec<(&'static str, String)>,
    /// Particle snapshots to keep (s).
    pub snapshot_times: Vec<f64>,
    /// Keep the final particle state.
    pub keep_final: bool,
}

impl Job {
    pub fn new(
        label: impl Into<String>,
        case: impl Into<Cow<'static, str>>,
        case_name: &'static str,
    ) -> Self {
        Job {
            label: label.into(),
            case: case.into(),
            case_name,
            sets: Vec::new(),
            backend: BackendChoice::Cpu,
            tags: Vec::new(),
            snapshot_times: Vec::new(),
            keep_final: false,
        }
    }

    pub fn set(mut self, s: impl Into<String>) -> Self {
        self.sets.push(s.into());
        self
    }

    pub fn tag(mut self, k: &'static str, v: impl ToString) -> Self {
        self.tags.push((k, v.to_string()));
        self
    }

    pub fn tag_value(&self, k: &str) -> Option<&str> {
        self.tags
            .iter()
            .find(|(key, _)| *key == k)
            .map(|(_, v)| v.as_str())
    }
}

/// What a job produced.
#[derive(Debug, Clone)]
pub struct RunData {
    pub status: RunStatus,
    pub t: f64,
    pub t_end: f64,
    pub steps: u64,
    pub particles: usize,
    /// Stepping wall time (s) on this job's threads.
    pub wall_seconds: f64,
    pub threads: usize,
    pub backend: String,
    pub errors: Option<Errors>,
    pub samples: Vec<Sample>,
    /// (time, particles) at the requested snapshot times.
    pub snapshots: Vec<(f64, Particles)>,
    pub final_particles: Option<Particles>,
    /// Initial positions of the probes' particles, by probe name.
    pub probe_x0: Vec<(String, [f64; 2])>,
}

impl RunData {
    pub fn completed(&self) -> bool {
        matches!(self.status, RunStatus::Completed)
    }

    /// "completed", or "unstable at t = … s: reason".
    pub fn status_text(&self) -> String {
        match &self.status {
            RunStatus::Completed => "completed".into(),
            RunStatus::Unstable { fault, t, .. } => format!("unstable at t = {t:.4e} s: {fault}"),
            RunStatus::Interrupted { t, .. } => format!("interrupted at t = {t:.4e} s"),
        }
    }

    pub fn particle_steps_per_second(&self) -> f64 {
        self.particles as f64 * self.steps as f64 / self.wall_seconds.max(1e-12)
    }

    /// History of one probe: (t, state).
    pub fn probe(&self, name: &str) -> Vec<(f64, crate::backend::ProbeState)> {
        let Some(k) = self.probe_x0.iter().position(|(n, _)| n == name) else {
            return Vec::new();
        };
        self.samples.iter().map(|s| (s.t, s.probes[k])).collect()
    }
}

/// A job and its outcome: data, or why it could not run.
#[derive(Debug, Clone)]
pub struct JobResult {
    pub job: Job,
    pub outcome: Result<RunData, String>,
}

impl JobResult {
    pub fn data(&self) -> Option<&RunData> {
        self.outcome.as_ref().ok()
    }

    pub fn completed(&self) -> bool {
        self.data().is_some_and(RunData::completed)
    }
}

struct Keeper {
    samples: Vec<Sample>,
    snapshots: Vec<(f64, Particles)>,
}

impl Observer for Keeper {
    fn sample(&mut self, s: &Sample) -> crate::Result<()> {
        self.samples.push(s.clone());
        Ok(())
    }
    fn snapshot(&mut self, backend: &mut dyn Backend) -> crate::Result<()> {
        let t = backend.time();
        let p = backend.particles()?;
        self.snapshots.push((t, p.clone()));
        Ok(())
    }
}

fn run_one(job: &Job, threads: usize, gpu_lock: &Mutex<()>) -> Result<RunData, String> {
    let overrides = job
        .sets
        .iter()
        .map(|s| Override::parse(s))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| e.to_string())?;
    let scene = Scene::from_str(&job.case, job.case_name, job.case_name, &overrides)
        .map_err(|e| e.to_string())?;
    // GPU jobs share one adapter: run them one at a time.
    let _gpu = (job.backend != BackendChoice::Cpu)
        .then(|| gpu_lock.lock().unwrap_or_else(|e| e.into_inner()));
    let mut sim =
        Simulation::new(&scene, &BackendSpec::new(job.backend)).map_err(|e| e.to_string())?;
    let probe_x0 = {
        let model = sim.backend_ref().model();
        model
            .probes
            .iter()
            .map(|p| (p.name.clone(), model.particles.x0[p.particle]))
            .collect()
    };
    let schedule = Schedule {
        snapshot_times: job.snapshot_times.clone(),
        vtk_interval: None,
        checkpoint_interval: None,
        ..sim.schedule()
    };
    let mut keeper = Keeper {
        samples: Vec::new(),
        snapshots: Vec::new(),
    };
    let start = Instant::now();
    let status = sim
        .drive_with(schedule, &mut keeper)
        .map_err(|e| e.to_string())?;
    let wall = start.elapsed().as_secs_f64();
    let errors = sim.score().map_err(|e| e.to_string())?;
    let backend = sim.backend();
    let t = backend.time();
    let particles = backend.particles().map_err(|e| e.to_string())?.clone();
    Ok(RunData {
        status,
        t,
        t_end: scene.file.solver.t_end,
        steps: backend.steps(),
        particles: particles.len(),
        wall_seconds: wall,
        threads,
        backend: backend.name(),
        errors,
        samples: keeper.samples,
        snapshots: keeper.snapshots,
        final_particles: job.keep_final.then_some(particles),
        probe_x0,
    })
}

/// Runs `jobs` on `n_workers` threads; results come back in job order.
pub fn run_jobs(jobs: Vec<Job>, n_workers: usize, progress: bool) -> Vec<JobResult> {
    let n = jobs.len();
    let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
    let workers = n_workers.clamp(1, n.max(1));
    let threads = (cores / workers).max(1);
    let bar = if progress {
        let b = ProgressBar::with_draw_target(Some(n as u64), ProgressDrawTarget::stderr());
        b.set_style(
            ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} runs  {msg}")
                .expect("valid template")
                .progress_chars("=> "),
        );
        b
    } else {
        ProgressBar::hidden()
    };
    let queue: Mutex<VecDeque<(usize, Job)>> = Mutex::new(jobs.into_iter().enumerate().collect());
    let results: Mutex<Vec<Option<JobResult>>> = Mutex::new(vec![None; n]);
    let gpu_lock = Mutex::new(());
    std::thread::scope(|s| {
        for _ in 0..workers {
            s.spawn(|| {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .expect("thread pool");
                loop {
                    let next = queue.lock().unwrap_or_else(|e| e.into_inner()).pop_front();
                    let Some((i, job)) = next else { break };
                    bar.set_message(job.label.clone());
                    let outcome = pool.install(|| {
                        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                            run_one(&job, threads, &gpu_lock)
                        }))
                        .unwrap_or_else(|p| {
                            let msg = p
                                .downcast_ref::<String>()
                                .cloned()
                                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                                .unwrap_or_default();
                            Err(format!("the run panicked: {msg}"))
                        })
                    });
                    results.lock().unwrap_or_else(|e| e.into_inner())[i] =
                        Some(JobResult { job, outcome });
                    bar.inc(1);
                }
            });
        }
    });
    bar.finish_and_clear();
    results
        .into_inner()
        .unwrap_or_else(|e| e.into_inner())
        .into_iter()
        .map(|r| r.expect("every job ran"))
        .collect()
}

/// The results as CSV: label, tags, then status and speed columns, then
/// the error figures (flattened from `summary.json`'s `errors`).
pub fn results_csv(results: &[JobResult]) -> String {
    use std::fmt::Write;
    let mut tag_keys: Vec<&'static str> = Vec::new();
    let mut err_keys: Vec<String> = Vec::new();
    for r in results {
        for (k, _) in &r.job.tags {
            if !tag_keys.contains(k) {
                tag_keys.push(k);
            }
        }
        if let Some(e) = r.data().and_then(|d| d.errors.as_ref()) {
            if let Ok(serde_json::Value::Object(m)) = serde_json::to_value(e) {
                for k in m.keys() {
                    if !err_keys.contains(k) {
                        err_keys.push(k.clone());
                    }
                }
            }
        }
    }
    let mut s = String::from("label,");
    for k in &tag_keys {
        let _ = write!(s, "{k},");
    }
    s.push_str("backend_name,status,reason,t,steps,particles,threads,wall_seconds,particle_steps_per_second");
    for k in &err_keys {
        let _ = write!(s, ",{k}");
    }
    s.push('\n');
    for r in results {
        let _ = write!(s, "{},", r.job.label);
        for k in &tag_keys {
            let _ = write!(s, "{},", r.job.tag_value(k).unwrap_or(""));
        }
        match &r.outcome {
            Err(e) => {
                let _ = write!(
                    s,
                    "{:?},error,\"{}\",,,,,,",
                    r.job.backend,
                    e.replace('"', "'")
                );
                s.extend(std::iter::repeat_n(',', err_keys.len()));
            }
            Ok(d) => {
                let (status, reason) = match &d.status {
                    RunStatus::Completed => ("completed", String::new()),
                    RunStatus::Unstable { fault, .. } => ("unstable", fault.to_string()),
                    RunStatus::Interrupted { .. } => ("interrupted", String::new()),
                };
                let _ = write!(
                    s,
                    "{},{status},\"{}\",{},{},{},{},{},{}",
                    d.backend.replace(',', ";"),
                    reason.replace('"', "'"),
                    d.t,
                    d.steps,
                    d.particles,
                    d.threads,
                    d.wall_seconds,
                    d.particle_steps_per_second()
                );
                let m = d
                    .errors
                    .as_ref()
                    .and_then(|e| serde_json::to_value(e).ok())
                    .and_then(|v| v.as_object().cloned())
                    .unwrap_or_default();
                for k in &err_keys {
                    let _ = write!(s, ",{}", m.get(k).map_or(String::new(), |v| v.to_string()));
                }
            }
        }
        s.push('\n');
    }
    s
}
