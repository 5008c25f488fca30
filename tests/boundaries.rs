//! Walls, prescribed velocities, tractions and point loads against exact
//! answers: a block sliding on a frictional plane (both geometries,
//! sliding and at rest; CPU and GPU), issue 23's suddenly loaded block
//! (at rest for μ > tan θ, sliding otherwise), a
//! suddenly loaded bar (stress behind the front), a column under a
//! surcharge and its weight (σ_yy = −p − ρ0 g (H − Y)), and a disk rolling
//! on friction and stick walls on a grid line.

use crate::common;

use lme_mpm::backend::Backend;
use lme_mpm::cpu::CpuBackend;
use lme_mpm::exact::Errors;
use lme_mpm::exact::sliding::SlidingErrors;
use lme_mpm::gpu::GpuBackend;
use lme_mpm::model::Model;
use lme_mpm::scene::{Override, Scene};
use lme_mpm::simulation::Simulation;
use lme_mpm::solver::{Recorder, RunStatus, Schedule};

/// The sliding block's velocity along the plane at t = 0.5 s within 2% of
/// the exact a R(t) (the issue's bound). We measure 0.2% to 0.6% on the CPU
/// (see docs/verification.md); the error is the elastic block's small
/// bounce on the wall, which modulates the normal force and so the friction.
const SLIDING_TOL: f64 = 0.02;
/// At rest (tan θ ≤ μ): the mean velocity over the frictionless speed
/// g_t R(t). We measure ≤ 1e-4 on both geometries; 2% as for sliding.
const AT_REST_TOL: f64 = 0.02;

fn scene_of(text: &str, sets: &[&str]) -> Scene {
    let o: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
    Scene::from_str(text, "test scene", "test", &o).unwrap_or_else(|e| panic!("{sets:?}: {e}"))
}

/// Runs `scene` on `backend` to t_end; the final particles and the samples.
fn run(scene: &Scene, backend: Box<dyn Backend>) -> (Simulation, Recorder) {
    let mut sim = Simulation::with_backend(scene, backend);
    let mut rec = Recorder::default();
    let schedule = Schedule {
        vtk_interval: None,
        ..sim.schedule()
    };
    let status = sim.drive_with(schedule, &mut rec).unwrap();
    assert_eq!(status, RunStatus::Completed);
    (sim, rec)
}

fn sliding(sim: &mut Simulation) -> SlidingErrors {
    match sim.score().unwrap() {
        Some(Errors::Sliding(e)) => e,
        other => panic!("not a sliding score: {other:?}"),
    }
}

/// Both geometries (tilted gravity on a level wall, vertical gravity on a
/// 30° wall), sliding (μ = 0.3) and at rest (μ = 0.7), and the sudden
/// gravity variant of the sliding one, on the CPU.
#[test]
fn sliding_block_matches_exact_on_cpu() {
    for (case, wall) in [
        ("sliding_block.toml", "floor"),
        ("sliding_block_incline.toml", "slope"),
    ] {
        let rest = format!("walls.{wall}.friction=0.7");
        for sets in [&[][..], &["gravity.ramp=none"][..], &[rest.as_str()][..]] {
            // Without the ramp the case's ramp_period has no effect, and
            // is refused: the text drops it (an override cannot).
            let scene = if sets == ["gravity.ramp=none"] {
                let text = std::fs::read_to_string(common::case(case)).unwrap();
                let text: Vec<&str> = text
                    .lines()
                    .filter(|l| !l.starts_with("ramp_period"))
                    .collect();
                let o = [lme_mpm::scene::Override::parse(sets[0]).unwrap()];
                lme_mpm::scene::Scene::from_str(&text.join("\n"), case, case, &o).unwrap()
            } else {
                common::scene(case, sets)
            };
            let model = Model::new(&scene).unwrap();
            let (mut sim, _) = run(&scene, Box::new(CpuBackend::new(model)));
            let e = sliding(&mut sim);
            println!("{case} {sets:?}: {e:?}");
            let tol = if e.velocity_exact > 0.0 {
                SLIDING_TOL
            } else {
                AT_REST_TOL
            };
            assert!(e.velocity_rel_error < tol, "{case} {sets:?}: {e:?}");
        }
    }
}

