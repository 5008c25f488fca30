//! The step plan: which stages run for a scene, in what order, which of
//! them fuse into one pass over the particles, and which GPU passes do each
//! (`StepPlan`), built once from the model and read by both backends and
//! the driver. Nothing else decides it: the CPU backend runs `StepPlan::cpu`,
//! the GPU backend records `StepPlan::gpu_step` and builds the pipelines of
//! `StepPlan::gpu_uses`.
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

/// One piece of a CPU step: a stage alone, or two consecutive stages done
/// in one pass over the particles (the same numbers as the two one by one:
/// `tests/fused_step.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CpuWork {
    Stage(Stage),
    /// `shape_eval` then `p2g` (`cpu::shape_eval::shape_eval_p2g`).
    ShapeEvalP2g,
    /// `stress` then `forces` (`cpu::stress::stress_forces`).
    StressForces,
}

/// One GPU pass: a WGSL file (under `shaders/`) and entry point `main`,
/// built with the scene's flags and the pass's own (`gpu::pipelines`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Pass {
    Cfl,
    StepBegin,
    ClearGrid,
    LmeNewton,
    /// Particles binned by cell (shared/bins.wgsl): for MLS in `p2g`, for
    /// the gather passes in `shape_eval`.
    BinClear,
    BinCount,
    BinScan,
    BinFill,
    /// p2g.wgsl as a scatter with float atomics, or built with GATHER as
    /// one invocation per node over the binned particles (no atomics).
    P2g,
    P2gGather,
    /// p2g.wgsl built with PATCH: one invocation per bin of particles that
    /// share a stencil (linear and B-splines on a regular grid, LME), summing
    /// their contributions in registers, then one atomic per node and
    /// component of the stencil.
    P2gPatch,
    MlsP2g,
    /// Walls only: the weight of the particles in contact per node
    /// (wall_touch.wgsl), before `GridPredict`.
    WallTouch,
    GridPredict,
    Stress,
    /// `stress` then `forces` in one pass (stress.wgsl built with FORCES):
    /// what a whole step runs without MLS. Not in `ALL`, which lists the
    /// passes of the stages one by one.
    StressForces,
    /// `StressForces` built with PATCH: per bin, as `P2gPatch`. Not in `ALL`.
    StressForcesPatch,
    /// forces.wgsl as a scatter, or built with GATHER as `P2gGather` is.
    Forces,
    ForcesGather,
    /// forces.wgsl built with PATCH, as `P2gPatch`.
    ForcesPatch,
    MlsForces,
    /// `solver.mls_scope = "force"`: the fit of σ at each Gauss point
    /// (mls_fit.wgsl, one invocation per Gauss point), then at each
    /// particle (built with PARTICLES); `Forces` then scatters the
    /// particles' −V_p (σ_p − σ_h(x_p)) ∇N_I(x_p) and `MlsForceGauss` the
    /// Gauss points' −ω_g σ_h(x_g) ∇N_I(x_g).
    MlsFitGauss,
    MlsFitParticles,
    MlsForceGauss,
    /// `solver.mls_scope = "force"`, stage `stress`: ω_g L(x_g) at each
    /// Gauss point (mls_grad.wgsl), then V_p L_p at each particle (built
    /// with PARTICLES), then each particle's strain-rate correction, the
    /// transpose of the force's bracket (mls_strain.wgsl), which `Stress`
    /// (built with MLS_FORCE) adds to L_p.
    MlsGradGauss,
    MlsGradParticles,
    MlsStrain,
    /// `solver.volumetric_strain = "cell_average"`, stage `stress`: zero
    /// the (cell, body) sums (cell_average.wgsl built with CLEAR, one
    /// invocation per cell), add each particle's V tr L and V to its
    /// slot (`CellAverage`), then `Stress` (built with CELL_AVERAGE)
    /// replaces tr L by its slot's mean.
    CellAverageClear,
    CellAverage,
    /// Walls only: the walls' forces at the contact points
    /// (wall_contact.wgsl), before `GridCorrect`.
    WallContact,
    GridCorrect,
    /// Contact pairs only (`cpu::contact`): `detect` as the fields' mass
    /// gradients and volumes (contact_grad.wgsl, a scatter per particle)
    /// then each pair node's normal and gap (contact_detect.wgsl, over the
    /// particles binned in `shape_eval`), before `GridPredict`; `exchange`
    /// after `GridPredict` (contact_exchange.wgsl) and, as forces, after
    /// `GridCorrect` (`ContactExchangeForce`, built with CORRECT).
    ContactGrad,
    ContactDetect,
    ContactExchange,
    ContactExchangeForce,
    /// Contact pairs only, after `G2p`: each field given back the momentum
    /// the interface's PIC share changed (`cpu::contact::conserve`,
    /// contact_conserve.wgsl).
    ContactConserve,
    /// Constraint points only (`cpu::constraint_points::hold`): the
    /// projection that holds the points at their group's velocity
    /// (constraint_points.wgsl), right after each `GridPredict` pass, and
    /// as forces with the groups' reactions right after `GridCorrect`
    /// (`ConstraintPointsForce`, built with CORRECT): before the contact
    /// exchange, as on the CPU.
    ConstraintPoints,
    ConstraintPointsForce,
    G2p,
    /// MUSL's remap: zero the nodal momentum (remap.wgsl built with CLEAR),
    /// then scatter the new velocities from particles (`Remap`) or Gauss
    /// points (`MlsRemap`).
    RemapClear,
    Remap,
    MlsRemap,
    StepEnd,
    Probes,
    Energy,
}

