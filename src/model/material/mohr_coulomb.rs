//! Elastic-perfectly plastic Mohr–Coulomb, plane strain, with a Rankine
//! tension cutoff. Tension-positive Cauchy stress; principal stresses
//! σ1 ≥ σ2 ≥ σ3 (σzz among them).
//!
//! - Yield: (σ1 − σ3) + (σ1 + σ3) sin φ − 2c cos φ ≤ 0, and σ1 ≤ t.
//! - Flow: the same planes with ψ for φ (non-associated when ψ < φ); the
//!   tension planes flow along their normal.
//! - Elastic trial on the Jaumann rate (`Elastic3::jaumann_trial`), then the
//!   closed-form return in principal stresses of de Souza Neto, Perić & Owen
//!   (2008, §8.2, box 8.1) for linear elasticity: the main plane, then the
//!   two edges, extended to the tension planes as a small active-set search
//!   (`return_principal`); the in-plane principal directions are kept.
//!
//! WGSL twin: `shaders/shared/material_mohr_coulomb.wgsl`.

use super::plastic::{self, ACTIVE_APEX, Elastic3, PlasticState};
use crate::model::fault::FaultKind;

/// A returned stress is accepted when every yield function, ordering and
/// −Δγ·2G is within this fraction of the stress scale (c + max |σ_trial|):
/// the return itself is exact up to f64 round-off (~1e-15 of the scale).
pub const RETURN_TOL_F64: f64 = 1e-11;

#[derive(Debug, Clone, PartialEq)]
pub struct MohrCoulomb {
    /// Young's modulus E (Pa).
    pub youngs: f64,
    /// Poisson's ratio ν.
    pub nu: f64,
    /// Initial density ρ0 (kg/m³).
    pub density: f64,
    pub elastic: Elastic3,
    /// Cohesion c (Pa).
    pub cohesion: f64,
    /// sin φ, cos φ of the friction angle.
    pub sin_phi: f64,
    pub cos_phi: f64,
    /// sin ψ of the dilation angle.
    pub sin_psi: f64,
    /// Tension cutoff t (Pa); `None` without one (φ = 0 and no key).
    pub tension: Option<f64>,
}

/// A linear surface in sorted principal space: a · σ ≤ k, flowing along n.
#[derive(Debug, Clone, Copy)]
struct Plane {
    a: [f64; 3],
    k: f64,
    n: [f64; 3],
}

/// The sets of active planes tried, in order (indices into `planes()`:
/// 0 main, 1 edge σ1 = σ2, 2 edge σ2 = σ3, 3–5 tension σ1, σ2, σ3), with
/// their bit mask. The first set whose return is admissible is taken.
pub const CANDIDATES: [(u32, [usize; 3], usize); 10] = [
    (plastic::ACTIVE_MAIN, [0, 0, 0], 1),
    (plastic::ACTIVE_T1, [3, 0, 0], 1),
    (plastic::ACTIVE_MAIN | plastic::ACTIVE_EDGE_12, [0, 1, 0], 2),
    (plastic::ACTIVE_MAIN | plastic::ACTIVE_EDGE_23, [0, 2, 0], 2),
    (plastic::ACTIVE_MAIN | plastic::ACTIVE_T1, [0, 3, 0], 2),
    (plastic::ACTIVE_T1 | plastic::ACTIVE_T2, [3, 4, 0], 2),
    (
        plastic::ACTIVE_MAIN | plastic::ACTIVE_EDGE_12 | plastic::ACTIVE_T1,
        [0, 1, 3],
        3,
    ),
    (
        plastic::ACTIVE_MAIN | plastic::ACTIVE_T1 | plastic::ACTIVE_T2,
        [0, 3, 4],
        3,
    ),
    (
        plastic::ACTIVE_MAIN | plastic::ACTIVE_EDGE_23 | plastic::ACTIVE_T1,
        [0, 2, 3],
        3,
    ),
    (ACTIVE_APEX, [3, 4, 5], 3),
];

