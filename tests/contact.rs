//! Contact between bodies (`[contact.NAME]`, issue 24) on the CPU path:
//! a block sliding on a stiffer elastic slab under tilted gravity (the
//! relative velocity against g (sin θ − μ cos θ) R(t), at rest for
//! μ > tan θ), and the single shared field beside it (the block glued).

mod common;

use lme_mpm::backend::Backend;
use lme_mpm::cpu::CpuBackend;
use lme_mpm::model::Model;
use lme_mpm::scene::Scene;

/// Mass-weighted mean velocity of each body (scene order).
fn body_velocities(b: &mut CpuBackend) -> Vec<[f64; 2]> {
    let m = b.model();
    let n = m.body_names.len();
    let mut acc = vec![[0.0; 3]; n];
    let p = &m.particles;
    for i in 0..p.len() {
        let a = &mut acc[p.body[i] as usize];
        a[0] += p.mass[i];
        a[1] += p.mass[i] * p.v[i][0];
        a[2] += p.mass[i] * p.v[i][1];
    }
    acc.iter().map(|a| [a[1] / a[0], a[2] / a[0]]).collect()
}

/// (t, velocity of each body) every `every` s up to t_end.
fn history(scene: &Scene, every: f64) -> Vec<(f64, Vec<[f64; 2]>)> {
    let model = Model::new(scene).unwrap();
    let t_end = model.t_end;
    let mut b = CpuBackend::new(model);
    let stop = std::sync::atomic::AtomicBool::new(false);
    let mut out = Vec::new();
    let mut t = 0.0;
    while t < t_end - 1e-12 {
        t = (t + every).min(t_end);
        b.advance(t, &stop).unwrap();
        out.push((b.time(), body_velocities(&mut b)));
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
/// issue's 3 %. Measured (h = 0.05, linear, NPC): μ = 0.2 −0.11 % at
/// 0.5 s, μ = 0 −0.03 %, μ = 0.4 −1.7 % (the block's elastic bounce
/// modulates the normal force and so the friction, as on a wall).
const SLIDING_TOL: f64 = 0.03;
/// At rest (μ > tan θ): the relative speed over the frictionless g sin θ
/// R(t). Measured 2e-4.
const AT_REST_TOL: f64 = 0.01;

fn exact_rel(mu: f64, t: f64) -> f64 {
    let th = 30f64.to_radians();
    9.81 * (th.sin() - mu * th.cos()).max(0.0) * ramp_integral(t, 0.2)
}

#[test]
fn block_slides_on_a_slab_at_the_coulomb_rate() {
    let scene = common::scene("contact_block.toml", &[]);
    for (t, v) in history(&scene, 0.1) {
        let rel = v[0][0] - v[1][0];
        let exact = exact_rel(0.2, t);
        println!("mu 0.2: t {t:.2} relative {rel:.4} m/s, exact {exact:.4}");
        if t >= 0.2 {
            assert!(
                (rel / exact - 1.0).abs() < SLIDING_TOL,
                "t = {t}: relative velocity {rel} against {exact}"
            );
        }
    }
}

#[test]
fn block_rests_on_a_slab_above_the_friction_angle() {
    let scene = common::scene(
        "contact_block.toml",
        &["contact.interface.friction=0.7", "solver.t_end=0.3"],
    );
    let free = |t: f64| exact_rel(0.0, t);
    for (t, v) in history(&scene, 0.1) {
        let rel = (v[0][0] - v[1][0]).hypot(v[0][1] - v[1][1]);
        println!("mu 0.7: t {t:.2} relative speed {rel:.2e} m/s");
        assert!(rel < AT_REST_TOL * free(t), "t = {t}: {rel} m/s");
    }
}

#[test]
fn one_shared_field_glues_the_block_to_the_slab() {
    // The same scene without the pair: one velocity field, no slip.
    let text = std::fs::read_to_string(common::case("contact_block.toml")).unwrap();
    let start = text.find("[contact.interface]").unwrap();
    let end = start + text[start..].find("\n\n").unwrap();
    let glued = format!("{}{}", &text[..start], &text[end..]);
    let scene = Scene::from_str(
        &glued,
        "glued",
        "glued",
        &[lme_mpm::scene::Override::parse("solver.t_end=0.2").unwrap()],
    )
    .unwrap();
    let (t, v) = history(&scene, 0.2).pop().unwrap();
    let rel = v[0][0] - v[1][0];
    println!(
        "one field: t {t:.2} relative {rel:.4} m/s against {:.4} sliding",
        exact_rel(0.2, t)
    );
    assert!(rel.abs() < 0.05 * exact_rel(0.2, t), "{rel}");
}
