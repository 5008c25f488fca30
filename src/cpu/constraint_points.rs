//! Part of stage `grid_update` (explicit integrators): the constraint
//! points (`model::constraint_points`) hold the body at their region's
//! edge. After `predict`, and after `correct`, the nodal velocities take
//! the smallest mass-weighted change that gives every point its
//! prescribed velocity: per held component, with C_ba = N_a(x_b) over the
//! nodes with mass whose component is free,
//!   Δv = M⁻¹ Cᵀ λ,   (C M⁻¹ Cᵀ) λ = v̄ − C v,
//! a Lagrange multiplier per point with the lumped mass (the points of one
//! edge overlap in their nodes, so λ comes from one solve, a Cholesky in
//! the band of the points that share nodes,
//! regularised by `HOLD_REG` because two points per cell can be more than
//! the nodes they hold). In `correct` the change is a force, m Δv / (γΔt),
//! added to f_I (so the particles' FLIP update feels it) and to the
//! group's reaction. GPU twin: `shaders/constraint_points.wgsl` (its
//! tables: `gpu::constraint_points`).

use crate::model::{ConstraintGroup, ConstraintPoint, FIX_X, FIX_Y};

/// Relative regularisation of the points' system: λ solves
/// (S + ε diag S) λ = r, ε = 1e-10, which leaves a consistent redundant
/// system's residual at about ε of r (then `REFINE` passes take it to
/// round-off) and keeps the factorisation positive.
const HOLD_REG: f64 = 1e-10;

/// Refinement passes after the first solve (each solves for what is left).
const REFINE: usize = 2;

/// Where `correct` puts the constraint's force: the nodal forces, the
/// groups' reactions and the step's γΔt (s).
pub struct AsForce<'a> {
    pub force: &'a mut [[f64; 2]],
    pub reactions: &'a mut [[f64; 2]],
    pub gamma_dt: f64,
}

/// Holds every point at its group's velocity at time `t` (s) on `mv`
/// (`[m, vx, vy]` per node; with contact pairs one copy per field,
/// stacked, each held on its own). `fix` is per grid node: components a
/// node constraint fixes are not changed.
pub fn hold(
    mv: &mut [[f64; 3]],
    fix: &[u8],
    points: &[ConstraintPoint],
    groups: &[ConstraintGroup],
    t: f64,
    mass_eps: f64,
    mut as_force: Option<AsForce>,
) {
    if points.is_empty() {
        return;
    }
    let n_nodes = fix.len();
    for (field, mv) in mv.chunks_mut(n_nodes).enumerate() {
        for (c, bit) in [(0usize, FIX_X), (1, FIX_Y)] {
            let held: Vec<&ConstraintPoint> = points
                .iter()
                .filter(|p| p.fix & bit != 0)
                .filter(|p| {
                    p.nodes
                        .iter()
                        .any(|&a| mv[a as usize][0] > mass_eps && fix[a as usize] & bit == 0)
                })
                .collect();
            if held.is_empty() {
                continue;
            }
            let target: Vec<f64> = held
                .iter()
                .map(|p| groups[p.group as usize].velocity_at(t)[c])
                .collect();
            let (dv, pushes) = solve(mv, fix, bit, &held, &target, c, mass_eps);
            for &(a, d) in &dv {
                mv[a][1 + c] += d;
            }
            if let Some(f) = as_force.as_mut() {
                let base = field * n_nodes;
                for &(a, d) in &dv {
                    f.force[base + a][c] += mv[a][0] * d / f.gamma_dt;
                }
                for (p, push) in held.iter().zip(pushes) {
                    f.reactions[p.group as usize][c] += push / f.gamma_dt;
                }
            }
        }
    }
}

