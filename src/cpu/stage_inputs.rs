//! What every CPU stage reads besides the model: the particles' shape
//! functions for the step (`ShapeCache` when stored, else `Weights`
//! evaluates them where a loop uses them) and the body force per unit mass
//! (`body_force`). A leaf, so the stage files name it and not the backend
//! (`cpu/mod.rs`) that calls them.

use crate::model::shape::separable::Separable;
use crate::model::shape::{Shape, ShapeFault};
use crate::model::{Grid, Integrator, Model};

/// N and ∇N of every particle for the current step: `stride` slots per
/// particle, `count[p]` of them used.
#[derive(Debug, Clone)]
pub struct ShapeCache {
    pub stride: usize,
    pub count: Vec<u16>,
    pub nodes: Vec<u32>,
    /// [N, ∂N/∂x, ∂N/∂y] per slot.
    pub w: Vec<[f64; 3]>,
}

impl ShapeCache {
    pub fn new(particles: usize, stride: usize) -> Self {
        ShapeCache {
            stride,
            count: vec![0; particles],
            nodes: vec![0; particles * stride],
            w: vec![[0.0; 3]; particles * stride],
        }
    }

    /// The nodes and weights of particle `p`.
    #[inline]
    pub fn particle(&self, p: usize) -> (&[u32], &[[f64; 3]]) {
        let (o, n) = (p * self.stride, self.count[p] as usize);
        (&self.nodes[o..o + n], &self.w[o..o + n])
    }

    /// A cache that stores nothing (`needed` is false): the loops
    /// evaluate the weights where they use them (`Weights::Eval`).
    pub fn empty(stride: usize) -> Self {
        ShapeCache::new(0, stride)
    }

    /// Whether the cache holds `particles` particles' slots (it is stored
    /// and every shape evaluation fills it).
    #[inline]
    pub fn is_stored(&self, particles: usize) -> bool {
        self.count.len() == particles && particles > 0
    }

    /// Whether a CPU step of `model` must store the shape functions: a
    /// costly shape (LME: a Newton solve per particle), or a loop that reads
    /// the weights apart from the particle's own (the walls' touch and
    /// contact, contact pairs' node offsets and gaps, the cell average, MLS,
    /// and MUSL, whose remap and stress use the step's start weights after
    /// the particles moved). Otherwise p2g, stress with forces, and g2p each
    /// evaluate N and ∇N at the particle as they need them (as Taichi does),
    /// and nothing is stored.
    pub fn needed(model: &Model) -> bool {
        matches!(model.shape, Shape::Lme(_))
            || !model.walls.is_empty()
            || model.contact.is_some()
            || model.cell_average_volumetric
            || model.mls
            || model.integrator == Integrator::Musl
    }

    /// The cache of a CPU step of `model`: `particles` × `max_nodes` slots
    /// when `needed`, else empty.
    pub fn for_model(model: &Model) -> Self {
        let stride = model.shape.max_nodes();
        if Self::needed(model) {
            ShapeCache::new(model.particles.len(), stride)
        } else {
            ShapeCache::empty(stride)
        }
    }

    /// Bytes the cache of `model` holds per particle: a count, then per slot
    /// a node index and 3 f64; 0 when not `needed`.
    pub fn bytes_per_particle(model: &Model) -> f64 {
        if Self::needed(model) {
            2.0 + model.shape.max_nodes() as f64 * (4.0 + 24.0)
        } else {
            0.0
        }
    }
}

/// Most slots one particle's weights take (cubic B-splines: 4 × 4; LME is
/// always stored in the cache).
pub const MAX_SLOTS: usize = 16;

/// One particle's nodes and weights evaluated on the spot (a loop's
/// scratch, on the stack).
#[derive(Debug, Clone, Copy)]
pub struct Slots {
    pub nodes: [u32; MAX_SLOTS],
    pub w: [[f64; 3]; MAX_SLOTS],
}

impl Default for Slots {
    fn default() -> Self {
        Slots {
            nodes: [0; MAX_SLOTS],
            w: [[0.0; 3]; MAX_SLOTS],
        }
    }
}

