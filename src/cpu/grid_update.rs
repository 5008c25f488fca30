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
//! GPU twin: `shaders/grid_update.wgsl` (built without and with
//! `CORRECT`).

use crate::model::{ConstraintGroup, FIX_X, FIX_Y};
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
}
