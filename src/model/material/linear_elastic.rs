//! Linear elastic, plane strain, small-strain increments (paper eq. 3):
//! Δσ = λ tr(Δε) I + 2μ Δε on the in-plane components. With the strain
//! increments taken on the current configuration and the density updated,
//! this is a hypoelastic law (logarithmic strain under uniaxial load).
//! WGSL twin: `shaders/shared/material_linear_elastic.wgsl`.

use super::registry::{Constitutive, Key, Keys, StateKind};
use super::{DefGrad, PlasticState};
use crate::error::SceneError;
use crate::model::fault::FaultKind;

/// The keys of the models with E and ν alone.
pub const ELASTIC_KEYS: &[Key] = &[
    Key {
        name: "E",
        unit: "Pa",
        doc: "Young's modulus, > 0",
    },
    Key {
        name: "nu",
        unit: "1",
        doc: "Poisson's ratio, in (-1, 0.5)",
    },
];

#[derive(Debug, Clone, PartialEq)]
pub struct LinearElastic {
    /// Young's modulus E (Pa).
    pub youngs: f64,
    /// Poisson's ratio ν.
    pub nu: f64,
    /// Initial density ρ0 (kg/m³).
    pub density: f64,
    /// Lamé λ (Pa).
    pub lame: f64,
    /// Shear modulus μ (Pa).
    pub shear: f64,
    /// P-wave (constrained) modulus λ + 2μ (Pa).
    pub p_modulus: f64,
}

impl LinearElastic {
    pub fn new(youngs: f64, nu: f64, density: f64) -> Self {
        let lame = youngs * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let shear = youngs / (2.0 * (1.0 + nu));
        LinearElastic {
            youngs,
            nu,
            density,
            lame,
            shear,
            p_modulus: lame + 2.0 * shear,
        }
    }

    #[inline]
    pub fn update_stress(&self, s: &mut [f64; 3], de: [f64; 3]) {
        let vol = self.lame * (de[0] + de[1]);
        s[0] += vol + 2.0 * self.shear * de[0];
        s[1] += vol + 2.0 * self.shear * de[1];
        s[2] += 2.0 * self.shear * de[2];
    }

    /// P-wave speed sqrt((λ + 2μ)/ρ). Equals the paper's sqrt(E/ρ) (eq. 43) when ν = 0.
    #[inline]
    pub fn wave_speed(&self, rho: f64) -> f64 {
        (self.p_modulus / rho).sqrt()
    }

    /// `wave_speed` squared: (λ + 2μ)/ρ.
    #[inline(always)]
    pub fn wave_speed_squared(&self, rho: f64) -> f64 {
        self.p_modulus / rho
    }

    /// ½ σ : ε with ε from the plane-strain compliance (σzz = ν(σxx + σyy) implied).
    #[inline]
    pub fn strain_energy_density(&self, s: &[f64; 3]) -> f64 {
        let (e, nu) = (self.youngs, self.nu);
        let exx = ((1.0 - nu * nu) * s[0] - nu * (1.0 + nu) * s[1]) / e;
        let eyy = ((1.0 - nu * nu) * s[1] - nu * (1.0 + nu) * s[0]) / e;
        let exy = s[2] / (2.0 * self.shear);
        0.5 * (s[0] * exx + s[1] * eyy + 2.0 * s[2] * exy)
    }
}

impl Constitutive for LinearElastic {
    const NAME: &'static str = "linear_elastic";
    const KEYS: &'static [Key] = ELASTIC_KEYS;
    const STATE: StateKind = StateKind::Stress;
    const GPU_PARAMS: &'static [&'static str] = &[];

    fn from_keys(k: &Keys) -> Result<Self, SceneError> {
        let (e, nu) = k.youngs_nu()?;
        Ok(LinearElastic::new(e, nu, k.density()))
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
    #[inline(always)]
    fn update(
        &self,
        l: [f64; 4],
        dt: f64,
        stress: &mut [f64; 3],
        _f: &mut DefGrad,
        _q: &mut PlasticState,
    ) -> Result<f64, FaultKind> {
        let de = [dt * l[0], dt * l[3], 0.5 * dt * (l[1] + l[2])];
        let j = 1.0 + de[0] + de[1];
        if j.is_nan() {
            return Err(FaultKind::NonFinite { field: "strain" });
        }
        if j <= 0.0 {
            return Err(FaultKind::NonPositiveDensity);
        }
        self.update_stress(stress, de);
        Ok(j)
    }
    #[inline]
    fn wave_speed(&self, rho: f64, _s: &[f64; 3], _q: &PlasticState) -> f64 {
        LinearElastic::wave_speed(self, rho)
    }
    #[inline(always)]
    fn wave_speed_squared(&self, rho: f64, _s: &[f64; 3], _q: &PlasticState) -> f64 {
        LinearElastic::wave_speed_squared(self, rho)
    }
    #[inline]
    fn strain_energy_density(&self, stress: &[f64; 3], _f: &DefGrad, _q: &PlasticState) -> f64 {
        LinearElastic::strain_energy_density(self, stress)
    }
    fn gpu_params(&self) -> Vec<f32> {
        Vec::new()
    }
    /// From a stress-free start: ν (σxx + σyy).
    fn stress_zz(
        &self,
        stress: &[f64; 3],
        _f: Option<&DefGrad>,
        _rho: f64,
        _q: Option<&PlasticState>,
    ) -> f64 {
        self.nu * (stress[0] + stress[1])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn energy_of_a_stress_from_a_strain_is_half_the_work() {
        let m = LinearElastic::new(2.0e7, 0.3, 1000.0);
        let de = [1e-4, -3e-5, 2e-5];
        let mut s = [0.0; 3];
        m.update_stress(&mut s, de);
        let work = 0.5 * (s[0] * de[0] + s[1] * de[1] + 2.0 * s[2] * de[2]);
        assert!((m.strain_energy_density(&s) - work).abs() < 1e-12 * work.abs());
    }

    #[test]
    fn nu_zero_gives_the_1d_wave_speed() {
        let m = LinearElastic::new(200e9, 0.0, 7833.0);
        assert!((m.wave_speed(7833.0) - (200e9f64 / 7833.0).sqrt()).abs() < 1e-9);
    }
}
