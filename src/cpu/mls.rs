//! MLS reconstruction at Gauss points (B-spline paper, eqs. 6–25): the
//! `p2g` and `forces` stages when `solver.mls = true`.
//!
//! Each integration cell (a knot span of the B-spline, a grid cell for the
//! other shapes) holding at least one particle gets 2 × 2 Gauss points g.
//! At each, particle data f_p are fitted by moving least squares with the
//! linear basis [1, x, y] and the weight w = w(r_x) w(r_y),
//! r = (x_g − x_p)/(2h), w the quadratic spline of eq. 17 (support 3h;
//! `solver.mls_support` narrows it: r = 1.5 (x_g − x_p)/(support · h)):
//!   f_g = Σ_p φ_gp f_p,  φ_gp = w_gp pᵀ(x_g) A⁻¹ p(x_p),  A = Σ_p w_gp p pᵀ,
//! with the basis centred on x_g and scaled by h, so that φ_gp =
//! w_gp (c₀ + c₁ Δx + c₂ Δy) with c = A⁻¹ e₀, Δ = (x_p − x_g)/h.
//! Nodal values are then Gauss quadratures of the fitted fields:
//!   m_I = Σ_g N_I(x_g) ρ_g ω_g,  q_I = Σ_g N_I(x_g) (ρv*)_g ω_g,
//!   f_I = Σ_g (−σ_g ∇N_I(x_g) + N_I(x_g) (ρb)_g) ω_g,
//! v* the (NPC-predicted) velocity and b the body force per unit mass (the
//! paper's eq. 24 leaves ρ out; b_g there is a force per volume).
//!
//! The step keeps the update-stress-first order of the other shapes: the
//! velocity gradient of the stress stage comes from the MLS-projected nodal
//! velocities at the step's start, which is the paper's v^L (eqs. 31–34)
//! computed one stage later. The fit is not mass-conserving: Σ m_I is the
//! quadrature of the fitted density, within O(h²) of Σ m_p.
//!
//! Gauss points are fixed in space, so their N and ∇N are computed once.
//! Particles are binned by grid cell each step (a counting sort) to find
//! those within 3h. GPU twin: `shaders/mls_*.wgsl`.

use super::{scatter::Scatter, stage_inputs::ShapeCache};
use crate::model::Grid;
use crate::model::fault::{Fault, FaultKind};
use crate::model::gauss::{breaks, gauss_point};
use crate::model::shape::{Shape, ShapeFault};
use rayon::prelude::*;

/// The quadratic-spline weight of eq. 17, w(r) for r ≥ 0 (support 3/2).
#[inline]
pub fn weight(r: f64) -> f64 {
    // Both pieces, then a select: the fits call this for every particle of
    // a 7 × 7-cell window, where the branches mispredicted (the same
    // values: max(1.5 − r, 0) is 0 where r ≥ 1.5).
    let a = (1.5 - r).max(0.0);
    let outer = 0.5 * a * a;
    let inner = 0.75 - r * r;
    if r <= 0.5 { inner } else { outer }
}

/// Half-width of the MLS support in cells: w(|Δ|/2) vanishes for |Δ| ≥ 3.
pub const SUPPORT_CELLS: f64 = 3.0;

/// A moment matrix with det A < this × A₀₀³ is treated as singular.
const SINGULAR_REL: f64 = 1e-10;

/// Gauss points, their static shape values, and the per-step fit.
#[derive(Debug)]
pub struct Mls {
    /// Integration-cell breaks along x and y (lattice units).
    breaks: [Vec<f64>; 2],
    /// Gauss point positions (m), 4 per integration cell, cell-major.
    pub gp_x: Vec<[f64; 2]>,
    /// Gauss weights ω_g (m² per unit thickness).
    pub gp_w: Vec<f64>,
    /// N, ∇N at every Gauss point.
    pub gp_shape: ShapeCache,
    /// Grid cells along x and y (for binning).
    cells: [usize; 2],
    /// Particles sorted by grid cell: `order[cell_start[c]..cell_start[c + 1]]`.
    cell_start: Vec<u32>,
    order: Vec<u32>,
    /// Per particle in binned order: [x, y, six fitted values].
    packed: Vec<[f64; 8]>,
    /// Per particle: its grid cell, then its integration cell.
    cell_of: Vec<[u32; 2]>,
    /// Per integration cell: holds a particle this step.
    occupied: Vec<bool>,
    /// Per Gauss point: c = A⁻¹ e₀ (zeros when inactive).
    pub coef: Vec<[f64; 3]>,
    /// Per Gauss point: [ρ, ρv*x, ρv*y] (p2g), then [σxx, σyy, σxy, ρbx, ρby] (forces).
    pub gp_mv: Vec<[f64; 3]>,
    pub gp_f: Vec<[f64; 5]>,
    /// Per Gauss point: the remap's (ρ^t v^{t+1}) (MUSL, eq. 31).
    pub gp_remap: Vec<[f64; 2]>,
    mv_scatter: Scatter<3>,
    /// r per Δx/h in the weight: 1.5 / support (the paper's 1/2).
    weight_scale: f64,
    f_scatter: Scatter<2>,
    /// `solver.mls_scope = "force"` only (empty otherwise): per particle,
    /// the fit σ_h(x_p) (zeros where singular), and per integration cell,
    /// whether the correction applies (every fit in it regular).
    pub part_fit: Vec<[f64; 3]>,
    part_ok: Vec<bool>,
    pub cell_ok: Vec<bool>,
    /// `"force"` only: per particle, its fit's c = A⁻¹e₀ (zeros where
    /// singular); per Gauss point, ω_g L(x_g) (zeros outside `cell_ok`);
    /// per particle in binned order, V_p L_p (zeros outside `cell_ok`) and
    /// the strain-rate correction (`strain_correction`).
    part_coef: Vec<[f64; 3]>,
    gp_l: Vec<[f64; 4]>,
    part_vl: Vec<[f64; 4]>,
    part_dl: Vec<[f64; 4]>,
}

