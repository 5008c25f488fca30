//! `lme-mpm run`: build the model, pick a backend, drive it to t_end while
//! writing samples and snapshots, then score and summarise. Nothing is
//! written before the scene and model are known to be valid.

use crate::backend::{Backend, Sample};
use crate::cpu::CpuBackend;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::model::shape::Shape;
use crate::output::{self, csv, summary::Summary, vtk};
use crate::scene::Scene;
pub use crate::simulation::BackendChoice;
use crate::simulation::{BackendSpec, Simulation};
use crate::solver::{Observer, RunStatus};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

#[derive(Debug, Clone)]
pub struct RunOptions {
    pub backend: BackendChoice,
    /// Case-insensitive substring of the GPU adapter's name (`--adapter`).
    pub adapter: Option<String>,
    pub out: PathBuf,
    /// Show a progress bar on a terminal (runs over a second).
    pub progress: bool,
    /// Print the backend choice and the result line to stderr.
    pub verbose: bool,
    /// What the preflight allows (memory, steps, hours, snapshots).
    pub limits: crate::preflight::Limits,
}

/// How a run ended, with its summary (also written to summary.json).
#[derive(Debug, Clone)]
pub struct Outcome {
    pub status: RunStatus,
    pub summary: Summary,
}

/// Runs `scene` and writes its outputs to `opts.out`. The preflight comes
/// first: a scene that cannot fit or run in the limits is refused before
/// anything is allocated, and output intervals below a step are clamped
/// (with a warning on stderr).
pub fn run(scene: &Scene, opts: &RunOptions) -> Result<Outcome> {
    let start = Instant::now();
    let plan = crate::preflight::plan(scene, &opts.limits, rayon::current_num_threads())?;
    for w in &plan.warnings {
        eprintln!("warning: {w}");
    }
    let scene = &plan.scene;
    let spec = BackendSpec {
        choice: Some(opts.backend),
        adapter: opts.adapter.clone(),
        gpu: Default::default(),
        verbose: opts.verbose,
    };
    let mut sim = Simulation::new(scene, &spec)?;

    std::fs::create_dir_all(&opts.out)
        .map_err(|e| Error::io("cannot create output folder", &opts.out, e))?;
    let resolved = toml::to_string(&scene.file).expect("a scene file serialises to TOML");
    output::write_atomic(&opts.out.join("scene.resolved.toml"), resolved.as_bytes())?;

    let mut writer = Writer::new(&opts.out, sim.backend_ref().model(), opts.progress);
    let t_drive = Instant::now();
    let driven = sim.drive(&mut writer);
    writer.finish_progress();
    let status = driven?;
    let wall = (t_drive.elapsed().as_secs_f64() - writer.io_seconds).max(1e-9);

    let errors = sim.score()?;
    let backend = sim.backend();
    let t = backend.time();
    let steps = backend.steps();
    let bytes_per_particle = backend.bytes_per_particle();
    let backend_name = backend.name();
    let final_sample = writer.samples.last().cloned();
    let particles = backend.particles()?.clone();
    let model = backend.model().clone();
    let particles = &particles;
    if scene.file.output.particles_csv {
        output::write_atomic(
            &opts.out.join("particles.csv"),
            csv::particles(&model.body_names, particles).as_bytes(),
        )?;
    }
    let snap_done = writer.snapshots.last().is_some_and(|(ts, _)| *ts == t);
    if (scene.file.output.vtk_final || !matches!(status, RunStatus::Completed)) && !snap_done {
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
    };
    let npc = matches!(model.integrator, crate::model::Integrator::Npc { .. });
    let summary = Summary {
        status: match status {
            RunStatus::Completed => "completed",
            RunStatus::Unstable { .. } => "unstable",
        },
        reason,
        reason_code,
        unstable_particle,
        scene: scene.name.clone(),
        t,
        t_end: model.t_end,
        steps,
        particles: n,
        nodes: model.grid.n_nodes(),
        wall_seconds: wall,
        wall_seconds_total: start.elapsed().as_secs_f64(),
        particle_steps_per_second: n as f64 * steps as f64 / wall,
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
                    .constraints
                    .groups
                    .iter()
                    .map(|g| g.name.clone())
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
    };
    let json = serde_json::to_string_pretty(&summary).expect("summary serialises");
    output::write_atomic(&opts.out.join("summary.json"), json.as_bytes())?;
    Ok(Outcome { status, summary })
}

/// Observer that keeps the samples, rewrites the CSV files now and then (so
/// a killed run leaves complete files) and writes VTK snapshots.
struct Writer {
    dir: PathBuf,
    probe_names: Vec<String>,
    group_names: Vec<String>,
    samples: Vec<Sample>,
    snapshots: Vec<(f64, String)>,
    last_flush: Instant,
    io_seconds: f64,
    progress: Option<(ProgressBar, Instant)>,
}

