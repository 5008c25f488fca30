//! GMM's meshfree bases over a material point's node cloud (implicit-MPM
//! paper §4.2.2): both give N_I and ∇N_I at x from the nodes gathered
//! within the search radius, and both reproduce constants and linear
//! fields (values and gradients).
//!
//! - LME (eq. 61): p_a ∝ exp(−β|x − x_a|² + λ·(x − x_a)), β = γ/h², h the
//!   initial node spacing; λ by the grid LME's own damped Newton
//!   (`model::shape::lme::Lme::newton`, shared), warm-started from the
//!   point's last λ, to a tighter tolerance than the grid's
//!   (`LME_TOL`). The cloud is cut at the search radius, as the paper's.
//! - MLS (eqs. 50–58): linear basis p = [1, (y − x)/h] centred on the
//!   evaluation point x and scaled by h, weight w_I = W(|x − x_I| / (2 f h))
//!   with W the cubic spline (support 1), f the dilation:
//!   N_I = cᵀ p_I w_I,  c = A⁻¹ e₀,  A = Σ_J w_J p_J p_Jᵀ, and
//!   ∂_k N_I = (g_k − q_k)ᵀ p_I w_I + cᵀ p_I ∂_k w_I, with
//!   g_k = A⁻¹ e_{k+1} / h (the basis's own slope), q_k = A⁻¹ (∂_k A) c,
//!   ∂_k A = Σ_J ∂_k w_J p_J p_Jᵀ (the basis centre held at x while
//!   differentiating, which is exact: N_I does not depend on the centre).

use crate::model::GmmSettings;
use crate::model::shape::ShapeFault;
use crate::model::shape::lme::{Lme, NEWTON_MAX_ITER};
use crate::scene::GmmBasis;

/// GMM-LME's λ tolerance relative to h: |Σ N_a x_a − x| ≤ LME_TOL · h.
/// The grid's 1e-10 would leave the linear reproduction at that level;
/// the cloud's nodes move with this error, so it is taken near round-off
/// (the quadratic Newton reaches it in one more step).
pub const LME_TOL: f64 = 1e-13;

/// Relative size below which the MLS moment matrix counts as singular:
/// det A against the product of its diagonal.
const MLS_SINGULAR: f64 = 1e-12;

/// A basis over node clouds.
#[derive(Debug, Clone)]
pub enum Basis {
    Lme(Lme),
    Mls {
        /// Support radius of the weight, 2 f h (m).
        support: f64,
        /// The basis's scale h (m).
        h: f64,
    },
}

impl Basis {
    /// The basis of `s` for initial node spacing `h` (m).
    pub fn new(s: &GmmSettings, h: f64) -> Basis {
        match s.basis {
            GmmBasis::Lme => Basis::Lme(Lme {
                gamma: s.gamma,
                beta: s.gamma / (h * h),
                radius: s.search_radius * h,
                h,
                search_extra: 0.0,
                tol: LME_TOL * h,
                max_iter: NEWTON_MAX_ITER,
            }),
            GmmBasis::Mls => Basis::Mls {
                support: 2.0 * s.dilation * h,
                h,
            },
        }
    }

    /// N and ∇N at `x` over the nodes `cloud` (positions `xn`): writes
    /// `w[k] = [N, ∂N/∂x, ∂N/∂y]` for `nodes[k]` and keeps only nodes of
    /// non-zero weight (MLS drops those beyond its support). Returns the
    /// nodes kept. `lambda` is LME's warm start and receives its solution.
    pub fn eval(
        &self,
        x: [f64; 2],
        xn: &[[f64; 2]],
        nodes: &mut [u32],
        count: usize,
        lambda: &mut [f64; 2],
        w: &mut [[f64; 3]],
    ) -> Result<usize, ShapeFault> {
        match self {
            Basis::Lme(lme) => {
                if count < 3 {
                    return Err(ShapeFault::LmeTooFewNodes { nodes: Some(count) });
                }
                for k in 0..count {
                    let xa = xn[nodes[k] as usize];
                    w[k] = [0.0, x[0] - xa[0], x[1] - xa[1]];
                }
                lme.newton(&mut w[..count], lambda)?;
                Ok(count)
            }
            Basis::Mls { support, h } => mls(x, xn, nodes, count, *support, *h, w),
        }
    }
}

/// The cubic spline W(s) (support 1, W(0) = 2/3) and dW/ds.
#[inline]
fn spline(s: f64) -> (f64, f64) {
    if s <= 0.5 {
        (
            2.0 / 3.0 - 4.0 * s * s + 4.0 * s * s * s,
            -8.0 * s + 12.0 * s * s,
        )
    } else if s < 1.0 {
        let t = 1.0 - s;
        (4.0 / 3.0 * t * t * t, -4.0 * t * t)
    } else {
        (0.0, 0.0)
    }
}

