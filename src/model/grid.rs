//! The background grid: a logically structured lattice of nodes, spacing h,
//! optionally with each interior node moved randomly (a "perturbed" or
//! "unstructured" layout). Node (i, j) has index `j * nx + i`.

use crate::rng::SplitMix64;

#[derive(Debug, Clone)]
pub struct Grid {
    /// Nominal node spacing (m).
    pub h: f64,
    /// Position of node (0, 0) on the unperturbed lattice (m).
    pub min: [f64; 2],
    /// Nodes along x.
    pub nx: usize,
    /// Nodes along y.
    pub ny: usize,
    /// Largest node displacement per coordinate, as a fraction of h (0 = regular).
    pub perturb: f64,
    /// Actual node positions when perturbed; empty on a regular grid.
    pub pos: Vec<[f64; 2]>,
}

impl Grid {
    /// A regular grid of `nx` × `ny` nodes starting at `min`.
    pub fn regular(h: f64, min: [f64; 2], nx: usize, ny: usize) -> Self {
        assert!(nx >= 2 && ny >= 2, "a grid needs at least 2x2 nodes");
        Grid {
            h,
            min,
            nx,
            ny,
            perturb: 0.0,
            pos: Vec::new(),
        }
    }

    /// Moves every interior node by a uniform random amount in
    /// [−perturb·h, perturb·h] per coordinate (seeded). The outermost ring
    /// stays put so the grid still covers its rectangle.
    pub fn perturbed(mut self, perturb: f64, seed: u64) -> Self {
        if perturb == 0.0 {
            return self;
        }
        let mut rng = SplitMix64::new(seed);
        let d = perturb * self.h;
        let mut pos = Vec::with_capacity(self.n_nodes());
        for j in 0..self.ny {
            for i in 0..self.nx {
                let p = self.lattice_pos(i, j);
                let interior = i > 0 && j > 0 && i + 1 < self.nx && j + 1 < self.ny;
                // Draw for every node so a node's offset does not depend on the grid's size.
                let (dx, dy) = (rng.range(-d, d), rng.range(-d, d));
                pos.push(if interior { [p[0] + dx, p[1] + dy] } else { p });
            }
        }
        self.perturb = perturb;
        self.pos = pos;
        self
    }

    pub fn n_nodes(&self) -> usize {
        self.nx * self.ny
    }

    pub fn is_perturbed(&self) -> bool {
        !self.pos.is_empty()
    }

    #[inline]
    pub fn index(&self, i: usize, j: usize) -> usize {
        j * self.nx + i
    }

    /// Unperturbed lattice position of node (i, j) (m).
    #[inline]
    pub fn lattice_pos(&self, i: usize, j: usize) -> [f64; 2] {
        [
            self.min[0] + i as f64 * self.h,
            self.min[1] + j as f64 * self.h,
        ]
    }

    /// The nodes (i, j) whose unperturbed lattice position lies in the
    /// box [min, max] (m; `±inf` allowed), to 1e-9 h: a region of
    /// `[constraints]` or `[drainage]` (a perturbed grid selects the
    /// regular one's nodes). Row by row, x fastest.
    pub fn region(
        &self,
        min: [f64; 2],
        max: [f64; 2],
    ) -> impl Iterator<Item = (usize, usize)> + '_ {
        let eps = 1e-9 * self.h;
        (0..self.ny)
            .flat_map(move |j| (0..self.nx).map(move |i| (i, j)))
            .filter(move |&(i, j)| {
                let p = self.lattice_pos(i, j);
                p[0] >= min[0] - eps
                    && p[0] <= max[0] + eps
                    && p[1] >= min[1] - eps
                    && p[1] <= max[1] + eps
            })
    }

    /// Actual position of node (i, j) (m).
    #[inline]
    pub fn node_pos(&self, i: usize, j: usize) -> [f64; 2] {
        if self.pos.is_empty() {
            self.lattice_pos(i, j)
        } else {
            self.pos[self.index(i, j)]
        }
    }

    /// Upper-right corner (m).
    pub fn max(&self) -> [f64; 2] {
        self.lattice_pos(self.nx - 1, self.ny - 1)
    }

    /// Position in lattice units: node (i, j) sits at (i, j) when unperturbed.
    #[inline]
    pub fn logical(&self, x: [f64; 2]) -> [f64; 2] {
        [(x[0] - self.min[0]) / self.h, (x[1] - self.min[1]) / self.h]
    }

    /// True when `x` lies inside the grid with at least `margin` (m) to spare.
    #[inline]
    pub fn contains(&self, x: [f64; 2], margin: f64) -> bool {
        inside(self.bounds(margin), x)
    }

    /// The corners [lo, hi] (m) of the part `margin` (m) inside the grid's
    /// edge, for `inside`.
    pub fn bounds(&self, margin: f64) -> [[f64; 2]; 2] {
        let hi = self.max();
        [
            [self.min[0] + margin, self.min[1] + margin],
            [hi[0] - margin, hi[1] - margin],
        ]
    }

    /// Smallest distance two neighbouring nodes can have (m): the h that the
    /// CFL condition must use on a perturbed grid.
    pub fn min_spacing(&self) -> f64 {
        self.h * (1.0 - 2.0 * self.perturb)
    }
}

/// Whether `x` lies in `bounds` (`Grid::bounds`), edges included; NaN does not.
#[inline(always)]
pub fn inside(bounds: [[f64; 2]; 2], x: [f64; 2]) -> bool {
    let [lo, hi] = bounds;
    x[0] >= lo[0] && x[0] <= hi[0] && x[1] >= lo[1] && x[1] <= hi[1]
}
