//! The CPU's whole step fuses stages (`shape_eval` with `p2g`, `stress`
//! with `forces`) so each particle's weights are read while they are still
//! in cache, and where the scene stores no shape cache
//! (`ShapeCache::needed`) evaluates the weights in each loop instead; the
//! stages run one by one, as the parity tests run them, store the cache,
//! and must give the very same numbers (same weights, same sums, same
//! order), for every shape and integrator. Where the plan primes
//! (`StepPlan::primes`), each step also ends with the next one's P2G
//! (`Pass::G2pP2g`), which must leave the very grid and Δt that the next
//! step's `cfl`, `clear_grid`, `shape_eval` and `p2g` stages make; and the
//! loops' x86-64-v3 build (`cpu::isa`) must give the baseline's numbers.

use lme_mpm::backend::Backend;
use lme_mpm::bench::{Case, scene};
use lme_mpm::cpu::CpuBackend;
use lme_mpm::cpu::ShapeCache;
use lme_mpm::cpu::isa;
use lme_mpm::model::Model;
use lme_mpm::step::{Pass, Stage, stages};

#[test]
fn fused_step_equals_the_stages_one_by_one() {
    let mc = [
        "materials.m.model=mohr_coulomb",
        "materials.m.cohesion=10",
        "materials.m.friction_angle=30",
    ];
    let mut runs = 0;
    for integrator in ["npc", "fe", "musl"] {
        for (shape, extra) in [
            ("linear", ""),
            ("ugimp", ""),
            ("bspline2", ""),
            ("bspline3", ""),
            ("lme", ""),
            ("linear", "plastic"),
            // Not separable: evaluated by `Shape::eval` in each loop.
            ("linear", "grid.perturb=0.1"),
            ("linear", "solver.pic_fraction=0.3"),
        ] {
            let set = format!("solver.shape={shape}");
            let int = format!("solver.integrator={integrator}");
            let mut sets = vec![set.as_str(), int.as_str()];
            let plastic = extra == "plastic";
            if plastic {
                sets.extend(mc);
            } else if !extra.is_empty() {
                sets.push(extra);
            }
            let case = Case::new("t", &sets);
            let model = Model::new(&scene(900, &case).unwrap()).unwrap();
            // The fast path is what these scenes run: nothing stored unless
            // LME or MUSL.
            assert_eq!(
                ShapeCache::needed(&model),
                shape == "lme" || integrator == "musl",
                "{shape} {integrator}"
            );
            let mut fused = CpuBackend::new(model.clone());
            let mut staged = CpuBackend::new(model);
            let primes = fused.plan.primes();
            assert_eq!(
                primes,
                !ShapeCache::needed(fused.model()),
                "{shape} {integrator}"
            );
            assert_eq!(
                fused.plan.cpu_step.contains(&Pass::G2pP2g),
                primes,
                "{shape} {integrator}"
            );
            for _ in 0..3 {
                fused.step().unwrap();
                for stage in stages(staged.model().integrator) {
                    staged.run_stage_passes(*stage).unwrap();
                }
                staged.set_time(staged.time() + staged.dt());
            }
            let shape = format!("{shape} {extra} {integrator}");
            runs += 1;
            assert_eq!(fused.primed(), primes, "{shape}");
            if primes {
                // The grid the fused step left is the next step's start.
                for stage in [Stage::Cfl, Stage::ClearGrid, Stage::ShapeEval, Stage::P2g] {
                    staged.run_stage_passes(stage).unwrap();
                }
            }
            let (a, b) = (&fused.model().particles, &staged.model().particles);
            assert_eq!(a.stress, b.stress, "{shape}");
            assert_eq!(a.rho, b.rho, "{shape}");
            assert_eq!(a.x, b.x, "{shape}");
            assert_eq!(fused.force, staged.force, "{shape}");
            assert_eq!(fused.mv, staged.mv, "{shape}");
            assert_eq!(a.lambda, b.lambda, "{shape}");
            assert_eq!(a.plastic, b.plastic, "{shape}");
            if plastic {
                // The plastic path was exercised.
                assert!(
                    a.plastic.iter().any(|q| q[1] > 0.0),
                    "{shape}: nothing yielded"
                );
            }
        }
    }
    assert_eq!(runs, 24);
}

/// A primed run equals one that starts every step from the particles
/// (each step's grid dropped: `unprime`), and the x86-64-v3 build of the
/// loops equals the baseline's, bit for bit, over 20 steps of NPC with
/// each separable shape, FE, and the PIC blend.
#[test]
fn primed_steps_and_vector_code_change_no_bit() {
    for sets in [
        &["solver.shape=linear"][..],
        &["solver.shape=bspline2"],
        &["solver.shape=bspline3"],
        &["solver.shape=ugimp"],
        &["solver.shape=linear", "solver.integrator=fe"],
        &["solver.shape=bspline2", "solver.pic_fraction=0.3"],
    ] {
        let case = Case::new("t", sets);
        let model = Model::new(&scene(900, &case).unwrap()).unwrap();
        let run = |vector: bool, prime: bool| {
            isa::set_enabled(vector);
            let mut cpu = CpuBackend::new(model.clone());
            assert!(cpu.plan.primes(), "{sets:?}");
            for _ in 0..20 {
                if !prime {
                    cpu.unprime();
                }
                cpu.step().unwrap();
            }
            isa::set_enabled(true);
            (cpu.model().particles.clone(), cpu.time())
        };
        let (base, t) = run(false, true);
        let (unprimed, t1) = run(false, false);
        assert_eq!(
            (&base.x, &base.v, &base.stress),
            (&unprimed.x, &unprimed.v, &unprimed.stress),
            "{sets:?}"
        );
        assert_eq!(t, t1);
        let (vector, t2) = run(true, true);
        assert_eq!(
            (&base.x, &base.v, &base.stress),
            (&vector.x, &vector.v, &vector.stress),
            "{sets:?}"
        );
        assert_eq!(t, t2);
        // The particles moved.
        assert!(base.x != model.particles.x, "{sets:?}");
    }
}