impl Mls {
    /// Gauss points of every integration cell of `grid`, with `shape`'s
    /// values there. Fails only if the shape cannot be evaluated at a
    /// Gauss point (an LME support too small for the grid).
    pub fn new(shape: &Shape, grid: &Grid, particles: usize) -> Result<Mls, ShapeFault> {
        let breaks = [breaks(shape, grid.nx), breaks(shape, grid.ny)];
        let n_gp = 4 * (breaks[0].len() - 1) * (breaks[1].len() - 1);
        let (gp_x, gp_w): (Vec<[f64; 2]>, Vec<f64>) = (0..n_gp)
            .map(|g| gauss_point(&breaks[0], &breaks[1], grid, g))
            .unzip();
        let mut gp_shape = ShapeCache::new(n_gp, shape.max_nodes());
        for (k, &x) in gp_x.iter().enumerate() {
            let o = k * gp_shape.stride;
            let s = gp_shape.stride;
            let n = shape.eval(
                grid,
                x,
                &mut [0.0; 2],
                &mut gp_shape.nodes[o..o + s],
                &mut gp_shape.w[o..o + s],
            )?;
            gp_shape.count[k] = n as u16;
        }
        let cells = [grid.nx - 1, grid.ny - 1];
        let n_int = (breaks[0].len() - 1) * (breaks[1].len() - 1);
        Ok(Mls {
            breaks,
            gp_x,
            gp_w,
            gp_shape,
            cells,
            cell_start: vec![0; cells[0] * cells[1] + 1],
            order: vec![0; particles],
            packed: vec![[0.0; 8]; particles],
            cell_of: vec![[0; 2]; particles],
            occupied: vec![false; n_int],
            coef: vec![[0.0; 3]; n_gp],
            gp_mv: vec![[0.0; 3]; n_gp],
            gp_f: vec![[0.0; 5]; n_gp],
            gp_remap: vec![[0.0; 2]; n_gp],
            mv_scatter: Scatter::default(),
            weight_scale: 1.5 / SUPPORT_CELLS,
            f_scatter: Scatter::default(),
            part_fit: Vec::new(),
            part_ok: Vec::new(),
            cell_ok: Vec::new(),
            part_coef: Vec::new(),
            gp_l: Vec::new(),
            part_vl: Vec::new(),
            part_dl: Vec::new(),
        })
    }

    /// Allocates what `fit_stress` needs (`solver.mls_scope = "force"`).
    pub fn for_force_correction(mut self) -> Self {
        let n = self.order.len();
        self.part_fit = vec![[0.0; 3]; n];
        self.part_ok = vec![false; n];
        self.cell_ok = vec![false; self.occupied.len()];
        self.part_coef = vec![[0.0; 3]; n];
        self.gp_l = vec![[0.0; 4]; self.gp_x.len()];
        self.part_vl = vec![[0.0; 4]; n];
        self.part_dl = vec![[0.0; 4]; n];
        self
    }

    /// The weight's support half-width `cells` (`solver.mls_support`,
    /// 1.5 to 3; the paper's 3 by default): w(1.5 |Δx| / (cells h)).
    pub fn with_support(mut self, cells: f64) -> Self {
        self.weight_scale = 1.5 / cells.clamp(crate::limits::MLS_SUPPORT_MIN, SUPPORT_CELLS);
        self
    }

    pub fn n_gauss_points(&self) -> usize {
        self.gp_x.len()
    }

    /// Bins the particles at `x` by grid cell and marks the occupied integration cells.
    fn bin(&mut self, grid: &Grid, x: &[[f64; 2]]) {
        let (cells, breaks) = (self.cells, &self.breaks);
        self.cell_of
            .par_iter_mut()
            .zip(x)
            .with_min_len(4096)
            .for_each(|(c, x)| {
                let u = grid.logical(*x);
                let i = (u[0].floor().max(0.0) as usize).min(cells[0] - 1);
                let j = (u[1].floor().max(0.0) as usize).min(cells[1] - 1);
                let bi = breaks[0]
                    .partition_point(|&b| b <= u[0])
                    .clamp(1, breaks[0].len() - 1)
                    - 1;
                let bj = breaks[1]
                    .partition_point(|&b| b <= u[1])
                    .clamp(1, breaks[1].len() - 1)
                    - 1;
                *c = [
                    (j * cells[0] + i) as u32,
                    (bj * (breaks[0].len() - 1) + bi) as u32,
                ];
            });
        self.cell_start.fill(0);
        self.occupied.fill(false);
        for c in &self.cell_of {
            self.cell_start[c[0] as usize + 1] += 1;
            self.occupied[c[1] as usize] = true;
        }
        for k in 1..self.cell_start.len() {
            self.cell_start[k] += self.cell_start[k - 1];
        }
        // Fill in particle order; `cell_start[c]` runs ahead and is restored after.
        for (p, c) in self.cell_of.iter().enumerate() {
            let s = &mut self.cell_start[c[0] as usize];
            self.order[*s as usize] = p as u32;
            *s += 1;
        }
        for k in (1..self.cell_start.len()).rev() {
            self.cell_start[k] = self.cell_start[k - 1];
        }
        self.cell_start[0] = 0;
    }

