//! The `lme-mpm` command line: run, resume, check, info, study, sweep, bench.
//! Exit codes: 0 completed, 2 invalid input (or a folder or checkpoint
//! that cannot be used), 3 unstable run, 129/130/143 interrupted by
//! SIGHUP/SIGINT/SIGTERM, 1 anything else.

mod cmd;

use clap::{Parser, Subcommand};
use cmd::bench::{BenchArgs, bench};
use cmd::common::{Signals, adapter_without_gpu, fail, load, write_stdout};
use cmd::sweep::{SweepArgs, sweep};
use lme_mpm::Error;
use lme_mpm::run::{self, BackendChoice, RunOptions};
use lme_mpm::scene::Override;
use lme_mpm::solver::RunStatus;
use lme_mpm::study::{StudyBackend, StudyName, StudyOptions};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;

#[derive(Parser)]
#[command(name = "lme-mpm", version, about = "2D Material Point Method: LME, uGIMP, linear and B-spline (optionally MLS) shape functions, FE/NPC/MUSL time integration and an implicit Newton step (CPU; also on a GMM node cloud), elastic, Neo-Hookean, Mohr-Coulomb/Drucker-Prager and modified Cam-clay materials, walls, contact between bodies and loads, on the CPU (f64) and the GPU (wgpu)", long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene and write its outputs (summary.json, probes.csv, particles.csv, VTK).
    ///
    /// The output folder belongs to the run: the files an earlier run wrote
    /// there are removed first (only those: lme-mpm.manifest lists them), a
    /// second run into a folder in use is refused (lme-mpm.lock), and a
    /// non-empty folder that is not an lme-mpm output folder is refused.
    /// SIGINT/SIGTERM/SIGHUP stop the run at the next step boundary with every
    /// output written and a checkpoint (exit 130/143/129); `resume` continues it.
    Run {
        /// Scene file (TOML), e.g. cases/dyka_bar.toml.
        scene: PathBuf,
        /// Where to run: auto = a hardware GPU when wgpu finds one, else the CPU
        /// path (a software adapter such as llvmpipe is slower than the CPU
        /// path and counts as none; --backend gpu uses it).
        #[arg(long, value_enum, default_value_t = BackendChoice::Auto)]
        backend: BackendChoice,
        /// GPU adapter to use: a case-insensitive part of its name (see `lme-mpm info`).
        /// An error with --backend cpu.
        #[arg(long)]
        adapter: Option<String>,
        /// Output folder. Default: out/<scene name>.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a scene key, e.g. --set solver.shape=ugimp --set grid.h=0.0005 (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// No progress (bar on a terminal, else a line every 10 %) and no result line
        /// (warnings and errors still print).
        #[arg(long, short)]
        quiet: bool,
        #[command(flatten)]
        limits: LimitArgs,
    },
    /// Continue the run in DIR from its checkpoint (checkpoint.lmeck: written
    /// when a run is interrupted, every output.checkpoint_interval, and at
    /// the end of a completed run: extend it with --set solver.t_end=LATER),
    /// into the same folder: the CSV files keep their rows up to the checkpoint.
    Resume {
        /// The run's output folder.
        dir: PathBuf,
        /// Where to run: auto = a hardware GPU when wgpu finds one, else the CPU
        /// path (a software adapter such as llvmpipe is slower than the CPU
        /// path and counts as none; --backend gpu uses it).
        #[arg(long, value_enum, default_value_t = BackendChoice::Auto)]
        backend: BackendChoice,
        /// GPU adapter to use: a case-insensitive part of its name.
        #[arg(long)]
        adapter: Option<String>,
        /// Change a key: solver.t_end (to run further), output.checkpoint_interval,
        /// output.vtk_interval, output.vtk_final, output.particles_csv,
        /// output.final_checkpoint (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// No progress and no result line.
        #[arg(long, short)]
        quiet: bool,
        #[command(flatten)]
        limits: LimitArgs,
    },
    /// Check a scene without running it: estimates particles, nodes, steps,
    /// memory and time from the shapes (refusing what `run` would refuse),
    /// then builds the model and prints what will run.
    Check {
        /// Scene file (TOML), e.g. cases/elastic_block.toml.
        scene: PathBuf,
        /// Override a scene key as `run` would, e.g. --set grid.h=0.0005 (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        #[command(flatten)]
        limits: LimitArgs,
    },
    /// List GPU adapters: backend, device type, float-atomic support, key limits.
    Info,
    /// Run one of the papers' comparisons (or all): CSV tables and charts in
    /// --out; with --doc FILE (e.g. docs/verification.md) also the study's section there.
    Study {
        /// Which study (one of the values below), or all.
        #[arg(value_enum)]
        name: StudyName,
        /// auto = the CPU path, plus the GPU when a hardware adapter exists.
        #[arg(long, value_enum, default_value_t = StudyBackend::Auto)]
        backend: StudyBackend,
        /// Output folder; each study writes into <out>/<study>/.
        #[arg(long, default_value = "out/study")]
        out: PathBuf,
        /// A reduced sweep that runs in a few minutes (does not touch the docs).
        #[arg(long)]
        quick: bool,
        /// Runs at once (default: one per core).
        #[arg(long)]
        jobs: Option<usize>,
        /// Also regenerate the study's section of this markdown file (e.g.
        /// docs/verification.md) and copy its charts to charts/ beside it.
        /// Without it, a study writes only into --out. Ignored with --quick.
        #[arg(long)]
        doc: Option<PathBuf>,
        /// With --doc: write into the doc's section NAME (between
        /// `<!-- BEGIN NAME -->` and `<!-- END NAME -->`) instead of
        /// study-<study>, and its charts as NAME-*.png, so that a restricted
        /// run (e.g. LME_MPM_MMS_CELLS=64) sits beside the full one.
        #[arg(long, requires = "doc")]
        section: Option<String>,
    },
    /// Run a scene over every combination of values of any of its keys, in
    /// parallel, and chart speed against accuracy: sweep.csv, sweep.md and
    /// charts (error against wall time with the Pareto front, error against
    /// cell size with fitted orders, stability grid) in --out. Each run is
    /// an ordinary run folder in <out>/runs/<id>. With --emit-jobs, write
    /// one `lme-mpm run` shell line per run for a scheduler instead (Slurm,
    /// GNU parallel), then build the results with --collect <out>.
    /// See docs/sweeps.md.
    Sweep(SweepArgs),
    /// Measure particle-steps per second of whole steps on a synthetic scene,
    /// on the CPU path, the GPU, or both (with the GPU/CPU ratio).
    Bench(BenchArgs),
    /// Turn a run's VTK snapshots into pictures: one PNG per snapshot and an
    /// animated GIF (and an MP4 when ffmpeg is on the PATH), the particles
    /// drawn as their domains coloured by FIELD on one scale for the whole
    /// run, with a colour bar, the time, walls and prescribed-velocity
    /// regions, on one frame that holds every snapshot. The run needs
    /// snapshots: output.vtk_interval (e.g. --set output.vtk_interval=0.04).
    Render(RenderArgs),
}

