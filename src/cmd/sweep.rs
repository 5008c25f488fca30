//! `lme-mpm sweep`: its arguments and handler (plan, run locally, emit
//! jobs, collect), over `lme_mpm::sweep`.

use super::common::{Signals, fail};
use lme_mpm::Error;
use lme_mpm::run::BackendChoice;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::Ordering;

#[derive(clap::Args)]
pub struct SweepArgs {
    /// Scene file (TOML), e.g. cases/dyka_bar.toml. Not with --collect.
    #[arg(required_unless_present = "collect")]
    scene: Option<PathBuf>,
    /// A key and its values, e.g. --vary grid.h=0.01,0.005,0.0025 --vary
    /// solver.shape=linear,lme (repeatable; any key --set accepts; commas
    /// inside [..] belong to a value). Every combination is one run.
    #[arg(
        long = "vary",
        value_name = "KEY=V1,V2,...",
        required_unless_present = "collect"
    )]
    vary: Vec<String>,
    /// Override a scene key in every run (repeatable), as in `run`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// The varied key that sets the resolution (smaller is finer): the x of
    /// the convergence chart, and without an exact solution the finest
    /// run of each series is its reference. Default: grid.h, solver.dt or
    /// solver.cfl, the first of them varied.
    #[arg(long, value_name = "KEY")]
    resolution: Option<String>,
    /// The error figure the charts use, e.g. rms_velocity_relative.
    /// Default: the first error the runs' summary.json reports (without
    /// an exact solution: ref_probe_u_rms, against the finest run).
    #[arg(long, value_name = "NAME")]
    metric: Option<String>,
    /// Where each run runs: auto = a hardware GPU when wgpu finds one, else the
    /// CPU path (a software adapter counts as none; --backend gpu uses it).
    #[arg(long, value_enum, default_value_t = BackendChoice::Auto)]
    backend: BackendChoice,
    /// Runs at once (default: one per core; each run gets cores / jobs threads),
    /// fewer when their estimated memory together exceeds --max-memory.
    #[arg(long)]
    jobs: Option<usize>,
    /// Memory the runs running at once may take together (bytes, or with
    /// K/M/G/T); a run needing more alone is refused. Default: the memory
    /// available at the start (MemAvailable).
    #[arg(long, value_name = "SIZE", value_parser = lme_mpm::preflight::parse_size)]
    max_memory: Option<u64>,
    /// Sweep folder. Default: out/sweep/<scene name>.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Write one self-contained shell line per run to FILE (and the plan
    /// to <out>/sweep-plan.json) and run nothing.
    #[arg(long, value_name = "FILE")]
    emit_jobs: Option<PathBuf>,
    /// The command the emitted lines start with. Default: this executable's absolute path.
    #[arg(long, value_name = "CMD", requires = "emit_jobs")]
    exe: Option<String>,
    /// Build sweep.csv, the charts and sweep.md of the sweep in DIR from
    /// its finished run folders (missing or interrupted runs listed as such).
    #[arg(long, value_name = "DIR", conflicts_with_all = ["scene", "vary", "set", "resolution", "emit_jobs", "jobs", "max_memory", "out"])]
    collect: Option<PathBuf>,
    /// No progress bar and no closing lines.
    #[arg(long, short)]
    quiet: bool,
}

/// `lme-mpm sweep`: plan (every run checked first), then run, emit or collect.
pub fn sweep(a: SweepArgs) -> ExitCode {
    use lme_mpm::sweep::{self, Axis, Plan, SweepOptions};
    let closing = |w: &sweep::Written, dir: &std::path::Path| {
        if a.quiet {
            return;
        }
        let count = |o: lme_mpm::sweep::record::Outcome| {
            w.records.iter().filter(|r| r.outcome == o).count()
        };
        use lme_mpm::sweep::record::Outcome as O;
        eprintln!(
            "sweep: {} runs: {} completed, {} unstable, {} failed, {} interrupted, {} running or killed, {} missing",
            w.records.len(),
            count(O::Completed),
            count(O::Unstable),
            count(O::Failed),
            count(O::Interrupted),
            count(O::Running),
            count(O::Missing)
        );
        if let Some(m) = &w.metric {
            eprintln!("charted figure: {m}");
        }
        eprintln!(
            "results: {} (table and charts), {}",
            dir.join("sweep.md").display(),
            dir.join("sweep.csv").display()
        );
    };
    if let Some(dir) = &a.collect {
        return match sweep::collect(dir, a.metric.clone()) {
            Ok(w) => {
                closing(&w, dir);
                ExitCode::SUCCESS
            }
            Err(e) => fail(&e),
        };
    }
    let scene = a
        .scene
        .as_ref()
        .expect("clap requires SCENE without --collect");
    let axes = match a
        .vary
        .iter()
        .map(|v| Axis::parse(v))
        .collect::<Result<Vec<_>, _>>()
    {
        Ok(x) => x,
        Err(e) => return fail(&Error::Scene(e)),
    };
    let plan = match Plan::new(scene, &a.set, axes, a.resolution.clone(), a.backend) {
        Ok(p) => p,
        Err(e) => return fail(&Error::Scene(e)),
    };
    if let Some(m) = &a.metric {
        if let Err(e) = sweep::check_metric(&plan, m) {
            return fail(&e);
        }
    }
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out/sweep").join(&plan.scene_name));
    if let Some(file) = &a.emit_jobs {
        let exe = match &a.exe {
            Some(e) => e.clone(),
            None => match std::env::current_exe() {
                Ok(p) => p.display().to_string(),
                Err(e) => {
                    eprintln!("error: cannot find this executable's path ({e}): give --exe");
                    return ExitCode::from(1);
                }
            },
        };
        return match sweep::emit(&plan, &out, file, &exe) {
            Ok(n) => {
                if !a.quiet {
                    eprintln!(
                        "wrote {n} run lines to {}; run them anywhere that sees {} (e.g. `parallel < {}`), then `lme-mpm sweep --collect {}`",
                        file.display(),
                        out.display(),
                        file.display(),
                        out.display()
                    );
                }
                ExitCode::SUCCESS
            }
            Err(e) => fail(&e),
        };
    }
    let Some(signals) = Signals::install_or_say() else {
        return ExitCode::from(1);
    };
    let jobs = a
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    if !a.quiet {
        eprintln!(
            "sweep: {} runs of {} on {}, up to {jobs} at once; outputs in {}",
            plan.runs.len(),
            plan.scene_name,
            plan.backend,
            out.display()
        );
    }
    let opts = SweepOptions {
        jobs,
        progress: !a.quiet && std::io::stderr().is_terminal(),
        progress_lines: !a.quiet && !std::io::stderr().is_terminal(),
        stop: Some(Arc::clone(&signals.stop)),
        metric: a.metric.clone(),
        max_memory: a.max_memory,
    };
    match sweep::run_local(&plan, &out, &opts) {
        Ok(w) => {
            closing(&w, &out);
            if signals.stop.load(Ordering::Relaxed) {
                signals.exit_code()
            } else {
                ExitCode::SUCCESS
            }
        }
        Err(e) => fail(&e),
    }
}
