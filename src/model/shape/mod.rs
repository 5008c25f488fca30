//! Shape functions on the CPU: given a particle position, write the nodes it
//! sees with N_a and ∇N_a. One enum, one `eval`; each kind in its own file.
//! WGSL twins live in `shaders/shared/shape_*.wgsl`.

pub mod bspline;
mod fault;
pub mod index;
pub mod linear;
pub mod lme;
pub mod separable;
pub mod ugimp;

pub use fault::ShapeFault;

use crate::model::Grid;
use crate::scene::{BsplineKnots, ShapeKind, SolverSpec};

/// A shape function, with its parameters resolved for one scene.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    Linear,
    Ugimp(ugimp::Ugimp),
    Lme(lme::Lme),
    Bspline(bspline::Bspline),
}

impl Shape {
    /// The scene's shape function. `ppc` is the particles per cell per
    /// direction (used by uGIMP for the particle half-width).
    pub fn new(solver: &SolverSpec, h: f64, ppc: u32, perturb: f64) -> Shape {
        match solver.shape {
            ShapeKind::Linear => Shape::Linear,
            ShapeKind::Ugimp => Shape::Ugimp(ugimp::Ugimp::new(h, ppc)),
            ShapeKind::Lme => {
                Shape::Lme(lme::Lme::new(solver.lme_gamma, solver.lme_tol, h, perturb))
            }
            ShapeKind::Bspline2 | ShapeKind::Bspline3 => Shape::Bspline(bspline::Bspline {
                degree: if solver.shape == ShapeKind::Bspline2 {
                    2
                } else {
                    3
                },
                cells: solver.bspline_knots == Some(BsplineKnots::Cells),
            }),
        }
    }

    pub fn kind(&self) -> ShapeKind {
        match self {
            Shape::Linear => ShapeKind::Linear,
            Shape::Ugimp(_) => ShapeKind::Ugimp,
            Shape::Lme(_) => ShapeKind::Lme,
            Shape::Bspline(b) if b.degree == 2 => ShapeKind::Bspline2,
            Shape::Bspline(_) => ShapeKind::Bspline3,
        }
    }

    /// Largest number of nodes one particle can see (slots per particle).
    pub fn max_nodes(&self) -> usize {
        match self {
            Shape::Linear => 4,
            Shape::Ugimp(_) => 9,
            Shape::Lme(l) => l.max_nodes(),
            Shape::Bspline(b) => b.max_nodes(),
        }
    }

    /// Whole cells the support reaches beyond a particle: the grid keeps this
    /// many cells around the bodies so no support is cut at t = 0.
    pub fn reach_cells(&self) -> usize {
        match self {
            Shape::Linear | Shape::Ugimp(_) => 1,
            Shape::Lme(l) => l.reach_cells(),
            // Interior supports span ±(p + 1)/2 cells.
            Shape::Bspline(_) => 2,
        }
    }

    /// Cells the grid keeps beyond a wall (a fixed half-plane): uGIMP's
    /// particle domains reach across the wall's first node line; the
    /// others need no nodes inside the wall (B-splines: the open knot vector
    /// makes the boundary basis interpolate the wall).
    pub fn wall_ghost_cells(&self) -> usize {
        match self {
            Shape::Ugimp(_) => 1,
            Shape::Linear | Shape::Lme(_) | Shape::Bspline(_) => 0,
        }
    }

    /// Distance (m) a particle must keep from the edge of a grid of spacing
    /// `h` for the shape function to be defined; closer is "left the grid".
    pub fn edge_margin(&self, h: f64) -> f64 {
        match self {
            Shape::Linear => 0.0,
            Shape::Ugimp(u) => u.lp,
            // LME is defined anywhere inside the nodes' convex hull; a particle
            // very close to the hull shows up as a Newton failure instead.
            Shape::Lme(_) => 0.0,
            // The `cells` layout's bases live on the cells, e cells inside
            // its shifted nodes.
            Shape::Bspline(b) => b.end() * h,
        }
    }

    /// Evaluates the shape function at `x`. Writes node indices to `nodes`
    /// and (N, ∂N/∂x, ∂N/∂y) to `w`; returns how many slots were written.
    /// `lambda` is the particle's LME multiplier (read as the warm start,
    /// written with the solution); other shapes ignore it.
    #[inline]
    pub fn eval(
        &self,
        grid: &Grid,
        x: [f64; 2],
        lambda: &mut [f64; 2],
        nodes: &mut [u32],
        w: &mut [[f64; 3]],
    ) -> Result<usize, ShapeFault> {
        match self {
            Shape::Linear => linear::eval(grid, x, nodes, w),
            Shape::Ugimp(u) => u.eval(grid, x, nodes, w),
            Shape::Lme(l) => l.eval(grid, x, lambda, nodes, w).map(|(n, _)| n),
            Shape::Bspline(b) => b.eval(grid, x, nodes, w),
        }
    }
}
