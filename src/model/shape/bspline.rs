//! Tensor-product B-splines of degree 2 or 3 (Cox-de Boor), with open knot
//! vectors at the grid's edge, one basis function per grid node.
//!
//! Per direction, over n nodes the knot vector (in lattice units) is
//! t_k = e for k ≤ p, t_k = n − 1 − e for k ≥ n, and t_k = k − (p + 1)/2
//! in between: quadratic interior knots at cell midpoints, cubic ones at
//! the nodes. That is the usual uniform B-spline space, clamped at both
//! ends so the first and last basis functions interpolate the boundary (a
//! fixed boundary node fixes the boundary exactly, and no ghost nodes are
//! needed). The basis "positions" that reproduce linear fields are the
//! Greville abscissae (`greville`), which equal the nodes away from the
//! edge.
//!
//! The end offset e (`Bspline::end`) sets where the clamped ends sit:
//! - `midpoints` layout (`solver.bspline_knots`, the default): e = 0, the
//!   ends on the first and last nodes, end spans of (p + 1)/2 cells;
//! - `cells` layout (the B-spline paper's Fig. 1): e = (p − 1)/2, on a
//!   node lattice shifted out by e cells with p − 1 more nodes per
//!   direction (`Model::new`): then every knot span is one cell of the
//!   scene's grid (knots on its lines), n_c + p bases over n_c cells, and
//!   the bases live on the cells' extent, e cells inside the nodes'.
//!
//! WGSL twin: `shaders/shared/shape_bspline.wgsl`.

use super::ShapeFault;
use crate::model::Grid;

/// Largest degree supported.
pub const MAX_DEGREE: usize = 3;

#[derive(Debug, Clone, PartialEq)]
pub struct Bspline {
    /// 2 (quadratic) or 3 (cubic).
    pub degree: usize,
    /// The knots on the grid lines (`solver.bspline_knots = "cells"`)
    /// rather than at the midpoints layout.
    pub cells: bool,
}

/// Knot t_k in lattice units for `n` basis functions of degree `p`, the
/// clamped ends `e` lattice units inside the first and last nodes.
#[inline]
pub fn knot(k: i64, n: usize, p: usize, e: f64) -> f64 {
    if k <= p as i64 {
        e
    } else if k >= n as i64 {
        (n - 1) as f64 - e
    } else {
        k as f64 - 0.5 * (p as f64 + 1.0)
    }
}

/// Greville abscissa of basis `i` (lattice units): the point whose linear
/// function value the basis carries (Σ_i g_i N_i(u) = u).
pub fn greville(i: usize, n: usize, p: usize, e: f64) -> f64 {
    (1..=p).map(|k| knot((i + k) as i64, n, p, e)).sum::<f64>() / p as f64
}

/// The p + 1 nonzero basis functions at `u` (lattice units, in [0, n − 1])
/// and their derivatives d/du: returns (first basis index, values, derivatives).
///
/// Away from the grid's edge every knot the span touches (t_{s−p} to
/// t_{s+p+1}) is uniform and the bases are the cardinal B-splines centred
/// on their nodes, evaluated in closed form (`uniform_basis`); within 2p
/// cells of the edge the fixed edge polynomials (`table_basis`, on grids of
/// at least `3p + 1` nodes per direction) or, on smaller grids, the
/// open-knot recursion (`open_basis`). All give the same functions (equal
/// to round-off, tested below).
#[inline]
pub fn basis(
    u: f64,
    n: usize,
    p: usize,
    e: f64,
) -> (usize, [f64; MAX_DEGREE + 1], [f64; MAX_DEGREE + 1]) {
    let s = span(u, n, p);
    if s > 2 * p && s + p + 2 <= n {
        uniform_basis(u, s, p)
    } else if table_fits(n, p) {
        table_basis(u, s, n, p, e)
    } else {
        open_basis(u, s, n, p, e)
    }
}

