//! Materials: one enum, one `update`. Each model in its own file with a
//! WGSL twin in `shaders/shared/material_*.wgsl`. A model stores only the
//! per-particle state it needs (linear elastic: the stress alone;
//! Neo-Hookean: the deformation gradient too; Mohr–Coulomb and
//! Drucker–Prager: σzz and the plastic strains, `plastic::PlasticState`).

pub mod drucker_prager;
pub mod linear_elastic;
pub mod mohr_coulomb;
pub mod neo_hookean;
pub mod plastic;

pub use drucker_prager::DruckerPrager;
pub use linear_elastic::LinearElastic;
pub use mohr_coulomb::MohrCoulomb;
pub use neo_hookean::{DefGrad, NeoHookean};
pub use plastic::PlasticState;

use crate::model::fault::FaultKind;
use crate::scene::{MaterialModel, MaterialSpec};

#[derive(Debug, Clone, PartialEq)]
pub enum Material {
    LinearElastic(LinearElastic),
    NeoHookean(NeoHookean),
    MohrCoulomb(MohrCoulomb),
    DruckerPrager(DruckerPrager),
}

/// The tangent a later implicit solver asks of a material: dσ/dε in Voigt
/// form [xx, yy, xy] (engineering shear), plane strain (Pa).
pub type Tangent = [[f64; 3]; 3];

impl Material {
    pub fn new(spec: &MaterialSpec) -> Material {
        let (e, nu, rho) = (spec.youngs_modulus, spec.nu, spec.density);
        match spec.model {
            MaterialModel::LinearElastic => Material::LinearElastic(LinearElastic::new(e, nu, rho)),
            MaterialModel::NeoHookean => Material::NeoHookean(NeoHookean::new(e, nu, rho)),
            MaterialModel::MohrCoulomb | MaterialModel::DruckerPrager => {
                // Validation has made the two required keys present.
                let c = spec.cohesion.unwrap_or(0.0);
                let phi = spec.friction_angle.unwrap_or(0.0);
                let psi = spec.dilation_angle.unwrap_or(0.0);
                if spec.model == MaterialModel::MohrCoulomb {
                    Material::MohrCoulomb(MohrCoulomb::new(
                        e,
                        nu,
                        rho,
                        c,
                        phi,
                        psi,
                        spec.tension_cutoff,
                    ))
                } else {
                    Material::DruckerPrager(DruckerPrager::new(
                        e,
                        nu,
                        rho,
                        c,
                        phi,
                        psi,
                        spec.tension_cutoff,
                    ))
                }
            }
        }
    }

    /// Initial density ρ0 (kg/m³).
    pub fn density(&self) -> f64 {
        match self {
            Material::LinearElastic(m) => m.density,
            Material::NeoHookean(m) => m.density,
            Material::MohrCoulomb(m) => m.density,
            Material::DruckerPrager(m) => m.density,
        }
    }

    /// Lamé λ and shear modulus μ (Pa).
    pub fn lame_shear(&self) -> (f64, f64) {
        match self {
            Material::LinearElastic(m) => (m.lame, m.shear),
            Material::NeoHookean(m) => (m.lame, m.shear),
            Material::MohrCoulomb(m) => (m.elastic.lame, m.elastic.shear),
            Material::DruckerPrager(m) => (m.elastic.lame, m.elastic.shear),
        }
    }

    /// Young's modulus E (Pa) and Poisson's ratio ν.
    pub fn youngs_nu(&self) -> (f64, f64) {
        match self {
            Material::LinearElastic(m) => (m.youngs, m.nu),
            Material::NeoHookean(m) => (m.youngs, m.nu),
            Material::MohrCoulomb(m) => (m.youngs, m.nu),
            Material::DruckerPrager(m) => (m.youngs, m.nu),
        }
    }

    /// The model keeps a deformation gradient per particle.
    pub fn needs_deformation_gradient(&self) -> bool {
        matches!(self, Material::NeoHookean(_))
    }

    /// The model keeps a `PlasticState` (σzz, plastic strains) per particle.
    pub fn needs_plastic_state(&self) -> bool {
        matches!(self, Material::MohrCoulomb(_) | Material::DruckerPrager(_))
    }

    /// One step of the constitutive update from the velocity gradient
    /// `l` = [∂vx/∂x, ∂vx/∂y, ∂vy/∂x, ∂vy/∂y] (1/s) over `dt` (s): updates the
    /// stress (and F, or the plastic state `q`), and returns the volume
    /// ratio V_new / V_old. Models ignore the state they do not keep.
    #[inline]
    pub fn update(
        &self,
        l: [f64; 4],
        dt: f64,
        stress: &mut [f64; 3],
        f: &mut DefGrad,
        q: &mut PlasticState,
    ) -> Result<f64, FaultKind> {
        match self {
            Material::MohrCoulomb(m) => m.update(l, dt, stress, q),
            Material::DruckerPrager(m) => m.update(l, dt, stress, q),
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
            // The elastic P-wave speed bounds the elastoplastic one.
            Material::MohrCoulomb(m) => {
                ((m.elastic.lame + 2.0 * m.elastic.shear) / rho).sqrt()
            }
            Material::DruckerPrager(m) => {
                ((m.elastic.lame + 2.0 * m.elastic.shear) / rho).sqrt()
            }
        }
    }

    /// Stored elastic energy per unit current volume (J/m³), from the
    /// stress (linear elastic), the deformation gradient (Neo-Hookean), or
    /// for the plastic models the elastic part: ½ σ : C : σ on the current
    /// stress with its σzz (`q`).
    #[inline]
    pub fn strain_energy_density(&self, stress: &[f64; 3], f: &DefGrad, q: &PlasticState) -> f64 {
        let s4 = [stress[0], stress[1], q[plastic::SZZ], stress[2]];
        match self {
            Material::LinearElastic(m) => m.strain_energy_density(stress),
            Material::NeoHookean(m) => m.energy_density(f),
            Material::MohrCoulomb(m) => m.elastic.energy(s4),
            Material::DruckerPrager(m) => m.elastic.energy(s4),
        }
    }

    /// Hook for the implicit solver (a later issue): the tangent dσ/dε of
    /// the last `update` at this particle's state. Linear elastic gives its
    /// plane-strain D; the others return `None` until their consistent
    /// (algorithmic) tangents are written: for the plastic models it
    /// follows from the return recorded in `q[plastic::RETURN]` (the active
    /// surfaces) and de Souza Neto et al. box 8.4 (MC) / §8.3.3 (DP);
    /// Neo-Hookean's from ∂σ/∂F at `f`.
    pub fn tangent(&self, _stress: &[f64; 3], _f: &DefGrad, _q: &PlasticState) -> Option<Tangent> {
        match self {
            Material::LinearElastic(m) => {
                let (l, g) = (m.lame, m.shear);
                Some([[l + 2.0 * g, l, 0.0], [l, l + 2.0 * g, 0.0], [0.0, 0.0, g]])
            }
            _ => None,
        }
    }
}
