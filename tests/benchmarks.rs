//! The papers' benchmarks on the CPU path, scored against exact solutions:
//! Dyka's bar (NPC vs FE), the elastic block (LME vs Q4), and the test that
//! chose the NPC position update.

use crate::common;

use common::{column, dyka_rms, run};
use lme_mpm::cpu::CpuBackend;
use lme_mpm::model::Model;
use lme_mpm::scene::{Override, Scene};
use lme_mpm::solver::{self, Recorder, RunStatus, Schedule};

/// Dyka's bar, LME γ = 4, NPC, 1 mm cells: we measure an RMS velocity error
/// of 0.503 m/s at t_end = 1e-4 s (10% of the 5 m/s impact speed). At that
/// instant the reflected front is just reaching the free end, and the error
/// is the front smeared over ~3 cells plus the small trailing ripple NPC
/// leaves. The bound is the measured value plus 10%: loose enough for
/// harmless round-off changes, tight enough to fail if the ripple grows
/// (FE's ripple alone adds 20%) or the front arrives a cell late.
const DYKA_LME_NPC_RMS_BOUND: f64 = 0.55;

#[test]
fn dyka_lme_npc_error_is_bounded_and_below_fe() {
    let npc = run("dyka_bar.toml", &[]);
    let fe = run("dyka_bar.toml", &["solver.integrator=fe"]);
    assert_eq!(npc.status, RunStatus::Completed);
    assert_eq!(fe.status, RunStatus::Completed);
    let (e_npc, e_fe) = (dyka_rms(&npc), dyka_rms(&fe));
    println!("Dyka 1 mm LME g=4: RMS NPC {e_npc:.4} m/s, FE {e_fe:.4} m/s");
    assert!(
        e_npc < DYKA_LME_NPC_RMS_BOUND,
        "NPC RMS {e_npc} ≥ {DYKA_LME_NPC_RMS_BOUND}"
    );
    assert!(
        e_npc < 0.9 * e_fe,
        "NPC RMS {e_npc} not clearly below FE's {e_fe}"
    );

    // NPC damps the post-front ripple; FE does not (paper Fig. 8): energy
    // falls a little under NPC and is kept, ripple and all, by FE.
    let energy = |r: &common::Run| -> Vec<f64> {
        r.recorder
            .samples
            .iter()
            .map(|s| s.energy.kinetic + s.energy.strain)
            .collect()
    };
    let (en, ef) = (energy(&npc), energy(&fe));
    let e0 = en[0];
    let max_npc = en.iter().copied().fold(0.0, f64::max);
    assert!(
        max_npc <= e0 * (1.0 + 1e-9),
        "NPC energy grew to {max_npc} from {e0}"
    );
    println!(
        "energy at t_end / E0: NPC {:.4}, FE {:.4}",
        en.last().unwrap() / e0,
        ef.last().unwrap() / e0
    );
    assert!(
        ef.last().unwrap() > en.last().unwrap(),
        "FE should dissipate less than NPC"
    );
}

#[test]
fn elastic_block_lme_matches_the_exact_column() {
    let r = run("elastic_block.toml", &[]);
    assert_eq!(r.status, RunStatus::Completed);
    let e = column(&r);
    println!("{e:?}");
    // The issue's bounds: σ_yy of the bottom row within 5% of −ρ0 g (H − Y),
    // top settlement within 3% of the exact value for our (log-strain) law.
    assert!(e.sigma_yy_bottom_rel_error < 0.05, "{e:?}");
    assert!(e.settlement_rel_error < 0.03, "{e:?}");
    // The base carries the weight: ρ0 g H W = 5.886e6 N/m, give or take the
    // small oscillation the ramp leaves (we see < 1%).
    let ry = r.recorder.samples.last().unwrap().reactions[0][1];
    let weight = 6000.0 * 9.81 * 10.0 * 10.0;
    assert!(
        (ry - weight).abs() < 0.02 * weight,
        "base reaction {ry} vs weight {weight}"
    );
}

