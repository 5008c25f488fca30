//! Pass `contact_detect` of the contact between bodies (`contact_grad`
//! has the overview), before `predict`: per pair and node where both
//! fields have mass, the gap between the two bodies' particle domains that
//! reach the node (round, radius ½ sqrt(V_p)): the pair is in contact at
//! the node when the domains meet (gap ≤ a round-off slack), not a cell
//! early; there the normal n (from the first body towards the second) is
//! the line that separates the two bodies' particles reaching the node
//! (Nairn et al.'s logistic regression, `lr_normal`), or, where no line
//! separates them, the mass gradient of the body with the larger volume.
//! GPU twin: `shaders/contact_detect.wgsl`.

use super::stage_inputs::ShapeCache;
use crate::model::Contacts;
use crate::model::walls::CONTACT_SLIP;

/// Slack of the gap test relative to the particles' half-width: domains
/// seeded flush against each other touch whatever the round-off.
pub const CONTACT_GAP_SLACK: f64 = 1e-3;

/// What `detect` found, per pair and grid node (`pair · n_nodes + node`).
#[derive(Debug, Clone, Default)]
pub struct ContactState {
    /// Per field node: Σ_p m_p ∇N_I(x_p) (points out of the field's
    /// body) and the volume Σ_p N_I(x_p) V_p (m²).
    pub grad: Vec<[f64; 3]>,
    /// Per pair node: the unit normal from the first body to the second
    /// (zero where the pair is not in contact).
    pub normal: Vec<[f64; 2]>,
    /// Per pair node: the gap between the two bodies' particle domains
    /// there (m; negative where they overlap).
    pub gap: Vec<f64>,
    /// Per field node: some pair of the field with a tangential force
    /// (stick, friction) is in contact there (the nodes whose particles
    /// take `CONTACT_PIC_FRACTION` in g2p).
    pub touched: Vec<bool>,
    /// Per particle: m_p times the change the interface's PIC share made
    /// to its velocity in g2p (zero elsewhere), summed by
    /// `contact_conserve::conserve`.
    pub pic_dp: Vec<[f64; 2]>,
    /// Scratch per field: [mass, Σ pic_dp] (`contact_conserve`).
    pub field_dp: Vec<[f64; 3]>,
    /// Scratch: (pair node, side, particle) of the particles reaching a
    /// node where the pair has a normal.
    members: Vec<(u32, u8, u32)>,
}

impl ContactState {
    pub fn new(c: &Contacts, n_nodes: usize, n_particles: usize) -> Self {
        ContactState {
            grad: vec![[0.0; 3]; c.n_fields * n_nodes],
            normal: vec![[0.0; 2]; c.pairs.len() * n_nodes],
            gap: vec![f64::INFINITY; c.pairs.len() * n_nodes],
            touched: vec![false; c.n_fields * n_nodes],
            pic_dp: vec![[0.0; 2]; n_particles],
            field_dp: vec![[0.0; 3]; c.n_fields],
            members: Vec::new(),
        }
    }

    /// Whether pair `k` is in contact at grid node `i`.
    #[inline]
    pub fn touching(&self, k: usize, n_nodes: usize, i: usize) -> bool {
        let n = self.normal[k * n_nodes + i];
        n != [0.0, 0.0]
    }
}

/// Half-width of particle p's square domain (m): ½ sqrt(m_p / ρ_p).
#[inline]
fn half_width(mass: f64, rho: f64) -> f64 {
    0.5 * (mass / rho).sqrt()
}

