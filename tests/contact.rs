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
/// of it, `LR_FLAT_COS`): μ = 0 −0.1 %, μ = 0.2 +0.06 %, μ = 0.4 +0.55 %;
/// +0.72 % for μ = 0.4 since the floor's penalty k = 0.025 M/h (2026-11-29)
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

/// Issue 51: a soft block (E = 1 MPa, ten times softer than the case's)
/// and the case's stiff one, both with μ = 0.7 > tan 30°, stay on the slab
/// to 0.6 s on the case's grid (h = 0.05): once gravity has ramped in and
/// the block has settled (from 0.2 s; before, the soft block shears
/// elastically down the slope as its load comes on) their centres'
/// relative speed along the slab stays below 0.02 m/s, and the block's
/// centre moves less than one cell (0.05 m) along it. Pure FLIP let the
/// soft block creep at 0.057 m/s by 0.5 s and 0.083 m/s at 0.95 s, 50 mm
/// by then (2026-12-01), so 0.6 s catches it (the test ran to 1 s until
/// 2026-12-03, 74 s of CI); on a grid twice as coarse it held even so (5.1
/// mm, 1e-3 m/s at 1 s), so the soft block runs the case's grid. The stiff
/// block runs one twice as coarse (h = 0.1, a sixth of the time); its
/// start to 0.2 s on the case's grid is
/// `block_rests_on_a_slab_above_the_friction_angle`. With the interface's
/// PIC share (`CONTACT_PIC_FRACTION`), to 0.6 s (2026-12-03): the soft
/// block at most 4.1e-3 m/s from 0.2 s and 2.8 mm in all, the stiff one
/// 3.9e-4 m/s and 0.3 mm (to 1 s: 4.1e-3 m/s, 2.8 mm; 4.0e-4 m/s, 0.4 mm).
#[test]
fn soft_and_stiff_blocks_hold_on_the_slab() {
    const T_END: f64 = 0.6;
    for (e, h) in [("1e6", "0.05"), ("1e7", "0.1")] {
        let scene = common::scene(
            "contact_block.toml",
            &[
                "contact.interface.friction=0.7",
                &format!("solver.t_end={T_END}"),
                &format!("materials.soft.E={e}"),
                &format!("grid.h={h}"),
            ],
        );
        let model = Model::new(&scene).unwrap();
        let mut cpu = CpuBackend::new(model);
        let stop = std::sync::atomic::AtomicBool::new(false);
        let (mut fastest, mut t) = (0.0f64, 0.0);
        while t < T_END - 1e-12 {
            t += 0.05;
            cpu.advance(t, &stop).unwrap();
            let m = rigid(&mut cpu);
            let rel = (m[0].v[0] - m[1].v[0]).abs();
            if t > 0.2 - 1e-9 {
                fastest = fastest.max(rel);
            }
        }
        let m = rigid(&mut cpu);
        // Along the slab (x): the slip; the normal settling is elastic.
        let slip = (m[0].displacement[0] - m[1].displacement[0]).abs();
        println!(
            "E = {e} Pa, h = {h} m, mu 0.7: fastest relative speed from 0.2 s {fastest:.2e} m/s, slip {slip:.2e} m"
        );
        assert!(fastest < 0.02, "E = {e}: relative speed {fastest} m/s");
        assert!(slip < 0.05, "E = {e}: slipped {slip} m");
    }
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
    /// Σ over the steps of the left disk's change of velocity along the
    /// tangent of the line of centres at that step (m/s): what friction
    /// would give it; 0 for frictionless round bodies.
    tangential_kick: f64,
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
    let (mut kick, mut before) = (0.0, start.clone());
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
        // The tangent of the line of centres at mid-step.
        let c = |k: usize| {
            [
                0.5 * (r[k].centre[0] + before[k].centre[0]),
                0.5 * (r[k].centre[1] + before[k].centre[1]),
            ]
        };
        let (c0, c1) = (c(0), c(1));
        let d = [c1[0] - c0[0], c1[1] - c0[1]];
        let len = d[0].hypot(d[1]);
        let dv = [r[0].v[0] - before[0].v[0], r[0].v[1] - before[0].v[1]];
        kick += (-dv[0] * d[1] + dv[1] * d[0]) / len;
        before = r;
    }
    Collision {
        onset,
        max_overlap,
        end: rigid(&mut b),
        momentum_drift: drift / (start[0].mass * 1.0),
        tangential_kick: kick,
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
    // closing (2 m/s) before 0.025 s, not a cell early. Measured 0.02506
    // (ring-seeded disks; 0.02405 on the lattice).
    let onset = c.onset.expect("the disks never touched");
    assert!(
        (0.025 - 0.1 * 0.025 / 2.0..0.0275).contains(&onset),
        "{onset}"
    );
    // Measured 0.0001 m (h = 0.025).
    assert!(c.max_overlap < 0.025, "{}", c.max_overlap);
    // The exchange conserves momentum: measured 3.6e-15 of one disk's.
    assert!(c.momentum_drift < 1e-12, "{}", c.momentum_drift);
    // They bounce apart along x, without spin or sideways motion.
    assert!(l.v[0] < -0.5 && r.v[0] > 0.5, "{:?} {:?}", l.v, r.v);
    for b in [l, r] {
        assert!(b.omega.abs() < 1e-9 && b.v[1].abs() < 1e-9, "{b:?}");
    }
}

