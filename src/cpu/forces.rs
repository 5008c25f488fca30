//! Stage `forces`: scatter internal and external nodal forces,
//! f_I = Σ_p (−V_p σ_p ∇N_I + N_I m_p b) (paper eq. 14; V_p = m_p / ρ_p).
//! GPU twin: `shaders/forces.wgsl`.

use super::{ShapeCache, scatter::Scatter};

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
        let (nodes, w) = cache.particle(p);
        for (&node, wk) in nodes.iter().zip(w) {
            let acc = &mut acc[node as usize];
            acc[0] += -vol * (s[0] * wk[1] + s[2] * wk[2]) + wk[0] * bx;
            acc[1] += -vol * (s[2] * wk[1] + s[1] * wk[2]) + wk[0] * by;
        }
    });
}