    /// Copies each particle's position and the 6 values `fill(p)` into
    /// `packed`, in the binned order, so the neighbour sums stream through
    /// memory one cache line per particle.
    fn pack(&mut self, x: &[[f64; 2]], fill: impl Fn(usize) -> [f64; 6] + Sync) {
        let order = &self.order;
        self.packed
            .par_iter_mut()
            .zip(order)
            .with_min_len(4096)
            .for_each(|(out, &p)| {
                let p = p as usize;
                let f = fill(p);
                *out = [x[p][0], x[p][1], f[0], f[1], f[2], f[3], f[4], f[5]];
            });
    }

    /// Visits every particle within 3h of any of the 4 Gauss points of
    /// integration cell `ic`, passing its packed data, [Δx, Δy] per Gauss
    /// point in units of h, the weight w per Gauss point, and its index in
    /// the binned order.
    #[inline]
    fn neighbours(
        &self,
        grid: &Grid,
        ic: usize,
        mut visit: impl FnMut(&[f64; 8], &[[f64; 2]; 4], &[f64; 4], usize),
    ) {
        let g0 = 4 * ic;
        let lo = grid.logical(self.gp_x[g0]);
        let hi = grid.logical(self.gp_x[g0 + 3]);
        let cell_range = |a: f64, b: f64, n: usize| {
            let i0 = (a - SUPPORT_CELLS).floor().max(0.0) as usize;
            let i1 = ((b + SUPPORT_CELLS).floor().max(0.0) as usize).min(n - 1);
            (i0.min(n - 1), i1)
        };
        let (i0, i1) = cell_range(lo[0], hi[0], self.cells[0]);
        let (j0, j1) = cell_range(lo[1], hi[1], self.cells[1]);
        let inv_h = 1.0 / grid.h;
        let gx = [self.gp_x[g0][0], self.gp_x[g0 + 1][0]];
        let gy = [self.gp_x[g0][1], self.gp_x[g0 + 2][1]];
        for j in j0..=j1 {
            let row = j * self.cells[0];
            let (s, e) = (self.cell_start[row + i0], self.cell_start[row + i1 + 1]);
            for (k, q) in self.packed[s as usize..e as usize].iter().enumerate() {
                let d = [
                    (q[0] - gx[0]) * inv_h,
                    (q[0] - gx[1]) * inv_h,
                    (q[1] - gy[0]) * inv_h,
                    (q[1] - gy[1]) * inv_h,
                ];
                let sc = self.weight_scale;
                let w = [
                    weight(sc * d[0].abs()),
                    weight(sc * d[1].abs()),
                    weight(sc * d[2].abs()),
                    weight(sc * d[3].abs()),
                ];
                if (w[0] == 0.0 && w[1] == 0.0) || (w[2] == 0.0 && w[3] == 0.0) {
                    continue;
                }
                visit(
                    q,
                    &[[d[0], d[2]], [d[1], d[2]], [d[0], d[3]], [d[1], d[3]]],
                    &[w[0] * w[2], w[1] * w[2], w[0] * w[3], w[1] * w[3]],
                    s as usize + k,
                );
            }
        }
    }

    /// Visits every particle of the cells within the weight's reach of the
    /// point `at` (m), passing its packed data, Δ = (x_p − at)/h and the
    /// weight w (0 for those beyond it).
    #[inline]
    fn neighbours_at(
        &self,
        grid: &Grid,
        at: [f64; 2],
        mut visit: impl FnMut(&[f64; 8], [f64; 2], f64),
    ) {
        let u = grid.logical(at);
        let range = |a: f64, n: usize| {
            let i0 = (a - SUPPORT_CELLS).floor().max(0.0) as usize;
            let i1 = ((a + SUPPORT_CELLS).floor().max(0.0) as usize).min(n - 1);
            (i0.min(n - 1), i1)
        };
        let (i0, i1) = range(u[0], self.cells[0]);
        let (j0, j1) = range(u[1], self.cells[1]);
        let inv_h = 1.0 / grid.h;
        let sc = self.weight_scale;
        for j in j0..=j1 {
            let row = j * self.cells[0];
            let (s, e) = (self.cell_start[row + i0], self.cell_start[row + i1 + 1]);
            for q in &self.packed[s as usize..e as usize] {
                let d = [(q[0] - at[0]) * inv_h, (q[1] - at[1]) * inv_h];
                // A particle out of reach is visited with w = 0 (it adds
                // nothing): cheaper than a branch that mispredicts.
                let w = weight(sc * d[0].abs()) * weight(sc * d[1].abs());
                visit(q, d, w);
            }
        }
    }

    /// The fit of the first 3 packed fields at the point `at` with its own
    /// moment matrix, with c = A⁻¹ e₀; `None` where A is singular.
    fn fit_at(&self, grid: &Grid, at: [f64; 2]) -> Option<([f64; 3], [f64; 3])> {
        let mut m = [0.0f64; 6];
        let mut mom = [[0.0f64; 3]; 3];
        self.neighbours_at(grid, at, |q, d, w| {
            let (dx, dy) = (d[0], d[1]);
            m[0] += w;
            m[1] += w * dx;
            m[2] += w * dy;
            m[3] += w * dx * dx;
            m[4] += w * dx * dy;
            m[5] += w * dy * dy;
            for f in 0..3 {
                let wf = w * q[2 + f];
                mom[f][0] += wf;
                mom[f][1] += wf * dx;
                mom[f][2] += wf * dy;
            }
        });
        let c = solve_e0(&m)?;
        Some((c, [dot(&c, &mom[0]), dot(&c, &mom[1]), dot(&c, &mom[2])]))
    }

