//! The implicit integrator (CPU): the assembled Jacobian against a finite
//! difference of the residual, the cantilever against the paper's
//! reference with its mesh convergence, Newton's quadratic convergence, and
//! a step that does not converge: cut, then reported unstable (exit 3).

mod common;

use lme_mpm::cpu::implicit::ImplicitBackend;
use lme_mpm::exact::Errors;
use lme_mpm::exact::cantilever::{CantileverErrors, PAPER_NONLINEAR};
use lme_mpm::model::Model;
use lme_mpm::model::fault::FaultKind;
use lme_mpm::solver::RunStatus;
use std::process::Command;

/// The bound on the cantilever at h = 0.25 (relative to 0.67433 m).
const CANTILEVER_H025: f64 = 0.02;
/// Jacobian vs central difference of the residual, relative to the largest
/// entry. The difference's own error is ~1e-8 at ε = 1e-7 m on these scales.
const JACOBIAN_REL: f64 = 1e-6;

fn cantilever(r: &common::Run) -> CantileverErrors {
    match &r.errors {
        Some(Errors::Cantilever(e)) => e.clone(),
        other => panic!("not a cantilever score: {other:?}"),
    }
}

fn newton(r: &common::Run) -> lme_mpm::backend::NewtonStats {
    r.sim
        .backend_ref()
        .newton()
        .expect("an implicit run")
        .clone()
}

#[test]
fn jacobian_is_the_derivative_of_the_residual() {
    // A small Neo-Hookean cantilever, dynamic (inertia in the Jacobian) and
    // static, each shape function; Δu a smooth non-trivial field.
    for shape in ["linear", "ugimp", "lme", "bspline2"] {
        for is_static in [false, true] {
            let s = common::scene(
                "cantilever.toml",
                &[
                    &format!("solver.shape={shape}"),
                    &format!("solver.static={is_static}"),
                    "grid.h=0.5",
                    "bodies.beam.rects=[[0.0, 0.0, 2.0, 1.0]]",
                    "output.probes.tip=[1.9, 0.5]",
                ],
            );
            let mut b = ImplicitBackend::new(Model::new(&s).unwrap()).unwrap();
            let du = |n: usize| {
                let x = n as f64;
                [1e-3 * (0.7 * x).sin(), 2e-3 * (1.3 * x).cos()]
            };
            let dt = if is_static { 1.0 } else { 1e-3 };
            let e = b.jacobian_mismatch(dt, du, 1e-7).unwrap();
            println!("{shape} static={is_static}: Jacobian vs FD {e:.2e}");
            assert!(e < JACOBIAN_REL, "{shape} static={is_static}: {e:e}");
        }
    }
}

#[test]
fn cantilever_at_h_025_is_within_2_percent() {
    let r = common::run("cantilever.toml", &[]);
    assert_eq!(r.status, RunStatus::Completed);
    let e = cantilever(&r);
    let rel = e.rel_error.expect("the paper's beam");
    println!(
        "h = 0.25 bspline2: deflection {:.5} m, {:.3} % from {PAPER_NONLINEAR}",
        e.deflection,
        100.0 * rel
    );
    assert!(rel < CANTILEVER_H025, "{rel}");
    // The clamp carries the beam's weight, ρ g L H = 78480 N/m.
    let reaction = r.recorder.samples.last().unwrap().reactions[0][1];
    assert!((reaction - 78_480.0).abs() < 1e-6 * 78_480.0, "{reaction}");
}

#[test]
fn q4_cantilever_converges_at_second_order() {
    // Paper Fig. 7: quadratic. Errors against 0.67433 m at h = 0.5, 0.25, 0.125.
    let errs: Vec<f64> = [0.5, 0.25, 0.125]
        .iter()
        .map(|h| {
            let r = common::run(
                "cantilever.toml",
                &[&format!("grid.h={h}"), "solver.shape=linear"],
            );
            assert_eq!(r.status, RunStatus::Completed);
            cantilever(&r).rel_error.unwrap()
        })
        .collect();
    for w in errs.windows(2) {
        let order = (w[0] / w[1]).log2();
        println!("Q4 errors {:.3e} -> {:.3e}: order {order:.2}", w[0], w[1]);
        assert!(order >= 1.8, "{errs:?}");
    }
}

#[test]
fn newton_converges_quadratically_on_the_last_load_step() {
    let r = common::run("cantilever.toml", &["solver.load_steps=2"]);
    assert_eq!(r.status, RunStatus::Completed);
    let st = newton(&r);
    let res = &st.last_residuals;
    println!("last step's relative residuals: {res:?}");
    // Pairs in the asymptotic range (below 1e-2) and above round-off
    // (1e-12 of the load): each residual at most 100 times the square of
    // the one before (linear convergence would give ~ a constant ratio).
    let pairs: Vec<(f64, f64)> = res
        .windows(2)
        .map(|w| (w[0], w[1]))
        .filter(|&(a, b)| a < 1e-2 && b > 1e-12)
        .collect();
    assert!(
        !pairs.is_empty(),
        "no iterate in the asymptotic range: {res:?}"
    );
    for (a, b) in pairs {
        assert!(
            b <= 100.0 * a * a,
            "{a:e} -> {b:e} is not quadratic: {res:?}"
        );
    }
    assert!(*res.last().unwrap() <= 1e-9);
}

#[test]
fn a_step_that_does_not_converge_is_cut() {
    // Three iterations do not reach 1e-9 at the full load; half-loads do.
    let r = common::run("cantilever.toml", &["solver.newton_max_iter=3"]);
    assert_eq!(r.status, RunStatus::Completed);
    let st = newton(&r);
    println!("cuts {}, steps {}", st.cuts, st.steps);
    assert!(st.cuts > 0 && st.steps > 1, "{st:?}");
    assert!(cantilever(&r).rel_error.unwrap() < CANTILEVER_H025);
    // Two iterations never do: cut newton_max_cuts times, then unstable.
    let r = common::run("cantilever.toml", &["solver.newton_max_iter=2"]);
    match r.status {
        RunStatus::Unstable { fault, .. } => {
            assert!(
                matches!(fault.kind, FaultKind::NewtonDiverged { cuts: 6, .. }),
                "{fault}"
            );
            assert_eq!(fault.code(), "newton_diverged");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn cli_reports_newton_divergence_with_exit_3() {
    let out = std::env::temp_dir().join(format!("lme-implicit-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let status = Command::new(env!("CARGO_BIN_EXE_lme-mpm"))
        .args(["run", common::case("cantilever.toml").to_str().unwrap()])
        .args([
            "--backend",
            "cpu",
            "--set",
            "solver.newton_max_iter=2",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(
        status.status.code(),
        Some(3),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
    assert!(
        summary.contains("\"reason_code\": \"newton_diverged\""),
        "{summary}"
    );
    assert!(summary.contains("\"cuts\": 6"), "{summary}");
    // The GPU path refuses the implicit integrator: exit 2, naming the key.
    let gpu = Command::new(env!("CARGO_BIN_EXE_lme-mpm"))
        .args(["run", common::case("cantilever.toml").to_str().unwrap()])
        .args(["--backend", "gpu", "--out"])
        .arg(out.join("gpu"))
        .output()
        .unwrap();
    let msg = String::from_utf8_lossy(&gpu.stderr);
    assert_eq!(gpu.status.code(), Some(2), "{msg}");
    assert!(msg.contains("solver.integrator"), "{msg}");
    let _ = std::fs::remove_dir_all(&out);
}
