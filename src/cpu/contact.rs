//! Contact between bodies on the CPU (multi-field MPM, Bardenhagen et al.
//! 2000; the gap from the particles' domains, after Nairn's position
//! checks): `model::contact` stacks one copy of the nodes per field, and
//! `offset_nodes` moves each particle's node indices into its body's
//! field after `shape_eval`, so every other stage runs unchanged.
//! `detect` (before `predict`): per pair and node where both fields have
//! mass, the gap between the two bodies' particle domains that reach the
//! node (round, radius ½ sqrt(V_p)): the pair is in contact at the node
//! when the domains meet (gap ≤ a round-off slack), not a cell early;
//! there the normal n (from the first body towards the second) is the
//! line that separates the two bodies' particles reaching the node
//! (Nairn et al.'s logistic regression, `lr_normal`), or, where no line
//! separates them, the mass gradient of the body with the larger volume.
//! `exchange` (after `predict`, and after `correct` with `AsForce`): at
//! each node, for each two fields with mass (in field order): a declared
//! pair in contact applies its law on the relative velocity while the
//! bodies approach; two fields that are not a declared pair move together
//! (their centre-of-mass velocity, as one shared field would). Each
//! exchange adds Δp to one field and −Δp to the other: the pair's momentum
//! is conserved to round-off. Nodes with a fixed component are left to
//! their constraint.

use super::stage_inputs::ShapeCache;
use crate::model::Contacts;
use crate::model::walls::{CONTACT_FRICTION, CONTACT_STICK};

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
    /// Scratch: (pair node, side, particle) of the particles reaching a
    /// node where the pair has a normal.
    members: Vec<(u32, u8, u32)>,
}

