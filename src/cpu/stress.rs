//! Stage `stress`: strain increment from the (predicted) nodal velocities,
//! density and stress update (paper Algorithm 1, steps 4–5; update stress
//! first). Δε = Δt sym(Σ_I v_I ⊗ ∇N_I), ρ ← ρ / (1 + tr Δε), σ ← σ + D:Δε.
//! GPU twin: `shaders/stress.wgsl`.

use super::ShapeCache;
use crate::fault::{Fault, FaultKind};
use crate::material::Material;
use rayon::prelude::*;

#[allow(clippy::too_many_arguments)]
pub fn stress(
    cache: &ShapeCache,
    mv: &[[f64; 3]],
    dt: f64,
    body: &[u32],
    materials: &[Material],
    body_material: &[u32],
    stress: &mut [[f64; 3]],
    rho: &mut [f64],
) -> Result<(), Fault> {
    let fault = (stress.par_iter_mut(), rho.par_iter_mut())
        .into_par_iter()
        .enumerate()
        .with_min_len(256)
        .map(|(p, (s, r))| {
            let (nodes, w) = cache.particle(p);
            // Velocity gradient L_ij = Σ v_i ∂N/∂x_j.
            let mut l = [0.0; 4];
            for (&node, wk) in nodes.iter().zip(w) {
                let v = &mv[node as usize];
                l[0] += v[1] * wk[1];
                l[1] += v[1] * wk[2];
                l[2] += v[2] * wk[1];
                l[3] += v[2] * wk[2];
            }
            let de = [dt * l[0], dt * l[3], 0.5 * dt * (l[1] + l[2])];
            let j = 1.0 + de[0] + de[1];
            if j.is_nan() {
                return Some(Fault::at(p, FaultKind::NonFinite { field: "strain" }));
            }
            if j <= 0.0 {
                return Some(Fault::at(p, FaultKind::NonPositiveDensity));
            }
            *r /= j;
            materials[body_material[body[p] as usize] as usize].update_stress(s, de);
            if !(s[0].is_finite() && s[1].is_finite() && s[2].is_finite()) {
                return Some(Fault::at(p, FaultKind::NonFinite { field: "stress" }));
            }
            None
        })
        .reduce(|| None, Fault::first);
    fault.map_or(Ok(()), Err)
}
