//! Runs independent simulations spread over the cores (`--jobs` worker
//! threads, each with its own share of rayon threads) with one overall
//! progress bar: `run_parallel` for any work item (a sweep's run folders),
//! `run_jobs` for a study's in-memory jobs. A run that goes unstable,
//! cannot even start, or panics is a result, never an abort of the batch.

use crate::backend::{Backend, Sample};
use crate::exact::Errors;
use crate::model::Particles;
use crate::scene::{Override, Scene};
use crate::simulation::{BackendChoice, BackendSpec, Simulation};
use crate::solver::{Observer, RunStatus, Schedule};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::borrow::Cow;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Instant;

/// A shape function as the studies name it: (label, `solver.shape`, LME γ;
/// 0 for shapes without one).
pub type Method = (&'static str, &'static str, f64);

/// A backend's short name in run labels and tables.
pub fn backend_slug(b: BackendChoice) -> &'static str {
    match b {
        BackendChoice::Cpu => "cpu",
        BackendChoice::Gpu => "gpu",
        BackendChoice::Auto => "auto",
    }
}

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

    /// Runs on `b`, tagged `backend` with its slug (`cpu`, `gpu`, `auto`).
    pub fn on(mut self, b: BackendChoice) -> Self {
        self.backend = b;
        self.tag("backend", backend_slug(b))
    }

    /// Sets `solver.shape`, and `solver.lme_gamma` when γ > 0, tagged
    /// `method` with the method's label.
    pub fn method(self, (label, shape, gamma): Method) -> Self {
        let j = self
            .set(format!("solver.shape={shape}"))
            .tag("method", label);
        if gamma > 0.0 {
            j.set(format!("solver.lme_gamma={gamma}"))
        } else {
            j
        }
    }

    pub fn tag_value(&self, k: &str) -> Option<&str> {
        self.tags
            .iter()
            .find(|(key, _)| *key == k)
            .map(|(_, v)| v.as_str())
    }

    /// The job's scene: its case text with its overrides.
    pub fn scene(&self) -> Result<Scene, crate::error::SceneError> {
        let overrides = self
            .sets
            .iter()
            .map(|s| Override::parse(s))
            .collect::<Result<Vec<_>, _>>()?;
        Scene::from_str(&self.case, self.case_name, self.case_name, &overrides)
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
    /// Memory the backend holds per particle, grid included (bytes).
    pub bytes_per_particle: f64,
    /// Grid spacing (m).
    pub h: f64,
    pub errors: Option<Errors>,
    pub samples: Vec<Sample>,
    /// (time, particles) at the requested snapshot times.
    pub snapshots: Vec<(f64, Particles)>,
    pub final_particles: Option<Particles>,
    /// Initial positions of the probes' particles, by probe name.
    pub probe_x0: Vec<(String, [f64; 2])>,
    /// The implicit integrator's Newton statistics and timers (else None).
    pub newton: Option<crate::backend::NewtonStats>,
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

fn run_one(job: &Job, threads: usize) -> Result<RunData, String> {
    let scene = job.scene().map_err(|e| e.to_string())?;
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
    let errors = sim.score_with(&keeper.samples).map_err(|e| e.to_string())?;
    let backend = sim.backend();
    let t = backend.time();
    let bytes_per_particle = backend.bytes_per_particle();
    let h = backend.model().grid.h;
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
        bytes_per_particle,
        h,
        errors,
        samples: keeper.samples,
        snapshots: keeper.snapshots,
        final_particles: job.keep_final.then_some(particles),
        newton: backend.newton().cloned(),
        probe_x0,
    })
}

/// The threads a batch runs on: `workers` runs at once, each on a rayon
/// pool of `threads` threads (the cores shared out).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Split {
    pub workers: usize,
    pub threads: usize,
}

impl Split {
    /// `n_workers` runs at once (at least 1, at most `n_items`).
    pub fn new(n_workers: usize, n_items: usize) -> Split {
        let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
        let workers = n_workers.clamp(1, n_items.max(1));
        Split {
            workers,
            threads: (cores / workers).max(1),
        }
    }
}

