//! Compressible Neo-Hookean, plane strain, on the deformation gradient F
//! (B-spline paper eqs. 40–41): σ = λ ln J / J I + μ / J (F Fᵀ − I),
//! J = det F. F is updated each step as F ← (I + Δt L) F (eq. 35).
//! WGSL twin: `shaders/shared/material_neo_hookean.wgsl`.

use super::PlasticState;
use super::registry::{Constitutive, Key, Keys, StateKind};
use crate::error::SceneError;
use crate::model::fault::FaultKind;

#[derive(Debug, Clone, PartialEq)]
pub struct NeoHookean {
    /// Young's modulus E (Pa), for the wave speed.
    pub youngs: f64,
    pub nu: f64,
    /// Initial density ρ0 (kg/m³).
    pub density: f64,
    /// Lamé λ (Pa).
    pub lame: f64,
    /// Shear modulus μ (Pa).
    pub shear: f64,
}

pub use super::state::DefGrad;

impl NeoHookean {
    pub fn new(youngs: f64, nu: f64, density: f64) -> Self {
        NeoHookean {
            youngs,
            nu,
            density,
            lame: youngs * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
            shear: youngs / (2.0 * (1.0 + nu)),
        }
    }

    /// Cauchy stress [σxx, σyy, σxy] (Pa) at F; `None` when det F ≤ 0.
    #[inline]
    pub fn cauchy(&self, f: &DefGrad) -> Option<[f64; 3]> {
        let j = f[0] * f[3] - f[1] * f[2];
        if j.is_nan() || j <= 0.0 {
            return None;
        }
        // b = F Fᵀ (in plane).
        let bxx = f[0] * f[0] + f[1] * f[1];
        let byy = f[2] * f[2] + f[3] * f[3];
        let bxy = f[0] * f[2] + f[1] * f[3];
        let vol = self.lame * j.ln() / j;
        let s = self.shear / j;
        Some([vol + s * (bxx - 1.0), vol + s * (byy - 1.0), s * bxy])
    }

    /// Small-strain P-wave speed sqrt((λ + 2μ)/ρ) (m/s).
    #[inline]
    pub fn wave_speed(&self, rho: f64) -> f64 {
        ((self.lame + 2.0 * self.shear) / rho).sqrt()
    }

    /// Stored energy per unit current volume (J/m³):
    /// W = μ/2 (tr C − 3) − μ ln J + λ/2 (ln J)² per reference volume, over J
    /// (plane strain: C_zz = 1).
    #[inline]
    pub fn energy_density(&self, f: &DefGrad) -> f64 {
        let j = f[0] * f[3] - f[1] * f[2];
        if j.is_nan() || j <= 0.0 {
            return f64::INFINITY;
        }
        let tr_c = f.iter().map(|x| x * x).sum::<f64>() + 1.0;
        let lj = j.ln();
        (0.5 * self.shear * (tr_c - 3.0) - self.shear * lj + 0.5 * self.lame * lj * lj) / j
    }
}

