//! Stage `grid_update`, in two passes around the force computation.
//! `predict`: nodal velocity from the scattered momentum, v_I = q_I / m_I,
//! then the Dirichlet conditions (fixed components set to the
//! constraint's prescribed velocity at the step's end, zero by default).
//! `correct`: the walls' forces (`wall_contact`) added to f_I, reactions
//! on fixed nodes, their force components zeroed, then
//! v_I += γ Δt f_I / m_I (NPC corrector; FE is γ = 1: the nodal momentum
//! update p_I += Δt f_I of Zhang et al.). Fixed components keep their
//! prescribed value: a constraint wins over a wall.
//! With `solver.local_damping` α > 0 (Cundall), `correct` first takes
//! α |f_i| sign(v_i) off each component of the unbalanced force of a node
//! with mass (the walls' forces included), v_I the nodal velocity it is
//! about to correct (the predicted one), before the velocity update, so
//! the nodes and the particles' FLIP update (`g2p`) feel the damped force.
//! The walls' passes around them are `wall_touch` (before `predict`) and
//! `wall_contact` (before `correct`).
//! Loaded platens (`[platens]`) follow each of the two: `platens` gives
//! their nodes one velocity along the axis, the mass-weighted mean. After
//! `predict` that is Σ q / Σ m, after `correct` the predicted one plus
//! γ Δt Σ f / Σ m (`platen_totals`, `platens_correct`, the damping taken
//! on the summed force), with the force on each node made m_I Σ f / Σ m
//! (one acceleration, which `g2p` reads): the rigid plate's momentum
//! balance under the summed force (the load and the material's
//! reaction), exact for a lumped mass.
//! GPU twin: `shaders/grid_update.wgsl` (built without and with
//! `CORRECT`); the GPU path has no platens yet and refuses them.

use crate::model::{ConstraintGroup, FIX_X, FIX_Y, Platen};
use rayon::prelude::*;

pub use crate::model::MASS_EPS_REL;

#[inline]
fn zero_fixed(v: &mut [f64], fix: u8) {
    if fix & FIX_X != 0 {
        v[0] = 0.0;
    }
    if fix & FIX_Y != 0 {
        v[1] = 0.0;
    }
}

/// Cundall's non-viscous local damping of a nodal force `f` (N) at nodal
/// velocity `v` (m/s): f_i − α |f_i| sign(v_i) per component, sign(0) = 0
/// (WGSL's `sign`). It opposes the motion by a share of the unbalanced
/// force, whatever the frequency, and vanishes at equilibrium (f = 0) and
/// at rest (v = 0).
#[inline]
pub fn local_damping(f: [f64; 2], v: [f64; 2], alpha: f64) -> [f64; 2] {
    let sign = |x: f64| {
        if x > 0.0 {
            1.0
        } else if x < 0.0 {
            -1.0
        } else {
            0.0
        }
    };
    [
        f[0] - alpha * f[0].abs() * sign(v[0]),
        f[1] - alpha * f[1].abs() * sign(v[1]),
    ]
}
/// Prescribed velocities at time `t` (s) on the fixed components of the
/// groups that move (later groups win on shared nodes); nodes without
/// mass stay at rest.
fn prescribe(mv: &mut [[f64; 3]], groups: &[ConstraintGroup], t: f64, mass_eps: f64) {
    for g in groups.iter().filter(|g| g.moves()) {
        let v = g.velocity_at(t);
        for &n in &g.nodes {
            let node = &mut mv[n as usize];
            if node[0] > mass_eps {
                if g.fix & FIX_X != 0 {
                    node[1] = v[0];
                }
                if g.fix & FIX_Y != 0 {
                    node[2] = v[1];
                }
            }
        }
    }
}

/// `mv[n] = [m, qx, qy]` in, `[m, vx, vy]` out; `t` is the step's end
/// time (s). With contact pairs `mv` holds one copy of the nodes per
/// field, stacked (`model::contact`); `fix` is per grid node.
pub fn predict(mv: &mut [[f64; 3]], fix: &[u8], groups: &[ConstraintGroup], t: f64, mass_eps: f64) {
    for mv in mv.chunks_mut(fix.len()) {
        mv.par_iter_mut()
            .zip(fix)
            .with_min_len(4096)
            .for_each(|(n, &f)| {
                if n[0] > mass_eps {
                    let mut v = [n[1] / n[0], n[2] / n[0]];
                    zero_fixed(&mut v, f);
                    *n = [n[0], v[0], v[1]];
                } else {
                    *n = [n[0], 0.0, 0.0];
                }
            });
        prescribe(mv, groups, t, mass_eps);
    }
}