/// Finds, per pair and node, the normal and whether the pair's particle
/// domains meet there (`ContactState`), from the mass gradients `grad`
/// left. `mv` holds the scattered masses.
#[allow(clippy::too_many_arguments)]
pub fn detect(
    cache: &ShapeCache,
    x: &[[f64; 2]],
    mass: &[f64],
    rho: &[f64],
    body: &[u32],
    c: &Contacts,
    mv: &[[f64; 3]],
    n_nodes: usize,
    mass_eps: f64,
    st: &mut ContactState,
) {
    // Normals where both fields of a pair have mass.
    for (k, pair) in c.pairs.iter().enumerate() {
        let [a, b] = pair.fields.map(|f| f as usize * n_nodes);
        for i in 0..n_nodes {
            let o = k * n_nodes + i;
            st.normal[o] = [0.0; 2];
            st.gap[o] = f64::INFINITY;
            if mv[a + i][0] <= mass_eps || mv[b + i][0] <= mass_eps {
                continue;
            }
            // ∇m_a points out of a, −∇m_b into b: both from a towards b.
            let (ga, gb) = (st.grad[a + i], st.grad[b + i]);
            // The normal of the body with the larger volume at the node
            // (Nairn's "max volume" choice): the other body's gradient is
            // a poor normal where it has little material, at its corners.
            let d = if st.grad[a + i][2] >= st.grad[b + i][2] {
                [ga[0], ga[1]]
            } else {
                [-gb[0], -gb[1]]
            };
            let len = d[0].hypot(d[1]);
            if len > 0.0 {
                st.normal[o] = [d[0] / len, d[1] / len];
            }
        }
    }
    // The particles of each side of a pair that reach each node where
    // the pair has a normal, grouped by node.
    st.members.clear();
    for (p, &bp) in body.iter().enumerate() {
        let f = c.field_of_body[bp as usize];
        if f == 0 {
            continue;
        }
        let (nodes, w) = cache.particle(p);
        for (k, pair) in c.pairs.iter().enumerate() {
            let side = if pair.fields[0] == f {
                0
            } else if pair.fields[1] == f {
                1
            } else {
                continue;
            };
            for (&node, wk) in nodes.iter().zip(w) {
                let o = k * n_nodes + node as usize % n_nodes;
                if wk[0] > 0.0 && st.normal[o] != [0.0, 0.0] {
                    st.members.push((o as u32, side, p as u32));
                }
            }
        }
    }
    st.members.sort_unstable();
    // The gap at a node: the least distance between the round domains
    // (radius l_p) of the two sides' particles there. Distances, not
    // reaches along n: two convex bodies apart have a smaller extent along
    // a tilted normal than their true gap, which would start contact early.
    let slack = CONTACT_GAP_SLACK
        * mass
            .iter()
            .zip(rho)
            .map(|(m, r)| half_width(*m, *r))
            .fold(f64::INFINITY, f64::min);
    let m = &st.members;
    let mut start = 0;
    while start < m.len() {
        let o = m[start].0;
        let end = start + m[start..].iter().take_while(|e| e.0 == o).count();
        let split = start + m[start..end].iter().take_while(|e| e.1 == 0).count();
        let (side_a, side_b) = (&m[start..split], &m[split..end]);
        let mut gap = f64::INFINITY;
        for &(_, _, p) in side_a {
            let (p, lp) = (p as usize, half_width(mass[p as usize], rho[p as usize]));
            for &(_, _, q) in side_b {
                let q = q as usize;
                let d = (x[p][0] - x[q][0]).hypot(x[p][1] - x[q][1]);
                gap = gap.min(d - lp - half_width(mass[q], rho[q]));
            }
        }
        st.gap[o as usize] = gap;
        if gap <= slack {
            let n0 = st.normal[o as usize];
            st.normal[o as usize] = lr_normal(side_a, side_b, x, mass, rho, n0);
        }
        start = end;
    }
    // In contact where the domains meet.
    for (n, g) in st.normal.iter_mut().zip(&st.gap) {
        if *n != [0.0, 0.0] && *g > slack {
            *n = [0.0; 2];
        }
    }
    // Where a pair with a tangential force (stick, friction) touches: a
    // frictionless pair has no cap to chatter against.
    st.touched.fill(false);
    for (k, pair) in c.pairs.iter().enumerate() {
        if pair.law == CONTACT_SLIP {
            continue;
        }
        for i in 0..n_nodes {
            if st.touching(k, n_nodes, i) {
                for f in pair.fields {
                    st.touched[f as usize * n_nodes + i] = true;
                }
            }
        }
    }
}

/// Solves the 3 × 3 system a s = r by Cramer's rule (None if singular).
fn solve3(a: [[f64; 3]; 3], r: [f64; 3]) -> Option<[f64; 3]> {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(a);
    if d.abs() < 1e-300 || !d.is_finite() {
        return None;
    }
    let mut s = [0.0; 3];
    for (c, sc) in s.iter_mut().enumerate() {
        let mut m = a;
        for i in 0..3 {
            m[i][c] = r[i];
        }
        *sc = det(m) / d;
    }
    Some(s)
}

/// The logistic regression's ridge, relative to the particles' total
/// weight: small enough that the fit tends to the widest separating line
/// (a block's flat face stays flat at its ends: −0.06 % at 0.5 s on the
/// slab, against −6.5 % at 1e-4 and −25 % at 1e-1), large enough that
/// Newton's system stays regular in f32 on the GPU.
pub const LR_RIDGE: f64 = 1e-9;
/// Newton iterations of the logistic regression (fixed, so the CPU and the
/// GPU take the same steps); the scale |φ| grows by about one per step on
/// separable particles, the direction settles within a few.
pub const LR_ITERATIONS: usize = 10;
/// The longest Newton step |Δφ| of the fit (per half-width): Newton on a
/// logistic fit is unsafe far from the optimum (where the particles'
/// weights saturate its Hessian vanishes and the step explodes); capped,
/// the fit starts from φ = 0 and, on separable particles, grows |φ| by at
/// most this much per step.
pub const LR_MAX_STEP: f64 = 4.0;
/// Where the fitted line's normal lies within 3° of the larger volume's
/// gradient normal (its cosine), the gradient is kept: that body's face is
/// flat there, where its mass gradient has no tilt (a slab's top face),
/// while the fit follows the other body's particles, whose rows a dragged,
/// rocking block shears and tilts by a fraction of a degree (0.22° at
/// 0.2 s, against the slide at every node: the block at μ = 0.4 then lags
/// 3.4 % at 0.5 s). On a curved body the two differ off the line of
/// centres and the fit is kept. Measured (block on the slab, relative
/// velocity at 0.5 s for μ = 0.4): 0.5° −2.8 %, 1° −1.4 %, 2° +0.08 %, 3°
/// and 5° +0.55 %, so 3° sits on the plateau. cos 3°.
pub const LR_FLAT_COS: f64 = 0.998_629_534_754_573_8;

