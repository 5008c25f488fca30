//! Stage `cfl`: the time step from the Courant condition (paper eq. 43),
//! Δt = CFL · h / max_p max(|v_p|, c_p), with c_p the material's P-wave
//! speed at the particle's current density. GPU twin: `shaders/cfl.wgsl`.

use crate::material::Material;
use rayon::prelude::*;

/// Largest signal speed over all particles (m/s).
pub fn max_speed(
    v: &[[f64; 2]],
    rho: &[f64],
    body: &[u32],
    materials: &[Material],
    body_material: &[u32],
) -> f64 {
    (v, rho, body)
        .into_par_iter()
        .with_min_len(1024)
        .map(|(v, &r, &b)| {
            let c = materials[body_material[b as usize] as usize].wave_speed(r);
            (v[0] * v[0] + v[1] * v[1]).sqrt().max(c)
        })
        .reduce(|| 0.0, f64::max)
}
