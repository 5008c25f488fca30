//! Integration geometry of MLS reconstruction (B-spline paper §3): the
//! integration cells (knot spans of a B-spline, grid cells otherwise) and
//! their 2 × 2 Gauss points. Backend-neutral: the CPU's `cpu/mls.rs`, the
//! GPU's parameters and fault reports use the same numbering.

use crate::model::Grid;
use crate::model::shape::Shape;

/// Integration-cell breaks of `shape` along an axis of `n` nodes (lattice units):
/// the distinct knots for B-splines, the nodes otherwise.
pub fn breaks(shape: &Shape, n: usize) -> Vec<f64> {
    match shape {
        Shape::Bspline(b) => {
            let (p, e) = (b.degree, b.end());
            let mut out: Vec<f64> = (0..(n + p + 1) as i64)
                .map(|k| crate::model::shape::bspline::knot(k, n, p, e))
                .collect();
            out.dedup();
            out
        }
        _ => (0..n).map(|i| i as f64).collect(),
    }
}

/// Gauss points `Mls::new` makes for `shape` on `grid`.
pub fn gauss_points(shape: &Shape, grid: &Grid) -> usize {
    4 * (breaks(shape, grid.nx).len() - 1) * (breaks(shape, grid.ny).len() - 1)
}

/// Position (m) and weight ω (m²) of Gauss point `g` of the integration
/// cells with breaks `bx`, `by` (lattice units): g = 4 (sy · spans_x + sx) + k,
/// k = (−,−), (+,−), (−,+), (+,+).
pub fn gauss_point(bx: &[f64], by: &[f64], grid: &Grid, g: usize) -> ([f64; 2], f64) {
    let span = g / 4;
    let (sx, sy) = (span % (bx.len() - 1), span / (bx.len() - 1));
    let (a, b) = (
        if g % 2 == 1 { 1.0 } else { -1.0 },
        if g % 4 >= 2 { 1.0 } else { -1.0 },
    );
    let gq = 0.5 / 3f64.sqrt();
    let (x0, x1, y0, y1) = (bx[sx], bx[sx + 1], by[sy], by[sy + 1]);
    let u = 0.5 * (x0 + x1) + a * gq * (x1 - x0);
    let v = 0.5 * (y0 + y1) + b * gq * (y1 - y0);
    (
        [grid.min[0] + u * grid.h, grid.min[1] + v * grid.h],
        0.25 * (x1 - x0) * (y1 - y0) * grid.h * grid.h,
    )
}

/// Position (m) of Gauss point `g` of `shape` on `grid`.
pub fn gauss_point_position(shape: &Shape, grid: &Grid, g: usize) -> [f64; 2] {
    gauss_point(&breaks(shape, grid.nx), &breaks(shape, grid.ny), grid, g).0
}
