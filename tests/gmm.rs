//! The Galerkin meshfree method (issue 27; implicit-MPM paper §4.2,
//! Algorithm 2, §5.1): the scene keys' refusals, the Jacobian over a node
//! cloud against a difference of the residual, and the static cantilever
//! with GMM-LME and GMM-MLS against the paper's nonlinear deflection.

mod common;

use lme_mpm::cpu::implicit::{ImplicitBackend, Nodes};
use lme_mpm::exact::Errors;
use lme_mpm::exact::cantilever::{CantileverErrors, PAPER_NONLINEAR};
use lme_mpm::model::Model;
use lme_mpm::scene::{Override, Scene};
use lme_mpm::solver::RunStatus;

/// Jacobian vs central difference of the residual (`JacobianCheck`), as
/// tests/implicit.rs bounds the grid's (measured there 6e-11 to 5e-7).
const JACOBIAN_REL: f64 = 1e-6;

/// The paper's GMM settings on the cantilever (§5.1): r = sqrt(2 h²),
/// MLS dilation f = r/2 (the defaults), LME γ = 1.8.
const LME: [&str; 2] = ["solver.method=gmm", "solver.lme_gamma=1.8"];
const MLS: [&str; 2] = ["solver.method=gmm", "solver.gmm_basis=mls"];

fn cantilever(r: &common::Run) -> CantileverErrors {
    match &r.errors {
        Some(Errors::Cantilever(e)) => e.clone(),
        other => panic!("not a cantilever score: {other:?}"),
    }
}