/// `lme-mpm render`'s arguments.
#[derive(clap::Args, Debug)]
struct RenderArgs {
    /// The run's output folder (holding particles.pvd and vtk/).
    dir: PathBuf,
    /// What colours the particles: speed (m/s), stress (von Mises, Pa),
    /// pressure (Pa, positive in compression), a material's state column
    /// (as its particles.csv column: eps_p, eps_pv for Mohr-Coulomb and
    /// Drucker-Prager; p_c, v for modified Cam-clay), displacement (m, from
    /// the start).
    #[arg(long, value_enum, default_value_t = lme_mpm::output::render::Field::Speed)]
    field: lme_mpm::output::render::Field,
    /// Frames per second of the animation, 0.1 to 50 (a GIF's delays are
    /// whole hundredths of a second, 2 to 1000).
    #[arg(long, default_value_t = 10.0, value_parser = lme_mpm::output::render::parse_fps)]
    fps: f64,
    /// Image width in pixels, 320 to 4096 (the height follows the frame's
    /// shape, at most about 1.3 times the width). Before drawing the rest,
    /// render says what the frames will take on disk and in time, from the
    /// first.
    #[arg(long, default_value_t = 800, value_parser = lme_mpm::output::render::parse_width)]
    width: u32,
    /// Draw every N-th snapshot (the last one always), N at least 1.
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = lme_mpm::output::render::parse_every)]
    every: usize,
    /// Output folder. Default: DIR/render.
    #[arg(long)]
    out: Option<PathBuf>,
}

