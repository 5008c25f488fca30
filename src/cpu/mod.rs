//! The CPU reference path: f64, rayon across all cores, one file per pass
//! mirroring the WGSL twin of the same name (`shaders/wall_touch.wgsl` ↔
//! `wall_touch.rs`). A step is the plan's pass list (`StepPlan::cpu_step`),
//! each pass run by its twin (`CpuBackend::run_pass`, `CpuBackend::twin`).
//! Buffers are allocated once in `CpuBackend::new`; a step allocates
//! nothing.

pub mod cell_average;
pub mod cfl;
pub mod clear_grid;
pub mod constraint_points;
pub mod contact_conserve;
pub mod contact_detect;
pub mod contact_exchange;
pub mod contact_grad;
pub mod energy;
pub mod forces;
pub mod g2p;
pub mod g2p_p2g;
pub mod grid_update;
pub mod implicit;
pub mod isa;
pub mod mls;
pub mod p2g;
pub mod pore_flow;
pub mod remap;
pub mod scatter;
pub mod shape_eval;
pub mod stage_inputs;
pub mod stress;
pub mod wall_contact;
pub mod wall_touch;

use crate::backend::{Backend, Halt, Sample, State, stop_requested};
use crate::error::Result;
use crate::model::fault::Fault;
use crate::model::{Integrator, Model, Particles};
use crate::step::{Pass, Stage, StepPlan};
use scatter::Scatter;
pub(crate) use stage_inputs::body_force;
pub use stage_inputs::{ParticleWeights, Prepared, ShapeCache, Slices, Weights};
use std::sync::atomic::AtomicBool;

/// A pass's CPU twin (`CpuBackend::twin`).
pub type Twin = fn(&mut CpuBackend) -> std::result::Result<(), Fault>;

/// Runs a `Model` on the CPU.
pub struct CpuBackend {
    /// `advance` called from outside any rayon pool runs its steps on this
    /// pool of the global pool's size (made on first use), not on the
    /// global pool: a process running several simulations at once (the
    /// test harness) made each step's many small parallel loops queue
    /// behind the other simulation's work there (a test of 7 s alone took
    /// 38 s beside another).
    own_pool: Option<std::sync::Arc<rayon::ThreadPool>>,
    /// Read by `model()`; changed through `model_mut()`, which drops the
    /// next step's grid (`primed`).
    pub(crate) model: Model,
    /// What a step runs (`StepPlan::cpu_step`).
    pub plan: StepPlan,
    pub cache: ShapeCache,
    /// Per node: [mass, momentum or velocity x, y].
    pub mv: Vec<[f64; 3]>,
    /// Per node: force.
    pub force: Vec<[f64; 2]>,
    /// Per node: what g2p interpolates, [v, f/m] (`g2p::nodal`).
    nodal: Vec<[f64; 4]>,
    /// Per constraint group: reaction (N per unit thickness).
    pub reactions: Vec<[f64; 2]>,
    /// Per node: the weight of the particles in contact with a wall this
    /// step and their friction's weight, [S_I, T_I]
    /// (`wall_touch::wall_touch`); empty without walls.
    pub wall_touch: Vec<[f64; 2]>,
    /// Per node: the walls' forces this step (`wall_contact::wall_contact`);
    /// empty without walls.
    pub wall_force: Vec<[f64; 2]>,
    /// Per node: the walls' preloads this step (`wall_touch::wall_touch`);
    /// empty unless some particle starts with one (`Walls::preload`).
    pub wall_pre_force: Vec<[f64; 2]>,
    /// Per loaded platen: its velocity and acceleration this step
    /// (`grid_update::platen_totals`).
    platen_totals: Vec<[f64; 2]>,
    /// Contact pairs' normals and gaps this step; None without pairs.
    pub contact: Option<contact_detect::ContactState>,
    /// `p2g`'s (and `G2pP2g`'s) per-thread node sums.
    p2g_scatter: Scatter<5>,
    /// MUSL's remap.
    remap_scatter: Scatter<3>,
    force_scatter: Scatter<2>,
    /// Gauss points and fits when the scene asks for MLS reconstruction.
    pub mls: Option<mls::Mls>,
    /// `solver.mls_scope = "force"`: per particle, the strain-rate
    /// correction `Mls::strain_correction` (empty otherwise).
    mls_dl: Vec<[f64; 4]>,
    /// `solver.volumetric_strain = "cell_average"`: the cells' mean
    /// volumetric strain rate (`cell_average`); None otherwise.
    cell_average: Option<cell_average::CellAverage>,
    /// Saturated soil: the pore pressure's work space (`pore_flow`); None
    /// in a dry scene.
    pore_flow: Option<pore_flow::PoreFlow>,
    mass_eps: f64,
    t: f64,
    steps: u64,
    /// Time step of the step in progress (s).
    dt: f64,
    /// The step in progress lands on t_end.
    final_step: bool,
    /// The next step's Δt and last-step flag where the last step's
    /// `G2pP2g` already did its `Cfl`, `ClearGrid` and `P2g`: that step
    /// runs `StepPlan::cpu_primed`. Dropped whenever the particles may
    /// change from outside the steps (`model_mut`, `restore`,
    /// `set_time`, `run_stage_passes`) or a step fails.
    primed: Option<(f64, bool)>,
}

