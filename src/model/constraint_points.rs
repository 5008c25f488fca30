//! Constraint points: a constraint holds the body where its region's edge
//! is, not only at the grid nodes inside the region. Where an edge of a
//! `[constraints.NAME]` region (of some width, with no particle in it at
//! t = 0: a support beside the body, as a clamp) lies inside the grid and
//! on the body, points are placed along it (two per cell, at the Gauss
//! points of the edge's stretch in each cell), each with the shape
//! functions' weights N_a(x_b) on the unperturbed grid's nodes. When some
//! node outside the region weighs on a point (B-splines, whose supports
//! reach across the edge; linear and uGIMP only on an edge between node
//! lines), the group holds its points instead of the region's nodes that
//! weigh on them: those nodes are freed, and the backends impose
//! Σ_a N_a(x_b) v_a = v̄ at every point (`cpu::constraint_points` by a
//! mass-weighted projection, the implicit step by a penalty;
//! docs/methods.md, "Constraints at their place"). A group whose points no
//! outside node reaches (an edge on a node line with linear shapes, or on
//! the grid's edge), a pin line, a region holding particles and LME (see
//! `place`) keep their nodes and run as before.

use super::shape::{Shape, linear};
use super::{Grid, Particles};
use crate::error::SceneError;
use crate::scene::Scene;
use std::collections::HashMap;

/// A node outside the region weighing more than this at a point makes the
/// group hold its points: round-off of a weight that is zero by
/// construction (linear shapes on a node line, ~1e-17) stays below it,
/// LME's smallest kept weights (its tolerance, 1e-6) lie above.
pub const OUTSIDE_WEIGHT_TOL: f64 = 1e-9;

/// Gauss points of a segment's two-point rule, on [−1, 1].
const GAUSS_2: [f64; 2] = [-0.577_350_269_189_625_8, 0.577_350_269_189_625_8];

/// One point where a constraint holds the body.
#[derive(Debug, Clone, PartialEq)]
pub struct ConstraintPoint {
    /// Index of its group in `Constraints::groups`.
    pub group: u32,
    /// Position (m), on the region's edge.
    pub x: [f64; 2],
    /// Held components: the group's `FIX_X` / `FIX_Y` bits.
    pub fix: u8,
    /// The nodes whose shape functions are nonzero at `x`, and their N_a(x).
    pub nodes: Vec<u32>,
    pub n: Vec<f64>,
}

/// The points of every group that needs them, and per group the region's
/// nodes they free (sorted; the caller drops them from the group and its
/// fixed bits: `Constraints::hold_at`).
#[derive(Debug, Clone, Default)]
pub struct Placement {
    pub points: Vec<ConstraintPoint>,
    pub freed: Vec<Vec<u32>>,
}

/// Places the points of every group that needs them; `groups` holds each
/// group's region nodes and fixed bits, in scene order. `particles` at
/// t = 0 say where the body is.
pub fn place(
    scene: &Scene,
    grid: &Grid,
    shape: &Shape,
    particles: &Particles,
    groups: &[(&[u32], u8)],
) -> Result<Placement, SceneError> {
    let mut out = Placement {
        points: Vec::new(),
        freed: vec![Vec::new(); groups.len()],
    };
    if matches!(shape, Shape::Lme(_)) {
        // LME keeps the region's nodes: freed, they let the field bend in
        // the strip between the edge and the first particles, which no
        // particle samples (the stiff cantilever came out 3.2 times too
        // soft), while held they already hold the edge (0.09 % from the
        // grid-edge run; docs/methods.md).
        return Ok(out);
    }
    let mut body: Option<BodyCells> = None;
    for (g, (name, spec)) in scene.file.constraints.iter().enumerate() {
        let key = || format!("constraints.{name}");
        // A region that is a line (a pin inside a body) or that holds
        // particles keeps its nodes: they hold what lies in it.
        let eps = 1e-9 * grid.h;
        let inside =
            |x: &[f64; 2]| (0..2).all(|a| x[a] > spec.min[a] + eps && x[a] < spec.max[a] - eps);
        if (0..2).any(|a| spec.max[a] - spec.min[a] <= eps) || particles.x.iter().any(inside) {
            continue;
        }
        let xs = edge_points(spec.min, spec.max, grid);
        if xs.is_empty() {
            continue;
        }
        let (region, fix) = groups[g];
        let body = body.get_or_insert_with(|| BodyCells::new(grid, particles));
        let mut in_region = vec![false; grid.n_nodes()];
        for &n in region {
            in_region[n as usize] = true;
        }
        let mut pts = Vec::new();
        let mut outside = false;
        for x in xs.into_iter().filter(|&x| body.covers(x, particles)) {
            let (nodes, n) = weights(shape, grid, x).map_err(|why| {
                SceneError::invalid(
                    key(),
                    format!("its edge point ({:.6}, {:.6}) m: {why}", x[0], x[1]),
                )
            })?;
            // Whether nodes beyond the edge reach it is decided on the
            // unperturbed lattice, as membership is: a perturbed grid's
            // wavy node line holds the body as the regular one does.
            let reach = if grid.is_perturbed() {
                let lattice = Grid::regular(grid.h, grid.min, grid.nx, grid.ny);
                weights(shape, &lattice, x).map_err(|why| {
                    SceneError::invalid(
                        key(),
                        format!("its edge point ({:.6}, {:.6}) m: {why}", x[0], x[1]),
                    )
                })?
            } else {
                (nodes.clone(), n.clone())
            };
            outside |= reach
                .0
                .iter()
                .zip(&reach.1)
                .any(|(&a, &w)| !in_region[a as usize] && w.abs() > OUTSIDE_WEIGHT_TOL);
            pts.push(ConstraintPoint {
                group: g as u32,
                x,
                fix,
                nodes,
                n,
            });
        }
        if !outside {
            continue;
        }
        for p in &pts {
            for (&a, &w) in p.nodes.iter().zip(&p.n) {
                if in_region[a as usize] && w != 0.0 {
                    out.freed[g].push(a);
                }
            }
        }
        out.freed[g].sort_unstable();
        out.freed[g].dedup();
        out.points.extend(pts);
    }
    Ok(out)
}

