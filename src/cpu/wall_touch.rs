//! Pass `wall_touch` of stage `grid_update` (walls only, before
//! `predict`): per node, the weight S_I of the particles in contact with a
//! wall (their domain reaches past its contact line), and T_I, the same
//! with the weights their friction acts with (at the wall's line for
//! linear shapes), and the walls' preloads on the nodes. Only the walls
//! that act in the step (`Wall::active_at`: a gate's `appear_at` ≤ t <
//! `remove_at`) are in contact. What it reads of the particles
//! (`ContactParticles`) and the weights at a wall's line are shared with
//! `wall_contact`. GPU twin: `shaders/wall_touch.wgsl`.

use super::stage_inputs::ShapeCache;
use crate::model::shape::Shape;
use crate::model::walls::{self, face_weight, half_width, wall_depth};
use crate::model::{Grid, Walls};

/// `walls::contact_spring` of particle `p` on wall `k`, read from `pt`:
/// (spring force, preload), N per unit thickness.
#[inline]
pub(super) fn contact_spring(
    p: usize,
    k: usize,
    pt: &ContactParticles,
    walls: &Walls,
) -> (f64, f64) {
    walls::contact_spring(
        walls,
        p,
        k,
        pt.x[p],
        pt.mass[p],
        pt.rho[p],
        pt.stress[p],
        pt.gravity,
    )
}

/// What the contact reads of the particles: positions (m), masses (kg
/// per unit thickness), densities (kg/m³), stresses (Pa, for the
/// preload) and the scene's full gravity (m/s², zero without).
pub struct ContactParticles<'a> {
    pub x: &'a [[f64; 2]],
    pub mass: &'a [f64],
    pub rho: &'a [f64],
    pub stress: &'a [[f64; 3]],
    pub v: &'a [[f64; 2]],
    pub gravity: [f64; 2],
    /// The shape and grid by which the preload's weights at the wall's
    /// line are evaluated exactly (`LineWeights`), for B-splines; `None`
    /// keeps the first-order `face_weight`.
    pub line: Option<(&'a Shape, &'a Grid)>,
}

/// Most nodes of a B-spline's support (cubic: 4 × 4).
const LINE_NODES: usize = 16;

/// The nodes and weights N_I(x_p − d n) of a contact's point on the wall's
/// line, evaluated by the shape itself (B-splines; `ContactParticles::line`).
/// Fixed-size, so that a step allocates nothing (tests/no_alloc.rs).
pub(super) struct LineWeights {
    nodes: [u32; LINE_NODES],
    w: [[f64; 3]; LINE_NODES],
    len: usize,
}

impl LineWeights {
    pub(super) fn new(line: Option<(&Shape, &Grid)>) -> Self {
        assert!(
            line.is_none_or(|(s, _)| s.max_nodes() <= LINE_NODES),
            "line weights hold B-spline supports of at most {LINE_NODES} nodes"
        );
        LineWeights {
            nodes: [0; LINE_NODES],
            w: [[0.0; 3]; LINE_NODES],
            len: 0,
        }
    }

    /// Evaluates the weights at the point `d` (m) behind `x` along `n`,
    /// in the field of the particle whose first node is `first` (contact
    /// pairs stack a field per body: `cpu::contact_grad::offset_nodes`); false
    /// when there is no shape to evaluate (or it fails there).
    pub(super) fn at(
        &mut self,
        line: Option<(&Shape, &Grid)>,
        first: u32,
        x: [f64; 2],
        n: [f64; 2],
        d: f64,
    ) -> bool {
        let Some((shape, grid)) = line else {
            return false;
        };
        let xl = [x[0] - d * n[0], x[1] - d * n[1]];
        match shape.eval(grid, xl, &mut [0.0; 2], &mut self.nodes, &mut self.w) {
            Ok(k) => {
                let per_field = grid.n_nodes() as u32;
                let off = first / per_field * per_field;
                for node in &mut self.nodes[..k] {
                    *node += off;
                }
                self.len = k;
                true
            }
            Err(_) => false,
        }
    }

    pub(super) fn iter(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        self.nodes[..self.len]
            .iter()
            .zip(&self.w[..self.len])
            .map(|(&n, w)| (n as usize, w[0]))
    }
}

