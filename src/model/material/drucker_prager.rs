//! Elastic-perfectly plastic Drucker–Prager matched to Mohr–Coulomb in
//! plane strain, with a tension cap on the mean stress. Tension-positive.
//!
//! - Yield: f = sqrt(J2) + α I1 − k ≤ 0 and p = I1 / 3 ≤ t, with
//!   α = tan φ / sqrt(9 + 12 tan² φ), k = 3c / sqrt(9 + 12 tan² φ): the cone
//!   through the Mohr–Coulomb failure stresses of plane strain at collapse
//!   (de Souza Neto et al. 2008, §8.3.2, the plane-strain match).
//! - Flow: g = sqrt(J2) + ᾱ I1 with ᾱ = tan ψ / sqrt(9 + 12 tan² ψ); the cap
//!   flows along its normal (volumetric).
//! - Elastic trial on the Jaumann rate, then the closed-form cone return
//!   (Δγ = f / (G + 9Kαᾱ)), or the cap, or their corner (the apex of the
//!   cone when t is the default apex k / (3α) = c / tan φ).
//!
//! WGSL twin: `shaders/shared/material_drucker_prager.wgsl`.

use super::plastic::{self, ACTIVE_MAIN, ACTIVE_T1, Elastic3, PlasticState};
use crate::model::fault::FaultKind;

#[derive(Debug, Clone, PartialEq)]
pub struct DruckerPrager {
    /// Young's modulus E (Pa).
    pub youngs: f64,
    /// Poisson's ratio ν.
    pub nu: f64,
    /// Initial density ρ0 (kg/m³).
    pub density: f64,
    pub elastic: Elastic3,
    /// Cohesion c (Pa) and friction angle φ (rad), as given.
    pub cohesion: f64,
    pub friction: f64,
    /// Cone slope α, flow slope ᾱ and intercept k (Pa) of the plane-strain match.
    pub alpha: f64,
    pub alpha_psi: f64,
    pub k: f64,
    /// Cap on the mean stress t (Pa); `None` without one (φ = 0 and no key).
    pub tension: Option<f64>,
}

/// Plane-strain match of Drucker–Prager to Mohr–Coulomb: (α, k) for
/// friction angle `phi` (rad) and cohesion `c`.
pub fn plane_strain_match(c: f64, phi: f64) -> (f64, f64) {
    let t = phi.tan();
    let r = (9.0 + 12.0 * t * t).sqrt();
    (t / r, 3.0 * c / r)
}

impl DruckerPrager {
    /// Angles in degrees; `tension` `None` means the apex c / tan φ (none
    /// when φ = 0); a cap above the apex is clamped to it.
    pub fn new(
        youngs: f64,
        nu: f64,
        density: f64,
        cohesion: f64,
        friction_deg: f64,
        dilation_deg: f64,
        tension: Option<f64>,
    ) -> Self {
        let friction = friction_deg.to_radians();
        let (alpha, k) = plane_strain_match(cohesion, friction);
        let (alpha_psi, _) = plane_strain_match(0.0, dilation_deg.to_radians());
        let apex = (alpha > 0.0).then(|| k / (3.0 * alpha));
        let tension = match (tension, apex) {
            (Some(t), Some(a)) => Some(t.min(a)),
            (t, a) => t.or(a),
        };
        DruckerPrager {
            youngs,
            nu,
            density,
            elastic: Elastic3::new(youngs, nu),
            cohesion,
            friction,
            alpha,
            alpha_psi,
            k,
            tension,
        }
    }

    /// The cone's yield function f = sqrt(J2) + α I1 − k at [xx, yy, zz, xy] (Pa).
    pub fn yield_cone(&self, s: [f64; 4]) -> f64 {
        let (p, sj2) = p_sqrt_j2(s);
        sj2 + 3.0 * self.alpha * p - self.k
    }

    /// Return of the trial stress `t` = [xx, yy, zz, xy]: the stress and
    /// the active surfaces (0: elastic, `t` unchanged; `ACTIVE_MAIN` the
    /// cone; `ACTIVE_T1` the cap; both: their corner).
    pub fn return_stress(&self, t: [f64; 4]) -> ([f64; 4], u32) {
        let e = &self.elastic;
        let (p, sj2) = p_sqrt_j2(t);
        let f = sj2 + 3.0 * self.alpha * p - self.k;
        let cap = self.tension.unwrap_or(f64::INFINITY);
        if f <= 0.0 && p <= cap {
            return (t, 0);
        }
        // s ← s (1 − GΔγ / sqrt J2), p ← p − 3Kᾱ Δγ.
        let with = |p_new: f64, sj2_new: f64| {
            let r = if sj2 > 0.0 { sj2_new / sj2 } else { 0.0 };
            [
                p_new + r * (t[0] - p),
                p_new + r * (t[1] - p),
                p_new + r * (t[2] - p),
                r * t[3],
            ]
        };
        if f > 0.0 {
            let dg = f / (e.shear + 9.0 * e.bulk * self.alpha * self.alpha_psi);
            let sj2_new = sj2 - e.shear * dg;
            let p_new = p - 3.0 * e.bulk * self.alpha_psi * dg;
            if sj2_new >= 0.0 && p_new <= cap {
                return (with(p_new, sj2_new), ACTIVE_MAIN);
            }
        }
        // The cap alone: p = t, s kept, if that lies inside the cone.
        if p > cap && sj2 + 3.0 * self.alpha * cap - self.k <= 0.0 {
            return (with(cap, sj2), ACTIVE_T1);
        }
        // The corner: p = t on the cone (the apex when t = k / (3α)).
        let sj2_new = (self.k - 3.0 * self.alpha * cap).max(0.0);
        (with(cap, sj2_new.min(sj2)), ACTIVE_MAIN | ACTIVE_T1)
    }

    /// One step: Jaumann trial and return. Updates the in-plane stress and
    /// the plastic state; returns V_new / V_old.
    #[inline]
    pub fn update(
        &self,
        l: [f64; 4],
        dt: f64,
        stress: &mut [f64; 3],
        q: &mut PlasticState,
    ) -> Result<f64, FaultKind> {
        let j = plastic::volume_ratio(l, dt)?;
        let e = &self.elastic;
        let (t, tzz) = e.jaumann_trial(l, dt, stress, q[plastic::SZZ]);
        let trial = [t[0], t[1], tzz, t[2]];
        let (s, active) = self.return_stress(trial);
        plastic::record(q, e, trial, s, active);
        *stress = [s[0], s[1], s[3]];
        Ok(j)
    }
}

/// Mean stress p and sqrt(J2) of [xx, yy, zz, xy].
#[inline]
pub fn p_sqrt_j2(s: [f64; 4]) -> (f64, f64) {
    let p = (s[0] + s[1] + s[2]) / 3.0;
    let d = [s[0] - p, s[1] - p, s[2] - p];
    let j2 = 0.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) + s[3] * s[3];
    (p, j2.sqrt())
}
