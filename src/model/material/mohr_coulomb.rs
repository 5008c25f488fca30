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
        [v + 2.0 * e.shear * n[0], v + 2.0 * e.shear * n[1], v + 2.0 * e.shear * n[2]]
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
    let (cos2, sin2) = if r > 0.0 { (hd / r, t[2] / r) } else { (1.0, 0.0) };
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