impl MohrCoulomb {
    /// Angles in degrees; `tension` `None` means the apex c / tan φ (none
    /// when φ = 0); a cutoff above the apex is clamped to it.
    pub fn new(
        youngs: f64,
        nu: f64,
        density: f64,
        cohesion: f64,
        friction_deg: f64,
        dilation_deg: f64,
        tension: Option<f64>,
    ) -> Self {
        let (sin_phi, cos_phi) = friction_deg.to_radians().sin_cos();
        let apex = (sin_phi > 0.0).then(|| cohesion * cos_phi / sin_phi);
        let tension = match (tension, apex) {
            (Some(t), Some(a)) => Some(t.min(a)),
            (t, a) => t.or(a),
        };
        MohrCoulomb {
            youngs,
            nu,
            density,
            elastic: Elastic3::new(youngs, nu),
            cohesion,
            sin_phi,
            cos_phi,
            sin_psi: dilation_deg.to_radians().sin(),
            tension,
        }
    }

    fn planes(&self) -> [Plane; 6] {
        let (sf, sp) = (self.sin_phi, self.sin_psi);
        let k = 2.0 * self.cohesion * self.cos_phi;
        let t = self.tension.unwrap_or(f64::INFINITY);
        let unit = |i: usize| {
            let mut a = [0.0; 3];
            a[i] = 1.0;
            Plane { a, k: t, n: a }
        };
        [
            Plane {
                a: [1.0 + sf, 0.0, -(1.0 - sf)],
                k,
                n: [1.0 + sp, 0.0, -(1.0 - sp)],
            },
            Plane {
                a: [0.0, 1.0 + sf, -(1.0 - sf)],
                k,
                n: [0.0, 1.0 + sp, -(1.0 - sp)],
            },
            Plane {
                a: [1.0 + sf, -(1.0 - sf), 0.0],
                k,
                n: [1.0 + sp, -(1.0 - sp), 0.0],
            },
            unit(0),
            unit(1),
            unit(2),
        ]
    }

    /// The Mohr–Coulomb yield function at sorted principal stresses (Pa).
    pub fn yield_mc(&self, s: [f64; 3]) -> f64 {
        s[0] - s[2] + (s[0] + s[2]) * self.sin_phi - 2.0 * self.cohesion * self.cos_phi
    }

    /// D n in principal space: λ tr(n) 1 + 2G n.
    fn d_times(&self, n: [f64; 3]) -> [f64; 3] {
        let e = &self.elastic;
        let v = e.lame * (n[0] + n[1] + n[2]);
        [
            v + 2.0 * e.shear * n[0],
            v + 2.0 * e.shear * n[1],
            v + 2.0 * e.shear * n[2],
        ]
    }