/// The particles' fields the walls' contact reads, and the scene's full
/// gravity (zero without).
fn contact_particles<'a>(
    p: &'a Particles,
    gravity: Option<&crate::model::Gravity>,
    line: Option<(&'a crate::model::shape::Shape, &'a crate::model::Grid)>,
) -> wall_touch::ContactParticles<'a> {
    wall_touch::ContactParticles {
        line,
        x: &p.x,
        mass: &p.mass,
        rho: &p.rho,
        stress: &p.stress,
        v: &p.v,
        gravity: gravity.map_or([0.0; 2], |g| g.g),
    }
}

/// The shape by which the walls' preloads are put on their lines
/// exactly: B-splines (whose first-order extrapolation to the line is off
/// by ½ d² ∂²N, enough to unbalance a geostatic column); the others keep
/// `face_weight` (exact for linear shapes; uGIMP holds as it is; LME
/// would need a Newton solve per point).
fn line_shape<'a>(
    shape: &'a crate::model::shape::Shape,
    grid: &'a crate::model::Grid,
) -> Option<(&'a crate::model::shape::Shape, &'a crate::model::Grid)> {
    match shape {
        crate::model::shape::Shape::Bspline(_) => Some((shape, grid)),
        _ => None,
    }
}

impl CpuBackend {
    pub fn new(model: Model) -> Self {
        let n = model.particles.len();
        let grid_nodes = model.grid.n_nodes();
        // One copy of the nodes per field (contact pairs), stacked.
        let nodes = grid_nodes * model.n_fields();
        let min_mass = model.particles.min_mass();
        CpuBackend {
            cache: ShapeCache::for_model(&model),
            mv: vec![[0.0; 3]; nodes],
            force: vec![[0.0; 2]; nodes],
            nodal: vec![[0.0; 4]; nodes],
            reactions: vec![[0.0; 2]; model.reaction_names().len()],
            wall_touch: if model.walls.is_empty() {
                Vec::new()
            } else {
                vec![[0.0; 2]; nodes]
            },
            wall_force: if model.walls.is_empty() {
                Vec::new()
            } else {
                vec![[0.0; 2]; nodes]
            },
            platen_totals: vec![[0.0; 2]; model.constraints.platens.len()],
            wall_pre_force: if model.walls.preload.is_empty() {
                Vec::new()
            } else {
                vec![[0.0; 2]; nodes]
            },
            contact: model
                .contact
                .as_ref()
                .map(|c| contact_detect::ContactState::new(c, grid_nodes, n)),
            p2g_scatter: Scatter::default(),
            remap_scatter: Scatter::default(),
            force_scatter: Scatter::default(),
            mls: model.mls.then(|| {
                let m = mls::Mls::new(&model.shape, &model.grid, n)
                    .expect("shape functions are defined at Gauss points inside a regular grid")
                    .with_support(model.mls_support);
                match model.mls_scope {
                    crate::scene::MlsScope::Force => m.for_force_correction(),
                    crate::scene::MlsScope::All => m,
                }
            }),
            mls_dl: if model.mls && model.mls_scope == crate::scene::MlsScope::Force {
                vec![[0.0; 4]; n]
            } else {
                Vec::new()
            },
            cell_average: model
                .cell_average_volumetric
                .then(|| cell_average::CellAverage::new(&model.grid, model.body_names.len(), n)),
            pore_flow: model
                .pore
                .as_ref()
                .map(|pore| pore_flow::PoreFlow::new(pore, model.grid.n_nodes())),
            mass_eps: grid_update::MASS_EPS_REL * min_mass,
            t: 0.0,
            steps: 0,
            dt: 0.0,
            final_step: false,
            primed: None,
            own_pool: None,
            plan: StepPlan::of(&model, false, false),
            model,
        }
    }