impl Pass {
    /// Every pass of the stages one by one, and the sample passes.
    pub const ALL: [Pass; 43] = [
        Pass::Cfl,
        Pass::StepBegin,
        Pass::ClearGrid,
        Pass::LmeNewton,
        Pass::BinClear,
        Pass::BinCount,
        Pass::BinScan,
        Pass::BinFill,
        Pass::P2g,
        Pass::P2gGather,
        Pass::P2gPatch,
        Pass::MlsP2g,
        Pass::WallTouch,
        Pass::GridPredict,
        Pass::Stress,
        Pass::Forces,
        Pass::ForcesGather,
        Pass::ForcesPatch,
        Pass::MlsForces,
        Pass::MlsFitGauss,
        Pass::MlsFitParticles,
        Pass::MlsForceGauss,
        Pass::MlsGradGauss,
        Pass::MlsGradParticles,
        Pass::MlsStrain,
        Pass::CellAverageClear,
        Pass::CellAverage,
        Pass::WallContact,
        Pass::GridCorrect,
        Pass::ContactGrad,
        Pass::ContactDetect,
        Pass::ContactExchange,
        Pass::ContactExchangeForce,
        Pass::ContactConserve,
        Pass::ConstraintPoints,
        Pass::ConstraintPointsForce,
        Pass::G2p,
        Pass::RemapClear,
        Pass::Remap,
        Pass::MlsRemap,
        Pass::StepEnd,
        Pass::Probes,
        Pass::Energy,
    ];

    /// The WGSL file (under shaders/).
    pub fn file(self) -> &'static str {
        match self {
            Pass::Cfl => "cfl.wgsl",
            Pass::StepBegin => "step_begin.wgsl",
            Pass::ClearGrid => "clear_grid.wgsl",
            Pass::LmeNewton => "lme_newton.wgsl",
            Pass::P2g | Pass::P2gGather | Pass::P2gPatch => "p2g.wgsl",
            Pass::WallTouch => "wall_touch.wgsl",
            Pass::WallContact => "wall_contact.wgsl",
            Pass::GridPredict | Pass::GridCorrect => "grid_update.wgsl",
            Pass::ContactGrad => "contact_grad.wgsl",
            Pass::ContactDetect => "contact_detect.wgsl",
            Pass::ContactExchange | Pass::ContactExchangeForce => "contact_exchange.wgsl",
            Pass::ContactConserve => "contact_conserve.wgsl",
            Pass::ConstraintPoints | Pass::ConstraintPointsForce => "constraint_points.wgsl",
            Pass::Stress | Pass::StressForces | Pass::StressForcesPatch => "stress.wgsl",
            Pass::Forces | Pass::ForcesGather | Pass::ForcesPatch => "forces.wgsl",
            Pass::G2p => "g2p.wgsl",
            Pass::StepEnd => "step_end.wgsl",
            Pass::Probes => "probes.wgsl",
            Pass::Energy => "energy.wgsl",
            Pass::BinClear => "bin_clear.wgsl",
            Pass::BinCount => "bin_count.wgsl",
            Pass::BinScan => "bin_scan.wgsl",
            Pass::BinFill => "bin_fill.wgsl",
            Pass::MlsP2g => "mls_p2g.wgsl",
            Pass::MlsForces => "mls_forces.wgsl",
            Pass::MlsFitGauss | Pass::MlsFitParticles => "mls_fit.wgsl",
            Pass::MlsForceGauss => "mls_force_gauss.wgsl",
            Pass::MlsGradGauss | Pass::MlsGradParticles => "mls_grad.wgsl",
            Pass::MlsStrain => "mls_strain.wgsl",
            Pass::CellAverageClear | Pass::CellAverage => "cell_average.wgsl",
            Pass::RemapClear | Pass::Remap => "remap.wgsl",
            Pass::MlsRemap => "mls_remap.wgsl",
        }
    }
}

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
    /// pass (the CPU's `grid_update` stages call it themselves).
    pub points: bool,
    /// `solver.volumetric_strain = "cell_average"`: `stress` averages the
    /// volumetric strain rate over each cell first (on the GPU, the
    /// `CellAverageClear` and `CellAverage` passes), so it does not fuse
    /// with `forces`.
    pub cell_average: bool,
}

