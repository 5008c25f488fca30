//! `lme-mpm sweep`: the Cartesian product of `--vary KEY=V1,V2,…` on any
//! scene, each run an ordinary run folder (`DIR/runs/ID`, what `lme-mpm run`
//! writes), then one table and charts of speed against accuracy.
//!
//! - `plan`: the axes, the product, every run checked before any runs;
//! - `run_local`: the runs spread over the cores with one progress bar;
//! - `emit`: one shell line per run instead, for a scheduler;
//! - `collect`: the table, charts and `sweep.md` from the run folders;
//! - `runner`, `record`, `report`: shared with the papers' studies.
//!
//! Layout of DIR: `sweep-plan.json`, `runs/ID/…`, `sweep.csv`, `sweep.md`,
//! `sweep-front.{png,svg}`, `sweep-convergence.{png,svg}`, `sweep-stability.{png,svg}`.

pub mod collect;
pub mod document;
pub mod entry;
pub mod number;
pub mod plan;
pub mod record;
pub mod reference;
pub mod report;
pub mod runner;

pub use document::Written;
pub use plan::{Axis, Plan};

use crate::error::{Error, Result, SceneError};
use crate::scene::{Override, Scene};
use crate::simulation::BackendChoice;
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

/// How a local sweep runs.
#[derive(Debug, Clone, Default)]
pub struct SweepOptions {
    /// Runs at once (each gets cores / jobs threads).
    pub jobs: usize,
    /// One progress bar over the runs on stderr.
    pub progress: bool,
    /// A line on stderr as each run ends (for logs, when stderr is not a terminal).
    pub progress_lines: bool,
    /// Raised by a signal: running runs stop (interrupted, resumable) and no new one starts.
    pub stop: Option<Arc<AtomicBool>>,
    /// The figure the charts use (`--metric`); default the first error reported.
    pub metric: Option<String>,
    /// Memory the runs running at once may take together (`--max-memory`,
    /// bytes). Default: the memory available (MemAvailable) at the start.
    pub max_memory: Option<u64>,
}

fn mib(bytes: u64) -> f64 {
    bytes as f64 / 1048576.0
}

/// How many runs may run at once: at most `jobs`, and no more than the
/// largest of them fit together in `budget` bytes (the `k` largest
/// estimates summed), at least one. A run that alone exceeds the budget
/// is refused by its own preflight.
pub fn concurrent_runs(estimates: &[u64], budget: Option<u64>, jobs: usize) -> usize {
    let jobs = jobs.max(1).min(estimates.len().max(1));
    let Some(budget) = budget else {
        return jobs;
    };
    let mut largest = estimates.to_vec();
    largest.sort_unstable_by(|a, b| b.cmp(a));
    let mut total = 0u64;
    let mut k = 0;
    for e in largest.iter().take(jobs) {
        total = total.saturating_add(*e);
        if total > budget {
            break;
        }
        k += 1;
    }
    k.max(1)
}

/// Takes `dir` for a sweep: creates it, or accepts one that is empty or
/// holds a sweep (its plan file); refuses anything else (exit 2).
pub fn prepare(dir: &Path) -> Result<()> {
    if dir.is_file() {
        return Err(Error::Folder(format!(
            "{} is a file, not a folder",
            dir.display()
        )));
    }
    if dir.is_dir() {
        let mut entries = std::fs::read_dir(dir).map_err(|e| Error::io("cannot read", dir, e))?;
        if entries.next().is_some() && !dir.join(plan::PLAN_FILE).is_file() {
            return Err(Error::Folder(format!(
                "{} is not empty and holds no {}: give a new or empty folder (--out)",
                dir.display(),
                plan::PLAN_FILE
            )));
        }
    }
    std::fs::create_dir_all(dir.join("runs")).map_err(|e| Error::io("cannot create", dir, e))
}