/// `basis` for a degree known when compiled: the interior's closed form
/// inlined into the caller, the spans near the edge out of line. The same
/// numbers as `basis`.
#[inline(always)]
pub fn basis_of<const P: usize>(
    u: f64,
    n: usize,
    e: f64,
) -> (usize, [f64; MAX_DEGREE + 1], [f64; MAX_DEGREE + 1]) {
    let s = span(u, n, P);
    if s > 2 * P && s + P + 2 <= n {
        uniform_basis(u, s, P)
    } else {
        edge_basis(u, n, P, e)
    }
}

/// `basis_of` for L points at once, into `first[l]` and per basis r
/// `nb[r][l]`, `dn[r][l]`: the interior's closed form in lanes,
/// which the compiler vectorises, then the lanes near the grid's edge
/// again by `basis`. The same numbers as `basis_of` per lane. Points
/// outside [0, n − 1] give some numbers; the caller has refused them.
#[inline(always)]
// Lane l indexes several arrays at once: the form that vectorises.
#[allow(clippy::needless_range_loop)]
pub fn basis_lanes<const P: usize, const L: usize>(
    u: &[f64; L],
    n: usize,
    e: f64,
    first: &mut [u32; L],
    nb: &mut [[f64; L]; MAX_DEGREE + 1],
    dn: &mut [[f64; L]; MAX_DEGREE + 1],
) {
    let (lo, hi) = (P as f64, (n - 1) as f64);
    let (inner_lo, inner_hi) = ((2 * P) as f64, n as f64 - (P + 2) as f64);
    let mut span_f = [0.0; L];
    // `basis_of`'s interior test, inner_lo < s ≤ inner_hi, as a bit mask
    // of the lanes near the edge.
    let mut edge = 0u32;
    for l in 0..L {
        // `span`: floor(u + (p + 1)/2) clamped to [p, n − 1], by truncation
        // (u ≥ 0 inside the grid).
        let s = (u[l] + 0.5 * (P as f64 + 1.0))
            .max(0.0)
            .trunc()
            .clamp(lo, hi);
        span_f[l] = s;
        let interior = (s > inner_lo) & (s <= inner_hi);
        edge |= (!interior as u32) << l;
        // SAFETY: s is finite, in [p, n − 1].
        first[l] = unsafe { s.to_int_unchecked::<i32>() } as u32 - P as u32;
    }
    for l in 0..L {
        let fl = span_f[l] - P as f64;
        if P == 2 {
            let f = u[l] - fl;
            let (a, b, c) = (1.5 - f, f - 1.0, f - 0.5);
            nb[0][l] = 0.5 * a * a;
            nb[1][l] = 0.75 - b * b;
            nb[2][l] = 0.5 * c * c;
            dn[0][l] = -a;
            dn[1][l] = -2.0 * b;
            dn[2][l] = c;
        } else {
            let t = u[l] - (fl + 1.0);
            let (t2, r) = (t * t, 1.0 - t);
            let t3 = t2 * t;
            nb[0][l] = r * r * r / 6.0;
            nb[1][l] = 0.5 * t3 - t2 + 2.0 / 3.0;
            nb[2][l] = -0.5 * t3 + 0.5 * t2 + 0.5 * t + 1.0 / 6.0;
            nb[3][l] = t3 / 6.0;
            dn[0][l] = -0.5 * r * r;
            dn[1][l] = 1.5 * t2 - 2.0 * t;
            dn[2][l] = -1.5 * t2 + t + 0.5;
            dn[3][l] = 0.5 * t2;
        }
    }
    if edge != 0 {
        for l in (0..L).filter(|&l| edge >> l & 1 != 0) {
            // A lane the caller refuses may hold NaN.
            let ul = if u[l].is_nan() { 0.0 } else { u[l] };
            let (f, v, d) = edge_basis(ul, n, P, e);
            first[l] = f as u32;
            for r in 0..=P {
                nb[r][l] = v[r];
                dn[r][l] = d[r];
            }
        }
    }
}

/// `basis` near the grid's edge, out of line (`basis_of`).
#[inline(never)]
fn edge_basis(
    u: f64,
    n: usize,
    p: usize,
    e: f64,
) -> (usize, [f64; MAX_DEGREE + 1], [f64; MAX_DEGREE + 1]) {
    basis(u, n, p, e)
}

