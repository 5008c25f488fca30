//! The implicit integrator on the CPU (`solver.integrator = "implicit"`):
//! updated-Lagrangian Newmark with Newton–Raphson on the nodal displacement
//! increment (implicit-MPM paper §3–4, Algorithm 1). One step:
//!
//! 1. Initial phase: N, ∇N at the particles on the undeformed grid; nodal
//!    mass, velocity and acceleration from the particles (eqs. 38–41);
//!    Newmark predictor Δu = 0 (eqs. 42–44).
//! 2. UL-FEM phase: Newton on R(Δu) = 0 (`assemble`), the grid moving with
//!    the iterate, the sparse Jacobian factorised by faer's sparse LU;
//!    converged when the residual norm over the step's reference and the
//!    mass-weighted correction norm over Δu's are both below
//!    `solver.newton_tol` (the latter its square root). Wall contacts
//!    (`contact`) hold their state after the first iterations (`attempt`).
//! 3. Convective phase: particles take the converged grid solution
//!    (eqs. 46–49): x += Σ N Δu, a = Σ N a_I, v += Δt((1 − γ) a_n + γ a);
//!    stress, F and plastic state are those of the converged iterate; the
//!    grid is reset.
//!
//! A step whose Newton fails (no convergence in `newton_max_iter`, a
//! residual that blows up, a particle inverted, a singular Jacobian) is
//! retried with half the Δt, up to `newton_max_cuts` times; then the run
//! stops as unstable with reason `newton_diverged`. A static analysis
//! (`solver.static`) drops the inertia and scales every load by t / t_end
//! over `load_steps` steps of pseudo-time.
//!
//! The nodes are the grid's (implicit MPM) or, with `solver.method =
//! "gmm"`, the body's own node cloud (`gmm`, the paper's Algorithm 2):
//! the same residual, Jacobian, solve and constraints over "a set of
//! nodes with shape functions per particle" (`Nodes`); only the shape
//! evaluation, the predictor's nodal velocity and acceleration, and the
//! nodes' own update after convergence differ.

pub mod assemble;
pub mod contact;
pub mod gmm;

use crate::backend::{Backend, Halt, NewtonSample, NewtonStats, Sample, State, stop_requested};
use crate::cpu::{ShapeCache, shape_eval};
use crate::error::{Error, Result};
use crate::model::fault::{Fault, FaultKind};
use crate::model::material::increment::StepState;
use crate::model::walls::{CONTACT_FRICTION, CONTACT_STICK, coulomb_slip};
use crate::model::{ConstraintGroup, FIX_X, FIX_Y, ImplicitSettings, Integrator, Model, Particles};
use assemble::{Dofs, Incidence, NO_DOF, Newmark, ParticleIterate, Pattern, StepInputs};
use contact::{ContactPair, ContactState};
use faer::prelude::*;
use faer::sparse::SparseColMatRef;
use faer::sparse::linalg::solvers::Lu;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// A residual norm above this many times the step's reference is a
/// diverging Newton: the step is cut at once rather than iterated further.
const DIVERGED_RATIO: f64 = 1e8;

/// With `solver.newton_jacobian = "reuse"`: the factorization is kept for
/// the next iteration only if the residual fell at least this much in the
/// last one (a reused Jacobian converges linearly; when it slows, a fresh
/// one is cheaper than the iterations it saves).
const REUSE_CONTRACTION: f64 = 0.25;

/// Newton iterations whose contact states follow the iterate before they
/// are held (`ImplicitBackend::attempt`).
const FREE_CONTACT_ITERATIONS: u32 = 2;

/// `ImplicitBackend::jacobian_mismatch`'s answer.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct JacobianCheck {
    /// Largest |K_ij − (−∂R_i/∂Δu_j)_FD| over the largest |K_ij| of its
    /// column, or 1 / `PENALTY_REL` of the largest of all if more (so the
    /// contact penalty's columns do not hide the material's).
    pub mismatch: f64,
    /// Wall contacts open, sticking and slipping at the Δu checked.
    pub open: usize,
    pub stick: usize,
    pub slip: usize,
}

/// Why one attempt at a step failed.
enum AttemptFail {
    /// A particle faulted at an iterate (inverted, non-finite).
    Particle(Fault),
    /// No convergence; the last relative residual.
    Newton(f64),
}

/// The nodes a step solves for.
pub enum Nodes {
    /// The background grid's (implicit MPM): N from the particles'
    /// positions on it; nodal velocity and acceleration mapped from the
    /// particles each step; the grid reset after it.
    Grid,
    /// GMM: the body's node cloud, which keeps its state between steps.
    Cloud(Box<gmm::GmmNodes>),
}

/// Runs an implicit `Model` on the CPU.
pub struct ImplicitBackend {
    pub model: Model,
    pub settings: ImplicitSettings,
    pub nodes: Nodes,
    cache: ShapeCache,
    /// Per node at the step's start: mass, velocity, acceleration.
    node_mass: Vec<f64>,
    node_v: Vec<[f64; 2]>,
    node_a: Vec<[f64; 2]>,
    /// The iterate Δu and the residual, per node: the particles' part,
    /// with Coulomb's law, and with the held contact states.
    du: Vec<[f64; 2]>,
    r_body: Vec<[f64; 2]>,
    r: Vec<[f64; 2]>,
    r_held: Vec<[f64; 2]>,
    iterates: Vec<ParticleIterate>,
    start: Vec<StepState>,
    volume: Vec<f64>,
    body: Vec<[f64; 2]>,
    values: Vec<f64>,
    /// The step's unknowns and the Jacobian's structure (built once per step).
    dofs: Dofs,
    pattern: Option<Pattern>,
    incidence: Incidence,
    /// The step's wall contacts, their held and their natural states.
    pairs: Vec<ContactPair>,
    held: Vec<ContactState>,
    natural: Vec<ContactState>,
    /// Per node and wall: the contact state of the last converged step.
    node_states: Vec<ContactState>,
    /// Per constraint group then per wall: reaction of the last step (N/m).
    reactions: Vec<[f64; 2]>,
    wall_force: Vec<[f64; 2]>,
    mass_eps: f64,
    penalty: f64,
    /// Per constraint point: its prescribed Δu over the step (m).
    point_target: Vec<[f64; 2]>,
    point_penalty: f64,
    pub stats: NewtonStats,
    t: f64,
    steps: u64,
    dt: f64,
}