/// Points along the edges of the region [`min`, `max`] (m) that lie
/// strictly inside the grid: two per cell the edge crosses, at the Gauss
/// points of its stretch there.
pub fn edge_points(min: [f64; 2], max: [f64; 2], grid: &Grid) -> Vec<[f64; 2]> {
    let (lo, hi, h) = (grid.min, grid.max(), grid.h);
    let eps = 1e-9 * h;
    let mut out = Vec::new();
    for axis in 0..2 {
        let o = 1 - axis;
        let (a, b) = (min[o].max(lo[o]), max[o].min(hi[o]));
        if b - a <= eps {
            continue;
        }
        let edges = if min[axis] == max[axis] {
            vec![min[axis]]
        } else {
            vec![min[axis], max[axis]]
        };
        for e in edges {
            if !e.is_finite() || e <= lo[axis] + eps || e >= hi[axis] - eps {
                continue;
            }
            let first = ((a - lo[o]) / h).floor().max(0.0) as usize;
            let last = ((b - lo[o]) / h).ceil() as usize;
            for cell in first..last {
                let s0 = a.max(lo[o] + cell as f64 * h);
                let s1 = b.min(lo[o] + (cell + 1) as f64 * h);
                if s1 - s0 <= eps {
                    continue;
                }
                for g in GAUSS_2 {
                    let mut x = [0.0; 2];
                    x[axis] = e;
                    x[o] = 0.5 * (s0 + s1) + 0.5 * g * (s1 - s0);
                    out.push(x);
                }
            }
        }
    }
    out
}

/// The nonzero shape functions at `x`: uGIMP's field between particles is
/// the bilinear one (its particle average is not a point value), the
/// others their own.
fn weights(shape: &Shape, grid: &Grid, x: [f64; 2]) -> Result<(Vec<u32>, Vec<f64>), String> {
    let slots = shape.max_nodes();
    let mut nodes = vec![0u32; slots];
    let mut w = vec![[0.0; 3]; slots];
    let count = match shape {
        Shape::Ugimp(_) => linear::eval(grid, x, &mut nodes, &mut w),
        _ => shape.eval(grid, x, &mut [0.0; 2], &mut nodes, &mut w),
    }
    .map_err(|f| f.to_string())?;
    let (mut ns, mut vs) = (Vec::new(), Vec::new());
    for k in 0..count {
        if w[k][0] != 0.0 {
            ns.push(nodes[k]);
            vs.push(w[k][0]);
        }
    }
    Ok((ns, vs))
}

/// The particles binned by cell, to find whether a point lies in some
/// particle's domain (a square of side √V around it).
struct BodyCells {
    cells: HashMap<(i64, i64), Vec<u32>>,
    /// Cells a domain reaches beyond its particle's.
    reach: i64,
    min: [f64; 2],
    h: f64,
}

impl BodyCells {
    fn new(grid: &Grid, p: &Particles) -> BodyCells {
        let mut b = BodyCells {
            cells: HashMap::new(),
            reach: 0,
            min: grid.min,
            h: grid.h,
        };
        let mut half = 0.0f64;
        for i in 0..p.len() {
            let c = b.cell(p.x[i]);
            b.cells.entry(c).or_default().push(i as u32);
            half = half.max(0.5 * p.volume(i).sqrt());
        }
        b.reach = (half / grid.h).ceil() as i64 + 1;
        b
    }

    fn cell(&self, x: [f64; 2]) -> (i64, i64) {
        (
            ((x[0] - self.min[0]) / self.h).floor() as i64,
            ((x[1] - self.min[1]) / self.h).floor() as i64,
        )
    }

    /// Whether `x` lies in (or on the edge of) some particle's domain.
    fn covers(&self, x: [f64; 2], p: &Particles) -> bool {
        let (ci, cj) = self.cell(x);
        let eps = 1e-9 * self.h;
        for dj in -self.reach..=self.reach {
            for di in -self.reach..=self.reach {
                let Some(list) = self.cells.get(&(ci + di, cj + dj)) else {
                    continue;
                };
                for &i in list {
                    let i = i as usize;
                    let half = 0.5 * p.volume(i).sqrt() + eps;
                    if (x[0] - p.x[i][0]).abs() <= half && (x[1] - p.x[i][1]).abs() <= half {
                        return true;
                    }
                }
            }
        }
        false
    }
}