/// Whether `table_basis` holds on a grid of `n` nodes: the left edge's
/// spans (s < 2p) must not reach the right edge's knots (s + p + 1 < n).
#[inline]
pub fn table_fits(n: usize, p: usize) -> bool {
    n > 3 * p
}

/// The nonzero bases of every span as polynomials in c = u − s + p/2 (the
/// span's centre at c = 0 in the interior): `BSPLINE{2,3}_TABLE[row][k][r]`
/// is the coefficient of c^k of basis first + r. Rows 0..p are the left
/// edge's spans s = p..2p − 1 (open knots: the cardinal B-splines cut by
/// the clamped knots), row p is every interior span (the cardinal
/// B-splines); the right edge is the left one mirrored (N_i(u) =
/// N_{n−1−i}(n − 1 − u)). Derived from the Cox-de Boor recursion in exact
/// rationals; the WGSL twin (`bs_basis`) holds the same numbers. The
/// `cells` layout (e = (p − 1)/2) has its own edge rows
/// (`BSPLINE2_CELLS_TABLE`, `BSPLINE3_CELLS_TABLE`).
const BSPLINE2_TABLE: [[[f64; 3]; 3]; 3] = [
    // s = 2: knots 0, 0, 0, 3/2, 5/2, 7/2
    [
        [1.0 / 9.0, 28.0 / 45.0, 4.0 / 15.0],
        [-4.0 / 9.0, -4.0 / 45.0, 8.0 / 15.0],
        [4.0 / 9.0, -32.0 / 45.0, 4.0 / 15.0],
    ],
    // s = 3: knots 0, 0, 3/2, 5/2, 7/2, 9/2
    [
        [1.0 / 10.0, 31.0 / 40.0, 1.0 / 8.0],
        [-2.0 / 5.0, -1.0 / 10.0, 1.0 / 2.0],
        [2.0 / 5.0, -9.0 / 10.0, 1.0 / 2.0],
    ],
    // interior
    [
        [1.0 / 8.0, 3.0 / 4.0, 1.0 / 8.0],
        [-1.0 / 2.0, 0.0, 1.0 / 2.0],
        [1.0 / 2.0, -1.0, 1.0 / 2.0],
    ],
];

const BSPLINE3_TABLE: [[[f64; 4]; 4]; 4] = [
    // s = 3: knots 0, 0, 0, 0, 2, 3, 4, 5
    [
        [1.0 / 64.0, 21.0 / 64.0, 33.0 / 64.0, 9.0 / 64.0],
        [-3.0 / 32.0, -15.0 / 32.0, 9.0 / 32.0, 9.0 / 32.0],
        [3.0 / 16.0, -1.0 / 16.0, -5.0 / 16.0, 3.0 / 16.0],
        [-1.0 / 8.0, 19.0 / 72.0, -13.0 / 72.0, 1.0 / 24.0],
    ],
    // s = 4: knots 0, 0, 0, 2, 3, 4, 5, 6
    [
        [1.0 / 72.0, 211.0 / 576.0, 115.0 / 192.0, 1.0 / 48.0],
        [-1.0 / 12.0, -49.0 / 96.0, 15.0 / 32.0, 1.0 / 8.0],
        [1.0 / 6.0, -5.0 / 48.0, -5.0 / 16.0, 1.0 / 4.0],
        [-1.0 / 9.0, 23.0 / 72.0, -3.0 / 8.0, 1.0 / 6.0],
    ],
    // s = 5: knots 0, 0, 2, 3, 4, 5, 6, 7
    [
        [1.0 / 64.0, 31.0 / 64.0, 23.0 / 48.0, 1.0 / 48.0],
        [-3.0 / 32.0, -21.0 / 32.0, 5.0 / 8.0, 1.0 / 8.0],
        [3.0 / 16.0, -3.0 / 16.0, -1.0 / 4.0, 1.0 / 4.0],
        [-1.0 / 8.0, 11.0 / 24.0, -1.0 / 2.0, 1.0 / 6.0],
    ],
    // interior
    [
        [1.0 / 48.0, 23.0 / 48.0, 23.0 / 48.0, 1.0 / 48.0],
        [-1.0 / 8.0, -5.0 / 8.0, 5.0 / 8.0, 1.0 / 8.0],
        [1.0 / 4.0, -1.0 / 4.0, -1.0 / 4.0, 1.0 / 4.0],
        [-1.0 / 6.0, 1.0 / 2.0, -1.0 / 2.0, 1.0 / 6.0],
    ],
];