impl ImplicitBackend {
    /// Fails unless `model` has the implicit integrator.
    pub fn new(model: Model) -> Result<ImplicitBackend> {
        let Integrator::Implicit(settings) = model.integrator else {
            return Err(crate::error::SceneError::invalid(
                "solver.integrator",
                "must be \"implicit\" for the implicit backend",
            )
            .into());
        };
        let n = model.particles.len();
        let (node_set, nodes, stride) = match &settings.gmm {
            Some(g) => {
                let c = gmm::GmmNodes::new(&model, g)?;
                let (len, stride) = (c.cloud.len(), c.stride());
                (Nodes::Cloud(Box::new(c)), len, stride)
            }
            None => (Nodes::Grid, model.grid.n_nodes(), model.shape.max_nodes()),
        };
        let min_mass = model.particles.min_mass();
        let stiffest = model
            .materials
            .iter()
            .map(|m| {
                let (l, g) = m.lame_shear();
                l + 2.0 * g
            })
            .fold(0.0, f64::max);
        let blank = ParticleIterate {
            df: [1.0, 0.0, 0.0, 1.0],
            state: StepState {
                stress: [0.0; 3],
                f: [1.0, 0.0, 0.0, 1.0],
                q: [0.0; 4],
            },
            p: [0.0; 4],
            j: 1.0,
        };
        Ok(ImplicitBackend {
            nodes: node_set,
            cache: ShapeCache::new(n, stride),
            node_mass: vec![0.0; nodes],
            node_v: vec![[0.0; 2]; nodes],
            node_a: vec![[0.0; 2]; nodes],
            du: vec![[0.0; 2]; nodes],
            r_body: vec![[0.0; 2]; nodes],
            r: vec![[0.0; 2]; nodes],
            r_held: vec![[0.0; 2]; nodes],
            iterates: vec![blank; n],
            start: vec![blank.state; n],
            volume: vec![0.0; n],
            body: vec![[0.0; 2]; n],
            values: Vec::new(),
            dofs: Dofs::default(),
            pattern: None,
            incidence: Incidence::default(),
            pairs: Vec::new(),
            held: Vec::new(),
            natural: Vec::new(),
            node_states: vec![ContactState::Stick; nodes * model.walls.list.len()],
            reactions: vec![[0.0; 2]; model.constraints.groups.len() + model.walls.list.len()],
            wall_force: vec![[0.0; 2]; model.walls.list.len()],
            mass_eps: crate::model::MASS_EPS_REL * min_mass,
            penalty: assemble::PENALTY_REL * stiffest,
            point_target: vec![[0.0; 2]; model.constraints.points.len()],
            point_penalty: assemble::POINT_PENALTY_REL * stiffest,
            stats: NewtonStats::default(),
            t: 0.0,
            steps: 0,
            dt: 0.0,
            settings,
            model,
        })
    }

    /// Δt of the next step before any cut (s): t_end / load_steps when
    /// static, else `solver.dt` or the Courant rule (which may exceed 1).
    pub fn planned_dt(&self) -> f64 {
        let rem = self.model.t_end - self.t;
        let dt = if self.settings.static_analysis {
            self.model.t_end / self.settings.load_steps as f64
        } else {
            crate::model::time_step::time_step(&self.model, self.t).0
        };
        if dt >= rem * (1.0 - crate::model::time_step::LAST_STEP_REL) {
            rem
        } else {
            dt
        }
    }

    /// The Newmark parameters of a step of `dt`.
    fn newmark(&self, dt: f64) -> Newmark {
        Newmark {
            beta: self.settings.beta,
            gamma: self.settings.gamma,
            dt,
            is_static: self.settings.static_analysis,
        }
    }

    /// Δt of the last step taken (s).
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// One step, cutting Δt on failure. The time advances only on success.
    pub fn step(&mut self) -> std::result::Result<(), Fault> {
        self.initial_phase()?;
        if self.settings.consistent_start
            && self.steps == 0
            && self.t == 0.0
            && !self.settings.static_analysis
        {
            self.initial_acceleration()?;
        }
        let mut dt = self.planned_dt();
        let mut cuts = 0;
        loop {
            match self.attempt(dt) {
                Ok(()) => break,
                Err(fail) => {
                    if cuts >= self.settings.max_cuts {
                        return Err(match fail {
                            AttemptFail::Particle(f) if self.settings.max_cuts == 0 => f,
                            AttemptFail::Particle(f) => Fault {
                                particle: f.particle,
                                kind: FaultKind::NewtonDiverged {
                                    cuts,
                                    ratio: f64::NAN,
                                    iterate: Some(f.code()),
                                },
                            },
                            AttemptFail::Newton(ratio) => Fault {
                                particle: None,
                                kind: FaultKind::NewtonDiverged {
                                    cuts,
                                    ratio,
                                    iterate: None,
                                },
                            },
                        });
                    }
                    cuts += 1;
                    self.stats.cuts += 1;
                    dt *= 0.5;
                }
            }
        }
        let clock = Instant::now();
        self.convect();
        self.stats.seconds.convect += clock.elapsed().as_secs_f64();
        self.t = if self.model.t_end - (self.t + self.dt)
            <= crate::model::time_step::LAST_STEP_REL * self.dt
        {
            self.model.t_end
        } else {
            self.t + self.dt
        };
        self.steps += 1;
        Ok(())
    }

