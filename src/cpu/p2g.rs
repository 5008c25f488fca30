//! Stage `p2g`: scatter particle mass and momentum to the nodes.
//! FE: m_I = Σ N m_p, q_I = Σ N m_p v_p.
//! NPC: q_I = Σ N m_p (v_p + (1 − γ) Δt a_p) (paper eq. 27, the stable form),
//!      summed as Σ N m_p v_p + (1 − γ) Δt Σ N m_p a_p (`combine`), so that
//!      the fused `g2p_p2g` can scatter before the next Δt is known and
//!      give the same sums.
//! GPU twin: `shaders/p2g.wgsl`.

use super::scatter::Scatter;
use super::stage_inputs::{ParticleWeights, Stencil, Weights, with_weights};
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
    scatter: &mut Scatter<5>,
) -> Result<(), Fault> {
    with_weights!(weights, |w| p2g_with(
        w, x, mass, v, a, a_factor, mv, scatter
    ))
}

#[allow(clippy::too_many_arguments)]
fn p2g_with<W: ParticleWeights>(
    weights: &W,
    x: &[[f64; 2]],
    mass: &[f64],
    v: &[[f64; 2]],
    a: &[[f64; 2]],
    a_factor: f64,
    mv: &mut [[f64; 3]],
    scatter: &mut Scatter<5>,
) -> Result<(), Fault> {
    let n = mass.len();
    let len = Scatter::<5>::range_len(n);
    let (fault, used) = scatter.accumulate(
        mv.len(),
        n,
        (0..n.div_ceil(len)).into_par_iter(),
        #[inline(always)]
        |first, _, acc| {
            let mut slots = W::Scratch::default();
            let mut fault = None;
            for p in first..(first + len).min(n) {
                match weights.get::<false>(p, x[p], &mut slots) {
                    Ok(st) => add_particle(&st, mass[p], v[p], accel(a, p), acc),
                    Err(e) => Fault::note(&mut fault, Some(Fault::at(p, FaultKind::Shape(e)))),
                }
            }
            fault
        },
        Fault::first,
        || None,
    );
    if n > 0 {
        scatter.reduce_map(mv, used, |s| combine(s, a_factor));
    }
    fault.map_or(Ok(()), Err)
}

/// Adds one particle's N m, N m v and N m a to its nodes in `acc`.
/// Shared with the fused `shape_eval::shape_eval_p2g` and `g2p_p2g`.
#[inline(always)]
pub fn add_particle(st: &impl Stencil, m: f64, vel: [f64; 2], a: [f64; 2], acc: &mut [[f64; 5]]) {
    st.each(|node, wk| {
        let nm = wk[0] * m;
        let acc = &mut acc[node as usize];
        acc[0] += nm;
        acc[1] += nm * vel[0];
        acc[2] += nm * vel[1];
        acc[3] += nm * a[0];
        acc[4] += nm * a[1];
    });
}

/// Particle p's acceleration (zero for FE and MUSL, which keep none).
#[inline(always)]
pub fn accel(a: &[[f64; 2]], p: usize) -> [f64; 2] {
    a.get(p).copied().unwrap_or([0.0; 2])
}

/// A node's [m, q] from its sums [Σ N m, Σ N m v, Σ N m a]: q = Σ N m v +
/// `a_factor` Σ N m a, `a_factor` = (1 − γ) Δt for NPC, 0 otherwise.
#[inline(always)]
pub fn combine(s: [f64; 5], a_factor: f64) -> [f64; 3] {
    [s[0], s[1] + a_factor * s[3], s[2] + a_factor * s[4]]
}
