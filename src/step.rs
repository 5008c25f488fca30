//! The step plan: which stages run for a scene, in what order, which of
//! them fuse into one pass over the particles, and which GPU passes do each
//! (`StepPlan`), built once from the model and read by both backends and
//! the driver. Nothing else decides it: each pass is described once
//! (`passes!`: its WGSL file, domain and flags, what the CPU does with it),
//! the stages' passes are listed once (`StepPlan::stage_passes`), the CPU
//! backend runs `StepPlan::cpu_step` pass by pass, the GPU backend records
//! `StepPlan::gpu_step` and builds the pipelines of `StepPlan::gpu_passes`.
//!
//! The stage list is the paper's Algorithm 1 (`STEP`; FE and NPC share it
//! and differ in parameters only: NPC predicts with (1 − γ)Δt a_p in `p2g`
//! and corrects with γΔt f/m, FE has no acceleration term and corrects with
//! Δt f/m); MUSL (the B-spline paper's update) orders the stages
//! differently, `STEP_MUSL`: forces from the stress at the step's start,
//! the particle update, a remap of the new velocities to the nodes, and the
//! stress last.

use crate::model::shape::Shape;
use crate::model::{Integrator, Model};
use crate::scene::MlsScope;

/// One stage of a step. Each has a CPU twin `src/cpu/<name>.rs` and a
/// WGSL twin `shaders/<name>.wgsl` of the same name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Δt from the Courant condition (eq. 43).
    Cfl,
    /// Zero nodal accumulators.
    ClearGrid,
    /// N, ∇N at every particle (LME: Newton on λ).
    ShapeEval,
    /// Scatter mass and (predicted) momentum.
    P2g,
    /// Nodal velocities and Dirichlet conditions.
    GridPredict,
    /// Strain increment, density and stress.
    Stress,
    /// Internal and external nodal forces.
    Forces,
    /// Reactions, fixed components, corrector.
    GridCorrect,
    /// Particle update.
    G2p,
    /// MUSL: the updated particle velocities mapped back to the nodes with
    /// the step's start weights (by MLS with `solver.mls`, eqs. 31–33),
    /// then the nodal velocities and Dirichlet conditions as in `GridPredict`.
    Remap,
}

/// The stages of one step, in order.
pub const STEP: &[Stage] = &[
    Stage::Cfl,
    Stage::ClearGrid,
    Stage::ShapeEval,
    Stage::P2g,
    Stage::GridPredict,
    Stage::Stress,
    Stage::Forces,
    Stage::GridCorrect,
    Stage::G2p,
];

/// The stages of one MUSL step (B-spline paper eqs. 18–37), in order:
/// projection at t (18–25), forces from σ^t, nodal momentum update (28),
/// FLIP velocity and position (29–30), remap (31–33), and the velocity
/// gradient, F, density and stress from the remapped velocity (34–37).
pub const STEP_MUSL: &[Stage] = &[
    Stage::Cfl,
    Stage::ClearGrid,
    Stage::ShapeEval,
    Stage::P2g,
    Stage::GridPredict,
    Stage::Forces,
    Stage::GridCorrect,
    Stage::G2p,
    Stage::Remap,
    Stage::Stress,
];

/// The stage list of `integrator`.
pub fn stages(integrator: Integrator) -> &'static [Stage] {
    match integrator {
        Integrator::Musl => STEP_MUSL,
        _ => STEP,
    }
}

/// What a GPU pass's invocations run over (`gpu::pipelines` turns it into
/// a dispatch size).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Domain {
    Particles,
    /// Nodes (of every field, with contact pairs), and at least 2 per
    /// reaction (clear_grid zeroes them).
    Nodes,
    One,
    Probes,
    /// Grid cells or integration cells, whichever are more (MLS).
    Cells,
    /// Contact pairs × grid nodes.
    PairNodes,
    /// Gauss points (MLS).
    GaussPoints,
    /// One workgroup of one invocation per field and component
    /// (constraint_points.wgsl).
    PointLanes,
}

/// A pass on the GPU: its WGSL file (under `shaders/`, entry point
/// `main`), what it runs over, and the flags it is built with on top of
/// the scene's (`gpu::pipelines::expand`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GpuPass {
    pub file: &'static str,
    pub domain: Domain,
    pub flags: &'static [&'static str],
}

/// What the CPU does with a pass of the plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OnCpu {
    /// Its twin runs it (`cpu::CpuBackend::run_pass`).
    Twin,
    /// The CPU's twin of the pass named, in the same stage, does this
    /// pass's work too (the GPU splits one CPU loop in two).
    In(Pass),
    /// GPU bookkeeping the CPU does not need (binning particles by cell):
    /// left out of the CPU's list.
    GpuOnly,
    /// A sample pass, outside the step: `Backend::sample` computes it on
    /// the CPU (`cpu::energy`, `backend::probe_states`).
    Sample,
}

/// Everything about one pass, in one place (`Pass::info`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PassInfo {
    /// None for a pass only the CPU runs.
    pub gpu: Option<GpuPass>,
    pub cpu: OnCpu,
}

const fn gpu(
    file: &'static str,
    domain: Domain,
    flags: &'static [&'static str],
) -> Option<GpuPass> {
    Some(GpuPass {
        file,
        domain,
        flags,
    })
}