/// The step of one scene, for both backends.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StepPlan {
    pub inputs: PlanInputs,
    /// The stages in order (`STEP` or `STEP_MUSL`).
    pub stages: &'static [Stage],
    /// The CPU's step: without MLS, `shape_eval` and `p2g` fuse, and
    /// `stress` and `forces` where they follow each other (not in MUSL).
    pub cpu: Vec<CpuWork>,
    /// The GPU's passes of one whole step, in order: each stage's passes
    /// (`passes_for`), with `stress` and `forces` fused into `StressForces`
    /// (per bin: `StressForcesPatch`) where both scatter (no MLS, not
    /// MUSL, not gathering), then `StepEnd` (commit the time).
    pub gpu_step: Vec<Pass>,
}

const BINS: [Pass; 4] = [Pass::BinClear, Pass::BinCount, Pass::BinScan, Pass::BinFill];

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
        })
    }

    pub fn new(inputs: PlanInputs) -> StepPlan {
        let PlanInputs {
            mls,
            mls_force,
            musl,
            gather,
            contact,
            cell_average,
            ..
        } = inputs;
        let stages = if musl { STEP_MUSL } else { STEP };
        let fuse_stress = !mls && !mls_force && !musl && !cell_average;
        let fuse_p2g = !mls && !contact;
        let cpu = stages
            .iter()
            .filter_map(|&s| match s {
                Stage::ShapeEval if fuse_p2g => Some(CpuWork::ShapeEvalP2g),
                Stage::P2g if fuse_p2g => None,
                Stage::Stress if fuse_stress => Some(CpuWork::StressForces),
                Stage::Forces if fuse_stress => None,
                s => Some(CpuWork::Stage(s)),
            })
            .collect();
        let mut plan = StepPlan {
            inputs,
            stages,
            cpu,
            gpu_step: Vec::new(),
        };
        let fuse_gpu = fuse_stress && !gather;
        plan.gpu_step = stages
            .iter()
            .flat_map(|&s| plan.passes_for(s))
            .filter_map(|pass| match pass {
                Pass::Stress if fuse_gpu && inputs.patch => Some(Pass::StressForcesPatch),
                Pass::Stress if fuse_gpu => Some(Pass::StressForces),
                Pass::Forces | Pass::ForcesPatch if fuse_gpu => None,
                p => Some(p),
            })
            .chain([Pass::StepEnd])
            .collect();
        plan
    }

    /// The GPU passes that do `stage` on its own (`stage_passes`, and with
    /// constraint points their projection after each grid update).
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

    /// The GPU passes that do `stage` on its own, constraint points aside.
    /// `Cfl` is the reduction
    /// plus the one-invocation Δt/stop pass; shape evaluation is LME's
    /// Newton solve and, for the gather and per-bin passes, the binning
    /// (the weights themselves are evaluated inline where used). With MLS,
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
        } = self.inputs;
        let binned = gather || patch || contact;
        match stage {
            Stage::Cfl => &[Pass::Cfl, Pass::StepBegin],
            Stage::ClearGrid => &[Pass::ClearGrid],
            Stage::ShapeEval if binned && lme => {
                &[Pass::LmeNewton, BINS[0], BINS[1], BINS[2], BINS[3]]
            }
            Stage::ShapeEval if binned => &BINS,
            Stage::ShapeEval if lme => &[Pass::LmeNewton],
            Stage::ShapeEval => &[],
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
            Stage::Stress if cell_average => {
                &[Pass::CellAverageClear, Pass::CellAverage, Pass::Stress]
            }
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
        matches!(pass, Pass::Probes | Pass::Energy)
            || self.gpu_step.contains(&pass)
            || self
                .stages
                .iter()
                .any(|&s| self.passes_for(s).contains(&pass))
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
        })
    }

    #[test]
    fn both_backends_fuse_stress_and_forces_only_without_mls_and_musl() {
        let p = plan(false, false, false, false, false);
        assert!(p.cpu.contains(&CpuWork::StressForces));
        assert!(p.gpu_step.contains(&Pass::StressForces));
        assert!(!p.gpu_step.contains(&Pass::Stress) && !p.gpu_step.contains(&Pass::Forces));
        for (mls, musl) in [(true, true), (false, true)] {
            let p = plan(false, mls, musl, false, false);
            assert!(!p.cpu.contains(&CpuWork::StressForces));
            assert!(!p.gpu_step.contains(&Pass::StressForces));
            assert!(p.gpu_uses(Pass::Stress));
        }
        // The gather keeps stress and forces apart on the GPU only.
        let p = plan(false, false, false, true, false);
        assert!(p.cpu.contains(&CpuWork::StressForces));
        assert!(p.gpu_step.contains(&Pass::ForcesGather) && !p.gpu_uses(Pass::StressForces));
        let p = plan(true, false, false, false, true);
        assert!(p.gpu_step.contains(&Pass::StressForcesPatch));
        assert!(p.gpu_uses(Pass::ForcesPatch) && !p.gpu_uses(Pass::Forces));
        // The cell average of the volumetric strain rate needs every
        // particle's L before any stress: the CPU runs the stages apart.
        let mut inputs = plan(false, false, false, false, false).inputs;
        inputs.cell_average = true;
        let p = StepPlan::new(inputs);
        assert!(!p.cpu.contains(&CpuWork::StressForces));
        assert!(p.cpu.contains(&CpuWork::Stage(Stage::Stress)));
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
            });
            assert_eq!(p.cpu[2], CpuWork::ShapeEvalP2g);
            assert!(!p.cpu.contains(&CpuWork::StressForces));
            assert!(p.cpu.contains(&CpuWork::Stage(Stage::Forces)));
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
            let cpu: Vec<Stage> = p
                .cpu
                .iter()
                .flat_map(|w| match w {
                    CpuWork::Stage(s) => vec![*s],
                    CpuWork::ShapeEvalP2g => vec![Stage::ShapeEval, Stage::P2g],
                    CpuWork::StressForces => vec![Stage::Stress, Stage::Forces],
                })
                .collect();
            assert_eq!(cpu, p.stages, "{bits:05b}");
            assert_eq!(p.gpu_step.last(), Some(&Pass::StepEnd));
            assert_eq!(p.gpu_step[..2], [Pass::Cfl, Pass::StepBegin]);
            assert_eq!(p.gpu_uses(Pass::LmeNewton), lme, "{bits:05b}");
            assert_eq!(p.gpu_uses(Pass::RemapClear), musl, "{bits:05b}");
            assert_eq!(p.gpu_uses(Pass::WallTouch), p.inputs.walls, "{bits:05b}");
        }
    }

    /// Contact pairs add their passes where the CPU does its work (detect
    /// before `predict`, the exchange after it, after `correct` and after
    /// MUSL's remap) and the binning in `shape_eval`; without pairs the
    /// step is the same, pass for pass.
    #[test]
    fn contact_pairs_add_their_passes_only_with_pairs() {
        let contact_passes = [
            Pass::ContactGrad,
            Pass::ContactDetect,
            Pass::ContactExchange,
            Pass::ContactExchangeForce,
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
                if musl {
                    let remap = with.passes_for(Stage::Remap);
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
