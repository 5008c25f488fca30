//! What the run driver needs from a backend (CPU reference or GPU): advance
//! in time, report probes, energy and reactions at sample times, and hand
//! back the particle state at the end.

use crate::error::{Error, Result};
use crate::model::energy::Energy;
use crate::model::fault::Fault;
use crate::model::{Model, Particles};
use std::sync::atomic::{AtomicBool, Ordering};

/// Why `advance` stopped short: the run went unstable (a result), or the
/// backend itself failed (a GPU device error: an error).
#[derive(Debug)]
pub enum Halt {
    Unstable(Fault),
    Failed(Error),
}

impl From<Fault> for Halt {
    fn from(f: Fault) -> Self {
        Halt::Unstable(f)
    }
}

impl From<Error> for Halt {
    fn from(e: Error) -> Self {
        Halt::Failed(e)
    }
}

/// A backend's state between stages, in a form either backend can load:
/// the CPU path hands it to the GPU path in the parity tests
/// (`GpuBackend::upload_state`).
#[derive(Debug, Clone)]
pub struct State {
    pub particles: Particles,
    /// Per node: [mass, momentum or velocity x, y] (kg, kg·m/s or m/s).
    pub mv: Vec<[f64; 3]>,
    /// Per node: force (N per unit thickness).
    pub force: Vec<[f64; 2]>,
    /// Time reached (s).
    pub t: f64,
    /// Time step of the step in progress, or of the last one (s).
    pub dt: f64,
    /// The implicit integrator's Newton statistics so far, so a resumed
    /// run's `summary.json` covers the whole run (None otherwise).
    pub newton: Option<NewtonStats>,
    /// The implicit integrator's wall contact states of the last converged
    /// step, per node then wall (`held_contact_code`), where the next step
    /// starts its active set; empty for the explicit integrators.
    pub held_contacts: Vec<u8>,
    /// A GMM run's node cloud (`solver.method = "gmm"`); None otherwise.
    pub cloud: Option<CloudState>,
}

impl State {
    /// `particles` at time `t` (the last step's Δt `dt`) as a state of
    /// `model` at a step boundary: every field's grid nodes (grid nodes ×
    /// `Model::n_fields`, one set per body of a contact pair) at zero,
    /// which is exact there (each step clears them before it scatters); no
    /// Newton counters, held contacts or node cloud.
    pub fn at_step_boundary(model: &Model, particles: Particles, t: f64, dt: f64) -> State {
        let nodes = model.grid.n_nodes() * model.n_fields();
        State {
            particles,
            mv: vec![[0.0; 3]; nodes],
            force: vec![[0.0; 2]; nodes],
            t,
            dt,
            newton: None,
            held_contacts: Vec::new(),
            cloud: None,
        }
    }
}

/// What a GMM run's node cloud carries from step to step, beyond what its
/// scene rebuilds (the nodes' lattice origin, constraints and the rim
/// nodes' fit to the outline come from the initial particles): per node, the
/// position (m), displacement since the start (m), velocity (m/s) and
/// acceleration (m/s²) of the last converged step; per particle, LME's
/// multiplier λ of the last step (its Newton solve's warm start).
#[derive(Debug, Clone, PartialEq)]
pub struct CloudState {
    pub x: Vec<[f64; 2]>,
    pub u: Vec<[f64; 2]>,
    pub v: Vec<[f64; 2]>,
    pub a: Vec<[f64; 2]>,
    pub lambda: Vec<[f64; 2]>,
}

/// State of one probe particle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProbeState {
    pub x: [f64; 2],
    pub v: [f64; 2],
    pub stress: [f64; 3],
    /// Saturated soil: the pore pressure (Pa); None in a dry scene.
    pub pore_pressure: Option<f64>,
}

/// Everything recorded at a sample time.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// Time of the sample (s).
    pub t: f64,
    /// In `Model::probes` order.
    pub probes: Vec<ProbeState>,
    pub energy: Energy,
    /// Per constraint group, reaction of the last step (N per unit thickness).
    pub reactions: Vec<[f64; 2]>,
    /// The implicit integrator's last step (None for the explicit ones,
    /// and for samples read back from a checkpoint).
    pub newton: Option<NewtonSample>,
}

/// The implicit integrator's last step, as a sample reports it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonSample {
    /// Newton iterations the step took.
    pub iterations: u32,
    /// Its final residual norm over the step's reference norm.
    pub residual: f64,
    /// Its Δt after any cuts (s).
    pub dt: f64,
}

/// Newton statistics of an implicit run, for `summary.json`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct NewtonStats {
    /// Converged steps and the Newton iterations they took in all.
    pub steps: u64,
    pub iterations: u64,
    /// Most iterations one step took.
    pub max_iterations: u32,
    /// Iterations of the last step.
    pub last_iterations: u32,
    /// Relative residual norms of the last step's iterates, first to last.
    pub last_residuals: Vec<f64>,
    /// Relative correction norms |δ| / |Δu| of the last step's iterations.
    pub last_corrections: Vec<f64>,
    /// Halvings of Δt over the run.
    pub cuts: u64,
    /// Jacobians assembled and factored (every iteration's with full
    /// Newton, fewer with `solver.newton_jacobian = "reuse"`).
    pub factorizations: u64,
    /// Where the time went, summed over every attempt (failed ones too).
    pub seconds: NewtonSeconds,
}

