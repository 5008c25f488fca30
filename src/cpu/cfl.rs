//! Stage `cfl`: the time step from the Courant condition (paper eq. 43),
//! Δt = CFL · h / max_p max(|v_p|, c_p), with c_p the material's P-wave
//! speed at the particle's current density. GPU twin: `shaders/cfl.wgsl`.

use crate::material::Material;
use crate::model::Model;
use rayon::prelude::*;

/// A step that would reach within this fraction of the time left of t_end
/// is the last and lands on t_end exactly (shaders/step_begin.wgsl has the
/// same constant; tests/gpu_shaders.rs compares them).
pub const LAST_STEP_REL: f64 = 1e-6;

/// Δt of a step starting at `t` (the CFL condition, or the scene's fixed
/// `solver.dt`), and whether it is the last: a step that
/// would reach within `LAST_STEP_REL` of t_end is shortened to land on it exactly
/// (the same rule as shaders/step_begin.wgsl).
pub fn time_step(model: &Model, t: f64) -> (f64, bool) {
    let p = &model.particles;
    let c = max_speed(
        &p.v,
        &p.rho,
        &p.body,
        &model.materials,
        &model.body_material,
    );
    let dt = model
        .fixed_dt
        .unwrap_or(model.cfl * model.grid.min_spacing() / c);
    let rem = model.t_end - t;
    if dt >= rem * (1.0 - LAST_STEP_REL) {
        (rem, true)
    } else {
        (dt, false)
    }
}

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