/// Adds the walls' forces (`wall_contact`'s `wall_force`; empty without
/// walls) to the nodal forces, records reactions per constraint group
/// (the force the support exerts, −f_I on each fixed component), zeroes
/// those components, then corrects the velocities by `gamma_dt` · f/m.
/// `reactions` holds the constraint groups' (the walls' are
/// `wall_contact`'s). `damping` is Cundall's α (`local_damping`; 0 leaves
/// the force as it is).
#[allow(clippy::too_many_arguments)]
pub fn correct(
    mv: &mut [[f64; 3]],
    force: &mut [[f64; 2]],
    fix: &[u8],
    groups: &[ConstraintGroup],
    wall_force: &[[f64; 2]],
    reactions: &mut [[f64; 2]],
    gamma_dt: f64,
    damping: f64,
    mass_eps: f64,
) {
    let n_nodes = fix.len();
    if !wall_force.is_empty() {
        force
            .par_iter_mut()
            .zip(wall_force)
            .with_min_len(4096)
            .for_each(|(f, w)| {
                f[0] += w[0];
                f[1] += w[1];
            });
    }
    for (g, r) in groups.iter().zip(reactions.iter_mut()) {
        *r = [0.0; 2];
        for field in force.chunks(n_nodes) {
            for &n in &g.nodes {
                let f = field[n as usize];
                if g.fix & FIX_X != 0 {
                    r[0] -= f[0];
                }
                if g.fix & FIX_Y != 0 {
                    r[1] -= f[1];
                }
            }
        }
    }
    for (mv, force) in mv.chunks_mut(n_nodes).zip(force.chunks_mut(n_nodes)) {
        mv.par_iter_mut()
            .zip(force.par_iter_mut())
            .zip(fix)
            .with_min_len(4096)
            .for_each(|((n, f), &fx)| {
                zero_fixed(f, fx);
                if n[0] > mass_eps {
                    if damping > 0.0 {
                        *f = local_damping(*f, [n[1], n[2]], damping);
                    }
                    n[1] += gamma_dt * f[0] / n[0];
                    n[2] += gamma_dt * f[1] / n[0];
                }
            });
    }
}

/// After `predict`: each platen's nodes with mass take one velocity along
/// its axis, the mass-weighted mean of theirs (`mv` as `[m, vx, vy]`, one
/// field).
pub fn platens(mv: &mut [[f64; 3]], platens: &[Platen], mass_eps: f64) {
    for p in platens {
        let k = 1 + p.axis;
        let (mut m, mut q) = (0.0, 0.0);
        for &n in &p.nodes {
            let node = &mv[n as usize];
            if node[0] > mass_eps {
                m += node[0];
                q += node[0] * node[k];
            }
        }
        if m > 0.0 {
            for &n in &p.nodes {
                let node = &mut mv[n as usize];
                if node[0] > mass_eps {
                    node[k] = q / m;
                }
            }
        }
    }
}

/// Before `correct`: each platen's one velocity along its axis (the
/// predicted, tied one) and its acceleration, the summed force on its
/// nodes (the walls' included) and its load at `t` (the step's end, as
/// for the other loads) over their summed mass, with Cundall's
/// damping taken on the plate as one body: damped node by node, the
/// large and opposed forces on a plate's nodes (the load on one, the
/// material's reaction on the next) would each be damped and hold the
/// plate up. Into `totals[k] = [v, a]`.
#[allow(clippy::too_many_arguments)]
pub fn platen_totals(
    mv: &[[f64; 3]],
    force: &[[f64; 2]],
    wall_force: &[[f64; 2]],
    platens: &[Platen],
    t: f64,
    damping: f64,
    mass_eps: f64,
    totals: &mut [[f64; 2]],
) {
    for (p, total) in platens.iter().zip(totals.iter_mut()) {
        let k = p.axis;
        let (mut m, mut q, mut f) = (0.0, 0.0, 0.0);
        for &n in &p.nodes {
            let n = n as usize;
            if mv[n][0] > mass_eps {
                m += mv[n][0];
                q += mv[n][0] * mv[n][1 + k];
                f += force[n][k] + wall_force.get(n).map_or(0.0, |w| w[k]);
            }
        }
        let v = if m > 0.0 { q / m } else { 0.0 };
        f += p.force_at(t);
        if damping > 0.0 {
            f = local_damping([f, 0.0], [v, 0.0], damping)[0];
        }
        *total = [v, if m > 0.0 { f / m } else { 0.0 }];
    }
}

