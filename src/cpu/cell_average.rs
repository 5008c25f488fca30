//! `solver.volumetric_strain = "cell_average"`, in the `stress` stage: a
//! B-bar against volumetric locking (Coombs, Charlton, Cortis & Augarde
//! 2018, "Overcoming volumetric locking in material point methods").
//! Under nearly incompressible flow (plasticity with no dilation, φ = 0
//! Tresca soil) a particle's own tr L over-constrains the few nodes of its
//! cell, and the limit loads come out high. Here each particle's
//! volumetric strain rate is replaced by the volume-weighted mean of tr L
//! over the particles of its body in its grid cell,
//!   L̄_p = L_p + ½ (⟨tr L⟩_c − tr L_p) I,  ⟨tr L⟩_c = Σ_q V_q tr L_q / Σ_q V_q,
//! q over the particles of p's body in p's cell; the deviatoric part stays
//! the particle's own. Bodies average apart, so a contact pair's two fields
//! do not mix. Applied as the additive correction `dl` the stress stage
//! already reads (`stress::stress`). GPU twin: shaders/cell_average.wgsl
//! with stress.wgsl built with CELL_AVERAGE.

use super::stage_inputs::ShapeCache;
use crate::model::Grid;
use rayon::prelude::*;

/// The per-step work space (sized once; a step allocates nothing).
#[derive(Debug)]
pub struct CellAverage {
    /// Cells along x and y.
    cells: [usize; 2],
    bodies: usize,
    /// Per (cell, body): Σ V tr L, Σ V.
    sums: Vec<[f64; 2]>,
    /// Per particle: tr L and its (cell, body) slot.
    tr: Vec<(f64, u32)>,
    /// Per particle: the correction added to L = [Lxx, Lxy, Lyx, Lyy].
    pub dl: Vec<[f64; 4]>,
}

impl CellAverage {
    pub fn new(grid: &Grid, bodies: usize, particles: usize) -> Self {
        let cells = [grid.nx - 1, grid.ny - 1];
        CellAverage {
            cells,
            bodies,
            sums: vec![[0.0; 2]; cells[0] * cells[1] * bodies.max(1)],
            tr: vec![(0.0, 0); particles],
            dl: vec![[0.0; 4]; particles],
        }
    }

    /// The corrections `dl` for the nodal velocities `mv` ([m, mvx, mvy]
    /// after the predictor: velocities) and the particles' shape cache.
    #[allow(clippy::too_many_arguments)]
    pub fn update(
        &mut self,
        grid: &Grid,
        cache: &ShapeCache,
        mv: &[[f64; 3]],
        x: &[[f64; 2]],
        mass: &[f64],
        rho: &[f64],
        body: &[u32],
    ) {
        let n = x.len();
        self.tr.resize(n, (0.0, 0));
        self.dl.resize(n, [0.0; 4]);
        let (cells, bodies) = (self.cells, self.bodies.max(1));
        self.tr
            .par_iter_mut()
            .enumerate()
            .with_min_len(1024)
            .for_each(|(p, out)| {
                let (nodes, w) = cache.particle(p);
                let mut t = 0.0;
                for (&node, wk) in nodes.iter().zip(w) {
                    let v = &mv[node as usize];
                    t += v[1] * wk[1] + v[2] * wk[2];
                }
                let c = cell_of(grid, cells, x[p]);
                *out = (t, (c * bodies + body[p] as usize) as u32);
            });
        self.sums.fill([0.0; 2]);
        for (p, &(t, k)) in self.tr.iter().enumerate() {
            let v = mass[p] / rho[p];
            let s = &mut self.sums[k as usize];
            s[0] += v * t;
            s[1] += v;
        }
        let sums = &self.sums;
        self.dl
            .par_iter_mut()
            .zip(&self.tr)
            .with_min_len(1024)
            .for_each(|(d, &(t, k))| {
                let s = sums[k as usize];
                let half = 0.5 * (s[0] / s[1] - t);
                *d = [half, 0.0, 0.0, half];
            });
    }
}

/// The lattice cell holding `x` (clamped to the grid).
#[inline]
fn cell_of(grid: &Grid, cells: [usize; 2], x: [f64; 2]) -> usize {
    let u = grid.logical(x);
    let i = (u[0].floor().max(0.0) as usize).min(cells[0] - 1);
    let j = (u[1].floor().max(0.0) as usize).min(cells[1] - 1);
    j * cells[0] + i
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Four particles in one cell of a 2 × 1-cell grid and one in the
    /// other, of two bodies; the cache's single "node" carries each
    /// particle's velocity gradient directly (∂N/∂x = 1 at node p with
    /// v = [Lxx, Lyx] … enough for tr L = v_x ∂N/∂x + v_y ∂N/∂y).
    fn setup(tr: &[f64]) -> (Grid, ShapeCache, Vec<[f64; 3]>) {
        let grid = Grid::regular(1.0, [0.0, 0.0], 3, 2);
        let mut cache = ShapeCache::new(tr.len(), 1);
        let mut mv = Vec::new();
        for (p, &t) in tr.iter().enumerate() {
            cache.count[p] = 1;
            cache.nodes[p] = p as u32;
            // v = [t, 0], ∇N = [1, 0]: tr L = t.
            cache.w[p] = [1.0, 1.0, 0.0];
            mv.push([1.0, t, 0.0]);
        }
        (grid, cache, mv)
    }

    #[test]
    fn the_cells_mean_replaces_each_particles_volumetric_rate_per_body() {
        let tr = [1.0, 3.0, 5.0, -2.0, 7.0];
        let (grid, cache, mv) = setup(&tr);
        // Particles 0–3 in cell 0 (3 is of body 1), 4 in cell 1.
        let x = [[0.2, 0.2], [0.7, 0.3], [0.5, 0.8], [0.4, 0.4], [1.5, 0.5]];
        let mass = [1.0, 1.0, 2.0, 1.0, 1.0];
        let rho = [1.0; 5];
        let body = [0, 0, 0, 1, 0];
        let mut ca = CellAverage::new(&grid, 2, 5);
        ca.update(&grid, &cache, &mv, &x, &mass, &rho, &body);
        // Body 0 in cell 0: (1 + 3 + 2·5)/4 = 3.5.
        for (p, (t, d)) in tr.iter().zip(&ca.dl).take(3).enumerate() {
            let corrected = t + d[0] + d[3];
            assert!((corrected - 3.5).abs() < 1e-14, "{p}: {corrected}");
            // Only the volumetric part changes.
            assert_eq!(d[0], d[3]);
            assert_eq!([d[1], d[2]], [0.0, 0.0]);
        }
        // Alone in their (cell, body): unchanged.
        assert_eq!(ca.dl[3], [0.0; 4]);
        assert_eq!(ca.dl[4], [0.0; 4]);
        // The cell's volume-weighted volumetric rate is kept.
        let v: f64 = (0..3).map(|p| mass[p] * (tr[p] + 2.0 * ca.dl[p][0])).sum();
        assert!((v - (1.0 + 3.0 + 10.0)).abs() < 1e-13);
    }
}