    /// Shape functions at the particles and the nodal mass, velocity and
    /// acceleration they map to the grid (lumped, eqs. 38–41).
    fn initial_phase(&mut self) -> std::result::Result<(), Fault> {
        let clock = Instant::now();
        let m = &mut self.model;
        // Moving regions where their velocity has taken them by the step's
        // start (the dofs below hold their nodes through the step).
        if matches!(self.nodes, Nodes::Grid) {
            let g = &m.grid;
            m.constraints.move_to(self.t, g.h, g.nx, g.ny);
        }
        let p = &mut m.particles;
        match &mut self.nodes {
            Nodes::Grid => {
                shape_eval::shape_eval(&m.shape, &m.grid, &p.x, &mut p.lambda, &mut self.cache)?
            }
            Nodes::Cloud(c) => c.shape_eval(&p.x, &mut self.cache)?,
        }
        self.node_mass.fill(0.0);
        self.node_v.fill([0.0; 2]);
        self.node_a.fill([0.0; 2]);
        for i in 0..p.len() {
            let (nodes, w) = self.cache.particle(i);
            let mass = p.mass[i];
            for (&n, wk) in nodes.iter().zip(w) {
                let n = n as usize;
                let mw = mass * wk[0];
                self.node_mass[n] += mw;
                for d in 0..2 {
                    self.node_v[n][d] += mw * p.v[i][d];
                    self.node_a[n][d] += mw * p.a[i][d];
                }
            }
        }
        for n in 0..self.node_mass.len() {
            let mass = self.node_mass[n];
            if mass > self.mass_eps {
                for d in 0..2 {
                    self.node_v[n][d] /= mass;
                    self.node_a[n][d] /= mass;
                }
            } else {
                self.node_v[n] = [0.0; 2];
                self.node_a[n] = [0.0; 2];
            }
        }
        // GMM's predictor reads the nodes' own state (Algorithm 2, step 1).
        if let Nodes::Cloud(c) = &self.nodes {
            self.node_v.copy_from_slice(&c.cloud.v);
            self.node_a.copy_from_slice(&c.cloud.a);
        }
        for i in 0..p.len() {
            self.start[i] = StepState {
                stress: p.stress[i],
                f: p.f.get(i).copied().unwrap_or([1.0, 0.0, 0.0, 1.0]),
                q: p.plastic.get(i).copied().unwrap_or([0.0; 4]),
            };
            self.volume[i] = p.volume(i);
        }
        let n = p.len();
        self.dofs = self.build_dofs();
        let mapped = Instant::now();
        self.stats.seconds.map += (mapped - clock).as_secs_f64();
        self.pairs = self.build_pairs();
        self.incidence = Incidence::new(&self.cache, &self.dofs, n);
        self.pattern = Some(Pattern::new(
            &self.cache,
            &self.dofs,
            n,
            &self.model.constraints.points,
            self.pattern.take(),
        )?);
        self.stats.seconds.symbolic += mapped.elapsed().as_secs_f64();
        Ok(())
    }

