//! Stage `grid_update`, in two passes around the force computation.
//! `predict`: nodal velocity from the scattered momentum, v_I = q_I / m_I,
//! then the Dirichlet conditions (fixed components set to zero).
//! `correct`: reactions on fixed nodes, their force components zeroed, then
//! v_I += γ Δt f_I / m_I (NPC corrector; FE is γ = 1: the nodal momentum
//! update p_I += Δt f_I of Zhang et al.).
//! GPU twin: `shaders/grid_update.wgsl` (entry points `predict`, `correct`).

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

/// `mv[n] = [m, qx, qy]` in, `[m, vx, vy]` out.
pub fn predict(mv: &mut [[f64; 3]], fix: &[u8], mass_eps: f64) {
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
}

/// Records reactions per constraint group (the force the support exerts,
/// −f_I on each fixed component), zeroes those components, and corrects
/// the velocities by `gamma_dt` · f/m.
pub fn correct(
    mv: &mut [[f64; 3]],
    force: &mut [[f64; 2]],
    fix: &[u8],
    groups: &[ConstraintGroup],
    reactions: &mut [[f64; 2]],
    gamma_dt: f64,
    mass_eps: f64,
) {
    for (g, r) in groups.iter().zip(reactions.iter_mut()) {
        *r = [0.0; 2];
        for &n in &g.nodes {
            let f = force[n as usize];
            if g.fix & FIX_X != 0 {
                r[0] -= f[0];
            }
            if g.fix & FIX_Y != 0 {
                r[1] -= f[1];
            }
        }
    }
    mv.par_iter_mut()
        .zip(force.par_iter_mut())
        .zip(fix)
        .with_min_len(4096)
        .for_each(|((n, f), &fx)| {
            zero_fixed(f, fx);
            if n[0] > mass_eps {
                n[1] += gamma_dt * f[0] / n[0];
                n[2] += gamma_dt * f[1] / n[0];
            }
        });
}