    /// Memory the CPU path holds per particle for `model` (bytes): the
    /// particle fields it uses, the shape cache, and the grid's share.
    pub fn bytes_per_particle_of(model: &Model) -> f64 {
        let p = &model.particles;
        let n = p.len().max(1) as f64;
        // x, v, x0 (16 each), mass, rho (8 each), stress (24), body (4).
        let mut per = 16.0 * 3.0 + 8.0 * 2.0 + 24.0 + 4.0;
        if !p.a.is_empty() {
            per += 16.0;
        }
        if !p.lambda.is_empty() {
            per += 16.0;
        }
        if !p.f.is_empty() {
            per += 32.0;
        }
        if !p.plastic.is_empty() {
            per += 32.0;
        }
        if model.external.is_some() {
            // Traction and point-load forces and their ramp times.
            per += 24.0;
        }
        if model.mls {
            // Sort order and cells per particle, the Gauss points' share
            // (position, weight, count, shape slots, and 13 f64 of fits:
            // coefficients 3, p2g 3, forces 5, remap 2).
            let slots = model.shape.max_nodes() as f64;
            let per_gp = 16.0 + 8.0 + 2.0 + slots * (4.0 + 24.0) + 8.0 * 13.0;
            per += 12.0
                + crate::model::gauss::gauss_points(&model.shape, &model.grid) as f64 * per_gp / n;
            if model.mls_scope == crate::scene::MlsScope::Force {
                // The fit at each particle, its c and flag; V_p L_p and ΔL
                // in binned order and in particle order; ω_g L(x_g).
                per += 49.0
                    + 3.0 * 32.0
                    + crate::model::gauss::gauss_points(&model.shape, &model.grid) as f64 * 32.0
                        / n;
            }
        }
        // Shape cache, when the scene stores one.
        per += ShapeCache::bytes_per_particle(model);
        // The cell average: tr L and its slot, the correction; per cell
        // and body two sums.
        if model.cell_average_volumetric {
            per += 16.0 + 32.0 + 16.0 * (model.grid.n_nodes() * model.body_names.len()) as f64 / n;
        }
        // Nodes: [m, qx, qy], [fx, fy] and g2p's [v, f/m] in f64; the walls' node mask,
        // contact weights, forces and node lists.
        let walls = if model.walls.is_empty() {
            0.0
        } else {
            (4.0 + 8.0 + 16.0) * model.grid.n_nodes() as f64
                + 4.0
                    * model
                        .walls
                        .list
                        .iter()
                        .map(|w| w.nodes.len())
                        .sum::<usize>() as f64
        };
        // Contact pairs: one copy of the nodes per field, and per field node
        // the mass gradient and volume (24) and the touched flag (1), per
        // pair node normal and gap (24); per particle the interface blend's
        // momentum (16, `contact_conserve`).
        let fields = model.n_fields() as f64;
        let pairs = model.contact.as_ref().map_or(0, |c| c.pairs.len()) as f64;
        let contact = if model.contact.is_some() {
            per += 16.0;
            model.grid.n_nodes() as f64 * (25.0 * fields + 24.0 * pairs)
        } else {
            0.0
        };
        per + (model.grid.n_nodes() as f64 * 72.0 * fields + walls + contact) / n
    }

    /// `Backend::advance`'s steps, on the calling thread's pool.
    fn advance_here(&mut self, t_stop: f64, stop: &AtomicBool) -> std::result::Result<(), Halt> {
        while !crate::model::time_step::stop_reached(self.t, t_stop, self.dt)
            && self.t < self.model.t_end
            && !stop_requested(stop)
        {
            if let Err(f) = self.step() {
                self.primed = None;
                return Err(f.into());
            }
        }
        self.t = crate::model::time_step::settle_on_stop(self.t, t_stop, self.model.t_end, self.dt);
        Ok(())
    }

    /// Time step the next `step` would take (s).
    pub fn next_dt(&self) -> f64 {
        cfl::time_step(&self.model, self.t).0
    }

    /// Time step of the step in progress, or of the last one (s).
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// The state as either backend can load it (a copy).
    pub fn state(&self) -> State {
        State {
            particles: self.model.particles.clone(),
            mv: self.mv.clone(),
            force: self.force.clone(),
            t: self.t,
            dt: self.dt,
            newton: None,
            held_contacts: Vec::new(),
            cloud: None,
        }
    }

    /// Sets the time reached (s), e.g. to check time-dependent loads at a
    /// chosen instant.
    pub fn set_time(&mut self, t: f64) {
        self.t = t;
        self.primed = None;
    }

    /// Whether the last step left the next one's grid (`G2pP2g`): `mv`
    /// then holds the next step's scatter, not this one's nodal solution.
    pub fn primed(&self) -> bool {
        self.primed.is_some()
    }

    /// Forgets the next step's grid, so the next step starts from the
    /// particles alone (`cpu_step`), as after a restore.
    pub fn unprime(&mut self) {
        self.primed = None;
    }

    /// The model, particles included.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The model to change between steps: the next step then starts from
    /// the particles alone (`unprime`), whatever it changes.
    pub fn model_mut(&mut self) -> &mut Model {
        self.primed = None;
        &mut self.model
    }

    /// One step: the plan's passes in order (`StepPlan::cpu_step`, some
    /// fused in one pass over the particles), each by its twin
    /// (`run_pass`). The time advances (`StepEnd`) only when every pass
    /// before it succeeded.
    pub fn step(&mut self) -> std::result::Result<(), Fault> {
        let primed = self.primed.take();
        if let Some(next) = primed {
            (self.dt, self.final_step) = next;
        }
        let n = if primed.is_some() {
            self.plan.cpu_primed.len()
        } else {
            self.plan.cpu_step.len()
        };
        for i in 0..n {
            let pass = if primed.is_some() {
                self.plan.cpu_primed[i]
            } else {
                self.plan.cpu_step[i]
            };
            if let Err(f) = self.run_pass(pass) {
                self.primed = None;
                return Err(f);
            }
        }
        Ok(())
    }

    /// Runs the plan's CPU passes of `stage` one by one, unfused
    /// (`StepPlan::cpu_passes_for`): what the parity tests compare with the
    /// GPU's passes of the same stage.
    pub fn run_stage_passes(&mut self, stage: Stage) -> std::result::Result<(), Fault> {
        self.primed = None;
        for pass in self.plan.cpu_passes_for(stage) {
            self.run_pass(pass)?;
        }
        Ok(())
    }