/// Rewrite the CSV files at most this often while running.
const FLUSH_EVERY: Duration = Duration::from_secs(5);
/// Runs shorter than this show no progress bar.
const PROGRESS_AFTER: Duration = Duration::from_secs(1);

impl Writer {
    fn new(dir: &Path, model: &Model, progress: bool) -> Self {
        let bar = progress.then(|| {
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
        Writer {
            dir: dir.to_path_buf(),
            probe_names: model.probes.iter().map(|p| p.name.clone()).collect(),
            group_names: model
                .constraints
                .groups
                .iter()
                .map(|g| g.name.clone())
                .collect(),
            samples: Vec::new(),
            snapshots: Vec::new(),
            last_flush: Instant::now(),
            io_seconds: 0.0,
            progress: bar,
        }
    }

    fn flush(&mut self) -> Result<()> {
        let t0 = Instant::now();
        output::write_atomic(
            &self.dir.join("probes.csv"),
            csv::probes(&self.probe_names, &self.samples).as_bytes(),
        )?;
        output::write_atomic(
            &self.dir.join("energy.csv"),
            csv::energy(&self.samples).as_bytes(),
        )?;
        output::write_atomic(
            &self.dir.join("reactions.csv"),
            csv::reactions(&self.group_names, &self.samples).as_bytes(),
        )?;
        self.last_flush = Instant::now();
        self.io_seconds += t0.elapsed().as_secs_f64();
        Ok(())
    }

    fn write_snapshot(&mut self, particles: &crate::model::Particles, t: f64) -> Result<()> {
        let t0 = Instant::now();
        let vdir = self.dir.join("vtk");
        std::fs::create_dir_all(&vdir).map_err(|e| Error::io("cannot create", &vdir, e))?;
        let name = format!("particles_{:05}.vtu", self.snapshots.len());
        output::write_atomic(&vdir.join(&name), &vtk::particles_vtu(particles, t))?;
        self.snapshots.push((t, format!("vtk/{name}")));
        output::write_atomic(
            &self.dir.join("particles.pvd"),
            vtk::pvd(&self.snapshots).as_bytes(),
        )?;
        self.io_seconds += t0.elapsed().as_secs_f64();
        Ok(())
    }

    fn finish_progress(&mut self) {
        if let Some((bar, _)) = &self.progress {
            bar.finish_and_clear();
        }
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

    fn progress(&mut self, fraction: f64) {
        if let Some((bar, started)) = &self.progress {
            if bar.is_hidden() && started.elapsed() > PROGRESS_AFTER {
                bar.set_draw_target(ProgressDrawTarget::stderr());
            }
            bar.set_position((fraction * 1000.0) as u64);
            if let Some(s) = self.samples.last() {
                bar.set_message(format!("t = {:.4e} s", s.t));
            }
        }
    }
}

/// Text that `lme-mpm check` prints: what the scene will run.
pub fn describe(scene: &Scene, model: &Model) -> String {
    let dt = crate::model::time_step::time_step(model, 0.0).0;
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
        Shape::Bspline(b) => format!("B-spline of degree {} (open knots)", b.degree),
    };
    let shape = if model.mls {
        format!(
            "{shape}, MLS reconstruction at {} Gauss points",
            crate::model::gauss::gauss_points(&model.shape, g)
        )
    } else {
        shape
    };
    let step_rule = match model.fixed_dt {
        Some(fixed) => {
            // Courant number of the fixed step at t = 0.
            let c = crate::model::time_step::max_speed(
                &model.particles.v,
                &model.particles.rho,
                &model.particles.body,
                &model.materials,
                &model.body_material,
            );
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
        .map(|(n, m)| {
            let model = serde_json::to_value(m.model)
                .ok()
                .and_then(|v| v.as_str().map(String::from))
                .unwrap_or_default();
            format!(
                "{n} ({model}, E = {} Pa, nu = {}, rho = {} kg/m^3)",
                m.youngs_modulus, m.nu, m.density
            )
        })
        .collect::<Vec<_>>()
        .join(", ");
    let integrator = match model.integrator {
        crate::model::Integrator::Fe => "fe".to_string(),
        crate::model::Integrator::Npc { gamma, position } => {
            format!("npc (gamma = {gamma}, position: {position:?})")
        }
    };
    format!(
        "scene {name}: valid\n{desc}\
         particles   {np}\n\
         grid        {nx} x {ny} nodes, h = {h} m, from ({x0}, {y0}) to ({x1}, {y1}) m{pert}\n\
         materials   {materials}\n\
         shape       {shape}\n\
         integrator  {integrator}, {step_rule}\n\
         time        t_end = {t_end} s, first dt = {dt:.4e} s, about {steps:.0} steps\n\
         work        about {work:.3e} particle-steps\n\
         memory      {bpp:.0} bytes per particle on the CPU path\n\
         constraints {nc}\n\
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
            .map(|c| format!("{} ({} nodes)", c.name, c.nodes.len()))
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
