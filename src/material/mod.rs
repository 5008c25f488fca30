//! Materials: one enum, one `update_stress`. Each model in its own file with a
//! WGSL twin in `shaders/shared/material_*.wgsl`. A model stores only the
//! per-particle state it needs (linear elastic: the stress alone).

pub mod linear_elastic;

pub use linear_elastic::LinearElastic;

use crate::scene::{MaterialModel, MaterialSpec};

#[derive(Debug, Clone, PartialEq)]
pub enum Material {
    LinearElastic(LinearElastic),
}

impl Material {
    pub fn new(spec: &MaterialSpec) -> Material {
        match spec.model {
            MaterialModel::LinearElastic => Material::LinearElastic(LinearElastic::new(
                spec.youngs_modulus,
                spec.nu,
                spec.density,
            )),
        }
    }

    /// Initial density ρ0 (kg/m³).
    pub fn density(&self) -> f64 {
        match self {
            Material::LinearElastic(m) => m.density,
        }
    }

    /// Updates the in-plane Cauchy stress `[σxx, σyy, σxy]` (Pa) for a strain
    /// increment `[Δεxx, Δεyy, Δεxy]` (tensor shear, not engineering).
    #[inline]
    pub fn update_stress(&self, stress: &mut [f64; 3], de: [f64; 3]) {
        match self {
            Material::LinearElastic(m) => m.update_stress(stress, de),
        }
    }

    /// Speed of the fastest wave at density `rho` (m/s), for the CFL condition.
    #[inline]
    pub fn wave_speed(&self, rho: f64) -> f64 {
        match self {
            Material::LinearElastic(m) => m.wave_speed(rho),
        }
    }

    /// Stored elastic energy per unit volume (J/m³) at stress `stress`.
    #[inline]
    pub fn strain_energy_density(&self, stress: &[f64; 3]) -> f64 {
        match self {
            Material::LinearElastic(m) => m.strain_energy_density(stress),
        }
    }
}