/// Below this final scale |φ| the particles are not separated by a line
/// (the bodies' particles mix at the node, or too few reach it): the
/// direction is then ill-determined and the larger volume's normal is kept.
pub const LR_MIN_SCALE: f64 = 2.0;

/// Logistic weights of one particle at z = φ·d + b, computed without
/// cancellation: (σ(z) − y, σ(z) (1 − σ(z))) for label y ∈ {0, 1}.
#[inline]
fn logistic(z: f64, y_is_a: bool) -> (f64, f64) {
    let e = (-z.abs()).exp();
    let (s, one_minus_s) = if z >= 0.0 {
        (1.0 / (1.0 + e), e / (1.0 + e))
    } else {
        (e / (1.0 + e), 1.0 / (1.0 + e))
    };
    (
        if y_is_a { -one_minus_s } else { s },
        e / ((1.0 + e) * (1.0 + e)),
    )
}

/// Nairn's logistic-regression normal (Nairn et al. 2018): the line that
/// best separates the two sides' particles reaching the node,
/// P_a(x) = σ(φ·(x − c)/l̄ + b), c and l̄ the particles' mean position and
/// half-width, each weighted by its volume over the total; `LR_ITERATIONS`
/// Newton steps on the log-likelihood with the ridge `LR_RIDGE` |φ|²/2,
/// from φ = 0, each step's |Δφ| capped at `LR_MAX_STEP`. The normal (from a to b) is −φ/|φ|; `n0` where
/// the fit fails or separates nothing (|φ| < `LR_MIN_SCALE`), and where it
/// lies within 3° of `n0` (`LR_FLAT_COS`: a flat face's gradient is exact).
pub fn lr_normal(
    side_a: &[(u32, u8, u32)],
    side_b: &[(u32, u8, u32)],
    x: &[[f64; 2]],
    mass: &[f64],
    rho: &[f64],
    n0: [f64; 2],
) -> [f64; 2] {
    let all = || {
        let a = side_a.iter().map(|e| (e.2 as usize, true));
        a.chain(side_b.iter().map(|e| (e.2 as usize, false)))
    };
    let (mut c, mut vol, mut l) = ([0.0; 2], 0.0, 0.0);
    for (p, _) in all() {
        let v = mass[p] / rho[p];
        c[0] += v * x[p][0];
        c[1] += v * x[p][1];
        vol += v;
        l += v * half_width(mass[p], rho[p]);
    }
    if vol.is_nan() || vol <= 0.0 {
        return n0;
    }
    c = [c[0] / vol, c[1] / vol];
    l /= vol;
    let mut th = [0.0; 3];
    for _ in 0..LR_ITERATIONS {
        let mut g = [LR_RIDGE * th[0], LR_RIDGE * th[1], 0.0];
        let mut hm = [[0.0; 3]; 3];
        hm[0][0] = LR_RIDGE;
        hm[1][1] = LR_RIDGE;
        for (p, is_a) in all() {
            let w = mass[p] / rho[p] / vol;
            let d = [(x[p][0] - c[0]) / l, (x[p][1] - c[1]) / l, 1.0];
            let (r, h) = logistic(th[0] * d[0] + th[1] * d[1] + th[2], is_a);
            for i in 0..3 {
                g[i] += w * r * d[i];
                for j in 0..3 {
                    hm[i][j] += w * h * d[i] * d[j];
                }
            }
        }
        let Some(step) = solve3(hm, g) else {
            break;
        };
        let len = (step[0] * step[0] + step[1] * step[1]).sqrt();
        let cut = if len > LR_MAX_STEP {
            LR_MAX_STEP / len
        } else {
            1.0
        };
        for i in 0..3 {
            th[i] -= cut * step[i];
        }
    }
    let len = th[0].hypot(th[1]);
    if len >= LR_MIN_SCALE && len.is_finite() {
        let n = [-th[0] / len, -th[1] / len];
        if n[0] * n0[0] + n[1] * n0[1] >= LR_FLAT_COS {
            n0
        } else {
            n
        }
    } else {
        n0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_flat_face_angle_is_three_degrees() {
        assert!((LR_FLAT_COS - 3f64.to_radians().cos()).abs() < 1e-15);
    }
}
