//! `lme-mpm run`: build the model, pick a backend, drive it to t_end while
//! writing samples and snapshots, then score and summarise. Nothing is
//! written before the scene and model are known to be valid.

use crate::backend::{Backend, Sample, State};
use crate::cpu::CpuBackend;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::model::shape::Shape;
use crate::output::checkpoint::{self, Checkpoint};
use crate::output::folder::Folder;
use crate::output::state::StateLayout;
use crate::output::{self, csv, summary::Summary, vtk};
use crate::scene::{Override, Scene};
pub use crate::simulation::BackendChoice;
use crate::simulation::{BackendSpec, Simulation};
use crate::solver::{Cursor, Observer, RunStatus};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

#[derive(Debug, Clone)]
pub struct RunOptions {
    pub backend: BackendChoice,
    /// Case-insensitive substring of the GPU adapter's name (`--adapter`).
    pub adapter: Option<String>,
    pub out: PathBuf,
    /// Show a progress bar on a terminal (runs over a second).
    pub progress: bool,
    /// Print a progress line to stderr every 10 % of t_end (and at least
    /// once a minute): for logs, when stderr is not a terminal.
    pub progress_lines: bool,
    /// Print the backend choice and the result line to stderr.
    pub verbose: bool,
    /// What the preflight allows (memory, steps, hours, snapshots).
    pub limits: crate::preflight::Limits,
    /// Raised (by a signal handler) to stop at the next step boundary:
    /// the run then writes its outputs and a checkpoint and ends `interrupted`.
    pub stop: Option<Arc<AtomicBool>>,
}

/// How a run ended, with its summary (also written to summary.json).
#[derive(Debug, Clone)]
pub struct Outcome {
    pub status: RunStatus,
    pub summary: Summary,
}

/// `--set` keys `lme-mpm resume` accepts: the rest would change the run
/// being continued.
pub const RESUME_KEYS: &[&str] = &[
    "solver.t_end",
    "output.checkpoint_interval",
    "output.vtk_interval",
    "output.vtk_final",
    "output.particles_csv",
    "output.final_checkpoint",
];

/// Runs `scene` and writes its outputs to `opts.out`, which it takes for
/// itself (see `output::folder`): the files of an earlier run there go.
/// The preflight comes first: a scene that cannot fit or run in the limits
/// is refused before anything is allocated or written, and output
/// intervals below a step are clamped (with a warning on stderr).
pub fn run(scene: &Scene, opts: &RunOptions) -> Result<Outcome> {
    let start = Instant::now();
    let plan = preflight(scene, opts)?;
    let scene = &plan.scene;
    let mut sim = Simulation::new(scene, &spec(opts))?;
    let folder = Folder::create(&opts.out)?;
    let writer = Writer::start(folder, scene, sim.backend_ref().model(), opts)?;
    execute(&mut sim, writer, None, start, opts, &plan)
}

/// The preflight of `scene` under `opts.limits`, its warnings printed.
fn preflight(scene: &Scene, opts: &RunOptions) -> Result<crate::preflight::Plan> {
    let plan = crate::preflight::plan(scene, &opts.limits, rayon::current_num_threads())?;
    for w in &plan.warnings {
        crate::say!("warning: {w}");
    }
    if opts.verbose {
        for c in &plan.scene.chosen {
            crate::say!("note: {c}");
        }
    }
    Ok(plan)
}

/// Continues the run in `dir` from its checkpoint, into the same folder:
/// the CSV files keep their rows up to the checkpoint and go on from there.
/// `overrides` may only touch `RESUME_KEYS` (a later `solver.t_end`, say).
pub fn resume(dir: &Path, overrides: &[Override], opts: &RunOptions) -> Result<Outcome> {
    let start = Instant::now();
    for o in overrides {
        let key = o.path.join(".");
        if !RESUME_KEYS.contains(&key.as_str()) {
            return Err(Error::Scene(crate::SceneError::Override {
                arg: o.arg.clone(),
                message: format!(
                    "resume continues the run as it was; only {} can change",
                    RESUME_KEYS.join(", ")
                ),
            }));
        }
    }
    let mut folder = Folder::resume(dir)?;
    let ck_path = folder.path(checkpoint::FILE);
    if !ck_path.is_file() {
        return Err(Error::Checkpoint(format!(
            "{}: none in this folder (a run writes one when interrupted, every \
             output.checkpoint_interval, and at t_end unless output.final_checkpoint = false)",
            ck_path.display()
        )));
    }
    let ck = Checkpoint::read(&ck_path)?;
    same_run(&folder, &ck)?;
    let origin = ck_path.display().to_string();
    let scene = Scene::from_str(&ck.scene_toml, &origin, &ck.scene_name, overrides)?;
    if ck.t >= scene.solver().t_end {
        return Err(Error::Checkpoint(format!(
            "{origin} is at t = {} s, not before t_end = {} s: resume with --set solver.t_end=LATER",
            ck.t,
            scene.solver().t_end
        )));
    }
    // A later t_end goes through the preflight like a new run.
    let plan = preflight(&scene, opts)?;
    let mut sim = Simulation::new(&plan.scene, &spec(opts))?;
    // Every field's nodes: a scene with contact pairs has one grid per
    // field, and resume refused every such scene while it sized one.
    let model = sim.backend_ref().model();
    let state = State {
        newton: ck.newton.clone(),
        held_contacts: ck.held_contacts.clone(),
        cloud: ck.cloud.clone(),
        ..State::at_step_boundary(model, ck.particles.clone(), ck.t, ck.dt)
    };
    sim.backend().restore(&state, ck.steps)?;
    // What the run wrote after its checkpoint goes; the snapshots up to it stay.
    let keep: std::collections::BTreeSet<&str> = ck
        .snapshots
        .iter()
        .map(|(_, f)| f.as_str())
        .chain([checkpoint::FILE])
        .chain((!ck.snapshots.is_empty()).then_some("particles.pvd"))
        .collect();
    folder.retain(|f| keep.contains(f))?;
    let mut writer = Writer::start(folder, &plan.scene, sim.backend_ref().model(), opts)?;
    writer.samples = ck.samples.clone();
    writer.snapshots = ck.snapshots.clone();
    writer.resumed_from = Some(ck.t);
    writer.set_last_words();
    writer.flush()?;
    writer.write_pvd()?;
    execute(&mut sim, writer, Some(ck.cursor), start, opts, &plan)
}