/// The off-centre collision with both disks shifted along x by `dx` (m)
/// on a grid of cell `h` (m), with or without the contact pair, and with
/// the disks' particles on `layout` ("rings" as in the case, or "lattice").
fn off_centre(dx: f64, h: f64, pair: bool, layout: &str) -> Collision {
    let sets = [
        format!("bodies.left.disks=[[{}, 0.5, 0.2]]", 0.3 + dx),
        format!(
            "bodies.right.disks=[[{}, 0.7, 0.2]]",
            0.696_410_161_513_775_4 + dx
        ),
        format!("grid.h={h}"),
        format!("bodies.left.disk_layout=\"{layout}\""),
        format!("bodies.right.disk_layout=\"{layout}\""),
    ];
    let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
    if pair {
        collide(&common::scene("contact_disks.toml", &sets))
    } else {
        collide(&without_contact("contact_disks.toml", "impact", &sets))
    }
}

/// ω R of both disks (m/s; the impact speed is 1 m/s).
fn spins(c: &Collision) -> [f64; 2] {
    [c.end[0].omega * 0.2, c.end[1].omega * 0.2]
}

fn print_collision(what: &str, c: &Collision) {
    let dot = |a: [f64; 2], b: [f64; 2]| a[0] * b[0] + a[1] * b[1];
    let [l, r] = [c.end[0], c.end[1]];
    println!(
        "{what}: omega R {:.3} / {:.3}, v.t {:.3} / {:.3} (exact -0.5 / 0.5, omega 0), v.u {:.3} / \
         {:.3}, max overlap {:.4} m, momentum drift {:.1e}, tangential kick {:.4}",
        l.omega * 0.2,
        r.omega * 0.2,
        dot(l.v, T),
        dot(r.v, T),
        dot(l.v, U),
        dot(r.v, U),
        c.max_overlap,
        c.momentum_drift,
        c.tangential_kick
    );
}

/// Shifts of both disks along x, in cells, for the placement sweeps: the
/// collision's position relative to the grid (and the rings' to the
/// grid's lines) changes, the physics does not.
const PLACEMENTS: [f64; 8] = [0.0, 0.123, 0.246, 0.369, 0.492, 0.615, 0.738, 0.861];

#[test]
fn frictionless_disks_off_centre_do_not_spin_up() {
    // R/h = 8, the case's cell, at eight placements on the grid: the pair
    // against one shared field (2026-11-29: pair |omega R| at most 0.064,
    // mean 0.027 of the impact speed; one field 0.46-0.47 at the first two).
    let h = 0.025;
    let (mut worst, mut sum) = (0.0f64, 0.0);
    for (k, cells) in PLACEMENTS.iter().enumerate() {
        let c = off_centre(cells * h, h, true, "rings");
        print_collision(&format!("pair, R/h 8, shift {cells} h"), &c);
        // The exchange conserves momentum: measured 2.6e-15 to 3.8e-15.
        assert!(c.momentum_drift < 1e-12, "{}", c.momentum_drift);
        assert!(c.max_overlap < 0.025, "{}", c.max_overlap);
        for w in spins(&c) {
            worst = worst.max(w.abs());
            sum += w.abs();
        }
        // The tangential velocity is kept: the left disk's velocity along
        // the current line of centres' tangent changes by at most 0.0063
        // m/s over the placements (below 5e-5 at the case's; the
        // lattice-seeded disks' drag: 0.073). Along the impact's tangent
        // v.t grows to 0.52-0.53 because the line of centres turns, by
        // about 2° over the 15 ms of contact.
        assert!(c.tangential_kick.abs() < 0.01, "{}", c.tangential_kick);
        // They bounce apart (v.u -0.53 to -0.57 / +0.53 to +0.57: the
        // exchange is inelastic, docs/methods.md).
        let sep = (c.end[1].v[0] - c.end[0].v[0]) * U[0] + (c.end[1].v[1] - c.end[0].v[1]) * U[1];
        assert!(sep > 1.0, "{sep}");
        if k < 2 {
            let one = off_centre(cells * h, h, false, "rings");
            print_collision(&format!("one field, R/h 8, shift {cells} h"), &one);
            for (p, o) in spins(&c).into_iter().zip(spins(&one)) {
                assert!(o.abs() > 0.3 && o.abs() > 5.0 * p.abs(), "{p} {o}");
            }
        }
    }
    let mean = sum / (2 * PLACEMENTS.len()) as f64;
    println!("R/h 8: largest |omega R| {worst:.3}, mean {mean:.3}");
    assert!(worst < 0.08 && mean < 0.05, "{worst} {mean}");
}

