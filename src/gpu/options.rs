//! Choices of the GPU path that are not part of the scene (`GpuOptions`):
//! stored LME weights, gather or scatter, per-bin scatter. A leaf that the
//! buffers and pipelines read without naming the backend (`gpu/mod.rs`).

use crate::model::shape::Shape;
use crate::model::{Integrator, Model};

/// Choices of the GPU path that are not part of the scene.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct GpuOptions {
    /// LME: store N and ∇N per particle and search-box slot in `lme_newton`
    /// instead of recomputing them from (λ, log Z, J⁻¹) in each pass. Off by
    /// default: docs/performance.md has the measurement that decided it.
    pub lme_stored: bool,
    /// `p2g` and `forces` as node-centred gathers over particles binned by
    /// cell (`Some(true)`) or as particle-centred scatters with float
    /// atomics (`Some(false)`); `None` picks what measured faster
    /// (docs/performance.md): the gather for linear shapes on a regular
    /// grid, the scatter for the rest, whose wider stencils make each
    /// node visit more particles and evaluate each one's shape anew.
    /// MUSL and MLS always scatter.
    pub gather: Option<bool>,
    /// `p2g` and `forces` scattered per bin of particles that share their
    /// stencil (`Some(true)`: one invocation per bin sums its particles in
    /// registers, then one atomic per node of the stencil) or per particle
    /// (`Some(false)`); `None` picks what measured faster
    /// (docs/performance.md): per bin for B-splines and LME. Only linear
    /// shapes and B-splines on a regular grid and LME on any grid, where
    /// they do not gather, without MLS or MUSL.
    pub patch: Option<bool>,
}

impl GpuOptions {
    /// Whether `p2g` and `forces` gather (`pipelines::Variant::gather`).
    pub fn gathers(&self, model: &Model) -> bool {
        let auto = matches!(model.shape, Shape::Linear) && !model.grid.is_perturbed();
        // Contact pairs scatter: a node of one field would walk the
        // particles of every field near it.
        self.gather.unwrap_or(auto)
            && !model.mls
            && model.integrator != Integrator::Musl
            && model.contact.is_none()
    }

    /// Whether `p2g` and `forces` scatter per bin (`pipelines::Variant::patch`).
    pub fn patches(&self, model: &Model) -> bool {
        // A bin's particles share their stencil: for linear shapes and
        // B-splines its cell on a regular grid; for LME its search box, a
        // box of logical node indices on any grid.
        let shares = match model.shape {
            Shape::Lme(_) => true,
            Shape::Linear | Shape::Bspline(_) => !model.grid.is_perturbed(),
            Shape::Ugimp(_) => false,
        };
        // A bin's particles may belong to different fields with contact pairs.
        let fits = shares
            && !model.mls
            && model.integrator != Integrator::Musl
            && model.contact.is_none()
            && !self.gathers(model);
        let auto = matches!(model.shape, Shape::Bspline(_) | Shape::Lme(_));
        self.patch.unwrap_or(auto) && fits
    }
}