/// Issue 23's suddenly loaded block: E = 1 MPa, 1 m × 0.5 m, h = 0.05 m,
/// gravity tilted 30° applied at once (no ramp), so the elastic block
/// rings on the wall. It must rest (|v| below `SUDDEN_REST_SPEED`) for
/// μ = 0.7 and 1.0 (> tan 30°), and slide within `SUDDEN_SLIDE_TOL` of
/// g (sin θ − μ cos θ) t for μ = 0.5. Measured (2026-11-29, walls at the
/// contact points, k = 0.025 M/h): 0.0080 and 0.0010 m/s, and 2.90 %
/// fast; at k = 0.03 M/h (2026-11-25) 0.0055 and 0.00017 m/s, and 3.18 %
/// fast; with the node rule before, 0.24 and 0.11 m/s, and 58 % fast.
const SUDDEN_BLOCK: &str = r#"
exact = "sliding_block"
[grid]
h = 0.05
origin = [0.0, 0.0]
margin = 0.5
[materials.block]
model = "linear_elastic"
density = 1000.0
E = 1e6
nu = 0.3
[bodies.block]
material = "block"
rects = [[0.0, 0.0, 1.0, 0.5]]
[walls.floor]
point = [0.0, 0.0]
normal = [0.0, 1.0]
contact = "friction"
friction = 0.7
[gravity]
g = [4.905, -8.495709211]
ramp = "none"
[solver]
shape = "linear"
t_end = 0.5
[output]
sample_interval = 0.1
"#;
/// Issue 23's bound on the resting block's speed (m/s).
const SUDDEN_REST_SPEED: f64 = 0.02;
/// The sliding block's velocity, relative: issue 23's bound, 3 %;
/// measured 2.90 % (μ = 0.5, 2026-11-29, k = 0.025 M/h); 3.18 % at the
/// k = 0.03 M/h before (docs/methods.md, "The penalty's stiffness,
/// again"). The whole excess is the landing (`SUDDEN_LANDING`): the
/// rigid block's a t is not the elastic block's answer
/// (`exact::sliding`).
const SUDDEN_SLIDE_TOL: f64 = 0.03;
/// The end of the block's landing on its floor (s): by then its bounce
/// on the wall has died down (mean normal speed 6.8e-5 m/s at 0.25 s;
/// 3.0e-3 at 0.2 s, when some contact points still stick at each bounce
/// and the Coulomb invariant after it grows at a (1 + 9.2e-5); k = 0.025
/// M/h, 2026-11-29). The stiffer k = 0.03 M/h before landed by 0.1 s.
const SUDDEN_LANDING: f64 = 0.25;
/// How far the Coulomb invariant v_t + μ v_n may grow from a (relative)
/// between the landing and 0.5 s: it grows at a exactly while every
/// contact point slides with friction μ N (`exact::sliding`), and the
/// step's momentum balance is exact, so the measured 4.8e-15
/// (2026-11-29) is round-off; 1e-6 fails a contact point that sticks for
/// one step of the 0.25 s.
const COULOMB_SLOPE_TOL: f64 = 1e-6;

/// The suddenly loaded block at μ = `mu` to `t_end` (s), scored.
fn sudden_block(mu: &str, t_end: f64) -> SlidingErrors {
    let sets = [
        format!("walls.floor.friction={mu}"),
        format!("solver.t_end={t_end}"),
    ];
    let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
    let scene = scene_of(SUDDEN_BLOCK, &sets);
    let model = Model::new(&scene).unwrap();
    let (mut sim, _) = run(&scene, Box::new(CpuBackend::new(model)));
    sliding(&mut sim)
}

/// At rest for μ > tan θ; for μ = 0.5 two checks. The friction law: after
/// the landing, v_t + μ v_n grows at a = g (sin θ − μ cos θ) within
/// `COULOMB_SLOPE_TOL` (every contact slides with friction μ N). The
/// issue's figure: v_t at 0.5 s within `SUDDEN_SLIDE_TOL` of a t; what it
/// misses is the friction the base did not use while it stuck at the
/// peak of the landing (v_t + μ v_n − a t: 1.0e-2 m/s from 0.08 s on,
/// 2e-4 at 0.01 s), which a rigid block has no part in and an elastic
/// one, ringing undamped, makes far larger (`exact::sliding`).
#[test]
fn suddenly_loaded_block_rests_or_slides_as_coulomb_says() {
    for mu in ["0.7", "1.0"] {
        let e = sudden_block(mu, 0.5);
        println!("sudden block mu = {mu}: {e:?}");
        assert!(e.velocity_exact == 0.0);
        assert!(e.velocity.abs() < SUDDEN_REST_SPEED, "mu {mu}: {e:?}");
    }
    let landed = sudden_block("0.5", SUDDEN_LANDING);
    let e = sudden_block("0.5", 0.5);
    println!("sudden block mu = 0.5 at {SUDDEN_LANDING} s: {landed:?}");
    println!("sudden block mu = 0.5: {e:?}");
    let slope = (e.coulomb_velocity - landed.coulomb_velocity)
        / ((0.5 - SUDDEN_LANDING) * e.acceleration_exact)
        - 1.0;
    println!(
        "v_t + mu v_n grows at a (1 {slope:+.2e}) after the landing; \
         it is {:.3e} m/s ahead of a t at 0.5 s",
        e.coulomb_velocity - e.velocity_exact
    );
    assert!(slope.abs() < COULOMB_SLOPE_TOL, "{slope}");
    assert!(e.velocity_rel_error < SUDDEN_SLIDE_TOL, "{e:?}");
}

