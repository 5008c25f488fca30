//! Stage `p2g`: scatter particle mass and momentum to the nodes.
//! FE: m_I = Σ N m_p, q_I = Σ N m_p v_p.
//! NPC: q_I = Σ N m_p (v_p + (1 − γ) Δt a_p) (paper eq. 27, the stable form).
//! GPU twin: `shaders/p2g.wgsl`.

use super::{ShapeCache, scatter::Scatter};

/// `a` is empty for FE; `a_factor` = (1 − γ) Δt for NPC.
pub fn p2g(
    cache: &ShapeCache,
    mass: &[f64],
    v: &[[f64; 2]],
    a: &[[f64; 2]],
    a_factor: f64,
    mv: &mut [[f64; 3]],
    scatter: &mut Scatter<3>,
) {
    scatter.run(mv, mass.len(), |p, acc| {
        let m = mass[p];
        let mut vel = v[p];
        if !a.is_empty() {
            vel[0] += a_factor * a[p][0];
            vel[1] += a_factor * a[p][1];
        }
        let (nodes, w) = cache.particle(p);
        for (&node, wk) in nodes.iter().zip(w) {
            let nm = wk[0] * m;
            let acc = &mut acc[node as usize];
            acc[0] += nm;
            acc[1] += nm * vel[0];
            acc[2] += nm * vel[1];
        }
    });
}
