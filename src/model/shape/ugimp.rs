//! Uniform GIMP (Bardenhagen & Kober 2004): the tent function averaged over
//! a particle square of half-width lp = h / (2 ppc), as a tensor product of
//! the closed-form 1D weight. Up to 3 × 3 nodes.
//!
//! On a perturbed grid there is no closed form; we evaluate the same 1D
//! weights in the lattice coordinates of the isoparametric Q4 map and take
//! gradients through that map's Jacobian. This keeps the partition of unity
//! but loses linear reproduction (Σ N_a x_a ≠ x): uGIMP is a regular-grid
//! method, which is the paper's point in its §3.3.
//! WGSL twin: `shaders/shared/shape_ugimp.wgsl`.

use super::{ShapeFault, linear};
use crate::model::Grid;

#[derive(Debug, Clone, PartialEq)]
pub struct Ugimp {
    /// Particle half-width (m).
    pub lp: f64,
    /// lp / h (dimensionless, ≤ 1/2).
    pub lp_h: f64,
}

/// 1D uGIMP weight and its derivative, in lattice units: `d` = particle −
/// node distance / h, `l` = lp / h ≤ 1/2. Derivative is d/d(d).
#[inline]
pub fn weight_1d(d: f64, l: f64) -> (f64, f64) {
    let a = d.abs();
    let sg = if d < 0.0 { -1.0 } else { 1.0 };
    if a < l {
        (1.0 - (d * d + l * l) / (2.0 * l), -d / l)
    } else if a < 1.0 - l {
        (1.0 - a, -sg)
    } else if a < 1.0 + l {
        let u = 1.0 + l - a;
        (u * u / (4.0 * l), -sg * u / (2.0 * l))
    } else {
        (0.0, 0.0)
    }
}

impl Ugimp {
    pub fn new(h: f64, ppc: u32) -> Self {
        let lp_h = 0.5 / ppc as f64;
        Ugimp { lp: lp_h * h, lp_h }
    }

    #[inline]
    pub fn eval(
        &self,
        grid: &Grid,
        x: [f64; 2],
        nodes: &mut [u32],
        w: &mut [[f64; 3]],
    ) -> Result<usize, ShapeFault> {
        if !grid.contains(x, self.lp) {
            return Err(ShapeFault::OutsideGrid);
        }
        // Lattice coordinate q and the map from lattice gradients to x-gradients.
        let (q, jac) = if grid.is_perturbed() {
            let cp = linear::locate(grid, x).ok_or(ShapeFault::OutsideGrid)?;
            let q = [cp.i as f64 + cp.s, cp.j as f64 + cp.t];
            // The particle square must stay inside the grid in lattice units too.
            let (qx_max, qy_max) = (
                (grid.nx - 1) as f64 - self.lp_h,
                (grid.ny - 1) as f64 - self.lp_h,
            );
            if q[0] < self.lp_h || q[1] < self.lp_h || q[0] > qx_max || q[1] > qy_max {
                return Err(ShapeFault::OutsideGrid);
            }
            (q, cp.jac)
        } else {
            (grid.logical(x), [[grid.h, 0.0], [0.0, grid.h]])
        };
        // Nodes round(q) − 1 ..= round(q) + 1 per direction; farther ones have zero weight.
        let base = [
            (q[0] + 0.5).floor() as i64 - 1,
            (q[1] + 0.5).floor() as i64 - 1,
        ];
        let mut wx = [(0.0, 0.0); 3];
        let mut wy = [(0.0, 0.0); 3];
        for k in 0..3 {
            wx[k] = weight_1d(q[0] - (base[0] + k as i64) as f64, self.lp_h);
            wy[k] = weight_1d(q[1] - (base[1] + k as i64) as f64, self.lp_h);
        }
        let mut count = 0;
        for (ky, &(ny, dny)) in wy.iter().enumerate() {
            let j = base[1] + ky as i64;
            for (kx, &(nx, dnx)) in wx.iter().enumerate() {
                let i = base[0] + kx as i64;
                if i < 0 || j < 0 || i as usize >= grid.nx || j as usize >= grid.ny {
                    debug_assert!(nx * ny == 0.0, "uGIMP weight outside the grid");
                    continue;
                }
                let g = linear::to_physical(&jac, [dnx * ny, nx * dny]);
                nodes[count] = grid.index(i as usize, j as usize) as u32;
                w[count] = [nx * ny, g[0], g[1]];
                count += 1;
            }
        }
        Ok(count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weight_is_continuous_and_its_derivative_matches_differences() {
        for l in [0.5, 0.25, 1.0 / 6.0] {
            let eps = 1e-7;
            let mut d = -1.6;
            while d < 1.6 {
                let (w, dw) = weight_1d(d, l);
                let fd = (weight_1d(d + eps, l).0 - weight_1d(d - eps, l).0) / (2.0 * eps);
                assert!((dw - fd).abs() < 1e-5, "l={l} d={d}: {dw} vs {fd}");
                assert!((0.0..=1.0).contains(&w));
                d += 0.0137;
            }
        }
    }
}