fn sets<'a>(a: &[&'a str], b: &[&'a str]) -> Vec<&'a str> {
    a.iter().chain(b).copied().collect()
}

#[test]
fn gmm_keys_are_checked_and_what_gmm_lacks_is_refused_naming_the_key() {
    let cases: [(&[&str], &str); 8] = [
        (
            &[
                "solver.method=gmm",
                "solver.integrator=npc",
                "solver.static=false",
            ],
            "solver.method",
        ),
        (
            &["solver.method=gmm", "solver.lme_gamma=0.2"],
            "solver.lme_gamma",
        ),
        (
            &["solver.gmm_search_radius=1.0"],
            "solver.gmm_search_radius",
        ),
        (&["solver.gmm_dilation=0.5"], "solver.gmm_dilation"),
        (
            &["solver.method=gmm", "solver.mls_scope=force"],
            "solver.mls_scope",
        ),
        (
            &["solver.method=gmm", "solver.mls_support=2"],
            "solver.mls_support",
        ),
        (
            &[
                "solver.method=gmm",
                "walls.floor.point=[0.0, -0.5]",
                "walls.floor.normal=[0.0, 1.0]",
                "walls.floor.contact=slip",
            ],
            "is not available with method = \"gmm\" yet",
        ),
        (&["solver.method=fem"], "unknown variant `fem`"),
    ];
    for (set, key) in cases {
        let o: Vec<Override> = set.iter().map(|s| Override::parse(s).unwrap()).collect();
        let e = Scene::load(&common::case("cantilever.toml"), &o)
            .err()
            .unwrap_or_else(|| panic!("{set:?} was accepted"));
        let msg = e.to_string();
        println!("{set:?}: {msg}");
        assert!(msg.contains(key), "{set:?}: {msg}");
        assert_eq!(lme_mpm::Error::from(e).exit_code(), 2);
    }
    // The defaults pass, and GMM-MLS with its own keys.
    common::scene("cantilever.toml", &LME);
    common::scene("cantilever.toml", &sets(&MLS, &["solver.gmm_dilation=1.0"]));
}

#[test]
fn jacobian_over_a_node_cloud_is_the_derivative_of_the_residual() {
    for basis in [&LME[..], &MLS[..]] {
        for is_static in [false, true] {
            let st = format!("solver.static={is_static}");
            let s = common::scene(
                "cantilever.toml",
                &sets(
                    basis,
                    &[
                        &st,
                        "grid.h=0.5",
                        "bodies.beam.rects=[[0.0, 0.0, 2.0, 1.0]]",
                        "output.probes.tip=[1.9, 0.5]",
                    ],
                ),
            );
            let mut b = ImplicitBackend::new(Model::new(&s).unwrap()).unwrap();
            let Nodes::Cloud(c) = &b.nodes else {
                panic!("a GMM scene solves on the grid")
            };
            // 2 m × 1 m at h = 0.5: a 5 × 3 lattice.
            assert_eq!(c.cloud.len(), 15);
            let du = |n: usize| {
                let x = n as f64;
                [1e-3 * (0.7 * x).sin(), 2e-3 * (1.3 * x).cos()]
            };
            let dt = if is_static { 1.0 } else { 1e-3 };
            let e = b.jacobian_mismatch(dt, du, 1e-7).unwrap().mismatch;
            println!("{basis:?} static={is_static}: Jacobian vs FD {e:.2e}");
            assert!(e < JACOBIAN_REL, "{basis:?} static={is_static}: {e:e}");
        }
    }
}

/// One static cantilever run (`cases/cantilever.toml`, one load step).
fn static_cantilever(basis: &[&str], h: f64) -> (f64, f64, f64) {
    let hs = format!("grid.h={h}");
    let r = common::run("cantilever.toml", &sets(basis, &[&hs]));
    assert_eq!(r.status, RunStatus::Completed, "{basis:?} h = {h}");
    let e = cantilever(&r);
    let reaction = r.recorder.samples.last().unwrap().reactions[0][1];
    (e.deflection, e.rel_error.unwrap(), reaction)
}

#[test]
fn static_cantilever_at_h_025() {
    for basis in [&LME[..], &MLS[..]] {
        let (d, rel, reaction) = static_cantilever(basis, 0.25);
        println!(
            "{basis:?} h = 0.25: deflection {d:.5} m, {:.3} % from {PAPER_NONLINEAR}, clamp {reaction:.3} N/m",
            100.0 * rel
        );
        // The clamp carries the beam's weight, ρ g L H = 78480 N/m.
        assert!((reaction - 78_480.0).abs() < 1e-6 * 78_480.0, "{reaction}");
    }
}

/// GMM's mesh study (issue 27's acceptance): self-convergence order of
/// the finest pair at least this, and the finest deflection within
/// `LIMIT_REL` of the Richardson limit. Measured: orders 1.96 (LME) and
/// 1.99 (MLS), 0.057 % and 0.044 % from the limits 0.67438 / 0.67437 m.
const ORDER_MIN: f64 = 1.8;
const LIMIT_REL: f64 = 1e-3;
/// The paper's study h = 0.5 … 0.0625 and one halving more: at 0.0625 the
/// finest is still 0.18 % (MLS) and 0.24 % (LME) from the limit.
const MESH: [f64; 5] = [0.5, 0.25, 0.125, 0.0625, 0.03125];

#[test]
fn cantilever_mesh_study_converges_at_second_order_with_mls_below_lme() {
    let mut errors = Vec::new();
    for basis in [&LME[..], &MLS[..]] {
        let runs: Vec<(f64, f64)> = MESH
            .iter()
            .map(|&h| {
                let (d, rel, _) = static_cantilever(basis, h);
                println!(
                    "{basis:?} h = {h}: {d:.6} m, {:.4} % from {PAPER_NONLINEAR}",
                    100.0 * rel
                );
                (d, rel)
            })
            .collect();
        let d: Vec<f64> = runs.iter().map(|r| r.0).collect();
        let n = d.len();
        let (d1, d2) = (d[n - 2] - d[n - 3], d[n - 1] - d[n - 2]);
        let order = (d1 / d2).log2();
        let limit = d[n - 1] + d2 / (2f64.powf(order) - 1.0);
        let off = (d[n - 1] - limit).abs() / limit;
        println!(
            "{basis:?}: order {order:.3}, Richardson limit {limit:.5} m, finest {:.3} % from it",
            100.0 * off
        );
        assert!(order >= ORDER_MIN, "{basis:?}: order {order}");
        assert!(off <= LIMIT_REL, "{basis:?}: {off}");
        errors.push(runs.iter().map(|r| r.1).collect::<Vec<_>>());
    }
    // The paper's Fig. 7: GMM-MLS below GMM-LME on this case, every h.
    for (k, h) in MESH.iter().enumerate() {
        assert!(
            errors[1][k] < errors[0][k],
            "h = {h}: MLS {} LME {}",
            errors[1][k],
            errors[0][k]
        );
    }
}

/// Peak over static deflection under gravity applied at once: 2 for a
/// linear undamped beam (each mode swings to twice its static share);
/// measured at the probe particle 2.0104 (LME) and 2.0105 (MLS). The bound
/// allows for the nonlinearity (a deflection of L/6: the beam stiffens as
/// it bends, and the swing reaches twice the static deflection's load),
/// the higher modes and the 0.02 s sampling of a 1.4 s period (0.1 %).
const SWING: f64 = 0.02;
/// The work of gravity against the kinetic plus strain energy at the end
/// of the swing (trapezoidal Newmark conserves energy on a linear
/// problem); measured below 0.1 %.
const ENERGY_REL: f64 = 0.01;

#[test]
fn dynamic_cantilever_swings_to_twice_its_static_deflection_on_the_moving_cloud() {
    let h = 0.125;
    let hs = format!("grid.h={h}");
    for basis in [&LME[..], &MLS[..]] {
        // The probe particle's own static deflection (not the fitted
        // mid-height one the score gives), so both are the same point's.
        let st = common::run("cantilever.toml", &sets(basis, &[&hs]));
        assert_eq!(st.status, RunStatus::Completed, "{basis:?}");
        let tip = |s: &lme_mpm::backend::Sample| s.probes[0].x[1];
        let static_d = tip(&st.recorder.samples[0]) - tip(st.recorder.samples.last().unwrap());
        // No grid margin: the tip falls 1.34 m, below the grid (margin 1
        // m), which GMM never reads after seeding its cloud.
        let r = common::run(
            "cantilever.toml",
            &sets(
                basis,
                &[
                    &hs,
                    "solver.static=false",
                    "solver.dt=0.02",
                    "solver.t_end=0.8",
                    "output.sample_interval=0.02",
                ],
            ),
        );
        assert_eq!(r.status, RunStatus::Completed, "{basis:?}");
        let y0 = r.recorder.samples[0].probes[0].x[1];
        let peak = r
            .recorder
            .samples
            .iter()
            .map(|s| y0 - s.probes[0].x[1])
            .fold(0.0, f64::max);
        let ratio = peak / static_d;
        let mut b = r.sim;
        let last = r.recorder.samples.last().unwrap().energy;
        let p = b.backend().particles().unwrap();
        let work: f64 = (0..p.len())
            .map(|i| p.mass[i] * 9.81 * (p.x0[i][1] - p.x[i][1]))
            .sum();
        let balance = (last.kinetic + last.strain - work).abs() / work;
        println!(
            "{basis:?} h = {h}: peak {peak:.5} m, static {static_d:.5} m, ratio {ratio:.4}; \
             kinetic + strain against gravity's work at 0.8 s: {:.3} %",
            100.0 * balance
        );
        assert!((ratio - 2.0).abs() < SWING, "{basis:?}: {ratio}");
        assert!(balance < ENERGY_REL, "{basis:?}: {balance}");
    }
}

/// GMM against implicit MPM (B-splines) over the dynamic swing, both at
/// h = 0.0625 (the same particles, so the same probe particle), at the
/// sample times both reached: the largest difference over the peak.
/// Measured 1.23 % (LME) and 1.17 % (MLS) at 29 common samples.
const AGAINST_MPM: f64 = 0.02;

#[test]
#[ignore = "a reference run of a minute: the dynamic swing against implicit MPM (bspline2)"]
fn dynamic_cantilever_against_implicit_mpm() {
    let run = |extra: &[&str]| {
        let r = common::run(
            "cantilever.toml",
            &sets(
                extra,
                &[
                    "grid.h=0.0625",
                    "solver.static=false",
                    "solver.dt=0.02",
                    "solver.t_end=0.8",
                    "output.sample_interval=0.02",
                    "grid.margin=2.0",
                ],
            ),
        );
        assert_eq!(r.status, RunStatus::Completed, "{extra:?}");
        let y0 = r.recorder.samples[0].probes[0].x[1];
        r.recorder
            .samples
            .iter()
            .map(|s| (s.t, y0 - s.probes[0].x[1]))
            .collect::<Vec<(f64, f64)>>()
    };
    let mpm = run(&["solver.shape=bspline2"]);
    let peak = mpm.iter().fold(0.0f64, |a, &b| a.max(b.1));
    for basis in [&LME[..], &MLS[..]] {
        let g = run(basis);
        let mut d = 0.0f64;
        let mut n = 0;
        for &(t, v) in &g {
            if let Some(&(_, w)) = mpm.iter().find(|(tm, _)| (tm - t).abs() < 1e-9) {
                d = d.max((v - w).abs());
                n += 1;
            }
        }
        println!(
            "{basis:?} against MPM bspline2, h = 0.0625, {n} common samples: max |Δδ| {d:.5} m of a {peak:.4} m swing ({:.2} %)",
            100.0 * d / peak
        );
        // MPM halves some steps (Newton cuts), so not every time is shared.
        assert!(n >= 20, "{n} common samples");
        assert!(d < AGAINST_MPM * peak, "{basis:?}: {d}");
    }
}
