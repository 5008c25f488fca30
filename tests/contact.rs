//! Contact between bodies (`[contact.NAME]`, issue 24): a block sliding
//! on a stiffer elastic slab under tilted gravity (the relative velocity
//! against g (sin θ − μ cos θ) R(t), at rest for μ > tan θ) on the CPU
//! and the GPU, the single shared field beside it (the block glued), and
//! two disks colliding (CPU).

use crate::common;

use lme_mpm::backend::Backend;
use lme_mpm::cpu::CpuBackend;
use lme_mpm::gpu::GpuBackend;
use lme_mpm::model::Model;
use lme_mpm::scene::Scene;
use lme_mpm::study::contact::{BodyMotion, PRANDTL, body_motion, one_field, overlap};

/// Mass-weighted mean velocity of each body (scene order).
fn body_velocities(b: &mut dyn Backend) -> Vec<[f64; 2]> {
    let n = b.model().body_names.len();
    let p = b.particles().unwrap();
    body_motion(p, n).iter().map(|m| m.v).collect()
}

/// (t, velocity of each body) every `every` s up to t_end, on the CPU.
fn history(scene: &Scene, every: f64) -> Vec<(f64, Vec<[f64; 2]>)> {
    let model = Model::new(scene).unwrap();
    history_on(&mut CpuBackend::new(model), every)
}

/// `history` on backend `b`.
fn history_on(b: &mut dyn Backend, every: f64) -> Vec<(f64, Vec<[f64; 2]>)> {
    let t_end = b.model().t_end;
    let stop = std::sync::atomic::AtomicBool::new(false);
    let mut out = Vec::new();
    let mut t = 0.0;
    while t < t_end - 1e-12 {
        t = (t + every).min(t_end);
        b.advance(t, &stop).unwrap();
        out.push((b.time(), body_velocities(b)));
    }
    out
}

/// R(t) of the sine ramp over T/2 (eq. 45): t − T/4 after the ramp.
fn ramp_integral(t: f64, period: f64) -> f64 {
    let half = period / 2.0;
    if t >= half {
        t - period / 4.0
    } else {
        t / 2.0 - (std::f64::consts::PI * t / half).sin() * half / (2.0 * std::f64::consts::PI)
    }
}

/// Relative velocity while sliding against g (sin θ − μ cos θ) R(t): the
/// issue's 3 %. Measured (h = 0.05, linear, NPC, CPU, at 0.5 s,
/// 2026-11-28, with the gradient normal kept where the fit is within 3°
/// of it, `LR_FLAT_COS`): μ = 0 −0.1 %, μ = 0.2 +0.06 %, μ = 0.4 +0.55 %
/// (without that, the fitted line's 0.2° tilt left μ = 0.4 −3.4 % at
/// 0.5 s, the 3 % missed, and μ = 0.2 −1.4 %).
const SLIDING_TOL: f64 = 0.03;
/// At rest (μ > tan θ): the relative speed over the frictionless g sin θ
/// R(t). Measured 2e-4.
const AT_REST_TOL: f64 = 0.01;

fn exact_rel(mu: f64, t: f64) -> f64 {
    let th = 30f64.to_radians();
    9.81 * (th.sin() - mu * th.cos()).max(0.0) * ramp_integral(t, 0.2)
}

/// The block slides at the Coulomb rate for `mu` once the ramp is over
/// (t ≥ 0.2 s).
fn check_sliding(label: &str, mu: f64, h: &[(f64, Vec<[f64; 2]>)]) {
    let mut checked = 0;
    for (t, v) in h {
        let (t, rel) = (*t, v[0][0] - v[1][0]);
        let exact = exact_rel(mu, t);
        println!("{label} mu {mu}: t {t:.2} relative {rel:.4} m/s, exact {exact:.4}");
        if t >= 0.2 - 1e-9 {
            checked += 1;
            assert!(
                (rel / exact - 1.0).abs() < SLIDING_TOL,
                "{label} t = {t}: relative velocity {rel} against {exact}"
            );
        }
    }
    assert!(checked > 0, "{label}: no sample after the ramp");
}

