//! Drained compression of a modified Cam-clay sample towards the critical
//! state (`critical_state`): sheared at constant confining pressure, the
//! clay's stress ratio q/p′ rises towards the critical state line
//! q = M p′, reached at large strain (in plane strain near 100 % axial
//! strain for the case's normally consolidated clay; docs/methods.md,
//! "Modified Cam-clay"). The figures are the sample's mean p′ and q
//! (volume-weighted, σzz from the plastic state), their ratio, and the
//! axial strain: the change of the particles' height span over the first.

use crate::model::Particles;
use crate::scene::Scene;
use serde::Serialize;

/// Figures for `summary.json`.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct CriticalStateErrors {
    /// Mean effective pressure p′ = −(σxx + σyy + σzz)/3 (Pa).
    pub p: f64,
    /// Mean deviatoric stress q = sqrt(3 J2) (Pa).
    pub q: f64,
    /// q / p′.
    pub stress_ratio: f64,
    /// The critical state's M.
    pub m: f64,
    /// stress_ratio / M.
    pub ratio_over_m: f64,
    /// Axial (vertical) strain, compression positive.
    pub axial_strain: f64,
}

/// p′ and q of a particle's in-plane stress with its σzz (Pa).
pub fn p_q(s: [f64; 3], szz: f64) -> (f64, f64) {
    let p = -(s[0] + s[1] + szz) / 3.0;
    let (dx, dy, dz) = (s[0] + p, s[1] + p, szz + p);
    let j2 = 0.5 * (dx * dx + dy * dy + dz * dz) + s[2] * s[2];
    (p, (3.0 * j2).sqrt())
}

/// The critical state's M of the scene's first modified Cam-clay material.
pub fn m_of(scene: &Scene) -> f64 {
    scene
        .materials()
        .find(|(_, m)| m.model == "modified_cam_clay")
        .and_then(|(_, m)| m.get("M"))
        .unwrap_or(f64::NAN)
}

pub fn score(scene: &Scene, p: &Particles) -> CriticalStateErrors {
    let (mut sp, mut sq, mut sv) = (0.0, 0.0, 0.0);
    for i in 0..p.len() {
        let szz = p.plastic.get(i).map_or(0.0, |q| q[0]);
        let (pp, qq) = p_q(p.stress[i], szz);
        let v = p.mass[i] / p.rho[i];
        sp += v * pp;
        sq += v * qq;
        sv += v;
    }
    let sv = sv.max(f64::MIN_POSITIVE);
    let (pm, qm) = (sp / sv, sq / sv);
    let span = |f: &dyn Fn(usize) -> f64| {
        let (lo, hi) = (0..p.len()).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), i| {
            (a.min(f(i)), b.max(f(i)))
        });
        hi - lo
    };
    let h0 = span(&|i| p.x0[i][1]);
    let h = span(&|i| p.x[i][1]);
    let m = m_of(scene);
    let ratio = qm / pm;
    CriticalStateErrors {
        p: pm,
        q: qm,
        stress_ratio: ratio,
        m,
        ratio_over_m: ratio / m,
        axial_strain: if h0 > 0.0 { 1.0 - h / h0 } else { 0.0 },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn isotropic_stress_has_no_deviator_and_a_triaxial_one_has_its_difference() {
        let (p, q) = p_q([-1e5, -1e5, 0.0], -1e5);
        assert!((p - 1e5).abs() < 1e-9 && q.abs() < 1e-9);
        // σ1 = −3e5, σ2 = σ3 = −1e5: q = σ1 − σ3 = 2e5, p = 5e5/3.
        let (p, q) = p_q([-1e5, -3e5, 0.0], -1e5);
        assert!((p - 5e5 / 3.0).abs() < 1e-6 && (q - 2e5).abs() < 1e-6);
    }
}