    /// Return of sorted principal trial stresses `v` (σ1 ≥ σ2 ≥ σ3):
    /// the stress and the bit mask of the active surfaces (0: elastic,
    /// `v` unchanged). For each candidate set A the consistency conditions
    /// a_i · (v − Σ_j Δγ_j D n_j) = k_i (i, j ∈ A) are solved (≤ 3×3,
    /// Cramer); the first set with Δγ ≥ 0, every surface satisfied and the
    /// order σ1 ≥ σ2 ≥ σ3 kept is the return. The main plane, then the
    /// edges, are box 8.1 of de Souza Neto et al.; the apex of that box is
    /// the set of the three tension planes, as the default cutoff t is the
    /// apex. Should no set pass (round-off at a boundary), the one with
    /// the smallest violation is taken.
    // Index loops on purpose: they mirror mc_return in the WGSL twin.
    #[allow(clippy::needless_range_loop)]
    pub fn return_principal(&self, v: [f64; 3], tol_rel: f64) -> ([f64; 3], u32) {
        let planes = self.planes();
        let has_t = self.tension.is_some();
        let n_planes = if has_t { 6 } else { 3 };
        let f = |p: &Plane, s: [f64; 3]| p.a[0] * s[0] + p.a[1] * s[1] + p.a[2] * s[2] - p.k;
        if f(&planes[0], v) <= 0.0 && (!has_t || f(&planes[3], v) <= 0.0) {
            return (v, 0);
        }
        let scale = self.cohesion + v[0].abs().max(v[1].abs()).max(v[2].abs());
        let tol = tol_rel * scale;
        let mut best = (v, 0u32, f64::INFINITY);
        for (mask, idx, count) in CANDIDATES {
            if idx[..count].iter().any(|&i| i >= n_planes) {
                continue;
            }
            // M Δγ = f(v) with M_ij = a_i · D n_j; unused rows are identity.
            let mut m = [[0.0; 3]; 3];
            let mut rhs = [0.0; 3];
            let mut dn = [[0.0; 3]; 3];
            for r in 0..3 {
                if r < count {
                    dn[r] = self.d_times(planes[idx[r]].n);
                }
            }
            for r in 0..3 {
                if r < count {
                    let a = planes[idx[r]].a;
                    for c in 0..count {
                        m[r][c] = a[0] * dn[c][0] + a[1] * dn[c][1] + a[2] * dn[c][2];
                    }
                    rhs[r] = f(&planes[idx[r]], v);
                } else {
                    m[r][r] = 1.0;
                }
            }
            let Some(dg) = solve3(m, rhs) else {
                continue;
            };
            let mut s = v;
            for c in 0..count {
                for k in 0..3 {
                    s[k] -= dg[c] * dn[c][k];
                }
            }
            // One step of iterative refinement on the active surfaces (the
            // WGSL twin needs it in f32; kept here so the two stay alike).
            let mut res = [0.0; 3];
            for r in 0..count {
                res[r] = f(&planes[idx[r]], s);
            }
            let Some(ddg) = solve3(m, res) else {
                continue;
            };
            let mut dg = dg;
            for c in 0..count {
                dg[c] += ddg[c];
                for k in 0..3 {
                    s[k] -= ddg[c] * dn[c][k];
                }
            }
            let mut viol = (s[1] - s[0]).max(s[2] - s[1]);
            for c in 0..count {
                viol = viol.max(-dg[c] * 2.0 * self.elastic.shear);
            }
            for p in &planes[..n_planes] {
                viol = viol.max(f(p, s));
            }
            if viol <= tol {
                return (s, mask);
            }
            if viol < best.2 {
                best = (s, mask, viol);
            }
        }
        (best.0, best.1)
    }

    /// One step: Jaumann trial, principal return, rotation back. Updates
    /// the in-plane stress and the plastic state; returns V_new / V_old.
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
        let (s, active) = principal_return(t, tzz, |v| self.return_principal(v, RETURN_TOL_F64));
        plastic::record(q, e, trial, s, active);
        *stress = [s[0], s[1], s[3]];
        Ok(j)
    }
}


plastic::elastoplastic_constitutive!(
    MohrCoulomb,
    "mohr_coulomb",
    ["cohesion", "sin_phi", "cos_phi", "sin_psi", "tension"],
    // Tension cutoff −1 where there is none.
    |m| vec![
        m.cohesion as f32,
        m.sin_phi as f32,
        m.cos_phi as f32,
        m.sin_psi as f32,
        m.tension.map_or(-1.0, |t| t as f32),
    ]
);

