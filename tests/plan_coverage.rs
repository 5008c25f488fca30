//! Every pass of every step plan runs somewhere: each pass the GPU is
//! given has a pipeline (a WGSL file under shaders/, in the list
//! `gpu::pipelines::Pipelines::new` builds, and its expansion validates),
//! each pass the CPU is given has a twin (`CpuBackend::twin`), and a pass
//! the CPU leaves to the GPU is either GPU bookkeeping or done by a CPU
//! pass of the same stage. The plans are every combination of the inputs
//! `StepPlan::of` reads (shape LME or not, MLS of either scope, MUSL, the
//! GPU's gather or per-bin scatter, walls, contact pairs, constraint
//! points, the cell average) that the scene checks and the GPU options
//! allow.

use lme_mpm::cpu::CpuBackend;
use lme_mpm::gpu::constraint_points::PointCounts;
use lme_mpm::gpu::context::AtomicMode;
use lme_mpm::gpu::pipelines::{self, Variant};
use lme_mpm::model::Integrator;
use lme_mpm::scene::{NpcPosition, ShapeKind};
use lme_mpm::step::{OnCpu, Pass, PlanInputs, StepPlan, on_cpu, on_gpu};
use std::collections::HashSet;
use std::path::Path;

/// The plan inputs a scene can give (`StepPlan::of` with the GPU options'
/// choice of gather and per-bin scatter; the CPU's plans are those with
/// both off).
fn every_plan_input() -> Vec<PlanInputs> {
    let mut out = Vec::new();
    for bits in 0..1u32 << 11 {
        let b = |i: u32| bits & 1 << i != 0;
        let i = PlanInputs {
            lme: b(0),
            mls: b(1),
            mls_force: b(2),
            musl: b(3),
            gather: b(4),
            patch: b(5),
            walls: b(6),
            contact: b(7),
            points: b(8),
            cell_average: b(9),
            pore: b(10),
        };
        // One MLS scope at a time; the cell average refuses MLS
        // (scene::validate); the gather and the per-bin scatter exclude
        // each other, MLS, MUSL and contact pairs (`GpuOptions::gathers`,
        // `patches`); saturated soil refuses MLS, MUSL and contact pairs
        // (`model::pore`).
        let mls = i.mls || i.mls_force;
        if i.mls && i.mls_force
            || i.cell_average && mls
            || i.pore && (mls || i.musl || i.contact)
            || i.gather && i.patch
            || (i.gather || i.patch) && (mls || i.musl || i.contact)
        {
            continue;
        }
        out.push(i);
    }
    out
}

/// A shader variant whose plan is `i`'s.
fn variant_of(i: PlanInputs) -> Variant {
    Variant {
        shape: if i.lme {
            ShapeKind::Lme
        } else {
            ShapeKind::Linear
        },
        integrator: if i.musl {
            Integrator::Musl
        } else {
            Integrator::Npc {
                gamma: 0.5,
                position: NpcPosition::Corrected,
            }
        },
        perturbed: false,
        multi_material: false,
        atomics: AtomicMode::CompareExchange,
        lme_side: if i.lme { 5 } else { 1 },
        lme_stored: false,
        materials: 1,
        def_grad: false,
        plastic: false,
        mms: false,
        mls: i.mls || i.mls_force,
        mls_force: i.mls_force,
        walls: i.walls,
        gates: false,
        wall_preload: false,
        wall_pre_fit: false,
        pic: false,
        local_damping: false,
        ext_force: false,
        gather: i.gather,
        bspline_small_grid: false,
        bspline_cells: false,
        patch: i.patch,
        contact: i.contact.then_some([2, 1]),
        points: i.points.then_some(PointCounts {
            n_points: 22,
            slots: 9,
            n_held: 40,
            n_list: 180,
            env: 120,
            n_fields: if i.contact { 2 } else { 1 },
        }),
        cell_average_bodies: if i.cell_average { 2 } else { 0 },
    }
}