/// The block stays at rest on the slab (μ = 0.7 > tan 30°).
fn check_at_rest(label: &str, h: &[(f64, Vec<[f64; 2]>)]) {
    for (t, v) in h {
        let rel = (v[0][0] - v[1][0]).hypot(v[0][1] - v[1][1]);
        println!("{label} mu 0.7: t {t:.2} relative speed {rel:.2e} m/s");
        assert!(
            rel < AT_REST_TOL * exact_rel(0.0, *t),
            "{label} t = {t}: {rel} m/s"
        );
    }
}

/// μ = 0.4 to the case's 0.5 s, where the error had grown to −3.4 % with
/// the fitted normal's tilt (the smallest margin over Coulomb's
/// deceleration of the three sliding μ; μ = 0.2 is checked on the GPU
/// below and by `lme-mpm study contact`).
#[test]
fn block_slides_on_a_slab_at_the_coulomb_rate() {
    let scene = common::scene("contact_block.toml", &["contact.interface.friction=0.4"]);
    check_sliding("cpu", 0.4, &history(&scene, 0.1));
}

#[test]
fn block_rests_on_a_slab_above_the_friction_angle() {
    let scene = common::scene(
        "contact_block.toml",
        // To 0.2 s: 0.1 s past the ramp (0.3 s added 8 s to CI).
        &["contact.interface.friction=0.7", "solver.t_end=0.2"],
    );
    check_at_rest("cpu", &history(&scene, 0.1));
}

/// The block on the slab on the GPU, sliding (to 0.2 s: the check is at
/// 0.2 s, after the ramp; the CPU test runs μ = 0.4 to 0.5 s) and at rest (to
/// 0.1 s, the ramp's end; the CPU test runs to 0.2 s), against the same
/// tolerances as the CPU, on a grid twice as coarse as the CPU's (h = 0.1:
/// block and slab 5 cells thick). llvmpipe stepped the h = 0.05 scene at
/// ~15 ms a step, 3300 steps to 0.2 s, the suite's slowest test (130 s in
/// CI); at h = 0.1 it takes a fifth of that and measured −0.98 % at 0.2 s
/// sliding and 5e-5 m/s at rest (2026-11-28).
#[test]
fn block_on_a_slab_on_gpu() {
    for (sets, sliding) in [
        (&["solver.t_end=0.2", "grid.h=0.1"][..], true),
        (
            &[
                "contact.interface.friction=0.7",
                "solver.t_end=0.1",
                "grid.h=0.1",
            ][..],
            false,
        ),
    ] {
        let Some(ctx) = common::gpu::open("contact block on gpu", false) else {
            return;
        };
        let model = Model::new(&common::scene("contact_block.toml", sets)).unwrap();
        let mut gpu = GpuBackend::new(ctx, model).unwrap();
        let h = history_on(&mut gpu, 0.1);
        if sliding {
            check_sliding("gpu", 0.2, &h);
        } else {
            check_at_rest("gpu", &h);
        }
    }
}

#[test]
fn one_shared_field_glues_the_block_to_the_slab() {
    // The same scene without the pair: one velocity field, no slip.
    let scene = without_contact("contact_block.toml", "interface", &["solver.t_end=0.2"]);
    let (t, v) = history(&scene, 0.2).pop().unwrap();
    let rel = v[0][0] - v[1][0];
    println!(
        "one field: t {t:.2} relative {rel:.4} m/s against {:.4} sliding",
        exact_rel(0.2, t)
    );
    assert!(rel.abs() < 0.05 * exact_rel(0.2, t), "{rel}");
}

/// Each body's motion (scene order), from the library's study helper.
fn rigid(b: &mut CpuBackend) -> Vec<BodyMotion> {
    let n = b.model().body_names.len();
    body_motion(&b.model().particles, n)
}