/// Refuses a checkpoint that is not of the run the folder holds (one copied
/// in from another run's folder), naming both: its scene name must be the
/// name summary.json gives, and its scene the folder's scene.resolved.toml
/// but for the keys a resume may change. A folder with neither file (an
/// older layout) is taken on the checkpoint's word.
fn same_run(folder: &Folder, ck: &Checkpoint) -> Result<()> {
    let read = |name: &str| std::fs::read_to_string(folder.path(name)).ok();
    let mismatch = |what: String| {
        Err(Error::Checkpoint(format!(
            "{}: the checkpoint is of a run of scene '{}', and this folder holds another run \
             ({what}); resume the folder the checkpoint was written in, or start the scene \
             anew with `lme-mpm run`",
            folder.path(checkpoint::FILE).display(),
            ck.scene_name
        )))
    };
    if let Some(text) = read("summary.json") {
        let name = serde_json::from_str::<serde_json::Value>(&text)
            .ok()
            .and_then(|v| v["scene"].as_str().map(str::to_string));
        if let Some(name) = name.filter(|n| *n != ck.scene_name) {
            return mismatch(format!("its summary.json names scene '{name}'"));
        }
    }
    let Some(text) = read("scene.resolved.toml") else {
        return Ok(());
    };
    let parse = |t: &str| t.parse::<toml::Table>().ok().map(toml::Value::Table);
    let (Some(here), Some(theirs)) = (parse(&text), parse(&ck.scene_toml)) else {
        return mismatch("its scene.resolved.toml does not parse".into());
    };
    let mut skip = RESUME_KEYS.to_vec();
    skip.push("output.sample_interval");
    match crate::scene::first_difference(&here, &theirs, &skip, ("the folder", "the checkpoint")) {
        Some(d) => mismatch(format!("scene.resolved.toml differs: {d}")),
        None => Ok(()),
    }
}

fn spec(opts: &RunOptions) -> BackendSpec {
    BackendSpec {
        choice: Some(opts.backend),
        adapter: opts.adapter.clone(),
        gpu: Default::default(),
        verbose: opts.verbose,
    }
}

/// Drives `sim` to its end with `writer`, then writes the final outputs
/// and summary.json. A failure on the way is written to summary.json too.
fn execute(
    sim: &mut Simulation,
    mut writer: Writer,
    cursor: Option<Cursor>,
    start: Instant,
    opts: &RunOptions,
    plan: &crate::preflight::Plan,
) -> Result<Outcome> {
    let result = finish(sim, &mut writer, cursor, start, opts, plan);
    if let Err(e) = &result {
        // Best effort: the folder must not claim a run that has ended.
        let _ = writer.status_summary("failed", Some(&e.to_string()));
    }
    result
}