#[test]
fn elastic_block_q4_fails_or_is_far_worse_than_lme() {
    let lme = column(&run("elastic_block.toml", &[]));
    let q4 = run("elastic_block.toml", &["solver.shape=linear"]);
    match q4.status {
        RunStatus::Unstable { fault, t, .. } => println!("Q4 went unstable at t = {t}: {fault}"),
        RunStatus::Interrupted { .. } => panic!("nothing interrupts this run"),
        RunStatus::Completed => {
            // Our Q4 completes (the paper's blew up early; see
            // docs/verification.md), but no better than this:
            let q = column(&q4);
            println!("Q4 {q:?}\nLME {lme:?}");
            assert!(
                q.settlement_rel_error > 0.03
                    && q.settlement_rel_error > 10.0 * lme.settlement_rel_error,
                "Q4 settlement error {} vs LME {}",
                q.settlement_rel_error,
                lme.settlement_rel_error
            );
            assert!(
                q.sigma_yy_bottom_rel_error > 3.0 * lme.sigma_yy_bottom_rel_error,
                "Q4 bottom stress error {} vs LME {}",
                q.sigma_yy_bottom_rel_error,
                lme.sigma_yy_bottom_rel_error
            );
        }
    }
}

/// A free-falling, unconstrained body: every particle must follow
/// x0 + v0 t + ½ g t². The three readings of the NPC position update differ
/// by a multiple of Δt² a per step, which adds up to an O(Δt) drift.
fn free_fall(position: &str, shape: &str) -> (f64, f64) {
    let text = r#"
        [grid]
        h = 0.25
        margin = 6.0
        [materials.m]
        model = "linear_elastic"
        density = 1000.0
        E = 1e6
        nu = 0.2
        [bodies.b]
        material = "m"
        velocity = [1.0, 0.0]
        rects = [[0.0, 0.0, 1.0, 1.0]]
        [gravity]
        g = [0.0, -10.0]
        [solver]
        lme_gamma = 3.0
        t_end = 1.0
    "#;
    let sets = [
        format!("solver.npc_position={position}"),
        format!("solver.shape={shape}"),
    ];
    let o: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
    let scene = Scene::from_str(text, "free fall", "fall", &o).unwrap();
    let mut b = CpuBackend::new(Model::new(&scene).unwrap());
    let dt = b.next_dt();
    let status = solver::drive(
        &mut b,
        Schedule {
            sample_interval: 0.1,
            vtk_interval: None,
            ..Default::default()
        },
        &mut Recorder::default(),
    )
    .unwrap();
    assert_eq!(status, RunStatus::Completed);
    let p = &b.model().particles;
    let worst = (0..p.len())
        .map(|i| {
            let dy = p.x[i][1] - p.x0[i][1];
            let dx = p.x[i][0] - p.x0[i][0];
            (dy + 5.0).abs().max((dx - 1.0).abs())
        })
        .fold(0.0, f64::max);
    (worst, dt)
}

#[test]
fn npc_position_reading_newmark_is_exact_in_free_fall() {
    for shape in ["lme", "linear", "ugimp"] {
        let (newmark, dt) = free_fall("newmark", shape);
        let (predicted, _) = free_fall("predicted", shape);
        let (corrected, _) = free_fall("corrected", shape);
        println!(
            "{shape}: dt {dt:.3e}; drift newmark {newmark:.3e}, predicted {predicted:.3e}, corrected {corrected:.3e} m"
        );
        // Newmark: exact but for the first step, where a_p = 0 (½Δt² g).
        assert!(
            newmark < 0.5 * dt * dt * 10.0 * 1.01,
            "{shape}: newmark drift {newmark}"
        );
        // The paper's printed reading drifts by ½ Δt g t, the authors' code by Δt g t.
        let gt = 10.0 * 1.0;
        assert!(
            (predicted / (0.5 * dt * gt) - 1.0).abs() < 0.05,
            "{shape}: predicted drift {predicted}"
        );
        assert!(
            (corrected / (dt * gt) - 1.0).abs() < 0.05,
            "{shape}: corrected drift {corrected}"
        );
    }
}

#[test]
fn npc_position_readings_agree_on_dyka() {
    // Dyka's displacements are ~3e-5 of the bar: the reading cannot matter
    // there, and must not (it only moves particles, not the strain).
    let base = dyka_rms(&run("dyka_bar.toml", &["solver.npc_position=newmark"]));
    for pos in ["predicted", "corrected"] {
        let e = dyka_rms(&run(
            "dyka_bar.toml",
            &[&format!("solver.npc_position={pos}")],
        ));
        assert!(
            (e - base).abs() < 1e-3 * base,
            "{pos}: {e} vs newmark {base}"
        );
    }
}