/// In-plane principal decomposition of `t` with `tzz`, sorted, returned by
/// `ret`, and rotated back with the in-plane eigenvectors. Returns
/// [xx, yy, zz, xy] and the active mask. Shared by the plastic models that
/// return in principal space.
#[inline]
pub fn principal_return(
    t: [f64; 3],
    tzz: f64,
    ret: impl Fn([f64; 3]) -> ([f64; 3], u32),
) -> ([f64; 4], u32) {
    let c = 0.5 * (t[0] + t[1]);
    let hd = 0.5 * (t[0] - t[1]);
    let r = hd.hypot(t[2]);
    let (cos2, sin2) = if r > 0.0 {
        (hd / r, t[2] / r)
    } else {
        (1.0, 0.0)
    };
    // Values and where each came from (0: in-plane major, 1: minor, 2: zz).
    let mut v = [c + r, c - r, tzz];
    let mut idx = [0usize, 1, 2];
    for (i, j) in [(0, 1), (1, 2), (0, 1)] {
        if v[j] > v[i] {
            v.swap(i, j);
            idx.swap(i, j);
        }
    }
    let (s, active) = ret(v);
    if active == 0 {
        return ([t[0], t[1], tzz, t[2]], 0);
    }
    let mut out = [0.0; 3];
    for k in 0..3 {
        out[idx[k]] = s[k];
    }
    let (c2, r2) = (0.5 * (out[0] + out[1]), 0.5 * (out[0] - out[1]));
    ([c2 + r2 * cos2, c2 - r2 * cos2, out[2], r2 * sin2], active)
}

