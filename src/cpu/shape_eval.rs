//! Stage `shape_eval`: N and ∇N of every particle at its current position,
//! into the per-step shape cache read by p2g, stress, forces and g2p. For
//! LME this is the per-particle Newton solve on λ (warm-started).
//! GPU twin: `shaders/lme_newton.wgsl` (LME); other shapes are evaluated
//! inline in each GPU pass.

use super::ShapeCache;
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
