//! Stage `p2g`: scatter particle mass and momentum to the nodes.
//! FE: m_I = Σ N m_p, q_I = Σ N m_p v_p.
//! NPC: q_I = Σ N m_p (v_p + (1 − γ) Δt a_p) (paper eq. 27, the stable form).
//! GPU twin: `shaders/p2g.wgsl`.

use super::scatter::Scatter;
use super::stage_inputs::{Slots, Weights};
use crate::model::fault::{Fault, FaultKind};
use rayon::prelude::*;

/// `a` is empty for FE; `a_factor` = (1 − γ) Δt for NPC. `x` is where
/// `weights` are evaluated when not stored.
#[allow(clippy::too_many_arguments)]
pub fn p2g(
    weights: Weights<'_>,
    x: &[[f64; 2]],
    mass: &[f64],
    v: &[[f64; 2]],
    a: &[[f64; 2]],
    a_factor: f64,
    mv: &mut [[f64; 3]],
    scatter: &mut Scatter<3>,
) -> Result<(), Fault> {
    let n = mass.len();
    let len = Scatter::<3>::range_len(n);
    let fault = scatter.run_ranges(
        mv,
        n,
        (0..n.div_ceil(len)).into_par_iter(),
        |first, _, acc| {
            let mut slots = Slots::default();
            let mut fault = None;
            for p in first..(first + len).min(n) {
                match weights.particle_values(p, x[p], &mut slots) {
                    Ok((nodes, w)) => {
                        let vel = particle_velocity(v, a, a_factor, p);
                        add_particle(nodes, w, mass[p], vel, acc);
                    }
                    Err(e) => fault = Fault::first(fault, Some(Fault::at(p, FaultKind::Shape(e)))),
                }
            }
            fault
        },
        Fault::first,
        || None,
    );
    fault.map_or(Ok(()), Err)
}

/// Adds one particle's N m and N m v to its nodes in `acc`. Shared with the
/// fused `shape_eval::shape_eval_p2g`.
#[inline]
pub fn add_particle(nodes: &[u32], w: &[[f64; 3]], m: f64, vel: [f64; 2], acc: &mut [[f64; 3]]) {
    for (&node, wk) in nodes.iter().zip(w) {
        let nm = wk[0] * m;
        let acc = &mut acc[node as usize];
        acc[0] += nm;
        acc[1] += nm * vel[0];
        acc[2] += nm * vel[1];
    }
}

/// The velocity particle p scatters (NPC: the predictor's).
#[inline]
pub fn particle_velocity(v: &[[f64; 2]], a: &[[f64; 2]], a_factor: f64, p: usize) -> [f64; 2] {
    let mut vel = v[p];
    if !a.is_empty() {
        vel[0] += a_factor * a[p][0];
        vel[1] += a_factor * a[p][1];
    }
    vel
}
