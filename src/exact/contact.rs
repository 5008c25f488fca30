//! References for bodies in contact through a scene's one contact pair
//! (`[contact.<name>]`), measured on the bodies' particles:
//! - `contact_sliding`: the pair's first body slides on a face of its
//!   second under gravity, Coulomb μ (0 for `slip`): the same rigid-block
//!   solution as on a wall (`sliding.rs`), a = g_t − μ g_n, so the slide
//!   (the first body's displacement along the face relative to the
//!   second's) is max(a, 0) ∫R = a t²/2 without a ramp;
//! - `contact_rolling`: the pair's first body, one disk, rolls without
//!   slip on its second: the centre moves (2/3) g_t t²/2 (`rolling.rs`);
//! - `disk_impact`: two disks meet through a frictionless pair: the forces
//!   pass through the centres, so the total momentum is kept and neither
//!   disk spins (ω R = 0).

use super::bodies::{self, BodyMotion};
use super::sliding::SlidingBlock;
use crate::model::Particles;
use crate::scene::{Contact, Scene};
use serde::Serialize;

/// The face's slide: the rigid block's solution on the pair's face.
pub fn sliding(scene: &Scene) -> SlidingBlock {
    let p = bodies::pair(scene);
    let n = bodies::pair_normal(scene);
    let g = scene.file.gravity.as_ref().map_or([0.0; 2], |g| g.g);
    let (tangent, g_tangential, g_normal) = bodies::split_gravity(g, n);
    SlidingBlock {
        tangent,
        normal: n,
        g_tangential,
        g_normal,
        mu: match p.spec.law {
            Contact::Friction => p.spec.friction.unwrap_or(0.0),
            _ => 0.0,
        },
        ramp_period: scene.file.gravity.as_ref().map_or(0.0, |g| match g.ramp {
            crate::scene::Ramp::Sine => g.ramp_period.unwrap_or(0.0),
            crate::scene::Ramp::None => 0.0,
        }),
    }
}

/// ∫₀ᵗ R(s) ds (s²): the slide's time factor, t²/2 without a ramp.
pub fn ramp_double_integral(block: &SlidingBlock, t: f64) -> f64 {
    let tp = block.ramp_period;
    let pi = std::f64::consts::PI;
    let inside =
        |t: f64| 0.25 * t * t + tp * tp * ((2.0 * pi * t / tp).cos() - 1.0) / (8.0 * pi * pi);
    if tp <= 0.0 {
        0.5 * t * t
    } else if t <= 0.5 * tp {
        inside(t)
    } else {
        let s = t - 0.5 * tp;
        inside(0.5 * tp) + 0.25 * tp * s + 0.5 * s * s
    }
}

/// Exact slide along the face at `t` (m).
pub fn slide_exact(block: &SlidingBlock, t: f64) -> f64 {
    block.acceleration().max(0.0) * ramp_double_integral(block, t)
}

/// Figures for `summary.json` (`contact_sliding`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ContactSlidingErrors {
    /// The first body's displacement along the face relative to the
    /// second's, centres of mass (m).
    pub slide: f64,
    /// max(a, 0) ∫R (m): a t²/2 without a ramp.
    pub slide_exact: f64,
    /// a = g_t − μ g_n (m/s²); ≤ 0: the body stays at rest.
    pub acceleration_exact: f64,
    /// |slide − exact| / exact while sliding; at rest, |slide| over the
    /// frictionless slide g_t ∫R.
    pub slide_rel_error: f64,
    /// The first body's velocity along the face relative to the second's (m/s).
    pub velocity: f64,
    /// max(a, 0) R(t) (m/s).
    pub velocity_exact: f64,
}

pub fn score_sliding(scene: &Scene, p: &Particles, t: f64) -> ContactSlidingErrors {
    let block = sliding(scene);
    let pair = bodies::pair(scene);
    let m = bodies::body_motion(p, scene.file.bodies.len());
    let (a, b) = (m[pair.index[0]], m[pair.index[1]]);
    let tg = block.tangent;
    let along = |v: [f64; 2]| v[0] * tg[0] + v[1] * tg[1];
    let slide = along(a.displacement) - along(b.displacement);
    let exact = slide_exact(&block, t);
    let scale = if exact > 0.0 {
        exact
    } else {
        block.g_tangential * ramp_double_integral(&block, t)
    };
    ContactSlidingErrors {
        slide,
        slide_exact: exact,
        acceleration_exact: block.acceleration(),
        slide_rel_error: (slide - exact).abs() / scale.max(f64::MIN_POSITIVE),
        velocity: along(a.v) - along(b.v),
        velocity_exact: block.velocity(t),
    }
}