/// The nodes' velocity changes (node, Δv) of one component `c` that hold
/// the points `held` at `target`, by the regularised projection, and each
/// point's momentum change λ_b Σ_a N_ab (kg m/s per unit thickness; its
/// force is this over γΔt).
fn solve(
    mv: &[[f64; 3]],
    fix: &[u8],
    bit: u8,
    held: &[&ConstraintPoint],
    target: &[f64],
    c: usize,
    mass_eps: f64,
) -> (Vec<(usize, f64)>, Vec<f64>) {
    let free = |a: usize| mv[a][0] > mass_eps && fix[a] & bit == 0;
    // S = C M⁻¹ Cᵀ over the free nodes with mass, per node's points.
    let k = held.len();
    let mut by_node: Vec<(usize, usize, f64)> = Vec::new();
    for (i, p) in held.iter().enumerate() {
        for (&a, &w) in p.nodes.iter().zip(&p.n) {
            if free(a as usize) {
                by_node.push((a as usize, i, w));
            }
        }
    }
    by_node.sort_unstable_by_key(|&(a, i, _)| (a, i));
    // S in its envelope: row i from the first point that shares a node
    // with it (points along an edge share nodes with their neighbours
    // only, so the envelope is a band and its factor stays in it).
    let mut groups = Vec::new();
    let mut start = 0;
    while start < by_node.len() {
        let mut end = start;
        while end < by_node.len() && by_node[end].0 == by_node[start].0 {
            end += 1;
        }
        groups.push(start..end);
        start = end;
    }
    let mut first: Vec<usize> = (0..k).collect();
    for g in &groups {
        let lo = by_node[g.start].1;
        for &(_, i, _) in &by_node[g.clone()] {
            first[i] = first[i].min(lo);
        }
    }
    let mut s = Envelope::new(first);
    for g in &groups {
        let inv_m = 1.0 / mv[by_node[g.start].0][0];
        for &(_, i, wi) in &by_node[g.clone()] {
            for &(_, j, wj) in &by_node[g.clone()] {
                if j <= i {
                    *s.at(i, j) += wi * wj * inv_m;
                }
            }
        }
    }
    for i in 0..k {
        *s.at(i, i) *= 1.0 + HOLD_REG;
    }
    let l = s.cholesky();
    // v at each point now, then λ and its refinements.
    let mut v: Vec<f64> = held
        .iter()
        .map(|p| {
            p.nodes
                .iter()
                .zip(&p.n)
                .map(|(&a, &w)| w * mv[a as usize][1 + c])
                .sum()
        })
        .collect();
    let mut lambda = vec![0.0; k];
    for _ in 0..=REFINE {
        let mut r: Vec<f64> = target.iter().zip(&v).map(|(t, x)| t - x).collect();
        if !l {
            break;
        }
        s.solve(&mut r);
        for (li, ri) in lambda.iter_mut().zip(&r) {
            *li += ri;
        }
        // v at the points after the change so far: C (v + M⁻¹ Cᵀ λ).
        let mut dvn: Vec<(usize, f64)> = Vec::new();
        change(&by_node, &lambda, mv, &mut dvn);
        for (i, p) in held.iter().enumerate() {
            v[i] = p
                .nodes
                .iter()
                .zip(&p.n)
                .map(|(&a, &w)| {
                    let a = a as usize;
                    let d = dvn
                        .binary_search_by_key(&a, |&(n, _)| n)
                        .map_or(0.0, |k| dvn[k].1);
                    w * (mv[a][1 + c] + d)
                })
                .sum();
        }
    }
    let mut dv = Vec::new();
    change(&by_node, &lambda, mv, &mut dv);
    let mut pushes = vec![0.0; k];
    for &(_, i, w) in &by_node {
        pushes[i] += w * lambda[i];
    }
    (dv, pushes)
}

/// Δv_a = Σ_i N_ia λ_i / m_a over `by_node` (sorted by node), into `out`
/// sorted by node.
fn change(
    by_node: &[(usize, usize, f64)],
    lambda: &[f64],
    mv: &[[f64; 3]],
    out: &mut Vec<(usize, f64)>,
) {
    out.clear();
    for &(a, i, w) in by_node {
        let d = w * lambda[i] / mv[a][0];
        match out.last_mut() {
            Some(last) if last.0 == a => last.1 += d,
            _ => out.push((a, d)),
        }
    }
}

/// A symmetric matrix by rows of its lower envelope: row i holds columns
/// `first[i]..=i`.
struct Envelope {
    first: Vec<usize>,
    start: Vec<usize>,
    val: Vec<f64>,
}

impl Envelope {
    fn new(first: Vec<usize>) -> Envelope {
        let mut start = Vec::with_capacity(first.len() + 1);
        let mut n = 0;
        for (i, &f) in first.iter().enumerate() {
            start.push(n);
            n += i + 1 - f;
        }
        start.push(n);
        Envelope {
            first,
            start,
            val: vec![0.0; n],
        }
    }

    /// Entry (i, j), j in `first[i]..=i`.
    #[inline]
    fn at(&mut self, i: usize, j: usize) -> &mut f64 {
        &mut self.val[self.start[i] + j - self.first[i]]
    }

    #[inline]
    fn get(&self, i: usize, j: usize) -> f64 {
        self.val[self.start[i] + j - self.first[i]]
    }

    /// In-place Cholesky S = L Lᵀ (the factor fills no entry outside the
    /// envelope); false when a pivot is not positive.
    fn cholesky(&mut self) -> bool {
        for i in 0..self.first.len() {
            for j in self.first[i]..=i {
                let mut x = self.get(i, j);
                for m in self.first[i].max(self.first[j])..j {
                    x -= self.get(i, m) * self.get(j, m);
                }
                if j < i {
                    *self.at(i, j) = x / self.get(j, j);
                } else if x > 0.0 && x.is_finite() {
                    *self.at(i, i) = x.sqrt();
                } else {
                    return false;
                }
            }
        }
        true
    }

    /// Solves L Lᵀ x = r in place (after `cholesky`).
    fn solve(&self, r: &mut [f64]) {
        for i in 0..r.len() {
            let f = self.first[i];
            let row = &self.val[self.start[i]..self.start[i + 1]];
            let x = r[i]
                - row[..i - f]
                    .iter()
                    .zip(&r[f..i])
                    .map(|(l, y)| l * y)
                    .sum::<f64>();
            r[i] = x / row[i - f];
        }
        for i in (0..r.len()).rev() {
            let f = self.first[i];
            let row = &self.val[self.start[i]..self.start[i + 1]];
            r[i] /= row[i - f];
            let xi = r[i];
            for (y, l) in r[f..i].iter_mut().zip(&row[..i - f]) {
                *y -= l * xi;
            }
        }
    }
}
