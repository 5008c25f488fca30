//! Stage `shape_eval`: N and ∇N of every particle at its current position,
//! into the per-step shape cache read by p2g, stress, forces and g2p, where
//! the scene stores one (`ShapeCache::needed`); otherwise those loops
//! evaluate the shape themselves (`Weights::Eval`) and a whole step has no
//! shape evaluation of its own. For LME this is the per-particle Newton
//! solve on λ (warm-started).
//! GPU twin: `shaders/lme_newton.wgsl` (LME); other shapes are evaluated
//! inline in each GPU pass.

use super::p2g::{accel, add_particle, combine};
use super::stage_inputs::{ShapeCache, Slices, Weights};
use super::{p2g, scatter::Scatter};
use crate::model::Grid;
use crate::model::fault::{Fault, FaultKind};
use crate::model::shape::Shape;
use rayon::prelude::*;

pub fn shape_eval(
    shape: &Shape,
    grid: &Grid,
    x: &[[f64; 2]],
    lambda: &mut [[f64; 2]],
    cache: &mut ShapeCache,
) -> Result<(), Fault> {
    let s = cache.stride;
    let eval = |p: usize,
                x: [f64; 2],
                lam: &mut [f64; 2],
                cnt: &mut u16,
                nodes: &mut [u32],
                w: &mut [[f64; 3]]| {
        match shape.eval(grid, x, lam, nodes, w) {
            Ok(n) => {
                *cnt = n as u16;
                None
            }
            Err(e) => {
                *cnt = 0;
                Some(Fault::at(p, FaultKind::Shape(e)))
            }
        }
    };
    let fault = if lambda.is_empty() {
        (
            x.par_iter(),
            cache.count.par_iter_mut(),
            cache.nodes.par_chunks_mut(s),
            cache.w.par_chunks_mut(s),
        )
            .into_par_iter()
            .enumerate()
            .with_min_len(256)
            .map(|(p, (x, c, n, w))| eval(p, *x, &mut [0.0; 2], c, n, w))
            .reduce(|| None, Fault::first)
    } else {
        (
            x.par_iter(),
            lambda.par_iter_mut(),
            cache.count.par_iter_mut(),
            cache.nodes.par_chunks_mut(s),
            cache.w.par_chunks_mut(s),
        )
            .into_par_iter()
            .enumerate()
            .with_min_len(64)
            .map(|(p, (x, l, c, n, w))| eval(p, *x, l, c, n, w))
            .reduce(|| None, Fault::first)
    };
    fault.map_or(Ok(()), Err)
}

/// Stages `shape_eval` then `p2g` in one pass over the particles (what a
/// whole step runs without MLS): each worker range evaluates its particles'
/// weights into the cache and scatters them while they are still in the
/// core's cache. The same values and sums in the same order as the two
/// stages. Without a stored cache it is `p2g::p2g` with the weights
/// evaluated on the spot. Arguments as `shape_eval` and `p2g::p2g`.
#[allow(clippy::too_many_arguments)]
pub fn shape_eval_p2g(
    shape: &Shape,
    grid: &Grid,
    x: &[[f64; 2]],
    lambda: &mut [[f64; 2]],
    cache: &mut ShapeCache,
    mass: &[f64],
    v: &[[f64; 2]],
    a: &[[f64; 2]],
    a_factor: f64,
    mv: &mut [[f64; 3]],
    scatter: &mut Scatter<5>,
) -> Result<(), Fault> {
    let n = x.len();
    if !cache.is_stored(n) {
        let weights = Weights::eval(shape, grid);
        return p2g::p2g(weights, x, mass, v, a, a_factor, mv, scatter);
    }
    let s = cache.stride;
    let len = Scatter::<5>::range_len(n);
    let particle = |p: usize,
                    lam: &mut [f64; 2],
                    cnt: &mut u16,
                    nodes: &mut [u32],
                    w: &mut [[f64; 3]],
                    acc: &mut [[f64; 5]]| {
        match shape.eval(grid, x[p], lam, nodes, w) {
            Ok(k) => {
                *cnt = k as u16;
                add_particle(
                    &Slices(&nodes[..k], &w[..k]),
                    mass[p],
                    v[p],
                    accel(a, p),
                    acc,
                );
                None
            }
            Err(e) => {
                *cnt = 0;
                Some(Fault::at(p, FaultKind::Shape(e)))
            }
        }
    };
    let ranges = cache
        .count
        .par_chunks_mut(len)
        .zip(cache.nodes.par_chunks_mut(len * s))
        .zip(cache.w.par_chunks_mut(len * s));
    let (fault, used) = if lambda.is_empty() {
        scatter.accumulate(
            mv.len(),
            n,
            ranges,
            |first, ((c, nodes), w), acc| {
                let mut fault = None;
                for (k, ((c, nodes), w)) in c
                    .iter_mut()
                    .zip(nodes.chunks_mut(s))
                    .zip(w.chunks_mut(s))
                    .enumerate()
                {
                    let f = particle(first + k, &mut [0.0; 2], c, nodes, w, acc);
                    Fault::note(&mut fault, f);
                }
                fault
            },
            Fault::first,
            || None,
        )
    } else {
        scatter.accumulate(
            mv.len(),
            n,
            ranges.zip(lambda.par_chunks_mut(len)),
            |first, (((c, nodes), w), lam), acc| {
                let mut fault = None;
                for (k, (((c, nodes), w), lam)) in c
                    .iter_mut()
                    .zip(nodes.chunks_mut(s))
                    .zip(w.chunks_mut(s))
                    .zip(lam)
                    .enumerate()
                {
                    let f = particle(first + k, lam, c, nodes, w, acc);
                    Fault::note(&mut fault, f);
                }
                fault
            },
            Fault::first,
            || None,
        )
    };
    if n > 0 {
        scatter.reduce_map(mv, used, |s| combine(s, a_factor));
    }
    fault.map_or(Ok(()), Err)
}