    /// `solver.mls_scope = "force"`, first half of the `forces` stage: bins
    /// the particles, fits σ by MLS at every Gauss point of the occupied
    /// integration cells (`gp_f[g][0..3]`, `coef`) and at every particle
    /// (`part_fit`), each with its own moment matrix, and marks in
    /// `cell_ok` the integration cells whose fits are all regular (Gauss
    /// points and the particles in them); the correction skips the others
    /// in both of its sums. Needs `for_force_correction`.
    pub fn fit_stress(&mut self, grid: &Grid, x: &[[f64; 2]], stress: &[[f64; 3]]) {
        self.bin(grid, x);
        self.pack(x, |p| {
            let s = stress[p];
            [s[0], s[1], s[2], 0.0, 0.0, 0.0]
        });
        let (mut coef, mut vals, mut cell_ok) = (
            std::mem::take(&mut self.coef),
            std::mem::take(&mut self.gp_f),
            std::mem::take(&mut self.cell_ok),
        );
        let (mut part_fit, mut part_ok, mut part_coef) = (
            std::mem::take(&mut self.part_fit),
            std::mem::take(&mut self.part_ok),
            std::mem::take(&mut self.part_coef),
        );
        let this = &*self;
        coef.par_chunks_mut(4)
            .zip(vals.par_chunks_mut(4))
            .zip(cell_ok.par_iter_mut())
            .enumerate()
            .for_each(|(ic, ((c, val), ok))| {
                c.fill([0.0; 3]);
                val.fill([0.0; 5]);
                *ok = this.occupied[ic];
                if !*ok {
                    return;
                }
                for k in 0..4 {
                    match this.fit_at(grid, this.gp_x[4 * ic + k]) {
                        Some((ck, f)) => {
                            c[k] = ck;
                            val[k] = [f[0], f[1], f[2], 0.0, 0.0];
                        }
                        None => *ok = false,
                    }
                }
            });
        part_fit
            .par_iter_mut()
            .zip(part_ok.par_iter_mut())
            .zip(part_coef.par_iter_mut())
            .zip(x)
            // A fit visits some 450 particles (~3 µs): small chunks keep
            // every thread busy on small scenes too.
            .with_min_len(64)
            .for_each(|(((f, ok), c), &xp)| match this.fit_at(grid, xp) {
                Some((cp, v)) => (*f, *ok, *c) = (v, true, cp),
                None => (*f, *ok, *c) = ([0.0; 3], false, [0.0; 3]),
            });
        for (p, ok) in part_ok.iter().enumerate() {
            if !ok {
                cell_ok[this.cell_of[p][1] as usize] = false;
            }
        }
        (self.coef, self.gp_f, self.cell_ok) = (coef, vals, cell_ok);
        (self.part_fit, self.part_ok, self.part_coef) = (part_fit, part_ok, part_coef);
    }

    /// `solver.mls_scope = "force"`, in the `stress` stage, after
    /// `fit_stress` at the same positions: the transpose of the force's
    /// bracket applied to the nodal velocities `mv` (after
    /// `grid_update::predict`), per particle q in particle order,
    ///   V_q ΔL_q = Σ_{g∈c ok} ω_g φ_q(x_g) L(x_g) − Σ_{p∈c ok} V_p φ_q(x_p) L_p,
    /// L = Σ_I v_I ⊗ ∇N_I, φ_q(x) = w(x_q − x) c(x)·[1, (x_q − x)/h] the
    /// fit's weight of particle q at x. Added to L_q, it makes the stress
    /// power Σ_q V_q σ_q : (L_q + ΔL_q) equal the nodal forces' work
    /// −Σ_I v_I · f_I (docs/methods.md, "MLS as a force correction"):
    /// without it the bracket's work is not stored as strain energy.
    /// `mass`, `rho`: the particles' at the fit's positions.
    pub fn strain_correction(
        &mut self,
        grid: &Grid,
        cache: &ShapeCache,
        mv: &[[f64; 3]],
        mass: &[f64],
        rho: &[f64],
        dl: &mut [[f64; 4]],
    ) {
        let grad = |nodes: &[u32], w: &[[f64; 3]]| {
            let mut l = [0.0; 4];
            for (&node, wk) in nodes.iter().zip(w) {
                let v = &mv[node as usize];
                l[0] += v[1] * wk[1];
                l[1] += v[1] * wk[2];
                l[2] += v[2] * wk[1];
                l[3] += v[2] * wk[2];
            }
            l
        };
        let (mut gp_l, mut part_vl, mut part_dl) = (
            std::mem::take(&mut self.gp_l),
            std::mem::take(&mut self.part_vl),
            std::mem::take(&mut self.part_dl),
        );
        let this = &*self;
        gp_l.par_iter_mut().enumerate().for_each(|(g, o)| {
            *o = [0.0; 4];
            if this.cell_ok[g / 4] {
                let (nodes, w) = this.gp_shape.particle(g);
                *o = grad(nodes, w).map(|l| l * this.gp_w[g]);
            }
        });
        part_vl
            .par_iter_mut()
            .zip(&this.order)
            .with_min_len(1024)
            .for_each(|(o, &p)| {
                let p = p as usize;
                *o = [0.0; 4];
                if this.cell_ok[this.cell_of[p][1] as usize] {
                    let (nodes, w) = cache.particle(p);
                    *o = grad(nodes, w).map(|l| l * mass[p] / rho[p]);
                }
            });
        let inv_h = 1.0 / grid.h;
        let sc = this.weight_scale;
        let reach = 1.5 / sc;
        let nb = [this.breaks[0].len() - 1, this.breaks[1].len() - 1];
        let span_range = |b: &[f64], a: f64| {
            let lo = b.partition_point(|&t| t <= a - reach).saturating_sub(1);
            let hi = b.partition_point(|&t| t < a + reach).min(b.len() - 1);
            lo..hi
        };
        let (gp_l_ref, part_vl_ref) = (&gp_l, &part_vl);
        part_dl
            .par_iter_mut()
            .enumerate()
            .with_min_len(64)
            .for_each(|(k, o)| {
                let xq = [this.packed[k][0], this.packed[k][1]];
                let u = grid.logical(xq);
                let mut acc = [0.0; 4];
                // Gauss points: φ_q(x_g) with the Gauss point's c.
                for sy in span_range(&this.breaks[1], u[1]) {
                    for sx in span_range(&this.breaks[0], u[0]) {
                        let ic = sy * nb[0] + sx;
                        if !this.cell_ok[ic] {
                            continue;
                        }
                        let gs = 4 * ic..4 * ic + 4;
                        for ((xg, c), lg) in this.gp_x[gs.clone()]
                            .iter()
                            .zip(&this.coef[gs.clone()])
                            .zip(&gp_l_ref[gs])
                        {
                            let d = [(xq[0] - xg[0]) * inv_h, (xq[1] - xg[1]) * inv_h];
                            // w = 0 beyond reach adds nothing (no branch).
                            let w = weight(sc * d[0].abs()) * weight(sc * d[1].abs());
                            let phi = w * (c[0] + c[1] * d[0] + c[2] * d[1]);
                            for (a, l) in acc.iter_mut().zip(lg) {
                                *a += phi * l;
                            }
                        }
                    }
                }
                // Particles: −φ_q(x_p) with particle p's c.
                let range = |a: f64, n: usize| {
                    let i0 = (a - SUPPORT_CELLS).floor().max(0.0) as usize;
                    let i1 = ((a + SUPPORT_CELLS).floor().max(0.0) as usize).min(n - 1);
                    (i0.min(n - 1), i1)
                };
                let (i0, i1) = range(u[0], this.cells[0]);
                let (j0, j1) = range(u[1], this.cells[1]);
                for j in j0..=j1 {
                    let row = j * this.cells[0];
                    let (s, e) = (this.cell_start[row + i0], this.cell_start[row + i1 + 1]);
                    let ks = s as usize..e as usize;
                    for ((vl, q), &p) in part_vl_ref[ks.clone()]
                        .iter()
                        .zip(&this.packed[ks.clone()])
                        .zip(&this.order[ks])
                    {
                        if *vl == [0.0; 4] {
                            continue;
                        }
                        let d = [(xq[0] - q[0]) * inv_h, (xq[1] - q[1]) * inv_h];
                        let w = weight(sc * d[0].abs()) * weight(sc * d[1].abs());
                        let c = this.part_coef[p as usize];
                        let phi = w * (c[0] + c[1] * d[0] + c[2] * d[1]);
                        for (a, l) in acc.iter_mut().zip(vl) {
                            *a -= phi * l;
                        }
                    }
                }
                *o = acc;
            });
        for (k, &p) in this.order.iter().enumerate() {
            let p = p as usize;
            let inv_v = rho[p] / mass[p];
            dl[p] = part_dl[k].map(|a| a * inv_v);
        }
        (self.gp_l, self.part_vl, self.part_dl) = (gp_l, part_vl, part_dl);
    }