/// The manufactured aligned vibration (A = 0.1 m, Δt = 1e-5 s) with
/// bspline2 + MLS over one period (0.02 s): the displacement error falls
/// from 8 to 16 to 32 cells at the paper's second order. We measure RMS
/// errors of 0.104, 0.0205 and 0.00335 m, orders 2.3 and 2.6. Only the
/// displacement is asserted: the velocity's order over this period is 2.3
/// then 1.0, and over the paper's ten periods the fit's smoothing and the
/// particle-scale modes it cannot see take over (docs/verification.md,
/// `lme-mpm study mms`).
fn bspline2_mls_orders(cells: &[f64]) {
    let errors: Vec<f64> = cells
        .iter()
        .map(|n| {
            let h = format!("grid.h={}", 1.0 / n);
            let r = run(
                "aligned_vibration.toml",
                &[
                    &h,
                    "solver.shape=bspline2",
                    "solver.mls=true",
                    "solver.mls_scope=all",
                    "solver.t_end=0.02",
                ],
            );
            assert_eq!(r.status, RunStatus::Completed, "{n} cells");
            match r.errors {
                Some(lme_mpm::exact::Errors::Mms(e)) => e.rms_displacement,
                other => panic!("no manufactured errors: {other:?}"),
            }
        })
        .collect();
    let orders: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    println!("bspline2+MLS one period: RMS displacement {errors:?}, orders {orders:?}");
    for o in orders {
        assert!(o >= 1.8, "order {o} below 1.8: errors {errors:?}");
    }
}

/// 8 to 16 cells in the suite; the 32-cell run was three quarters of the
/// whole (about 70 s of 96 on 2 cores, 2026-12-02) and is the ignored
/// acceptance run below.
#[test]
fn aligned_vibration_bspline2_mls_converges_at_second_order_over_one_period() {
    bspline2_mls_orders(&[8.0, 16.0]);
}

///   cargo test --release --test suite -- --ignored benchmarks::aligned_vibration_bspline2_mls_converges_to_32_cells
#[test]
#[ignore]
fn aligned_vibration_bspline2_mls_converges_to_32_cells() {
    bspline2_mls_orders(&[8.0, 16.0, 32.0]);
}

/// The B-spline paper's method as printed (bspline2 + MLS with its MUSL
/// update and weight), asserted as measured on 2026-11-23, not as the paper
/// claims: over the ten periods it stops with `energy_runaway` at 0.024 s
/// on 8 cells, where plain bspline2 completes. Over one period it
/// converges at second order but errs 8 times more than plain bspline2;
/// those figures are asserted by `studies::mms_quick_…`, whose quick sweep
/// runs exactly those runs (the same scene, E, MUSL and end time), so they
/// are not run twice. The cause is the fit (docs/methods.md, "Why MLS is
/// less accurate"); `tests/mls_reconstruction.rs` measures it.
#[test]
fn aligned_vibration_paper_method_figures_as_measured() {
    let disp = |sets: &[&str]| -> (RunStatus, f64) {
        let r = run("aligned_vibration.toml", sets);
        let e = match r.errors {
            Some(lme_mpm::exact::Errors::Mms(e)) => e.rms_displacement,
            other => panic!("no manufactured errors: {other:?}"),
        };
        (r.status, e)
    };
    let paper = [
        "solver.shape=bspline2",
        "solver.mls=true",
        "solver.mls_scope=all",
        "solver.integrator=musl",
    ];
    let plain = ["solver.shape=bspline2", "solver.integrator=musl"];
    let with = |base: &[&'static str], more: &[&'static str]| -> Vec<&'static str> {
        base.iter().chain(more).copied().collect()
    };
    // Ten periods at 8 cells.
    let (s, _) = disp(&with(&paper, &["grid.h=0.125"]));
    match s {
        RunStatus::Unstable { fault, t, .. } => {
            assert_eq!(fault.code(), "energy_runaway");
            assert!(
                (0.02..0.03).contains(&t),
                "unstable at {t} s, measured 0.024 s"
            );
        }
        other => panic!("measured unstable at 0.024 s, got {other:?}"),
    }
    let (s, _) = disp(&with(&plain, &["grid.h=0.125"]));
    assert_eq!(
        s,
        RunStatus::Completed,
        "plain bspline2 completes the ten periods"
    );
}