/// After `correct`: each platen's nodes with mass move as one, v + γ Δt a
/// along the axis (`platen_totals`), with the force m_I a there, one
/// acceleration, which `g2p` reads.
pub fn platens_correct(
    mv: &mut [[f64; 3]],
    force: &mut [[f64; 2]],
    platens: &[Platen],
    totals: &[[f64; 2]],
    gamma_dt: f64,
    mass_eps: f64,
) {
    for (p, &[v, a]) in platens.iter().zip(totals) {
        for &n in &p.nodes {
            let n = n as usize;
            if mv[n][0] > mass_eps {
                mv[n][1 + p.axis] = v + gamma_dt * a;
                force[n][p.axis] = mv[n][0] * a;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn local_damping_opposes_motion() {
        // α = 0.5: a force along the motion loses half, one against it
        // grows by half; no motion, no change.
        assert_eq!(local_damping([2.0, -2.0], [1.0, 1.0], 0.5), [1.0, -3.0]);
        assert_eq!(local_damping([2.0, -2.0], [0.0, 0.0], 0.5), [2.0, -2.0]);
        assert_eq!(local_damping([2.0, 0.0], [-1.0, 3.0], 0.5), [3.0, 0.0]);
    }

    #[test]
    fn a_platen_moves_its_nodes_as_one_and_keeps_their_momentum() {
        // Masses 1 and 3 at v_y 4 and 0: one v_y = 1 (momentum 4 kept);
        // x and the massless node untouched.
        let mut mv = [[1.0, 2.0, 4.0], [3.0, -1.0, 0.0], [0.0, 0.0, 0.0]];
        let p = [Platen {
            name: "plate".into(),
            nodes: vec![0, 1, 2],
            axis: 1,
            force: 0.0,
            ramp_time: 0.0,
        }];
        platens(&mut mv, &p, 1e-12);
        assert_eq!(mv, [[1.0, 2.0, 1.0], [3.0, -1.0, 1.0], [0.0, 0.0, 0.0]]);
        // Forces +6 and −2 along y: Σ f / Σ m = 1, one acceleration
        // (f_y = m); the plate's velocity 1 + 0.5 · 1; x untouched. With
        // α = 0.5 the plate as one body keeps 4 − 0.5 · 4 = 2 of its 4.
        let mut f = [[5.0, 6.0], [7.0, -2.0], [0.0, 9.0]];
        let mut totals = [[0.0; 2]];
        platen_totals(&mv, &f, &[], &p, 0.0, 0.0, 1e-12, &mut totals);
        assert_eq!(totals, [[1.0, 1.0]]);
        platens_correct(&mut mv, &mut f, &p, &totals, 0.5, 1e-12);
        assert_eq!(mv, [[1.0, 2.0, 1.5], [3.0, -1.0, 1.5], [0.0, 0.0, 0.0]]);
        assert_eq!(f, [[5.0, 1.0], [7.0, 3.0], [0.0, 9.0]]);
        let f = [[0.0, 6.0], [0.0, -2.0], [0.0; 2]];
        platen_totals(&mv, &f, &[], &p, 0.0, 0.5, 1e-12, &mut totals);
        assert_eq!(totals, [[1.5, 0.5]]);
        // A load of −8 N/m ramped over 2 s, at 1 s: 4 − 4 = 0 on the plate.
        let p = [Platen {
            force: -8.0,
            ramp_time: 2.0,
            ..p[0].clone()
        }];
        platen_totals(&mv, &f, &[], &p, 1.0, 0.0, 1e-12, &mut totals);
        assert_eq!(totals, [[1.5, 0.0]]);
    }
}