/// The collision's figures: first time the pair's reaction is non-zero,
/// the largest overlap, and the bodies at the end.
struct Collision {
    onset: Option<f64>,
    max_overlap: f64,
    end: Vec<BodyMotion>,
    momentum_drift: f64,
}

fn collide(scene: &Scene) -> Collision {
    let model = Model::new(scene).unwrap();
    let t_end = model.t_end;
    let mut b = CpuBackend::new(model);
    let start = rigid(&mut b);
    let p0 = [
        start[0].mass * start[0].v[0] + start[1].mass * start[1].v[0],
        start[0].mass * start[0].v[1] + start[1].mass * start[1].v[1],
    ];
    let (mut onset, mut max_overlap, mut drift) = (None, f64::NEG_INFINITY, 0.0f64);
    while b.time() < t_end {
        let t0 = b.time();
        b.step().unwrap();
        let s = b.sample().unwrap();
        if onset.is_none() && s.reactions.last().is_some_and(|r| r != &[0.0, 0.0]) {
            onset = Some(t0);
        }
        let r = rigid(&mut b);
        max_overlap = max_overlap.max(overlap(&b.model().particles, &r));
        let p = [
            r[0].mass * r[0].v[0] + r[1].mass * r[1].v[0],
            r[0].mass * r[0].v[1] + r[1].mass * r[1].v[1],
        ];
        drift = drift.max((p[0] - p0[0]).abs().max((p[1] - p0[1]).abs()));
    }
    Collision {
        onset,
        max_overlap,
        end: rigid(&mut b),
        momentum_drift: drift / (start[0].mass * 1.0),
    }
}

/// The scene `name` without its `[contact.<table>]` table: one shared field.
fn without_contact(name: &str, table: &str, sets: &[&str]) -> Scene {
    let text = std::fs::read_to_string(common::case(name)).unwrap();
    let o: Vec<_> = sets
        .iter()
        .map(|s| lme_mpm::scene::Override::parse(s).unwrap())
        .collect();
    Scene::from_str(&one_field(&text, table), "one field", "one_field", &o).unwrap()
}

/// Line of centres at impact in `contact_disks.toml` (30° off x) and its
/// tangent.
const U: [f64; 2] = [0.866_025_403_784_438_6, 0.5];
const T: [f64; 2] = [-0.5, 0.866_025_403_784_438_6];

#[test]
fn frictionless_disks_bounce_apart_head_on() {
    let scene = common::scene(
        "contact_disks.toml",
        &["bodies.right.disks=[[0.75, 0.5, 0.2]]"],
    );
    let c = collide(&scene);
    let [l, r] = [c.end[0], c.end[1]];
    println!(
        "head-on: onset {:?} s (surfaces meet at 0.025 s), max overlap {:.4} m, left v {:?} \
         omega {:.2e}, right v {:?} omega {:.2e}, momentum drift {:.1e}",
        c.onset, c.max_overlap, l.v, l.omega, r.v, r.omega, c.momentum_drift
    );
    // Contact starts when the domains meet: within a tenth of a cell of
    // closing (2 m/s) before 0.025 s, not a cell early. Measured 0.02405.
    let onset = c.onset.expect("the disks never touched");
    assert!(
        (0.025 - 0.1 * 0.025 / 2.0..0.0275).contains(&onset),
        "{onset}"
    );
    // Measured 0.0034 m (h = 0.025).
    assert!(c.max_overlap < 0.025, "{}", c.max_overlap);
    // The exchange conserves momentum: measured 3e-15 of one disk's.
    assert!(c.momentum_drift < 1e-12, "{}", c.momentum_drift);
    // They bounce apart along x, without spin or sideways motion.
    assert!(l.v[0] < -0.5 && r.v[0] > 0.5, "{:?} {:?}", l.v, r.v);
    for b in [l, r] {
        assert!(b.omega.abs() < 1e-9 && b.v[1].abs() < 1e-9, "{b:?}");
    }
}