/// Where a loop takes a particle's N and ∇N from: the step's stored
/// cache, or the shape evaluated at the particle's position where it is
/// used (`ShapeCache::needed` false): as products of 1-D weights for the
/// separable shapes, else by `Shape::eval`. All give the same numbers: the
/// cache holds what `Shape::eval` wrote at the same position.
#[derive(Clone, Copy)]
pub enum Weights<'a> {
    Cache(&'a ShapeCache),
    Separable(Separable),
    Eval { shape: &'a Shape, grid: &'a Grid },
}

impl<'a> Weights<'a> {
    /// The cache when it is stored for `particles` particles, else the
    /// shape evaluated on the spot.
    pub fn of(cache: &'a ShapeCache, particles: usize, shape: &'a Shape, grid: &'a Grid) -> Self {
        if cache.is_stored(particles) {
            Weights::Cache(cache)
        } else {
            Self::eval(shape, grid)
        }
    }

    /// The shape evaluated on the spot: separable where it is.
    pub fn eval(shape: &'a Shape, grid: &'a Grid) -> Self {
        debug_assert!(shape.max_nodes() <= MAX_SLOTS);
        match shape.separable(grid) {
            Some(s) => Weights::Separable(s),
            None => Weights::Eval { shape, grid },
        }
    }

    /// Particle `p`'s nodes and [N, ∂N/∂x, ∂N/∂y], at `x` (its position at
    /// the step's shape evaluation) when evaluated, into `slots`.
    #[inline(always)]
    pub fn particle<'s>(
        &'s self,
        p: usize,
        x: [f64; 2],
        slots: &'s mut Slots,
    ) -> Result<(&'s [u32], &'s [[f64; 3]]), ShapeFault> {
        self.particle_with::<true>(p, x, slots)
    }

    /// As `particle`, where the loop reads N only: the separable shapes
    /// leave the gradients unwritten.
    #[inline(always)]
    pub fn particle_values<'s>(
        &'s self,
        p: usize,
        x: [f64; 2],
        slots: &'s mut Slots,
    ) -> Result<(&'s [u32], &'s [[f64; 3]]), ShapeFault> {
        self.particle_with::<false>(p, x, slots)
    }

    #[inline(always)]
    fn particle_with<'s, const GRAD: bool>(
        &'s self,
        p: usize,
        x: [f64; 2],
        slots: &'s mut Slots,
    ) -> Result<(&'s [u32], &'s [[f64; 3]]), ShapeFault> {
        match self {
            Weights::Cache(c) => Ok(c.particle(p)),
            Weights::Separable(s) => {
                let k = s.eval::<GRAD>(x, &mut slots.nodes, &mut slots.w)?;
                Ok((&slots.nodes[..k], &slots.w[..k]))
            }
            Weights::Eval { shape, grid } => {
                let k = shape.eval(grid, x, &mut [0.0; 2], &mut slots.nodes, &mut slots.w)?;
                Ok((&slots.nodes[..k], &slots.w[..k]))
            }
        }
    }
}
/// Body force per unit mass on particle `i` at time `t` (m/s²): gravity
/// with its ramp, plus a manufactured solution's load at the particle's
/// reference position, plus the particle's share of the tractions and
/// point loads divided by its mass (the stages multiply by m_p again).
pub(crate) fn body_force<'a>(
    gravity: Option<crate::model::Gravity>,
    mms: &'a Option<crate::model::AlignedVibration>,
    ext: &'a Option<crate::model::ExternalForces>,
    x0: &'a [[f64; 2]],
    mass: &'a [f64],
    t: f64,
) -> impl Fn(usize) -> [f64; 2] + Sync + 'a {
    let g = gravity.map_or([0.0; 2], |g| g.at(t));
    move |i: usize| {
        let mut b = g;
        if let Some(s) = mms {
            let s = s.body_force(x0[i], t);
            b = [b[0] + s[0], b[1] + s[1]];
        }
        if let Some(e) = ext {
            let f = e.at(i, t);
            b = [b[0] + f[0] / mass[i], b[1] + f[1] / mass[i]];
        }
        b
    }
}