#[test]
fn sliding_block_matches_exact_on_gpu() {
    for (case, wall) in [
        ("sliding_block.toml", "floor"),
        ("sliding_block_incline.toml", "slope"),
    ] {
        let rest = format!("walls.{wall}.friction=0.7");
        for sets in [&[][..], &[rest.as_str()][..]] {
            let Some(ctx) = common::gpu::open(case, false) else {
                return;
            };
            let scene = common::scene(case, sets);
            let model = Model::new(&scene).unwrap();
            let (mut sim, _) = run(&scene, Box::new(GpuBackend::new(ctx, model).unwrap()));
            let e = sliding(&mut sim);
            println!("gpu {case} {sets:?}: {e:?}");
            let tol = if e.velocity_exact > 0.0 {
                SLIDING_TOL
            } else {
                AT_REST_TOL
            };
            assert!(e.velocity_rel_error < tol, "gpu {case} {sets:?}: {e:?}");
        }
    }
}

/// A bar 1 m × 0.1 m (ν = 0, free all round) pulled at its right end by a
/// traction p = 10 kPa applied suddenly at t = 0. The front runs left at
/// c = sqrt(E/ρ) = 100 m/s; at t = 5 ms it is at x = 0.5 m, and behind it
/// σ_xx = p and the material moves toward the load at v_x = p/(ρ c) = 0.1 m/s.
const BAR: &str = r#"
[grid]
h = 0.02
origin = [0.0, 0.0]
margin = 0.02
[materials.m]
model = "linear_elastic"
density = 1000.0
E = 1e7
nu = 0.0
[bodies.bar]
material = "m"
rects = [[0.0, 0.0, 1.0, 0.1]]
[tractions.end]
from = [1.0, 0.0]
to = [1.0, 0.1]
traction = [1e4, 0.0]
[solver]
lme_gamma = 3.0
t_end = 0.005
[output]
sample_interval = 0.001
"#;

/// The stress behind the front within 2% of the traction (the issue's
/// bound) as the mean σ_xx of the particles with 0.6 ≤ X ≤ 0.9 m (five cells
/// clear of the front and of the loaded layer), and v_x there likewise. We
/// measure 0.5% (Q4) to 0.9% (LME NPC): the front's overshoot, not yet
/// decayed 5 cells behind it.
const BAR_STRESS_TOL: f64 = 0.02;
/// The bar's momentum equals the impulse p H t: the particle shares add up
/// to the traction exactly. We measure 4e-11 (LME), 2e-15 (Q4) and 1.2e-9
/// (uGIMP) relative after 500 steps: round-off.
const BAR_MOMENTUM_TOL: f64 = 1e-8;

