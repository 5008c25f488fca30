//! The walls' preload fitted to the body's discrete reaction at rest
//! (`Walls::pre_fit`), computed once when the model is built, for both
//! backends. It evaluates the shapes, the forces and the preload's
//! weights as the CPU stages do (`cpu::forces`,
//! `cpu::wall_touch`), here at the model layer, below both backends.
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

use super::grid::Grid;
use super::shape::Shape;
use super::walls::{Walls, contact_spring, face_weight, half_width, wall_depth};
use super::{Particles, node_force};

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
/// nothing to fit: no preload, contact pairs (`contact`: a field per
/// body; they keep the preload on the line alone), MLS (`mls`: its forces
/// are not the grid's N and ∇N), or a shape that cannot be evaluated at
/// the start (the run's first step reports that). `gravity` is the full
/// body force (m/s²) the preload is in equilibrium with.
pub fn preload_fit(
    shape: &Shape,
    grid: &Grid,
    p: &Particles,
    walls: &Walls,
    gravity: [f64; 2],
    contact: bool,
    mls: bool,
) -> Vec<[f64; 2]> {
    if walls.preload.is_empty() || contact || mls {
        return Vec::new();
    }
    let n_nodes = grid.n_nodes();
    let slots = shape.max_nodes();
    let (mut nodes, mut w) = (vec![0u32; slots], vec![[0.0; 3]; slots]);
    let (mut line_nodes, mut line_w) = (vec![0u32; slots], vec![[0.0; 3]; slots]);
    let mut force = vec![[0.0; 2]; n_nodes];
    let mut pre_force = vec![[0.0; 2]; n_nodes];
    let mut weight = vec![0.0; n_nodes];
    let line_exact = matches!(shape, Shape::Bspline(_));
    for i in 0..p.len() {
        let mut lambda = p.lambda.get(i).copied().unwrap_or([0.0; 2]);
        let Ok(count) = shape.eval(grid, p.x[i], &mut lambda, &mut nodes, &mut w) else {
            return Vec::new();
        };
        // f_int + f_ext, as `cpu::forces`.
        let vol = p.mass[i] / p.rho[i];
        let s = p.stress[i];
        let mg = [p.mass[i] * gravity[0], p.mass[i] * gravity[1]];
        for (&n, wk) in nodes[..count].iter().zip(&w[..count]) {
            let f = &mut force[n as usize];
            let fi = node_force(vol, s, wk, mg);
            f[0] += fi[0];
            f[1] += fi[1];
        }
        // The preloads at the start and their nodal force, as
        // `cpu::wall_touch` puts them (B-splines: their basis
        // at the line's point; else N − d n·∇N).
        let lp = half_width(p.mass[i], p.rho[i]);
        for (k, wl) in walls.list.iter().enumerate() {
            if !wl.active_at(0.0) {
                continue;
            }
            let (spring, pre) =
                contact_spring(walls, i, k, p.x[i], p.mass[i], p.rho[i], s, gravity);
            if spring <= 0.0 || pre <= 0.0 {
                continue;
            }
            let d = wall_depth(p.x[i], lp, wl);
            for (&n, wk) in nodes[..count].iter().zip(&w[..count]) {
                weight[n as usize] += pre * wk[0];
            }
            let xl = [p.x[i][0] - d * wl.normal[0], p.x[i][1] - d * wl.normal[1]];
            let at_line = if line_exact {
                shape
                    .eval(grid, xl, &mut [0.0; 2], &mut line_nodes, &mut line_w)
                    .ok()
            } else {
                None
            };
            if let Some(lc) = at_line {
                for (&n, wk) in line_nodes[..lc].iter().zip(&line_w[..lc]) {
                    pre_force[n as usize][0] += pre * wk[0] * wl.normal[0];
                    pre_force[n as usize][1] += pre * wk[0] * wl.normal[1];
                }
            } else {
                for (&n, wk) in nodes[..count].iter().zip(&w[..count]) {
                    let face = face_weight(wk, wl.normal, d);
                    pre_force[n as usize][0] += pre * face * wl.normal[0];
                    pre_force[n as usize][1] += pre * face * wl.normal[1];
                }
            }
        }
    }
    let floor = FIT_WEIGHT_REL * weight.iter().fold(0.0f64, |a, &b| a.max(b.abs()));
    let fit: Vec<[f64; 2]> = (0..n_nodes)
        .map(|n| {
            if weight[n].abs() <= floor {
                return [0.0; 2];
            }
            let r = [
                -force[n][0] - pre_force[n][0],
                -force[n][1] - pre_force[n][1],
            ];
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