/// Solves the 3×3 system m x = b by Cramer's rule; `None` when singular.
pub fn solve3(m: [[f64; 3]; 3], b: [f64; 3]) -> Option<[f64; 3]> {
    let det = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(&m);
    if d == 0.0 || !d.is_finite() {
        return None;
    }
    let mut x = [0.0; 3];
    for (c, xc) in x.iter_mut().enumerate() {
        let mut mc = m;
        for r in 0..3 {
            mc[r][c] = b[r];
        }
        *xc = det(&mc) / d;
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::material::plastic::{
        ACTIVE_EDGE_12, ACTIVE_EDGE_23, ACTIVE_MAIN, ACTIVE_T1, EPS_EQ, EPS_VOL, RETURN,
    };

    /// E = 20 MPa, ν = 0.3, c = 10 kPa, φ = 30°: G = 7.6923 MPa,
    /// K = 16.667 MPa, apex c / tan φ = 17320.5 Pa.
    fn mc(psi: f64, t: Option<f64>) -> MohrCoulomb {
        MohrCoulomb::new(2.0e7, 0.3, 1800.0, 1.0e4, 30.0, psi, t)
    }

    /// |f| ≤ this · max(c, |p|) on a returned stress: the return is exact
    /// up to f64 round-off (~1e-15 of the stresses).
    const ON_SURFACE: f64 = 1e-8;

    fn violation(m: &MohrCoulomb, s: [f64; 3]) -> f64 {
        let t = m.tension.map_or(f64::NEG_INFINITY, |t| s[0] - t);
        m.yield_mc(s).max(t)
    }

    #[test]
    fn elastic_states_are_untouched() {
        let m = mc(0.0, None);
        let v = [-1.0e4, -2.0e4, -3.0e4];
        assert!(m.yield_mc(v) < 0.0);
        assert_eq!(m.return_principal(v, RETURN_TOL_F64), (v, 0));
        // Through `update`: the Jaumann trial itself, bit for bit.
        let (l, dt) = ([0.01, 0.02, -0.005, -0.03], 1e-3);
        let s0 = [-2.0e4, -2.5e4, 1.0e3];
        let mut q = [-1.5e4, 0.0, 0.0, 0.0];
        let mut s = s0;
        let j = m.update(l, dt, &mut s, &mut q).unwrap();
        let (t, tzz) = m.elastic.jaumann_trial(l, dt, &s0, -1.5e4);
        assert_eq!(s, t);
        assert_eq!(q, [tzz, 0.0, 0.0, 0.0]);
        assert_eq!(j, 1.0 + dt * (l[0] + l[3]));
    }

    #[test]
    fn main_plane_return_matches_the_closed_form() {
        // de Souza Neto et al. box 8.1 (H = 0): Δγ = Φ / a with
        // a = 4G(1 + sin φ sin ψ / 3) + 4K sin φ sin ψ, then
        // σ1 −= (2G(1 + sin ψ/3) + 2K sin ψ) Δγ, σ2 += (4G/3 − 2K) sin ψ Δγ,
        // σ3 += (2G(1 − sin ψ/3) − 2K sin ψ) Δγ.
        for psi in [0.0, 10.0, 30.0] {
            let m = mc(psi, None);
            let (g, k) = (m.elastic.shear, m.elastic.bulk);
            let (sf, sp) = (m.sin_phi, m.sin_psi);
            let v = [0.0, -5.0e4, -1.0e5];
            let phi = m.yield_mc(v);
            let dg = phi / (4.0 * g * (1.0 + sf * sp / 3.0) + 4.0 * k * sf * sp);
            let want = [
                v[0] - (2.0 * g * (1.0 + sp / 3.0) + 2.0 * k * sp) * dg,
                v[1] + (4.0 / 3.0 * g - 2.0 * k) * sp * dg,
                v[2] + (2.0 * g * (1.0 - sp / 3.0) - 2.0 * k * sp) * dg,
            ];
            let (s, active) = m.return_principal(v, RETURN_TOL_F64);
            assert_eq!(active, ACTIVE_MAIN, "ψ = {psi}");
            for i in 0..3 {
                assert!(
                    (s[i] - want[i]).abs() < 1e-9 * 1e5,
                    "ψ = {psi}: {s:?} vs {want:?}"
                );
            }
            assert!(m.yield_mc(s).abs() <= ON_SURFACE * 1e4, "{}", m.yield_mc(s));
        }
        // Golden values (ψ = 0): Φ = 32679.49 Pa, Δγ = Φ / 4G = 1.062083e-3,
        // σ1 = −2GΔγ, σ3 = −1e5 + 2GΔγ, σ2 unchanged.
        let (s, _) = mc(0.0, None).return_principal([0.0, -5.0e4, -1.0e5], RETURN_TOL_F64);
        let golden = [-16_339.746, -50_000.0, -83_660.254];
        for i in 0..3 {
            assert!((s[i] - golden[i]).abs() < 1e-3, "{s:?}");
        }
    }

    #[test]
    fn edges_and_apex_are_reached_from_their_regions() {
        let m = mc(0.0, None);
        // σ1 = σ2: the main-plane return would put σ1 below σ2.
        let (s, active) = m.return_principal([0.0, 0.0, -1.0e5], RETURN_TOL_F64);
        assert_eq!(active, ACTIVE_MAIN | ACTIVE_EDGE_12, "{s:?}");
        assert!((s[0] - s[1]).abs() < 1e-9 * 1e5 && m.yield_mc(s).abs() < ON_SURFACE * 1e5);
        // σ2 = σ3: it would put σ3 above σ2.
        let (s, active) = m.return_principal([0.0, -1.0e5, -1.0e5], RETURN_TOL_F64);
        assert_eq!(active, ACTIVE_MAIN | ACTIVE_EDGE_23, "{s:?}");
        assert!((s[1] - s[2]).abs() < 1e-9 * 1e5 && m.yield_mc(s).abs() < ON_SURFACE * 1e5);
        // ψ = 0: the flow is deviatoric, so the mean stress is kept.
        let p = (s[0] + s[1] + s[2]) / 3.0;
        assert!((p + 200_000.0 / 3.0).abs() < 1e-6, "p = {p}");
        // Hydrostatic tension past the apex: the apex.
        let apex = 1.0e4 / 30f64.to_radians().tan();
        let (s, active) = m.return_principal([3.0e4, 3.0e4, 3.0e4], RETURN_TOL_F64);
        assert_eq!(active, ACTIVE_APEX, "{s:?}");
        assert!(s.iter().all(|x| (x - apex).abs() < 1e-9 * apex), "{s:?}");
        // Tension cutoff below the apex: σ1 returns to t alone, σ2, σ3
        // follow by −λΔγ, Δγ = (σ1 − t)/(λ + 2G).
        let m = mc(0.0, Some(5.0e3));
        let v = [8.0e3, 0.0, -1.0e3];
        assert!(m.yield_mc(v) < 0.0);
        let (s, active) = m.return_principal(v, RETURN_TOL_F64);
        assert_eq!(active, ACTIVE_T1);
        let dg = 3.0e3 / (m.elastic.lame + 2.0 * m.elastic.shear);
        let want = [5.0e3, -m.elastic.lame * dg, -1.0e3 - m.elastic.lame * dg];
        for i in 0..3 {
            assert!((s[i] - want[i]).abs() < 1e-9, "{s:?} vs {want:?}");
        }
    }

    #[test]
    fn every_return_lands_on_the_surface() {
        // Pseudo-random trials over all regions (tension and compression,
        // with and without a cutoff below the apex, φ = 0 included).
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let models = [
            mc(0.0, None),
            mc(30.0, None),
            mc(10.0, Some(4.0e3)),
            MohrCoulomb::new(2.0e7, 0.3, 1800.0, 1.0e4, 0.0, 0.0, None),
            MohrCoulomb::new(2.0e7, 0.3, 1800.0, 1.0e4, 0.0, 0.0, Some(2.0e3)),
            MohrCoulomb::new(2.0e7, 0.3, 1800.0, 0.0, 35.0, 5.0, None),
        ];
        let mut counts = std::collections::BTreeMap::new();
        for m in &models {
            for _ in 0..4000 {
                let mut v = [rnd() * 1.0e5, rnd() * 1.0e5, rnd() * 1.0e5];
                v.sort_by(|a, b| b.total_cmp(a));
                let (s, active) = m.return_principal(v, RETURN_TOL_F64);
                *counts.entry(active).or_insert(0) += 1;
                let p = (v[0] + v[1] + v[2]).abs() / 3.0;
                let tol = ON_SURFACE * m.cohesion.max(p);
                assert!(violation(m, s) <= tol, "{m:?} {v:?} -> {s:?} ({active})");
                assert!(s[0] >= s[1] - tol && s[1] >= s[2] - tol, "{v:?} -> {s:?}");
                if active != 0 {
                    // On the surface, not inside it.
                    assert!(violation(m, s) >= -tol, "{v:?} -> {s:?} ({active})");
                }
            }
        }
        // Every kind of return occurred.
        for mask in [0, 1, 3, 5, 8, 9, 24, ACTIVE_APEX] {
            assert!(counts.contains_key(&mask), "no return {mask}: {counts:?}");
        }
    }

    #[test]
    fn plastic_strain_follows_the_flow_rule() {
        // A large shear step (Δεxy = 5e-3) from an isotropic state at
        // −100 kPa: trial σ1 = −23 kPa, σ3 = −177 kPa, σzz between.
        let step = |m: &MohrCoulomb| {
            let mut s = [-1.0e5, -1.0e5, 0.0];
            let mut q = [-1.0e5, 0.0, 0.0, 0.0];
            m.update([0.0, 1.0, 1.0, 0.0], 5e-3, &mut s, &mut q)
                .unwrap();
            q
        };
        // ψ = 0: no plastic volume change.
        let q = step(&mc(0.0, None));
        assert_eq!(q[RETURN], ACTIVE_MAIN as f64);
        assert!(
            q[EPS_EQ] > 1e-4 && q[EPS_VOL].abs() < 1e-12 * q[EPS_EQ],
            "{q:?}"
        );
        // ψ = φ (associated): Δεp = Δγ (1 + sin φ, 0, −(1 − sin φ)), so
        // εp_v / ε̄p = 2 sin φ / sqrt(4/3 (1 + sin² φ)): dilation.
        let q = step(&mc(30.0, None));
        assert_eq!(q[RETURN], ACTIVE_MAIN as f64);
        let s: f64 = 0.5;
        let want = 2.0 * s / (4.0 / 3.0 * (1.0 + s * s)).sqrt();
        assert!(
            (q[EPS_VOL] / q[EPS_EQ] - want).abs() < 1e-9,
            "{} vs {want}",
            q[EPS_VOL] / q[EPS_EQ]
        );
    }
}