#[test]
fn pass_all_lists_each_pass_once_at_its_index() {
    for (k, pass) in Pass::ALL.into_iter().enumerate() {
        assert_eq!(pass as usize, k, "{pass:?}");
    }
}

/// The CPU's twins are the passes `Pass::info` says the CPU runs, no more.
#[test]
fn the_cpu_has_a_twin_exactly_for_the_passes_it_runs() {
    for pass in Pass::ALL {
        assert_eq!(
            CpuBackend::twin(pass).is_some(),
            on_cpu(pass),
            "{pass:?}: {:?}",
            pass.info()
        );
        // A pass only the CPU runs has no one else to do it.
        if !on_gpu(pass) {
            assert_eq!(pass.info().cpu, OnCpu::Twin, "{pass:?}");
        }
    }
}

#[test]
fn every_pass_of_every_plan_has_a_pipeline_and_a_cpu_twin() {
    let shaders = Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let inputs = every_plan_input();
    // All eleven inputs on and off, less the combinations excluded above.
    assert_eq!(inputs.len(), 208);
    // Each distinct expanded source is validated once.
    let mut validated: HashSet<String> = HashSet::new();
    for i in inputs {
        let v = variant_of(i);
        let plan = StepPlan::new(i);
        if i.pore {
            // Saturated soil has no WGSL twin yet: the CPU step updates
            // the pore pressure, and the GPU backend refuses such scenes
            // (`GpuBackend::with_options`), whose step would lack it.
            assert!(plan.cpu_step.contains(&Pass::PoreFlow), "{i:?}");
            assert!(!plan.gpu_step.contains(&Pass::PoreFlow), "{i:?}");
        } else {
            assert_eq!(v.plan(), plan, "{i:?}: the variant's plan");
        }
        let built = plan.gpu_passes();
        let gpu_lists = std::iter::once(plan.gpu_step.clone())
            .chain(plan.stages.iter().map(|&s| plan.gpu_passes_for(s)));
        for pass in gpu_lists.flatten() {
            assert!(built.contains(&pass), "{i:?}: {pass:?} has no pipeline");
        }
        let d = v.defines();
        for &pass in &built {
            let file = pass
                .file()
                .unwrap_or_else(|| panic!("{i:?}: {pass:?} built without WGSL"));
            assert!(shaders.join(file).is_file(), "{pass:?}: no shaders/{file}");
            let src = pipelines::expand(pass, &d).unwrap_or_else(|e| panic!("{pass:?} {i:?}: {e}"));
            if validated.insert(src.clone()) {
                pipelines::validate(&src, file, v.atomics)
                    .unwrap_or_else(|e| panic!("{pass:?} {i:?}: {e}"));
            }
        }
        let cpu_lists = [plan.cpu_step.clone(), plan.cpu_primed.clone()]
            .into_iter()
            .chain(plan.stages.iter().map(|&s| plan.cpu_passes_for(s)));
        for pass in cpu_lists.flatten() {
            assert!(
                CpuBackend::twin(pass).is_some(),
                "{i:?}: {pass:?} has no CPU twin"
            );
        }
        // What the CPU leaves out is done in the same stage by the CPU
        // pass named, or is GPU bookkeeping.
        for &stage in plan.stages {
            let cpu = plan.cpu_passes_for(stage);
            for pass in plan.passes_for(stage) {
                match pass.info().cpu {
                    OnCpu::Twin => {}
                    OnCpu::In(q) => assert!(
                        cpu.contains(&q),
                        "{i:?}: {stage:?}: {pass:?} is done in {q:?}, which the CPU does not run"
                    ),
                    OnCpu::GpuOnly => assert!(on_gpu(pass), "{pass:?} runs nowhere"),
                    OnCpu::Sample => panic!("{i:?}: the sample pass {pass:?} in {stage:?}"),
                }
            }
        }
    }
    // Distinct sources: the test reached the shaders' variants.
    assert!(validated.len() > 100, "{} sources", validated.len());
}