impl Constitutive for NeoHookean {
    const NAME: &'static str = "neo_hookean";
    const KEYS: &'static [Key] = super::linear_elastic::ELASTIC_KEYS;
    const STATE: StateKind = StateKind::DefGrad;
    const GPU_PARAMS: &'static [&'static str] = &[];

    fn from_keys(k: &Keys) -> Result<Self, SceneError> {
        let (e, nu) = k.youngs_nu()?;
        Ok(NeoHookean::new(e, nu, k.density()))
    }
    fn density(&self) -> f64 {
        self.density
    }
    fn lame_shear(&self) -> (f64, f64) {
        (self.lame, self.shear)
    }
    fn youngs_nu(&self) -> (f64, f64) {
        (self.youngs, self.nu)
    }
    /// F ← (I + Δt L) F, σ = σ(F).
    #[inline]
    fn update(
        &self,
        l: [f64; 4],
        dt: f64,
        stress: &mut [f64; 3],
        f: &mut DefGrad,
        _q: &mut PlasticState,
    ) -> Result<f64, FaultKind> {
        let g = [1.0 + dt * l[0], dt * l[1], dt * l[2], 1.0 + dt * l[3]];
        let nf = [
            g[0] * f[0] + g[1] * f[2],
            g[0] * f[1] + g[1] * f[3],
            g[2] * f[0] + g[3] * f[2],
            g[2] * f[1] + g[3] * f[3],
        ];
        let j_old = f[0] * f[3] - f[1] * f[2];
        let j_new = nf[0] * nf[3] - nf[1] * nf[2];
        if j_new.is_nan() {
            return Err(FaultKind::NonFinite {
                field: "deformation gradient",
            });
        }
        let s = self.cauchy(&nf).ok_or(FaultKind::NonPositiveDensity)?;
        *f = nf;
        *stress = s;
        Ok(j_new / j_old)
    }
    #[inline]
    fn wave_speed(&self, rho: f64, _s: &[f64; 3], _q: &PlasticState) -> f64 {
        NeoHookean::wave_speed(self, rho)
    }
    #[inline]
    fn wave_speed_squared(&self, rho: f64, _s: &[f64; 3], _q: &PlasticState) -> f64 {
        (self.lame + 2.0 * self.shear) / rho
    }
    #[inline]
    fn strain_energy_density(&self, _s: &[f64; 3], f: &DefGrad, _q: &PlasticState) -> f64 {
        self.energy_density(f)
    }
    /// λ ln J / J (b_zz = 1), J = det F, or ρ0 / ρ without F.
    fn stress_zz(
        &self,
        _stress: &[f64; 3],
        f: Option<&DefGrad>,
        rho: f64,
        _q: Option<&PlasticState>,
    ) -> f64 {
        let j = match f {
            Some(f) => f[0] * f[3] - f[1] * f[2],
            None => self.density / rho,
        };
        self.lame * j.ln() / j
    }
    fn gpu_params(&self) -> Vec<f32> {
        Vec::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_stress_and_energy_at_identity() {
        let m = NeoHookean::new(1e7, 0.3, 1000.0);
        assert_eq!(m.cauchy(&[1.0, 0.0, 0.0, 1.0]), Some([0.0, 0.0, 0.0]));
        assert_eq!(m.energy_density(&[1.0, 0.0, 0.0, 1.0]), 0.0);
        assert_eq!(m.cauchy(&[1.0, 0.0, 0.0, -1.0]), None);
    }

    #[test]
    fn stress_matches_hand_computed_values() {
        // E = 1e7, ν = 0.3: λ = 5.769230769e6, μ = 3.846153846e6 Pa.
        let m = NeoHookean::new(1e7, 0.3, 1000.0);
        // Uniaxial stretch F = diag(1.1, 1): J = 1.1, ln J = 0.09531018,
        // λ ln J = 549866.42, μ (1.21 − 1) = 807692.31,
        // σxx = (549866.42 + 807692.31) / 1.1 = 1234144.30,
        // σyy = λ ln J / J = 499878.57, σxy = 0.
        let s = m.cauchy(&[1.1, 0.0, 0.0, 1.0]).unwrap();
        assert!((s[0] - 1_234_144.30).abs() < 0.05, "{s:?}");
        assert!((s[1] - 499_878.57).abs() < 0.05, "{s:?}");
        assert!(s[2].abs() < 1e-9);
        // Simple shear F = [[1, 0.2], [0, 1]]: J = 1, b = [[1.04, 0.2], [0.2, 1]]:
        // σxx = 0.04 μ = 153846.15, σyy = 0, σxy = 0.2 μ = 769230.77.
        let s = m.cauchy(&[1.0, 0.2, 0.0, 1.0]).unwrap();
        assert!(
            (s[0] - 153_846.15).abs() < 0.01
                && s[1].abs() < 1e-6
                && (s[2] - 769_230.77).abs() < 0.01,
            "{s:?}"
        );
    }

    #[test]
    fn stress_is_the_derivative_of_the_energy() {
        // σ = (1/J) ∂W/∂F Fᵀ: check one component by finite differences of
        // the energy per reference volume, W0 = J · energy_density.
        let m = NeoHookean::new(1e7, 0.3, 1000.0);
        let f = [1.05, 0.1, -0.03, 0.97];
        let w0 = |f: &DefGrad| (f[0] * f[3] - f[1] * f[2]) * m.energy_density(f);
        let eps = 1e-7;
        let mut p = [0.0; 4];
        for k in 0..4 {
            let (mut a, mut b) = (f, f);
            a[k] += eps;
            b[k] -= eps;
            p[k] = (w0(&a) - w0(&b)) / (2.0 * eps);
        }
        // σ = P Fᵀ / J with P = [[P00, P01], [P10, P11]] in f's order.
        let j = f[0] * f[3] - f[1] * f[2];
        let sxx = (p[0] * f[0] + p[1] * f[1]) / j;
        let syy = (p[2] * f[2] + p[3] * f[3]) / j;
        let sxy = (p[0] * f[2] + p[1] * f[3]) / j;
        let s = m.cauchy(&f).unwrap();
        for (a, b) in [(sxx, s[0]), (syy, s[1]), (sxy, s[2])] {
            assert!((a - b).abs() < 1e-3 * s[0].abs(), "{a} vs {b}");
        }
    }
}