fn finish(
    sim: &mut Simulation,
    writer: &mut Writer,
    cursor: Option<Cursor>,
    start: Instant,
    opts: &RunOptions,
    plan: &crate::preflight::Plan,
) -> Result<Outcome> {
    let scene = sim.scene.clone();
    let steps0 = sim.backend_ref().steps();
    let mut schedule = sim.schedule();
    schedule.stop = opts.stop.clone();
    schedule.final_checkpoint = scene.file.output.final_checkpoint;
    let t_drive = Instant::now();
    let t0 = sim.backend_ref().time();
    writer.started = Some((t_drive, t0, steps0));
    // Stepping time is counted from here: the I/O of a resume's set-up (the
    // CSV files rewritten up to the checkpoint) came before it and is not
    // subtracted from it.
    writer.io_seconds = 0.0;
    if let Some((_, at)) = writer.lines {
        // A log says when stepping begins, after the set-up; the tenth it
        // begins in (a resume's, past 0) is said then and not again.
        writer.progress_line(t0, scene.solver().t_end, steps0);
        writer.lines = Some((tenth_of(t0, scene.solver().t_end), at));
    }
    let driven = sim.drive_from(schedule, writer, cursor);
    writer.finish_progress();
    // From here to summary.json no signal ends the process.
    let _saving = writer.folder.saving();
    let status = driven?;
    let wall = (t_drive.elapsed().as_secs_f64() - writer.io_seconds).max(1e-9);

    let errors = sim.score_with(&writer.samples)?;
    let backend = sim.backend();
    let t = backend.time();
    let steps = backend.steps();
    if matches!(status, RunStatus::Interrupted { .. })
        && writer.samples.last().is_none_or(|s| s.t < t)
    {
        // Every CSV ends at the time reached.
        let s = backend.sample()?;
        writer.samples.push(s);
    }
    let bytes_per_particle = backend.bytes_per_particle();
    let newton = backend
        .newton()
        .map(crate::output::summary::NewtonSummary::from_stats);
    let backend_name = backend.name();
    let final_sample = writer.samples.last().cloned();
    // The particles are read once (a GPU download) and used in place.
    backend.particles()?;
    let model = backend.model();
    let particles = &model.particles;
    if scene.file.output.particles_csv {
        writer.write(
            "particles.csv",
            csv::particles(&model.body_names, &StateLayout::of(model), particles).as_bytes(),
        )?;
    }
    let out = &scene.file.output;
    let vtk_on = out.vtk_final || out.vtk_interval.is_some();
    let final_snapshot = match status {
        RunStatus::Completed => out.vtk_final,
        RunStatus::Unstable { .. } => true,
        RunStatus::Interrupted { .. } => vtk_on,
    };
    let snap_done = writer.snapshots.last().is_some_and(|(ts, _)| *ts == t);
    if final_snapshot && !snap_done {
        writer.write_snapshot(particles, t)?;
    }
    writer.flush()?;

    let n = model.particles.len();
    let solver = scene.solver();
    let (reason, reason_code, unstable_particle) = match &status {
        RunStatus::Completed => (None, None, None),
        RunStatus::Unstable { fault, .. } => {
            (Some(fault.to_string()), Some(fault.code()), fault.particle)
        }
        RunStatus::Interrupted { .. } => (
            Some(format!(
                "stopped by a signal at a step boundary; `lme-mpm resume {}` continues it",
                writer.folder.dir().display()
            )),
            None,
            None,
        ),
    };
    let npc = matches!(model.integrator, crate::model::Integrator::Npc { .. });
    let summary = Summary {
        status: match status {
            RunStatus::Completed => "completed",
            RunStatus::Unstable { .. } => "unstable",
            RunStatus::Interrupted { .. } => "interrupted",
        },
        reason,
        reason_code,
        unstable_particle,
        scene: scene.name.clone(),
        t,
        t_end: model.t_end,
        resumed_from: writer.resumed_from,
        steps,
        particles: n,
        nodes: model.grid.n_nodes(),
        wall_seconds: wall,
        wall_seconds_total: start.elapsed().as_secs_f64(),
        particle_steps_per_second: n as f64 * (steps - steps0) as f64 / wall,
        backend: backend_name,
        bytes_per_particle,
        shape: solver.shape,
        lme_gamma: matches!(model.shape, Shape::Lme(_)).then_some(solver.lme_gamma),
        integrator: solver.integrator,
        npc_gamma: npc.then_some(solver.npc_gamma),
        npc_position: npc.then_some(solver.npc_position),
        cfl: solver.cfl,
        dt: solver.dt,
        mls: solver.mls,
        mls_scope: solver.mls.then_some(solver.mls_scope),
        bspline_knots: matches!(
            solver.shape,
            crate::scene::ShapeKind::Bspline2 | crate::scene::ShapeKind::Bspline3
        )
        .then(|| solver.bspline_knots.unwrap_or_default()),
        h: model.grid.h,
        perturb: model.grid.perturb,
        energy: final_sample
            .as_ref()
            .map(|s| BTreeMap::from([("kinetic", s.energy.kinetic), ("strain", s.energy.strain)]))
            .unwrap_or_default(),
        reactions: final_sample
            .as_ref()
            .map(|s| {
                model
                    .reaction_names()
                    .into_iter()
                    .zip(s.reactions.iter().copied())
                    .collect()
            })
            .unwrap_or_default(),
        exact: scene.file.exact,
        errors,
        scene_resolved: scene.file.clone(),
        version: env!("CARGO_PKG_VERSION"),
        memory_estimate_bytes: plan.estimate.memory_bytes.round() as u64,
        peak_rss_bytes: crate::preflight::peak_rss(),
        newton,
    };
    write_result_picture(writer, &scene, model, &summary)?;
    let json = serde_json::to_string_pretty(&summary).expect("summary serialises");
    writer.write("summary.json", json.as_bytes())?;
    Ok(Outcome { status, summary })
}