    /// With `solver.implicit_start = "consistent"`: the nodes'
    /// acceleration at t = 0 from the equations of motion,
    /// a₀ = (f_ext − f_int) / m_I (lumped; exact for a body force with
    /// either mass, since Σ_J M_IJ = m_I), in place of the particles'
    /// zero: started from a₀ = 0 the trapezoidal rule lags ½ a t² by
    /// ½ a Δt t for good (docs/methods.md, "Implicit integrator"). Held
    /// components start at 0; at a closed wall contact (gap ≤ 0) the push
    /// into the wall is taken out (the wall's reaction at t = 0 is what a
    /// rigid support would give) and the tangential part by Coulomb's
    /// law, all of it for `stick`, up to μ |a·n| for `friction`, none for
    /// `slip`. The particles take a₀ at their place (the trapezoid of
    /// their velocity update reads it), a GMM cloud's nodes their own.
    fn initial_acceleration(&mut self) -> std::result::Result<(), Fault> {
        let m = &self.model;
        let p = &m.particles;
        let body =
            crate::cpu::body_force(m.gravity, &m.manufactured, &m.external, &p.x0, &p.mass, 0.0);
        let body: Vec<[f64; 2]> = (0..p.len()).map(|i| body.at(i)).collect();
        let zero = vec![[0.0; 2]; self.du.len()];
        let inp = StepInputs {
            cache: &self.cache,
            model: m,
            volume: &self.volume,
            body: &body,
            start: &self.start,
            v: &self.node_v,
            a: &self.node_a,
            newmark: Newmark {
                is_static: true,
                ..self.newmark(1.0)
            },
            dofs: &self.dofs,
            penalty: self.penalty,
            pairs: &self.pairs,
            lumped_mass: true,
            point_target: &self.point_target,
            point_penalty: self.point_penalty,
        };
        let mut force = vec![[0.0; 2]; self.du.len()];
        assemble::residual(&inp, &zero, &mut self.iterates, &mut force)?;
        let mut a0 = vec![[0.0; 2]; force.len()];
        for (n, (a, f)) in a0.iter_mut().zip(&force).enumerate() {
            let mass = self.node_mass[n];
            if self.dofs.id[n] == NO_DOF || mass <= self.mass_eps {
                continue;
            }
            for c in 0..2 {
                if self.dofs.free(n, c) {
                    a[c] = f[c] / mass;
                }
            }
        }
        for pair in self.pairs.iter().filter(|p| p.gap <= 0.0) {
            let w = &m.walls.list[pair.wall as usize];
            let a = &mut a0[pair.node as usize];
            let nrm = w.normal;
            let an = a[0] * nrm[0] + a[1] * nrm[1];
            if an >= 0.0 {
                continue;
            }
            let t = [a[0] - an * nrm[0], a[1] - an * nrm[1]];
            let mag = t[0].hypot(t[1]);
            // Coulomb's law on the accelerations: a stick wall holds all
            // of the tangential part, a friction wall up to μ |a·n|.
            let mu = match w.contact {
                CONTACT_STICK => f64::INFINITY,
                CONTACT_FRICTION => w.mu,
                _ => 0.0,
            };
            let keep = match coulomb_slip(mag, an.abs(), mu) {
                Some(cap) => 1.0 - cap / mag,
                None => 0.0,
            };
            *a = [keep * t[0], keep * t[1]];
        }
        let p = &mut self.model.particles;
        for i in 0..p.len() {
            let (nodes, w) = self.cache.particle(i);
            let mut ap = [0.0; 2];
            for (&n, wk) in nodes.iter().zip(w) {
                ap[0] += wk[0] * a0[n as usize][0];
                ap[1] += wk[0] * a0[n as usize][1];
            }
            p.a[i] = ap;
        }
        if let Nodes::Cloud(c) = &mut self.nodes {
            c.cloud.a.copy_from_slice(&a0);
        }
        self.node_a = a0;
        Ok(())
    }

    /// The step's wall contacts: every unknown grid node behind a `slip`
    /// or `friction` wall (stick walls hold theirs instead), at gap 0; or
    /// the cloud's nodes near any wall (`GmmNodes::wall_pairs`).
    fn build_pairs(&self) -> Vec<ContactPair> {
        let walls = &self.model.walls;
        if let Nodes::Cloud(c) = &self.nodes {
            return c.wall_pairs(&self.model, &self.dofs, self.t);
        }
        let mut pairs = Vec::new();
        for (n, &mask) in walls.mask.iter().enumerate() {
            if mask == 0 || self.dofs.id[n] == NO_DOF {
                continue;
            }
            for (k, w) in walls.list.iter().enumerate() {
                if mask & (1 << k) != 0 && w.contact != CONTACT_STICK {
                    pairs.push(ContactPair {
                        node: n as u32,
                        wall: k as u32,
                        gap: 0.0,
                    });
                }
            }
        }
        pairs
    }

    /// The step's unknowns: nodes with mass, their held components
    /// (constraints and stick walls).
    fn build_dofs(&self) -> Dofs {
        let m = &self.model;
        let nodes = self.node_mass.len();
        let stick = |n: usize| {
            m.walls.mask.get(n).is_some_and(|&mask| {
                m.walls
                    .list
                    .iter()
                    .enumerate()
                    .any(|(k, w)| mask & (1 << k) != 0 && w.contact == CONTACT_STICK)
            })
        };
        let mut id = vec![NO_DOF; nodes];
        let mut held = vec![0u8; nodes];
        let mut active = 0u32;
        for n in 0..nodes {
            if self.node_mass[n] <= self.mass_eps {
                continue;
            }
            id[n] = active;
            active += 1;
            held[n] = match &self.nodes {
                Nodes::Cloud(c) => c.cloud.fix[n],
                Nodes::Grid if stick(n) => FIX_X | FIX_Y,
                Nodes::Grid => m.constraints.fix[n],
            };
        }
        Dofs {
            id,
            held,
            active: active as usize,
        }
    }

    /// Δu on held components (a prescribed velocity × Δt, trapezoidal in
    /// time; zero otherwise), the free ones zero: Newton's start.
    fn predict(&mut self, dt: f64) {
        self.du.fill([0.0; 2]);
        let groups = &self.model.constraints.groups;
        for (p, target) in self
            .model
            .constraints
            .points
            .iter()
            .zip(&mut self.point_target)
        {
            let g = &groups[p.group as usize];
            let (v0, v1) = (g.velocity_at(self.t), g.velocity_at(self.t + dt));
            *target = std::array::from_fn(|d| 0.5 * dt * (v0[d] + v1[d]));
        }
        for (k, g) in self.model.constraints.groups.iter().enumerate() {
            if !g.moves() {
                continue;
            }
            let (v0, v1) = (g.velocity_at(self.t), g.velocity_at(self.t + dt));
            for &n in group_nodes(&self.nodes, g, k) {
                for (d, bit) in [(0, FIX_X), (1, FIX_Y)] {
                    if g.fix & bit != 0 {
                        self.du[n as usize][d] = 0.5 * dt * (v0[d] + v1[d]);
                    }
                }
            }
        }
    }

