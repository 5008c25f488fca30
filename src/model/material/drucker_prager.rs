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

plastic::elastoplastic_constitutive!(
    DruckerPrager,
    "drucker_prager",
    ["tension", "alpha", "alpha_psi", "k"],
    // Cap t −1 where there is none; α, ᾱ, k of the plane-strain match.
    |m| vec![
        m.tension.map_or(-1.0, |t| t as f32),
        m.alpha as f32,
        m.alpha_psi as f32,
        m.k as f32,
    ]
);


/// Mean stress p and sqrt(J2) of [xx, yy, zz, xy].
#[inline]
pub fn p_sqrt_j2(s: [f64; 4]) -> (f64, f64) {
    let p = (s[0] + s[1] + s[2]) / 3.0;
    let d = [s[0] - p, s[1] - p, s[2] - p];
    let j2 = 0.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) + s[3] * s[3];
    (p, j2.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::material::plastic::{EPS_EQ, EPS_VOL, RETURN};

    /// E = 20 MPa, ν = 0.3, c = 10 kPa, φ = 30°: α = 0.1601, k = 8321.5 Pa.
    fn dp(psi: f64, t: Option<f64>) -> DruckerPrager {
        DruckerPrager::new(2.0e7, 0.3, 1800.0, 1.0e4, 30.0, psi, t)
    }

    /// |f| ≤ this · max(c, |p|) on a returned stress (f64 round-off).
    const ON_SURFACE: f64 = 1e-8;

    #[test]
    fn matching_and_elastic_states() {
        let m = dp(0.0, None);
        // tan 30° = 0.57735: sqrt(9 + 12/3) = sqrt(13).
        assert!((m.alpha - 0.577_350_269 / 13f64.sqrt()).abs() < 1e-9);
        assert!((m.k - 3.0e4 / 13f64.sqrt()).abs() < 1e-6);
        // The apex is Mohr–Coulomb's, c / tan φ.
        assert!((m.tension.unwrap() - 1.0e4 * 3f64.sqrt()).abs() < 1e-6);
        let t = [-2.0e4, -3.0e4, -2.5e4, 1.0e3];
        assert!(m.yield_cone(t) < 0.0);
        assert_eq!(m.return_stress(t), (t, 0));
    }

    #[test]
    fn cone_cap_and_apex_returns() {
        let m = dp(0.0, None);
        // Cone, ψ = 0: p kept, sqrt J2 = k − 3αp, direction of s kept.
        let t = [0.0, -1.0e5, -5.0e4, 2.0e4];
        let (s, active) = m.return_stress(t);
        assert_eq!(active, ACTIVE_MAIN);
        let (p0, _) = p_sqrt_j2(t);
        let (p1, j1) = p_sqrt_j2(s);
        assert!((p1 - p0).abs() < 1e-9 && (j1 - (m.k - 3.0 * m.alpha * p1)).abs() < 1e-8);
        // Golden value: p = −50 kPa, sqrt J2 = k + 3α·5e4 = 8320.50 + 24019.23.
        assert!((j1 - 32_339.73).abs() < 0.01, "{j1}");
        assert!(m.yield_cone(s).abs() < ON_SURFACE * 5.0e4);
        // Past the apex (tension, a little deviatoric): the apex, where
        // the cap at its default t = k / (3α) meets the cone.
        let apex = m.k / (3.0 * m.alpha);
        let (s, active) = m.return_stress([3.0e4, 3.1e4, 2.9e4, 0.0]);
        assert_eq!(active, ACTIVE_MAIN | ACTIVE_T1);
        assert!(s[..3].iter().all(|x| (x - apex).abs() < 1e-9 * apex) && s[3] == 0.0);
        // A cap below the apex: p returns to t, s kept.
        let m = dp(0.0, Some(2.0e3));
        let t = [4.0e3, 2.0e3, 3.0e3, 500.0];
        let (s, active) = m.return_stress(t);
        assert_eq!(active, ACTIVE_T1);
        assert!((s[0] - 3.0e3).abs() < 1e-9 && (s[1] - 1.0e3).abs() < 1e-9 && s[3] == 500.0);
    }

    #[test]
    fn every_return_lands_on_the_surface() {
        let mut seed = 777u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let models = [dp(0.0, None), dp(30.0, None), dp(10.0, Some(5.0e3))];
        let mut seen = [false; 4];
        for m in &models {
            for k in 0..4000 {
                // Every other trial near the hydrostatic axis (the cap's region).
                let d = if k % 2 == 0 { 1.0 } else { 0.05 };
                let p = rnd() * 1e5;
                let t = [
                    p + d * rnd() * 1e5,
                    p + d * rnd() * 1e5,
                    p + d * rnd() * 1e5,
                    d * rnd() * 3e4,
                ];
                let (s, active) = m.return_stress(t);
                seen[(active & 1 | (active >> 2) & 2) as usize] = true;
                let p = ((t[0] + t[1] + t[2]) / 3.0).abs();
                let tol = ON_SURFACE * m.cohesion.max(p);
                let cap = m.tension.unwrap();
                let (ps, _) = p_sqrt_j2(s);
                assert!(m.yield_cone(s) <= tol && ps <= cap + tol, "{t:?} -> {s:?}");
                if active != 0 {
                    assert!(m.yield_cone(s).max(ps - cap) >= -tol, "{t:?} -> {s:?}");
                }
            }
        }
        assert_eq!(seen, [true; 4], "elastic, cone, cap, corner");
    }

    #[test]
    fn plastic_strain_follows_the_flow_rule() {
        let step = |m: &DruckerPrager| {
            let mut s = [-1.0e5, -1.0e5, 0.0];
            let mut q = [-1.0e5, 0.0, 0.0, 0.0];
            m.update([0.0, 1.0, 1.0, 0.0], 5e-3, &mut s, &mut q)
                .unwrap();
            q
        };
        let q = step(&dp(0.0, None));
        assert_eq!(q[RETURN], ACTIVE_MAIN as f64);
        assert!(
            q[EPS_EQ] > 1e-4 && q[EPS_VOL].abs() < 1e-12 * q[EPS_EQ],
            "{q:?}"
        );
        // ψ = φ: Δεp = Δγ (s / (2 sqrt J2) + ᾱ I): εp_v / ε̄p = 3ᾱ / sqrt(2/3 (1/2 + 3ᾱ²)).
        let m = dp(30.0, None);
        let q = step(&m);
        assert_eq!(q[RETURN], ACTIVE_MAIN as f64);
        let a = m.alpha_psi;
        let want = 3.0 * a / (2.0 / 3.0 * (0.5 + 3.0 * a * a)).sqrt();
        assert!((q[EPS_VOL] / q[EPS_EQ] - want).abs() < 1e-9, "{q:?} {want}");
    }
}