    /// Runs one pass of the plan by its CPU twin.
    ///
    /// # Panics
    /// On a pass the CPU does not run (`step::OnCpu` other than `Twin`):
    /// the plan never lists one (`tests/plan_coverage.rs`).
    pub fn run_pass(&mut self, pass: Pass) -> std::result::Result<(), Fault> {
        match Self::twin(pass) {
            Some(twin) => twin(self),
            None => panic!("{pass:?} has no CPU twin ({:?})", pass.info().cpu),
        }
    }

    /// The CPU twin of `pass`, None for a pass the CPU does not run
    /// (`Pass::info` says why). The GPU's variants of one pass (gather,
    /// per bin) share its twin.
    pub fn twin(pass: Pass) -> Option<Twin> {
        Some(match pass {
            Pass::Cfl => Self::cfl,
            Pass::ClearGrid => Self::clear_grid,
            Pass::ShapeEval => Self::shape_eval,
            Pass::ShapeEvalP2g => Self::shape_eval_p2g,
            Pass::P2g | Pass::P2gGather | Pass::P2gPatch => Self::p2g,
            Pass::MlsP2g => Self::mls_p2g,
            Pass::WallTouch => Self::wall_touch,
            Pass::ContactGrad => Self::contact_grad,
            Pass::ContactDetect => Self::contact_detect,
            Pass::GridPredict => Self::grid_predict,
            Pass::ConstraintPoints => Self::constraint_points,
            Pass::ContactExchange => Self::contact_exchange,
            Pass::MlsFitGauss => Self::mls_fit,
            Pass::MlsStrain => Self::mls_strain,
            Pass::CellAverage => Self::cell_average,
            Pass::PoreFlow => Self::pore_flow,
            Pass::Stress => Self::stress,
            Pass::StressForces | Pass::StressForcesPatch => Self::stress_forces,
            Pass::Forces | Pass::ForcesGather | Pass::ForcesPatch => Self::forces,
            Pass::MlsForces => Self::mls_forces,
            Pass::WallContact => Self::wall_contact,
            Pass::GridCorrect => Self::grid_correct,
            Pass::ConstraintPointsForce => Self::constraint_points_force,
            Pass::ContactExchangeForce => Self::contact_exchange_force,
            Pass::G2p => Self::g2p,
            Pass::G2pP2g => Self::g2p_p2g,
            Pass::ContactConserve => Self::contact_conserve,
            Pass::RemapClear => Self::remap_clear,
            Pass::Remap => Self::remap,
            Pass::MlsRemap => Self::mls_remap,
            Pass::StepEnd => Self::step_end,
            Pass::StepBegin
            | Pass::LmeNewton
            | Pass::BinClear
            | Pass::BinCount
            | Pass::BinScan
            | Pass::BinFill
            | Pass::MlsFitParticles
            | Pass::MlsForceGauss
            | Pass::MlsGradGauss
            | Pass::MlsGradParticles
            | Pass::CellAverageClear
            | Pass::Probes
            | Pass::Energy => return None,
        })
    }

    /// Factor of a_p in p2g's predicted momentum: (1 − γ)Δt for NPC, 0 for FE and MUSL.
    fn p2g_accel(&self) -> f64 {
        self.p2g_accel_for(self.dt)
    }

    /// `p2g_accel` for a step of `dt`.
    fn p2g_accel_for(&self, dt: f64) -> f64 {
        match self.model.integrator {
            Integrator::Fe | Integrator::Musl => 0.0,
            Integrator::Npc { gamma, .. } => (1.0 - gamma) * dt,
            // Implicit models run on `implicit::ImplicitBackend`, never here.
            Integrator::Implicit(_) => 0.0,
        }
    }

    /// γ of the corrector: NPC's, 1 for FE and MUSL.
    fn gamma(&self) -> f64 {
        match self.model.integrator {
            Integrator::Fe | Integrator::Musl | Integrator::Implicit(_) => 1.0,
            Integrator::Npc { gamma, .. } => gamma,
        }
    }

    /// The forces' loads' time: at the step's end where the stress already
    /// is (update stress first), at its start for MUSL (σ^t, b^t: eq. 24).
    fn t_load(&self) -> f64 {
        if self.model.integrator == Integrator::Musl {
            self.t
        } else {
            self.t + self.dt
        }
    }

    fn cfl(&mut self) -> std::result::Result<(), Fault> {
        (self.dt, self.final_step) = cfl::time_step(&self.model, self.t);
        Ok(())
    }

    fn clear_grid(&mut self) -> std::result::Result<(), Fault> {
        clear_grid::clear_grid(&mut self.mv, &mut self.force);
        Ok(())
    }

    /// N, ∇N into the shape cache, then with contact pairs each particle's
    /// nodes moved into its body's field.
    fn shape_eval(&mut self) -> std::result::Result<(), Fault> {
        let m = &mut self.model;
        let p = &mut m.particles;
        // Passes run one by one store the weights even where a whole
        // step evaluates them on the spot (allocated here, once; then
        // every shape evaluation fills the cache).
        if !self.cache.is_stored(p.len()) {
            self.cache = ShapeCache::new(p.len(), m.shape.max_nodes());
        }
        shape_eval::shape_eval(&m.shape, &m.grid, &p.x, &mut p.lambda, &mut self.cache)?;
        if let Some(c) = &m.contact {
            contact_grad::offset_nodes(&mut self.cache, &p.body, c, m.grid.n_nodes());
        }
        Ok(())
    }

