//! Part of stage `grid_update` (explicit integrators): the constraint
//! points (`model::constraint_points`) hold the body at their region's
//! edge. After `predict`, and after `correct`, the nodal velocities take
//! the smallest mass-weighted change that gives every point its
//! prescribed velocity: per held component, with C_ba = N_a(x_b) over the
//! nodes with mass whose component is free,
//!   Δv = M⁻¹ Cᵀ λ,   (C M⁻¹ Cᵀ) λ = v̄ − C v,
//! a Lagrange multiplier per point with the lumped mass (the points of one
//! edge overlap in their nodes, so λ comes from one small dense solve,
//! regularised by `HOLD_REG` because two points per cell can be more than
//! the nodes they hold). In `correct` the change is a force, m Δv / (γΔt),
//! added to f_I (so the particles' FLIP update feels it) and to the
//! group's reaction. No GPU twin yet: the GPU path refuses such scenes
//! (`simulation::open_backend`).

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
    let mut s = vec![0.0; k * k];
    let mut start = 0;
    while start < by_node.len() {
        let a = by_node[start].0;
        let mut end = start;
        while end < by_node.len() && by_node[end].0 == a {
            end += 1;
        }
        let inv_m = 1.0 / mv[a][0];
        for &(_, i, wi) in &by_node[start..end] {
            for &(_, j, wj) in &by_node[start..end] {
                s[i * k + j] += wi * wj * inv_m;
            }
        }
        start = end;
    }
    for i in 0..k {
        s[i * k + i] *= 1.0 + HOLD_REG;
    }
    let l = cholesky(&mut s, k);
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
        cholesky_solve(&s, k, &mut r);
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

/// In-place Cholesky S = L Lᵀ (lower triangle of `s`, row-major k × k);
/// false when a pivot is not positive.
fn cholesky(s: &mut [f64], k: usize) -> bool {
    for j in 0..k {
        let mut d = s[j * k + j];
        for m in 0..j {
            d -= s[j * k + m] * s[j * k + m];
        }
        if d <= 0.0 || !d.is_finite() {
            return false;
        }
        let d = d.sqrt();
        s[j * k + j] = d;
        for i in j + 1..k {
            let mut x = s[i * k + j];
            for m in 0..j {
                x -= s[i * k + m] * s[j * k + m];
            }
            s[i * k + j] = x / d;
        }
    }
    true
}

/// Solves L Lᵀ x = r in place (`s` from `cholesky`).
fn cholesky_solve(s: &[f64], k: usize, r: &mut [f64]) {
    for i in 0..k {
        let mut x = r[i];
        for m in 0..i {
            x -= s[i * k + m] * r[m];
        }
        r[i] = x / s[i * k + i];
    }
    for i in (0..k).rev() {
        let mut x = r[i];
        for m in i + 1..k {
            x -= s[m * k + i] * r[m];
        }
        r[i] = x / s[i * k + i];
    }
}
