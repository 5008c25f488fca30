//! Dyka's bar (paper appendix A): a 1D elastic bar, free at its left end and
//! fixed at its right end, with piecewise-constant initial velocity and no
//! initial stress, solved exactly by characteristics. The invariants
//! R⁺ = v − σ/Z (moving at +c) and R⁻ = v + σ/Z (moving at −c) are constant
//! along their characteristics; at the free end σ = 0 so R⁺ = R⁻, at the
//! fixed end v = 0 so R⁻ = −R⁺. Then v = (R⁺ + R⁻)/2, σ = Z (R⁻ − R⁺)/2.

use crate::model::Particles;
use crate::scene::Scene;
use serde::Serialize;

#[derive(Debug, Clone)]
pub struct DykaBar {
    /// Free end (m).
    pub x_free: f64,
    /// Fixed end (m).
    pub x_fixed: f64,
    /// Wave speed sqrt(E/ρ) (m/s).
    pub c: f64,
    /// Impedance sqrt(E ρ) (Pa·s/m).
    pub z: f64,
    /// Initial velocity on [x0, x1): (x0, x1, v).
    pub segments: Vec<(f64, f64, f64)>,
}

/// Figures for `summary.json`.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct DykaErrors {
    /// RMS over particles of |v_p − v_exact(X_p, t)| (m/s), paper eq. 44.
    pub rms_velocity: f64,
    /// `rms_velocity` divided by the largest initial speed.
    pub rms_velocity_relative: f64,
    /// Largest |v_p − v_exact| (m/s).
    pub max_velocity: f64,
    /// `max_velocity` divided by the largest initial speed.
    pub max_velocity_relative: f64,
}

impl DykaBar {
    /// The bar spans the bodies' x-extent; each rect's body velocity is its
    /// initial velocity. Material from the scene's single material.
    pub fn from_scene(scene: &Scene) -> DykaBar {
        let m = scene.materials().next().expect("validated: one material").1;
        let mut segments = Vec::new();
        for (_, b) in scene.bodies() {
            for r in &b.rects {
                segments.push((r[0], r[2], b.velocity[0]));
            }
        }
        segments.sort_by(|a, b| a.0.total_cmp(&b.0));
        let x_free = segments.iter().map(|s| s.0).fold(f64::INFINITY, f64::min);
        let x_fixed = segments
            .iter()
            .map(|s| s.1)
            .fold(f64::NEG_INFINITY, f64::max);
        DykaBar {
            x_free,
            x_fixed,
            c: (m.get("E").expect("validated: E") / m.density).sqrt(),
            z: (m.get("E").expect("validated: E") * m.density).sqrt(),
            segments,
        }
    }

    fn v0(&self, x: f64) -> f64 {
        self.segments
            .iter()
            .find(|s| x >= s.0 && x < s.1)
            .or_else(|| self.segments.last().filter(|s| x >= s.1))
            .map_or(0.0, |s| s.2)
    }

    /// Invariant of family `plus` (R⁺ if true) at (x, t), traced back along
    /// characteristics and reflections to t = 0 (where σ = 0, so R± = v0).
    fn invariant(&self, mut x: f64, mut t: f64, mut plus: bool) -> f64 {
        let mut sign = 1.0;
        loop {
            if plus {
                let foot = x - self.c * t;
                if foot >= self.x_free {
                    return sign * self.v0(foot);
                }
                // Came from the free end, where R⁺ = R⁻.
                t -= (x - self.x_free) / self.c;
                x = self.x_free;
                plus = false;
            } else {
                let foot = x + self.c * t;
                if foot <= self.x_fixed {
                    return sign * self.v0(foot);
                }
                // Came from the fixed end, where R⁻ = −R⁺.
                t -= (self.x_fixed - x) / self.c;
                x = self.x_fixed;
                sign = -sign;
                plus = true;
            }
        }
    }