    /// `solver.mls_scope = "force"`, second half of the `forces` stage,
    /// after `fit_stress`: the nodal forces of plain MPM with the internal
    /// force's quadrature corrected by the fit,
    ///   f_I = Σ_p (−V_p σ_p ∇N_I(x_p) + N_I(x_p) m_p b_p)
    ///       − Σ_c [Σ_{g∈c} ω_g σ_h(x_g) ∇N_I(x_g) − Σ_{p∈c} V_p σ_h(x_p) ∇N_I(x_p)],
    /// c over the integration cells in `cell_ok`. Added to `force` (zeroed
    /// by `clear_grid`). `body(p)` is the body force per unit mass (m/s²).
    #[allow(clippy::too_many_arguments)]
    pub fn corrected_forces(
        &mut self,
        cache: &ShapeCache,
        stress: &[[f64; 3]],
        mass: &[f64],
        rho: &[f64],
        body: &(dyn Fn(usize) -> [f64; 2] + Sync),
        force: &mut [[f64; 2]],
        scatter: &mut Scatter<2>,
    ) {
        let (fit, cell_of, cell_ok) = (&self.part_fit, &self.cell_of, &self.cell_ok);
        scatter.run(force, mass.len(), |p, acc| {
            let vol = mass[p] / rho[p];
            let mut s = stress[p];
            if cell_ok[cell_of[p][1] as usize] {
                let f = fit[p];
                s = [s[0] - f[0], s[1] - f[1], s[2] - f[2]];
            }
            let g = body(p);
            let mb = [mass[p] * g[0], mass[p] * g[1]];
            let (nodes, w) = cache.particle(p);
            super::forces::add_particle_forces(
                &super::stage_inputs::Slices(nodes, w),
                vol,
                s,
                mb,
                acc,
            );
        });
        let (shape, gw, gf) = (&self.gp_shape, &self.gp_w, &self.gp_f);
        self.f_scatter.run(force, gf.len(), |g, acc| {
            if !cell_ok[g / 4] {
                return;
            }
            let (nodes, w) = shape.particle(g);
            let s = gf[g];
            let om = gw[g];
            for (&node, wk) in nodes.iter().zip(w) {
                let o = &mut acc[node as usize];
                o[0] -= om * (s[0] * wk[1] + s[2] * wk[2]);
                o[1] -= om * (s[2] * wk[1] + s[1] * wk[2]);
            }
        });
    }