/// The rolling disk's solution on the pair's face.
pub fn rolling(scene: &Scene) -> super::rolling::RollingDisk {
    let p = bodies::pair(scene);
    let g = scene.file.gravity.as_ref().map_or([0.0; 2], |g| g.g);
    let radius = p.body[0].disks.first().map_or(0.0, |d| d[2]);
    super::rolling::RollingDisk::new(g, bodies::pair_normal(scene), radius)
}

/// Figures for `summary.json` (`contact_rolling`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ContactRollingErrors {
    /// The disk's centre displacement along the face (m).
    pub distance: f64,
    /// (2/3) g_t t²/2 (m).
    pub distance_exact: f64,
    /// |distance − exact| / exact.
    pub distance_rel_error: f64,
    /// The centre's velocity along the face (m/s), and exact (2/3) g_t t.
    pub velocity: f64,
    pub velocity_exact: f64,
    /// Slip at the contact point, its velocity along the face (v_t + ω R
    /// on a floor, ω counter-clockwise) (m/s): 0 rolling without slip.
    pub slip: f64,
}

pub fn score_rolling(scene: &Scene, p: &Particles, t: f64) -> ContactRollingErrors {
    let disk = rolling(scene);
    let pair = bodies::pair(scene);
    let n = bodies::pair_normal(scene);
    let m = bodies::body_motion(p, scene.file.bodies.len())[pair.index[0]];
    let a = disk.accel_along();
    let dir = if a > 0.0 {
        [disk.accel[0] / a, disk.accel[1] / a]
    } else {
        [n[1], -n[0]]
    };
    let along = |v: [f64; 2]| v[0] * dir[0] + v[1] * dir[1];
    let exact = 0.5 * a * t * t;
    // The contact point is at −R n from the centre: its velocity along
    // the face is v_t + (ω ẑ × (−R n))·dir = v_t + ω R (n_y d_x − n_x d_y).
    let turn = n[1] * dir[0] - n[0] * dir[1];
    ContactRollingErrors {
        distance: along(m.displacement),
        distance_exact: exact,
        distance_rel_error: (along(m.displacement) - exact).abs() / exact.max(f64::MIN_POSITIVE),
        velocity: along(m.v),
        velocity_exact: a * t,
        slip: along(m.v) + m.omega * disk.radius * turn,
    }
}

/// Figures for `summary.json` (`disk_impact`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct DiskImpactErrors {
    /// |Σ m v (t_end) − Σ m v (0)| over the larger body's |m v(0)|: 0
    /// exactly (no external force).
    pub momentum_drift: f64,
    /// ω R of the pair's first and second disk (m/s): 0 exactly.
    pub spin_first: f64,
    pub spin_second: f64,
    /// The centres' velocities along the contact tangent at the start's
    /// line of centres (m/s), and what each had at the start (kept by a
    /// frictionless contact between rigid disks).
    pub tangential_first: f64,
    pub tangential_second: f64,
    pub tangential_first_start: f64,
    pub tangential_second_start: f64,
    /// The centres' separating speed along that line (m/s): the rebound,
    /// 2 m/s for the case's elastic, rigid disks.
    pub separating: f64,
    /// Approach speed along that line at the start (m/s).
    pub approaching: f64,
}

