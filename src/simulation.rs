//! One run of a scene, the same for every caller (`run`, `study`, `bench`,
//! the tests): build the model from a checked scene, open the chosen
//! backend, drive it to t_end with an observer, and score it against the
//! scene's exact solution.
//!
//! ```no_run
//! # use lme_mpm::{scene::Scene, simulation::{Simulation, BackendSpec}, solver::Recorder};
//! let scene = Scene::load("cases/dyka_bar.toml".as_ref(), &[]).unwrap();
//! let mut sim = Simulation::new(&scene, &BackendSpec::cpu()).unwrap();
//! let status = sim.drive(&mut Recorder::default()).unwrap();
//! let errors = sim.score().unwrap();
//! ```

use crate::backend::Backend;
use crate::cpu::CpuBackend;
use crate::cpu::implicit::ImplicitBackend;
use crate::error::{Error, Result};
use crate::exact::{self, Errors};
use crate::gpu::{self, GpuBackend};
use crate::model::Model;
use crate::scene::Scene;
use crate::solver::{self, Cursor, Observer, RunStatus, Schedule};

/// `--backend`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum BackendChoice {
    /// A hardware GPU when wgpu finds one, else the CPU path; a software
    /// adapter (llvmpipe) counts as none (says which and why).
    Auto,
    /// The f64 CPU reference path.
    Cpu,
    /// The wgpu path on any adapter, software included; fails when none exists.
    Gpu,
}

/// Which backend to open, and how.
#[derive(Debug, Clone, Default)]
pub struct BackendSpec {
    pub choice: Option<BackendChoice>,
    /// Case-insensitive substring of the GPU adapter's name (`--adapter`).
    pub adapter: Option<String>,
    /// GPU-path choices that are not part of the scene.
    pub gpu: gpu::GpuOptions,
    /// Say on stderr which backend was taken and why.
    pub verbose: bool,
}

impl BackendSpec {
    pub fn new(choice: BackendChoice) -> Self {
        BackendSpec {
            choice: Some(choice),
            ..Default::default()
        }
    }

    /// The CPU reference path.
    pub fn cpu() -> Self {
        BackendSpec::new(BackendChoice::Cpu)
    }

    fn choice(&self) -> BackendChoice {
        self.choice.unwrap_or(BackendChoice::Auto)
    }
}

/// Makes the backend `spec` asks for. `auto` takes a hardware GPU when
/// there is one and otherwise the CPU path (a software adapter such as
/// llvmpipe is slower than the CPU path); with `verbose` it says which it
/// took and why.
pub fn open_backend(spec: &BackendSpec, model: Model) -> Result<Box<dyn Backend>> {
    let req = |allow_software| gpu::context::AdapterRequest {
        name: spec.adapter.clone(),
        allow_software,
        force_cas: std::env::var_os("LME_MPM_FORCE_CAS").is_some(),
    };
    if matches!(model.integrator, crate::model::Integrator::Implicit(_)) {
        return match spec.choice() {
            BackendChoice::Gpu => Err(crate::error::SceneError::invalid(
                "solver.integrator",
                "= \"implicit\" runs on the CPU path only: use --backend cpu or auto",
            )
            .into()),
            BackendChoice::Cpu | BackendChoice::Auto => {
                let b = ImplicitBackend::new(model)?;
                if spec.verbose && spec.choice() == BackendChoice::Auto {
                    crate::say!(
                        "backend: {} (auto: the implicit integrator runs on the CPU only)",
                        b.name()
                    );
                }
                Ok(Box::new(b))
            }
        };
    }
    // Saturated soil and loaded platens have no WGSL twin yet: the CPU
    // path steps them.
    let cpu_only = if model.pore.is_some() {
        Some((
            "materials".to_string(),
            "a saturated material (`permeability`)",
            "saturated soil",
        ))
    } else {
        model.constraints.platens.first().map(|p| {
            (
                format!("platens.{}", p.name),
                "a loaded platen",
                "a loaded platen",
            )
        })
    };
    if let Some((key, what, short)) = cpu_only {
        return match spec.choice() {
            BackendChoice::Gpu => Err(crate::error::SceneError::invalid(
                key,
                format!("{what} runs on the CPU path only for now: use --backend cpu or auto"),
            )
            .into()),
            BackendChoice::Cpu | BackendChoice::Auto => {
                let b = CpuBackend::new(model);
                if spec.verbose && spec.choice() == BackendChoice::Auto {
                    crate::say!(
                        "backend: {} (auto: {short} runs on the CPU only for now)",
                        b.name()
                    );
                }
                Ok(Box::new(b))
            }
        };
    }
    match spec.choice() {
        BackendChoice::Cpu => Ok(Box::new(CpuBackend::new(model))),
        BackendChoice::Gpu => {
            let ctx = gpu::context::open(&req(true))?;
            let b = GpuBackend::with_options(ctx, model, spec.gpu)?;
            if spec.verbose {
                crate::say!("backend: {}", b.name());
            }
            Ok(Box::new(b))
        }
        BackendChoice::Auto => match gpu::context::open(&req(false)) {
            Ok(ctx) => {
                let b = GpuBackend::with_options(ctx, model, spec.gpu)?;
                if spec.verbose {
                    crate::say!("backend: {} (auto: a GPU adapter was found)", b.name());
                }
                Ok(Box::new(b))
            }
            Err(e) => {
                if spec.verbose {
                    let why = match &e {
                        Error::NoAdapter(m) => m.clone(),
                        other => other.to_string(),
                    };
                    crate::say!(
                        "backend: CPU path (f64, {} threads); auto found no usable GPU: {why}",
                        rayon::current_num_threads()
                    );
                }
                Ok(Box::new(CpuBackend::new(model)))
            }
        },
    }
}