#[test]
fn frictionless_disks_off_centre_against_one_shared_field() {
    let c = collide(&common::scene("contact_disks.toml", &[]));
    let one = collide(&without_contact("contact_disks.toml", "impact", &[]));
    let dot = |a: [f64; 2], b: [f64; 2]| a[0] * b[0] + a[1] * b[1];
    for (name, c) in [("contact pair", &c), ("one field", &one)] {
        let [l, r] = [c.end[0], c.end[1]];
        println!(
            "off-centre, {name}: left v.u {:.3} v.t {:.3} omega R {:.3}; right v.u {:.3} v.t {:.3} \
             omega R {:.3} (exact frictionless: v.t -0.5 / 0.5, omega 0); max overlap {:.4} m; \
             momentum drift {:.1e}",
            dot(l.v, U),
            dot(l.v, T),
            l.omega * 0.2,
            dot(r.v, U),
            dot(r.v, T),
            r.omega * 0.2,
            c.max_overlap,
            c.momentum_drift
        );
    }
    assert!(c.momentum_drift < 1e-12, "{}", c.momentum_drift);
    assert!(c.max_overlap < 0.025, "{}", c.max_overlap);
    let sep = |c: &Collision| dot(c.end[1].v, U) - dot(c.end[0].v, U);
    assert!(sep(&c) > 0.5, "{}", sep(&c));
    // The "neither spins up" is not met in full: with the
    // logistic-regression normals omega R = 0.025 / 0.187 of the impact
    // speed and v.t = -0.468 / 0.468 (exact -0.5 / 0.5), against 0.39 /
    // 0.48 and -0.30 / 0.30 with the larger volume's gradient normal and
    // 0.24 / 0.38 with one shared field (2026-11-25; with the exact line
    // of centres as the normal, 0.05). What is asserted: the pair spins
    // each disk less than the shared field does, and keeps more of the
    // tangential velocity. docs/methods.md, "Contact between bodies".
    for i in 0..2 {
        let (pair, shared) = (c.end[i], one.end[i]);
        assert!(
            pair.omega.abs() < shared.omega.abs(),
            "disk {i}: omega {} against one field's {}",
            pair.omega,
            shared.omega
        );
        assert!(
            dot(pair.v, T).abs() > dot(shared.v, T).abs(),
            "disk {i}: v.t {:?} against one field's {:?}",
            pair.v,
            shared.v
        );
    }
}

#[test]
fn bad_contact_pairs_are_refused_naming_the_key() {
    let text = std::fs::read_to_string(common::case("contact_block.toml")).unwrap();
    let with = |table: &str, sets: &[&str]| {
        let start = text.find("[contact.interface]").unwrap();
        let end = start + text[start..].find("\n\n").unwrap();
        let t = format!("{}{table}{}", &text[..start], &text[end..]);
        let o: Vec<_> = sets
            .iter()
            .map(|s| lme_mpm::scene::Override::parse(s).unwrap())
            .collect();
        Scene::from_str(&t, "bad", "bad", &o)
            .map(|_| ())
            .unwrap_err()
            .to_string()
    };
    for (table, sets, key) in [
        (
            "[contact.i]\nbodies = [\"block\", \"floor\"]\nlaw = \"slip\"",
            vec![],
            "contact.i.bodies",
        ),
        (
            "[contact.i]\nbodies = [\"block\", \"block\"]\nlaw = \"slip\"",
            vec![],
            "contact.i.bodies",
        ),
        (
            "[contact.i]\nbodies = [\"block\", \"slab\"]\nlaw = \"slip\"\n[contact.j]\nbodies = [\"slab\", \"block\"]\nlaw = \"stick\"",
            vec![],
            "contact.j.bodies",
        ),
        (
            "[contact.i]\nbodies = [\"block\", \"slab\"]\nlaw = \"friction\"\nfriction = -0.1",
            vec![],
            "contact.i.friction",
        ),
        (
            "[contact.i]\nbodies = [\"block\", \"slab\"]\nlaw = \"friction\"",
            vec![],
            "contact.i.friction",
        ),
        (
            "[contact.i]\nbodies = [\"block\", \"slab\"]\nlaw = \"slip\"\nfriction = 0.3",
            vec![],
            "contact.i.friction",
        ),
        (
            "[contact.i]\nbodies = [\"block\", \"slab\"]\nlaw = \"slip\"",
            vec!["solver.integrator=implicit"],
            "contact.i",
        ),
    ] {
        let e = with(table, &sets);
        assert!(e.contains(key), "{table}: {e}");
    }
}