/// `result.png` (`output::result`): the run's result as a picture. A
/// picture that cannot be drawn is a warning, not a failed run.
fn write_result_picture(
    writer: &mut Writer,
    scene: &Scene,
    model: &Model,
    summary: &Summary,
) -> Result<()> {
    match output::result::picture(scene, model, &writer.samples, summary) {
        Ok(png) => writer.write(output::result::FILE, &png),
        Err(e) => {
            eprintln!("warning: {e}");
            Ok(())
        }
    }
}

/// Observer that keeps the samples, rewrites the CSV files now and then (so
/// a killed run leaves complete files), writes VTK snapshots and
/// checkpoints, and lists every file in the folder's manifest first.
struct Writer {
    folder: Folder,
    scene_name: String,
    /// The resolved scene with `output.sample_interval` explicit (checkpoints).
    scene_toml: String,
    probe_names: Vec<String>,
    group_names: Vec<String>,
    n_particles: usize,
    samples: Vec<Sample>,
    snapshots: Vec<(f64, String)>,
    last_flush: Instant,
    io_seconds: f64,
    progress: Option<(ProgressBar, Instant)>,
    /// Progress lines: the last tenth of t_end reported, and when.
    lines: Option<(u64, Instant)>,
    /// When driving started, with the time and steps then.
    started: Option<(Instant, f64, u64)>,
    resumed_from: Option<f64>,
    /// σzz of the VTK stress tensor and the materials' state columns, per body.
    state: StateLayout,
}

/// Rewrite the CSV files at most this often while running.
const FLUSH_EVERY: Duration = Duration::from_secs(5);
/// Runs shorter than this show no progress bar.
const PROGRESS_AFTER: Duration = Duration::from_secs(1);
/// A progress line at least this often, even between tenths.
const LINE_EVERY: Duration = Duration::from_secs(60);

impl Writer {
    /// Takes the folder for `scene`: writes a `running` summary.json and
    /// scene.resolved.toml, and makes `vtk/` when snapshots are on, so an
    /// unwritable folder fails before the first step.
    fn start(folder: Folder, scene: &Scene, model: &Model, opts: &RunOptions) -> Result<Writer> {
        let bar = opts.progress.then(|| {
            let bar = ProgressBar::with_draw_target(Some(1000), ProgressDrawTarget::hidden());
            bar.set_style(
                ProgressStyle::with_template(
                    "{elapsed_precise} [{bar:40}] {percent:>3}%  {msg}  eta {eta}",
                )
                .expect("valid template")
                .progress_chars("=> "),
            );
            (bar, Instant::now())
        });
        let mut file = scene.file.clone();
        file.output.sample_interval = Some(scene.sample_interval);
        let mut w = Writer {
            folder,
            scene_name: scene.name.clone(),
            scene_toml: toml::to_string(&file).expect("a scene file serialises to TOML"),
            probe_names: model.probes.iter().map(|p| p.name.clone()).collect(),
            group_names: model.reaction_names(),
            n_particles: model.particles.len(),
            samples: Vec::new(),
            snapshots: Vec::new(),
            last_flush: Instant::now(),
            io_seconds: 0.0,
            progress: bar,
            lines: opts.progress_lines.then(|| (0, Instant::now())),
            started: None,
            resumed_from: None,
            state: StateLayout::of(model),
        };
        let o = &scene.file.output;
        if o.vtk_final || o.vtk_interval.is_some() {
            let vdir = w.folder.path("vtk");
            std::fs::create_dir_all(&vdir)
                .map_err(|e| Error::io("cannot create snapshot folder", &vdir, e))?;
        }
        w.status_summary("running", None)?;
        w.set_last_words();
        let resolved = toml::to_string(&scene.file).expect("a scene file serialises to TOML");
        w.write("scene.resolved.toml", resolved.as_bytes())?;
        Ok(w)
    }

    /// Writes `rel` in the folder (atomically), listed in the manifest first.
    fn write(&mut self, rel: &str, bytes: &[u8]) -> Result<()> {
        self.folder.record(rel)?;
        output::write_atomic(&self.folder.path(rel), bytes)
    }

    /// A short summary.json while the run is not done (`running`) or after
    /// it failed (`failed`, with the error).
    fn status_summary(&mut self, status: &str, error: Option<&str>) -> Result<()> {
        let json = serde_json::json!({
            "status": status,
            "error": error,
            "scene": self.scene_name,
            "pid": std::process::id(),
            "resumed_from": self.resumed_from,
            "version": env!("CARGO_PKG_VERSION"),
        });
        let text = serde_json::to_string_pretty(&json).expect("json serialises");
        self.write("summary.json", text.as_bytes())
    }

