//! The Galerkin meshfree method (issue 27; implicit-MPM paper §4.2,
//! Algorithm 2, §5.1): the scene keys' refusals, the Jacobian over a node
//! cloud against a difference of the residual, and the static cantilever
//! with GMM-LME and GMM-MLS against the paper's nonlinear deflection.

use crate::common;

use lme_mpm::backend::Backend;
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
    let cases: [(&[&str], &str); 7] = [
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

/// A 1 m × 0.5 m elastic block (ρ = 1000 kg/m³, E = 10 MPa, ν = 0.3) on
/// the floor y = 0, its lower face on a lattice line, the floor's
/// contact `contact`; gravity `g`; implicit GMM-LME γ = 2.8.
fn block_scene(contact: &str, g: [f64; 2], solver: &str) -> String {
    format!(
        r#"name = "gmm_block"
[grid]
h = 0.1
origin = [0.0, 0.0]
margin = 0.6
[materials.m]
model = "linear_elastic"
density = 1000.0
E = 1e7
nu = 0.3
[bodies.block]
material = "m"
ppc = 2
rects = [[0.0, 0.0, 1.0, 0.5]]
[walls.floor]
point = [0.0, 0.0]
normal = [0.0, 1.0]
{contact}
[gravity]
g = [{}, {}]
[solver]
method = "gmm"
lme_gamma = 2.8
integrator = "implicit"
implicit_mass = "lumped"
newton_tol = 1e-9
{solver}
[output]
sample_interval = 0.01
"#,
        g[0], g[1]
    )
}

/// The model of a block scene's text.
fn block_model(text: &str) -> Model {
    Model::new(&Scene::from_str(text, "gmm_block", "gmm_block", &[]).unwrap()).unwrap()
}

/// Runs a scene's text in memory on the CPU: status, the samples, and the
/// mass-weighted mean displacement of the particles at the end (m).
fn run_text(text: &str) -> (RunStatus, Vec<lme_mpm::backend::Sample>, [f64; 2]) {
    let scene = Scene::from_str(text, "gmm_block", "gmm_block", &[]).unwrap();
    let mut sim =
        lme_mpm::simulation::Simulation::new(&scene, &lme_mpm::simulation::BackendSpec::cpu())
            .unwrap();
    let mut rec = lme_mpm::solver::Recorder::default();
    let schedule = lme_mpm::solver::Schedule {
        vtk_interval: None,
        ..sim.schedule()
    };
    let status = sim.drive_with(schedule, &mut rec).unwrap();
    let p = sim.backend().particles().unwrap();
    let m: f64 = p.mass.iter().sum();
    let mut u = [0.0; 2];
    for i in 0..p.len() {
        for (d, ud) in u.iter_mut().enumerate() {
            *ud += p.mass[i] * (p.x[i][d] - p.x0[i][d]) / m;
        }
    }
    (status, rec.samples, u)
}

/// The block's weight, ρ g × area (N/m).
const BLOCK_WEIGHT: f64 = 1000.0 * 9.81 * 0.5;
/// A static floor's reaction against the weight: Newton's tolerance
/// (1e-9 of the load) leaves this much; measured 1e-12 or less.
const REACTION_REL: f64 = 1e-6;

#[test]
fn a_block_rests_on_a_floor_that_acts_on_the_clouds_nodes() {
    for contact in [
        "contact = \"friction\"\nfriction = 0.5",
        "contact = \"stick\"",
    ] {
        let text = block_scene(
            contact,
            [0.0, -9.81],
            "static = true\nload_steps = 2\nt_end = 1.0",
        );
        let (status, samples, u) = run_text(&text);
        assert_eq!(status, RunStatus::Completed, "{contact}");
        let r = samples.last().unwrap().reactions[0];
        println!(
            "{contact:?}: floor reaction ({:.6}, {:.6}) N/m against a weight {BLOCK_WEIGHT}, mean u ({:.3e}, {:.3e}) m",
            r[0], r[1], u[0], u[1]
        );
        // The force on the floor is the block's weight, straight down.
        assert!(
            (r[1] + BLOCK_WEIGHT).abs() < REACTION_REL * BLOCK_WEIGHT,
            "{r:?}"
        );
        assert!(r[0].abs() < REACTION_REL * BLOCK_WEIGHT, "{r:?}");
        // It settles by its elastic squash, ρ g H² / (2 M) ≈ 0.9 mm at
        // the top (half that on average), not through the floor.
        assert!(u[1] < 0.0 && u[1] > -1e-3, "{u:?}");
    }
}

/// Gravity tilted by θ = 30° over the floor: the block slides at
/// a = g (sin θ − μ cos θ) (μ = 0.2: 3.206 m/s²) from rest: u = ½ a t².
/// The implicit step starts from the consistent acceleration
/// (`solver.implicit_start = "consistent"`: the floor's nodes take
/// Coulomb's share at t = 0); from a = 0 (the default) the trapezoidal
/// rule (β = 1/4, γ = 1/2) lags ½ a t² by ½ a Δt t − ¼ a Δt², 2.5 % at
/// 0.2 s with Δt = 5 ms, and the test checks that lag too. Measured
/// 0.04 % from the consistent start and 0.02 % off the lagged motion from
/// rest (2026-11-25); the bound leaves room for the contact's ringing
/// under the sudden load.
const SLIDE_REL: f64 = 0.005;
/// A stick floor under the same load: the block's mean moves by its
/// shear and rocking only, 0.80 mm against the 98 mm it would slide
/// without friction (8.1e-3 of it; its static shear alone moves the mean
/// about 0.16 mm, and the sudden load swings it to twice that and more).
const STICK_REL: f64 = 0.02;

#[test]
fn a_block_slides_on_a_friction_floor_and_a_stick_floor_holds_it() {
    let theta = 30f64.to_radians();
    let g = [9.81 * theta.sin(), -9.81 * theta.cos()];
    let (t, dt) = (0.2, 5e-3);
    let solver = format!("dt = {dt}\nt_end = {t}");
    let free = 0.5 * g[0] * t * t;
    let mu = 0.2;
    let a = 9.81 * (theta.sin() - mu * theta.cos());
    for (start, exact) in [
        (
            "rest",
            0.5 * a * t * t - 0.5 * a * dt * t + 0.25 * a * dt * dt,
        ),
        ("consistent", 0.5 * a * t * t),
    ] {
        let text = block_scene(
            &format!("contact = \"friction\"\nfriction = {mu}"),
            g,
            &format!("{solver}\nimplicit_start = \"{start}\""),
        );
        let (status, _, u) = run_text(&text);
        assert_eq!(status, RunStatus::Completed);
        let rel = (u[0] - exact).abs() / exact;
        println!(
            "friction μ = {mu}, start {start}: u_x {:.6} m against {exact:.6} m (½ a t² {:.6} m): {:.3} %, u_y {:.2e} m",
            u[0],
            0.5 * a * t * t,
            100.0 * rel,
            u[1]
        );
        assert!(rel < SLIDE_REL, "{start}: {rel}");
    }
    let (status, _, u) = run_text(&block_scene("contact = \"stick\"", g, &solver));
    assert_eq!(status, RunStatus::Completed);
    println!(
        "stick: u_x {:.3e} m against {free:.4} m free ({:.2e})",
        u[0],
        u[0].abs() / free
    );
    assert!(u[0].abs() < STICK_REL * free, "{u:?}");
}

/// A cloud node that no particle holds (no unknown) stays at rest, where
/// Newmark's update with Δu = 0 (the trapezoidal rule, β = 1/4) would flip
/// its velocity every step and grow its acceleration by 4|v|/Δt a step, a
/// state that a particle gathering the node again would start Newton
/// from (before 2026-11-27, a candidate for the column collapse's NaN at
/// 0.304 s; docs/methods.md, GMM). A node with an unknown and the same
/// Δu = 0 takes Newmark's update, which the test shows too.
#[test]
fn a_cloud_node_that_no_particle_holds_stays_at_rest() {
    use lme_mpm::cpu::implicit::assemble::{NO_DOF, Newmark};
    use lme_mpm::cpu::implicit::gmm::GmmNodes;
    let text = block_scene(
        "contact = \"friction\"\nfriction = 0.5",
        [0.0, -9.81],
        "t_end = 0.1\ndt = 0.01",
    );
    let model = block_model(&text);
    let lme_mpm::model::Integrator::Implicit(settings) = &model.integrator else {
        panic!("the block scene is implicit");
    };
    let mut nodes = GmmNodes::new(&model, settings.gmm.as_ref().unwrap()).unwrap();
    let n = nodes.cloud.len();
    let x0 = nodes.cloud.x.clone();
    for k in 0..n {
        nodes.cloud.v[k] = [1.0, -0.5];
        nodes.cloud.a[k] = [3.0, 2.0];
    }
    // Node 0 lost its particles; node 1 is an unknown that did not move.
    let mut dof: Vec<u32> = (0..n as u32).collect();
    dof[0] = NO_DOF;
    let nm = Newmark {
        beta: 0.25,
        gamma: 0.5,
        dt: 0.01,
        is_static: false,
    };
    let du = vec![[0.0; 2]; n];
    for _ in 0..5 {
        nodes.advance(&du, &dof, &nm);
    }
    let c = &nodes.cloud;
    assert_eq!(c.v[0], [0.0; 2]);
    assert_eq!(c.a[0], [0.0; 2]);
    assert_eq!(c.x[0], x0[0]);
    // Newmark with Δu = 0 five times: v flips to −v, |a| grows.
    assert!((c.v[1][0] + 1.0).abs() < 1e-12, "{:?}", c.v[1]);
    assert!(c.a[1][0].abs() > 1500.0, "{:?}", c.a[1]);
}

/// A block dropped under sudden gravity onto a `stick` floor, dynamic:
/// the floor's nodes that it holds are at rest at the end (velocity and
/// acceleration zero, `GmmNodes::persist_contact`), and no particle
/// moves faster than the block's elastic bounce allows. Measured: the
/// fastest particle 0.0176 m/s at 0.5 s, the floor's nodes 5.7e-7 m/s
/// at most, leaving the floor (the bounce's scale: the static
/// squash ρ g H² / (2 M) ≈ 0.9 mm at the block's frequency c / 4H ≈ 50
/// Hz, about 0.3 m/s). Before the hold, the column collapse's bottom row
/// (a stick floor, Δt 2 ms) reached 94 to 5170 m/s by 0.30 s while moving
/// by millimetres (docs/methods.md, GMM).
const STICK_BOUNCE: f64 = 0.5;
/// A held node's leaving speed (m/s): the penalty's squash, 1e-9 m deep,
/// released over a step is of order 1e-7 m/s.
const STICK_LEAVING: f64 = 1e-5;

/// The block dropped under sudden gravity onto a floor of `contact`,
/// run for 0.5 s (Δt 5 ms): the backend, and its fastest particle (m/s).
fn drop_block(contact: &str) -> (ImplicitBackend, f64) {
    let text = block_scene(contact, [0.0, -9.81], "dt = 5e-3\nt_end = 0.5");
    let mut b = ImplicitBackend::new(block_model(&text)).unwrap();
    let stop = std::sync::atomic::AtomicBool::new(false);
    b.advance(0.5, &stop).unwrap();
    let p = b.particles().unwrap();
    let fastest = p.v.iter().map(|v| v[0].hypot(v[1])).fold(0.0, f64::max);
    (b, fastest)
}

/// A GMM backend's cloud and its nodes on the floor y = 0.
fn floor_nodes(b: &ImplicitBackend) -> (&lme_mpm::cpu::implicit::gmm::GmmNodes, Vec<usize>) {
    let Nodes::Cloud(c) = &b.nodes else {
        panic!("a GMM run solves on its cloud");
    };
    let floor = (0..c.cloud.len())
        .filter(|&n| c.cloud.x[n][1].abs() < 1e-3)
        .collect();
    (c, floor)
}

#[test]
fn a_stick_floor_holds_its_nodes_at_rest() {
    let (b, fastest) = drop_block("contact = \"stick\"");
    let (c, floor) = floor_nodes(&b);
    // Held: nothing along the floor and nothing normal while closed; a
    // node whose contact opened keeps Newmark's leaving part (the
    // penalty's release of its squash, 1e-7 m/s at most).
    let leaving = floor.iter().map(|&n| c.cloud.v[n][1]).fold(0.0, f64::max);
    println!(
        "stick floor: fastest particle {fastest:.3e} m/s; fastest floor node {leaving:.1e} m/s, \
         leaving the floor, over {} nodes",
        floor.len()
    );
    assert!(!floor.is_empty());
    for &n in &floor {
        let (v, a) = (c.cloud.v[n], c.cloud.a[n]);
        assert!(v[0] == 0.0 && a[0] == 0.0, "node {n}: {v:?} {a:?}");
        assert!(v[1] >= 0.0 && a[1] >= 0.0, "node {n}: {v:?} {a:?}");
    }
    assert!(leaving < STICK_LEAVING, "{leaving}");
    assert!(fastest < STICK_BOUNCE, "{fastest}");
}

/// The same drop onto a `slip` floor: its closed nodes keep their motion
/// along the floor but none normal to it (`GmmNodes::persist_contact`,
/// since 2026-11-28): no floor node approaches the floor at the end,
/// none leaves faster than a stick floor's, and the block's spreading
/// still moves some along it. Before, the trapezoidal rule left the
/// approach each node landed with, flipping sign every step.
#[test]
fn a_slip_floor_keeps_no_approach_at_its_closed_nodes() {
    let (b, fastest) = drop_block("contact = \"slip\"");
    let (c, floor) = floor_nodes(&b);
    assert!(!floor.is_empty());
    let leaving = floor.iter().map(|&n| c.cloud.v[n][1]).fold(0.0, f64::max);
    println!(
        "slip floor: fastest particle {fastest:.3e} m/s; fastest floor node {leaving:.1e} m/s \
         leaving the floor, over {} nodes",
        floor.len()
    );
    for &n in &floor {
        let (v, a) = (c.cloud.v[n], c.cloud.a[n]);
        assert!(v[1] >= 0.0 && a[1] >= 0.0, "node {n}: {v:?} {a:?}");
    }
    let along = floor
        .iter()
        .map(|&n| c.cloud.v[n][0].abs())
        .fold(0.0, f64::max);
    println!("slip floor: fastest floor node along it {along:.1e} m/s");
    assert!(along > 0.0, "the slip floor held its nodes along it");
    assert!(leaving < STICK_LEAVING, "{leaving}");
    assert!(fastest < STICK_BOUNCE, "{fastest}");
}

/// The rolling disk with GMM (issue 27, paper §5.2): GMM-LME γ = 2.8 at
/// the study's Δt1 against implicit MPM (Q4, the paper's MPM) at the same
/// short end time, and on a stick wall. The final displacement's error at
/// 0.1 s: measured 3.45 % (friction) and 4.16 % (stick) against implicit
/// MPM's 4.19 %, of which 2.0 % is the implicit step's start from a = 0
/// (the trapezoidal rule lags ½ a t² by about ½ a Δt t, Δt / t of it) and
/// about 1.6 % the disk's bounce on its contact under the sudden load
/// (its centre 0.46 mm into the plane at 0.1 s, whose x part is 1.6 % of
/// u_x); the bound is 1.2 times the stick wall's. Before the cloud's rim
/// nodes were put on the disk's circle (2026-11-28) the disk rolled about
/// nodes outside it, faster, which hid part of both: 2.57 and 3.01 %.
/// Eq. 67 over so short a history is the start's (20 % at the first
/// sample, 0.01 s): 7.1 % GMM, 5.6 % MPM; over the study's 0.5 s GMM is
/// far below (docs/methods.md, GMM).
const GMM_DISK_SHORT: f64 = 0.05;

#[test]
fn gmm_rolling_disk_beats_implicit_mpm_at_a_short_end_time() {
    let common_sets = [
        "solver.integrator=implicit",
        "solver.implicit_mass=lumped",
        "solver.dt=2e-3",
        "solver.t_end=0.1",
    ];
    let gmm = sets(&common_sets, &["solver.method=gmm", "solver.lme_gamma=2.8"]);
    let g = common::disk::disk_run(&gmm);
    let m = common::disk::disk_run(&sets(&common_sets, &["solver.shape=linear"]));
    let stick = common::disk::disk_run_text(&lme_mpm::study::disk::stick_variant(), &gmm);
    for (name, r) in [
        ("GMM-LME", &g),
        ("implicit MPM Q4", &m),
        ("GMM-LME stick", &stick),
    ] {
        println!(
            "{name}: {:?}, eq. 67 {:.3} %, final {:.3} %, {:.2} iterations per step, {} cuts, {:.1} s",
            r.status,
            r.error_percent,
            100.0 * r.final_rel,
            r.newton.mean_iterations(),
            r.newton.cuts,
            r.wall
        );
        assert_eq!(r.status, RunStatus::Completed, "{name}");
    }
    assert!(g.final_rel < GMM_DISK_SHORT, "{}", g.final_rel);
    assert!(stick.final_rel < GMM_DISK_SHORT, "{}", stick.final_rel);
    assert!(g.final_rel < m.final_rel, "{} {}", g.final_rel, m.final_rel);
}

/// GMM's rolling disk as `study implicit` runs it (0.5 s, Δt1 = 2 ms =
/// 2Δt2 = 4Δt3): a measurement for docs/methods.md, not a check.
/// `cargo test --release --test suite -- --ignored --nocapture gmm::gmm_disk_`
fn gmm_disk_rows(label: &str, keys: &[&str], dts: &[f64]) {
    for dt in dts {
        let d = format!("solver.dt={dt}");
        let all = sets(
            &[
                "solver.integrator=implicit",
                "solver.implicit_mass=lumped",
                &d,
            ],
            keys,
        );
        let r = if std::env::var_os("LME_MPM_DISK_STICK").is_some() {
            common::disk::disk_run_text(&lme_mpm::study::disk::stick_variant(), &all)
        } else {
            common::disk::disk_run(&all)
        };
        println!(
            "| {label} | {dt} | {:?} | {:.3} | {:.3} | {:.0} | {:.2} / {} | {} |",
            r.status,
            r.error_percent,
            100.0 * r.final_rel,
            r.wall,
            r.newton.mean_iterations(),
            r.newton.max_iterations,
            r.newton.cuts
        );
    }
}

#[test]
#[ignore = "measurement: GMM-LME γ = 2.8 disk at three Δt (minutes)"]
fn gmm_disk_lme_28() {
    gmm_disk_rows(
        "GMM-LME γ = 2.8",
        &["solver.method=gmm", "solver.lme_gamma=2.8"],
        &[2e-3, 1e-3, 5e-4],
    );
}

#[test]
#[ignore = "measurement: GMM-LME γ = 0.8 and 1.8 disk at three Δt (minutes)"]
fn gmm_disk_lme_other() {
    for g in ["0.8", "1.8"] {
        let k = format!("solver.lme_gamma={g}");
        gmm_disk_rows(
            &format!("GMM-LME γ = {g}"),
            &["solver.method=gmm", &k],
            &[2e-3, 1e-3, 5e-4],
        );
    }
}

#[test]
#[ignore = "measurement: GMM-MLS disk at three Δt (minutes)"]
fn gmm_disk_mls() {
    gmm_disk_rows(
        "GMM-MLS",
        lme_mpm::study::implicit::DISK_GMM[3].1,
        &[2e-3, 1e-3, 5e-4],
    );
}

#[test]
#[ignore = "measurement: one disk run, Δt and keys from LME_MPM_DISK_DT and LME_MPM_DISK_SETS (LME_MPM_DISK_STICK: on the stick wall)"]
fn gmm_disk_one() {
    let dt: f64 = std::env::var("LME_MPM_DISK_DT").map_or(2e-3, |v| v.parse().unwrap());
    let keys = std::env::var("LME_MPM_DISK_SETS").unwrap_or_default();
    let keys: Vec<&str> = keys.split_whitespace().collect();
    gmm_disk_rows("one", &keys, &[dt]);
}

/// `solver.newton_jacobian = "reuse"` (modified Newton: the factorization
/// kept while the contact states hold and the residual falls fourfold per
/// iteration) converges to the same steps as full Newton with fewer
/// factorizations: the GMM-LME rolling disk on its friction wall over
/// 0.05 s at Δt 2 ms. Measured 2026-11-28: full Newton 65 factorizations
/// in 65 iterations, reused 39 in 89; the particles end 1.3e-12 m apart,
/// 1.7e-10 of the largest displacement (7.7e-3 m). Over 0.1 s the run took 4.7 s against 7.9 s on two idle cores (the LU
/// is three quarters of a GMM step); timings belong to benchmarks, so
/// only the count is asserted.
#[test]
fn a_reused_jacobian_reaches_the_same_steps_with_fewer_factorizations() {
    let disk = |jacobian: &str| {
        let j = format!("solver.newton_jacobian={jacobian}");
        let r = common::run(
            "rolling_disk.toml",
            &[
                "solver.integrator=implicit",
                "solver.implicit_mass=lumped",
                "solver.method=gmm",
                "solver.dt=2e-3",
                "solver.t_end=0.05",
                &j,
            ],
        );
        assert_eq!(r.status, RunStatus::Completed, "{jacobian}");
        let n = r.sim.backend_ref().newton().unwrap().clone();
        (r.sim.backend_ref().model().particles.clone(), n)
    };
    let (full, nf) = disk("every_iteration");
    let (reused, nr) = disk("reuse");
    let moved = (0..full.len())
        .map(|i| (full.x[i][0] - full.x0[i][0]).hypot(full.x[i][1] - full.x0[i][1]))
        .fold(0.0, f64::max);
    let apart = (0..full.len())
        .map(|i| (full.x[i][0] - reused.x[i][0]).hypot(full.x[i][1] - reused.x[i][1]))
        .fold(0.0, f64::max);
    println!(
        "full Newton: {} factorizations, {} iterations; reused: {} and {}; particles apart by \
         {apart:.2e} m of {moved:.2e} m moved",
        nf.factorizations, nf.iterations, nr.factorizations, nr.iterations
    );
    // Full Newton factors once per iteration.
    assert_eq!(nf.factorizations, nf.iterations);
    assert!(
        (nr.factorizations as f64) < REUSE_FACTOR_SHARE * nf.factorizations as f64,
        "{} against {}",
        nr.factorizations,
        nf.factorizations
    );
    // Both stop at Newton's tolerance (1e-8 on the residual, its square
    // root on the correction): the same steps, to far below a cell.
    assert!(apart < REUSE_SAME * moved, "{apart} of {moved}");
}

/// Reused factorizations over full Newton's, at most (measured 0.60).
const REUSE_FACTOR_SHARE: f64 = 0.75;
/// How far apart the two runs' particles may end, relative to the largest
/// displacement: both stop where the correction is below sqrt(1e-8) of
/// the step's increment, so they may differ by that much per step in
/// principle; measured 1.7e-10.
const REUSE_SAME: f64 = 1e-6;