    /// Exact (velocity, stress) at reference position `x` and time `t`.
    pub fn velocity_stress(&self, x: f64, t: f64) -> (f64, f64) {
        let rp = self.invariant(x, t, true);
        let rm = self.invariant(x, t, false);
        (0.5 * (rp + rm), 0.5 * self.z * (rm - rp))
    }

    /// Paper eq. 44 at time `t`, the exact solution evaluated at each
    /// particle's reference position (the solution is linear theory, so
    /// Lagrangian; displacements are ~1e-3 of the cell size).
    pub fn score(&self, p: &Particles, t: f64) -> DykaErrors {
        let (mut sum, mut max) = (0.0, 0.0f64);
        for i in 0..p.len() {
            let (ve, _) = self.velocity_stress(p.x0[i][0], t);
            let d2 = (p.v[i][0] - ve).powi(2) + p.v[i][1].powi(2);
            sum += d2;
            max = max.max(d2.sqrt());
        }
        let rms = (sum / p.len().max(1) as f64).sqrt();
        let vmax = self.segments.iter().map(|s| s.2.abs()).fold(0.0, f64::max);
        DykaErrors {
            rms_velocity: rms,
            rms_velocity_relative: if vmax > 0.0 { rms / vmax } else { rms },
            max_velocity: max,
            max_velocity_relative: if vmax > 0.0 { max / vmax } else { max },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bar() -> DykaBar {
        let l = 0.1333;
        DykaBar {
            x_free: 0.0,
            x_fixed: l,
            c: (200e9f64 / 7833.0).sqrt(),
            z: (200e9f64 * 7833.0).sqrt(),
            segments: vec![(0.0, l / 4.0, -5.0), (l / 4.0, l, 0.0)],
        }
    }

    #[test]
    fn initial_state_is_reproduced() {
        let b = bar();
        assert_eq!(b.velocity_stress(0.01, 0.0), (-5.0, 0.0));
        assert_eq!(b.velocity_stress(0.1, 0.0), (0.0, 0.0));
    }

    #[test]
    fn boundary_conditions_hold_at_all_times() {
        let b = bar();
        for k in 1..200 {
            let t = k as f64 * 5e-7;
            let (_, s_free) = b.velocity_stress(b.x_free, t);
            let (v_fixed, _) = b.velocity_stress(b.x_fixed, t);
            assert!(s_free.abs() < 1e-6, "free end stress {s_free} at t = {t}");
            assert!(
                v_fixed.abs() < 1e-12,
                "fixed end velocity {v_fixed} at t = {t}"
            );
        }
    }

    #[test]
    fn first_wave_is_the_impact_solution() {
        // Before any reflection reaches it, the interface at L/4 carries
        // v = −2.5 m/s and a tension/compression of magnitude Z·2.5.
        let b = bar();
        let t = 0.1 * b.x_fixed / b.c;
        let (v, s) = b.velocity_stress(b.x_fixed / 4.0 + 0.5 * b.c * t, t);
        assert!((v + 2.5).abs() < 1e-12);
        assert!((s.abs() - 2.5 * b.z).abs() < 1e-6 * b.z);
    }

    #[test]
    fn energy_is_conserved() {
        // ∫ (½ρv² + σ²/(2E)) dx is constant for the exact solution.
        let b = bar();
        let (rho, e) = (7833.0, 200e9);
        let energy = |t: f64| {
            let n = 20000;
            let dx = (b.x_fixed - b.x_free) / n as f64;
            (0..n)
                .map(|i| {
                    let (v, s) = b.velocity_stress(b.x_free + (i as f64 + 0.5) * dx, t);
                    (0.5 * rho * v * v + s * s / (2.0 * e)) * dx
                })
                .sum::<f64>()
        };
        let e0 = energy(0.0);
        for t in [1e-5, 3.3e-5, 7e-5, 1e-4] {
            assert!(
                (energy(t) - e0).abs() < 2e-3 * e0,
                "t = {t}: {} vs {e0}",
                energy(t)
            );
        }
    }
}
