//! Local max-ent shape functions (Arroyo & Ortiz 2006; paper §2.3):
//! p_a = exp(−β|x−x_a|² + λ·(x−x_a)) / Z, with λ the minimiser of log Z,
//! found per particle by damped Newton warm-started from the last step's λ.
//! ∇N_a = −N_a J⁻¹ (x − x_a). Nodes farther than r = h·sqrt(−ln(tol)/γ)
//! are dropped (exp(−β r²) = tol).
//! WGSL twin: `shaders/lme_newton.wgsl` and `shaders/shared/shape_lme.wgsl`.

use super::ShapeFault;
use crate::model::Grid;

pub use crate::limits::{
    LME_MAX_REACH_CELLS as MAX_REACH_CELLS, lme_gamma_max as gamma_max, lme_gamma_min as gamma_min,
};
/// Newton stops when |r| ≤ NEWTON_TOL · h and the Newton step
/// |J⁻¹ r| ≤ NEWTON_TOL / h. The first bounds the linear-reproduction error
/// (Σ N_a x_a − x = r), the second the gradient-consistency error
/// (Σ ∇N_a = −J⁻¹ r), which near the grid's edge, where J has a small
/// eigenvalue, is the larger. f64 reaches both in a few quadratic steps.
pub const NEWTON_TOL: f64 = 1e-10;
/// Iteration cap. Warm-started particles need 1–3; a cold start at γ = 6 about 8.
pub const NEWTON_MAX_ITER: u32 = 50;
/// Line-search halvings before the step is declared failed.
const LINE_SEARCH_MAX: u32 = 40;
/// Armijo constant of the line search.
const ARMIJO: f64 = 1e-4;

#[derive(Debug, Clone, PartialEq)]
pub struct Lme {
    /// Dimensionless locality γ = β h².
    pub gamma: f64,
    /// β (1/m²).
    pub beta: f64,
    /// Support radius r (m).
    pub radius: f64,
    /// Nominal spacing (m).
    pub h: f64,
    /// Extra search reach for perturbed nodes (m).
    pub search_extra: f64,
    /// Newton residual tolerance (m).
    pub tol: f64,
    /// Newton iteration cap.
    pub max_iter: u32,
}

impl Lme {
    pub fn new(gamma: f64, tol: f64, h: f64, perturb: f64) -> Self {
        let radius = h * (-tol.ln() / gamma).sqrt();
        Lme {
            gamma,
            beta: gamma / (h * h),
            radius,
            h,
            search_extra: std::f64::consts::SQRT_2 * perturb * h,
            tol: NEWTON_TOL * h,
            max_iter: NEWTON_MAX_ITER,
        }
    }

    /// Search radius in lattice units (support plus perturbation).
    fn search_cells(&self) -> f64 {
        (self.radius + self.search_extra) / self.h
    }

    pub fn reach_cells(&self) -> usize {
        (self.radius / self.h).ceil() as usize
    }

    /// Upper bound on the nodes inside the support: every such node's unit
    /// lattice cell lies in a disk of radius R + √2/2, so the count is at most
    /// π (R + √2/2)², and never more than the search box.
    pub fn max_nodes(&self) -> usize {
        let r = self.search_cells();
        let disk = std::f64::consts::PI * (r + std::f64::consts::FRAC_1_SQRT_2).powi(2);
        let side = 2.0 * r.floor() + 2.0;
        disk.min(side * side).ceil() as usize
    }

    /// Evaluates LME at `x`: finds the support nodes, solves for λ (warm
    /// start from `lambda`, which receives the solution) and writes N and ∇N.
    /// Returns (nodes written, Newton iterations).
    pub fn eval(
        &self,
        grid: &Grid,
        x: [f64; 2],
        lambda: &mut [f64; 2],
        nodes: &mut [u32],
        w: &mut [[f64; 3]],
    ) -> Result<(usize, u32), ShapeFault> {
        if !grid.contains(x, 0.0) {
            return Err(ShapeFault::OutsideGrid);
        }
        // Gather support nodes; w[k][1..3] temporarily holds d = x − x_a.
        let q = grid.logical(x);
        let reach = self.search_cells();
        let i0 = (q[0] - reach).ceil().max(0.0) as usize;
        let i1 = ((q[0] + reach).floor() as usize).min(grid.nx - 1);
        let j0 = (q[1] - reach).ceil().max(0.0) as usize;
        let j1 = ((q[1] + reach).floor() as usize).min(grid.ny - 1);
        let r2 = self.radius * self.radius;
        let mut n = 0;
        for j in j0..=j1 {
            for i in i0..=i1 {
                let xa = grid.node_pos(i, j);
                let d = [x[0] - xa[0], x[1] - xa[1]];
                if d[0] * d[0] + d[1] * d[1] <= r2 {
                    nodes[n] = grid.index(i, j) as u32;
                    w[n] = [0.0, d[0], d[1]];
                    n += 1;
                }
            }
        }
        if n < 3 {
            return Err(ShapeFault::LmeTooFewNodes { nodes: Some(n) });
        }
        let its = self.newton(&mut w[..n], lambda)?;
        Ok((n, its))
    }

