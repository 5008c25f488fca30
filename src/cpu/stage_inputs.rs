//! What every CPU stage reads besides the model: the particles' shape
//! functions for the step (`ShapeCache` when stored, else `Weights`
//! evaluates them where a loop uses them) and the body force per unit mass
//! (`body_force`). A leaf, so the stage files name it and not the backend
//! (`cpu/mod.rs`) that calls them.

use crate::model::shape::separable::{Lanes, Separable, Stencil1};
use crate::model::shape::{Shape, ShapeFault};
use crate::model::{Grid, Integrator, Model};
use rayon::iter::Either;
use rayon::prelude::*;

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
}

/// One particle's nodes and [N, ∂N/∂x, ∂N/∂y], slot by slot, as a loop
/// over its nodes reads them: stored slots (`Slots`), or a separable
/// shape's 1-D bases whose products are taken where they are used
/// (`FixedView`), so no loop stores and reloads them.
pub trait Stencil {
    /// `f(node, [N, ∂N/∂x, ∂N/∂y])` for each slot in order; a loop that
    /// reads N only leaves the gradients' products unused (and the
    /// compiler drops them).
    fn each(&self, f: impl FnMut(u32, [f64; 3]));
}

/// Stored slots: nodes and weights side by side.
#[derive(Clone, Copy)]
pub struct Slices<'a>(pub &'a [u32], pub &'a [[f64; 3]]);

impl Stencil for Slices<'_> {
    #[inline(always)]
    fn each(&self, mut f: impl FnMut(u32, [f64; 3])) {
        for (&node, w) in self.0.iter().zip(self.1) {
            f(node, *w);
        }
    }
}

/// Where a loop over the particles takes each particle's nodes and
/// [N, ∂N/∂x, ∂N/∂y]: `Weights` (the stored cache, or `Shape::eval` at the
/// particle), or a separable shape as a type of its own (`Fixed`), whose
/// slots are a constant the compiler unrolls the loops over the nodes by.
/// The loops are generic over it and `with_weights!` picks the type once
/// per loop. All give the same numbers (`Separable::eval_fixed` is
/// `Shape::eval`, tested in `model::shape::separable`).
pub trait ParticleWeights: Sync {
    /// A loop's scratch for one particle's weights (`get`).
    type Scratch: Default;
    /// A loop's scratch for the weights of `BATCH` particles (`prepare`).
    type Batch: Default;
    /// What a particle's weights read as.
    type View<'s>: Stencil
    where
        Self: 's;
    /// Particle `p`'s nodes and weights at `x` (its position at the step's
    /// shape evaluation), gradients only when `GRAD`.
    fn get<'s, const GRAD: bool>(
        &'s self,
        p: usize,
        x: [f64; 2],
        scratch: &'s mut Self::Scratch,
    ) -> Result<Self::View<'s>, ShapeFault>;
    /// Evaluates the weights of particles `first + j` at `x[j]` for the
    /// `x.len()` ≤ `BATCH` lanes j of `batch`, which `view` then reads:
    /// the loops that take the particles by batches evaluate them in
    /// lanes, as they depend on the positions alone.
    fn prepare<const GRAD: bool>(&self, first: usize, x: &[[f64; 2]], batch: &mut Self::Batch);
    /// Particle `p`'s weights from lane `j` of what `prepare` left.
    fn view<'s>(
        &'s self,
        p: usize,
        batch: &'s Self::Batch,
        j: usize,
    ) -> Result<Self::View<'s>, ShapeFault>;
}

/// Particles a loop evaluates the weights of at once
/// (`ParticleWeights::prepare`).
pub const BATCH: usize = 8;

/// `Weights`' scratch: the slots and what the evaluation returned.
pub struct Prepared {
    slots: Slots,
    k: Result<usize, ShapeFault>,
}

impl Default for Prepared {
    fn default() -> Self {
        Prepared {
            slots: Slots::default(),
            k: Ok(0),
        }
    }
}

impl Weights<'_> {
    #[inline(always)]
    fn prepare_one<const GRAD: bool>(&self, x: [f64; 2], s: &mut Prepared) {
        let slots = &mut s.slots;
        s.k = match self {
            Weights::Cache(_) => Ok(0),
            Weights::Separable(sep) => sep.eval::<GRAD>(x, &mut slots.nodes, &mut slots.w),
            Weights::Eval { shape, grid } => {
                shape.eval(grid, x, &mut [0.0; 2], &mut slots.nodes, &mut slots.w)
            }
        };
    }

    #[inline(always)]
    fn view_one<'s>(&'s self, p: usize, s: &'s Prepared) -> Result<Slices<'s>, ShapeFault> {
        match self {
            Weights::Cache(c) => {
                let (n, w) = c.particle(p);
                Ok(Slices(n, w))
            }
            _ => s.k.map(|k| Slices(&s.slots.nodes[..k], &s.slots.w[..k])),
        }
    }
}

impl ParticleWeights for Weights<'_> {
    type Scratch = Prepared;
    type Batch = [Prepared; BATCH];
    type View<'s>
        = Slices<'s>
    where
        Self: 's;
    #[inline(always)]
    fn get<'s, const GRAD: bool>(
        &'s self,
        p: usize,
        x: [f64; 2],
        s: &'s mut Prepared,
    ) -> Result<Slices<'s>, ShapeFault> {
        self.prepare_one::<GRAD>(x, s);
        self.view_one(p, s)
    }
    #[inline(always)]
    fn prepare<const GRAD: bool>(&self, _first: usize, x: &[[f64; 2]], b: &mut [Prepared; BATCH]) {
        for (x, s) in x.iter().zip(b) {
            self.prepare_one::<GRAD>(*x, s);
        }
    }
    #[inline(always)]
    fn view<'s>(
        &'s self,
        p: usize,
        b: &'s [Prepared; BATCH],
        j: usize,
    ) -> Result<Slices<'s>, ShapeFault> {
        self.view_one(p, &b[j])
    }
}