/// Preflight limits of `run` and `check` (see docs/outputs.md).
#[derive(clap::Args, Debug, Clone)]
struct LimitArgs {
    /// Refuse a run whose estimated peak memory exceeds SIZE (bytes, or with
    /// K/M/G/T, e.g. 2G). Default: the memory available now (MemAvailable).
    #[arg(long, value_name = "SIZE", value_parser = lme_mpm::preflight::parse_size)]
    max_memory: Option<u64>,
    /// Refuse a run of more than N estimated steps (t_end / first time step).
    #[arg(long, value_name = "N", default_value_t = lme_mpm::preflight::DEFAULT_MAX_STEPS)]
    max_steps: u64,
    /// Refuse a run estimated to take more than H hours at a conservative
    /// speed of the CPU path. Default: no limit (runs over 1 h only warn).
    #[arg(long, value_name = "H", value_parser = lme_mpm::preflight::parse_hours)]
    max_hours: Option<f64>,
    /// Allow more than 1000 VTK snapshots (output.vtk_interval).
    #[arg(long)]
    allow_many_snapshots: bool,
}

impl LimitArgs {
    fn limits(&self) -> lme_mpm::preflight::Limits {
        lme_mpm::preflight::Limits {
            max_memory: self.max_memory,
            max_steps: self.max_steps,
            max_hours: self.max_hours,
            allow_many_snapshots: self.allow_many_snapshots,
        }
    }
}

fn main() -> ExitCode {
    // Mesa's Vulkan device-select layer prints a harmless XDG_RUNTIME_DIR
    // warning on headless machines; this is its documented switch. Set
    // before any thread starts.
    if std::env::var_os("NODEVICE_SELECT").is_none() {
        // SAFETY: single-threaded here, nothing reads the environment concurrently.
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    }
    let cli = Cli::parse();
    match cli.command {
        Command::Run {
            scene,
            backend,
            adapter,
            out,
            set,
            quiet,
            limits,
        } => {
            if let Some(code) = adapter_without_gpu(&adapter, backend == BackendChoice::Cpu) {
                return code;
            }
            let scene = match load(&scene, &set) {
                Ok(s) => s,
                Err(e) => return fail(&Error::Scene(e)),
            };
            let out = out.unwrap_or_else(|| PathBuf::from("out").join(&scene.name));
            let Some(signals) = Signals::install_or_say() else {
                return ExitCode::from(1);
            };
            let mut opts = run_options(backend, adapter, out, quiet, &signals);
            opts.limits = limits.limits();
            report(run::run(&scene, &opts), &opts, quiet, &signals)
        }
        Command::Resume {
            dir,
            backend,
            adapter,
            set,
            quiet,
            limits,
        } => {
            let overrides = match set
                .iter()
                .map(|s| Override::parse(s))
                .collect::<Result<Vec<_>, _>>()
            {
                Ok(o) => o,
                Err(e) => return fail(&Error::Scene(e)),
            };
            let Some(signals) = Signals::install_or_say() else {
                return ExitCode::from(1);
            };
            let mut opts = run_options(backend, adapter, dir.clone(), quiet, &signals);
            opts.limits = limits.limits();
            report(run::resume(&dir, &overrides, &opts), &opts, quiet, &signals)
        }
        Command::Info => info(),
        Command::Study {
            name,
            backend,
            out,
            quick,
            jobs,
            doc,
            section,
        } => {
            let opts = StudyOptions {
                backend,
                out,
                quick,
                jobs: jobs
                    .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
                doc: doc.clone(),
                section: section.clone(),
                progress: std::io::stderr().is_terminal(),
                progress_lines: !std::io::stderr().is_terminal(),
            };
            match lme_mpm::study::run(name, &opts) {
                Ok(reports) => {
                    for r in &reports {
                        let failed = r.results.iter().filter(|j| !j.completed()).count();
                        eprintln!(
                            "study {}: {} runs, {} did not complete; outputs in {}",
                            r.study.slug(),
                            r.results.len(),
                            failed,
                            opts.out.join(r.study.slug()).display()
                        );
                    }
                    match (&doc, quick) {
                        (Some(d), false) => eprintln!(
                            "docs: regenerated the study sections of {} and copied the charts to {}",
                            d.display(),
                            d.parent()
                                .unwrap_or(std::path::Path::new("."))
                                .join("charts")
                                .display()
                        ),
                        (Some(_), true) => eprintln!("docs: untouched (--quick never writes them)"),
                        (None, _) => eprintln!("docs: untouched (--doc FILE regenerates them)"),
                    }
                    ExitCode::SUCCESS
                }
                Err(e) => fail(&e),
            }
        }
        Command::Sweep(args) => sweep(args),
        Command::Bench(args) => bench(&args),
        Command::Render(a) => {
            lme_mpm::output::render::command(&a.dir, a.field, a.fps, a.width, a.every, a.out)
        }
        Command::Check { scene, set, limits } => {
            let scene = match load(&scene, &set) {
                Ok(s) => s,
                Err(e) => return fail(&Error::Scene(e)),
            };
            // The estimate first, from the shapes alone: a scene too large
            // to build is refused here, before seeding.
            let plan = match lme_mpm::preflight::plan(
                &scene,
                &limits.limits(),
                rayon::current_num_threads(),
            ) {
                Ok(p) => p,
                Err(e) => return fail(&Error::Scene(e)),
            };
            for w in &plan.warnings {
                lme_mpm::say!("warning: {w}");
            }
            for c in &plan.scene.chosen {
                lme_mpm::say!("note: {c}");
            }
            match lme_mpm::model::Model::new(&plan.scene) {
                Ok(model) => {
                    let text = lme_mpm::run::describe(&plan.scene, &model)
                        + &lme_mpm::preflight::describe(&plan.estimate);
                    write_stdout(&text)
                }
                Err(e) => fail(&Error::Scene(e)),
            }
        }
    }
}

