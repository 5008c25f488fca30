//! The CPU's whole step fuses stages (`shape_eval` with `p2g`, `stress`
//! with `forces`) so each particle's weights are read while they are still
//! in cache, and where the scene stores no shape cache
//! (`ShapeCache::needed`) evaluates the weights in each loop instead; the
//! stages run one by one, as the parity tests run them, store the cache,
//! and must give the very same numbers (same weights, same sums, same
//! order), for every shape and integrator.

use lme_mpm::backend::Backend;
use lme_mpm::bench::{Case, scene};
use lme_mpm::cpu::CpuBackend;
use lme_mpm::cpu::ShapeCache;
use lme_mpm::model::Model;
use lme_mpm::step::stages;

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
            for _ in 0..3 {
                fused.step().unwrap();
                for stage in stages(staged.model.integrator) {
                    staged.run_stage_passes(*stage).unwrap();
                }
                staged.set_time(staged.time() + staged.dt());
            }
            let shape = format!("{shape} {extra} {integrator}");
            runs += 1;
            let (a, b) = (&fused.model.particles, &staged.model.particles);
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