/// The footing's q/c history (`cases/footing.toml` with `sets`): the
/// contact pair's vertical reaction over the 1 m width and c = 10 kPa.
fn footing_q(sets: &[&str]) -> Vec<(f64, f64)> {
    let r = common::run("footing.toml", sets);
    assert_eq!(r.status, lme_mpm::solver::RunStatus::Completed, "{sets:?}");
    r.recorder
        .samples
        .iter()
        .map(|s| (s.t, s.reactions.last().unwrap()[1] / 1e4))
        .collect()
}

/// The cell-averaged volumetric strain rate (B-bar) against locking: the
/// smooth footing on the Tresca soil at h = 0.1 m (the case's h = 0.05 m
/// takes a minute), largest q/c over the case's 1.2 s with and without
/// the average. Measured 2026-11-28: 5.730 with it (+11.4 % from
/// Prandtl's 5.142), 6.530 without (+27.0 %): 12.3 % lower. The bounds: the
/// average lowers the peak by at least 8 %, and it stays within 15 % of
/// Prandtl at this coarse grid, 10 cells under the footing (at the case's
/// h = 0.05 m, +6.2 % against +14.6 % without: docs/methods.md,
/// "Cell-averaged volumetric strain rate").
#[test]
fn the_cell_average_unlocks_a_footing_on_a_tresca_soil() {
    let peak = |h: &[(f64, f64)]| h.iter().map(|x| x.1).fold(0.0, f64::max);
    let coarse = "grid.h=0.1";
    let averaged = footing_q(&[coarse]);
    let own = footing_q(&[coarse, "solver.volumetric_strain=particle"]);
    let (a, o) = (peak(&averaged), peak(&own));
    println!(
        "footing h = 0.1: peak q/c {a:.3} with the cell average, {o:.3} without ({:+.1} %, {:+.1} % from Prandtl)",
        100.0 * (a / PRANDTL - 1.0),
        100.0 * (o / PRANDTL - 1.0)
    );
    assert!(a < 0.92 * o, "the average should unlock: {a} against {o}");
    assert!((a / PRANDTL - 1.0).abs() < 0.15, "q/c {a}");
}

/// `solver.volumetric_strain = "cell_average"`: refused with the implicit
/// integrator and with MLS (exit 2 naming the key). The GPU path runs it
/// (`stage_parity::stages_match_cell_average`,
/// `run_parity::footing_gpu_matches_cpu`).
#[test]
fn the_cell_average_is_refused_where_it_does_not_apply() {
    // A case without contact pairs, so that nothing else is refused first.
    let text = std::fs::read_to_string(common::case("elastic_block.toml")).unwrap();
    for sets in [
        &[
            "solver.volumetric_strain=cell_average",
            "solver.integrator=implicit",
        ][..],
        &[
            "solver.volumetric_strain=cell_average",
            "solver.shape=bspline2",
            "solver.mls=true",
        ][..],
    ] {
        let o: Vec<_> = sets
            .iter()
            .map(|s| lme_mpm::scene::Override::parse(s).unwrap())
            .collect();
        let e = Scene::from_str(&text, "f", "f", &o)
            .map(|_| ())
            .unwrap_err();
        assert!(
            e.to_string().contains("solver.volumetric_strain"),
            "{sets:?}: {e}"
        );
    }
}