/// Checks `--metric` against the figures the plan's runs will report,
/// before any run: the exact solution's (scored once on the first run's
/// initial state) or, without one, the reference figures.
pub fn check_metric(plan: &Plan, metric: &str) -> Result<()> {
    let first = plan.runs.first().expect("a plan has at least one run");
    let overrides = plan
        .sets_of(first)
        .iter()
        .map(|s| Override::parse(s))
        .collect::<std::result::Result<Vec<_>, _>>()?;
    let scene = Scene::load(&plan.scene, &overrides)?;
    let known: Vec<String> = match scene.file.exact {
        Some(kind) => {
            let model = crate::model::Model::new(&scene)?;
            let e = crate::exact::score(kind, &scene, &model, &model.particles, 0.0, &[]);
            let json = serde_json::to_string(&e).expect("errors serialise");
            let summary = format!(r#"{{"status":"completed","errors":{json}}}"#);
            record::Record::from_summary("", vec![], &summary)
                .map(|r| r.errors.into_iter().map(|(k, _)| k).collect())
                .unwrap_or_default()
        }
        None => reference::figure_names(),
    };
    if known.iter().any(|k| k == metric) {
        Ok(())
    } else {
        Err(Error::Scene(SceneError::Sweep {
            arg: format!("--metric {metric}"),
            message: format!(
                "the runs do not report it; they report {}",
                known.join(", ")
            ),
        }))
    }
}

/// Runs every run of `plan` into `dir/runs/ID` (as `lme-mpm run` would),
/// then writes the table and charts. A run that fails is a row with its
/// reason; only a folder that cannot be used ends the sweep.
pub fn run_local(plan: &Plan, dir: &Path, opts: &SweepOptions) -> Result<Written> {
    // A run that alone exceeds --max-memory: refused before anything is written.
    if let (Some(b), Some(big)) = (
        opts.max_memory,
        plan.runs.iter().max_by_key(|r| r.memory_bytes),
    ) {
        if big.memory_bytes > b {
            return Err(Error::Scene(SceneError::Sweep {
                arg: format!("run {} and --max-memory {b}", big.id),
                message: format!(
                    "the run alone needs about {:.1} MiB, more than --max-memory",
                    mib(big.memory_bytes)
                ),
            }));
        }
    }
    prepare(dir)?;
    plan.write(dir)?;
    let choice = plan.backend_choice();
    // GPU runs share one adapter: one at a time. `auto` runs on the GPU
    // only where a hardware adapter exists.
    let on_gpu = match choice {
        BackendChoice::Cpu => false,
        BackendChoice::Gpu => true,
        BackendChoice::Auto => crate::gpu::context::adapters()
            .iter()
            .any(|a| !a.is_software()),
    };
    // Runs at once: what --jobs asks, as far as the memory allows.
    let estimates: Vec<u64> = plan.runs.iter().map(|r| r.memory_bytes).collect();
    let budget = opts.max_memory.or_else(crate::preflight::memory_available);
    let jobs = if on_gpu { 1 } else { opts.jobs.max(1) };
    let at_once = concurrent_runs(&estimates, budget, jobs);
    if at_once < jobs.min(plan.runs.len()) {
        crate::say!(
            "sweep: running {at_once} at once, not {jobs}: the {} largest runs need about {:.1} \
             MiB together, more than the {:.1} MiB {}",
            at_once + 1,
            {
                let mut e = estimates.clone();
                e.sort_unstable_by(|a, b| b.cmp(a));
                mib(e.iter().take(at_once + 1).sum::<u64>())
            },
            mib(budget.unwrap_or(0)),
            if opts.max_memory.is_some() {
                "of --max-memory"
            } else {
                "available (MemAvailable; --max-memory sets it)"
            }
        );
    }
    for r in &plan.runs {
        entry::Entry::of(plan, r).write(&dir.join("runs").join(&r.id))?;
    }
    let bar = runner::progress_bar(plan.runs.len(), opts.progress);
    let opts_lines = opts.progress_lines;
    let split = runner::Split::new(at_once, plan.runs.len());
    let done = std::sync::atomic::AtomicUsize::new(0);
    let outcomes = runner::run_parallel(
        &plan.runs,
        split,
        &bar,
        |r| r.id.clone(),
        |_| on_gpu,
        opts.stop.as_deref(),
        |r, _threads| -> std::result::Result<(), String> {
            let overrides = plan
                .sets_of(r)
                .iter()
                .map(|s| Override::parse(s))
                .collect::<std::result::Result<Vec<_>, _>>()
                .map_err(|e| e.to_string())?;
            let scene = Scene::load(&plan.scene, &overrides).map_err(|e| e.to_string())?;
            let opts = crate::run::RunOptions {
                backend: choice,
                adapter: None,
                out: dir.join("runs").join(&r.id),
                progress: false,
                progress_lines: false,
                verbose: false,
                limits: crate::preflight::Limits {
                    max_memory: opts.max_memory,
                    ..Default::default()
                },
                stop: opts.stop.clone(),
            };
            let result = crate::run::run(&scene, &opts);
            if opts_lines {
                let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                let how = match &result {
                    Ok(o) => match &o.summary.reason {
                        Some(why) => format!("{}: {why}", o.summary.status),
                        None => o.summary.status.to_string(),
                    },
                    Err(e) => format!("failed: {e}"),
                };
                crate::say!("sweep: {k}/{} runs done; {} {how}", plan.runs.len(), r.id);
            }
            result.map(|_| ()).map_err(|e| e.to_string())
        },
        |_, msg| Err(format!("the run panicked: {msg}")),
    );
    bar.finish_and_clear();
    let known: BTreeMap<String, String> = plan
        .runs
        .iter()
        .zip(outcomes)
        .filter_map(|(r, o)| match o {
            Some(Err(e)) => Some((r.id.clone(), e)),
            _ => None,
        })
        .collect();
    let records = collect::records(plan, dir, &known);
    document::write(plan, dir, records, opts.metric.clone())
}

/// Writes `file`: one self-contained shell line per run of `plan`, whose
/// output goes to `dir/runs/ID`; and `dir/sweep-plan.json`, which
/// `collect` reads. Runs nothing. Returns the number of lines.
/// A folder that holds another plan is refused (exit 2): its runs would
/// be tabled as this plan's. The same plan again is fine.
pub fn emit(plan: &Plan, dir: &Path, file: &Path, exe: &str) -> Result<usize> {
    prepare(dir)?;
    let dir = dir
        .canonicalize()
        .map_err(|e| Error::io("cannot resolve", dir, e))?;
    if dir.join(plan::PLAN_FILE).is_file() {
        let same = Plan::read(&dir).is_ok_and(|old| old.same_runs(plan));
        if !same {
            return Err(Error::Folder(format!(
                "{} holds another sweep's plan ({}): its run folders would be collected as \
                 this sweep's; give a new --out, or remove the folder first",
                dir.display(),
                plan::PLAN_FILE
            )));
        }
    }
    plan.write(&dir)?;
    for r in &plan.runs {
        entry::Entry::of(plan, r).write(&dir.join("runs").join(&r.id))?;
    }
    let lines = plan.shell_lines(exe, &dir);
    let mut text = lines.join("\n");
    text.push('\n');
    crate::output::write_atomic(file, text.as_bytes())?;
    Ok(lines.len())
}

/// Builds `sweep.csv`, the charts and `sweep.md` of the sweep in `dir`
/// from its run folders (missing, killed and failed runs listed as such).
pub fn collect(dir: &Path, metric: Option<String>) -> Result<Written> {
    let plan = Plan::read(dir)?;
    let records = collect::records(&plan, dir, &BTreeMap::new());
    if let Some(m) = &metric {
        let names = report::figure_names(&records);
        if !names.contains(m) {
            return Err(Error::Scene(SceneError::Sweep {
                arg: format!("--metric {m}"),
                message: if names.is_empty() {
                    "no run of this sweep reports an error figure".into()
                } else {
                    format!(
                        "the runs do not report it; they report {}",
                        names.join(", ")
                    )
                },
            }));
        }
    }
    document::write(&plan, dir, records, metric)
}