    /// Passes `shape_eval` and `p2g` fused (`shape_eval::shape_eval_p2g`).
    fn shape_eval_p2g(&mut self) -> std::result::Result<(), Fault> {
        let a_factor = self.p2g_accel();
        let m = &mut self.model;
        let p = &mut m.particles;
        shape_eval::shape_eval_p2g(
            &m.shape,
            &m.grid,
            &p.x,
            &mut p.lambda,
            &mut self.cache,
            &p.mass,
            &p.v,
            &p.a,
            a_factor,
            &mut self.mv,
            &mut self.p2g_scatter,
        )
    }

    fn p2g(&mut self) -> std::result::Result<(), Fault> {
        let a_factor = self.p2g_accel();
        let m = &self.model;
        let p = &m.particles;
        p2g::p2g(
            Weights::of(&self.cache, p.len(), &m.shape, &m.grid),
            &p.x,
            &p.mass,
            &p.v,
            &p.a,
            a_factor,
            &mut self.mv,
            &mut self.p2g_scatter,
        )
    }

    fn mls_p2g(&mut self) -> std::result::Result<(), Fault> {
        let a_factor = self.p2g_accel();
        let (m, p) = (&self.model, &self.model.particles);
        match self.mls.as_mut() {
            Some(mls) => mls.p2g(&m.grid, &p.x, &p.rho, &p.v, &p.a, a_factor, &mut self.mv),
            None => Ok(()),
        }
    }

    fn wall_touch(&mut self) -> std::result::Result<(), Fault> {
        let m = &self.model;
        wall_touch::wall_touch(
            &self.cache,
            &contact_particles(
                &m.particles,
                m.gravity.as_ref(),
                line_shape(&m.shape, &m.grid),
            ),
            &m.walls,
            self.t,
            &mut self.wall_touch,
            &mut self.wall_pre_force,
        );
        Ok(())
    }

    fn contact_grad(&mut self) -> std::result::Result<(), Fault> {
        let (m, p) = (&self.model, &self.model.particles);
        if let (Some(c), Some(st)) = (&m.contact, &mut self.contact) {
            contact_grad::grad(&self.cache, &p.mass, &p.rho, &p.body, c, st);
        }
        Ok(())
    }

    fn contact_detect(&mut self) -> std::result::Result<(), Fault> {
        let (m, p) = (&self.model, &self.model.particles);
        if let (Some(c), Some(st)) = (&m.contact, &mut self.contact) {
            contact_detect::detect(
                &self.cache,
                &p.x,
                &p.mass,
                &p.rho,
                &p.body,
                c,
                &self.mv,
                m.grid.n_nodes(),
                self.mass_eps,
                st,
            );
        }
        Ok(())
    }

    /// The predictor's nodal rule, after P2G and after MUSL's remap:
    /// moving regions where their velocity has taken them by the step's
    /// end (the time their velocity is taken at), then the nodes'
    /// velocities and Dirichlet conditions.
    fn grid_predict(&mut self) -> std::result::Result<(), Fault> {
        let m = &mut self.model;
        let g = &m.grid;
        m.constraints.move_to(self.t + self.dt, g.h, g.nx, g.ny);
        let c = &m.constraints;
        grid_update::predict(
            &mut self.mv,
            &c.fix,
            &c.groups,
            self.t + self.dt,
            self.mass_eps,
        );
        grid_update::platens(&mut self.mv, &c.platens, self.mass_eps);
        Ok(())
    }

    fn constraint_points(&mut self) -> std::result::Result<(), Fault> {
        let c = &self.model.constraints;
        constraint_points::hold(
            &mut self.mv,
            &c.fix,
            &c.points,
            &c.groups,
            self.t + self.dt,
            self.mass_eps,
            None,
        );
        Ok(())
    }

    /// The contact pairs' exchange on the velocities, with the contacts
    /// `contact_detect` found (after MUSL's remap, those of the step's start).
    fn contact_exchange(&mut self) -> std::result::Result<(), Fault> {
        let m = &self.model;
        if let (Some(pairs), Some(st)) = (&m.contact, &self.contact) {
            contact_exchange::exchange(
                pairs,
                st,
                &mut self.mv,
                &m.constraints.fix,
                self.mass_eps,
                None,
            );
        }
        Ok(())
    }

    /// `solver.mls_scope = "force"`: σ fitted at the Gauss points and
    /// particles (`Mls::fit_stress`).
    fn mls_fit(&mut self) -> std::result::Result<(), Fault> {
        let (m, p) = (&self.model, &self.model.particles);
        if let Some(mls) = self.mls.as_mut() {
            mls.fit_stress(&m.grid, &p.x, &p.stress);
        }
        Ok(())
    }

