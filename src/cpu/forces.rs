//! Stage `forces`: scatter internal and external nodal forces,
//! f_I = Σ_p (−V_p σ_p ∇N_I + N_I m_p b) (paper eq. 14; V_p = m_p / ρ_p).
//! GPU twin: `shaders/forces.wgsl`.

use super::{scatter::Scatter, stage_inputs::ShapeCache};
use crate::model::node_force;

/// `body(p)` is particle p's body force per unit mass at this step (m/s²):
/// gravity, plus a manufactured solution's source term when there is one.
pub fn forces(
    cache: &ShapeCache,
    stress: &[[f64; 3]],
    mass: &[f64],
    rho: &[f64],
    body: &(dyn Fn(usize) -> [f64; 2] + Sync),
    force: &mut [[f64; 2]],
    scatter: &mut Scatter<2>,
) {
    scatter.run(force, mass.len(), |p, acc| {
        let vol = mass[p] / rho[p];
        let s = stress[p];
        let g = body(p);
        let (bx, by) = (mass[p] * g[0], mass[p] * g[1]);
        add_particle_forces(cache, p, vol, s, [bx, by], acc);
    });
}

/// Adds particle p's −V_p σ_p ∇N + N m_p b to its nodes in `acc` (`mb` is
/// m_p b). Shared with the fused `stress::stress_forces`.
#[inline]
pub fn add_particle_forces(
    cache: &ShapeCache,
    p: usize,
    vol: f64,
    s: [f64; 3],
    mb: [f64; 2],
    acc: &mut [[f64; 2]],
) {
    let (nodes, w) = cache.particle(p);
    for (&node, wk) in nodes.iter().zip(w) {
        let acc = &mut acc[node as usize];
        let f = node_force(vol, s, wk, mb);
        acc[0] += f[0];
        acc[1] += f[1];
    }
}