    /// Body force per unit mass at the step's end (m/s²), times the load
    /// factor when static.
    fn fill_body(&mut self, dt: f64) {
        let m = &self.model;
        let p = &m.particles;
        let (t, factor) = if self.settings.static_analysis {
            (m.t_end, (self.t + dt) / m.t_end)
        } else {
            (self.t + dt, 1.0)
        };
        let body =
            crate::cpu::body_force(m.gravity, &m.manufactured, &m.external, &p.x0, &p.mass, t);
        for (i, b) in self.body.iter_mut().enumerate() {
            let v = body.at(i);
            *b = [factor * v[0], factor * v[1]];
        }
    }

    /// Newton on one step of `dt`; on success the converged iterate is in
    /// `du` and `iterates`, and `dt` is the step's.
    ///
    /// Wall contact is piecewise smooth (open, stick, slip), and Newton
    /// across its kinks can cycle: a light node behind the wall flips its
    /// slip direction, or opens and closes, at every iterate. So the
    /// contact states follow the iterate for the first
    /// `FREE_CONTACT_ITERATIONS` iterations only, then are held: Newton
    /// solves the smooth problem of the held states, and when that is
    /// solved (residual at most `newton_tol`) but Coulomb's law is not, the
    /// held states are revised (`contact::revise`) and Newton goes on.
    /// Convergence is always judged on Coulomb's law itself.
    fn attempt(&mut self, dt: f64) -> std::result::Result<(), AttemptFail> {
        self.fill_body(dt);
        self.predict(dt);
        let newmark = self.newmark(dt);
        let m = &self.model;
        let dofs = &self.dofs;
        let Some(pattern) = self.pattern.as_ref() else {
            return Err(AttemptFail::Newton(f64::NAN));
        };
        let inp = StepInputs {
            cache: &self.cache,
            model: m,
            volume: &self.volume,
            body: &self.body,
            start: &self.start,
            v: &self.node_v,
            a: &self.node_a,
            newmark,
            dofs,
            penalty: self.penalty,
            pairs: &self.pairs,
            lumped_mass: self.settings.lumped_mass,
            point_target: &self.point_target,
            point_penalty: self.point_penalty,
        };
        // The load's own size, |Σ_p N m_p b_p| over the free components.
        let mut fext = vec![[0.0f64; 2]; self.du.len()];
        for i in 0..m.particles.len() {
            let (nodes, w) = self.cache.particle(i);
            for (&n, wk) in nodes.iter().zip(w) {
                let mw = wk[0] * m.particles.mass[i];
                let f = &mut fext[n as usize];
                f[0] += mw * self.body[i][0];
                f[1] += mw * self.body[i][1];
            }
        }
        let free_norm = |r: &[[f64; 2]]| -> f64 {
            let mut s = 0.0;
            for (n, rn) in r.iter().enumerate() {
                for (c, v) in rn.iter().enumerate() {
                    if dofs.free(n, c) {
                        s += v * v;
                    }
                }
            }
            s.sqrt()
        };
        let load_norm = free_norm(&fext);
        let mut residuals = Vec::new();
        let mut corrections = Vec::new();
        let mut reference = 0.0;
        let mut last_correction = f64::INFINITY;
        let tol = self.settings.tol;
        let mut rhs = Mat::<f64>::zeros(dofs.count(), 1);
        let walls = m.walls.list.len();
        let slot = |p: &ContactPair| state_slot(p, walls);
        // `solver.newton_jacobian = "reuse"`: the factorization and the
        // contact states it was built with, and the residual ratio of the
        // iteration before.
        let mut kept: Option<(Lu<usize, f64>, Vec<ContactState>)> = None;
        let mut previous = f64::INFINITY;
        for iter in 0..=self.settings.max_iter {
            let clock = Instant::now();
            let res = assemble::residual(&inp, &self.du, &mut self.iterates, &mut self.r_body);
            self.stats.seconds.residual += clock.elapsed().as_secs_f64();
            res.map_err(AttemptFail::Particle)?;
            assemble::add_points(&inp, &self.du, &mut self.r_body, None);
            let clock = Instant::now();
            self.r.copy_from_slice(&self.r_body);
            assemble::add_contact(
                &inp,
                &self.du,
                None,
                &mut self.r,
                Some(&mut self.wall_force),
            );
            assemble::natural_states(&inp, &self.du, &mut self.natural);
            self.stats.seconds.residual += clock.elapsed().as_secs_f64();
            let norm = free_norm(&self.r);
            if iter == 0 {
                reference = norm.max(load_norm);
            }
            let rel = |norm: f64| {
                if reference > 0.0 {
                    norm / reference
                } else {
                    0.0
                }
            };
            let ratio = rel(norm);
            residuals.push(ratio);
            if !ratio.is_finite() || ratio > DIVERGED_RATIO {
                return Err(AttemptFail::Newton(ratio));
            }
            let converged = ratio <= tol && (iter == 0 || last_correction <= tol.sqrt());
            if converged || dofs.active == 0 {
                for (p, &st) in self.pairs.iter().zip(&self.natural) {
                    self.node_states[slot(p)] = st;
                }
                self.dt = dt;
                self.stats.steps += 1;
                self.stats.iterations += iter as u64;
                self.stats.max_iterations = self.stats.max_iterations.max(iter);
                self.stats.last_iterations = iter;
                self.stats.last_residuals = residuals;
                self.stats.last_corrections = corrections;
                return Ok(());
            }
            if iter == self.settings.max_iter {
                return Err(AttemptFail::Newton(ratio));
            }
            // The contact states this iteration's Newton step assumes: the
            // last step's first (Δu = 0 says nothing), open for a node off
            // the wall at the step's start (a GMM cloud node: gap > 0),
            // then the iterate's, then held, and revised once their own
            // problem is solved.
            if iter == 0 {
                self.held.clear();
                self.held.extend(self.pairs.iter().map(|p| {
                    if p.gap > 0.0 {
                        ContactState::Open
                    } else {
                        self.node_states[slot(p)]
                    }
                }));
            } else if iter < FREE_CONTACT_ITERATIONS {
                self.held.clone_from(&self.natural);
            }
            held_residual(&inp, &self.du, &self.held, &self.r_body, &mut self.r_held);
            if iter >= FREE_CONTACT_ITERATIONS && rel(free_norm(&self.r_held)) <= tol {
                for (h, &n) in self.held.iter_mut().zip(&self.natural) {
                    *h = contact::revise(*h, n);
                }
                held_residual(&inp, &self.du, &self.held, &self.r_body, &mut self.r_held);
            }
            // Modified Newton keeps the last factorization while the
            // contact states it was built with hold and it still converges
            // fast (the residual down fourfold in the last iteration).
            let reuse = self.settings.reuse_jacobian
                && ratio <= REUSE_CONTRACTION * previous
                && kept.as_ref().is_some_and(|(_, h)| *h == self.held);
            previous = ratio;
            let clock = Instant::now();
            if !reuse {
                let jac = assemble::jacobian(
                    &inp,
                    pattern,
                    &self.du,
                    &self.incidence,
                    &self.iterates,
                    &self.held,
                    &mut self.values,
                );
                let assembled = Instant::now();
                self.stats.seconds.jacobian += (assembled - clock).as_secs_f64();
                jac.map_err(AttemptFail::Particle)?;
                let k = SparseColMatRef::new(pattern.symbolic.as_ref(), &self.values);
                let lu = Lu::try_new_with_symbolic(pattern.lu.clone(), k);
                self.stats.seconds.factor += assembled.elapsed().as_secs_f64();
                self.stats.factorizations += 1;
                let lu = lu.map_err(|_| AttemptFail::Newton(ratio))?;
                kept = Some((lu, self.held.clone()));
            }
            let factored = Instant::now();
            let Some((lu, _)) = &kept else {
                unreachable!("factored above")
            };
            for (n, &id) in dofs.id.iter().enumerate() {
                if id == NO_DOF {
                    continue;
                }
                for c in 0..2 {
                    rhs[(2 * id as usize + c, 0)] = if dofs.free(n, c) {
                        self.r_held[n][c]
                    } else {
                        0.0
                    };
                }
            }
            lu.solve_in_place(rhs.as_mut());
            // The correction's size in the mass-weighted norm, so that a
            // node holding a sliver of a particle (which may move far for
            // the little it weighs) does not decide convergence.
            let (mut dn, mut un) = (0.0, 0.0);
            for (n, &id) in dofs.id.iter().enumerate() {
                if id == NO_DOF {
                    continue;
                }
                for c in 0..2 {
                    if dofs.free(n, c) {
                        let delta = rhs[(2 * id as usize + c, 0)];
                        if !delta.is_finite() {
                            return Err(AttemptFail::Newton(ratio));
                        }
                        self.du[n][c] += delta;
                        let mass = self.node_mass[n];
                        dn += mass * delta * delta;
                        un += mass * self.du[n][c] * self.du[n][c];
                    }
                }
            }
            self.stats.seconds.solve += factored.elapsed().as_secs_f64();
            // A zero increment with a zero correction has converged.
            last_correction = if un > 0.0 {
                (dn / un).sqrt()
            } else {
                dn.sqrt()
            };
            corrections.push(last_correction);
        }
        Err(AttemptFail::Newton(f64::NAN))
    }