/// Declares `Pass`, `Pass::ALL` and `Pass::info` from one table: a pass's
/// facts are written once.
macro_rules! passes {
    ($($(#[$doc:meta])* $name:ident => $gpu:expr, $cpu:expr;)*) => {
        /// One pass of a step: a WGSL file the GPU runs, the CPU twin that
        /// does the same work, or both (`Pass::info`).
        #[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
        pub enum Pass {
            $($(#[$doc])* $name,)*
        }

        impl Pass {
            /// Every pass, in declaration order (`pass as usize` indexes it).
            pub const ALL: [Pass; [$(Pass::$name),*].len()] = [$(Pass::$name),*];

            /// Where the pass runs and how it is built.
            pub const fn info(self) -> PassInfo {
                use Domain::*;
                use OnCpu::*;
                match self {
                    $(Pass::$name => PassInfo { gpu: $gpu, cpu: $cpu },)*
                }
            }
        }
    };
}

passes! {
    /// Δt from the Courant condition: the GPU's reduction of the wave
    /// speed over the particles (cpu/cfl.rs).
    Cfl => gpu("cfl.wgsl", Particles, &[]), Twin;
    /// The GPU's Δt and stop logic from the reduction (the CPU's `Cfl`
    /// decides both).
    StepBegin => gpu("step_begin.wgsl", One, &[]), In(Pass::Cfl);
    ClearGrid => gpu("clear_grid.wgsl", Nodes, &[]), Twin;
    /// N, ∇N at every particle into the CPU's shape cache (cpu/shape_eval.rs;
    /// LME: the Newton solve on λ), and with contact pairs the nodes offset
    /// into each body's field. The GPU evaluates the weights inline where
    /// they are used; LME's Newton is `LmeNewton`.
    ShapeEval => None, Twin;
    /// `ShapeEval` then `P2g` in one loop over the particles
    /// (`cpu::shape_eval::shape_eval_p2g`; `FUSED`).
    ShapeEvalP2g => None, Twin;
    LmeNewton => gpu("lme_newton.wgsl", Particles, &[]), In(Pass::ShapeEval);
    /// Particles binned by cell (shared/bins.wgsl): for MLS in `p2g`, for
    /// the gather passes in `shape_eval`.
    BinClear => gpu("bin_clear.wgsl", Cells, &[]), GpuOnly;
    BinCount => gpu("bin_count.wgsl", Particles, &[]), GpuOnly;
    BinScan => gpu("bin_scan.wgsl", One, &[]), GpuOnly;
    BinFill => gpu("bin_fill.wgsl", Particles, &[]), GpuOnly;
    /// p2g.wgsl as a scatter with float atomics, or built with GATHER as
    /// one invocation per node over the binned particles (no atomics).
    /// The CPU twin of all three is cpu/p2g.rs.
    P2g => gpu("p2g.wgsl", Particles, &["WALK"]), Twin;
    P2gGather => gpu("p2g.wgsl", Nodes, &["WALK", "GATHER"]), Twin;
    /// p2g.wgsl built with PATCH: one invocation per bin of particles that
    /// share a stencil (linear and B-splines on a regular grid, LME), summing
    /// their contributions in registers, then one atomic per node and
    /// component of the stencil.
    P2gPatch => gpu("p2g.wgsl", Cells, &["WALK", "PATCH"]), Twin;
    MlsP2g => gpu("mls_p2g.wgsl", GaussPoints, &[]), Twin;
    /// Walls only: the weight of the particles in contact per node
    /// (wall_touch.wgsl), before `GridPredict`.
    WallTouch => gpu("wall_touch.wgsl", Particles, &[]), Twin;
    GridPredict => gpu("grid_update.wgsl", Nodes, &[]), Twin;
    Stress => gpu("stress.wgsl", Particles, &[]), Twin;
    /// `stress` then `forces` in one pass (stress.wgsl built with FORCES;
    /// on the CPU `cpu::stress::stress_forces`): what a whole step runs
    /// without MLS (`FUSED`).
    StressForces => gpu("stress.wgsl", Particles, &["WALK", "FORCES"]), Twin;
    /// `StressForces` built with PATCH: per bin, as `P2gPatch`.
    StressForcesPatch => gpu("stress.wgsl", Cells, &["WALK", "FORCES", "PATCH"]), Twin;
    /// forces.wgsl as a scatter, or built with GATHER as `P2gGather` is.
    Forces => gpu("forces.wgsl", Particles, &["WALK"]), Twin;
    ForcesGather => gpu("forces.wgsl", Nodes, &["WALK", "GATHER"]), Twin;
    /// forces.wgsl built with PATCH, as `P2gPatch`.
    ForcesPatch => gpu("forces.wgsl", Cells, &["WALK", "PATCH"]), Twin;
    MlsForces => gpu("mls_forces.wgsl", GaussPoints, &[]), Twin;
    /// `solver.mls_scope = "force"`: the fit of σ at each Gauss point
    /// (mls_fit.wgsl, one invocation per Gauss point), then at each
    /// particle (built with PARTICLES); `Forces` then scatters the
    /// particles' −V_p (σ_p − σ_h(x_p)) ∇N_I(x_p) and `MlsForceGauss` the
    /// Gauss points' −ω_g σ_h(x_g) ∇N_I(x_g). On the CPU `Mls::fit_stress`
    /// does both fits, `Mls::corrected_forces` both scatters.
    MlsFitGauss => gpu("mls_fit.wgsl", GaussPoints, &[]), Twin;
    MlsFitParticles => gpu("mls_fit.wgsl", Particles, &["PARTICLES"]), In(Pass::MlsFitGauss);
    MlsForceGauss => gpu("mls_force_gauss.wgsl", GaussPoints, &[]), In(Pass::Forces);
    /// `solver.mls_scope = "force"`, stage `stress`: ω_g L(x_g) at each
    /// Gauss point (mls_grad.wgsl), then V_p L_p at each particle (built
    /// with PARTICLES), then each particle's strain-rate correction, the
    /// transpose of the force's bracket (mls_strain.wgsl), which `Stress`
    /// (built with MLS_FORCE) adds to L_p. On the CPU
    /// `Mls::strain_correction` does the three.
    MlsGradGauss => gpu("mls_grad.wgsl", GaussPoints, &[]), In(Pass::MlsStrain);
    MlsGradParticles => gpu("mls_grad.wgsl", Particles, &["PARTICLES"]), In(Pass::MlsStrain);
    MlsStrain => gpu("mls_strain.wgsl", Particles, &[]), Twin;
    /// `solver.volumetric_strain = "cell_average"`, stage `stress`: zero
    /// the (cell, body) sums (cell_average.wgsl built with CLEAR, one
    /// invocation per cell), add each particle's V tr L and V to its
    /// slot (`CellAverage`), then `Stress` (built with CELL_AVERAGE)
    /// replaces tr L by its slot's mean.
    CellAverageClear => gpu("cell_average.wgsl", Nodes, &["CLEAR"]), In(Pass::CellAverage);
    CellAverage => gpu("cell_average.wgsl", Particles, &[]), Twin;
    /// Saturated soil, stage `stress`: the pore pressure's update from the
    /// fluid's mass balance with Darcy flow on the grid (cpu/pore_flow.rs;
    /// no WGSL twin yet: the GPU refuses saturated scenes).
    PoreFlow => None, Twin;
    /// Walls only: the walls' forces at the contact points
    /// (wall_contact.wgsl), before `GridCorrect`.
    WallContact => gpu("wall_contact.wgsl", Particles, &[]), Twin;
    GridCorrect => gpu("grid_update.wgsl", Nodes, &["CORRECT"]), Twin;
    /// Contact pairs only: the fields' mass gradients and volumes
    /// (contact_grad.wgsl, a scatter per particle) then each pair node's
    /// normal and gap (contact_detect.wgsl, over the particles binned in
    /// `shape_eval`), before `GridPredict`; the exchange after
    /// `GridPredict` (contact_exchange.wgsl) and, as forces, after
    /// `GridCorrect` (`ContactExchangeForce`, built with CORRECT).
    ContactGrad => gpu("contact_grad.wgsl", Particles, &[]), Twin;
    ContactDetect => gpu("contact_detect.wgsl", PairNodes, &[]), Twin;
    ContactExchange => gpu("contact_exchange.wgsl", Nodes, &[]), Twin;
    ContactExchangeForce => gpu("contact_exchange.wgsl", Nodes, &["CORRECT"]), Twin;
    /// Contact pairs only, after `G2p`: each field given back the momentum
    /// the interface's PIC share changed (`cpu::contact_conserve`).
    ContactConserve => gpu("contact_conserve.wgsl", Particles, &[]), Twin;
    /// Constraint points only (`cpu::constraint_points::hold`): the
    /// projection that holds the points at their group's velocity
    /// (constraint_points.wgsl), right after each `GridPredict` pass, and
    /// as forces with the groups' reactions right after `GridCorrect`
    /// (`ConstraintPointsForce`, built with CORRECT): before the contact
    /// exchange.
    ConstraintPoints => gpu("constraint_points.wgsl", PointLanes, &[]), Twin;
    ConstraintPointsForce => gpu("constraint_points.wgsl", PointLanes, &["CORRECT"]), Twin;
    G2p => gpu("g2p.wgsl", Particles, &[]), Twin;
    /// CPU only, where nothing between a step's `g2p` and the next step's
    /// `p2g` reads or writes the particles or the grid (`StepPlan::primes`):
    /// `g2p`, then the next step's `cfl` reduction, `clear_grid` and `p2g`
    /// at the new positions, in one loop over the particles
    /// (`cpu::g2p_p2g`); the next step runs `StepPlan::cpu_primed`.
    G2pP2g => None, Twin;
    /// MUSL's remap: zero the nodal momentum (remap.wgsl built with CLEAR),
    /// then scatter the new velocities from particles (`Remap`) or Gauss
    /// points (`MlsRemap`).
    RemapClear => gpu("remap.wgsl", Nodes, &["CLEAR"]), Twin;
    Remap => gpu("remap.wgsl", Particles, &[]), Twin;
    MlsRemap => gpu("mls_remap.wgsl", GaussPoints, &[]), Twin;
    /// Commit the step's time (and count it).
    StepEnd => gpu("step_end.wgsl", One, &[]), Twin;
    Probes => gpu("probes.wgsl", Probes, &[]), Sample;
    Energy => gpu("energy.wgsl", Particles, &[]), Sample;
}

impl Pass {
    /// The WGSL file (under shaders/); None for a pass only the CPU runs.
    pub fn file(self) -> Option<&'static str> {
        self.info().gpu.map(|g| g.file)
    }
}

/// Two consecutive passes that a backend runs as one pass where both are
/// in its list side by side and `apart` does not hold. Applied to the
/// stages' passes to give each backend's whole step (`StepPlan`); the
/// fused pass gives the same numbers as the two one by one
/// (`tests/fused_step.rs`).
pub struct Fusion {
    pub first: Pass,
    pub then: Pass,
    pub fused: Pass,
    /// When the two must stay apart although they follow each other.
    pub apart: fn(&PlanInputs) -> bool,
}

/// The fusions of both backends. The CPU's `ShapeEvalP2g` (the GPU
/// evaluates shapes inline, so it has no `ShapeEval` to fuse): not with
/// contact pairs, whose nodes `shape_eval` offsets into each body's field
/// before `p2g` scatters. `stress` with `forces` where both scatter: not
/// with the cell average, which needs every particle's L before any
/// stress (on the GPU, the gather keeps them apart: `ForcesGather` has no
/// fusion).
pub const FUSED: [Fusion; 3] = [
    Fusion {
        first: Pass::ShapeEval,
        then: Pass::P2g,
        fused: Pass::ShapeEvalP2g,
        apart: |i| i.contact,
    },
    Fusion {
        first: Pass::Stress,
        then: Pass::Forces,
        fused: Pass::StressForces,
        apart: |i| i.cell_average,
    },
    Fusion {
        first: Pass::Stress,
        then: Pass::ForcesPatch,
        fused: Pass::StressForcesPatch,
        apart: |i| i.cell_average,
    },
];

/// What a plan is decided from: the shape, the integrator, MLS, and how
/// the GPU puts particle terms on nodes (its options' choice: the gather
/// or the per-bin scatter; both off on the CPU and for MLS or MUSL).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PlanInputs {
    pub lme: bool,
    /// The paper's MLS step (`solver.mls_scope = "all"`): `p2g`, `forces`
    /// and the remap at Gauss points.
    pub mls: bool,
    /// MLS as the internal force's quadrature correction only
    /// (`solver.mls_scope = "force"`): `forces` alone changes; `p2g`, the
    /// remap and `g2p` stay the particles' own.
    pub mls_force: bool,
    pub musl: bool,
    /// `p2g` and `forces` gather at nodes over particles binned in `shape_eval`.
    pub gather: bool,
    /// `p2g` and `forces` scatter per bin of particles binned in `shape_eval`.
    pub patch: bool,
    /// Rigid walls: the nodes they act on are found before `GridPredict`.
    pub walls: bool,
    /// Contact pairs: `shape_eval` must offset the nodes into each body's
    /// field before `p2g` scatters (so the two do not fuse on the CPU); on
    /// the GPU `shape_eval` bins the particles (for the gaps) and
    /// `GridPredict`, `GridCorrect` and `Remap` add the contact passes.
    pub contact: bool,
    /// Constraint points (`model::constraint_points`): the GPU adds the
    /// points' projection after every `GridPredict` and `GridCorrect`
    /// pass.
    pub points: bool,
    /// `solver.volumetric_strain = "cell_average"`: `stress` averages the
    /// volumetric strain rate over each cell first (on the GPU, the
    /// `CellAverageClear` and `CellAverage` passes), so it does not fuse
    /// with `forces`.
    pub cell_average: bool,
    /// Saturated soil (`model::pore`): `stress` ends with the pore
    /// pressure's update (`PoreFlow`, CPU only for now), so it does not
    /// fuse with `forces`, which then takes the total stress.
    pub pore: bool,
}

/// The step of one scene, for both backends: the stages' passes
/// (`stage_passes`), each backend's share of them (`Pass::info`), fused
/// where `FUSED` says. The CPU runs `cpu_step` pass by pass
/// (`cpu::CpuBackend::run_pass`), the GPU records `gpu_step`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StepPlan {
    pub inputs: PlanInputs,
    /// The stages in order (`STEP` or `STEP_MUSL`).
    pub stages: &'static [Stage],
    /// The CPU's passes of one whole step, in order: each stage's CPU
    /// passes (`cpu_passes_for`), fused (`ShapeEvalP2g` without MLS or
    /// contact pairs, `StressForces` where `stress` and `forces` follow
    /// each other), then `StepEnd`.
    pub cpu_step: Vec<Pass>,
    /// The GPU's passes of one whole step, in order: each stage's GPU
    /// passes (`gpu_passes_for`), with `stress` and `forces` fused into
    /// `StressForces` (per bin: `StressForcesPatch`) where both scatter (no
    /// MLS, not MUSL, not gathering), then `StepEnd` (commit the time).
    pub gpu_step: Vec<Pass>,
    /// Where the plan `primes`: the CPU's step after one whose `G2pP2g`
    /// already did this step's `Cfl`, `ClearGrid` and `P2g` (`cpu_step`
    /// without them); empty otherwise.
    pub cpu_primed: Vec<Pass>,
}

const BINS: [Pass; 4] = [Pass::BinClear, Pass::BinCount, Pass::BinScan, Pass::BinFill];

/// Whether the GPU runs `pass`.
pub fn on_gpu(pass: Pass) -> bool {
    pass.info().gpu.is_some()
}

/// Whether the CPU's `run_pass` runs `pass`.
pub fn on_cpu(pass: Pass) -> bool {
    pass.info().cpu == OnCpu::Twin
}

/// `passes` with each `FUSED` pair that follows each other replaced by its
/// fused pass (where the backend runs it).
fn fuse(passes: Vec<Pass>, inputs: &PlanInputs, runs: fn(Pass) -> bool) -> Vec<Pass> {
    let mut out: Vec<Pass> = Vec::with_capacity(passes.len());
    for pass in passes {
        let last = out.last().copied();
        let fusion = FUSED.iter().find(|f| {
            Some(f.first) == last && f.then == pass && runs(f.fused) && !(f.apart)(inputs)
        });
        match fusion {
            Some(f) => *out.last_mut().expect("a fusion follows its first pass") = f.fused,
            None => out.push(pass),
        }
    }
    out
}

impl StepPlan {
    /// The plan of `model` with the GPU's `gather` / `patch` choice (both
    /// false for the CPU, whose step does not depend on them).
    pub fn of(model: &Model, gather: bool, patch: bool) -> StepPlan {
        StepPlan::new(PlanInputs {
            lme: matches!(model.shape, Shape::Lme(_)),
            mls: model.mls && model.mls_scope == MlsScope::All,
            mls_force: model.mls && model.mls_scope == MlsScope::Force,
            musl: model.integrator == Integrator::Musl,
            gather,
            patch,
            walls: !model.walls.is_empty(),
            contact: model.contact.is_some(),
            points: !model.constraints.points.is_empty(),
            cell_average: model.cell_average_volumetric,
            pore: model.pore.is_some(),
        })
    }

    pub fn new(inputs: PlanInputs) -> StepPlan {
        let stages = if inputs.musl { STEP_MUSL } else { STEP };
        let mut plan = StepPlan {
            inputs,
            stages,
            cpu_step: Vec::new(),
            gpu_step: Vec::new(),
            cpu_primed: Vec::new(),
        };
        let whole = |per_stage: &dyn Fn(Stage) -> Vec<Pass>| -> Vec<Pass> {
            stages.iter().flat_map(|&s| per_stage(s)).collect()
        };
        let mut cpu = fuse(whole(&|s| plan.cpu_passes_for(s)), &inputs, on_cpu);
        let mut gpu = fuse(whole(&|s| plan.gpu_passes_for(s)), &inputs, on_gpu);
        if plan.primes() {
            // The step from the particles ends with the next one's P2G;
            // the steps after it start where that left the grid.
            let last = cpu.last_mut().expect("a step has passes");
            debug_assert_eq!(*last, Pass::G2p);
            *last = Pass::G2pP2g;
            let p2g = cpu
                .iter()
                .position(|&p| p == Pass::ShapeEvalP2g)
                .expect("a plan that primes scatters in ShapeEvalP2g");
            debug_assert_eq!(cpu[..p2g], [Pass::Cfl, Pass::ClearGrid]);
            plan.cpu_primed = cpu[p2g + 1..].to_vec();
            plan.cpu_primed.push(Pass::StepEnd);
        }
        cpu.push(Pass::StepEnd);
        gpu.push(Pass::StepEnd);
        (plan.cpu_step, plan.gpu_step) = (cpu, gpu);
        plan
    }

    /// Whether the CPU's step ends with the next one's `Cfl`, `ClearGrid`
    /// and `P2g` (`Pass::G2pP2g`): where nothing but those runs between a
    /// step's `G2p` and the next `P2g`, and no shape cache is stored (the
    /// next P2G needs the weights at the new positions, the cache holds
    /// those of the old: `cpu::ShapeCache::needed`). Not with LME, MLS,
    /// MUSL, walls, contact pairs, the cell average or saturated soil.
    pub fn primes(&self) -> bool {
        let i = &self.inputs;
        !(i.lme
            || i.mls
            || i.mls_force
            || i.musl
            || i.walls
            || i.contact
            || i.cell_average
            || i.pore)
    }

    /// The passes that do `stage` on its own on either backend, in order
    /// (`stage_passes`, and with constraint points their projection after
    /// each grid update).
    pub fn passes_for(&self, stage: Stage) -> Vec<Pass> {
        let passes = self.stage_passes(stage);
        if !self.inputs.points {
            return passes.to_vec();
        }
        passes
            .iter()
            .flat_map(|&p| match p {
                Pass::GridPredict => vec![p, Pass::ConstraintPoints],
                Pass::GridCorrect => vec![p, Pass::ConstraintPointsForce],
                p => vec![p],
            })
            .collect()
    }

    /// The GPU's passes of `stage` on its own (the parity tests run them).
    pub fn gpu_passes_for(&self, stage: Stage) -> Vec<Pass> {
        let mut passes = self.passes_for(stage);
        passes.retain(|&p| on_gpu(p));
        passes
    }

    /// The CPU's passes of `stage` on its own, unfused (the parity tests
    /// and `fused_step` run them). The CPU scatters per particle whatever
    /// the GPU's choice: its passes are those of the plan without the
    /// gather and the per-bin scatter (the twins of their passes are the
    /// scatter's all the same).
    pub fn cpu_passes_for(&self, stage: Stage) -> Vec<Pass> {
        let scatter = StepPlan {
            inputs: PlanInputs {
                gather: false,
                patch: false,
                ..self.inputs
            },
            stages: self.stages,
            cpu_step: Vec::new(),
            gpu_step: Vec::new(),
            cpu_primed: Vec::new(),
        };
        let mut passes = scatter.passes_for(stage);
        passes.retain(|&p| on_cpu(p));
        passes
    }

    /// The passes that do `stage` on its own, constraint points aside,
    /// on both backends (each runs those `Pass::info` gives it).
    /// `Cfl` is the reduction plus the one-invocation Δt/stop pass; shape
    /// evaluation is the CPU's shape cache, LME's Newton solve on the GPU
    /// and, for the gather and per-bin passes, the binning (the GPU
    /// evaluates the weights themselves inline where used). With MLS,
    /// `p2g` and `forces` work at Gauss points.
    fn stage_passes(&self, stage: Stage) -> &'static [Pass] {
        let PlanInputs {
            lme,
            mls,
            mls_force,
            musl,
            gather,
            patch,
            walls,
            contact,
            points: _,
            cell_average,
            pore,
        } = self.inputs;
        let binned = gather || patch || contact;
        const SHAPES: Pass = Pass::ShapeEval;
        match stage {
            Stage::Cfl => &[Pass::Cfl, Pass::StepBegin],
            Stage::ClearGrid => &[Pass::ClearGrid],
            Stage::ShapeEval if binned && lme => {
                &[SHAPES, Pass::LmeNewton, BINS[0], BINS[1], BINS[2], BINS[3]]
            }
            Stage::ShapeEval if binned => &[SHAPES, BINS[0], BINS[1], BINS[2], BINS[3]],
            Stage::ShapeEval if lme => &[SHAPES, Pass::LmeNewton],
            Stage::ShapeEval => &[SHAPES],
            Stage::P2g if mls => &[BINS[0], BINS[1], BINS[2], BINS[3], Pass::MlsP2g],
            Stage::P2g if gather => &[Pass::P2gGather],
            Stage::P2g if patch => &[Pass::P2gPatch],
            Stage::P2g => &[Pass::P2g],
            Stage::Forces if mls => &[Pass::MlsForces],
            Stage::Forces if mls_force => &[
                BINS[0],
                BINS[1],
                BINS[2],
                BINS[3],
                Pass::MlsFitGauss,
                Pass::MlsFitParticles,
                Pass::Forces,
                Pass::MlsForceGauss,
            ],
            Stage::Forces if gather => &[Pass::ForcesGather],
            Stage::Forces if patch => &[Pass::ForcesPatch],
            Stage::GridPredict if walls && contact => &[
                Pass::WallTouch,
                Pass::ContactGrad,
                Pass::ContactDetect,
                Pass::GridPredict,
                Pass::ContactExchange,
            ],
            Stage::GridPredict if contact => &[
                Pass::ContactGrad,
                Pass::ContactDetect,
                Pass::GridPredict,
                Pass::ContactExchange,
            ],
            Stage::GridPredict if walls => &[Pass::WallTouch, Pass::GridPredict],
            Stage::GridPredict => &[Pass::GridPredict],
            // The fit at the forces' positions: MUSL's forces came first
            // this step; update-stress-first fits here (and again in
            // `forces`, for the new stress).
            Stage::Stress if mls_force && musl => &[
                Pass::MlsGradGauss,
                Pass::MlsGradParticles,
                Pass::MlsStrain,
                Pass::Stress,
            ],
            Stage::Stress if mls_force => &[
                BINS[0],
                BINS[1],
                BINS[2],
                BINS[3],
                Pass::MlsFitGauss,
                Pass::MlsFitParticles,
                Pass::MlsGradGauss,
                Pass::MlsGradParticles,
                Pass::MlsStrain,
                Pass::Stress,
            ],
            Stage::Stress if cell_average && pore => &[
                Pass::CellAverageClear,
                Pass::CellAverage,
                Pass::Stress,
                Pass::PoreFlow,
            ],
            Stage::Stress if cell_average => {
                &[Pass::CellAverageClear, Pass::CellAverage, Pass::Stress]
            }
            Stage::Stress if pore => &[Pass::Stress, Pass::PoreFlow],
            Stage::Stress => &[Pass::Stress],
            Stage::Forces => &[Pass::Forces],
            Stage::GridCorrect if walls && contact => &[
                Pass::WallContact,
                Pass::GridCorrect,
                Pass::ContactExchangeForce,
            ],
            Stage::GridCorrect if contact => &[Pass::GridCorrect, Pass::ContactExchangeForce],
            Stage::GridCorrect if walls => &[Pass::WallContact, Pass::GridCorrect],
            Stage::GridCorrect => &[Pass::GridCorrect],
            Stage::G2p if contact => &[Pass::G2p, Pass::ContactConserve],
            Stage::G2p => &[Pass::G2p],
            Stage::Remap if mls => &[Pass::RemapClear, Pass::MlsRemap, Pass::GridPredict],
            // The contacts stay those of the step's start (`GridPredict`).
            Stage::Remap if contact => &[
                Pass::RemapClear,
                Pass::Remap,
                Pass::GridPredict,
                Pass::ContactExchange,
            ],
            Stage::Remap => &[Pass::RemapClear, Pass::Remap, Pass::GridPredict],
        }
    }

    /// Whether the GPU builds `pass` for this scene: a pass of some stage
    /// (the parity tests run stages one by one), of the whole step, or a
    /// sample pass (probes, energy).
    pub fn gpu_uses(&self, pass: Pass) -> bool {
        on_gpu(pass)
            && (pass.info().cpu == OnCpu::Sample
                || self.gpu_step.contains(&pass)
                || self
                    .stages
                    .iter()
                    .any(|&s| self.gpu_passes_for(s).contains(&pass)))
    }

    /// The passes the GPU builds a pipeline for (`gpu_uses`), in `Pass::ALL`'s order.
    pub fn gpu_passes(&self) -> Vec<Pass> {
        Pass::ALL
            .into_iter()
            .filter(|&p| self.gpu_uses(p))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan(lme: bool, mls: bool, musl: bool, gather: bool, patch: bool) -> StepPlan {
        StepPlan::new(PlanInputs {
            lme,
            mls,
            mls_force: false,
            musl,
            gather,
            patch,
            walls: lme,
            contact: false,
            points: false,
            cell_average: false,
            pore: false,
        })
    }

    #[test]
    fn both_backends_fuse_stress_and_forces_only_without_mls_and_musl() {
        let p = plan(false, false, false, false, false);
        assert!(p.cpu_step.contains(&Pass::StressForces));
        assert!(p.gpu_step.contains(&Pass::StressForces));
        assert!(!p.gpu_step.contains(&Pass::Stress) && !p.gpu_step.contains(&Pass::Forces));
        for (mls, musl) in [(true, true), (false, true)] {
            let p = plan(false, mls, musl, false, false);
            assert!(!p.cpu_step.contains(&Pass::StressForces));
            assert!(!p.gpu_step.contains(&Pass::StressForces));
            assert!(p.gpu_uses(Pass::Stress));
        }
        // The gather keeps stress and forces apart on the GPU only.
        let p = plan(false, false, false, true, false);
        assert!(p.cpu_step.contains(&Pass::StressForces));
        assert!(p.gpu_step.contains(&Pass::ForcesGather) && !p.gpu_uses(Pass::StressForces));
        let p = plan(true, false, false, false, true);
        assert!(p.gpu_step.contains(&Pass::StressForcesPatch));
        assert!(p.gpu_uses(Pass::ForcesPatch) && !p.gpu_uses(Pass::Forces));
        // The cell average of the volumetric strain rate needs every
        // particle's L before any stress: the CPU runs the stages apart.
        let mut inputs = plan(false, false, false, false, false).inputs;
        inputs.cell_average = true;
        let p = StepPlan::new(inputs);
        assert!(!p.cpu_step.contains(&Pass::StressForces));
        assert!(p.cpu_step.contains(&Pass::Stress));
        assert!(!p.gpu_step.contains(&Pass::StressForces));
    }

    /// `solver.mls_scope = "force"` changes `forces` alone: p2g, the remap
    /// and the stress stay the particles' own (fused where they were).
    #[test]
    fn the_force_correction_replaces_only_the_forces_passes() {
        for musl in [false, true] {
            let p = StepPlan::new(PlanInputs {
                lme: false,
                mls: false,
                mls_force: true,
                musl,
                gather: false,
                patch: false,
                walls: false,
                contact: false,
                points: false,
                cell_average: false,
                pore: false,
            });
            assert_eq!(p.cpu_step[2], Pass::ShapeEvalP2g);
            assert!(!p.cpu_step.contains(&Pass::StressForces));
            assert!(p.cpu_step.contains(&Pass::Forces));
            for pass in [Pass::MlsP2g, Pass::MlsForces, Pass::MlsRemap] {
                assert!(!p.gpu_uses(pass), "{pass:?}");
            }
            for pass in [
                Pass::P2g,
                Pass::MlsFitGauss,
                Pass::MlsFitParticles,
                Pass::Forces,
                Pass::MlsForceGauss,
                Pass::MlsGradGauss,
                Pass::MlsGradParticles,
                Pass::MlsStrain,
            ] {
                assert!(p.gpu_step.contains(&pass), "{pass:?}");
            }
            assert_eq!(p.gpu_uses(Pass::Remap), musl);
        }
    }

    #[test]
    fn every_stage_is_done_once_in_order_on_both_backends() {
        for bits in 0..32u32 {
            let b = |i: u32| bits & 1 << i != 0;
            let (lme, mls, musl, gather, patch) = (b(0), b(1), b(2), b(3), b(4));
            if (gather || patch) && (mls || musl) || gather && patch {
                continue; // the GPU options never pick these
            }
            let p = plan(lme, mls, musl, gather, patch);
            // Each backend's step, unfused, is its stages' passes in turn.
            // (`G2pP2g` is the step's `G2p`; its next step's share is
            // what `cpu_primed` leaves out.)
            let unfused = |step: &[Pass]| -> Vec<Pass> {
                step.iter()
                    .flat_map(|&q| match FUSED.iter().find(|f| f.fused == q) {
                        Some(f) => vec![f.first, f.then],
                        None if q == Pass::G2pP2g => vec![Pass::G2p],
                        None => vec![q],
                    })
                    .collect()
            };
            let stages = |per: &dyn Fn(Stage) -> Vec<Pass>| -> Vec<Pass> {
                let mut v: Vec<Pass> = p.stages.iter().flat_map(|&s| per(s)).collect();
                v.push(Pass::StepEnd);
                v
            };
            assert_eq!(
                unfused(&p.cpu_step),
                stages(&|s| p.cpu_passes_for(s)),
                "{bits:05b}"
            );
            assert_eq!(
                unfused(&p.gpu_step),
                stages(&|s| p.gpu_passes_for(s)),
                "{bits:05b}"
            );
            assert_eq!(p.cpu_step[..2], [Pass::Cfl, Pass::ClearGrid]);
            assert_eq!(p.cpu_step[2] == Pass::ShapeEvalP2g, !mls, "{bits:05b}");
            // Only the plans without a shape cache prime, and their primed
            // step is the whole one less what the last step's `G2pP2g` did.
            assert_eq!(p.primes(), !(lme || mls || musl), "{bits:05b}");
            assert_eq!(p.cpu_step.contains(&Pass::G2pP2g), p.primes(), "{bits:05b}");
            if p.primes() {
                assert_eq!(p.cpu_primed, p.cpu_step[3..], "{bits:05b}");
            } else {
                assert!(p.cpu_primed.is_empty(), "{bits:05b}");
            }
            assert_eq!(p.gpu_step.last(), Some(&Pass::StepEnd));
            assert_eq!(p.gpu_step[..2], [Pass::Cfl, Pass::StepBegin]);
            assert_eq!(p.gpu_uses(Pass::LmeNewton), lme, "{bits:05b}");
            assert_eq!(p.gpu_uses(Pass::RemapClear), musl, "{bits:05b}");
            assert_eq!(p.gpu_uses(Pass::WallTouch), p.inputs.walls, "{bits:05b}");
        }
    }

    /// Contact pairs add their passes where the CPU does its work (detect
    /// before `predict`, the exchange after it, after `correct` and after
    /// MUSL's remap, the momentum given back after `g2p`) and the binning
    /// in `shape_eval`; without pairs the step is the same, pass for pass.
    #[test]
    fn contact_pairs_add_their_passes_only_with_pairs() {
        let contact_passes = [
            Pass::ContactGrad,
            Pass::ContactDetect,
            Pass::ContactExchange,
            Pass::ContactExchangeForce,
            Pass::ContactConserve,
        ];
        for musl in [false, true] {
            for walls in [false, true] {
                let base = PlanInputs {
                    lme: false,
                    mls: false,
                    mls_force: false,
                    musl,
                    gather: false,
                    patch: false,
                    walls,
                    contact: false,
                    points: false,
                    cell_average: false,
                    pore: false,
                };
                let without = StepPlan::new(base);
                let with = StepPlan::new(PlanInputs {
                    contact: true,
                    ..base
                });
                for pass in contact_passes {
                    assert!(!without.gpu_uses(pass), "{pass:?}");
                    assert!(with.gpu_step.contains(&pass), "{pass:?}");
                }
                let at = |p: Pass| with.gpu_step.iter().position(|x| *x == p).unwrap();
                assert!(at(Pass::BinFill) < at(Pass::P2g));
                assert!(at(Pass::P2g) < at(Pass::ContactGrad));
                assert!(at(Pass::ContactDetect) < at(Pass::GridPredict));
                assert!(at(Pass::GridPredict) < at(Pass::ContactExchange));
                assert!(at(Pass::GridCorrect) < at(Pass::ContactExchangeForce));
                assert!(at(Pass::ContactExchangeForce) < at(Pass::G2p));
                assert_eq!(at(Pass::G2p) + 1, at(Pass::ContactConserve));
                if musl {
                    let remap = with.gpu_passes_for(Stage::Remap);
                    assert_eq!(remap.last(), Some(&Pass::ContactExchange));
                }
                let stripped: Vec<Pass> = with
                    .gpu_step
                    .iter()
                    .copied()
                    .filter(|p| !contact_passes.contains(p) && !BINS.contains(p))
                    .collect();
                assert_eq!(stripped, without.gpu_step);
            }
        }
    }
    /// Constraint points add their projection right after each grid
    /// update on the GPU (after `GridPredict`, MUSL's remap included, and
    /// after `GridCorrect`), before the contact exchange as on the CPU;
    /// without points the step is the same, pass for pass.
    #[test]
    fn constraint_points_add_their_passes_only_with_points() {
        for bits in 0..16u32 {
            let b = |i: u32| bits & 1 << i != 0;
            let base = PlanInputs {
                lme: b(0),
                mls: false,
                mls_force: false,
                musl: b(1),
                gather: false,
                patch: false,
                walls: b(2),
                contact: b(3),
                points: false,
                cell_average: false,
                pore: false,
            };
            let without = StepPlan::new(base);
            let with = StepPlan::new(PlanInputs {
                points: true,
                ..base
            });
            for pass in [Pass::ConstraintPoints, Pass::ConstraintPointsForce] {
                assert!(!without.gpu_uses(pass), "{bits:04b} {pass:?}");
                assert!(with.gpu_uses(pass), "{bits:04b} {pass:?}");
            }
            for (k, p) in with.gpu_step.iter().enumerate() {
                let next = with.gpu_step.get(k + 1);
                match p {
                    Pass::GridPredict => assert_eq!(next, Some(&Pass::ConstraintPoints)),
                    Pass::GridCorrect => assert_eq!(next, Some(&Pass::ConstraintPointsForce)),
                    _ => {}
                }
            }
            let predicts =
                |p: &StepPlan, pass: Pass| p.gpu_step.iter().filter(|x| **x == pass).count();
            assert_eq!(
                predicts(&with, Pass::ConstraintPoints),
                predicts(&without, Pass::GridPredict)
            );
            let stripped: Vec<Pass> = with
                .gpu_step
                .iter()
                .copied()
                .filter(|p| !matches!(p, Pass::ConstraintPoints | Pass::ConstraintPointsForce))
                .collect();
            assert_eq!(stripped, without.gpu_step, "{bits:04b}");
        }
    }
}
