//! The separable shapes on a regular grid (bilinear, B-splines) evaluated
//! cheaply where a loop uses them: per axis the 1-D values and derivatives
//! once, then their products per node, with the grid's constants taken
//! once per scene. The same numbers, in the same slot order, as
//! `Shape::eval` (tested below), so a loop may evaluate rather than read a
//! stored cache and give the same result. Values only (`GRAD = false`) for
//! the loops that need no ∇N (p2g, g2p).

use super::bspline::MAX_DEGREE;
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
    /// numbers in the same order, into arrays of that length, through
    /// `bases_lanes` and `each` (what the loops use).
    #[inline(always)]
    pub fn eval_fixed<const GRAD: bool, const K: usize>(
        &self,
        x: [f64; 2],
        nodes: &mut [u32; K],
        w: &mut [[f64; 3]; K],
    ) -> Result<(), ShapeFault> {
        let mut b = Lanes::<K, 1>::default();
        self.bases_lanes::<K, 1>(&[x], &mut b);
        if let Some(e) = b.fault(0) {
            return Err(e);
        }
        let mut k = 0;
        self.each(&b.lane(0), |node, wk| {
            nodes[k] = node;
            w[k][0] = wk[0];
            if GRAD {
                w[k][1] = wk[1];
                w[k][2] = wk[2];
            }
            k += 1;
        });
        Ok(())
    }

    /// The stencils of the first `x.len()` ≤ L points at once into
    /// `out` (whose `each` gives `eval_fixed`'s numbers): the per-axis
    /// work in lanes, which the compiler vectorises
    /// (`bspline::basis_lanes`). A lane outside the grid gets its fault
    /// and some stencil inside it.
    #[inline(always)]
    // Lane l indexes several arrays at once: the form that vectorises.
    #[allow(clippy::needless_range_loop)]
    pub fn bases_lanes<const K: usize, const L: usize>(
        &self,
        x: &[[f64; 2]],
        out: &mut Lanes<K, L>,
    ) {
        let m = self.margin;
        let (lo, hi) = (
            [self.min[0] + m, self.min[1] + m],
            [self.hi[0] - m, self.hi[1] - m],
        );
        // A full batch as it is, else the points padded with the first.
        let mut padded = [x.first().copied().unwrap_or(self.min); L];
        let x: &[[f64; 2]; L] = match x.try_into() {
            Ok(full) => full,
            Err(_) => {
                padded[..x.len()].copy_from_slice(x);
                &padded
            }
        };
        let mut q = [[0.0; L]; 2];
        let mut outside = 0u32;
        for l in 0..L {
            let p = x[l];
            // Not inside (NaN is outside), lane by lane as a bit mask.
            let inside = (p[0] >= lo[0]) & (p[0] <= hi[0]) & (p[1] >= lo[1]) & (p[1] <= hi[1]);
            outside |= (!inside as u32) << l;
            q[0][l] = (p[0] - self.min[0]) / self.h;
            q[1][l] = (p[1] - self.min[1]) / self.h;
        }
        let mut first = [[0u32; L]; 2];
        for ax in 0..2 {
            let nodes = [self.nx, self.ny][ax];
            let (n, d) = (&mut out.n[ax], &mut out.d[ax]);
            match (self.kind, K) {
                (Kind::Linear, 4) => {
                    for l in 0..L {
                        // `linear`'s cell: the floor, at least 0, at most
                        // n − 2; the 1-D weights [1 − s, s] and their
                        // derivatives [−1, 1], whose products are
                        // `linear::q4_n` and `q4_dn` exactly.
                        let c = q[ax][l].max(0.0).trunc().min((nodes - 2) as f64);
                        // SAFETY: c is finite, in [0, n − 2].
                        first[ax][l] = unsafe { c.to_int_unchecked::<i32>() } as u32;
                        let s = q[ax][l] - c;
                        n[0][l] = 1.0 - s;
                        n[1][l] = s;
                        d[0][l] = -1.0;
                        d[1][l] = 1.0;
                    }
                }
                (Kind::Bspline { p: 2, e }, 9) => {
                    bspline::basis_lanes::<2, L>(&q[ax], nodes, e, &mut first[ax], n, d)
                }
                (Kind::Bspline { p: 3, e }, 16) => {
                    bspline::basis_lanes::<3, L>(&q[ax], nodes, e, &mut first[ax], n, d)
                }
                (kind, k) => unreachable!("{kind:?} has no stencil of {k} slots"),
            }
        }
        for l in 0..L {
            out.node0[l] = first[1][l] * self.nx as u32 + first[0][l];
        }
        out.outside = outside;
    }

    /// A stencil's node and [N, ∂N/∂x, ∂N/∂y] slot by slot, in
    /// `eval_fixed`'s order and arithmetic, through `f`.
    #[inline(always)]
    pub fn each<const K: usize>(&self, b: &Stencil1<K>, mut f: impl FnMut(u32, [f64; 3])) {
        let side = Stencil1::<K>::SIDE;
        for k in 0..K {
            // Linear's corners run counter-clockwise from (i, j) (`linear`),
            // the B-splines' x fastest (`bspline`).
            let (i, j) = if K == 4 {
                [(0, 0), (1, 0), (1, 1), (0, 1)][k]
            } else {
                (k % side, k / side)
            };
            let (nx, ny) = (b.n[0][i], b.n[1][j]);
            f(
                b.node0 + (j * self.nx + i) as u32,
                [
                    nx * ny,
                    b.d[0][i] * ny * self.inv_h,
                    nx * b.d[1][j] * self.inv_h,
                ],
            );
        }
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

/// The stencils of L points on a separable shape of K slots, lane by
/// lane: each one's first node and, per axis, the 1-D values and
/// derivatives (lattice units) whose products are N and ∇N
/// (`Separable::each`): what a loop keeps of its particles' weights
/// instead of the K products each.
#[derive(Debug, Clone, Copy)]
pub struct Lanes<const K: usize, const L: usize> {
    pub node0: [u32; L],
    /// Per axis and basis r (p + 1 of them; linear 2) the lanes' values.
    pub n: [[[f64; L]; MAX_DEGREE + 1]; 2],
    /// Their derivatives d/du.
    pub d: [[[f64; L]; MAX_DEGREE + 1]; 2],
    /// Bit l: lane l's point is outside the grid (`ShapeFault::OutsideGrid`).
    pub outside: u32,
}

impl<const K: usize, const L: usize> Default for Lanes<K, L> {
    fn default() -> Self {
        Lanes {
            node0: [0; L],
            n: [[[0.0; L]; MAX_DEGREE + 1]; 2],
            d: [[[0.0; L]; MAX_DEGREE + 1]; 2],
            outside: 0,
        }
    }
}

impl<const K: usize, const L: usize> Lanes<K, L> {
    /// Lane l's fault, if any.
    #[inline(always)]
    pub fn fault(&self, l: usize) -> Option<ShapeFault> {
        (self.outside >> l & 1 != 0).then_some(ShapeFault::OutsideGrid)
    }

    /// Lane l's stencil.
    #[inline(always)]
    pub fn lane(&self, l: usize) -> Stencil1<K> {
        let mut s = Stencil1 {
            node0: self.node0[l],
            n: [[0.0; MAX_DEGREE + 1]; 2],
            d: [[0.0; MAX_DEGREE + 1]; 2],
        };
        for ax in 0..2 {
            for r in 0..Stencil1::<K>::SIDE {
                s.n[ax][r] = self.n[ax][r][l];
                s.d[ax][r] = self.d[ax][r][l];
            }
        }
        s
    }
}

/// One point's stencil on a separable shape of K slots: its first node
/// and, per axis, the 1-D values and derivatives (`Lanes`' lane).
#[derive(Debug, Clone, Copy)]
pub struct Stencil1<const K: usize> {
    pub node0: u32,
    pub n: [[f64; MAX_DEGREE + 1]; 2],
    pub d: [[f64; MAX_DEGREE + 1]; 2],
}

impl<const K: usize> Stencil1<K> {
    /// Nodes per side of the stencil.
    pub const SIDE: usize = match K {
        4 => 2,
        9 => 3,
        16 => 4,
        _ => panic!("no separable stencil has this many slots"),
    };
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

    /// Every separable shape: linear, and B-splines of degree 2 and 3 in
    /// both knot layouts.
    fn shapes() -> [Shape; 5] {
        [
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
        ]
    }

    /// The stencils of a batch in lanes (`bases_lanes`, what the loops
    /// evaluate) equal `eval_fixed`'s point by point, bit for bit, with
    /// the same faults: full and partial batches, points near every edge,
    /// outside the grid and NaN among them.
    #[test]
    fn lanes_equal_the_points_one_by_one() {
        let grid = Grid::regular(0.37, [-1.1, 0.4], 13, 11);
        let hi = grid.max();
        let mut points = Vec::new();
        for a in -3..=100 {
            for b in -3..=92 {
                points.push([
                    grid.min[0] + (hi[0] - grid.min[0]) * a as f64 / 97.0,
                    grid.min[1] + (hi[1] - grid.min[1]) * b as f64 / 89.0,
                ]);
            }
        }
        points.insert(17, [f64::NAN, 1.0]);
        points.insert(40, [0.5, f64::INFINITY]);
        fn check<const K: usize>(sep: &Separable, points: &[[f64; 2]]) -> usize {
            let mut faults = 0;
            // Batches of 8, then a partial one of 5.
            for chunk in points.chunks(8).chain([&points[..5]]) {
                let mut lanes = Lanes::<K, 8>::default();
                sep.bases_lanes::<K, 8>(chunk, &mut lanes);
                for (l, &x) in chunk.iter().enumerate() {
                    let (mut n, mut w) = ([0u32; K], [[0.0; 3]; K]);
                    let want = sep.eval_fixed::<true, K>(x, &mut n, &mut w);
                    assert_eq!(lanes.fault(l), want.err(), "{x:?}");
                    if want.is_err() {
                        faults += 1;
                        continue;
                    }
                    let mut k = 0;
                    sep.each(&lanes.lane(l), |node, wk| {
                        assert_eq!((node, wk), (n[k], w[k]), "{x:?} slot {k}");
                        k += 1;
                    });
                    assert_eq!(k, K);
                }
            }
            faults
        }
        for shape in shapes() {
            let sep = shape.separable(&grid).unwrap();
            let faults = match sep.class() {
                SeparableClass::Linear => check::<4>(&sep, &points),
                SeparableClass::Bspline2 => check::<9>(&sep, &points),
                SeparableClass::Bspline3 => check::<16>(&sep, &points),
            };
            assert!(faults > 100, "{shape:?}: {faults} points outside");
        }
    }

    /// Every slot of the separable evaluation equals `Shape::eval`'s, bit
    /// for bit (zeros up to sign), over points across the whole grid,
    /// edges included.
    #[test]
    fn separable_eval_equals_shape_eval() {
        let grid = Grid::regular(0.37, [-1.1, 0.4], 13, 11);
        for shape in shapes() {
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