/// R/h = 16 at the worse of two placements above in the suite (each run
/// about 30 s on 2 cores); both:
///   cargo test --release --test suite -- --ignored contact::frictionless_disks_spin_falls_with_the_cell_at_both_placements
#[test]
fn frictionless_disks_spin_falls_with_the_cell() {
    spin_at_r16(&[0.246]);
}

#[test]
#[ignore]
fn frictionless_disks_spin_falls_with_the_cell_at_both_placements() {
    spin_at_r16(&[0.0, 0.246]);
}

fn spin_at_r16(placements: &[f64]) {
    // R/h = 16 at two of the placements above: the spin left at R/h 8 is
    // the discretisation's (2026-11-29: |omega R| 0.007 / 0.016 and
    // 0.022 / 0.003, against 0.024 / 0.021 and 0.062 / 0.064 at R/h 8).
    for &cells in placements {
        let h = 0.0125;
        let c = off_centre(cells * 0.025, h, true, "rings");
        print_collision(&format!("pair, R/h 16, shift {cells} h(8)"), &c);
        // 8.1e-10 at the first placement, all of it after the disks have
        // parted (7.8e-15 up to 0.06 s, contact ends by 0.045 s), so not
        // the exchange; likely a vibrating particle that reaches a node
        // with weight below MASS_EPS_REL, which `predict` leaves at rest
        // (docs/methods.md, "Contact between bodies"; not traced further).
        assert!(c.momentum_drift < 1e-8, "{}", c.momentum_drift);
        for w in spins(&c) {
            assert!(w.abs() < 0.03, "{w}");
        }
    }
}

#[test]
fn lattice_seeded_disks_are_rough_at_the_particle_scale() {
    // The same collision with the disks' particles on the cell lattice:
    // their edges are staircases of the particle spacing, which interlock
    // as the disks slide, and the pair spins them (2026-11-29, the case's
    // placement: 0.064 / 0.222, v.t -0.449 / 0.449; over eight placements
    // up to 0.38), where ring-seeded disks stay below 0.07. The spin is the
    // seeding's, not the exchange's: see docs/methods.md, "Contact
    // between bodies".
    let h = 0.025;
    let lattice = off_centre(0.0, h, true, "lattice");
    let rings = off_centre(0.0, h, true, "rings");
    print_collision("pair, lattice-seeded", &lattice);
    print_collision("pair, ring-seeded", &rings);
    let largest = |c: &Collision| spins(c).into_iter().fold(0.0f64, |a, w| a.max(w.abs()));
    assert!(largest(&lattice) > 0.15, "{}", largest(&lattice));
    // ... and drag each other along the contact as friction would
    // (measured 0.073 m/s along the current tangent; rings: below 5e-5).
    assert!(
        lattice.tangential_kick.abs() > 0.05,
        "{}",
        lattice.tangential_kick
    );
    assert!(largest(&rings) < 0.5 * largest(&lattice));
    // Lattice seeding conserves momentum to round-off (no particle sits
    // on a node's edge).
    assert!(lattice.momentum_drift < 1e-12, "{}", lattice.momentum_drift);
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
        // Rings place the particles of disks; the block has none.
        (
            "[contact.i]\nbodies = [\"block\", \"slab\"]\nlaw = \"slip\"",
            vec!["bodies.block.disk_layout=\"rings\""],
            "bodies.block.disk_layout",
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

/// The disk rolling on the elastic slab (`cases/contact_rolling.toml`,
/// R/h = 20, the disk seeded on rings): its centre's displacement at
/// 0.5 s against ½ (2/3) g sin 30° t², issue 24's 5 %. Measured
/// 2026-11-29: −1.67 % (ω R / v = 0.95); −2.20 % (ω R / v = 1.001) with
/// the interface's PIC share (`CONTACT_PIC_FRACTION`, 2026-12-02); with the disk seeded on the
/// lattice −8.56 % (its staircase rim rolls on a flat of particles), and
/// at R/h = 10 −5.7 % on rings against −16.0 % on the lattice.
#[test]
fn disk_rolls_on_an_elastic_slab_within_five_percent() {
    let a = 2.0 / 3.0 * 9.81 * 0.5;
    let scene = common::scene("contact_rolling.toml", &[]);
    let mut b = CpuBackend::new(Model::new(&scene).unwrap());
    let t_end = b.model().t_end;
    while b.time() < t_end {
        b.step().unwrap();
    }
    let r = rigid(&mut b);
    let t = b.time();
    let err = r[0].displacement[0] / (0.5 * a * t * t) - 1.0;
    println!(
        "rolling on the slab, R/h 20: {:+.2} % of the exact distance, omega R / v {:.3}",
        100.0 * err,
        -r[0].omega * 0.5 / r[0].v[0]
    );
    assert!(err.abs() < 0.05, "{err}");
}