/// The `cells` layout's rows (knots e, e, e, e + 1, e + 2, … with
/// e = 1/2): only the first span differs from the interior.
const BSPLINE2_CELLS_TABLE: [[[f64; 3]; 3]; 3] = [
    // s = 2: knots 1/2, 1/2, 1/2, 3/2, 5/2, 7/2
    [
        [1.0 / 4.0, 5.0 / 8.0, 1.0 / 8.0],
        [-1.0, 1.0 / 2.0, 1.0 / 2.0],
        [1.0, -3.0 / 2.0, 1.0 / 2.0],
    ],
    BSPLINE2_TABLE[2],
    BSPLINE2_TABLE[2],
];

/// The `cells` layout's cubic rows (knots 1, 1, 1, 1, 2, 3, …): the first
/// two spans differ from the interior.
const BSPLINE3_CELLS_TABLE: [[[f64; 4]; 4]; 4] = [
    // s = 3: knots 1, 1, 1, 1, 2, 3, 4, 5
    [
        [1.0 / 8.0, 19.0 / 32.0, 25.0 / 96.0, 1.0 / 48.0],
        [-3.0 / 4.0, -3.0 / 16.0, 13.0 / 16.0, 1.0 / 8.0],
        [3.0 / 2.0, -15.0 / 8.0, 1.0 / 8.0, 1.0 / 4.0],
        [-1.0, 7.0 / 4.0, -11.0 / 12.0, 1.0 / 6.0],
    ],
    // s = 4: knots 1, 1, 1, 2, 3, 4, 5, 6
    [
        [1.0 / 32.0, 15.0 / 32.0, 23.0 / 48.0, 1.0 / 48.0],
        [-3.0 / 16.0, -9.0 / 16.0, 5.0 / 8.0, 1.0 / 8.0],
        [3.0 / 8.0, -3.0 / 8.0, -1.0 / 4.0, 1.0 / 4.0],
        [-1.0 / 4.0, 7.0 / 12.0, -1.0 / 2.0, 1.0 / 6.0],
    ],
    BSPLINE3_TABLE[3],
    BSPLINE3_TABLE[3],
];

/// Any span `s` (valid where `table_fits`) from the tables above: a span
/// of the right edge is evaluated as its mirror on the left (reversed
/// bases, negated derivatives). No recursion and no data-dependent loop:
/// the WGSL twin runs it in every lane with selects.
#[inline]
pub fn table_basis(
    u: f64,
    s: usize,
    n: usize,
    p: usize,
    e: f64,
) -> (usize, [f64; MAX_DEGREE + 1], [f64; MAX_DEGREE + 1]) {
    let cells = e > 0.0;
    let right = s + p >= n;
    let (um, sm) = if right {
        ((n - 1) as f64 - u, n + p - 1 - s)
    } else {
        (u, s)
    };
    let c = um - sm as f64 + 0.5 * p as f64;
    let row = (sm - p).min(p);
    let mut nb = [0.0; MAX_DEGREE + 1];
    let mut dn = [0.0; MAX_DEGREE + 1];
    for r in 0..=p {
        // Horner in c for the value and its derivative.
        let coef = |k: usize| match (p, cells) {
            (2, false) => BSPLINE2_TABLE[row][k][r],
            (2, true) => BSPLINE2_CELLS_TABLE[row][k][r],
            (_, false) => BSPLINE3_TABLE[row][k][r],
            (_, true) => BSPLINE3_CELLS_TABLE[row][k][r],
        };
        let (mut v, mut d) = (coef(p), 0.0);
        for k in (0..p).rev() {
            d = d * c + v;
            v = v * c + coef(k);
        }
        let r_out = if right { p - r } else { r };
        nb[r_out] = v;
        dn[r_out] = if right { -d } else { d };
    }
    (s - p, nb, dn)
}