    /// The fit f_g = Σ_p φ_gp f_p, with this step's coefficients, of the
    /// first `F` packed fields at every Gauss point (4 per integration
    /// cell; zero in cells without particles).
    fn fit<const F: usize>(&self, grid: &Grid, out: &mut [[f64; F]]) {
        out.par_chunks_mut(4).enumerate().for_each(|(ic, val)| {
            val.fill([0.0; F]);
            if !self.occupied[ic] {
                return;
            }
            let c = &self.coef[4 * ic..4 * ic + 4];
            self.neighbours(grid, ic, |q, d, w, _| {
                for k in 0..4 {
                    let phi = w[k] * (c[k][0] + c[k][1] * d[k][0] + c[k][2] * d[k][1]);
                    for f in 0..F {
                        val[k][f] += phi * q[2 + f];
                    }
                }
            });
        });
    }

    /// MLS p2g: bins the particles, solves each Gauss point's moment matrix,
    /// fits ρ and ρv* (v* = v + a_factor a), and adds their quadratures to
    /// `mv` (zeroed by `clear_grid`).
    #[allow(clippy::too_many_arguments)]
    pub fn p2g(
        &mut self,
        grid: &Grid,
        x: &[[f64; 2]],
        rho: &[f64],
        v: &[[f64; 2]],
        a: &[[f64; 2]],
        a_factor: f64,
        mv: &mut [[f64; 3]],
    ) -> Result<(), Fault> {
        self.bin(grid, x);
        self.pack(x, |p| {
            let mut f = [rho[p], rho[p] * v[p][0], rho[p] * v[p][1], 0.0, 0.0, 0.0];
            if !a.is_empty() {
                f[1] += rho[p] * a_factor * a[p][0];
                f[2] += rho[p] * a_factor * a[p][1];
            }
            f
        });
        let mut coef = std::mem::take(&mut self.coef);
        let mut vals = std::mem::take(&mut self.gp_mv);
        let this = &*self;
        let fault = coef
            .par_chunks_mut(4)
            .zip(vals.par_chunks_mut(4))
            .enumerate()
            .map(|(ic, (c, val))| {
                if !this.occupied[ic] {
                    c.fill([0.0; 3]);
                    val.fill([0.0; 3]);
                    return None;
                }
                // Per Gauss point: A (a00 a01 a02 a11 a12 a22) and the moments Σ w p f.
                let mut am = [[0.0f64; 6]; 4];
                let mut mom = [[[0.0f64; 3]; 3]; 4];
                this.neighbours(grid, ic, |q, d, w, _| {
                    for k in 0..4 {
                        let (wk, dx, dy) = (w[k], d[k][0], d[k][1]);
                        let m = &mut am[k];
                        m[0] += wk;
                        m[1] += wk * dx;
                        m[2] += wk * dy;
                        m[3] += wk * dx * dx;
                        m[4] += wk * dx * dy;
                        m[5] += wk * dy * dy;
                        for f in 0..3 {
                            let wf = wk * q[2 + f];
                            mom[k][f][0] += wf;
                            mom[k][f][1] += wf * dx;
                            mom[k][f][2] += wf * dy;
                        }
                    }
                });
                for k in 0..4 {
                    let Some(ck) = solve_e0(&am[k]) else {
                        return Some(Fault {
                            particle: None,
                            kind: FaultKind::MlsSingular {
                                at: this.gp_x[4 * ic + k],
                            },
                        });
                    };
                    c[k] = ck;
                    for f in 0..3 {
                        val[k][f] = dot(&ck, &mom[k][f]);
                    }
                }
                None
            })
            .reduce(|| None, |a, b| a.or(b));
        self.coef = coef;
        self.gp_mv = vals;
        if let Some(f) = fault {
            return Err(f);
        }
        let (shape, gw, gv) = (&self.gp_shape, &self.gp_w, &self.gp_mv);
        self.mv_scatter.run(mv, gv.len(), |g, acc| {
            let (nodes, w) = shape.particle(g);
            let val = gv[g];
            if val[0] == 0.0 {
                return;
            }
            for (&node, wk) in nodes.iter().zip(w) {
                let nw = wk[0] * gw[g];
                let o = &mut acc[node as usize];
                o[0] += nw * val[0];
                o[1] += nw * val[1];
                o[2] += nw * val[2];
            }
        });
        Ok(())
    }

    /// MLS forces: fits σ and ρb at the Gauss points with this step's
    /// coefficients (the particles have not moved since `p2g`) and adds
    /// their quadratures to `force` (zeroed by `clear_grid`). `body(p)` is
    /// the body force per unit mass (m/s²).
    pub fn forces(
        &mut self,
        grid: &Grid,
        x: &[[f64; 2]],
        rho: &[f64],
        stress: &[[f64; 3]],
        body: &(dyn Fn(usize) -> [f64; 2] + Sync),
        force: &mut [[f64; 2]],
    ) {
        self.pack(x, |p| {
            let (s, b) = (stress[p], body(p));
            [s[0], s[1], s[2], rho[p] * b[0], rho[p] * b[1], 0.0]
        });
        let mut vals = std::mem::take(&mut self.gp_f);
        self.fit(grid, &mut vals);
        self.gp_f = vals;
        let (shape, gw, gf) = (&self.gp_shape, &self.gp_w, &self.gp_f);
        let coef = &self.coef;
        self.f_scatter.run(force, gf.len(), |g, acc| {
            if coef[g][0] == 0.0 {
                return;
            }
            let (nodes, w) = shape.particle(g);
            let s = gf[g];
            let om = gw[g];
            for (&node, wk) in nodes.iter().zip(w) {
                let o = &mut acc[node as usize];
                o[0] += om * (-(s[0] * wk[1] + s[2] * wk[2]) + wk[0] * s[3]);
                o[1] += om * (-(s[2] * wk[1] + s[1] * wk[2]) + wk[0] * s[4]);
            }
        });
    }

