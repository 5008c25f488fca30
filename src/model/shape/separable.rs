//! The separable shapes on a regular grid (bilinear, B-splines) evaluated
//! cheaply where a loop uses them: per axis the 1-D values and derivatives
//! once, then their products per node, with the grid's constants taken
//! once per scene. The same numbers, in the same slot order, as
//! `Shape::eval` (tested below), so a loop may evaluate rather than read a
//! stored cache and give the same result. Values only (`GRAD = false`) for
//! the loops that need no ∇N (p2g, g2p).

use super::{Shape, ShapeFault, bspline, linear};
use crate::model::Grid;

/// A shape whose N is a product of 1-D weights per axis on this grid.
#[derive(Debug, Clone, Copy)]
pub struct Separable {
    kind: Kind,
    /// The grid's lattice origin (m), spacing h (m), 1/h.
    min: [f64; 2],
    h: f64,
    inv_h: f64,
    /// The lattice's last node position (m): `Grid::max`.
    hi: [f64; 2],
    /// The margin (m) a particle keeps from the grid's edge.
    margin: f64,
    nx: usize,
    ny: usize,
}

#[derive(Debug, Clone, Copy)]
enum Kind {
    Linear,
    /// Degree p and clamped ends' offset e (lattice units).
    Bspline {
        p: usize,
        e: f64,
    },
}

impl Shape {
    /// The separable form of this shape on `grid`: linear and B-splines on
    /// a regular grid; None for uGIMP (whose stencil is cut at the grid's
    /// edge), LME and any perturbed grid.
    pub fn separable(&self, grid: &Grid) -> Option<Separable> {
        let kind = match self {
            Shape::Linear if !grid.is_perturbed() => Kind::Linear,
            Shape::Bspline(b) => Kind::Bspline {
                p: b.degree,
                e: b.end(),
            },
            _ => return None,
        };
        let margin = match kind {
            Kind::Linear => 0.0,
            Kind::Bspline { e, .. } => e * grid.h,
        };
        Some(Separable {
            kind,
            min: grid.min,
            h: grid.h,
            inv_h: 1.0 / grid.h,
            hi: grid.max(),
            margin,
            nx: grid.nx,
            ny: grid.ny,
        })
    }
}

use super::index::floor_i64 as floor_nonneg;

impl Separable {
    /// Writes the nodes and [N, ∂N/∂x, ∂N/∂y] at `x` as `Shape::eval` does
    /// (gradients only when `GRAD`); returns the slots written.
    #[inline(always)]
    pub fn eval<const GRAD: bool>(
        &self,
        x: [f64; 2],
        nodes: &mut [u32; 16],
        w: &mut [[f64; 3]; 16],
    ) -> Result<usize, ShapeFault> {
        let q = self.lattice(x)?;
        match self.kind {
            Kind::Linear => Ok(self.linear::<GRAD, 16>(q, nodes, w)),
            Kind::Bspline { p: 2, e } => Ok(self.bspline::<GRAD, 2, 16>(q, e, nodes, w)),
            Kind::Bspline { e, .. } => Ok(self.bspline::<GRAD, 3, 16>(q, e, nodes, w)),
        }
    }

    /// The stencil this shape has, for the loops that take it as a type
    /// (`cpu::stage_inputs::with_weights`): its slots are a constant.
    pub fn class(&self) -> SeparableClass {
        match self.kind {
            Kind::Linear => SeparableClass::Linear,
            Kind::Bspline { p: 2, .. } => SeparableClass::Bspline2,
            Kind::Bspline { .. } => SeparableClass::Bspline3,
        }
    }

    /// `eval` for a shape of `class` with exactly K = its slots: the same
    /// numbers in the same order, into arrays of that length.
    #[inline(always)]
    pub fn eval_fixed<const GRAD: bool, const K: usize>(
        &self,
        x: [f64; 2],
        nodes: &mut [u32; K],
        w: &mut [[f64; 3]; K],
    ) -> Result<(), ShapeFault> {
        let q = self.lattice(x)?;
        match (self.kind, K) {
            (Kind::Linear, 4) => {
                self.linear::<GRAD, K>(q, nodes, w);
            }
            (Kind::Bspline { p: 2, e }, 9) => {
                self.bspline::<GRAD, 2, K>(q, e, nodes, w);
            }
            (Kind::Bspline { p: 3, e }, 16) => {
                self.bspline::<GRAD, 3, K>(q, e, nodes, w);
            }
            (kind, k) => unreachable!("{kind:?} has no stencil of {k} slots"),
        }
        Ok(())
    }

    /// `x` in lattice units, or outside the grid (with the shape's margin).
    #[inline(always)]
    fn lattice(&self, x: [f64; 2]) -> Result<[f64; 2], ShapeFault> {
        let m = self.margin;
        if !(x[0] >= self.min[0] + m
            && x[0] <= self.hi[0] - m
            && x[1] >= self.min[1] + m
            && x[1] <= self.hi[1] - m)
        {
            return Err(ShapeFault::OutsideGrid);
        }
        Ok([(x[0] - self.min[0]) / self.h, (x[1] - self.min[1]) / self.h])
    }