/// Knot span s: t_s ≤ u < t_{s+1}, s in [p, n − 1].
#[inline(always)]
fn span(u: f64, n: usize, p: usize) -> usize {
    super::index::floor_i64(u + 0.5 * (p as f64 + 1.0)).clamp(p as i64, n as i64 - 1) as usize
}

/// Uniform knots: quadratic with f = u − first in [0.5, 1.5), cubic with
/// t = u − (first + 1) in [0, 1) (the mpm88 weights and their cubic kin).
#[inline(always)]
fn uniform_basis(
    u: f64,
    s: usize,
    p: usize,
) -> (usize, [f64; MAX_DEGREE + 1], [f64; MAX_DEGREE + 1]) {
    let first = s - p;
    if p == 2 {
        let f = u - first as f64;
        let (a, b, c) = (1.5 - f, f - 1.0, f - 0.5);
        (
            first,
            [0.5 * a * a, 0.75 - b * b, 0.5 * c * c, 0.0],
            [-a, -2.0 * b, c, 0.0],
        )
    } else {
        let t = u - (first + 1) as f64;
        let (t2, r) = (t * t, 1.0 - t);
        let t3 = t2 * t;
        (
            first,
            [
                r * r * r / 6.0,
                0.5 * t3 - t2 + 2.0 / 3.0,
                -0.5 * t3 + 0.5 * t2 + 0.5 * t + 1.0 / 6.0,
                t3 / 6.0,
            ],
            [
                -0.5 * r * r,
                1.5 * t2 - 2.0 * t,
                -1.5 * t2 + t + 0.5,
                0.5 * t2,
            ],
        )
    }
}

