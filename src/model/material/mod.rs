//! Materials: one enum, one `update`. Each model in its own file with a
//! WGSL twin in `shaders/shared/material_*.wgsl`. A model stores only the
//! per-particle state it needs (linear elastic: the stress alone;
//! Neo-Hookean: the deformation gradient too).

pub mod linear_elastic;
pub mod neo_hookean;

pub use linear_elastic::LinearElastic;
pub use neo_hookean::{DefGrad, NeoHookean};

use crate::model::fault::FaultKind;
use crate::scene::{MaterialModel, MaterialSpec};

#[derive(Debug, Clone, PartialEq)]
pub enum Material {
    LinearElastic(LinearElastic),
    NeoHookean(NeoHookean),
}

impl Material {
    pub fn new(spec: &MaterialSpec) -> Material {
        let (e, nu, rho) = (spec.youngs_modulus, spec.nu, spec.density);
        match spec.model {
            MaterialModel::LinearElastic => Material::LinearElastic(LinearElastic::new(e, nu, rho)),
            MaterialModel::NeoHookean => Material::NeoHookean(NeoHookean::new(e, nu, rho)),
        }
    }

    /// Initial density ρ0 (kg/m³).
    pub fn density(&self) -> f64 {
        match self {
            Material::LinearElastic(m) => m.density,
            Material::NeoHookean(m) => m.density,
        }
    }

    /// Lamé λ and shear modulus μ (Pa).
    pub fn lame_shear(&self) -> (f64, f64) {
        match self {
            Material::LinearElastic(m) => (m.lame, m.shear),
            Material::NeoHookean(m) => (m.lame, m.shear),
        }
    }

    /// The model keeps a deformation gradient per particle.
    pub fn needs_deformation_gradient(&self) -> bool {
        matches!(self, Material::NeoHookean(_))
    }

    /// One step of the constitutive update from the velocity gradient
    /// `l` = [∂vx/∂x, ∂vx/∂y, ∂vy/∂x, ∂vy/∂y] (1/s) over `dt` (s): updates the
    /// stress (and F), and returns the volume ratio V_new / V_old.
    #[inline]
    pub fn update(
        &self,
        l: [f64; 4],
        dt: f64,
        stress: &mut [f64; 3],
        f: &mut DefGrad,
    ) -> Result<f64, FaultKind> {
        match self {
            Material::LinearElastic(m) => {
                let de = [dt * l[0], dt * l[3], 0.5 * dt * (l[1] + l[2])];
                let j = 1.0 + de[0] + de[1];
                if j.is_nan() {
                    return Err(FaultKind::NonFinite { field: "strain" });
                }
                if j <= 0.0 {
                    return Err(FaultKind::NonPositiveDensity);
                }
                m.update_stress(stress, de);
                Ok(j)
            }
            Material::NeoHookean(m) => {
                // F ← (I + Δt L) F.
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
                let s = m.cauchy(&nf).ok_or(FaultKind::NonPositiveDensity)?;
                *f = nf;
                *stress = s;
                Ok(j_new / j_old)
            }
        }
    }

    /// Speed of the fastest wave at density `rho` (m/s), for the CFL condition.
    #[inline]
    pub fn wave_speed(&self, rho: f64) -> f64 {
        match self {
            Material::LinearElastic(m) => m.wave_speed(rho),
            Material::NeoHookean(m) => m.wave_speed(rho),
        }
    }

    /// Stored elastic energy per unit current volume (J/m³), from the
    /// stress (linear elastic) or the deformation gradient (Neo-Hookean).
    #[inline]
    pub fn strain_energy_density(&self, stress: &[f64; 3], f: &DefGrad) -> f64 {
        match self {
            Material::LinearElastic(m) => m.strain_energy_density(stress),
            Material::NeoHookean(m) => m.energy_density(f),
        }
    }
}
