//! The manufactured 2D aligned vibration (B-spline paper, eq. 38, after
//! Sadeghirad et al. 2011) on a square of side L, Neo-Hookean:
//!   u(X, t) = A [sin(2πX/L) sin(cπt/L), sin(2πY/L) sin(cπt/L + π)],
//! c = sqrt(E/ρ0), X relative to the square's lower-left corner. F is
//! diagonal: F_xx = 1 + (2πA/L) cos(2πX/L) sin(cπt/L), likewise F_yy.
//!
//! Body force (derived here; the paper's eq. 42 prints π where π² belongs):
//! with P_xx = λ ln J / F_xx + μ (F_xx − 1/F_xx) and ∂F_xx/∂X = −(2π/L)² u_x,
//!   b_x = ü_x − (1/ρ0) ∂P_xx/∂X
//!       = (π² u_x / L²) [4μ/ρ0 − c² + 4 (λ (1 − ln J) + μ) / (ρ0 F_xx²)],
//! and b_y the same with y for x. The test `momentum_balance_holds`
//! checks it against finite differences of the exact fields.

use crate::material::NeoHookean;
use crate::model::Particles;
use crate::scene::Scene;
use serde::Serialize;
use std::f64::consts::PI;

#[derive(Debug, Clone, PartialEq)]
pub struct AlignedVibration {
    /// A (m).
    pub amplitude: f64,
    /// L (m).
    pub length: f64,
    /// c = sqrt(E/ρ0) (m/s).
    pub c: f64,
    /// Lower-left corner of the square (m).
    pub origin: [f64; 2],
    pub material: NeoHookean,
}

/// Figures for `summary.json`: RMS over particles at t_end (paper eq. 43).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct MmsErrors {
    /// RMS |u − u_exact| (m).
    pub rms_displacement: f64,
    /// RMS |v − v_exact| (m/s).
    pub rms_velocity: f64,
    /// RMS of the Cauchy stress difference, sqrt(Δσxx² + Δσyy² + 2Δσxy²) (Pa).
    pub rms_stress: f64,
}

impl AlignedVibration {
    /// From a scene with `[manufactured]`: the square is the bodies' bounding
    /// box, the material its single (Neo-Hookean) material.
    pub fn from_scene(scene: &Scene) -> Option<AlignedVibration> {
        let spec = scene.file.manufactured.as_ref()?;
        let m = scene.materials().next()?.1;
        let bb = crate::scene::seed::bodies_bbox(scene);
        Some(AlignedVibration {
            amplitude: spec.amplitude,
            length: bb[2] - bb[0],
            c: (m.youngs_modulus / m.density).sqrt(),
            origin: [bb[0], bb[1]],
            material: NeoHookean::new(m.youngs_modulus, m.nu, m.density),
        })
    }

    fn k(&self) -> f64 {
        2.0 * PI / self.length
    }

    fn omega(&self) -> f64 {
        self.c * PI / self.length
    }

    /// Displacement at reference position `x` (m) and time `t` (s).
    pub fn displacement(&self, x: [f64; 2], t: f64) -> [f64; 2] {
        let (k, w) = (self.k(), self.omega());
        let (xx, yy) = (x[0] - self.origin[0], x[1] - self.origin[1]);
        [
            self.amplitude * (k * xx).sin() * (w * t).sin(),
            self.amplitude * (k * yy).sin() * (w * t + PI).sin(),
        ]
    }

    /// Velocity (m/s).
    pub fn velocity(&self, x: [f64; 2], t: f64) -> [f64; 2] {
        let (k, w) = (self.k(), self.omega());
        let (xx, yy) = (x[0] - self.origin[0], x[1] - self.origin[1]);
        [
            self.amplitude * w * (k * xx).sin() * (w * t).cos(),
            self.amplitude * w * (k * yy).sin() * (w * t + PI).cos(),
        ]
    }

    /// Deformation gradient [xx, xy, yx, yy] (diagonal).
    pub fn def_grad(&self, x: [f64; 2], t: f64) -> [f64; 4] {
        let (k, w) = (self.k(), self.omega());
        let (xx, yy) = (x[0] - self.origin[0], x[1] - self.origin[1]);
        let fxx = 1.0 + self.amplitude * k * (k * xx).cos() * (w * t).sin();
        let fyy = 1.0 + self.amplitude * k * (k * yy).cos() * (w * t + PI).sin();
        [fxx, 0.0, 0.0, fyy]
    }

    /// Cauchy stress [xx, yy, xy] (Pa).
    pub fn cauchy(&self, x: [f64; 2], t: f64) -> [f64; 3] {
        self.material
            .cauchy(&self.def_grad(x, t))
            .unwrap_or([f64::NAN; 3])
    }

    /// Body force per unit mass that makes the field a solution (m/s²).
    pub fn body_force(&self, x: [f64; 2], t: f64) -> [f64; 2] {
        let m = &self.material;
        let rho0 = m.density;
        let u = self.displacement(x, t);
        let f = self.def_grad(x, t);
        let lnj = (f[0] * f[3]).ln();
        let l2 = self.length * self.length;
        let common = 4.0 * m.shear / rho0 - self.c * self.c;
        let tail = 4.0 * (m.lame * (1.0 - lnj) + m.shear) / rho0;
        [
            PI * PI * u[0] / l2 * (common + tail / (f[0] * f[0])),
            PI * PI * u[1] / l2 * (common + tail / (f[3] * f[3])),
        ]
    }

