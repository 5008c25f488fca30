//! The CPU's whole step fuses stages (`shape_eval` with `p2g`, `stress`
//! with `forces`) so each particle's weights are read while they are still
//! in cache; the stages run one by one, as the parity tests run them, must
//! give the very same numbers (same sums, same order).

use lme_mpm::backend::Backend;
use lme_mpm::bench::{Case, scene};
use lme_mpm::cpu::CpuBackend;
use lme_mpm::model::Model;
use lme_mpm::step::STEP;

#[test]
fn fused_step_equals_the_stages_one_by_one() {
    let mc = [
        "materials.m.model=mohr_coulomb",
        "materials.m.cohesion=10",
        "materials.m.friction_angle=30",
    ];
    for (shape, plastic) in [
        ("linear", false),
        ("bspline2", false),
        ("lme", false),
        ("linear", true),
    ] {
        let set = format!("solver.shape={shape}");
        let mut sets = vec![set.as_str()];
        if plastic {
            sets.extend(mc);
        }
        let case = Case::new("t", &sets);
        let model = Model::new(&scene(900, &case).unwrap()).unwrap();
        let mut fused = CpuBackend::new(model.clone());
        let mut staged = CpuBackend::new(model);
        for _ in 0..3 {
            fused.step().unwrap();
            for stage in STEP {
                staged.run_stage_passes(*stage).unwrap();
            }
            staged.set_time(staged.time() + staged.dt());
        }
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