    /// Damped Newton on λ over the gathered nodes (`w[k] = [_, dx, dy]` in,
    /// d = x − x_a, `[N, ∂N/∂x, ∂N/∂y]` out), warm-started from `lambda`,
    /// which receives the solution. Returns the iterations taken. Any node
    /// set will do (the grid's support here, a GMM node cloud in
    /// `gmm::basis`); only `beta`, `h`, `tol` and `max_iter` are read.
    pub fn newton(&self, w: &mut [[f64; 3]], lambda: &mut [f64; 2]) -> Result<u32, ShapeFault> {
        let mut lam = *lambda;
        let mut cur = self.objective(w, lam);
        for it in 0..=self.max_iter {
            let (r, jm) = (cur.r, cur.j);
            let rn = (r[0] * r[0] + r[1] * r[1]).sqrt();
            let det = jm[0] * jm[2] - jm[1] * jm[1];
            let tr = jm[0] + jm[2];
            // Also catches NaN: every comparison with NaN is false.
            let regular = det > 1e-14 * tr * tr;
            if !regular || !rn.is_finite() {
                return Err(ShapeFault::LmeSingular { iterations: it });
            }
            let inv = [jm[2] / det, -jm[1] / det, jm[0] / det];
            let step = [
                -(inv[0] * r[0] + inv[1] * r[1]),
                -(inv[1] * r[0] + inv[2] * r[1]),
            ];
            let step_n = step[0].hypot(step[1]);
            if rn <= self.tol && step_n * self.h * self.h <= self.tol {
                // Converged: N_a = p_a, ∇N_a = −p_a J⁻¹ (x − x_a).
                // w[k][0] holds exp(f_a − f_max) of the last (accepted) evaluation.
                for wk in w.iter_mut() {
                    let d = [wk[1], wk[2]];
                    let pa = wk[0] / cur.z;
                    wk[0] = pa;
                    wk[1] = -pa * (inv[0] * d[0] + inv[1] * d[1]);
                    wk[2] = -pa * (inv[1] * d[0] + inv[2] * d[1]);
                }
                *lambda = lam;
                return Ok(it);
            }
            if it == self.max_iter {
                return Err(ShapeFault::LmeNotConverged {
                    iterations: it,
                    residual: Some(rn / self.h),
                });
            }
            // Backtracking along the Newton direction (log Z is convex in λ).
            let slope = r[0] * step[0] + r[1] * step[1];
            let mut alpha = 1.0;
            let mut accepted = None;
            for _ in 0..LINE_SEARCH_MAX {
                let trial = [lam[0] + alpha * step[0], lam[1] + alpha * step[1]];
                let t = self.objective(w, trial);
                // Near the minimum the decrease (~|r|²/|J|) falls below the
                // round-off of log Z; allow for that so the last quadratic
                // steps are not refused.
                let roundoff = 8.0 * f64::EPSILON * cur.log_z.abs().max(1.0);
                if t.log_z <= cur.log_z + ARMIJO * alpha * slope + roundoff {
                    accepted = Some((trial, t));
                    break;
                }
                alpha *= 0.5;
            }
            let Some((trial, t)) = accepted else {
                return Err(ShapeFault::LmeNotConverged {
                    iterations: it,
                    residual: Some(rn / self.h),
                });
            };
            lam = trial;
            cur = t;
        }
        unreachable!("the loop returns at it == max_iter")
    }

    /// log Z, r = ∂ log Z/∂λ and J = ∂r/∂λ (symmetric: [J00, J01, J11]) at λ.
    /// Leaves exp(f_a − f_max) in `w[k][0]` so the caller need not recompute it.
    fn objective(&self, w: &mut [[f64; 3]], lam: [f64; 2]) -> Objective {
        // Shift by the largest exponent so exp never overflows.
        let mut fmax = f64::NEG_INFINITY;
        for wk in w.iter() {
            let f = -self.beta * (wk[1] * wk[1] + wk[2] * wk[2]) + lam[0] * wk[1] + lam[1] * wk[2];
            fmax = fmax.max(f);
        }
        let (mut z, mut r, mut m) = (0.0, [0.0; 2], [0.0; 3]);
        for wk in w.iter_mut() {
            let d = [wk[1], wk[2]];
            let f = -self.beta * (d[0] * d[0] + d[1] * d[1]) + lam[0] * d[0] + lam[1] * d[1];
            let e = (f - fmax).exp();
            wk[0] = e;
            z += e;
            r[0] += e * d[0];
            r[1] += e * d[1];
            m[0] += e * d[0] * d[0];
            m[1] += e * d[0] * d[1];
            m[2] += e * d[1] * d[1];
        }
        let (r0, r1) = (r[0] / z, r[1] / z);
        Objective {
            log_z: fmax + z.ln(),
            z,
            r: [r0, r1],
            j: [m[0] / z - r0 * r0, m[1] / z - r0 * r1, m[2] / z - r1 * r1],
        }
    }
}

struct Objective {
    /// log Z (with the exponent shift put back).
    log_z: f64,
    /// Σ exp(f_a − f_max): divides w[k][0] into N_a.
    z: f64,
    r: [f64; 2],
    j: [f64; 3],
}