    /// The nodes in wall contact at the next step (behind a `slip` or
    /// `friction` wall, with mass), one per contact: for tests.
    pub fn contact_nodes(&mut self) -> std::result::Result<Vec<usize>, Fault> {
        self.initial_phase()?;
        Ok(self.pairs.iter().map(|p| p.node as usize).collect())
    }

    /// Checks the assembled Jacobian against a central difference of the
    /// residual (a test of `assemble` and `contact`): at a step of `dt`
    /// from the current state, with Δu set to `du_of(node)` on the free
    /// components. The residual is Coulomb's law itself, the Jacobian that
    /// of the contact states at Δu, so a difference that crosses a state's
    /// edge shows as a mismatch (choose Δu away from them).
    pub fn jacobian_mismatch(
        &mut self,
        dt: f64,
        du_of: impl Fn(usize) -> [f64; 2],
        eps: f64,
    ) -> std::result::Result<JacobianCheck, Fault> {
        self.initial_phase()?;
        self.fill_body(dt);
        self.predict(dt);
        for n in 0..self.du.len() {
            for (c, d) in du_of(n).into_iter().enumerate() {
                if self.dofs.free(n, c) {
                    self.du[n][c] = d;
                }
            }
        }
        let newmark = self.newmark(dt);
        let m = &self.model;
        let pattern = self.pattern.as_ref().expect("initial_phase built it");
        let inp = StepInputs {
            cache: &self.cache,
            model: m,
            volume: &self.volume,
            body: &self.body,
            start: &self.start,
            v: &self.node_v,
            a: &self.node_a,
            newmark,
            dofs: &self.dofs,
            penalty: self.penalty,
            pairs: &self.pairs,
            lumped_mass: self.settings.lumped_mass,
            point_target: &self.point_target,
            point_penalty: self.point_penalty,
        };
        let mut its = self.iterates.clone();
        let mut wf = self.wall_force.clone();
        let residual = |du: &[[f64; 2]],
                        its: &mut [ParticleIterate],
                        r: &mut [[f64; 2]],
                        wf: &mut [[f64; 2]]| {
            assemble::residual(&inp, du, its, r).map(|()| {
                assemble::add_points(&inp, du, r, None);
                assemble::add_contact(&inp, du, None, r, Some(wf));
            })
        };
        residual(&self.du, &mut its, &mut self.r, &mut wf)?;
        assemble::natural_states(&inp, &self.du, &mut self.natural);
        assemble::jacobian(
            &inp,
            pattern,
            &self.du,
            &self.incidence,
            &its,
            &self.natural,
            &mut self.values,
        )?;
        let mut check = JacobianCheck::default();
        for st in &self.natural {
            match st {
                ContactState::Open => check.open += 1,
                ContactState::Stick => check.stick += 1,
                ContactState::Slip(_) => check.slip += 1,
            }
        }
        let nodes: Vec<usize> = (0..self.du.len())
            .filter(|&n| self.dofs.id[n] != NO_DOF)
            .collect();
        let (mut rp, mut rm) = (self.r.clone(), self.r.clone());
        let mut column = Vec::new();
        // A column's scale is at least the material's, 1 / PENALTY_REL of
        // the contact's: a column of a node that carries a sliver of mass
        // is then not held to the difference's round-off.
        let floor = self.values.iter().fold(0.0f64, |a, v| a.max(v.abs())) / assemble::PENALTY_REL;
        for &nb in &nodes {
            for k in 0..2 {
                if !self.dofs.free(nb, k) {
                    continue;
                }
                let mut du = self.du.clone();
                du[nb][k] += eps;
                residual(&du, &mut its, &mut rp, &mut wf)?;
                du[nb][k] -= 2.0 * eps;
                residual(&du, &mut its, &mut rm, &mut wf)?;
                // (assembled, difference) down column (nb, k).
                column.clear();
                for &na in &nodes {
                    for i in 0..2 {
                        if !self.dofs.free(na, i) {
                            continue;
                        }
                        let fd = -(rp[na][i] - rm[na][i]) / (2.0 * eps);
                        let (ia, ib) = (self.dofs.id[na], self.dofs.id[nb]);
                        let coupled = pattern.adj
                            [pattern.adj_start[ib as usize]..pattern.adj_start[ib as usize + 1]]
                            .binary_search(&ia)
                            .is_ok();
                        let k_ab = if coupled {
                            self.values[pattern.slot(ia, ib, i, k)]
                        } else {
                            0.0
                        };
                        column.push((k_ab, fd));
                    }
                }
                let scale = column.iter().fold(floor, |a, &(v, _)| a.max(v.abs()));
                for &(v, fd) in &column {
                    check.mismatch = check.mismatch.max((v - fd).abs() / scale);
                }
            }
        }
        Ok(check)
    }