    /// What summary.json says if a repeated signal ends the process in the
    /// middle of a step (`output::folder::abandon_all`).
    fn set_last_words(&self) {
        let json = serde_json::json!({
            "status": "interrupted",
            "error": null,
            "reason": "ended by a repeated signal in the middle of a step: the CSV files hold \
                       the rows of their last rewrite, and checkpoint.lmeck (when there is one) \
                       the state of the last periodic checkpoint, which `lme-mpm resume` continues",
            "scene": self.scene_name,
            "pid": std::process::id(),
            "resumed_from": self.resumed_from,
            "version": env!("CARGO_PKG_VERSION"),
        });
        let text = serde_json::to_string_pretty(&json).expect("json serialises");
        self.folder.set_last_words(text);
    }

    fn flush(&mut self) -> Result<()> {
        let t0 = Instant::now();
        let probes = csv::probes(&self.probe_names, &self.samples);
        self.write("probes.csv", probes.as_bytes())?;
        let energy = csv::energy(&self.samples);
        self.write("energy.csv", energy.as_bytes())?;
        let reactions = csv::reactions(&self.group_names, &self.samples);
        self.write("reactions.csv", reactions.as_bytes())?;
        self.last_flush = Instant::now();
        self.io_seconds += t0.elapsed().as_secs_f64();
        Ok(())
    }

    fn write_snapshot(&mut self, particles: &crate::model::Particles, t: f64) -> Result<()> {
        let t0 = Instant::now();
        let vdir = self.folder.path("vtk");
        std::fs::create_dir_all(&vdir).map_err(|e| Error::io("cannot create", &vdir, e))?;
        let name = format!("vtk/particles_{:05}.vtu", self.snapshots.len());
        self.write(&name, &vtk::particles_vtu(particles, &self.state, t))?;
        self.snapshots.push((t, name));
        self.write_pvd()?;
        self.io_seconds += t0.elapsed().as_secs_f64();
        Ok(())
    }

    fn write_pvd(&mut self) -> Result<()> {
        if self.snapshots.is_empty() {
            return Ok(());
        }
        let pvd = vtk::pvd(&self.snapshots);
        self.write("particles.pvd", pvd.as_bytes())
    }

    fn finish_progress(&mut self) {
        if let Some((bar, _)) = &self.progress {
            bar.finish_and_clear();
        }
    }

    /// One progress line on stderr: time reached, steps, speed, ETA.
    fn progress_line(&self, t: f64, t_end: f64, steps: u64) {
        let Some((t0, time0, steps0)) = self.started else {
            return;
        };
        // Stepping time only, outputs excluded, as summary.json counts it.
        let secs = (t0.elapsed().as_secs_f64() - self.io_seconds).max(1e-9);
        let rate = self.n_particles as f64 * steps.saturating_sub(steps0) as f64 / secs;
        let done = (t - time0) / (t_end - time0).max(f64::MIN_POSITIVE);
        let eta = if done > 0.0 {
            // Never "-0 s" once past the end.
            format!("{:.0} s", (secs * (1.0 - done) / done).max(0.0))
        } else {
            "unknown".to_string()
        };
        crate::say!(
            "progress: {:>3.0} %  t = {t:.4e} s of {t_end:.4e} s, {steps} steps, \
             {rate:.3e} particle-steps/s, eta {eta}",
            100.0 * t / t_end
        );
    }
}

impl Observer for Writer {
    fn sample(&mut self, sample: &Sample) -> Result<()> {
        self.samples.push(sample.clone());
        if self.last_flush.elapsed() > FLUSH_EVERY {
            self.flush()?;
        }
        Ok(())
    }

    fn snapshot(&mut self, backend: &mut dyn Backend) -> Result<()> {
        let t = backend.time();
        let p = backend.particles()?;
        self.write_snapshot(p, t)
    }

    fn checkpoint(&mut self, backend: &mut dyn Backend, cursor: &Cursor) -> Result<()> {
        let _saving = self.folder.saving();
        let t0 = Instant::now();
        let ck = Checkpoint {
            scene_name: self.scene_name.clone(),
            scene_toml: self.scene_toml.clone(),
            t: backend.time(),
            // The next step computes its own Δt; 0 says "not known".
            dt: 0.0,
            steps: backend.steps(),
            particles: backend.particles()?.clone(),
            cursor: *cursor,
            samples: self.samples.clone(),
            snapshots: self.snapshots.clone(),
            newton: backend.newton().cloned(),
            held_contacts: backend.held_contacts(),
            cloud: backend.cloud_state(),
        };
        self.write(checkpoint::FILE, &ck.encode())?;
        // The CSV files as of the checkpoint, so a kill leaves them consistent with it.
        self.flush()?;
        self.io_seconds += t0.elapsed().as_secs_f64();
        Ok(())
    }

