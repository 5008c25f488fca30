//! Pass `g2p_p2g` (CPU only): this step's particle update (`g2p`) and, in
//! the same loop over the particles, the next step's `cfl` reduction and
//! `p2g` scatter at the positions just reached, so a particle's fields are
//! read once for the three (what `StepPlan::cpu_primed` then starts from).
//! Each particle is updated exactly as `g2p::g2p` does, its signal speed
//! is `time_step::max_speed`'s, and its mass, momentum and m a go to the
//! nodes in the same ranges and order as `p2g::p2g`'s, so a step from a
//! primed grid equals the step from the particles alone bit for bit
//! (`tests/fused_step.rs`). The scatter is summed into the nodes once the
//! next Δt is known (`p2g::combine`, NPC's (1 − γ) Δt a_p).
//! No GPU twin: the GPU runs `g2p`, then the next step's passes.

use super::g2p::{self, G2pParams};
use super::p2g::add_particle;
use super::scatter::Scatter;
use super::stage_inputs::{BATCH, ParticleWeights, Weights, optional_chunks, with_weights};
use crate::model::Grid;
use crate::model::fault::{Fault, FaultKind};
use crate::model::material::{Material, PlasticState};

/// What the next step's Δt needs from the particles' state after this
/// step: their materials and state (`Material::wave_speed_squared`).
pub struct SpeedInputs<'a> {
    pub materials: &'a [Material],
    pub body_material: &'a [u32],
    pub body: &'a [u32],
    pub rho: &'a [f64],
    pub stress: &'a [[f64; 3]],
    pub plastic: &'a [PlasticState],
    pub mass: &'a [f64],
    /// A fixed Δt: no speeds needed.
    pub fixed_dt: bool,
}

/// Runs the pass: returns the largest signal speed (m/s) after the update
/// and the worker ranges `scatter` holds (`Scatter::reduce_map` sums them).
#[allow(clippy::too_many_arguments)]
pub fn g2p_p2g(
    weights: Weights<'_>,
    nodal: &[[f64; 4]],
    grid: &Grid,
    prm: G2pParams,
    speed: &SpeedInputs<'_>,
    x: &mut [[f64; 2]],
    v: &mut [[f64; 2]],
    a: &mut [[f64; 2]],
    n_nodes: usize,
    scatter: &mut Scatter<5>,
) -> Result<(f64, usize), Fault> {
    with_weights!(weights, |w| run(
        w, nodal, grid, prm, speed, x, v, a, n_nodes, scatter
    ))
}

#[allow(clippy::too_many_arguments)]
fn run<W: ParticleWeights>(
    weights: &W,
    nodal: &[[f64; 4]],
    grid: &Grid,
    prm: G2pParams,
    sp: &SpeedInputs<'_>,
    x: &mut [[f64; 2]],
    v: &mut [[f64; 2]],
    a: &mut [[f64; 2]],
    n_nodes: usize,
    scatter: &mut Scatter<5>,
) -> Result<(f64, usize), Fault> {
    use rayon::prelude::*;
    let n = x.len();
    let len = Scatter::<5>::range_len(n);
    let update = g2p::Update {
        nodal,
        bounds: grid.bounds(prm.edge_margin),
        prm,
        touched: None,
        mass: &[],
    };
    let ranges = (
        x.par_chunks_mut(len),
        v.par_chunks_mut(len),
        optional_chunks(a, n, len),
    )
        .into_par_iter();
    let ((fault, c), used) = scatter.accumulate(
        n_nodes,
        n,
        ranges,
        #[inline(always)]
        |first, (x, v, mut a), acc| {
            let mut fault = None;
            let mut c2 = 0.0f64;
            let mut batch = W::Batch::default();
            let mut moved = [false; BATCH];
            let mut next = [[0.0; 2]; BATCH];
            for (b, (x, v)) in x.chunks_mut(BATCH).zip(v.chunks_mut(BATCH)).enumerate() {
                let (k0, len) = (b * BATCH, x.len());
                // The weights at the step's start, for g2p.
                weights.prepare::<false>(first + k0, x, &mut batch);
                for (j, (x, v)) in x.iter_mut().zip(v.iter_mut()).enumerate() {
                    let p = first + k0 + j;
                    let a = a.as_deref_mut().map(|a| &mut a[k0 + j]);
                    let f = match weights.view(p, &batch, j) {
                        Ok(st) => update.particle(p, &st, x, v, a, None),
                        Err(e) => Some(Fault::at(p, FaultKind::Shape(e))),
                    };
                    moved[j] = f.is_none();
                    Fault::note(&mut fault, f);
                    next[j] = *x;
                }
                // Then at the positions reached, for the next p2g.
                weights.prepare::<false>(first + k0, &next[..len], &mut batch);
                for j in (0..len).filter(|&j| moved[j]) {
                    let (p, v) = (first + k0 + j, v[j]);
                    if !sp.fixed_dt {
                        // Squared, as `time_step::max_speed` takes them.
                        let wave = sp.materials[sp.body_material[sp.body[p] as usize] as usize]
                            .wave_speed_squared(
                                sp.rho[p],
                                &sp.stress[p],
                                sp.plastic.get(p).unwrap_or(&[0.0; 4]),
                            );
                        c2 = c2.max((v[0] * v[0] + v[1] * v[1]).max(wave));
                    }
                    match weights.view(p, &batch, j) {
                        Ok(st) => {
                            let acc_p = a.as_deref().map_or([0.0; 2], |a| a[k0 + j]);
                            add_particle(&st, sp.mass[p], v, acc_p, acc);
                        }
                        Err(e) => Fault::note(&mut fault, Some(Fault::at(p, FaultKind::Shape(e)))),
                    }
                }
            }
            (fault, c2)
        },
        |(fa, ca), (fb, cb)| (Fault::first(fa, fb), ca.max(cb)),
        || (None, 0.0),
    );
    match fault {
        Some(f) => Err(f),
        None => Ok((c.sqrt(), used)),
    }
}
