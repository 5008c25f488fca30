//! GMM's node cloud (implicit-MPM paper §4.2, Algorithm 2): nodes that
//! belong to the body and move with it, each with its position and the
//! Newmark state of the last converged step (total displacement, velocity,
//! acceleration), plus a cell list over the current positions for the
//! search-in-radius that gathers a material point's cloud.
//!
//! The initial nodes are the grid lattice (`grid.h`, perturbed if the grid
//! is) restricted to the cells the bodies cover: the four corners of every
//! cell that holds a particle. Constraints select the cloud's nodes as they
//! select the grid's (membership of the node's lattice position in the
//! constraint's box, `Model::constraints`), through the grid index each
//! cloud node was made from.
//!
//! A lattice node of a cell the body only partly covers lies outside the
//! body, by up to a cell's diagonal. Such nodes are moved onto the body's
//! outline (`fit_to_outline`), as a mesh that conforms to the body has its
//! boundary nodes on it (the paper's triangulation does): walls act on the
//! cloud's nodes (`cpu::implicit::gmm`), and a node the wall holds
//! outside the body would make the body roll about it, a disk on a radius
//! up to a cell larger than its own.

use crate::error::SceneError;
use crate::model::{BodyOutline, FIX_X, FIX_Y, Model};

/// A cloud of nodes that moves with the body.
#[derive(Debug, Clone)]
pub struct Cloud {
    /// Initial node spacing h (m): the lattice's.
    pub h: f64,
    /// Current position (m).
    pub x: Vec<[f64; 2]>,
    /// Displacement since the start (m).
    pub u: Vec<[f64; 2]>,
    /// Velocity and acceleration at the end of the last converged step
    /// (m/s, m/s²): Newmark's predictor reads them (Algorithm 2, step 1).
    pub v: Vec<[f64; 2]>,
    pub a: Vec<[f64; 2]>,
    /// The grid node each cloud node was made from.
    pub grid_node: Vec<u32>,
    /// Per node: `FIX_X | FIX_Y` bits from the constraints.
    pub fix: Vec<u8>,
    /// Per constraint group (`Model::constraints.groups` order): its nodes.
    pub groups: Vec<Vec<u32>>,
    cells: CellList,
}