#[test]
fn suddenly_loaded_bar_carries_the_traction() {
    for sets in [
        &[][..],
        &["solver.integrator=fe"][..],
        &["solver.shape=linear"][..],
        &["solver.shape=ugimp"][..],
    ] {
        let scene = scene_of(BAR, sets);
        let model = Model::new(&scene).unwrap();
        let (mut sim, _) = run(&scene, Box::new(CpuBackend::new(model)));
        let t = sim.backend().time();
        let p = sim.backend().particles().unwrap();
        let behind: Vec<usize> = (0..p.len())
            .filter(|&i| (0.6..=0.9).contains(&p.x0[i][0]))
            .collect();
        let sxx = behind.iter().map(|&i| p.stress[i][0]).sum::<f64>() / behind.len() as f64;
        let vx = behind.iter().map(|&i| p.v[i][0]).sum::<f64>() / behind.len() as f64;
        let momentum: f64 = (0..p.len()).map(|i| p.mass[i] * p.v[i][0]).sum();
        let impulse = 1e4 * 0.1 * t;
        let err = (sxx - 1e4).abs() / 1e4;
        println!(
            "bar {sets:?}: sigma_xx behind the front {sxx:.1} Pa (rel. error {err:.2e}), \
             v_x {vx:.4} m/s (exact 0.1), momentum / impulse − 1 = {:.1e}",
            momentum / impulse - 1.0
        );
        assert!(err < BAR_STRESS_TOL, "{sets:?}: {sxx}");
        assert!((vx - 0.1).abs() < 0.1 * BAR_STRESS_TOL, "{sets:?}: {vx}");
        assert!(
            (momentum / impulse - 1.0).abs() < BAR_MOMENTUM_TOL,
            "{sets:?}"
        );
    }
}

/// A column 4 m wide and 10 m high (ν = 0, E = 500 MPa, ρ0 = 6000 kg/m³)
/// on a fixed base, under gravity ramped by eq. 45 (T = 20 s) and a
/// surcharge p = 200 kPa on its top, ramped over 10 s; scored at t = 20 s,
/// ten seconds after both are full. The column is stiff (strain 0.2%,
/// period 4H/c = 0.14 s) so the ramps are slow against its period and it
/// is at rest: the elastic block's 5 MPa leaves an oscillation of ±10% in
/// σ_yy after a 10 s linear ramp.
const COLUMN: &str = r#"
[grid]
h = 1.0
origin = [0.0, 0.0]
[materials.soil]
model = "linear_elastic"
density = 6000.0
E = 5e8
nu = 0.0
[bodies.column]
material = "soil"
rects = [[0.0, 0.0, 4.0, 10.0]]
[constraints.base]
min = [-inf, -inf]
max = [inf, 0.0]
fix = "xy"
[tractions.surcharge]
from = [0.0, 10.0]
to = [4.0, 10.0]
traction = [0.0, -2e5]
ramp_time = 10.0
[gravity]
g = [0.0, -9.81]
ramp = "sine"
ramp_period = 20.0
[solver]
lme_gamma = 3.0
t_end = 20.0
[output]
sample_interval = 0.5
"#;

/// σ_yy = −p − ρ0 g (H − Y) within 1% (the issue's bound) at rest, as
/// the mean σ_yy of each cell's layer of particles against the exact value
/// at the layer's mid-height, for every layer but the two under the load;
/// and the base reaction equals p W + ρ0 g H W within 1%. A particle's own
/// σ_yy is off by up to ±ρ0 g h/4 (2% here) as the stress is nearly
/// constant across a cell, and the two loaded layers are off by O(p): the
/// traction enters as forces on the top particle row, h/(2 ppc) below the
/// surface (docs/methods.md). The figures are printed and written in
/// docs/verification.md.
const COLUMN_TOL: f64 = 0.01;

#[test]
fn column_with_a_surcharge_matches_the_exact_stress() {
    for sets in [
        &[][..],
        &["solver.shape=linear"][..],
        &["solver.integrator=fe"][..],
    ] {
        let scene = scene_of(COLUMN, sets);
        let model = Model::new(&scene).unwrap();
        let (mut sim, rec) = run(&scene, Box::new(CpuBackend::new(model)));
        let p = sim.backend().particles().unwrap();
        let (rho, g, h, w, q, cell) = (6000.0, 9.81, 10.0, 4.0, 2e5, 1.0);
        let exact = |y: f64| -q - rho * g * (h - y);
        let layers = (h / cell) as usize;
        let mut worst: f64 = 0.0;
        let mut loaded = Vec::new();
        for k in 0..layers {
            let sel: Vec<usize> = (0..p.len())
                .filter(|&i| (p.x0[i][1] / cell).floor() as usize == k)
                .collect();
            let mean = sel.iter().map(|&i| p.stress[i][1]).sum::<f64>() / sel.len() as f64;
            let want = exact((k as f64 + 0.5) * cell);
            let err = (mean - want).abs() / want.abs();
            if k + 2 < layers {
                worst = worst.max(err);
            } else {
                loaded.push(err);
            }
        }
        let ry = rec.samples.last().unwrap().reactions[0][1];
        let load = q * w + rho * g * h * w;
        println!(
            "column {sets:?}: worst layer-mean sigma_yy error {worst:.2e} (the two loaded \
             layers: {loaded:?}); base reaction / load − 1 = {:.2e}",
            ry / load - 1.0
        );
        assert!(worst < COLUMN_TOL, "{sets:?}: {worst}");
        assert!((ry / load - 1.0).abs() < COLUMN_TOL, "{sets:?}: {ry}");
    }
}

