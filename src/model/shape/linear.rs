//! Bilinear Q4 shape functions. On a regular grid the tent functions in
//! closed form; on a perturbed grid the isoparametric Q4 of the cell that
//! holds the particle, found by inverting the bilinear map with Newton.
//! WGSL twin: `shaders/shared/shape_linear.wgsl`.

use super::ShapeFault;
use crate::model::Grid;

/// Where a point sits in the grid: cell (i, j) (its lower-left node) and the
/// cell-local coordinates (s, t) ∈ [0, 1]², with the map's Jacobian
/// `jac[r][c] = ∂x_r/∂(s,t)_c` (m per unit of s or t).
#[derive(Debug, Clone, Copy)]
pub struct CellPoint {
    pub i: usize,
    pub j: usize,
    pub s: f64,
    pub t: f64,
    pub jac: [[f64; 2]; 2],
}

/// Tolerance on (s, t) for accepting a cell: round-off outside [0, 1] (dimensionless).
const CELL_TOL: f64 = 1e-12;

/// Finds the cell containing `x` and its local coordinates, or `None` if `x`
/// is outside the grid.
pub fn locate(grid: &Grid, x: [f64; 2]) -> Option<CellPoint> {
    if !grid.contains(x, 0.0) {
        return None;
    }
    let q = grid.logical(x);
    let clamp = |v: f64, n: usize| (super::index::floor_i64(v).max(0) as usize).min(n - 2);
    let (mut i, mut j) = (clamp(q[0], grid.nx), clamp(q[1], grid.ny));
    if !grid.is_perturbed() {
        let h = grid.h;
        return Some(CellPoint {
            i,
            j,
            s: q[0] - i as f64,
            t: q[1] - j as f64,
            jac: [[h, 0.0], [0.0, h]],
        });
    }
    // Perturbed: nodes move by < h/4, so the cell is the lattice guess or a
    // neighbour; walk towards (s, t) until it lands in [0, 1]².
    for _ in 0..4 {
        let c = [
            grid.node_pos(i, j),
            grid.node_pos(i + 1, j),
            grid.node_pos(i + 1, j + 1),
            grid.node_pos(i, j + 1),
        ];
        let (s, t, jac) = invert_q4(&c, x, [q[0] - i as f64, q[1] - j as f64]);
        let step = |v: f64| {
            if v < -CELL_TOL {
                -1
            } else if v > 1.0 + CELL_TOL {
                1
            } else {
                0
            }
        };
        let (di, dj) = (step(s), step(t));
        if di == 0 && dj == 0 {
            return Some(CellPoint {
                i,
                j,
                s: s.clamp(0.0, 1.0),
                t: t.clamp(0.0, 1.0),
                jac,
            });
        }
        let ni = i as i64 + di;
        let nj = j as i64 + dj;
        if ni < 0 || nj < 0 || ni as usize > grid.nx - 2 || nj as usize > grid.ny - 2 {
            return None;
        }
        (i, j) = (ni as usize, nj as usize);
    }
    None
}

/// Q4 values at local (s, t), corners counter-clockwise from (0, 0).
#[inline]
pub fn q4_n(s: f64, t: f64) -> [f64; 4] {
    [(1.0 - s) * (1.0 - t), s * (1.0 - t), s * t, (1.0 - s) * t]
}

/// Q4 derivatives with respect to (s, t).
#[inline]
pub fn q4_dn(s: f64, t: f64) -> [[f64; 2]; 4] {
    [
        [-(1.0 - t), -(1.0 - s)],
        [1.0 - t, -s],
        [t, s],
        [-t, 1.0 - s],
    ]
}

/// Inverts the bilinear map of corners `c` at `x` by Newton from `guess`.
/// Returns (s, t, Jacobian at the solution).
fn invert_q4(c: &[[f64; 2]; 4], x: [f64; 2], guess: [f64; 2]) -> (f64, f64, [[f64; 2]; 2]) {
    let (mut s, mut t) = (guess[0], guess[1]);
    let mut jac = [[0.0; 2]; 2];
    for _ in 0..20 {
        let n = q4_n(s, t);
        let dn = q4_dn(s, t);
        let mut r = [-x[0], -x[1]];
        jac = [[0.0; 2]; 2];
        for a in 0..4 {
            for d in 0..2 {
                r[d] += n[a] * c[a][d];
                jac[d][0] += dn[a][0] * c[a][d];
                jac[d][1] += dn[a][1] * c[a][d];
            }
        }
        let det = jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0];
        let ds = (jac[1][1] * r[0] - jac[0][1] * r[1]) / det;
        let dt = (-jac[1][0] * r[0] + jac[0][0] * r[1]) / det;
        s -= ds;
        t -= dt;
        if ds.abs() + dt.abs() < 1e-14 {
            break;
        }
    }
    (s, t, jac)
}

/// ∇_x of a function whose (s, t) gradient is `g`, through the map's Jacobian.
#[inline]
pub fn to_physical(jac: &[[f64; 2]; 2], g: [f64; 2]) -> [f64; 2] {
    // ∇_x = J^{-T} ∇_(s,t)
    let det = jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0];
    [
        (jac[1][1] * g[0] - jac[1][0] * g[1]) / det,
        (-jac[0][1] * g[0] + jac[0][0] * g[1]) / det,
    ]
}

/// Bilinear shape functions at `x`: the 4 corners of its cell.
#[inline]
pub fn eval(
    grid: &Grid,
    x: [f64; 2],
    nodes: &mut [u32],
    w: &mut [[f64; 3]],
) -> Result<usize, ShapeFault> {
    let cp = locate(grid, x).ok_or(ShapeFault::OutsideGrid)?;
    let n = q4_n(cp.s, cp.t);
    let dn = q4_dn(cp.s, cp.t);
    let corners = [(0, 0), (1, 0), (1, 1), (0, 1)];
    // On a regular grid ∇_x = ∇_(s,t) / h: one reciprocal, no division
    // per node (`separable` evaluates the same products).
    let inv_h = 1.0 / grid.h;
    for a in 0..4 {
        let (di, dj) = corners[a];
        nodes[a] = grid.index(cp.i + di, cp.j + dj) as u32;
        let g = if grid.is_perturbed() {
            to_physical(&cp.jac, dn[a])
        } else {
            [dn[a][0] * inv_h, dn[a][1] * inv_h]
        };
        w[a] = [n[a], g[0], g[1]];
    }
    Ok(4)
}