/// A separable shape with exactly K slots (linear 4, quadratic B-splines
/// 9, cubic 16), evaluated on the spot.
#[derive(Clone, Copy)]
pub struct Fixed<const K: usize>(pub Separable);

/// `Fixed`'s view of one particle: its stencil's 1-D bases (one lane of
/// `Lanes`), with the shape.
pub struct FixedView<'a, const K: usize> {
    sep: &'a Separable,
    stencil: Stencil1<K>,
}

impl<const K: usize> Stencil for FixedView<'_, K> {
    #[inline(always)]
    fn each(&self, f: impl FnMut(u32, [f64; 3])) {
        self.sep.each(&self.stencil, f);
    }
}

impl<const K: usize> Fixed<K> {
    #[inline(always)]
    fn view_lane<const L: usize>(
        &self,
        lanes: &Lanes<K, L>,
        j: usize,
    ) -> Result<FixedView<'_, K>, ShapeFault> {
        match lanes.fault(j) {
            Some(e) => Err(e),
            None => Ok(FixedView {
                sep: &self.0,
                stencil: lanes.lane(j),
            }),
        }
    }
}

impl<const K: usize> ParticleWeights for Fixed<K> {
    type Scratch = Lanes<K, 1>;
    type Batch = Lanes<K, BATCH>;
    type View<'s> = FixedView<'s, K>;
    #[inline(always)]
    fn get<'s, const GRAD: bool>(
        &'s self,
        _p: usize,
        x: [f64; 2],
        s: &'s mut Lanes<K, 1>,
    ) -> Result<FixedView<'s, K>, ShapeFault> {
        self.0.bases_lanes::<K, 1>(&[x], s);
        self.view_lane(s, 0)
    }
    #[inline(always)]
    fn prepare<const GRAD: bool>(&self, _first: usize, x: &[[f64; 2]], b: &mut Lanes<K, BATCH>) {
        self.0.bases_lanes::<K, BATCH>(x, b);
    }
    #[inline(always)]
    fn view<'s>(
        &'s self,
        _p: usize,
        b: &'s Lanes<K, BATCH>,
        j: usize,
    ) -> Result<FixedView<'s, K>, ShapeFault> {
        self.view_lane(b, j)
    }
}

/// Runs `$body` with `$w` bound to a `ParticleWeights` for `$weights` (a
/// `Weights`): a `Fixed` of the separable shape's slots, else the
/// `Weights` itself. `$body` is compiled once per type.
macro_rules! with_weights {
    ($weights:expr, |$w:ident| $body:expr) => {{
        let weights: $crate::cpu::stage_inputs::Weights<'_> = $weights;
        use $crate::cpu::stage_inputs::Fixed;
        use $crate::model::shape::separable::SeparableClass as C;
        match weights {
            $crate::cpu::stage_inputs::Weights::Separable(s) => match s.class() {
                C::Linear => {
                    let $w = &Fixed::<4>(s);
                    $body
                }
                C::Bspline2 => {
                    let $w = &Fixed::<9>(s);
                    $body
                }
                C::Bspline3 => {
                    let $w = &Fixed::<16>(s);
                    $body
                }
            },
            _ => {
                let $w = &weights;
                $body
            }
        }
    }};
}
pub(crate) use with_weights;

/// The body force per unit mass of every particle at one time
/// (`body_force`): gravity, plus the manufactured solution's and the
/// loads' shares where the scene has them.
pub struct BodyForce<'a> {
    g: [f64; 2],
    t: f64,
    mms: &'a Option<crate::model::AlignedVibration>,
    ext: &'a Option<crate::model::ExternalForces>,
    x0: &'a [[f64; 2]],
    mass: &'a [f64],
}

impl BodyForce<'static> {
    /// The same `g` (m/s²) on every particle.
    pub fn uniform(g: [f64; 2]) -> Self {
        BodyForce {
            g,
            t: 0.0,
            mms: &None,
            ext: &None,
            x0: &[],
            mass: &[],
        }
    }
}

impl BodyForce<'_> {
    /// Particle `i`'s (m/s²).
    #[inline(always)]
    pub fn at(&self, i: usize) -> [f64; 2] {
        let mut b = self.g;
        if let Some(s) = self.mms {
            let s = s.body_force(self.x0[i], self.t);
            b = [b[0] + s[0], b[1] + s[1]];
        }
        if let Some(e) = self.ext {
            let f = e.at(i, self.t);
            b = [b[0] + f[0] / self.mass[i], b[1] + f[1] / self.mass[i]];
        }
        b
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
) -> BodyForce<'a> {
    BodyForce {
        g: gravity.map_or([0.0; 2], |g| g.at(t)),
        t,
        mms,
        ext,
        x0,
        mass,
    }
}

/// Per-particle `Option<&mut T>` over `v`, or `None` n times when `v` is empty.
pub fn optional<T: Send>(
    v: &mut [T],
    n: usize,
) -> impl IndexedParallelIterator<Item = Option<&mut T>> {
    if v.is_empty() {
        Either::Left((0..n).into_par_iter().map(|_| None))
    } else {
        Either::Right(v.par_iter_mut().map(Some))
    }
}

/// `optional` by chunks of `len`.
pub fn optional_chunks<T: Send>(
    v: &mut [T],
    n: usize,
    len: usize,
) -> impl IndexedParallelIterator<Item = Option<&mut [T]>> {
    if v.is_empty() {
        Either::Left((0..n.div_ceil(len)).into_par_iter().map(|_| None))
    } else {
        Either::Right(v.par_chunks_mut(len).map(Some))
    }
}