/// The general open-knot evaluation on span `s` (Cox-de Boor).
fn open_basis(
    u: f64,
    s: usize,
    n: usize,
    p: usize,
    e: f64,
) -> (usize, [f64; MAX_DEGREE + 1], [f64; MAX_DEGREE + 1]) {
    let t = |k: usize| knot(k as i64, n, p, e);
    // Cox-de Boor triangle (The NURBS Book, A2.2), keeping degree p − 1 for the derivatives.
    let mut nb = [0.0; MAX_DEGREE + 1];
    let mut lower = [0.0; MAX_DEGREE + 1];
    let (mut left, mut right) = ([0.0; MAX_DEGREE + 1], [0.0; MAX_DEGREE + 1]);
    nb[0] = 1.0;
    for j in 1..=p {
        left[j] = u - t(s + 1 - j);
        right[j] = t(s + j) - u;
        if j == p {
            lower = nb;
        }
        let mut saved = 0.0;
        for r in 0..j {
            let den = right[r + 1] + left[j - r];
            let temp = if den != 0.0 { nb[r] / den } else { 0.0 };
            nb[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        nb[j] = saved;
    }
    // dN_{i,p} = p (N_{i,p−1} / (t_{i+p} − t_i) − N_{i+1,p−1} / (t_{i+p+1} − t_{i+1})),
    // where lower[r] is N_{s−p+1+r, p−1}.
    let first = s - p;
    let mut dn = [0.0; MAX_DEGREE + 1];
    for (r, d) in dn.iter_mut().enumerate().take(p + 1) {
        let i = first + r;
        let a = if r >= 1 { lower[r - 1] } else { 0.0 };
        let b = if r < p { lower[r] } else { 0.0 };
        let da = t(i + p) - t(i);
        let db = t(i + p + 1) - t(i + 1);
        *d = p as f64
            * ((if da != 0.0 { a / da } else { 0.0 }) - (if db != 0.0 { b / db } else { 0.0 }));
    }
    (first, nb, dn)
}

impl Bspline {
    /// Degree `degree` on the default (midpoints) layout.
    pub const fn midpoints(degree: usize) -> Bspline {
        Bspline {
            degree,
            cells: false,
        }
    }

    /// Nodes a particle sees: (p + 1)².
    pub fn max_nodes(&self) -> usize {
        (self.degree + 1) * (self.degree + 1)
    }

    /// The clamped ends' offset e inside the first and last nodes (lattice
    /// units): 0 for the midpoints layout, (p − 1)/2 for `cells`.
    pub fn end(&self) -> f64 {
        if self.cells {
            0.5 * (self.degree as f64 - 1.0)
        } else {
            0.0
        }
    }

    /// Nodes per direction beyond the scene's grid lines: p − 1 for
    /// `cells` (n_c + p bases over n_c cells), none otherwise.
    pub fn extra_nodes(&self) -> usize {
        if self.cells { self.degree - 1 } else { 0 }
    }

    #[inline]
    pub fn eval(
        &self,
        grid: &Grid,
        x: [f64; 2],
        nodes: &mut [u32],
        w: &mut [[f64; 3]],
    ) -> Result<usize, ShapeFault> {
        let e = self.end();
        if !grid.contains(x, e * grid.h) {
            return Err(ShapeFault::OutsideGrid);
        }
        let p = self.degree;
        let q = grid.logical(x);
        let (fx, nx, dnx) = basis(q[0], grid.nx, p, e);
        let (fy, ny, dny) = basis(q[1], grid.ny, p, e);
        let inv_h = 1.0 / grid.h;
        let mut k = 0;
        for b in 0..=p {
            for a in 0..=p {
                nodes[k] = grid.index(fx + a, fy + b) as u32;
                w[k] = [
                    nx[a] * ny[b],
                    dnx[a] * ny[b] * inv_h,
                    nx[a] * dny[b] * inv_h,
                ];
                k += 1;
            }
        }
        Ok(k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// (degree, end offset e) of both layouts: midpoints, then cells.
    const LAYOUTS: [(usize, f64); 4] = [(2, 0.0), (2, 0.5), (3, 0.0), (3, 1.0)];

    #[test]
    fn basis_is_a_partition_of_unity_reproducing_linear_functions() {
        for (p, e) in LAYOUTS {
            for n in [p + 1, p + 2, 9] {
                let mut u = e;
                while u <= (n - 1) as f64 - e {
                    let (first, nb, dn) = basis(u, n, p, e);
                    let s: f64 = nb[..=p].iter().sum();
                    let ds: f64 = dn[..=p].iter().sum();
                    let g: f64 = (0..=p).map(|r| nb[r] * greville(first + r, n, p, e)).sum();
                    let dg: f64 = (0..=p).map(|r| dn[r] * greville(first + r, n, p, e)).sum();
                    assert!(
                        (s - 1.0).abs() < 1e-13 && ds.abs() < 1e-12,
                        "p {p} e {e} n {n} u {u}: {s} {ds}"
                    );
                    assert!(
                        (g - u).abs() < 1e-13 && (dg - 1.0).abs() < 1e-12,
                        "p {p} e {e} n {n} u {u}: {g} {dg}"
                    );
                    assert!(nb[..=p].iter().all(|&v| v >= -1e-15));
                    u += 0.0371;
                }
            }
        }
    }

    #[test]
    fn closed_form_interior_matches_the_open_knot_recursion() {
        for (p, e) in LAYOUTS {
            let n = 16;
            let mut u = e;
            let mut interior = 0;
            while u <= (n - 1) as f64 - e {
                let s = span(u, n, p);
                let (f0, n0, d0) = open_basis(u, s, n, p, e);
                let (f1, n1, d1) = basis(u, n, p, e);
                assert_eq!(f0, f1);
                for r in 0..=p {
                    assert!((n0[r] - n1[r]).abs() < 1e-14, "p {p} e {e} u {u} r {r}");
                    assert!((d0[r] - d1[r]).abs() < 1e-13, "p {p} e {e} u {u} r {r}");
                }
                if s > 2 * p && s + p + 2 <= n {
                    interior += 1;
                }
                u += 0.0173;
            }
            assert!(
                interior > 200,
                "p {p}: the closed form ran {interior} times"
            );
        }
    }

    #[test]
    fn edge_tables_match_the_open_knot_recursion_on_every_span() {
        for (p, e) in LAYOUTS {
            for n in [3 * p + 1, 3 * p + 2, 16, 41] {
                assert!(table_fits(n, p));
                let mut u = e;
                let mut spans = std::collections::BTreeSet::new();
                while u <= (n - 1) as f64 - e {
                    let s = span(u, n, p);
                    spans.insert(s);
                    let (f0, n0, d0) = open_basis(u, s, n, p, e);
                    let (f1, n1, d1) = table_basis(u, s, n, p, e);
                    let (f2, n2, d2) = basis(u, n, p, e);
                    assert_eq!(f0, f1);
                    assert_eq!(f0, f2);
                    for r in 0..=p {
                        for (a, b) in [
                            (n0[r], n1[r]),
                            (d0[r], d1[r]),
                            (n0[r], n2[r]),
                            (d0[r], d2[r]),
                        ] {
                            assert!(
                                (a - b).abs() < 1e-14,
                                "p {p} e {e} n {n} u {u} r {r}: {a} vs {b}"
                            );
                        }
                    }
                    u += 0.0137;
                }
                // Both ends included, and every span visited.
                let end = (n - 1) as f64 - e;
                let (_, n1, d1) = table_basis(end, n - 1, n, p, e);
                assert_eq!(n1[p], 1.0);
                assert!(d1[p] > 0.0);
                assert_eq!(spans.len(), n - p, "p {p} e {e} n {n}");
            }
            assert!(!table_fits(3 * p, p));
        }
    }

    #[test]
    fn derivatives_match_differences_and_the_boundary_interpolates() {
        for (p, e) in LAYOUTS {
            let n = 8;
            let value = |i: usize, u: f64| {
                let (first, nb, _) = basis(u, n, p, e);
                if i >= first && i <= first + p {
                    nb[i - first]
                } else {
                    0.0
                }
            };
            for i in 0..n {
                let mut u = e + 0.013;
                while u < (n - 1) as f64 - e - 0.013 {
                    let (first, _, dn) = basis(u, n, p, e);
                    let d = if i >= first && i <= first + p {
                        dn[i - first]
                    } else {
                        0.0
                    };
                    let fd = (value(i, u + 1e-6) - value(i, u - 1e-6)) / 2e-6;
                    assert!(
                        (d - fd).abs() < 1e-5,
                        "p {p} e {e} i {i} u {u}: {d} vs {fd}"
                    );
                    u += 0.049;
                }
            }
            // Open knots: the end bases are 1 at the ends.
            assert_eq!(value(0, e), 1.0);
            assert!((value(n - 1, (n - 1) as f64 - e) - 1.0).abs() < 1e-15);
            assert_eq!(greville(0, n, p, e), e);
            assert_eq!(greville(n - 1, n, p, e), (n - 1) as f64 - e);
            // Interior Greville abscissae are the nodes.
            assert!((greville(n / 2, n, p, e) - (n / 2) as f64).abs() < 1e-15);
        }
    }

    /// The paper's layout puts a knot on every line of the scene's grid: on
    /// the node lattice shifted out by e, the knot spans are whole cells.
    #[test]
    fn the_cells_layout_has_a_knot_on_every_grid_line() {
        for p in [2, 3] {
            let b = Bspline {
                degree: p,
                cells: true,
            };
            let (e, cells) = (b.end(), 10);
            let n = cells + 1 + b.extra_nodes();
            let mut knots: Vec<f64> = (0..(n + p + 1) as i64).map(|k| knot(k, n, p, e)).collect();
            knots.dedup();
            let want: Vec<f64> = (0..=cells).map(|c| c as f64 + e).collect();
            assert_eq!(knots, want, "p {p}");
        }
    }
}