/// Wall time of the implicit step's parts (s), summed over the run.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct NewtonSeconds {
    /// Shape functions at the particles, the nodal mass, velocity and
    /// acceleration, and the unknowns (once per step).
    pub map: f64,
    /// The Jacobian's sparsity and faer's symbolic LU (once per step).
    pub symbolic: f64,
    /// Residual assembly, stress updates included (once per iterate).
    pub residual: f64,
    /// Jacobian assembly (once per iteration, or per factorization with
    /// `solver.newton_jacobian = "reuse"`).
    pub jacobian: f64,
    /// faer's numeric LU factorisation (likewise).
    pub factor: f64,
    /// The triangular solves and the update of Δu (once per iteration).
    pub solve: f64,
    /// Particles take the converged solution (once per step).
    pub convect: f64,
}

impl NewtonSeconds {
    /// Their sum (s).
    pub fn total(&self) -> f64 {
        self.map
            + self.symbolic
            + self.residual
            + self.jacobian
            + self.factor
            + self.solve
            + self.convect
    }
}

impl NewtonStats {
    /// Mean Newton iterations per converged step.
    pub fn mean_iterations(&self) -> f64 {
        self.iterations as f64 / self.steps.max(1) as f64
    }
}

pub trait Backend {
    /// Human-readable description, e.g. "cpu (f64, 2 threads, x86-64-v3)".
    fn name(&self) -> String;
    /// Simulated time reached (s).
    fn time(&self) -> f64;
    /// Steps taken.
    fn steps(&self) -> u64;
    /// Takes steps until the time reaches `t_stop` or the model's `t_end`,
    /// or `stop` is raised (checked between steps on the CPU, between
    /// submissions on the GPU; the caller sees it raised and the time short).
    /// The last step before `t_end` is shortened to land on it exactly;
    /// other stops may be passed by less than one step.
    fn advance(&mut self, t_stop: f64, stop: &AtomicBool) -> std::result::Result<(), Halt>;
    /// Takes exactly `n` steps (or fewer if t_end comes first); for benchmarks.
    fn advance_steps(&mut self, n: u64) -> std::result::Result<(), Halt>;
    /// Probes, energy and reactions now.
    fn sample(&mut self) -> Result<Sample>;
    /// Particle state now (the GPU backend downloads it).
    fn particles(&mut self) -> Result<&Particles>;
    /// The model being run. Its particles are those of the last
    /// `particles()` call (on the GPU backend they may be stale after it).
    fn model(&self) -> &Model;
    /// Memory the backend holds per particle, grid included (bytes).
    fn bytes_per_particle(&self) -> f64;
    /// Replaces the run state with `state` after `steps` steps (resuming
    /// from a checkpoint): particles, time, Δt of the last step.
    fn restore(&mut self, state: &State, steps: u64) -> Result<()>;
    /// Newton statistics (the implicit integrator only).
    fn newton(&self) -> Option<&NewtonStats> {
        None
    }
    /// The implicit integrator's held wall contact states (see
    /// `State::held_contacts`); empty for the others.
    fn held_contacts(&self) -> Vec<u8> {
        Vec::new()
    }
    /// A GMM run's node cloud (see `State::cloud`); None for the others.
    fn cloud_state(&self) -> Option<CloudState> {
        None
    }
}

/// The probes' state now, in `Model::probes` order.
pub fn probe_states(model: &Model) -> Vec<ProbeState> {
    let p = &model.particles;
    model
        .probes
        .iter()
        .map(|pr| ProbeState {
            x: p.x[pr.particle],
            v: p.v[pr.particle],
            stress: p.stress[pr.particle],
            pore_pressure: p.pore_pressure.get(pr.particle).copied(),
        })
        .collect()
}

/// `stop` raised? (Relaxed: the flag is a request, nothing else hangs on it.)
pub fn stop_requested(stop: &AtomicBool) -> bool {
    stop.load(Ordering::Relaxed)
}

/// `state` fits `model`: same particle count and fields, same node count.
pub fn check_state(model: &Model, state: &State) -> Result<()> {
    let (p, q) = (&model.particles, &state.particles);
    let same = p.len() == q.len()
        && p.a.len() == q.a.len()
        && p.lambda.len() == q.lambda.len()
        && p.f.len() == q.f.len()
        && p.plastic.len() == q.plastic.len()
        && state.mv.len() == model.grid.n_nodes() * model.n_fields()
        && state.force.len() == model.grid.n_nodes() * model.n_fields();
    let gmm = matches!(&model.integrator, crate::model::Integrator::Implicit(s) if s.gmm.is_some());
    match (state.cloud.is_some(), gmm) {
        (true, false) => {
            return Err(Error::Checkpoint(
                "holds a GMM run's node cloud, and the scene is not a GMM run: resume it with \
                 solver.integrator = \"implicit\" and solver.method = \"gmm\""
                    .into(),
            ));
        }
        (false, true) => {
            return Err(Error::Checkpoint(
                "holds no node cloud, and the scene is a GMM run (solver.method = \"gmm\"): \
                 resume it with the scene it was written with"
                    .into(),
            ));
        }
        _ => {}
    }
    if same {
        Ok(())
    } else {
        Err(Error::Checkpoint(format!(
            "the state holds {} particles and {} nodes, the scene {} and {}",
            q.len(),
            state.mv.len(),
            p.len(),
            model.grid.n_nodes() * model.n_fields()
        )))
    }
}
