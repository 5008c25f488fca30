//! The implicit step's node set when `solver.method = "gmm"` (implicit-MPM
//! paper Algorithm 2): the body's own node cloud (`gmm::Cloud`) in place
//! of the grid. What differs from implicit MPM is here, and only here:
//!
//! - shape functions: each particle gathers the nodes within the search
//!   radius (a cell list rebuilt each step) and evaluates the basis
//!   (`gmm::Basis`, LME or MLS) over them, into the same `ShapeCache` the
//!   grid's shapes fill, so the residual, Jacobian and solve
//!   (`assemble`) run unchanged;
//! - Newmark's predictor reads the nodes' own velocity and acceleration
//!   of the last converged step (like FEM; MPM maps them from the
//!   particles);
//! - after convergence the nodes move with the solution: x += Δu, the
//!   Newmark acceleration and velocity (eqs. 43–44) become their state.

use super::assemble::Newmark;
use crate::cpu::ShapeCache;
use crate::error::SceneError;
use crate::gmm::{Basis, Cloud};
use crate::model::fault::{Fault, FaultKind};
use crate::model::{GmmSettings, Model};
use rayon::prelude::*;

/// A particle's cloud may hold this many times the nodes of the undeformed
/// lattice's disk before the cache grows (it grows on demand anyway).
const STRIDE_SLACK: f64 = 2.0;

/// The cloud, its basis and each particle's LME multiplier.
pub struct GmmNodes {
    pub cloud: Cloud,
    basis: Basis,
    /// Search radius (m).
    radius: f64,
    /// Per particle: LME's λ of the last step (warm start; unused by MLS).
    lambda: Vec<[f64; 2]>,
}

impl GmmNodes {
    pub fn new(model: &Model, s: &GmmSettings) -> Result<GmmNodes, SceneError> {
        let cloud = Cloud::from_model(model)?;
        let h = cloud.h;
        Ok(GmmNodes {
            basis: Basis::new(s, h),
            radius: s.search_radius * h,
            lambda: vec![[0.0; 2]; model.particles.len()],
            cloud,
        })
    }

    /// "GMM-LME" or "GMM-MLS", for the backend's name.
    pub fn label(&self) -> &'static str {
        match self.basis {
            Basis::Lme(_) => "GMM-LME",
            Basis::Mls { .. } => "GMM-MLS",
        }
    }

    /// Slots per particle in the shape cache: the nodes of the lattice
    /// within the radius (π (r/h + √2/2)², every such node's unit cell lying
    /// in that disk) times `STRIDE_SLACK`.
    pub fn stride(&self) -> usize {
        let r = self.radius / self.cloud.h + std::f64::consts::FRAC_1_SQRT_2;
        (STRIDE_SLACK * std::f64::consts::PI * r * r).ceil() as usize
    }

    /// N and ∇N of every particle over its cloud, into `cache` (grown when
    /// a cloud outnumbers its slots).
    pub fn shape_eval(&mut self, x: &[[f64; 2]], cache: &mut ShapeCache) -> Result<(), Fault> {
        self.cloud.rebuild(self.radius);
        let (cloud, basis, radius) = (&self.cloud, &self.basis, self.radius);
        loop {
            let stride = cache.stride;
            let (fault, need) = cache
                .nodes
                .par_chunks_mut(stride)
                .zip(cache.w.par_chunks_mut(stride))
                .zip(cache.count.par_iter_mut())
                .zip(self.lambda.par_iter_mut())
                .enumerate()
                .with_min_len(64)
                .map_init(Vec::new, |list, (p, (((nodes, w), count), lam))| {
                    cloud.gather(x[p], radius, list);
                    if list.len() > stride {
                        return (None, list.len());
                    }
                    nodes[..list.len()].copy_from_slice(list);
                    match basis.eval(x[p], &cloud.x, nodes, list.len(), lam, w) {
                        Ok(kept) => {
                            *count = kept as u16;
                            (None, 0)
                        }
                        Err(e) => (Some(Fault::at(p, FaultKind::Shape(e))), 0),
                    }
                })
                .reduce(|| (None, 0), |a, b| (Fault::first(a.0, b.0), a.1.max(b.1)));
            if need > stride {
                *cache = ShapeCache::new(x.len(), need + need / 2);
                continue;
            }
            return fault.map_or(Ok(()), Err);
        }
    }

    /// The nodes take the converged step (Algorithm 2, step 3): position
    /// and displacement += Δu, acceleration from Newmark (eq. 44),
    /// velocity by the trapezoid of the accelerations (eq. 43); zero in a
    /// static analysis.
    pub fn advance(&mut self, du: &[[f64; 2]], newmark: &Newmark) {
        let c = &mut self.cloud;
        let (gamma, dt) = (newmark.gamma, newmark.dt);
        for (n, dn) in du.iter().enumerate() {
            let a = newmark.accel(*dn, c.v[n], c.a[n]);
            for d in 0..2 {
                c.x[n][d] += dn[d];
                c.u[n][d] += dn[d];
                if newmark.is_static {
                    c.v[n][d] = 0.0;
                } else {
                    c.v[n][d] += dt * ((1.0 - gamma) * c.a[n][d] + gamma * a[d]);
                }
            }
            c.a[n] = a;
        }
    }
}