/// One overall bar over `n` runs on stderr, or a hidden one.
pub fn progress_bar(n: usize, show: bool) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let b = ProgressBar::with_draw_target(Some(n as u64), ProgressDrawTarget::stderr());
    b.set_style(
        ProgressStyle::with_template(
            "{elapsed_precise} [{bar:40}] {pos}/{len} runs  eta {eta}  {msg}",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    b
}

/// Runs `work(item, threads)` for every item on `split.workers` threads, each
/// inside its own rayon pool of `split.threads`; results come back in item
/// order. Items for which `exclusive` is true (GPU runs: one adapter) run one
/// at a time. A panic becomes `on_panic(item, message)`. Once `stop` is
/// raised no further item starts: those come back as None.
#[allow(clippy::too_many_arguments)]
pub fn run_parallel<T: Sync, R: Send>(
    items: &[T],
    split: Split,
    bar: &ProgressBar,
    label: impl Fn(&T) -> String + Sync,
    exclusive: impl Fn(&T) -> bool + Sync,
    stop: Option<&AtomicBool>,
    work: impl Fn(&T, usize) -> R + Sync,
    on_panic: impl Fn(&T, String) -> R + Sync,
) -> Vec<Option<R>> {
    let n = items.len();
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<R>>> = Mutex::new((0..n).map(|_| None).collect());
    let gpu_lock = Mutex::new(());
    std::thread::scope(|s| {
        for _ in 0..split.workers.min(n.max(1)) {
            s.spawn(|| {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(split.threads)
                    .build()
                    .expect("thread pool");
                loop {
                    if stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
                        break;
                    }
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(item) = items.get(i) else { break };
                    bar.set_message(label(item));
                    let _gpu =
                        exclusive(item).then(|| gpu_lock.lock().unwrap_or_else(|e| e.into_inner()));
                    let r = pool.install(|| {
                        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                            work(item, split.threads)
                        }))
                        .unwrap_or_else(|p| {
                            let msg = p
                                .downcast_ref::<String>()
                                .cloned()
                                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                                .unwrap_or_default();
                            on_panic(item, msg)
                        })
                    });
                    results.lock().unwrap_or_else(|e| e.into_inner())[i] = Some(r);
                    bar.inc(1);
                }
            });
        }
    });
    results.into_inner().unwrap_or_else(|e| e.into_inner())
}

/// Runs a study's `jobs` on `n_workers` threads; results come back in job
/// order. `progress`: the bar (a terminal); `lines`: one line on stderr per
/// finished run, for logs (`name` starts it).
pub fn run_jobs(
    jobs: Vec<Job>,
    n_workers: usize,
    progress: bool,
    lines: Option<&str>,
) -> Vec<JobResult> {
    let bar = progress_bar(jobs.len(), progress);
    let done = AtomicUsize::new(0);
    let start = Instant::now();
    let n = jobs.len();
    let outcomes = run_parallel(
        &jobs,
        Split::new(n_workers, jobs.len()),
        &bar,
        |j| j.label.clone(),
        |j| j.backend != BackendChoice::Cpu,
        None,
        |job, threads| {
            let r = run_one(job, threads);
            if let Some(name) = lines {
                let k = done.fetch_add(1, Ordering::Relaxed) + 1;
                let how = match &r {
                    Ok(d) => d.status_text(),
                    Err(e) => format!("failed: {e}"),
                };
                eprintln!(
                    "{name}: {k}/{n} runs done ({:.0} s); {} {how}",
                    start.elapsed().as_secs_f64(),
                    job.label
                );
            }
            r
        },
        |_, msg| Err(format!("the run panicked: {msg}")),
    );
    bar.finish_and_clear();
    jobs.into_iter()
        .zip(outcomes)
        .map(|(job, outcome)| JobResult {
            job,
            outcome: outcome.expect("no stop flag: every job ran"),
        })
        .collect()
}