    /// Particles take the converged grid solution (eqs. 46–49); reactions.
    fn convect(&mut self) {
        let (gamma, dt) = (self.settings.gamma, self.dt);
        let newmark = self.newmark(dt);
        let m = &mut self.model;
        let p = &mut m.particles;
        for i in 0..p.len() {
            let (nodes, w) = self.cache.particle(i);
            let (mut u, mut a) = ([0.0; 2], [0.0; 2]);
            for (&n, wk) in nodes.iter().zip(w) {
                let n = n as usize;
                let an = newmark.accel(self.du[n], self.node_v[n], self.node_a[n]);
                for d in 0..2 {
                    u[d] += wk[0] * self.du[n][d];
                    a[d] += wk[0] * an[d];
                }
            }
            let it = &self.iterates[i];
            for d in 0..2 {
                p.x[i][d] += u[d];
                if newmark.is_static {
                    p.v[i][d] = 0.0;
                    p.a[i][d] = 0.0;
                } else {
                    p.v[i][d] += dt * ((1.0 - gamma) * p.a[i][d] + gamma * a[d]);
                    p.a[i][d] = a[d];
                }
            }
            p.stress[i] = it.state.stress;
            p.rho[i] /= it.j;
            if let Some(f) = p.f.get_mut(i) {
                *f = it.state.f;
            }
            if let Some(q) = p.plastic.get_mut(i) {
                *q = it.state.q;
            }
        }
        // The support's reaction is minus the residual on its components.
        let groups = m.constraints.groups.len();
        for (k, (g, r)) in m
            .constraints
            .groups
            .iter()
            .zip(self.reactions.iter_mut())
            .enumerate()
        {
            *r = [0.0; 2];
            for &n in group_nodes(&self.nodes, g, k) {
                let n = n as usize;
                if g.fix & FIX_X != 0 {
                    r[0] -= self.r[n][0];
                }
                if g.fix & FIX_Y != 0 {
                    r[1] -= self.r[n][1];
                }
            }
        }
        // The points' penalty forces are the support's force on the body.
        for (p, target) in m.constraints.points.iter().zip(&self.point_target) {
            for (c, &t) in target.iter().enumerate() {
                if p.fix & (1 << c) != 0 {
                    let u: f64 = p
                        .nodes
                        .iter()
                        .zip(&p.n)
                        .map(|(&a, &w)| w * self.du[a as usize][c])
                        .sum();
                    self.reactions[p.group as usize][c] -= self.point_penalty * (u - t);
                }
            }
        }
        for (k, w) in m.walls.list.iter().enumerate() {
            let held_nodes = matches!(self.nodes, Nodes::Grid) && w.contact == CONTACT_STICK;
            self.reactions[groups + k] = if held_nodes {
                // Stick wall nodes are fixed: minus the residual there.
                let mut r = [0.0; 2];
                for &n in &w.nodes {
                    r[0] -= self.r[n as usize][0];
                    r[1] -= self.r[n as usize][1];
                }
                r
            } else {
                // The force on the wall: minus its force on the material.
                [-self.wall_force[k][0], -self.wall_force[k][1]]
            };
        }
        if let Nodes::Cloud(c) = &mut self.nodes {
            c.advance(&self.du, &self.dofs.id, &newmark);
            let walls = m.walls.list.len();
            for p in &self.pairs {
                let state = self.node_states[state_slot(p, walls)];
                c.persist_contact(p.node as usize, &m.walls.list[p.wall as usize], state);
            }
        }
    }
}