/// Per node, `touch[n] = [S_I, T_I]`: the contact weight S_I = Σ_p N_Ip
/// over the particles in contact with a wall (`contact_spring` > 0; a
/// particle in contact with two walls counts twice), and the friction's
/// T_I = Σ_p F_Ip over the same contacts, F_Ip the weights the contact's
/// friction goes to the nodes with (`friction_weight`: at the wall's line
/// for linear shapes, else N_Ip), by which `wall_contact` sizes the
/// friction. Only the walls that act in the step
/// starting at `t` (s) count (`Wall::active_at`), so a removed gate, or
/// one not there yet, is nowhere in contact. With preloads
/// (`Walls::preload`; `pre_force` is empty without), each contact's
/// preload P n onto the nodes at the wall's line (`face_weight`), into
/// `pre_force`: the load the walls carry whatever the body does, which
/// `wall_contact` counts in the body's velocity before it decides the
/// rest (else a stick floor's friction at a corner would also take up
/// the side wall's preload). `touch` and `pre_force` are zeroed first
/// (their GPU twins by `clear_grid`).
pub fn wall_touch(
    cache: &ShapeCache,
    pt: &ContactParticles,
    walls: &Walls,
    t: f64,
    touch: &mut [[f64; 2]],
    pre_force: &mut [[f64; 2]],
) {
    touch.fill([0.0; 2]);
    pre_force.fill([0.0; 2]);
    let fit_on = walls.fit_at(t);
    let mut lw = LineWeights::new(pt.line);
    for p in 0..pt.x.len() {
        let (nodes, w) = cache.particle(p);
        let lp = half_width(pt.mass[p], pt.rho[p]);
        let mut count = 0;
        for (k, wl) in walls.list.iter().enumerate() {
            if !wl.active_at(t) {
                continue;
            }
            let (spring, pre) = contact_spring(p, k, pt, walls);
            if spring <= 0.0 {
                continue;
            }
            count += 1;
            let d = wall_depth(pt.x[p], lp, wl);
            let on_line = line_weights_positive(w, wl.normal, d);
            for (&n, wk) in nodes.iter().zip(w) {
                touch[n as usize][1] += friction_weight(wk, wl.normal, d, on_line);
            }
            if pre > 0.0
                && lw.at(
                    pt.line,
                    nodes.first().copied().unwrap_or(0),
                    pt.x[p],
                    wl.normal,
                    d,
                )
            {
                for (n, wn) in lw.iter() {
                    pre_force[n][0] += pre * wn * wl.normal[0];
                    pre_force[n][1] += pre * wn * wl.normal[1];
                }
            } else if pre > 0.0 {
                for (&n, wk) in nodes.iter().zip(w) {
                    let f = pre * face_weight(wk, wl.normal, d);
                    pre_force[n as usize][0] += f * wl.normal[0];
                    pre_force[n as usize][1] += f * wl.normal[1];
                }
            }
            // The fit to the discrete reaction (`Walls::pre_fit`; empty
            // where the line's weights already give it).
            if pre > 0.0 && fit_on {
                for (&n, wk) in nodes.iter().zip(w) {
                    let a = walls.pre_fit[n as usize];
                    pre_force[n as usize][0] += pre * wk[0] * a[0];
                    pre_force[n as usize][1] += pre * wk[0] * a[1];
                }
            }
        }
        if count == 0 {
            continue;
        }
        for (&n, wk) in nodes.iter().zip(w) {
            touch[n as usize][0] += count as f64 * wk[0];
        }
    }
}

/// Whether the weights at the wall's line (`face_weight`) of a particle
/// with weights `wt` ([N, ∇N] per node), at distance `d` (m) from the
/// line along `n`, are all non-negative (to `LINE_WEIGHT_EPS`): always for linear
/// shapes while the line is in the particle's cell; LME's and the
/// B-splines' wider stencils extrapolate to negative weights on the nodes
/// away from the line. The friction acts on the line only where they are
/// (docs/methods.md, "Walls": with negative weights the geostatic LME
/// column moved at 1.1e-2 m/s).
#[inline]
pub(super) fn line_weights_positive(wt: &[[f64; 3]], n: [f64; 2], d: f64) -> bool {
    wt.iter()
        .all(|wk| face_weight(wk, n, d) >= -LINE_WEIGHT_EPS)
}

/// The weight of a node in a contact's friction: at the wall's line
/// (`face_weight`) where the line's weights are all non-negative
/// (`on_line`, from `line_weights_positive`), else the particle's N.
#[inline]
fn friction_weight(wk: &[f64; 3], n: [f64; 2], d: f64, on_line: bool) -> f64 {
    if on_line {
        face_weight(wk, n, d)
    } else {
        wk[0]
    }
}

/// Round-off allowance of `line_weights_positive`: the weights are O(1)
/// and the GPU twin computes them in f32 (a linear particle's node above
/// the line gets 0 exactly in exact arithmetic, ±1e-7 in f32), so both
/// decide alike.
pub const LINE_WEIGHT_EPS: f64 = 1e-6;
