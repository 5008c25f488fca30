//! A rigid block sliding on a frictional plane under gravity (Coulomb
//! friction). With n the wall's unit normal (into the material) and g the
//! gravity vector, the part of g along the plane is g_t = |g − (g·n) n|, the
//! part pressing the block on it g_n = −g·n. From rest the block moves along
//! the plane, in the direction of g's tangential part, with
//!   a = g_t − μ g_n   (= g (sin θ − μ cos θ) on a plane inclined by θ)
//! while a > 0, and stays at rest when g_t ≤ μ g_n (tan θ ≤ μ):
//! v(t) = max(a, 0) t. With gravity ramped by eq. 45 (period T) both g_t
//! and g_n carry the ramp factor r(t), so the block slides (or holds) all
//! along and v(t) = max(a, 0) R(t), R(t) = ∫₀ᵗ r = t/2 − T sin(2πt/T)/(4π)
//! up to T/2, then T/4 + (t − T/2). It covers both ways to set up the test:
//! gravity tilted by θ over a level wall, or a wall inclined by θ under
//! vertical gravity. The scene must hold one wall (slip or friction),
//! gravity, and bodies at rest (checked by validation).

use crate::model::Particles;
use crate::scene::{Contact, Scene};
use serde::Serialize;

#[derive(Debug, Clone, PartialEq)]
pub struct SlidingBlock {
    /// Unit vector along the plane, in the direction of g's tangential part.
    pub tangent: [f64; 2],
    /// g_t (m/s²).
    pub g_tangential: f64,
    /// g_n (m/s²), > 0 when gravity presses the block on the wall.
    pub g_normal: f64,
    /// μ (0 for a slip wall).
    pub mu: f64,
    /// T of the gravity's sine ramp (s); 0 = none.
    pub ramp_period: f64,
}

/// Figures for `summary.json`.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct SlidingErrors {
    /// Mass-weighted mean particle velocity along the plane (m/s).
    pub velocity: f64,
    /// max(a, 0) t (m/s), max(a, 0) R(t) with a ramp.
    pub velocity_exact: f64,
    /// a = g_t − μ g_n (m/s²); ≤ 0 means the block stays at rest.
    pub acceleration_exact: f64,
    /// |velocity − exact| / exact while sliding; at rest, |velocity| over
    /// the frictionless speed g_t t (g_t R(t) with a ramp).
    pub velocity_rel_error: f64,
    /// Mass-weighted mean velocity normal to the wall (m/s): 0 exactly.
    pub velocity_normal: f64,
}

impl SlidingBlock {
    pub fn from_scene(scene: &Scene) -> SlidingBlock {
        let f = &scene.file;
        let w = f.walls.values().next().expect("validated: one wall");
        let len = w.normal[0].hypot(w.normal[1]);
        let n = [w.normal[0] / len, w.normal[1] / len];
        let g = f.gravity.as_ref().map_or([0.0; 2], |g| g.g);
        let gn = g[0] * n[0] + g[1] * n[1];
        let gt = [g[0] - gn * n[0], g[1] - gn * n[1]];
        let gt_len = gt[0].hypot(gt[1]);
        // With no tangential gravity, any tangent will do: the block stays.
        let tangent = if gt_len > 0.0 {
            [gt[0] / gt_len, gt[1] / gt_len]
        } else {
            [n[1], -n[0]]
        };
        SlidingBlock {
            tangent,
            g_tangential: gt_len,
            g_normal: -gn,
            mu: match w.contact {
                Contact::Friction => w.friction.unwrap_or(0.0),
                _ => 0.0,
            },
            ramp_period: f.gravity.as_ref().map_or(0.0, |g| match g.ramp {
                crate::scene::Ramp::Sine => g.ramp_period.unwrap_or(0.0),
                crate::scene::Ramp::None => 0.0,
            }),
        }
    }

    /// R(t) = ∫₀ᵗ r(s) ds (s): t without a ramp.
    pub fn ramp_integral(&self, t: f64) -> f64 {
        let tp = self.ramp_period;
        if tp <= 0.0 {
            t
        } else if t <= 0.5 * tp {
            0.5 * t
                - tp * (2.0 * std::f64::consts::PI * t / tp).sin() / (4.0 * std::f64::consts::PI)
        } else {
            0.25 * tp + (t - 0.5 * tp)
        }
    }

    /// a = g_t − μ g_n (m/s²).
    pub fn acceleration(&self) -> f64 {
        self.g_tangential - self.mu * self.g_normal
    }

    /// Exact velocity along the plane at time t (m/s).
    pub fn velocity(&self, t: f64) -> f64 {
        self.acceleration().max(0.0) * self.ramp_integral(t)
    }

    pub fn score(&self, p: &Particles, t: f64) -> SlidingErrors {
        let mass: f64 = p.mass.iter().sum();
        let n = [-self.tangent[1], self.tangent[0]];
        let (mut vt, mut vn) = (0.0, 0.0);
        for i in 0..p.len() {
            let v = p.v[i];
            vt += p.mass[i] * (v[0] * self.tangent[0] + v[1] * self.tangent[1]);
            vn += p.mass[i] * (v[0] * n[0] + v[1] * n[1]);
        }
        let (vt, vn) = (vt / mass, vn / mass);
        let exact = self.velocity(t);
        let scale = if exact > 0.0 {
            exact
        } else {
            self.g_tangential * self.ramp_integral(t)
        };
        SlidingErrors {
            velocity: vt,
            velocity_exact: exact,
            acceleration_exact: self.acceleration(),
            velocity_rel_error: if scale > 0.0 {
                (vt - exact).abs() / scale
            } else {
                vt.abs()
            },
            velocity_normal: vn.abs(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_geometries_give_g_sin_minus_mu_cos() {
        let (th, mu, g) = (30f64.to_radians(), 0.3, 9.81);
        let want = g * (th.sin() - mu * th.cos());
        // Level wall, tilted gravity.
        let a = SlidingBlock {
            tangent: [1.0, 0.0],
            g_tangential: g * th.sin(),
            g_normal: g * th.cos(),
            mu,
            ramp_period: 0.0,
        };
        assert!((a.acceleration() - want).abs() < 1e-12);
        assert!((a.velocity(0.5) - 0.5 * want).abs() < 1e-12);
        // At rest when tan θ ≤ μ.
        let rest = SlidingBlock { mu: 0.7, ..a };
        assert_eq!(rest.velocity(0.5), 0.0);
        // The ramp's integral: T/4 at T/2, continuous, slope 1 after.
        let r = SlidingBlock {
            ramp_period: 0.2,
            ..a
        };
        assert!((r.ramp_integral(0.1) - 0.05).abs() < 1e-15);
        assert!((r.ramp_integral(0.5) - 0.45).abs() < 1e-15);
        let d = 1e-7;
        assert!(
            ((r.ramp_integral(0.05 + d) - r.ramp_integral(0.05 - d)) / (2.0 * d) - 0.5).abs()
                < 1e-6
        );
    }
}