/// Where a contact pair's state is kept in `node_states` (one slot per
/// node and wall, `walls` walls).
fn state_slot(p: &ContactPair, walls: usize) -> usize {
    p.node as usize * walls + p.wall as usize
}

/// Constraint group `k`'s nodes in the step's node set.
fn group_nodes<'a>(nodes: &'a Nodes, g: &'a ConstraintGroup, k: usize) -> &'a [u32] {
    match nodes {
        Nodes::Grid => &g.nodes,
        Nodes::Cloud(c) => &c.cloud.groups[k],
    }
}

/// The residual under the held contact states: the particles' part plus
/// each contact's force in its held state.
fn held_residual(
    inp: &StepInputs,
    du: &[[f64; 2]],
    held: &[ContactState],
    r_body: &[[f64; 2]],
    r_held: &mut [[f64; 2]],
) {
    r_held.copy_from_slice(r_body);
    assemble::add_contact(inp, du, Some(held), r_held, None);
}

impl Backend for ImplicitBackend {
    fn name(&self) -> String {
        let method = match &self.nodes {
            Nodes::Grid => String::new(),
            Nodes::Cloud(c) => format!(" {}", c.label()),
        };
        format!(
            "cpu implicit{method} (f64, {} threads, faer sparse LU)",
            rayon::current_num_threads()
        )
    }

    fn time(&self) -> f64 {
        self.t
    }

    fn steps(&self) -> u64 {
        self.steps
    }

    fn advance(&mut self, t_stop: f64, stop: &AtomicBool) -> std::result::Result<(), Halt> {
        while !crate::model::time_step::stop_reached(self.t, t_stop, self.dt)
            && self.t < self.model.t_end
            && !stop_requested(stop)
        {
            self.step()?;
        }
        self.t = crate::model::time_step::settle_on_stop(self.t, t_stop, self.model.t_end, self.dt);
        Ok(())
    }

    fn advance_steps(&mut self, n: u64) -> std::result::Result<(), Halt> {
        for _ in 0..n {
            if self.t >= self.model.t_end {
                break;
            }
            self.step()?;
        }
        Ok(())
    }

    fn sample(&mut self) -> Result<Sample> {
        Ok(Sample {
            t: self.t,
            probes: crate::backend::probe_states(&self.model),
            energy: crate::cpu::energy::energy(&self.model),
            reactions: self.reactions.clone(),
            newton: Some(NewtonSample {
                iterations: self.stats.last_iterations,
                residual: self.stats.last_residuals.last().copied().unwrap_or(0.0),
                dt: self.dt,
            }),
        })
    }

    fn particles(&mut self) -> Result<&Particles> {
        Ok(&self.model.particles)
    }

    fn model(&self) -> &Model {
        &self.model
    }

    fn bytes_per_particle(&self) -> f64 {
        // The explicit path's particle and cache share, plus the step's
        // per-particle iterate and start state (~16 f64), plus the
        // Jacobian: about (2 nodes' worth of dofs per particle)² entries of
        // 8 bytes and a sparse LU a few times that (measured by
        // `bench`, not counted here).
        crate::cpu::CpuBackend::bytes_per_particle_of(&self.model) + 16.0 * 8.0
    }

    fn newton(&self) -> Option<&NewtonStats> {
        Some(&self.stats)
    }

    fn held_contacts(&self) -> Vec<u8> {
        self.node_states.iter().map(|&s| contact::code(s)).collect()
    }

    fn cloud_state(&self) -> Option<crate::backend::CloudState> {
        match &self.nodes {
            Nodes::Cloud(c) => Some(c.state()),
            Nodes::Grid => None,
        }
    }

    fn restore(&mut self, state: &State, steps: u64) -> Result<()> {
        crate::backend::check_state(&self.model, state)?;
        // `check_state` has matched the cloud to the scene's method.
        if let (Nodes::Cloud(c), Some(s)) = (&mut self.nodes, &state.cloud) {
            c.load(s).map_err(Error::Checkpoint)?;
        }
        // The contact states the next step starts from (none saved: a run
        // from before they were kept, or an explicit run's state).
        let held = if state.held_contacts.is_empty() {
            vec![ContactState::Stick; self.node_states.len()]
        } else if state.held_contacts.len() == self.node_states.len() {
            state
                .held_contacts
                .iter()
                .map(|&c| contact::from_code(c))
                .collect::<Option<Vec<_>>>()
                .ok_or_else(|| Error::Checkpoint("holds an unknown contact state".into()))?
        } else {
            return Err(Error::Checkpoint(format!(
                "holds {} wall contact states, the model has {} (nodes x walls)",
                state.held_contacts.len(),
                self.node_states.len()
            )));
        };
        self.node_states = held;
        self.model.particles = state.particles.clone();
        self.t = state.t;
        self.dt = state.dt;
        self.steps = steps;
        if let Some(stats) = &state.newton {
            self.stats = stats.clone();
        }
        Ok(())
    }
}