impl ContactState {
    pub fn new(c: &Contacts, n_nodes: usize) -> Self {
        ContactState {
            grad: vec![[0.0; 3]; c.n_fields * n_nodes],
            normal: vec![[0.0; 2]; c.pairs.len() * n_nodes],
            gap: vec![f64::INFINITY; c.pairs.len() * n_nodes],
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

/// Moves particle p's node indices into its body's field (node i of field
/// f is `f · n_nodes + i`). Runs after `shape_eval`, which writes grid
/// nodes.
pub fn offset_nodes(cache: &mut ShapeCache, body: &[u32], c: &Contacts, n_nodes: usize) {
    let stride = cache.stride;
    for (p, &b) in body.iter().enumerate() {
        let off = c.field_of_body[b as usize] * n_nodes as u32;
        if off == 0 {
            continue;
        }
        let n = cache.count[p] as usize;
        for node in &mut cache.nodes[p * stride..p * stride + n] {
            *node += off;
        }
    }
}

/// Half-width of particle p's square domain (m): ½ sqrt(m_p / ρ_p).
#[inline]
fn half_width(mass: f64, rho: f64) -> f64 {
    0.5 * (mass / rho).sqrt()
}

/// The mass gradients and volumes per field node (`ContactState::grad`),
/// which `detect` reads.
pub fn grad(
    cache: &ShapeCache,
    mass: &[f64],
    rho: &[f64],
    body: &[u32],
    c: &Contacts,
    st: &mut ContactState,
) {
    st.grad.fill([0.0; 3]);
    for p in 0..body.len() {
        if c.field_of_body[body[p] as usize] == 0 {
            // Field 0 takes part only in merges, which need no normal.
            continue;
        }
        let (nodes, w) = cache.particle(p);
        for (&node, wk) in nodes.iter().zip(w) {
            let g = &mut st.grad[node as usize];
            g[0] += mass[p] * wk[1];
            g[1] += mass[p] * wk[2];
            g[2] += wk[0] * mass[p] / rho[p];
        }
    }
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

/// The momentum Δp that field a gains (field b gains −Δp) under `law` with
/// μ, at masses m_a, m_b and velocities v_a, v_b, normal n from a to b:
/// none unless the bodies approach ((v_a − v_b)·n > 0); stick: both take
/// the centre-of-mass velocity; slip: only the normal relative velocity
/// goes; friction: Coulomb, the tangential impulse at most μ times the
/// normal one (stick when that suffices).
#[inline]
pub fn pair_impulse(
    law: u32,
    mu: f64,
    ma: f64,
    va: [f64; 2],
    mb: f64,
    vb: [f64; 2],
    n: [f64; 2],
) -> [f64; 2] {
    let rel = [va[0] - vb[0], va[1] - vb[1]];
    let approach = rel[0] * n[0] + rel[1] * n[1];
    if approach <= 0.0 {
        return [0.0; 2];
    }
    // The stick impulse: m_a (v_cm − v_a) = −m_a m_b / (m_a + m_b) (v_a − v_b).
    let red = ma * mb / (ma + mb);
    let stick = [-red * rel[0], -red * rel[1]];
    if law == CONTACT_STICK {
        return stick;
    }
    let pn = stick[0] * n[0] + stick[1] * n[1];
    let normal = [pn * n[0], pn * n[1]];
    if law != CONTACT_FRICTION {
        return normal;
    }
    let t = [stick[0] - normal[0], stick[1] - normal[1]];
    let pt = t[0].hypot(t[1]);
    let cap = mu * pn.abs();
    if pt <= cap {
        return stick;
    }
    [normal[0] + cap * t[0] / pt, normal[1] + cap * t[1] / pt]
}

/// After `correct`: where the exchanges' forces go (`exchange`).
pub struct AsForce<'a> {
    /// The nodal forces (N), stacked per field.
    pub force: &'a mut [[f64; 2]],
    /// γ Δt of the corrector (s).
    pub gamma_dt: f64,
    /// Per pair: the force on its first body (N per unit thickness).
    pub reactions: &'a mut [[f64; 2]],
}

/// Applies the contact laws and merges at every node (see the file's
/// header). `mv` holds [m, vx, vy] per field node. With `as_force`
/// (after `correct`), each velocity
/// change m Δv also goes into `force` as m Δv / (γ Δt), so the particles'
/// update sees it, and each pair's share into its reaction.
pub fn exchange(
    c: &Contacts,
    st: &ContactState,
    mv: &mut [[f64; 3]],
    fix: &[u8],
    mass_eps: f64,
    mut as_force: Option<AsForce>,
) {
    let n_nodes = fix.len();
    let nf = c.n_fields;
    if let Some(a) = &mut as_force {
        a.reactions.fill([0.0; 2]);
    }
    for (i, &fixed) in fix.iter().enumerate() {
        if fixed != 0 {
            continue;
        }
        for fa in 0..nf {
            let ia = fa * n_nodes + i;
            if mv[ia][0] <= mass_eps {
                continue;
            }
            for fb in fa + 1..nf {
                let ib = fb * n_nodes + i;
                if mv[ib][0] <= mass_eps {
                    continue;
                }
                let (ma, mb) = (mv[ia][0], mv[ib][0]);
                let (va, vb) = ([mv[ia][1], mv[ia][2]], [mv[ib][1], mv[ib][2]]);
                // Δp on fa, and the pair's index and sign for its reaction.
                let (dp, reaction) = match c.pairs.iter().position(|p| {
                    p.fields == [fa as u32, fb as u32] || p.fields == [fb as u32, fa as u32]
                }) {
                    Some(k) => {
                        if !st.touching(k, n_nodes, i) {
                            continue;
                        }
                        let pair = &c.pairs[k];
                        // The normal points from the pair's first body to its second.
                        let sign = if pair.fields[0] == fa as u32 {
                            1.0
                        } else {
                            -1.0
                        };
                        let n0 = st.normal[k * n_nodes + i];
                        let n = [sign * n0[0], sign * n0[1]];
                        (
                            pair_impulse(pair.law, pair.mu, ma, va, mb, vb, n),
                            Some((k, sign)),
                        )
                    }
                    None => {
                        // Not a pair: one field (the centre-of-mass velocity).
                        let red = ma * mb / (ma + mb);
                        ([-red * (va[0] - vb[0]), -red * (va[1] - vb[1])], None)
                    }
                };
                if dp == [0.0, 0.0] {
                    continue;
                }
                mv[ia][1] += dp[0] / ma;
                mv[ia][2] += dp[1] / ma;
                mv[ib][1] -= dp[0] / mb;
                mv[ib][2] -= dp[1] / mb;
                if let Some(AsForce {
                    force,
                    gamma_dt,
                    reactions,
                }) = &mut as_force
                {
                    let f = [dp[0] / *gamma_dt, dp[1] / *gamma_dt];
                    force[ia][0] += f[0];
                    force[ia][1] += f[1];
                    force[ib][0] -= f[0];
                    force[ib][1] -= f[1];
                    if let Some((k, sign)) = reaction {
                        // The force on the pair's first body.
                        reactions[k][0] += sign * f[0];
                        reactions[k][1] += sign * f[1];
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::walls::CONTACT_SLIP;

    const N: [f64; 2] = [0.0, -1.0];

    #[test]
    fn the_flat_face_angle_is_three_degrees() {
        assert!((LR_FLAT_COS - 3f64.to_radians().cos()).abs() < 1e-15);
    }

    #[test]
    fn separating_bodies_exchange_nothing() {
        // a above b, moving up (away): n from a to b points down.
        for law in [CONTACT_STICK, CONTACT_SLIP, CONTACT_FRICTION] {
            assert_eq!(
                pair_impulse(law, 0.5, 1.0, [1.0, 1.0], 2.0, [0.0, 0.0], N),
                [0.0, 0.0]
            );
        }
    }

    #[test]
    fn stick_gives_both_the_centre_of_mass_velocity() {
        let (ma, mb) = (1.0, 3.0);
        let (va, vb) = ([2.0, -4.0], [0.0, 0.0]);
        let dp = pair_impulse(CONTACT_STICK, 0.0, ma, va, mb, vb, N);
        let v_cm = [(ma * va[0]) / 4.0, (ma * va[1]) / 4.0];
        assert!((va[0] + dp[0] / ma - v_cm[0]).abs() < 1e-15);
        assert!((va[1] + dp[1] / ma - v_cm[1]).abs() < 1e-15);
        assert!((vb[0] - dp[0] / mb - v_cm[0]).abs() < 1e-15);
    }

    #[test]
    fn slip_keeps_the_tangential_velocities() {
        let dp = pair_impulse(CONTACT_SLIP, 0.0, 1.0, [2.0, -4.0], 1.0, [0.0, 0.0], N);
        assert_eq!(dp[0], 0.0);
        // Normal relative velocity 4 removed: each gets half.
        assert!((dp[1] - 2.0).abs() < 1e-15);
    }

    #[test]
    fn friction_caps_the_tangential_impulse() {
        // Normal impulse 2, tangential stick impulse 1: μ 0.25 caps it at 0.5.
        let dp = pair_impulse(CONTACT_FRICTION, 0.25, 1.0, [2.0, -4.0], 1.0, [0.0, 0.0], N);
        assert!((dp[1] - 2.0).abs() < 1e-15);
        assert!((dp[0] + 0.5).abs() < 1e-15);
        // μ 1: sticks.
        let dp = pair_impulse(CONTACT_FRICTION, 1.0, 1.0, [2.0, -4.0], 1.0, [0.0, 0.0], N);
        assert_eq!(
            dp,
            pair_impulse(CONTACT_STICK, 0.0, 1.0, [2.0, -4.0], 1.0, [0.0, 0.0], N)
        );
    }

    #[test]
    fn exchange_conserves_momentum_at_every_node() {
        use crate::model::contact::{Contacts, Pair};
        // Three fields (0: bodies in no pair), pair 1-2 frictional; two nodes.
        let c = Contacts {
            pairs: vec![Pair {
                name: "p".into(),
                fields: [2, 1],
                law: CONTACT_FRICTION,
                mu: 0.3,
            }],
            field_of_body: vec![0, 1, 2],
            n_fields: 3,
        };
        let n_nodes = 2;
        let mut st = ContactState::new(&c, n_nodes);
        st.normal = vec![[0.6, -0.8], [0.0, 1.0]];
        let mut mv = vec![
            [1.0, 0.3, -0.2],
            [0.0, 0.0, 0.0],
            [2.0, -1.0, 2.0],
            [1.5, 0.5, 0.5],
            [0.0, 0.0, 0.0],
            [2.5, -0.5, 1.0],
        ];
        let momentum = |mv: &[[f64; 3]], i: usize| {
            (0..3).fold([0.0; 2], |s, f| {
                let n = mv[f * n_nodes + i];
                [s[0] + n[0] * n[1], s[1] + n[0] * n[2]]
            })
        };
        let before = [momentum(&mv, 0), momentum(&mv, 1)];
        let mut force = vec![[0.0; 2]; 6];
        let mut r = vec![[0.0; 2]; 1];
        exchange(
            &c,
            &st,
            &mut mv,
            &[0, 0],
            1e-12,
            Some(AsForce {
                force: &mut force,
                gamma_dt: 1e-3,
                reactions: &mut r,
            }),
        );
        for i in 0..2 {
            let after = momentum(&mv, i);
            for d in 0..2 {
                assert!(
                    (after[d] - before[i][d]).abs() < 1e-14,
                    "node {i}: {after:?} {:?}",
                    before[i]
                );
            }
            let f = (0..3).fold([0.0; 2], |s, k| {
                let f = force[k * n_nodes + i];
                [s[0] + f[0], s[1] + f[1]]
            });
            assert!(
                f[0].abs() < 1e-9 && f[1].abs() < 1e-9,
                "net exchange force {f:?}"
            );
        }
        // Node 0: field 0 merged with field 1 (no pair): one velocity;
        // node 1: the pair approaches along n = +y and exchanges.
        assert!(r[0] != [0.0, 0.0]);
        assert!((mv[0][1] - mv[2][1]).abs() < 1e-15 && (mv[0][2] - mv[2][2]).abs() < 1e-15);
    }
}
