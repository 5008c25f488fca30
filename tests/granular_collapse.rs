//! Why the cohesionless collapse ran out too far (issue 23 item 4): a
//! column with a = H/W = 1 released from geostatic rest by a gate
//! (`cases/granular_collapse.toml` at h = 0.05 m), once with pure FLIP and
//! once with 1 % PIC, everything else equal. FLIP overshoots the
//! experiments' (L_f − L_0)/L_0 = 1.2 a by more than 25 %, its deposit is
//! still moving at 2 s and its particles have spread apart; 1 % of PIC,
//! which only damps the velocity noise FLIP keeps, stops the deposit and
//! brings the run-out within 25 % (docs/methods.md, "Granular collapse").

use lme_mpm::cpu::CpuBackend;
use lme_mpm::model::{Model, Particles};
use lme_mpm::scene::{Override, Scene};
use lme_mpm::simulation::Simulation;
use lme_mpm::solver::{Recorder, RunStatus, Schedule};
use lme_mpm::study::column::run_out;
use lme_mpm::study::granular::GRANULAR_H;

/// The experiments' tolerance the issue accepts: within 25 % of 1.2 a.
const RUN_OUT_REL: f64 = 0.25;
/// The FLIP deposit's kinetic energy at 2 s over the PIC one's: measured
/// 32 (5.3 against 0.17 J/m, 2026-11-29, since `PRELOAD_HOLD`; 57, 7.7
/// against 0.13, on 2026-11-27) since the case's B-splines have
/// their knots on the grid lines (`bspline_knots = "cells"`, so the column
/// starts in balance behind its gate; 650 before, 5.8 against 8.8e-3,
/// on the `midpoints` layout). Both PIC figures are below 1e-5 of m g H,
/// a deposit at rest; the check asks for 20, a deposit still flowing.
const KE_RATIO_MIN: f64 = 20.0;
/// FLIP's least particle density over PIC's: measured 0.15 (135 against
/// 916 kg/m³; 74 against 491 on `midpoints`); the check asks for below a
/// half.
const DENSITY_RATIO_MAX: f64 = 0.5;

struct End {
    ratio: f64,
    kinetic: f64,
    rho_min: f64,
}

/// The case at a = 1 with `solver.pic_fraction = pic`, or unset (None: the
/// default a user gets).
fn collapse(pic: Option<f64>) -> End {
    let a = 1.0;
    let mut sets = vec![
        format!("grid.h={GRANULAR_H}"),
        format!("bodies.column.rects=[[0.0, 0.0, 1.0, {a}]]"),
        "output.vtk_interval=1e9".to_string(),
    ];
    sets.extend(pic.map(|p| format!("solver.pic_fraction={p}")));
    let o: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
    let scene = Scene::from_str(
        lme_mpm::cases::GRANULAR_COLLAPSE,
        "granular_collapse",
        "granular_collapse",
        &o,
    )
    .unwrap();
    if pic.is_none() {
        // The case sets none: the default for a cohesionless granular scene.
        assert_eq!(
            scene.solver().pic_fraction,
            Some(0.01),
            "{:?}",
            scene.chosen
        );
    }
    let model = Model::new(&scene).unwrap();
    let mut sim = Simulation::with_backend(&scene, Box::new(CpuBackend::new(model)));
    let schedule = Schedule {
        vtk_interval: None,
        ..sim.schedule()
    };
    let status = sim.drive_with(schedule, &mut Recorder::default()).unwrap();
    assert_eq!(status, RunStatus::Completed, "pic_fraction {pic:?}");
    let p: Particles = sim.backend().particles().unwrap().clone();
    let ratio = (run_out(&p, GRANULAR_H) - 1.0) / 1.0 / (1.2 * a);
    let kinetic = (0..p.len())
        .map(|i| 0.5 * p.mass[i] * (p.v[i][0].powi(2) + p.v[i][1].powi(2)))
        .sum();
    let rho_min = p.rho.iter().copied().fold(f64::INFINITY, f64::min);
    End {
        ratio,
        kinetic,
        rho_min,
    }
}

#[test]
fn flip_noise_keeps_the_deposit_flowing() {
    // Pure FLIP asked for; the default (1 % PIC for this scene) untouched.
    let flip = collapse(Some(0.0));
    let pic = collapse(None);
    println!(
        "a = 1: run-out over 1.2 a: FLIP {:.3}, 1 % PIC {:.3}; kinetic energy at 2 s {:.3e} and \
         {:.3e} J/m; least density {:.0} and {:.0} kg/m³",
        flip.ratio, pic.ratio, flip.kinetic, pic.kinetic, flip.rho_min, pic.rho_min
    );
    assert!(
        flip.ratio > 1.0 + RUN_OUT_REL,
        "FLIP no longer overshoots ({:.3} of 1.2 a): update docs/methods.md",
        flip.ratio
    );
    assert!(
        (pic.ratio - 1.0).abs() <= RUN_OUT_REL,
        "the default (1 % PIC) off the experiments: {:.3} of 1.2 a",
        pic.ratio
    );
    assert!(
        flip.kinetic > KE_RATIO_MIN * pic.kinetic,
        "FLIP's deposit came to rest too"
    );
    assert!(
        flip.rho_min < DENSITY_RATIO_MAX * pic.rho_min,
        "FLIP's particles did not spread apart"
    );
}