/// A disk (R = 0.5 m, Neo-Hookean, ρ = 7800 kg/m³, E = 200 MPa) at rest on
/// a level wall on a grid line, gravity tilted by 30°: R/h = 10, linear,
/// NPC, to t = 0.5 s (issue 23's coarse case).
const DISK_ON_A_GRID_LINE: &str = r#"
exact = "rolling_disk"
[grid]
h = 0.05
min = [-0.6, -0.3]
max = [1.4, 1.3]
[materials.steel_like]
model = "neo_hookean"
density = 7800.0
E = 2e8
nu = 0.3
[bodies.disk]
material = "steel_like"
ppc = 2
disks = [[0.0, 0.5, 0.5]]
[walls.floor]
point = [0.0, 0.0]
normal = [0.0, 1.0]
contact = "friction"
friction = 0.5
[gravity]
g = [4.905, -8.495709211]
[solver]
shape = "linear"
cfl = 0.3
t_end = 0.5
[output]
sample_interval = 0.1
"#;

/// The disk's centre displacement at 0.5 s within 5 % of the exact
/// rolling distance at R/h = 10 (a = (2/3) g sin θ; issue 23's bound),
/// for linear, bspline2 and LME (γ = 2.8) on both floors and both laws.
/// Measured (2026-11-29, k = 0.025 M/h; docs/methods.md, "Where the disk
/// stands"), friction / stick: aligned linear 3.37 / 2.61 %, bspline2
/// 2.33 / 2.99 %, LME 1.63 / 3.16 %; inclined 2.13 / 2.97, 1.27 / 1.99,
/// 1.25 / 2.16 %. At k = 0.03 M/h the aligned linear disk rolled 4.52
/// and 5.21 % short (2026-11-25, walls at the contact points, the
/// friction on the wall's line sized with the weights it acts with);
/// 5.17 % and 5.68 % with the friction at the particles' centres; 4.71 %
/// and 3.95 % on the line sized with the particle's weights, whose stick
/// loop rang (the disk's mean friction halved, its centre at 1.99 m/s
/// against the exact 1.64) and crept under a slab (docs/methods.md,
/// "Walls"); 6.65 % and 2.21 % when it stopped the nodal velocity's
/// (unstable under NPC), 17.5 % and 18.1 % with the node rule, 49.6 %
/// when every node behind the wall under the disk was held.
const DISK_R10_BOUND: f64 = 0.05;
/// Issue 23's bound at R/h = 20 (the rolling disk case's own grid).
/// Measured (2026-11-29), friction / stick: aligned linear 1.02 / 1.94 %,
/// bspline2 0.52 / 0.25 %, LME 0.52 / 0.13 %; inclined 0.71 / 1.99,
/// 0.77 / 1.55, 0.03 / 2.13 %.
const DISK_R20_BOUND: f64 = 0.03;
/// The stick wall rolls the linear disk on the aligned floor about as far
/// as the friction wall, within this much (both ought to roll without
/// slip). Measured: stick 0.76 points ahead of friction (0.69 behind at
/// k = 0.03 M/h). LME's stick lags its friction by 1.53 points there.
const DISK_STICK_SLACK: f64 = 0.01;

/// The disk rolled to 0.5 s on the CPU: `floor` "aligned" (a level wall
/// on a grid line, gravity tilted 30°) or "inclined"
/// (`cases/rolling_disk.toml`, a 30° wall), R = 0.5 m over `h`, `shape`
/// (LME at γ = 2.8), `law` "friction" (μ = 0.5) or "stick".
fn rolled_disk(
    floor: &str,
    h: f64,
    shape: &str,
    law: &str,
) -> lme_mpm::exact::rolling::RollingErrors {
    let text = match floor {
        "aligned" => DISK_ON_A_GRID_LINE.to_string(),
        _ => std::fs::read_to_string(common::case("rolling_disk.toml")).unwrap(),
    };
    // `friction` is refused on a stick wall, and an override cannot remove
    // a key: the stick wall's scene text.
    let text = if law == "stick" {
        let t = text.replace(
            "contact = \"friction\"\nfriction = 0.5",
            "contact = \"stick\"",
        );
        assert!(t != text, "no friction wall to make stick");
        t
    } else {
        text
    };
    let sets = [
        format!("grid.h={h}"),
        // The case's lme_gamma = 2.8 stays for LME (dropped for the others).
        format!("solver.shape={shape}"),
    ];
    let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
    let scene = scene_of(&text, &sets);
    let model = Model::new(&scene).unwrap();
    let (mut sim, _) = run(&scene, Box::new(CpuBackend::new(model)));
    match sim.score().unwrap() {
        Some(Errors::Rolling(e)) => e,
        other => panic!("not a rolling score: {other:?}"),
    }
}