    /// `linear::eval` on a regular grid: the cell's corners counter-clockwise
    /// from (i, j), gradients ∇_(s,t) / h as `linear::eval` takes them.
    #[inline(always)]
    fn linear<const GRAD: bool, const K: usize>(
        &self,
        q: [f64; 2],
        nodes: &mut [u32; K],
        w: &mut [[f64; 3]; K],
    ) -> usize {
        let cell = |v: f64, n: usize| (floor_nonneg(v).max(0) as usize).min(n - 2);
        let (i, j) = (cell(q[0], self.nx), cell(q[1], self.ny));
        let (s, t) = (q[0] - i as f64, q[1] - j as f64);
        let n = linear::q4_n(s, t);
        let base = j * self.nx + i;
        let idx = [base, base + 1, base + 1 + self.nx, base + self.nx];
        let dn = linear::q4_dn(s, t);
        for a in 0..4 {
            nodes[a] = idx[a] as u32;
            w[a][0] = n[a];
            if GRAD {
                w[a][1] = dn[a][0] * self.inv_h;
                w[a][2] = dn[a][1] * self.inv_h;
            }
        }
        4
    }

    /// `Bspline::eval`: the p + 1 bases per axis (`bspline::basis_of`), then
    /// their products, x fastest.
    #[inline(always)]
    fn bspline<const GRAD: bool, const P: usize, const K: usize>(
        &self,
        q: [f64; 2],
        e: f64,
        nodes: &mut [u32; K],
        w: &mut [[f64; 3]; K],
    ) -> usize {
        let (fx, nx, dnx) = bspline::basis_of::<P>(q[0], self.nx, e);
        let (fy, ny, dny) = bspline::basis_of::<P>(q[1], self.ny, e);
        let mut k = 0;
        for b in 0..=P {
            let row = (fy + b) * self.nx + fx;
            for a in 0..=P {
                nodes[k] = (row + a) as u32;
                w[k][0] = nx[a] * ny[b];
                if GRAD {
                    w[k][1] = dnx[a] * ny[b] * self.inv_h;
                    w[k][2] = nx[a] * dny[b] * self.inv_h;
                }
                k += 1;
            }
        }
        k
    }
}

/// The separable shapes by stencil (`Separable::class`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeparableClass {
    /// 2 × 2 nodes.
    Linear,
    /// 3 × 3.
    Bspline2,
    /// 4 × 4.
    Bspline3,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::shape::bspline::Bspline;

    fn fixed_eval<const K: usize>(sep: &Separable, x: [f64; 2]) -> (Vec<u32>, Vec<[f64; 3]>) {
        let (mut n, mut w) = ([0u32; K], [[0.0; 3]; K]);
        sep.eval_fixed::<true, K>(x, &mut n, &mut w).unwrap();
        (n.to_vec(), w.to_vec())
    }

    /// Every slot of the separable evaluation equals `Shape::eval`'s, bit
    /// for bit (zeros up to sign), over points across the whole grid,
    /// edges included.
    #[test]
    fn separable_eval_equals_shape_eval() {
        let grid = Grid::regular(0.37, [-1.1, 0.4], 13, 11);
        let shapes = [
            Shape::Linear,
            Shape::Bspline(Bspline::midpoints(2)),
            Shape::Bspline(Bspline {
                degree: 2,
                cells: true,
            }),
            Shape::Bspline(Bspline::midpoints(3)),
            Shape::Bspline(Bspline {
                degree: 3,
                cells: true,
            }),
        ];
        for shape in shapes {
            let sep = shape.separable(&grid).unwrap();
            let hi = grid.max();
            let mut checked = 0;
            for a in 0..=97 {
                for b in 0..=89 {
                    let x = [
                        grid.min[0] + (hi[0] - grid.min[0]) * a as f64 / 97.0,
                        grid.min[1] + (hi[1] - grid.min[1]) * b as f64 / 89.0,
                    ];
                    let (mut n0, mut w0) = ([0u32; 16], [[0.0; 3]; 16]);
                    let (mut n1, mut w1) = ([0u32; 16], [[0.0; 3]; 16]);
                    let r0 = shape.eval(&grid, x, &mut [0.0; 2], &mut n0, &mut w0);
                    let r1 = sep.eval::<true>(x, &mut n1, &mut w1);
                    match (r0, r1) {
                        (Ok(k0), Ok(k1)) => {
                            assert_eq!(k0, k1);
                            assert_eq!(n0[..k0], n1[..k1], "{shape:?} at {x:?}");
                            assert_eq!(w0[..k0], w1[..k1], "{shape:?} at {x:?}");
                            let mut n2 = [0u32; 16];
                            let mut w2 = [[0.0; 3]; 16];
                            assert_eq!(sep.eval::<false>(x, &mut n2, &mut w2), Ok(k0));
                            for k in 0..k0 {
                                assert_eq!((n2[k], w2[k][0]), (n0[k], w0[k][0]));
                            }
                            // The fixed-size stencil of the shape's class.
                            let fixed = |k: usize| match k {
                                4 => fixed_eval::<4>(&sep, x),
                                9 => fixed_eval::<9>(&sep, x),
                                _ => fixed_eval::<16>(&sep, x),
                            };
                            let (n3, w3) = fixed(k0);
                            assert_eq!((&n3[..], &w3[..]), (&n0[..k0], &w0[..k0]), "{shape:?}");
                            checked += 1;
                        }
                        (Err(a), Err(b)) => assert_eq!(a, b),
                        (a, b) => panic!("{shape:?} at {x:?}: {a:?} vs {b:?}"),
                    }
                }
            }
            assert!(checked > 5000, "{shape:?}: {checked}");
        }
        // Not separable here: uGIMP, a perturbed grid.
        assert!(
            Shape::Ugimp(crate::model::shape::ugimp::Ugimp::new(1.0, 2))
                .separable(&grid)
                .is_none()
        );
    }
}