    /// The most kinetic + stored energy (J/m) the exact field holds over one
    /// period 2L/c, on the particles' reference positions and masses (64
    /// instants). The body force feeds the field this energy and takes it
    /// back each period, so it is what a run may hold without running away.
    pub fn peak_energy(&self, p: &Particles) -> f64 {
        let period = 2.0 * self.length / self.c;
        (0..64)
            .map(|k| {
                let t = period * k as f64 / 64.0;
                (0..p.len())
                    .map(|i| {
                        let (x0, v) = (p.x0[i], self.velocity(p.x0[i], t));
                        let w = self.material.energy_density(&self.def_grad(x0, t));
                        let f = self.def_grad(x0, t);
                        let volume = p.mass[i] / self.material.density * (f[0] * f[3]);
                        0.5 * p.mass[i] * (v[0] * v[0] + v[1] * v[1]) + w * volume
                    })
                    .sum::<f64>()
            })
            .fold(0.0, f64::max)
    }

    /// Paper eq. 43 at time `t`, each particle against the exact field at
    /// its reference position.
    pub fn score(&self, p: &Particles, t: f64) -> MmsErrors {
        let n = p.len().max(1) as f64;
        let (mut du, mut dv, mut ds) = (0.0, 0.0, 0.0);
        for i in 0..p.len() {
            let x0 = p.x0[i];
            let u = self.displacement(x0, t);
            let v = self.velocity(x0, t);
            let s = self.cauchy(x0, t);
            du += (p.x[i][0] - x0[0] - u[0]).powi(2) + (p.x[i][1] - x0[1] - u[1]).powi(2);
            dv += (p.v[i][0] - v[0]).powi(2) + (p.v[i][1] - v[1]).powi(2);
            ds += (p.stress[i][0] - s[0]).powi(2)
                + (p.stress[i][1] - s[1]).powi(2)
                + 2.0 * (p.stress[i][2] - s[2]).powi(2);
        }
        MmsErrors {
            rms_displacement: (du / n).sqrt(),
            rms_velocity: (dv / n).sqrt(),
            rms_stress: (ds / n).sqrt(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn case() -> AlignedVibration {
        AlignedVibration {
            amplitude: 0.1,
            length: 1.0,
            c: (1e7f64 / 1000.0).sqrt(),
            origin: [0.0, 0.0],
            material: NeoHookean::new(1e7, 0.3, 1000.0),
        }
    }

    /// ρ0 ü = Div_X P + ρ0 b at random points and times, with ü and Div P
    /// from central differences of the exact displacement and of P(F).
    #[test]
    fn momentum_balance_holds() {
        let m = case();
        let rho0 = m.material.density;
        let piola_xx_yy = |x: [f64; 2], t: f64| {
            // P = σ J F^{-T}; diagonal F, so P_xx = σ_xx J / F_xx.
            let f = m.def_grad(x, t);
            let s = m.cauchy(x, t);
            let j = f[0] * f[3];
            [s[0] * j / f[0], s[1] * j / f[3]]
        };
        let mut rng = crate::rng::SplitMix64::new(5);
        for _ in 0..50 {
            let x = [rng.range(0.05, 0.95), rng.range(0.05, 0.95)];
            let t = rng.range(0.0, 0.2);
            // ht: ωt reaches ~60 rad, so sin(ωt) carries ~1e-14 absolute
            // roundoff; a step of 1e-5 s keeps that below 1e-7 of ü while
            // the truncation error ω⁴ u ht²/12 stays below 1e-6 of it.
            let (hx, ht) = (1e-5, 1e-5);
            let acc = |d: usize| {
                (m.displacement(x, t + ht)[d] - 2.0 * m.displacement(x, t)[d]
                    + m.displacement(x, t - ht)[d])
                    / (ht * ht)
            };
            let div_x = (piola_xx_yy([x[0] + hx, x[1]], t)[0]
                - piola_xx_yy([x[0] - hx, x[1]], t)[0])
                / (2.0 * hx);
            let div_y = (piola_xx_yy([x[0], x[1] + hx], t)[1]
                - piola_xx_yy([x[0], x[1] - hx], t)[1])
                / (2.0 * hx);
            let b = m.body_force(x, t);
            for (d, div) in [(0, div_x), (1, div_y)] {
                let lhs = rho0 * acc(d);
                let rhs = div + rho0 * b[d];
                let scale = (rho0 * acc(d)).abs().max(div.abs()).max(1.0);
                assert!(
                    (lhs - rhs).abs() < 1e-5 * scale,
                    "x {x:?} t {t} dir {d}: {lhs} vs {rhs}"
                );
            }
        }
    }

    #[test]
    fn boundaries_hold_still_in_the_normal_direction() {
        let m = case();
        for t in [0.013, 0.05, 0.17] {
            for s in [0.1, 0.5, 0.9] {
                assert!(m.displacement([0.0, s], t)[0].abs() < 1e-15);
                assert!(m.displacement([1.0, s], t)[0].abs() < 1e-15);
                assert!(m.displacement([s, 0.0], t)[1].abs() < 1e-15);
                assert!(m.displacement([s, 1.0], t)[1].abs() < 1e-15);
            }
        }
    }
}
