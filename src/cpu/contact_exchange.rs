//! Pass `contact_exchange` of the contact between bodies
//! (`contact_grad` has the overview), after `predict`, and after
//! `correct` with `AsForce`: at each node, for each two fields with mass
//! (in field order): a declared pair in contact (`contact_detect`) applies
//! its law on the relative velocity while the bodies approach; two fields
//! that are not a declared pair move together (their centre-of-mass
//! velocity, as one shared field would). Each exchange adds Δp to one
//! field and −Δp to the other: the pair's momentum is conserved to
//! round-off. Nodes with a fixed component are left to their constraint.
//! GPU twin: `shaders/contact_exchange.wgsl` (built with CORRECT as forces).

use super::contact_detect::ContactState;
use crate::model::Contacts;
use crate::model::walls::{CONTACT_FRICTION, CONTACT_STICK};

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
        let mut st = ContactState::new(&c, n_nodes, 0);
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
