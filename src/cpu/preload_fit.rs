//! The walls' preload fitted to the body's discrete reaction at rest
//! (`Walls::pre_fit`), computed once when the model is built, for both
//! backends.
//!
//! A body that starts in equilibrium against its walls (a geostatic
//! start) is in equilibrium on the grid only if the walls give each node
//! the force the particles' quadrature leaves there: R_I = −(f_int +
//! f_ext)_I at t = 0, the discrete reaction. The preload of each flush
//! particle (`Walls::preload`, put on the wall's line by `wall_touch`)
//! matches R for linear shapes (exactly) and B-splines (by their basis at
//! the line), but not for LME, whose weights at the line are first order
//! and whose support reaches the rows either side of the wall's: the LME
//! column settled and rang at 4.1e-3 m/s (docs/methods.md, "Preload").
//! The fit closes that gap with a per-node factor a_I (a vector) such
//! that each preloaded contact also puts P_p N_Ip a_I on node I, with
//! Σ_p P_p(0) N_Ip(0) a_I = R_I − (the preload's own nodal force)_I at
//! the start: at rest the walls give exactly R; the correction goes with
//! each particle's current preload P_p and weights N_Ip, so it lets go
//! where the body leaves the wall or unloads, and follows a particle that
//! slides along it.

use super::forces::forces;
use super::grid_update::{ContactParticles, preload_scale, wall_touch};
use super::scatter::Scatter;
use super::shape_eval::shape_eval;
use super::stage_inputs::ShapeCache;
use crate::model::Model;

/// Nodes whose preload weight W_I = Σ_p P_p N_Ip is below this share of
/// the largest get no correction (a guard against dividing by zero; the
/// cap below decides the rest).
pub const FIT_WEIGHT_REL: f64 = 1e-12;

/// The largest fit factor |a_I| a node takes: where the residual would
/// need more, it is not the walls' reaction but the free surface's own
/// quadrature residue, which nodes far out in the preloaded particles'
/// supports would otherwise be asked to carry. Measured on the geostatic
/// column of `tests/initial_states.rs` (LME, 2026-11-29): the walls'
/// nodes need |a| up to 1.24 (the side walls' rows, and the row behind
/// them that LME's support reaches); the top row of nodes, above the
/// free surface, 0.014 N of residual at |a| = 17 to 41. Leaving those
/// alone, the column holds to 2.4e-5 m/s, as with them fitted (1.7e-5).
pub const FIT_MAX: f64 = 2.0;

/// Fit factors below this are round-off (linear shapes and B-splines on
/// `cells` knots match the reaction to 1e-12 without a fit: measured
/// |a| ≤ 3e-11), so such a scene keeps no fit and pays nothing for it.
pub const FIT_MIN: f64 = 1e-9;

/// The fit's factors a_I per grid node, or an empty list when there is
/// nothing to fit: no preload, contact pairs (a field per body; they keep
/// the preload on the line alone), MLS (its forces are not the grid's
/// N and ∇N), or the shapes cannot be evaluated at the start (the run's
/// first step reports that).
pub fn preload_fit(model: &Model) -> Vec<[f64; 2]> {
    let w = &model.walls;
    if w.preload.is_empty() || model.contact.is_some() || model.mls {
        return Vec::new();
    }
    let p = &model.particles;
    let n_nodes = model.grid.n_nodes();
    let mut cache = ShapeCache::new(p.len(), model.shape.max_nodes());
    let mut lambda = p.lambda.clone();
    if shape_eval(&model.shape, &model.grid, &p.x, &mut lambda, &mut cache).is_err() {
        return Vec::new();
    }
    // The body force the preload is in equilibrium with: full gravity.
    let g = model.gravity.map_or([0.0; 2], |g| g.g);
    let mut force = vec![[0.0; 2]; n_nodes];
    forces(
        &cache,
        &p.stress,
        &p.mass,
        &p.rho,
        &|_| g,
        &mut force,
        &mut Scatter::default(),
    );
    let pt = ContactParticles {
        x: &p.x,
        mass: &p.mass,
        rho: &p.rho,
        stress: &p.stress,
        v: &p.v,
        gravity: g,
        line: super::line_shape(&model.shape, &model.grid),
    };
    let mut touch = vec![[0.0; 2]; n_nodes];
    let mut pre = vec![[0.0; 2]; n_nodes];
    wall_touch(&cache, &pt, w, 0.0, &mut touch, &mut pre);
    let mut weight = vec![0.0; n_nodes];
    for q in 0..p.len() {
        let s = preload_scale(q, &pt, w, 0.0);
        if s <= 0.0 {
            continue;
        }
        let (nodes, wt) = cache.particle(q);
        for (&n, wk) in nodes.iter().zip(wt) {
            weight[n as usize] += s * wk[0];
        }
    }
    let floor = FIT_WEIGHT_REL * weight.iter().fold(0.0f64, |a, &b| a.max(b.abs()));
    let fit: Vec<[f64; 2]> = (0..n_nodes)
        .map(|n| {
            if weight[n].abs() <= floor {
                return [0.0; 2];
            }
            let r = [-force[n][0] - pre[n][0], -force[n][1] - pre[n][1]];
            let a = [r[0] / weight[n], r[1] / weight[n]];
            let size = a[0].abs().max(a[1].abs());
            if !(FIT_MIN..=FIT_MAX).contains(&size) {
                return [0.0; 2];
            }
            a
        })
        .collect();
    if fit.iter().all(|a| a[0] == 0.0 && a[1] == 0.0) {
        Vec::new()
    } else {
        fit
    }
}