impl Cloud {
    /// The lattice nodes of the cells the particles occupy, with the
    /// particles' initial velocity (the mean over the particles of each
    /// node's cells would smear a velocity jump; every scene today starts
    /// each body at one velocity, which the nodes of its cells then take)
    /// and zero acceleration.
    pub fn from_model(model: &Model) -> Result<Cloud, SceneError> {
        let g = &model.grid;
        let p = &model.particles;
        let mut used = vec![u32::MAX; g.n_nodes()];
        let mut v_sum = vec![[0.0f64; 3]; g.n_nodes()];
        for (i, x) in p.x.iter().enumerate() {
            let q = g.logical(*x);
            let (ci, cj) = (q[0].floor(), q[1].floor());
            if ci < 0.0 || cj < 0.0 || ci as usize + 1 >= g.nx || cj as usize + 1 >= g.ny {
                return Err(SceneError::invalid(
                    "grid",
                    "a particle lies outside the grid's cells, so GMM has no lattice cell to put nodes on",
                ));
            }
            let (ci, cj) = (ci as usize, cj as usize);
            for (di, dj) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let n = g.index(ci + di, cj + dj);
                used[n] = 0;
                v_sum[n][0] += p.v[i][0];
                v_sum[n][1] += p.v[i][1];
                v_sum[n][2] += 1.0;
            }
        }
        let mut grid_node = Vec::new();
        let mut x = Vec::new();
        let mut v = Vec::new();
        for j in 0..g.ny {
            for i in 0..g.nx {
                let n = g.index(i, j);
                if used[n] == u32::MAX {
                    continue;
                }
                used[n] = grid_node.len() as u32;
                grid_node.push(n as u32);
                x.push(g.node_pos(i, j));
                let s = v_sum[n];
                v.push([s[0] / s[2], s[1] / s[2]]);
            }
        }
        let fix: Vec<u8> = grid_node
            .iter()
            .map(|&n| model.constraints.fix[n as usize])
            .collect();
        let mut groups = Vec::new();
        for grp in &model.constraints.groups {
            let nodes: Vec<u32> = grp
                .nodes
                .iter()
                .filter_map(|&n| (used[n as usize] != u32::MAX).then_some(used[n as usize]))
                .collect();
            if nodes.is_empty() {
                return Err(SceneError::invalid(
                    format!("constraints.{}", grp.name),
                    "holds none of the GMM cloud's nodes (the nodes of the cells the bodies cover)",
                ));
            }
            groups.push(nodes);
        }
        let n = x.len();
        debug_assert!(fix.iter().all(|&f| f & !(FIX_X | FIX_Y) == 0));
        Ok(Cloud {
            h: g.h,
            x,
            u: vec![[0.0; 2]; n],
            v,
            a: vec![[0.0; 2]; n],
            grid_node,
            fix,
            groups,
            cells: CellList::default(),
        })
    }

    /// A cloud of free nodes at `x` (tests; no constraints).
    pub fn from_points(h: f64, x: Vec<[f64; 2]>) -> Cloud {
        let n = x.len();
        Cloud {
            h,
            u: vec![[0.0; 2]; n],
            v: vec![[0.0; 2]; n],
            a: vec![[0.0; 2]; n],
            grid_node: vec![u32::MAX; n],
            fix: vec![0; n],
            groups: Vec::new(),
            x,
            cells: CellList::default(),
        }
    }

    /// Moves every node that lies outside the bodies' `outline` onto its
    /// nearest point of the outline, and drops one that lands within
    /// `MERGE` node spacings of a node it keeps (inside nodes first, then
    /// the moved ones in order; a constrained node is never dropped). A
    /// node keeps its lattice index, so constraints select it as before.
    /// Returns (moved, dropped). A body whose edges lie on the lattice's
    /// lines (the cantilever, the column) has no node outside and keeps
    /// its cloud as it was.
    pub fn fit_to_outline(&mut self, outline: &BodyOutline) -> (usize, usize) {
        let moved: Vec<usize> = (0..self.len())
            .filter_map(|n| {
                let q = nearest_on_outline(outline, self.x[n])?;
                self.x[n] = q;
                Some(n)
            })
            .collect();
        if moved.is_empty() {
            return (0, 0);
        }
        let merge = MERGE * self.h;
        self.cells.build(&self.x, merge);
        let mut is_moved = vec![false; self.len()];
        for &n in &moved {
            is_moved[n] = true;
        }
        let mut held: Vec<bool> = self.fix.iter().map(|&f| f != 0).collect();
        for &n in self.groups.iter().flatten() {
            held[n as usize] = true;
        }
        let mut keep = vec![true; self.len()];
        let mut near = Vec::new();
        for &n in &moved {
            if held[n] {
                continue;
            }
            self.gather(self.x[n], merge, &mut near);
            // A kept node that is not moved, or moved before this one.
            if near.iter().any(|&m| {
                m as usize != n && keep[m as usize] && (!is_moved[m as usize] || (m as usize) < n)
            }) {
                keep[n] = false;
            }
        }
        let dropped = keep.iter().filter(|&&k| !k).count();
        if dropped > 0 {
            self.retain(&keep);
        }
        (moved.len(), dropped)
    }

    /// Keeps the nodes with `keep[n]`, renumbering the constraint groups.
    fn retain(&mut self, keep: &[bool]) {
        let mut new_index = vec![u32::MAX; keep.len()];
        let mut next = 0u32;
        for (n, &k) in keep.iter().enumerate() {
            if k {
                new_index[n] = next;
                next += 1;
            }
        }
        fn keep_only<T: Copy>(v: &mut Vec<T>, keep: &[bool]) {
            let mut it = keep.iter();
            v.retain(|_| *it.next().expect("one flag per node"));
        }
        keep_only(&mut self.x, keep);
        keep_only(&mut self.u, keep);
        keep_only(&mut self.v, keep);
        keep_only(&mut self.a, keep);
        keep_only(&mut self.grid_node, keep);
        keep_only(&mut self.fix, keep);
        for g in &mut self.groups {
            // Constrained nodes are never dropped.
            for n in g.iter_mut() {
                *n = new_index[*n as usize];
            }
        }
    }

    pub fn len(&self) -> usize {
        self.x.len()
    }

    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Rebuilds the cell list over the current positions, cells of side
    /// `radius` (m), so a search reaches the 3 × 3 cells around a point.
    pub fn rebuild(&mut self, radius: f64) {
        self.cells.build(&self.x, radius);
    }

    /// The nodes within `radius` (m, at most the last `rebuild`'s) of `x`,
    /// in increasing index, into `out` (cleared first).
    pub fn gather(&self, x: [f64; 2], radius: f64, out: &mut Vec<u32>) {
        out.clear();
        let c = &self.cells;
        if c.nx == 0 {
            return;
        }
        let r2 = radius * radius;
        let (ci, cj) = c.cell_of(x);
        for j in cj.saturating_sub(1)..=(cj + 1).min(c.ny - 1) {
            for i in ci.saturating_sub(1)..=(ci + 1).min(c.nx - 1) {
                let cell = j * c.nx + i;
                for &n in &c.items[c.start[cell]..c.start[cell + 1]] {
                    let xn = self.x[n as usize];
                    let d = [x[0] - xn[0], x[1] - xn[1]];
                    if d[0] * d[0] + d[1] * d[1] <= r2 {
                        out.push(n);
                    }
                }
            }
        }
        out.sort_unstable();
    }

    /// Every node within `radius` (m, any size: a scan of the whole
    /// cloud, not the cell list) of `x`, nearest first, into `out`
    /// (cleared first). For the rare particle whose cloud needs nodes
    /// beyond the cell list's reach.
    pub fn nearest_within(&self, x: [f64; 2], radius: f64, out: &mut Vec<(f64, u32)>) {
        out.clear();
        let r2 = radius * radius;
        for (n, xn) in self.x.iter().enumerate() {
            let d = [x[0] - xn[0], x[1] - xn[1]];
            let d2 = d[0] * d[0] + d[1] * d[1];
            if d2 <= r2 {
                out.push((d2, n as u32));
            }
        }
        out.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    }
}