    fn progress(&mut self, t: f64, t_end: f64, steps: u64) {
        if let Some((bar, started)) = &self.progress {
            if bar.is_hidden() && started.elapsed() > PROGRESS_AFTER {
                bar.set_draw_target(ProgressDrawTarget::stderr());
            }
            bar.set_position((t / t_end * 1000.0) as u64);
            if let Some(s) = self.samples.last() {
                bar.set_message(format!("t = {:.4e} s", s.t));
            }
        }
        if let Some((tenth, at)) = self.lines {
            let now = tenth_of(t, t_end);
            if now > tenth || at.elapsed() > LINE_EVERY {
                self.progress_line(t, t_end, steps);
                self.lines = Some((now.max(tenth), Instant::now()));
            }
        }
    }
}

/// The tenth of `t_end` that `t` has reached, 0 to 10.
fn tenth_of(t: f64, t_end: f64) -> u64 {
    ((t / t_end * 10.0).floor() as u64).min(10)
}

/// Text that `lme-mpm check` prints: what the scene will run.
pub fn describe(scene: &Scene, model: &Model) -> String {
    let mut dt = crate::model::time_step::time_step(model, 0.0).0;
    if let crate::model::Integrator::Implicit(s) = &model.integrator {
        // A static run takes its load steps; a dynamic one its fixed Δt.
        if s.static_analysis {
            dt = scene.solver().t_end / f64::from(s.load_steps.max(1));
        } else if let Some(fixed) = model.fixed_dt {
            dt = fixed;
        }
    }
    let bytes_cpu = CpuBackend::bytes_per_particle_of(model);
    let s = scene.solver();
    let g = &model.grid;
    let shape = match &model.shape {
        Shape::Lme(l) => format!(
            "lme (gamma = {}, support radius {:.3} h)",
            l.gamma,
            l.radius / l.h
        ),
        Shape::Ugimp(u) => format!("ugimp (lp = {:.4} h)", u.lp_h),
        Shape::Linear => "linear".to_string(),
        Shape::Bspline(b) => format!(
            "B-spline of degree {} (open knots, {})",
            b.degree,
            if b.cells {
                "on the grid lines: solver.bspline_knots = \"cells\""
            } else {
                "interior ones mid-cell for degree 2, on the nodes for 3"
            }
        ),
    };
    let shape = if model.mls {
        format!(
            "{shape}, MLS {} at {} Gauss points",
            match model.mls_scope {
                crate::scene::MlsScope::All => "reconstruction (the paper's step)",
                crate::scene::MlsScope::Force => "correction of the internal force's quadrature",
            },
            crate::model::gauss::gauss_points(&model.shape, g)
        )
    } else {
        shape
    };
    // GMM's constraints hold the cloud's nodes, not the grid's.
    let cloud = match &model.integrator {
        crate::model::Integrator::Implicit(crate::model::ImplicitSettings {
            gmm: Some(_), ..
        }) => crate::gmm::Cloud::from_model(model).ok(),
        _ => None,
    };
    // GMM reads no grid shape: its basis over the node clouds instead.
    let shape = match &model.integrator {
        crate::model::Integrator::Implicit(crate::model::ImplicitSettings {
            gmm: Some(gm),
            ..
        }) => match gm.basis {
            crate::scene::GmmBasis::Lme => format!(
                "GMM-LME over node clouds (gamma = {}, search radius {:.3} h; the grid only seeds the nodes)",
                gm.gamma, gm.search_radius
            ),
            crate::scene::GmmBasis::Mls => format!(
                "GMM-MLS over node clouds (dilation {:.3} h, search radius {:.3} h; the grid only seeds the nodes)",
                gm.dilation, gm.search_radius
            ),
        },
        _ => shape,
    };
    let step_rule = match model.fixed_dt {
        Some(fixed) => {
            // Courant number of the fixed step at t = 0.
            let c = crate::model::time_step::max_speed(model);
            format!(
                "dt = {fixed} s fixed (Courant number {:.3} at t = 0)",
                c * fixed / g.min_spacing()
            )
        }
        None => format!("cfl = {}", s.cfl),
    };
    let materials = scene
        .file
        .materials
        .iter()
        .zip(&model.materials)
        .map(|((n, m), mat)| {
            // Each key with its unit, in the model's own order.
            let keys: Vec<String> = mat
                .entry()
                .keys
                .iter()
                .filter_map(|k| {
                    // Dimensionless keys ("1") without a unit.
                    m.get(k.name).map(|v| match k.unit {
                        "1" | "" | "-" => format!("{} = {v}", k.name),
                        unit => format!("{} = {v} {unit}", k.name),
                    })
                })
                .collect();
            format!(
                "{n} ({}, density = {} kg/m^3, {})",
                m.model,
                m.density,
                keys.join(", ")
            )
        })
        .collect::<Vec<_>>()
        .join(", ");
    let integrator = match model.integrator {
        crate::model::Integrator::Fe => "fe".to_string(),
        crate::model::Integrator::Musl => "musl (B-spline paper eqs. 28-37)".to_string(),
        crate::model::Integrator::Npc { gamma, position } => {
            format!("npc (gamma = {gamma}, position: {position:?})")
        }
        crate::model::Integrator::Implicit(s) => {
            let mode = if s.static_analysis {
                format!("static, {} load steps", s.load_steps)
            } else {
                format!("Newmark beta = {}, gamma = {}", s.beta, s.gamma)
            };
            format!(
                "implicit ({mode}; Newton tol = {:e}, at most {} iterations, {} cuts)",
                s.tol, s.max_iter, s.max_cuts
            )
        }
    };
    let f = &scene.file;
    let backends = match model.integrator {
        crate::model::Integrator::Implicit(_) => "the CPU (implicit)",
        _ if model.pore.is_some() => "the CPU (saturated soil)",
        _ if !model.constraints.platens.is_empty() => "the CPU (a loaded platen)",
        _ => "the CPU and the GPU alike",
    };
    // Saturated soil: each fluid, the drains, the stabilisation, the Δt rule.
    let pore = match &model.pore {
        None => String::new(),
        Some(pore) => {
            let fluids = scene
                .file
                .materials
                .keys()
                .zip(&pore.fluid)
                .filter_map(|(name, f)| {
                    f.map(|f| {
                        format!(
                            "{name} (k = {:e} m/s, n = {}, K_w = {:e} Pa, rho_w = {} kg/m^3)",
                            f.k, f.n, f.kw, f.rho_w
                        )
                    })
                })
                .collect::<Vec<_>>()
                .join(", ");
            let drains = pore
                .drains
                .iter()
                .map(|d| {
                    format!(
                        "{} (p = {} Pa; {} nodes)",
                        d.name,
                        d.pressure,
                        d.nodes.len()
                    )
                })
                .collect::<Vec<_>>();
            let drains = if drains.is_empty() {
                "none: undrained".to_string()
            } else {
                drains.join(", ")
            };
            let flow = pore.flow_dt(g.min_spacing());
            format!(
                "pore        saturated: {fluids}; drained {drains}; volumetric term {}; flow limit dt = {flow:.4e} s{}\n",
                if pore.nodal_volumetric {
                    "nodal (stabilised)"
                } else {
                    "per particle (equal order: oscillates)"
                },
                if model.fixed_dt.is_none() && flow <= dt {
                    " (governs)"
                } else {
                    ""
                }
            )
        }
    };
    // The nodes each backend holds: the grid's, once per contact field.
    let fields = model.contact.as_ref().map_or(1, |c| c.n_fields);
    let nodes = match &cloud {
        Some(cl) => format!(
            "{} of the GMM node cloud (from the grid's {}), on the CPU (implicit)",
            cl.x.len(),
            g.n_nodes()
        ),
        None if fields > 1 => format!(
            "{} per field x {fields} fields (one per body in a contact pair, one for the rest) = {}, on {}",
            g.n_nodes(),
            g.n_nodes() * fields,
            backends
        ),
        None => format!("{}, on {}", g.n_nodes(), backends),
    };
    let law = |contact: u32, mu: f64| match contact {
        crate::model::walls::CONTACT_STICK => "stick".to_string(),
        crate::model::walls::CONTACT_SLIP => "slip (frictionless)".to_string(),
        _ => format!("friction, mu = {mu}"),
    };
    let walls = if model.walls.list.is_empty() {
        "none".to_string()
    } else {
        model
            .walls
            .list
            .iter()
            .map(|w| {
                let when = match (w.appear_at > 0.0, w.remove_at.is_finite()) {
                    (false, false) => String::new(),
                    (a, r) => format!(
                        ", acting{}{}",
                        if a {
                            format!(" from {} s", w.appear_at)
                        } else {
                            String::new()
                        },
                        if r {
                            format!(" until {} s", w.remove_at)
                        } else {
                            String::new()
                        }
                    ),
                };
                format!(
                    "{} (through ({}, {}) m, normal ({}, {}); {}; {} nodes{when})",
                    w.name,
                    w.point[0],
                    w.point[1],
                    w.normal[0],
                    w.normal[1],
                    law(w.contact, w.mu),
                    w.nodes.len()
                )
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    let contact = match &model.contact {
        None => "none: bodies that touch share one velocity field".to_string(),
        Some(c) => f
            .contact
            .iter()
            .zip(&c.pairs)
            .map(|((n, spec), p)| {
                format!(
                    "{n}: {} / {} ({})",
                    spec.bodies[0],
                    spec.bodies[1],
                    law(p.law, p.mu)
                )
            })
            .collect::<Vec<_>>()
            .join(", "),
    };
    let gravity = match &f.gravity {
        None => "none".to_string(),
        Some(gr) => format!(
            "g = ({}, {}) m/s^2, {}",
            gr.g[0],
            gr.g[1],
            match gr.ramp {
                crate::scene::Ramp::None => "full from t = 0".to_string(),
                crate::scene::Ramp::Sine => format!(
                    "ramped (sine) to full at t = {} s",
                    0.5 * model.gravity.as_ref().map_or(0.0, |g| g.period)
                ),
            }
        ),
    };
    let bodies = scene
        .bodies()
        .map(|(n, b)| {
            let mut shapes = Vec::new();
            let count = |k: usize, one: &str, many: &str| match k {
                0 => None,
                1 => Some(format!("1 {one}")),
                k => Some(format!("{k} {many}")),
            };
            shapes.extend(count(b.rects.len(), "rectangle", "rectangles"));
            shapes.extend(count(b.disks.len(), "disk", "disks"));
            shapes.extend(count(b.polygons.len(), "polygon", "polygons"));
            let layout = match scene.layout(b) {
                crate::scene::Layout::Gauss => "gauss",
                crate::scene::Layout::Uniform => "uniform",
            };
            let disks = if b.disks.is_empty() {
                String::new()
            } else {
                match b.disk_layout {
                    crate::scene::DiskLayout::Rings => {
                        ", disks on rings at spacing h/ppc".to_string()
                    }
                    crate::scene::DiskLayout::Lattice => {
                        ", disks on the lattice (its points inside them)".to_string()
                    }
                }
            };
            let stress = match b.initial_stress {
                crate::scene::InitialStress::None => String::new(),
                crate::scene::InitialStress::Geostatic => {
                    let k0 = b.k0.unwrap_or_else(|| {
                        crate::model::geostatic::default_k0(&f.materials[&b.material])
                    });
                    format!(", initial stress geostatic with k0 = {k0:.4}")
                }
            };
            format!(
                "{n} ({}, {}; ppc {}, {layout} points{disks}; v0 = ({}, {}) m/s{stress})",
                shapes.join(", "),
                b.material,
                b.ppc,
                b.velocity[0],
                b.velocity[1]
            )
        })
        .collect::<Vec<_>>()
        .join(", ");
    format!(
        "scene {name}: valid\n{desc}\
         particles   {np}\n\
         grid        {nx} x {ny} nodes, h = {h} m, from ({x0}, {y0}) to ({x1}, {y1}) m{pert}\n\
         nodes       {nodes}\n\
         bodies      {bodies}\n\
         materials   {materials}\n\
         shape       {shape}\n\
         integrator  {integrator}, {step_rule}\n\
         time        t_end = {t_end} s, first dt = {dt:.4e} s, about {steps:.0} steps\n\
         work        about {work:.3e} particle-steps\n\
         memory      {bpp:.0} bytes per particle on the CPU path\n\
         constraints {nc}\n\
         walls       {walls}\n\
         contact     {contact}\n\
         gravity     {gravity}\n\
         {pore}\
         probes      {npr}\n\
         exact       {exact}\n",
        name = scene.name,
        desc = if scene.file.description.is_empty() {
            String::new()
        } else {
            format!("{}\n", scene.file.description.trim())
        },
        np = model.particles.len(),
        nx = g.nx,
        ny = g.ny,
        h = g.h,
        x0 = g.min[0],
        y0 = g.min[1],
        x1 = g.max()[0],
        y1 = g.max()[1],
        pert = if g.is_perturbed() {
            format!(", interior nodes perturbed by up to {} h", g.perturb)
        } else {
            String::new()
        },
        t_end = s.t_end,
        steps = (s.t_end / dt).ceil(),
        work = (s.t_end / dt).ceil() * model.particles.len() as f64,
        bpp = bytes_cpu,
        nc = model
            .constraints
            .groups
            .iter()
            .enumerate()
            .map(|(k, c)| {
                let held = match &cloud {
                    Some(cl) => format!("{} nodes of the GMM cloud", cl.groups[k].len()),
                    None => format!("{} nodes", c.nodes.len()),
                };
                let fixed = match c.fix {
                    crate::model::FIX_X => "x",
                    crate::model::FIX_Y => "y",
                    _ => "xy",
                };
                let moving = if c.moves() {
                    let d = c.travel(s.t_end);
                    let ramp = if c.ramp_time > 0.0 {
                        format!(", ramped over {} s", c.ramp_time)
                    } else {
                        String::new()
                    };
                    format!(
                        "; at v = ({}, {}) m/s{ramp}, its region travels ({:.6}, {:.6}) m by t_end \
                         ({:.2} cells), its nodes moving with it",
                        if c.fix & crate::model::FIX_X != 0 {
                            c.velocity[0]
                        } else {
                            0.0
                        },
                        if c.fix & crate::model::FIX_Y != 0 {
                            c.velocity[1]
                        } else {
                            0.0
                        },
                        d[0],
                        d[1],
                        d[0].hypot(d[1]) / g.h
                    )
                } else {
                    String::new()
                };
                format!("{} (fixes {fixed}; {held}{moving})", c.name)
            })
            .collect::<Vec<_>>()
            .join(", "),
        npr = model
            .probes
            .iter()
            .map(|p| format!("{} -> particle {}", p.name, p.particle))
            .collect::<Vec<_>>()
            .join(", "),
        exact = scene.file.exact.map_or("none".to_string(), |e| {
            serde_json::to_value(e)
                .ok()
                .and_then(|v| v.as_str().map(String::from))
                .unwrap_or_else(|| format!("{e:?}"))
        }),
    )
}