    /// `solver.mls_scope = "force"`: each particle's strain-rate correction
    /// (`Mls::strain_correction`), which `stress` adds to L_p.
    fn mls_strain(&mut self) -> std::result::Result<(), Fault> {
        let (m, p) = (&self.model, &self.model.particles);
        if let Some(mls) = self.mls.as_mut() {
            mls.strain_correction(
                &m.grid,
                &self.cache,
                &self.mv,
                &p.mass,
                &p.rho,
                &mut self.mls_dl,
            );
        }
        Ok(())
    }

    /// `solver.volumetric_strain = "cell_average"`: the cells' mean
    /// volumetric strain rate, which `stress` puts in place of each
    /// particle's own.
    fn cell_average(&mut self) -> std::result::Result<(), Fault> {
        let (m, p) = (&self.model, &self.model.particles);
        if let Some(ca) = &mut self.cell_average {
            ca.update(
                &m.grid,
                &self.cache,
                &self.mv,
                &p.x,
                &p.mass,
                &p.rho,
                &p.body,
            );
        }
        Ok(())
    }

    /// The stress, L_p corrected by the cell average or by MLS's strain
    /// correction where the scene has one (stress.wgsl built with
    /// CELL_AVERAGE or MLS_FORCE).
    fn stress(&mut self) -> std::result::Result<(), Fault> {
        let m = &mut self.model;
        let p = &mut m.particles;
        let dl = match &self.cell_average {
            Some(ca) => &ca.dl,
            None => &self.mls_dl,
        };
        stress::stress(
            Weights::of(&self.cache, p.len(), &m.shape, &m.grid),
            &p.x,
            &self.mv,
            self.dt,
            &p.body,
            &m.materials,
            &m.body_material,
            &mut p.stress,
            &mut p.rho,
            &mut p.f,
            &mut p.plastic,
            dl,
        )
    }

    /// Saturated soil: the pore pressure over the step (`pore_flow`), from
    /// the velocities the stress took.
    fn pore_flow(&mut self) -> std::result::Result<(), Fault> {
        let t_load = self.t_load();
        let m = &mut self.model;
        let (Some(pore), Some(flow)) = (&m.pore, &mut self.pore_flow) else {
            return Ok(());
        };
        let p = &mut m.particles;
        let (body_material, body, x0) = (&m.body_material, &p.body, &p.x0);
        let fluid = |i: usize| {
            let b = body[i] as usize;
            pore.particle_fluid(body_material[b] as usize, b, x0[i][1])
        };
        let dl = match &self.cell_average {
            Some(ca) => &ca.dl[..],
            None => &[],
        };
        let inp = pore_flow::PoreInputs {
            x: &p.x,
            mv: &self.mv,
            mass: &p.mass,
            rho: &p.rho,
            fluid: &fluid,
            dl,
            g: m.gravity.map_or([0.0; 2], |g| g.at(t_load)),
            dt: self.dt,
        };
        flow.update(
            Weights::of(&self.cache, p.len(), &m.shape, &m.grid),
            &inp,
            pore.nodal_volumetric,
            &mut p.pore_pressure,
        );
        Ok(())
    }

    /// Passes `stress` and `forces` fused (`stress::stress_forces`).
    fn stress_forces(&mut self) -> std::result::Result<(), Fault> {
        let m = &mut self.model;
        let p = &mut m.particles;
        // The stress is at the step's end (t + Δt), so are the loads.
        let body = body_force(
            m.gravity,
            &m.manufactured,
            &m.external,
            &p.x0,
            &p.mass,
            self.t + self.dt,
        );
        stress::stress_forces(
            Weights::of(&self.cache, p.len(), &m.shape, &m.grid),
            &p.x,
            &self.mv,
            self.dt,
            &p.body,
            &m.materials,
            &m.body_material,
            &p.mass,
            &body,
            &mut p.stress,
            &mut p.rho,
            &mut p.f,
            &mut p.plastic,
            &mut self.force,
            &mut self.force_scatter,
        )
    }

    /// The internal and external forces at the particles; with
    /// `solver.mls_scope = "force"` corrected by the fit (`mls_fit`) and
    /// with the Gauss points' share (forces.wgsl built with MLS_FORCE,
    /// then mls_force_gauss.wgsl).
    fn forces(&mut self) -> std::result::Result<(), Fault> {
        let t_load = self.t_load();
        let m = &self.model;
        let p = &m.particles;
        let body = body_force(
            m.gravity,
            &m.manufactured,
            &m.external,
            &p.x0,
            &p.mass,
            t_load,
        );
        match self.mls.as_mut().filter(|_| self.plan.inputs.mls_force) {
            Some(mls) => mls.corrected_forces(
                &self.cache,
                &p.stress,
                &p.mass,
                &p.rho,
                &|i| body.at(i),
                &mut self.force,
                &mut self.force_scatter,
            ),
            None => forces::forces(
                Weights::of(&self.cache, p.len(), &m.shape, &m.grid),
                &p.x,
                &p.stress,
                &p.pore_pressure,
                &p.mass,
                &p.rho,
                &body,
                &mut self.force,
                &mut self.force_scatter,
            )?,
        }
        Ok(())
    }