/// Where a node moved onto the outline may land within this many node
/// spacings of another node and is dropped instead: two lattice nodes
/// outside a curved edge can lie on nearly one normal to it (the R/h = 20
/// rolling disk moves 124 rim nodes and drops none; see the test).
const MERGE: f64 = 0.25;

/// The nearest point (m) to `p` on the boundary of the union of the
/// `outline`'s shapes, or None where `p` lies inside one.
pub fn nearest_on_outline(outline: &BodyOutline, p: [f64; 2]) -> Option<[f64; 2]> {
    let rects = outline.rects.iter().map(|r| {
        let q = [p[0].clamp(r[0], r[2]), p[1].clamp(r[1], r[3])];
        ((p[0] - q[0]).hypot(p[1] - q[1]), q)
    });
    let disks = outline.disks.iter().map(|d| {
        let (dx, dy) = (p[0] - d[0], p[1] - d[1]);
        let r = dx.hypot(dy);
        if r <= d[2] {
            (0.0, p)
        } else {
            (r - d[2], [d[0] + dx * d[2] / r, d[1] + dy * d[2] / r])
        }
    });
    let polygons = outline.polygons.iter().map(|poly| {
        // Even-odd inside test (as the seeding's), else the nearest edge.
        let n = poly.len();
        let mut inside = false;
        let mut nearest = (f64::INFINITY, p);
        for i in 0..n {
            let (a, b) = (poly[i], poly[(i + n - 1) % n]);
            if (a[1] > p[1]) != (b[1] > p[1])
                && p[0] < (b[0] - a[0]) * (p[1] - a[1]) / (b[1] - a[1]) + a[0]
            {
                inside = !inside;
            }
            let e = [b[0] - a[0], b[1] - a[1]];
            let len2 = e[0] * e[0] + e[1] * e[1];
            let s = if len2 > 0.0 {
                (((p[0] - a[0]) * e[0] + (p[1] - a[1]) * e[1]) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let q = [a[0] + s * e[0], a[1] + s * e[1]];
            let d = (p[0] - q[0]).hypot(p[1] - q[1]);
            if d < nearest.0 {
                nearest = (d, q);
            }
        }
        if inside { (0.0, p) } else { nearest }
    });
    let (d, q) = rects
        .chain(disks)
        .chain(polygons)
        .fold((f64::INFINITY, p), |a, b| if b.0 < a.0 { b } else { a });
    (d > 0.0 && d.is_finite()).then_some(q)
}

/// Nodes binned by square cells (a counting sort), rebuilt each step.
#[derive(Debug, Clone, Default)]
struct CellList {
    lo: [f64; 2],
    side: f64,
    nx: usize,
    ny: usize,
    /// Per cell: `items[start[c]..start[c + 1]]`.
    start: Vec<usize>,
    items: Vec<u32>,
}

impl CellList {
    fn cell_of(&self, x: [f64; 2]) -> (usize, usize) {
        let q = |v: f64, lo: f64, n: usize| {
            let c = ((v - lo) / self.side).floor();
            if c.is_nan() || c < 0.0 {
                0
            } else {
                (c as usize).min(n - 1)
            }
        };
        (q(x[0], self.lo[0], self.nx), q(x[1], self.lo[1], self.ny))
    }

    fn build(&mut self, x: &[[f64; 2]], side: f64) {
        if x.is_empty() {
            self.nx = 0;
            return;
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in x {
            for d in 0..2 {
                lo[d] = lo[d].min(p[d]);
                hi[d] = hi[d].max(p[d]);
            }
        }
        self.lo = lo;
        self.side = side;
        // Points outside the box (queries) fall in the edge cells, which
        // the 3 × 3 search still covers: a node within `side` of a query
        // outside the box lies in an edge cell or its neighbour.
        self.nx = (((hi[0] - lo[0]) / side).floor() as usize + 1).max(1);
        self.ny = (((hi[1] - lo[1]) / side).floor() as usize + 1).max(1);
        let cells = self.nx * self.ny;
        self.start.clear();
        self.start.resize(cells + 1, 0);
        let cell: Vec<usize> = x
            .iter()
            .map(|&p| {
                let (i, j) = self.cell_of(p);
                j * self.nx + i
            })
            .collect();
        for &c in &cell {
            self.start[c + 1] += 1;
        }
        for c in 0..cells {
            self.start[c + 1] += self.start[c];
        }
        let mut next = self.start.clone();
        self.items.clear();
        self.items.resize(x.len(), 0);
        for (n, &c) in cell.iter().enumerate() {
            self.items[next[c]] = n as u32;
            next[c] += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    #[test]
    fn the_nearest_point_of_the_outline_is_none_inside_and_on_the_boundary_outside() {
        let o = BodyOutline {
            rects: vec![[0.0, 0.0, 1.0, 1.0]],
            disks: vec![[3.0, 0.0, 0.5]],
            polygons: vec![vec![[5.0, 0.0], [6.0, 0.0], [5.0, 1.0]]],
        };
        let close = |p: [f64; 2], want: Option<[f64; 2]>| {
            let q = nearest_on_outline(&o, p);
            match (q, want) {
                (None, None) => {}
                (Some(q), Some(w)) => assert!(
                    (q[0] - w[0]).hypot(q[1] - w[1]) < 1e-14,
                    "{p:?}: {q:?} against {w:?}"
                ),
                _ => panic!("{p:?}: {q:?} against {want:?}"),
            }
        };
        close([0.5, 0.5], None);
        close([1.3, 1.4], Some([1.0, 1.0]));
        close([3.0, 0.8], Some([3.0, 0.5]));
        close([3.1, 0.1], None);
        close([5.2, 0.2], None);
        close([6.0, 1.0], Some([5.5, 0.5]));
        close([5.5, -0.25], Some([5.5, 0.0]));
    }

    /// The cloud of a scene run as GMM (implicit), and its model.
    fn scene_cloud(text: &str) -> (Cloud, Model) {
        use crate::scene::{Override, Scene};
        let sets: Vec<Override> = ["solver.integrator=implicit", "solver.method=gmm"]
            .iter()
            .map(|a| Override::parse(a).unwrap())
            .collect();
        let scene = Scene::from_str(text, "test", "test", &sets).unwrap();
        let model = Model::new(&scene).unwrap();
        (Cloud::from_model(&model).unwrap(), model)
    }

    /// The rolling disk (R/h = 20): the lattice nodes of the cells its rim
    /// cuts lie outside it, up to a cell diagonal; fitted, every node lies
    /// in the disk or on its circle, none closer than `MERGE` h to another,
    /// and the nodes inside have not moved. The column's rectangle lies on
    /// the lattice's lines: nothing moves.
    #[test]
    fn fitting_puts_the_rim_nodes_on_the_outline_and_leaves_a_lattice_edge_alone() {
        let (mut c, m) = scene_cloud(crate::cases::ROLLING_DISK);
        let before = c.x.clone();
        let outside = before
            .iter()
            .filter(|&&p| nearest_on_outline(&m.outline, p).is_some())
            .count();
        let (moved, dropped) = c.fit_to_outline(&m.outline);
        assert_eq!(moved, outside);
        assert!(moved > 100, "{moved} rim nodes");
        assert!(dropped < moved / 10, "{dropped} of {moved} dropped");
        assert_eq!(c.len(), before.len() - dropped);
        let d = m.outline.disks[0];
        let mut still = 0;
        for (n, p) in c.x.iter().enumerate() {
            let r = (p[0] - d[0]).hypot(p[1] - d[1]);
            assert!(r <= d[2] * (1.0 + 1e-12), "node {n} at r = {r}");
            still += before.contains(p) as usize;
            for q in &c.x[..n] {
                let gap = (p[0] - q[0]).hypot(p[1] - q[1]);
                assert!(gap >= MERGE * c.h, "nodes {gap} m apart");
            }
        }
        assert_eq!(still, c.len() - (moved - dropped));
        assert_eq!(c.grid_node.len(), c.len());

        let (mut c, m) = scene_cloud(crate::cases::COLUMN_COLLAPSE);
        let before = c.x.clone();
        assert_eq!(c.fit_to_outline(&m.outline), (0, 0));
        assert_eq!(c.x, before);
    }

    #[test]
    fn gather_finds_exactly_the_nodes_within_the_radius() {
        let mut rng = SplitMix64::new(7);
        let x: Vec<[f64; 2]> = (0..400)
            .map(|_| [rng.range(-2.0, 3.0), rng.range(0.0, 1.5)])
            .collect();
        let mut c = Cloud::from_points(0.1, x.clone());
        let r = 0.17;
        c.rebuild(r);
        let mut got = Vec::new();
        for _ in 0..200 {
            // Queries inside and somewhat outside the nodes' box.
            let q = [rng.range(-2.3, 3.3), rng.range(-0.3, 1.8)];
            c.gather(q, r, &mut got);
            let want: Vec<u32> = (0..x.len() as u32)
                .filter(|&n| {
                    let d = [q[0] - x[n as usize][0], q[1] - x[n as usize][1]];
                    d[0] * d[0] + d[1] * d[1] <= r * r
                })
                .collect();
            assert_eq!(got, want, "at {q:?}");
        }
    }
}
