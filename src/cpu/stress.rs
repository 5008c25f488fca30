//! Stage `stress`: velocity gradient from the (predicted) nodal velocities,
//! L = Σ_I v_I ⊗ ∇N_I, then the material's update over Δt (paper Algorithm 1,
//! steps 4–5; update stress first): linear elastic adds D : Δε with
//! Δε = Δt sym(L); Neo-Hookean updates F ← (I + Δt L) F and evaluates σ(F).
//! The density follows the volume ratio the material returns.
//! GPU twin: `shaders/stress.wgsl`.

use super::ShapeCache;
use crate::model::fault::{Fault, FaultKind};
use crate::model::material::Material;
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
    f: &mut [[f64; 4]],
) -> Result<(), Fault> {
    let kernel = |p: usize, s: &mut [f64; 3], r: &mut f64, f: &mut [f64; 4]| {
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
        match materials[body_material[body[p] as usize] as usize].update(l, dt, s, f) {
            Err(kind) => Some(Fault::at(p, kind)),
            Ok(j) => {
                *r /= j;
                if !(s[0].is_finite() && s[1].is_finite() && s[2].is_finite()) {
                    return Some(Fault::at(p, FaultKind::NonFinite { field: "stress" }));
                }
                None
            }
        }
    };
    let fault = if f.is_empty() {
        (stress.par_iter_mut(), rho.par_iter_mut())
            .into_par_iter()
            .enumerate()
            .with_min_len(256)
            .map(|(p, (s, r))| kernel(p, s, r, &mut [1.0, 0.0, 0.0, 1.0]))
            .reduce(|| None, Fault::first)
    } else {
        (stress.par_iter_mut(), rho.par_iter_mut(), f.par_iter_mut())
            .into_par_iter()
            .enumerate()
            .with_min_len(256)
            .map(|(p, (s, r, f))| kernel(p, s, r, f))
            .reduce(|| None, Fault::first)
    };
    fault.map_or(Ok(()), Err)
}