    fn mls_forces(&mut self) -> std::result::Result<(), Fault> {
        let t_load = self.t_load();
        let m = &self.model;
        let p = &m.particles;
        let body = body_force(
            m.gravity,
            &m.manufactured,
            &m.external,
            &p.x0,
            &p.mass,
            t_load,
        );
        if let Some(mls) = self.mls.as_mut() {
            mls.forces(
                &m.grid,
                &p.x,
                &p.rho,
                &p.stress,
                &|i| body.at(i),
                &mut self.force,
            );
        }
        Ok(())
    }

    fn wall_contact(&mut self) -> std::result::Result<(), Fault> {
        let gamma = self.gamma();
        let (dt, t, mass_eps) = (self.dt, self.t, self.mass_eps);
        let (groups, walls) = (
            self.model.constraints.groups.len(),
            self.model.walls.list.len(),
        );
        let wall_r = &mut self.reactions[groups..groups + walls];
        let m = &self.model;
        wall_contact::wall_contact(
            &self.cache,
            &contact_particles(
                &m.particles,
                m.gravity.as_ref(),
                line_shape(&m.shape, &m.grid),
            ),
            &self.mv,
            &self.force,
            &m.walls,
            t,
            &self.wall_touch,
            &self.wall_pre_force,
            &mut self.wall_force,
            wall_r,
            gamma * dt,
            (2.0 - gamma) * dt,
            mass_eps,
        );
        Ok(())
    }

    fn grid_correct(&mut self) -> std::result::Result<(), Fault> {
        let gamma_dt = self.gamma() * self.dt;
        let groups = self.model.constraints.groups.len();
        let group_r = &mut self.reactions[..groups];
        let m = &self.model;
        let platens = &m.constraints.platens;
        grid_update::platen_totals(
            &self.mv,
            &self.force,
            &self.wall_force,
            platens,
            self.t + self.dt,
            m.local_damping,
            self.mass_eps,
            &mut self.platen_totals,
        );
        grid_update::correct(
            &mut self.mv,
            &mut self.force,
            &m.constraints.fix,
            &m.constraints.groups,
            &self.wall_force,
            group_r,
            gamma_dt,
            m.local_damping,
            self.mass_eps,
        );
        grid_update::platens_correct(
            &mut self.mv,
            &mut self.force,
            platens,
            &self.platen_totals,
            gamma_dt,
            self.mass_eps,
        );
        Ok(())
    }

    /// The constraint points' projection as forces, into the groups'
    /// reactions.
    fn constraint_points_force(&mut self) -> std::result::Result<(), Fault> {
        let gamma_dt = self.gamma() * self.dt;
        let groups = self.model.constraints.groups.len();
        let group_r = &mut self.reactions[..groups];
        let c = &self.model.constraints;
        constraint_points::hold(
            &mut self.mv,
            &c.fix,
            &c.points,
            &c.groups,
            self.t + self.dt,
            self.mass_eps,
            Some(constraint_points::AsForce {
                force: &mut self.force,
                reactions: group_r,
                gamma_dt,
            }),
        );
        Ok(())
    }

    /// The contact pairs' exchange as forces, into the pairs' reactions.
    fn contact_exchange_force(&mut self) -> std::result::Result<(), Fault> {
        let gamma_dt = self.gamma() * self.dt;
        let m = &self.model;
        let fixed = m.constraints.groups.len() + m.walls.list.len();
        if let (Some(c), Some(st)) = (&m.contact, &self.contact) {
            contact_exchange::exchange(
                c,
                st,
                &mut self.mv,
                &m.constraints.fix,
                self.mass_eps,
                Some(contact_exchange::AsForce {
                    force: &mut self.force,
                    gamma_dt,
                    reactions: &mut self.reactions[fixed..],
                }),
            );
        }
        Ok(())
    }

    fn g2p(&mut self) -> std::result::Result<(), Fault> {
        let m = &mut self.model;
        let p = &mut m.particles;
        let prm = g2p::G2pParams {
            dt: self.dt,
            integrator: m.integrator,
            edge_margin: m.shape.edge_margin(m.grid.h),
            pic_fraction: m.pic_fraction,
        };
        g2p::nodal(&self.mv, &self.force, self.mass_eps, &mut self.nodal);
        g2p::g2p(
            Weights::of(&self.cache, p.len(), &m.shape, &m.grid),
            &self.nodal,
            &m.grid,
            prm,
            self.contact
                .as_mut()
                .map(|c| (&c.touched[..], &p.mass[..], &mut c.pic_dp[..])),
            &mut p.x,
            &mut p.v,
            &mut p.a,
        )
    }