/// Inverse of the symmetric 3 × 3 [a00, a01, a02, a11, a12, a22], or None
/// when singular relative to its diagonal.
fn inverse3(a: &[f64; 6]) -> Option<[[f64; 3]; 3]> {
    let [a00, a01, a02, a11, a12, a22] = *a;
    let c00 = a11 * a22 - a12 * a12;
    let c01 = a02 * a12 - a01 * a22;
    let c02 = a01 * a12 - a02 * a11;
    let c11 = a00 * a22 - a02 * a02;
    let c12 = a01 * a02 - a00 * a12;
    let c22 = a00 * a11 - a01 * a01;
    let det = a00 * c00 + a01 * c01 + a02 * c02;
    let scale = (a00 * a11 * a22).abs();
    // Also refuses NaN.
    if det.abs().partial_cmp(&(MLS_SINGULAR * scale)) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let d = 1.0 / det;
    Some([
        [c00 * d, c01 * d, c02 * d],
        [c01 * d, c11 * d, c12 * d],
        [c02 * d, c12 * d, c22 * d],
    ])
}

#[inline]
fn mat_vec(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
}

#[inline]
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// MLS with the linear basis (module header): compacts `nodes` to those
/// of positive weight.
fn mls(
    x: [f64; 2],
    xn: &[[f64; 2]],
    nodes: &mut [u32],
    count: usize,
    support: f64,
    h: f64,
    w: &mut [[f64; 3]],
) -> Result<usize, ShapeFault> {
    // (w, ∂w/∂x, ∂w/∂y) per kept node into `w`, kept nodes compacted.
    let mut kept = 0;
    let p_of = |xa: [f64; 2]| [1.0, (xa[0] - x[0]) / h, (xa[1] - x[1]) / h];
    let (mut a, mut dax, mut day) = ([0.0f64; 6], [0.0f64; 6], [0.0f64; 6]);
    for k in 0..count {
        let xa = xn[nodes[k] as usize];
        let d = [x[0] - xa[0], x[1] - xa[1]];
        let r = d[0].hypot(d[1]);
        let (wv, dw) = spline(r / support);
        if wv <= 0.0 {
            continue;
        }
        // ∂w/∂x = W'(s) (x − x_I) / (r · support); W'(0) = 0.
        let g = if r > 0.0 { dw / (r * support) } else { 0.0 };
        let wk = [wv, g * d[0], g * d[1]];
        let pk = p_of(xa);
        let outer = [
            pk[0] * pk[0],
            pk[0] * pk[1],
            pk[0] * pk[2],
            pk[1] * pk[1],
            pk[1] * pk[2],
            pk[2] * pk[2],
        ];
        for m in 0..6 {
            a[m] += wk[0] * outer[m];
            dax[m] += wk[1] * outer[m];
            day[m] += wk[2] * outer[m];
        }
        nodes[kept] = nodes[k];
        w[kept] = wk;
        kept += 1;
    }
    let inv = inverse3(&a).ok_or(ShapeFault::MlsSingular { nodes: kept })?;
    let c = [inv[0][0], inv[1][0], inv[2][0]];
    let full = |s: &[f64; 6]| [[s[0], s[1], s[2]], [s[1], s[3], s[4]], [s[2], s[4], s[5]]];
    let q = [
        mat_vec(&inv, mat_vec(&full(&dax), c)),
        mat_vec(&inv, mat_vec(&full(&day), c)),
    ];
    let g = [
        [inv[0][1] / h, inv[1][1] / h, inv[2][1] / h],
        [inv[0][2] / h, inv[1][2] / h, inv[2][2] / h],
    ];
    for (wk, &n) in w[..kept].iter_mut().zip(nodes.iter()) {
        let pk = &p_of(xn[n as usize]);
        let cp = dot(c, *pk);
        let n = cp * wk[0];
        let dn: [f64; 2] = std::array::from_fn(|k| {
            let gq = [g[k][0] - q[k][0], g[k][1] - q[k][1], g[k][2] - q[k][2]];
            dot(gq, *pk) * wk[0] + cp * wk[1 + k]
        });
        *wk = [n, dn[0], dn[1]];
    }
    Ok(kept)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gmm::Cloud;
    use crate::rng::SplitMix64;

    /// Reproduction of 1 and x, values and gradients, to this (relative to
    /// h for positions; the bound).
    const REPRODUCTION: f64 = 1e-12;
    /// Central-difference check of ∇N (step 1e-6 h, error O(step²) plus
    /// round-off 1e-16 / 1e-6).
    const FD_REL: f64 = 1e-7;

    /// A scattered cloud: a lattice of spacing h with every node moved by
    /// up to 0.3 h per coordinate, and evaluation points inside it.
    fn scattered(h: f64) -> (Cloud, Vec<[f64; 2]>) {
        let mut rng = SplitMix64::new(11);
        let mut x = Vec::new();
        for j in 0..12 {
            for i in 0..12 {
                x.push([
                    (i as f64 + rng.range(-0.3, 0.3)) * h + 1.7,
                    (j as f64 + rng.range(-0.3, 0.3)) * h - 0.4,
                ]);
            }
        }
        let pts = (0..200)
            .map(|_| [rng.range(3.0, 8.0) * h + 1.7, rng.range(3.0, 8.0) * h - 0.4])
            .collect();
        (Cloud::from_points(h, x), pts)
    }

    fn settings(basis: GmmBasis) -> GmmSettings {
        GmmSettings {
            basis,
            gamma: 1.8,
            search_radius: 2.0,
            dilation: 1.0,
        }
    }

    /// N, ∇N at `x` over the cloud gathered within the search radius.
    fn at(
        b: &Basis,
        c: &Cloud,
        r: f64,
        x: [f64; 2],
        lambda: &mut [f64; 2],
    ) -> (Vec<u32>, Vec<[f64; 3]>) {
        let mut list = Vec::new();
        c.gather(x, r, &mut list);
        let mut w = vec![[0.0; 3]; list.len()];
        let n = list.len();
        let kept = b.eval(x, &c.x, &mut list, n, lambda, &mut w).unwrap();
        list.truncate(kept);
        w.truncate(kept);
        (list, w)
    }

    #[test]
    fn both_bases_reproduce_linear_fields_on_a_scattered_cloud() {
        for h in [1.0, 0.01] {
            let (mut c, pts) = scattered(h);
            for basis in [GmmBasis::Lme, GmmBasis::Mls] {
                let s = settings(basis);
                let b = Basis::new(&s, h);
                let r = s.search_radius * h;
                c.rebuild(r);
                let mut worst = [0.0f64; 4];
                for &x in &pts {
                    let (list, w) = at(&b, &c, r, x, &mut [0.0; 2]);
                    let (mut s0, mut s1, mut g0, mut g1) = (0.0, [0.0; 2], [0.0; 2], [0.0; 4]);
                    for (&n, wk) in list.iter().zip(&w) {
                        let xa = c.x[n as usize];
                        s0 += wk[0];
                        for d in 0..2 {
                            s1[d] += wk[0] * xa[d];
                            g0[d] += wk[1 + d];
                            // Positions about x: Σ x_a ⊗ ∇N_a itself also
                            // carries x ⊗ Σ ∇N_a, which is checked alone
                            // (g0) and would otherwise grow with |x| / h.
                            for e in 0..2 {
                                g1[2 * d + e] += (xa[d] - x[d]) * wk[1 + e];
                            }
                        }
                    }
                    worst[0] = worst[0].max((s0 - 1.0).abs());
                    worst[1] = worst[1].max((s1[0] - x[0]).abs().max((s1[1] - x[1]).abs()) / h);
                    worst[2] = worst[2].max(g0[0].abs().max(g0[1].abs()) * h);
                    let eye = [1.0, 0.0, 0.0, 1.0];
                    for k in 0..4 {
                        worst[3] = worst[3].max((g1[k] - eye[k]).abs());
                    }
                }
                println!(
                    "{basis:?} h = {h}: |ΣN − 1|, |ΣN x − x|/h, |Σ∇N| h, |Σ (x_a − x) ⊗ ∇N − I| = {worst:?}"
                );
                for e in worst {
                    assert!(e < REPRODUCTION, "{basis:?} h = {h}: {worst:?}");
                }
            }
        }
    }

    #[test]
    fn gradients_are_the_derivatives_of_the_values() {
        let h = 0.05;
        let (mut c, pts) = scattered(h);
        for basis in [GmmBasis::Lme, GmmBasis::Mls] {
            let s = settings(basis);
            let b = Basis::new(&s, h);
            let r = s.search_radius * h;
            c.rebuild(r);
            let eps = 1e-6 * h;
            for &x in pts.iter().take(40) {
                let mut lam = [0.0; 2];
                let (list, w) = at(&b, &c, r, x, &mut lam);
                // The same nodes at the shifted points (a node crossing the
                // radius would be a jump, not a derivative).
                let eval = |y: [f64; 2]| {
                    let mut l = list.clone();
                    let mut wy = vec![[0.0; 3]; l.len()];
                    let n = l.len();
                    let mut lam2 = lam;
                    let k = b.eval(y, &c.x, &mut l, n, &mut lam2, &mut wy).unwrap();
                    (l[..k].to_vec(), wy[..k].to_vec())
                };
                let scale = w
                    .iter()
                    .fold(0.0f64, |m, wk| m.max(wk[1].abs()).max(wk[2].abs()));
                for d in 0..2 {
                    let mut yp = x;
                    let mut ym = x;
                    yp[d] += eps;
                    ym[d] -= eps;
                    let (lp, wp) = eval(yp);
                    let (lm, wm) = eval(ym);
                    for (k, &n) in list.iter().enumerate() {
                        let val = |l: &[u32], ww: &[[f64; 3]]| {
                            l.iter().position(|&m| m == n).map_or(0.0, |i| ww[i][0])
                        };
                        let fd = (val(&lp, &wp) - val(&lm, &wm)) / (2.0 * eps);
                        let err = (fd - w[k][1 + d]).abs() / scale;
                        assert!(err < FD_REL, "{basis:?} at {x:?} node {n} d {d}: {err:e}");
                    }
                }
            }
        }
    }
}