/// A scene on a backend.
pub struct Simulation {
    pub scene: Scene,
    backend: Box<dyn Backend>,
}

impl Simulation {
    /// Builds the model of `scene` and opens the backend `spec` asks for.
    pub fn new(scene: &Scene, spec: &BackendSpec) -> Result<Simulation> {
        let model = Model::new(scene)?;
        let backend = open_backend(spec, model)?;
        Ok(Simulation::with_backend(scene, backend))
    }

    /// `scene` on a backend the caller opened (tests pick a GPU context).
    pub fn with_backend(scene: &Scene, backend: Box<dyn Backend>) -> Simulation {
        Simulation {
            scene: scene.clone(),
            backend,
        }
    }

    /// Samples at the scene's `output.sample_interval`, snapshots at its
    /// `output.vtk_interval`.
    pub fn schedule(&self) -> Schedule {
        Schedule {
            sample_interval: self.scene.sample_interval,
            vtk_interval: self.scene.file.output.vtk_interval,
            snapshot_times: Vec::new(),
            checkpoint_interval: self.scene.file.output.checkpoint_interval,
            final_checkpoint: false,
            stop: None,
        }
    }

    /// Runs to t_end on the scene's schedule (see `solver::drive`).
    pub fn drive(&mut self, obs: &mut dyn Observer) -> Result<RunStatus> {
        let schedule = self.schedule();
        self.drive_with(schedule, obs)
    }

    /// Runs to t_end on `schedule`.
    pub fn drive_with(&mut self, schedule: Schedule, obs: &mut dyn Observer) -> Result<RunStatus> {
        solver::drive(self.backend.as_mut(), schedule, obs)
    }

    /// Runs to t_end on `schedule`, continuing from `cursor` (a resumed
    /// run, its backend restored) or from the start when None.
    pub fn drive_from(
        &mut self,
        schedule: Schedule,
        obs: &mut dyn Observer,
        cursor: Option<Cursor>,
    ) -> Result<RunStatus> {
        solver::drive_from(self.backend.as_mut(), schedule, obs, cursor)
    }

    /// Errors against the scene's exact solution at the time reached (None
    /// when the scene names none).
    pub fn score(&mut self) -> Result<Option<Errors>> {
        self.score_with(&[])
    }

    /// `score` with the run's samples, for the references read over time
    /// (the footing's peak, the energy at the start; without samples those
    /// figures are NaN).
    pub fn score_with(&mut self, samples: &[crate::backend::Sample]) -> Result<Option<Errors>> {
        let Some(kind) = self.scene.file.exact else {
            return Ok(None);
        };
        let t = self.backend.time();
        // Brings the model's particles up to date (a GPU download), so they
        // are scored in place rather than copied.
        self.backend.particles()?;
        let model = self.backend.model();
        Ok(Some(exact::score(
            kind,
            &self.scene,
            model,
            &model.particles,
            t,
            samples,
        )))
    }

    pub fn backend(&mut self) -> &mut dyn Backend {
        self.backend.as_mut()
    }

    pub fn backend_ref(&self) -> &dyn Backend {
        self.backend.as_ref()
    }

    /// The backend, for callers that need it after the run.
    pub fn into_backend(self) -> Box<dyn Backend> {
        self.backend
    }
}