/// The unit line of centres, first disk to second, where the approach at
/// the start velocities brings the disks together (the start's line when
/// they never meet).
pub fn impact_line(scene: &Scene) -> [f64; 2] {
    let pair = bodies::pair(scene);
    let disk = |k: usize| pair.body[k].disks.first().copied().unwrap_or([0.0; 3]);
    let (d0, d1) = (disk(0), disk(1));
    let v0 = [pair.body[0].velocity, pair.body[1].velocity];
    let rel = [v0[1][0] - v0[0][0], v0[1][1] - v0[0][1]];
    let dc = [d1[0] - d0[0], d1[1] - d0[1]];
    let contact = (d0[2] + d1[2]).powi(2);
    // Time to contact along the approach: |dc + rel s| = R0 + R1.
    let (aa, bb, cc) = (
        rel[0] * rel[0] + rel[1] * rel[1],
        2.0 * (dc[0] * rel[0] + dc[1] * rel[1]),
        dc[0] * dc[0] + dc[1] * dc[1] - contact,
    );
    let disc = bb * bb - 4.0 * aa * cc;
    let s = if aa > 0.0 && disc >= 0.0 {
        (-bb - disc.sqrt()) / (2.0 * aa)
    } else {
        0.0
    };
    let line = [dc[0] + rel[0] * s, dc[1] + rel[1] * s];
    let len = line[0].hypot(line[1]).max(f64::MIN_POSITIVE);
    [line[0] / len, line[1] / len]
}

pub fn score_impact(scene: &Scene, p: &Particles) -> DiskImpactErrors {
    let pair = bodies::pair(scene);
    let disk = |k: usize| pair.body[k].disks.first().copied().unwrap_or([0.0; 3]);
    let (d0, d1) = (disk(0), disk(1));
    let m = bodies::body_motion(p, scene.file.bodies.len());
    let (a, b) = (m[pair.index[0]], m[pair.index[1]]);
    let v0 = [pair.body[0].velocity, pair.body[1].velocity];
    let rel = [v0[1][0] - v0[0][0], v0[1][1] - v0[0][1]];
    let u = impact_line(scene);
    let tg = [-u[1], u[0]];
    let dot = |v: [f64; 2], w: [f64; 2]| v[0] * w[0] + v[1] * w[1];
    let p_now = [
        a.mass * a.v[0] + b.mass * b.v[0],
        a.mass * a.v[1] + b.mass * b.v[1],
    ];
    let p_start = [
        a.mass * v0[0][0] + b.mass * v0[1][0],
        a.mass * v0[0][1] + b.mass * v0[1][1],
    ];
    let scale = (a.mass * v0[0][0].hypot(v0[0][1])).max(b.mass * v0[1][0].hypot(v0[1][1]));
    DiskImpactErrors {
        momentum_drift: (p_now[0] - p_start[0]).hypot(p_now[1] - p_start[1])
            / scale.max(f64::MIN_POSITIVE),
        spin_first: a.omega * d0[2],
        spin_second: b.omega * d1[2],
        tangential_first: dot(a.v, tg),
        tangential_second: dot(b.v, tg),
        tangential_first_start: dot(v0[0], tg),
        tangential_second_start: dot(v0[1], tg),
        separating: dot([b.v[0] - a.v[0], b.v[1] - a.v[1]], u),
        approaching: -dot(rel, u),
    }
}

/// The motion of the pair's two bodies, first and second.
pub fn pair_motion(scene: &Scene, p: &Particles) -> [BodyMotion; 2] {
    let pair = bodies::pair(scene);
    let m = bodies::body_motion(p, scene.file.bodies.len());
    [m[pair.index[0]], m[pair.index[1]]]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ramped_slide_is_the_integral_of_the_ramped_velocity() {
        let block = SlidingBlock {
            tangent: [1.0, 0.0],
            normal: [0.0, 1.0],
            g_tangential: 4.905,
            g_normal: 8.4957,
            mu: 0.2,
            ramp_period: 0.2,
        };
        // Trapezoidal integral of R(t) against the closed form.
        let n = 200_000;
        let t_end = 0.5;
        let dt = t_end / n as f64;
        let mut sum = 0.0;
        for k in 0..n {
            let (a, b) = (k as f64 * dt, (k + 1) as f64 * dt);
            sum += 0.5 * dt * (block.ramp_integral(a) + block.ramp_integral(b));
        }
        assert!((sum - ramp_double_integral(&block, t_end)).abs() < 1e-9);
        let none = SlidingBlock {
            ramp_period: 0.0,
            ..block
        };
        assert_eq!(ramp_double_integral(&none, 2.0), 2.0);
    }
}
