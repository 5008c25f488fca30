//! Stage `remap` of MUSL without MLS: the particles' new velocities mapped
//! back to the nodes with the weights of the step's start (the shape cache
//! still holds N_I(x_p^t)): the nodal momentum becomes
//! q_I = Σ_p N_I(x_p^t) m_p v_p^{t+1}, the masses stay this step's m_I^t.
//! With MLS the remap is `Mls::remap` (B-spline paper eqs. 31–32).
//! `grid_update::predict` then divides by the mass and applies the walls
//! and Dirichlet conditions (eq. 33). GPU twin: `shaders/remap.wgsl`.

use super::{scatter::Scatter, stage_inputs::ShapeCache};

/// Zeroes the nodal momentum of `mv`, keeping the masses (pass
/// `RemapClear`, before `remap` or `Mls::remap` adds to it; GPU twin:
/// `remap.wgsl` built with `CLEAR`).
pub fn clear_momentum(mv: &mut [[f64; 3]]) {
    for n in mv.iter_mut() {
        n[1] = 0.0;
        n[2] = 0.0;
    }
}

/// Adds Σ_p N_I(x_p^t) m_p v_p to the nodal momentum (zeroed by
/// `clear_momentum`).
pub fn remap(
    cache: &ShapeCache,
    mass: &[f64],
    v: &[[f64; 2]],
    mv: &mut [[f64; 3]],
    scatter: &mut Scatter<3>,
) {
    scatter.run(mv, mass.len(), |p, acc| {
        let (nodes, w) = cache.particle(p);
        for (&node, wk) in nodes.iter().zip(w) {
            let nm = wk[0] * mass[p];
            let o = &mut acc[node as usize];
            o[1] += nm * v[p][0];
            o[2] += nm * v[p][1];
        }
    });
}