    /// `g2p`, then the next step's `cfl`, `clear_grid` and `p2g` in the
    /// same loop (`g2p_p2g`): leaves the next step's grid and Δt
    /// (`primed`).
    fn g2p_p2g(&mut self) -> std::result::Result<(), Fault> {
        debug_assert!(!self.cache.is_stored(self.model.particles.len()));
        let m = &mut self.model;
        let p = &mut m.particles;
        let prm = g2p::G2pParams {
            dt: self.dt,
            integrator: m.integrator,
            edge_margin: m.shape.edge_margin(m.grid.h),
            pic_fraction: m.pic_fraction,
        };
        g2p::nodal(&self.mv, &self.force, self.mass_eps, &mut self.nodal);
        let speed = g2p_p2g::SpeedInputs {
            materials: &m.materials,
            body_material: &m.body_material,
            body: &p.body,
            rho: &p.rho,
            stress: &p.stress,
            plastic: &p.plastic,
            mass: &p.mass,
            fixed_dt: m.fixed_dt.is_some(),
        };
        let (c, used) = g2p_p2g::g2p_p2g(
            Weights::of(&self.cache, p.x.len(), &m.shape, &m.grid),
            &self.nodal,
            &m.grid,
            prm,
            &speed,
            &mut p.x,
            &mut p.v,
            &mut p.a,
            self.mv.len(),
            &mut self.p2g_scatter,
        )?;
        // The next step's `cfl` (as `cfl::time_step` at the time `StepEnd`
        // commits), `clear_grid` and the end of its `p2g`.
        let t_next = if self.final_step {
            self.model.t_end
        } else {
            self.t + self.dt
        };
        let next = crate::model::time_step::step_of(&self.model, c, t_next);
        let a_factor = self.p2g_accel_for(next.0);
        if !self.model.particles.x.is_empty() {
            self.p2g_scatter
                .reduce_map(&mut self.mv, used, |s| p2g::combine(s, a_factor));
        }
        self.force.fill([0.0; 2]);
        self.primed = Some(next);
        Ok(())
    }

    /// Contact pairs, after `g2p`: each field's momentum as it was before
    /// the interface's PIC share (`contact_conserve::conserve`).
    fn contact_conserve(&mut self) -> std::result::Result<(), Fault> {
        let m = &mut self.model;
        let p = &mut m.particles;
        if let (Some(c), Some(st)) = (&m.contact, &mut self.contact) {
            contact_conserve::conserve(c, st, &p.mass, &p.body, &mut p.v);
        }
        Ok(())
    }

    /// MUSL's remap, first: the nodal momentum zeroed, the masses kept.
    fn remap_clear(&mut self) -> std::result::Result<(), Fault> {
        remap::clear_momentum(&mut self.mv);
        Ok(())
    }

    fn remap(&mut self) -> std::result::Result<(), Fault> {
        let p = &self.model.particles;
        remap::remap(
            &self.cache,
            &p.mass,
            &p.v,
            &mut self.mv,
            &mut self.remap_scatter,
        );
        Ok(())
    }

    fn mls_remap(&mut self) -> std::result::Result<(), Fault> {
        let (m, p) = (&self.model, &self.model.particles);
        if let Some(mls) = self.mls.as_mut() {
            mls.remap(&m.grid, &p.rho, &p.v, &mut self.mv);
        }
        Ok(())
    }

    /// The step's time committed (on t_end for the last step) and counted.
    fn step_end(&mut self) -> std::result::Result<(), Fault> {
        self.t = if self.final_step {
            self.model.t_end
        } else {
            self.t + self.dt
        };
        self.steps += 1;
        Ok(())
    }
}

impl Backend for CpuBackend {
    fn name(&self) -> String {
        format!(
            "cpu (f64, {} threads, {})",
            rayon::current_num_threads(),
            isa::name()
        )
    }

    fn time(&self) -> f64 {
        self.t
    }

    fn steps(&self) -> u64 {
        self.steps
    }

    fn advance(&mut self, t_stop: f64, stop: &AtomicBool) -> std::result::Result<(), Halt> {
        if rayon::current_thread_index().is_none() {
            if self.own_pool.is_none() {
                self.own_pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(rayon::current_num_threads())
                    .build()
                    .ok()
                    .map(std::sync::Arc::new);
            }
            if let Some(pool) = self.own_pool.clone() {
                return pool.install(|| self.advance_here(t_stop, stop));
            }
        }
        self.advance_here(t_stop, stop)
    }

    fn advance_steps(&mut self, n: u64) -> std::result::Result<(), Halt> {
        for _ in 0..n {
            if self.t >= self.model.t_end {
                break;
            }
            if let Err(f) = self.step() {
                self.primed = None;
                return Err(f.into());
            }
        }
        Ok(())
    }

    fn sample(&mut self) -> Result<Sample> {
        Ok(Sample {
            t: self.t,
            probes: crate::backend::probe_states(&self.model),
            energy: energy::energy(&self.model),
            reactions: self.reactions.clone(),
            newton: None,
        })
    }

    fn particles(&mut self) -> Result<&Particles> {
        Ok(&self.model.particles)
    }

    fn model(&self) -> &Model {
        &self.model
    }

    fn bytes_per_particle(&self) -> f64 {
        CpuBackend::bytes_per_particle_of(&self.model)
    }

    fn restore(&mut self, state: &State, steps: u64) -> Result<()> {
        crate::backend::check_state(&self.model, state)?;
        self.model.particles = state.particles.clone();
        self.mv.clone_from(&state.mv);
        self.force.clone_from(&state.force);
        self.t = state.t;
        self.dt = state.dt;
        self.steps = steps;
        self.final_step = false;
        self.primed = None;
        Ok(())
    }
}
