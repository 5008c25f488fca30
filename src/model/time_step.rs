//! The time-step rule both backends follow (paper eq. 43): Δt = CFL · h /
//! max_p max(|v_p|, c_p), c_p the material's P-wave speed at the particle's
//! current density, or the scene's fixed `solver.dt`; and the last-step
//! rule: a step that would reach within `LAST_STEP_REL` of t_end is
//! shortened to land on it exactly. The CPU stage `cfl` is this rule; its
//! WGSL twins are `shaders/cfl.wgsl` and `shaders/step_begin.wgsl`.

use crate::model::Model;
use rayon::prelude::*;

/// A step of Δt ≥ (1 − LAST_STEP_REL) × (t_end − t) is the last one and
/// lands on t_end. Mirrored in `shaders/step_begin.wgsl` (checked by
/// tests/gpu_shaders.rs).
pub const LAST_STEP_REL: f64 = 1e-6;

/// Whether a stop time (a sample, snapshot or checkpoint time) is reached
/// at `t`, the last step having been `dt_last`: within LAST_STEP_REL of
/// that step below it counts. Fixed steps meant to land on the stop can
/// fall short of it by round-off (2000 steps of 5e-5 s sum to 0.1 − 3e-15
/// in f64), and the step that follows would take the sample a whole Δt
/// late. Mirrored on the device in `shaders/step_begin.wgsl`.
pub fn stop_reached(t: f64, t_stop: f64, dt_last: f64) -> bool {
    t >= t_stop - LAST_STEP_REL * dt_last
}

/// The time a CPU backend reports once `advance` has stopped at `t`: the
/// stop time itself when `t` is within round-off below it (as the GPU
/// reports it), else `t`.
pub fn settle_on_stop(t: f64, t_stop: f64, t_end: f64, dt_last: f64) -> f64 {
    if t < t_stop && stop_reached(t, t_stop, dt_last) {
        t_stop.min(t_end)
    } else {
        t
    }
}

/// Δt of a step starting at `t` (s), and whether it is the last.
pub fn time_step(model: &Model, t: f64) -> (f64, bool) {
    step_of(model, max_speed(model), t)
}

/// Δt (s) and whether it is the last, given the largest signal speed `c` (m/s).
pub fn step_of(model: &Model, c: f64, t: f64) -> (f64, bool) {
    let dt = model.fixed_dt.unwrap_or_else(|| {
        let cfl = model.cfl * model.grid.min_spacing() / c;
        // Saturated soil: the flow's own explicit limit, where smaller.
        match &model.pore {
            Some(pore) => cfl.min(pore.flow_dt(model.grid.min_spacing())),
            None => cfl,
        }
    });
    let rem = model.t_end - t;
    if dt >= rem * (1.0 - LAST_STEP_REL) {
        (rem, true)
    } else {
        (dt, false)
    }
}

/// Largest signal speed over all particles (m/s): |v_p| or the material's
/// wave speed at the particle's density and state (undrained where the
/// material is saturated).
pub fn max_speed(model: &Model) -> f64 {
    let p = &model.particles;
    (0..p.len())
        .into_par_iter()
        .with_min_len(1024)
        .map(|i| {
            let v = p.v[i];
            let mut c2 = model.material_of(i).wave_speed_squared(
                p.rho[i],
                &p.stress[i],
                p.plastic.get(i).unwrap_or(&[0.0; 4]),
            );
            // Saturated soil: the undrained wave, (M + K_w / n) / ρ.
            if let Some(pore) = &model.pore {
                c2 += pore.undrained_modulus(model.material_index_of(i)) / p.rho[i];
            }
            (v[0] * v[0] + v[1] * v[1]).max(c2)
        })
        .reduce(|| 0.0, f64::max)
        .sqrt()
}