fn run_options(
    backend: BackendChoice,
    adapter: Option<String>,
    out: PathBuf,
    quiet: bool,
    signals: &Signals,
) -> RunOptions {
    let terminal = std::io::stderr().is_terminal();
    RunOptions {
        backend,
        adapter,
        out,
        progress: !quiet && terminal,
        progress_lines: !quiet && !terminal,
        verbose: !quiet,
        stop: Some(Arc::clone(&signals.stop)),
        limits: Default::default(),
    }
}

/// The result line of `run` and `resume`, and the exit code.
fn report(
    result: lme_mpm::Result<run::Outcome>,
    opts: &RunOptions,
    quiet: bool,
    signals: &Signals,
) -> ExitCode {
    let outcome = match result {
        Ok(o) => o,
        Err(e) => return fail(&e),
    };
    let s = &outcome.summary;
    if !quiet {
        lme_mpm::say!(
            "{}: t = {:.6e} s, {} steps, {} particles, {:.3e} particle-steps/s on {}",
            s.status,
            s.t,
            s.steps,
            s.particles,
            s.particle_steps_per_second,
            s.backend
        );
        if let Some(r) = &s.reason {
            lme_mpm::say!("reason: {r}");
        }
        if let Some(e) = &s.errors {
            lme_mpm::say!("errors: {}", serde_json::to_string(e).unwrap_or_default());
        }
        if let Some(words) = lme_mpm::output::result::text(s) {
            lme_mpm::say!("result: {words}");
        }
        lme_mpm::say!("outputs: {}", opts.out.display());
    }
    match outcome.status {
        RunStatus::Completed => ExitCode::SUCCESS,
        RunStatus::Unstable { .. } => ExitCode::from(3),
        RunStatus::Interrupted { .. } => signals.exit_code(),
    }
}

// The arguments of `lme-mpm sweep` (its help is the variant's doc comment).

fn info() -> ExitCode {
    let list = lme_mpm::gpu::context::adapters();
    if list.is_empty() {
        println!(
            "no GPU adapter: wgpu sees none (install a Vulkan driver; mesa-vulkan-drivers gives the llvmpipe software adapter)"
        );
        println!(
            "runs use the CPU path ({} threads)",
            rayon::current_num_threads()
        );
        return ExitCode::SUCCESS;
    }
    for a in &list {
        println!("{}", a.name);
        println!("  backend            {}", a.backend);
        println!(
            "  device type        {:?}{}",
            a.device_type,
            if a.is_software() {
                " (software: slower than the CPU path; --backend auto skips it)"
            } else {
                ""
            }
        );
        println!("  driver             {}", a.driver);
        println!(
            "  float atomics      {}",
            if a.float_atomics {
                "yes (atomic<f32> add)"
            } else {
                "no (compare-exchange loop)"
            }
        );
        println!(
            "  max binding size   {} MiB",
            a.max_storage_buffer_binding_size >> 20
        );
        println!("  max buffer size    {} MiB", a.max_buffer_size >> 20);
        println!(
            "  storage buffers    {} per stage",
            a.max_storage_buffers_per_shader_stage
        );
        println!(
            "  workgroups per dim {}",
            a.max_compute_workgroups_per_dimension
        );
    }
    ExitCode::SUCCESS
}