    /// MLS remap of MUSL (paper eqs. 31–32): fits ρ_p v_p at the Gauss
    /// points with this step's coefficients and the particles' positions at
    /// the step's start (as `p2g` packed them; the particles have moved
    /// since), ρ the density at the step's start (ρ_p^t, not yet updated),
    /// v the particles' new velocities, and adds its quadrature
    /// Σ_g N_I(x_g) (ρv)_g ω_g to the nodal momentum of `mv` (zeroed
    /// first by pass `RemapClear`, `remap::clear_momentum`). The masses stay
    /// m_I^t, so `grid_update::predict` then gives v^L (eq. 33).
    pub fn remap(&mut self, grid: &Grid, rho: &[f64], v: &[[f64; 2]], mv: &mut [[f64; 3]]) {
        let order = &self.order;
        self.packed
            .par_iter_mut()
            .zip(order)
            .with_min_len(4096)
            .for_each(|(out, &p)| {
                let p = p as usize;
                out[2] = rho[p] * v[p][0];
                out[3] = rho[p] * v[p][1];
            });
        let mut vals = std::mem::take(&mut self.gp_remap);
        self.fit(grid, &mut vals);
        self.gp_remap = vals;
        let (shape, gw, gv) = (&self.gp_shape, &self.gp_w, &self.gp_remap);
        let coef = &self.coef;
        self.mv_scatter.run(mv, gv.len(), |g, acc| {
            if coef[g][0] == 0.0 {
                return;
            }
            let (nodes, w) = shape.particle(g);
            let val = gv[g];
            for (&node, wk) in nodes.iter().zip(w) {
                let nw = wk[0] * gw[g];
                let o = &mut acc[node as usize];
                o[1] += nw * val[0];
                o[2] += nw * val[1];
            }
        });
    }

    /// Diagnostic, not a stage: the transpose of the fit's quadrature,
    /// out_p = Σ_g ω_g φ_gp val_g, and V̂_p = Σ_g ω_g φ_gp (the volume the
    /// fit's quadrature gives particle p), per particle in particle order,
    /// with this step's coefficients and the particles' positions at the
    /// step's start (as `p2g` packed them). Since f_I = −Σ_g ω_g σ_g ∇N_I(x_g)
    /// with σ_g = Σ_p φ_gp σ_p, the strain rate that does the work of those
    /// forces is V_p L_p = Σ_g ω_g φ_gp ∇v(x_g), and the particle velocity
    /// change that conserves the nodal momentum q_I = Σ_g N_I (ρv)_g ω_g is
    /// m_p Δv_p = ρ_p Σ_g ω_g φ_gp Δv(x_g). `tests/mls_reconstruction.rs`
    /// builds the energy-consistent step from these (docs/methods.md,
    /// "Why MLS is less accurate"). Sequential: it is for tests.
    pub fn transpose<const K: usize>(
        &self,
        grid: &Grid,
        val: &[[f64; K]],
        out: &mut [[f64; K]],
        vhat: &mut [f64],
    ) {
        out.fill([0.0; K]);
        vhat.fill(0.0);
        for ic in (0..self.occupied.len()).filter(|&ic| self.occupied[ic]) {
            let c = &self.coef[4 * ic..4 * ic + 4];
            self.neighbours(grid, ic, |_, d, w, k| {
                let p = self.order[k] as usize;
                for (j, cj) in c.iter().enumerate() {
                    let g = 4 * ic + j;
                    let phi = w[j] * (cj[0] + cj[1] * d[j][0] + cj[2] * d[j][1]);
                    let wphi = self.gp_w[g] * phi;
                    vhat[p] += wphi;
                    for f in 0..K {
                        out[p][f] += wphi * val[g][f];
                    }
                }
            });
        }
    }

    /// Diagnostic, not a stage: a nodal field `nodal[I] = [_, ux, uy]` (the
    /// layout of `mv` after `grid_update::predict`) and its gradient at every
    /// Gauss point, [ux, uy, ∂ux/∂x, ∂ux/∂y, ∂uy/∂x, ∂uy/∂y].
    pub fn at_gauss_points(&self, nodal: &[[f64; 3]], out: &mut [[f64; 6]]) {
        for (g, o) in out.iter_mut().enumerate() {
            let (nodes, w) = self.gp_shape.particle(g);
            *o = [0.0; 6];
            for (&n, wk) in nodes.iter().zip(w) {
                let u = nodal[n as usize];
                o[0] += wk[0] * u[1];
                o[1] += wk[0] * u[2];
                o[2] += wk[1] * u[1];
                o[3] += wk[2] * u[1];
                o[4] += wk[1] * u[2];
                o[5] += wk[2] * u[2];
            }
        }
    }
}