/// Issue 23's rolling matrix at `h` (R/h = 0.5 / h): every shape, floor
/// and law within `bound`; the linear disk's stick wall on the aligned
/// floor within `DISK_STICK_SLACK` of its friction wall.
fn disk_matrix(h: f64, bound: f64) {
    let mut failed = Vec::new();
    for floor in ["aligned", "inclined"] {
        for shape in ["linear", "bspline2", "lme"] {
            let [friction, stick] =
                ["friction", "stick"].map(|law| rolled_disk(floor, h, shape, law));
            println!(
                "R/h {}: {floor} {shape}: friction {:.2} %, stick {:.2} % short",
                0.5 / h,
                100.0 * friction.u_x_rel_error,
                100.0 * stick.u_x_rel_error
            );
            for (law, e) in [("friction", &friction), ("stick", &stick)] {
                if e.u_x_rel_error >= bound {
                    failed.push(format!("{floor} {shape} {law}: {e:?}"));
                }
            }
            if floor == "aligned"
                && shape == "linear"
                && stick.u_x_rel_error >= friction.u_x_rel_error + DISK_STICK_SLACK
            {
                failed.push(format!("stick {stick:?} against friction {friction:?}"));
            }
        }
    }
    assert!(failed.is_empty(), "{failed:#?}");
}

#[test]
fn disk_rolls_within_five_percent_at_ten_cells_per_radius() {
    disk_matrix(0.05, DISK_R10_BOUND);
}

/// The same at R/h = 20: 12 runs, 9 minutes on one core (520 s on a
/// loaded 2-core machine, 2026-11-29), so run
/// on demand (`cargo test --release --test suite -- --ignored
/// disk_rolls_within_three`); `study disk` runs the inclined friction
/// case at R/h = 20 for four shapes and three time steps.
#[test]
#[ignore]
fn disk_rolls_within_three_percent_at_twenty_cells_per_radius() {
    disk_matrix(0.025, DISK_R20_BOUND);
}

/// Issue 51: a prescribed-velocity platen keeps pressing as the material
/// moves (its region moves with its velocity). cases/clay_biaxial.toml
/// pressed at 0.05 m/s to 20 % axial strain (the platen travels 0.4 m,
/// 3.2 cells): the sample's top follows it to within a cell, where the
/// platen's nodes fixed at t = 0 let go after about a cell (5 %).
#[test]
fn a_platen_presses_the_clay_to_the_strain_asked() {
    let (t_end, v) = (8.25, 0.05);
    let mut r = common::run(
        "clay_biaxial.toml",
        &[
            "constraints.platen.velocity=[0.0, -0.05]",
            &format!("solver.t_end={t_end}"),
            "output.sample_interval=0.25",
        ],
    );
    assert_eq!(r.status, RunStatus::Completed);
    let platen = r.sim.backend_ref().model().constraints.groups[2].clone();
    let h = r.sim.backend_ref().model().grid.h;
    assert_eq!(platen.name, "platen");
    let travel = -platen.travel(t_end)[1];
    assert!((travel - v * (t_end - 0.25)).abs() < 1e-12, "{travel}");
    let top = r
        .sim
        .backend()
        .particles()
        .unwrap()
        .x
        .iter()
        .map(|x| x[1])
        .fold(f64::NEG_INFINITY, f64::max);
    println!(
        "clay pressed {travel:.3} m (strain {:.1} %): top at {top:.4} m, strain {:.2} %",
        100.0 * travel / 2.0,
        50.0 * (2.0 - top)
    );
    assert!(
        (2.0 - travel - top).abs() < h,
        "top {top} m, the platen at {} m",
        2.0 - travel
    );
}