#[inline]
fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// First column of A⁻¹ for the symmetric A = [a00 a01 a02; a01 a11 a12; a02 a12 a22]
/// given as [a00, a01, a02, a11, a12, a22]; `None` when A is (nearly) singular.
#[inline]
pub fn solve_e0(a: &[f64; 6]) -> Option<[f64; 3]> {
    let [a00, a01, a02, a11, a12, a22] = *a;
    let c00 = a11 * a22 - a12 * a12;
    let c01 = a02 * a12 - a01 * a22;
    let c02 = a01 * a12 - a02 * a11;
    let det = a00 * c00 + a01 * c01 + a02 * c02;
    // Written so that NaN counts as singular.
    let regular = a00 > 0.0 && det > SINGULAR_REL * a00 * a00 * a00;
    if !regular {
        return None;
    }
    Some([c00 / det, c01 / det, c02 / det])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weight_is_the_quadratic_spline() {
        assert_eq!(weight(0.0), 0.75);
        assert!((weight(0.5) - 0.5).abs() < 1e-15);
        assert!((weight(1.0) - 0.125).abs() < 1e-15);
        assert_eq!(weight(1.5), 0.0);
        assert_eq!(weight(2.0), 0.0);
        // Continuous at r = 1/2 with matching slopes (−1 on both sides).
        let e = 1e-7;
        assert!(((weight(0.5 + e) - weight(0.5 - e)) / (2.0 * e) + 1.0).abs() < 1e-6);
    }

    /// Linear fields are fitted exactly at every Gauss point from jittered
    /// particles, inside and at the open-knot boundary, and the nodal sums
    /// are their exact integrals over the square.
    #[test]
    fn reproduces_linear_fields_from_scattered_particles() {
        use crate::model::shape::bspline::Bspline;
        for shape in [
            Shape::Linear,
            Shape::Bspline(Bspline::midpoints(2)),
            Shape::Bspline(Bspline::midpoints(3)),
        ] {
            let h = 0.125;
            let grid = Grid::regular(h, [0.0, 0.0], 9, 9);
            let mut rng = crate::rng::SplitMix64::new(11);
            let mut x = Vec::new();
            for j in 0..24 {
                for i in 0..24 {
                    let jitter = |r: &mut crate::rng::SplitMix64| r.range(-0.4, 0.4);
                    x.push([
                        (i as f64 + 0.5 + jitter(&mut rng)) * h / 3.0,
                        (j as f64 + 0.5 + jitter(&mut rng)) * h / 3.0,
                    ]);
                }
            }
            let rho_f = |x: [f64; 2]| 2.0 + 0.5 * x[0] - 0.3 * x[1];
            let v_f = |x: [f64; 2]| [1.0 + x[1], -2.0 + 3.0 * x[0]];
            let sig_f = |x: [f64; 2]| [x[0], 2.0 * x[1], 1.0 - x[0] + x[1]];
            let rho: Vec<f64> = x.iter().map(|&p| rho_f(p)).collect();
            // v chosen so ρv is linear too: v = u/ρ with u linear.
            let v: Vec<[f64; 2]> = x
                .iter()
                .map(|&p| {
                    let u = v_f(p);
                    [u[0] / rho_f(p), u[1] / rho_f(p)]
                })
                .collect();
            let stress: Vec<[f64; 3]> = x.iter().map(|&p| sig_f(p)).collect();
            let mut mls = Mls::new(&shape, &grid, x.len()).unwrap();
            let mut mv = vec![[0.0; 3]; grid.n_nodes()];
            mls.p2g(&grid, &x, &rho, &v, &[], 0.0, &mut mv).unwrap();
            let mut force = vec![[0.0; 2]; grid.n_nodes()];
            let body = |_p: usize| [0.0, -10.0];
            mls.forces(&grid, &x, &rho, &stress, &body, &mut force);
            for g in 0..mls.n_gauss_points() {
                let xg = mls.gp_x[g];
                let (r, u, s) = (rho_f(xg), v_f(xg), sig_f(xg));
                let fit = mls.gp_mv[g];
                let fs = mls.gp_f[g];
                for (a, b) in [(fit[0], r), (fit[1], u[0]), (fit[2], u[1])]
                    .into_iter()
                    .chain([
                        (fs[0], s[0]),
                        (fs[1], s[1]),
                        (fs[2], s[2]),
                        (fs[4], -10.0 * r),
                    ])
                {
                    assert!((a - b).abs() < 1e-11, "{shape:?} at {xg:?}: {a} vs {b}");
                }
            }
            // ∫ρ over the unit square = 2 + 0.25 − 0.15.
            let mass: f64 = mv.iter().map(|m| m[0]).sum();
            assert!((mass - 2.1).abs() < 1e-12, "{shape:?}: {mass}");
            // ∫ρv_x = ∫(1 + y) = 1.5, ∫ρv_y = ∫(−2 + 3x) = −0.5.
            let qx: f64 = mv.iter().map(|m| m[1]).sum();
            let qy: f64 = mv.iter().map(|m| m[2]).sum();
            assert!(
                (qx - 1.5).abs() < 1e-12 && (qy + 0.5).abs() < 1e-12,
                "{qx} {qy}"
            );
            // Σ_I f_I = ∫ρb (Σ ∇N = 0): −10 · 2.1.
            let fy: f64 = force.iter().map(|f| f[1]).sum();
            assert!((fy + 21.0).abs() < 1e-10, "{fy}");
        }
    }

    /// Particles on one line leave the moment matrix singular: the fit
    /// reports the Gauss point instead of dividing by zero.
    #[test]
    fn collinear_particles_are_reported_as_singular() {
        let grid = Grid::regular(0.25, [0.0, 0.0], 5, 5);
        let x: Vec<[f64; 2]> = (0..12).map(|i| [0.02 + 0.08 * i as f64, 0.5]).collect();
        let n = x.len();
        let mut mls = Mls::new(&Shape::Linear, &grid, n).unwrap();
        let mut mv = vec![[0.0; 3]; grid.n_nodes()];
        let err = mls
            .p2g(
                &grid,
                &x,
                &vec![1.0; n],
                &vec![[0.0; 2]; n],
                &[],
                0.0,
                &mut mv,
            )
            .unwrap_err();
        assert!(matches!(err.kind, FaultKind::MlsSingular { .. }), "{err}");
        assert_eq!(err.code(), "mls_singular");
    }

    #[test]
    fn solve_e0_inverts() {
        let a = [4.0, 1.0, 0.5, 3.0, 0.2, 2.0];
        let c = solve_e0(&a).unwrap();
        let full = [[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]];
        for (r, row) in full.iter().enumerate() {
            let v = dot(row, &c);
            assert!((v - if r == 0 { 1.0 } else { 0.0 }).abs() < 1e-14);
        }
        // Collinear particles: rank 2.
        assert_eq!(solve_e0(&[2.0, 1.0, 0.0, 1.0, 0.0, 0.0]), None);
    }
}
