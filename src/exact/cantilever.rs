//! Cantilever under self-weight, static (implicit-MPM paper §5.1): a beam
//! of length L and height H clamped at its left end, plane strain, loaded
//! by its own weight w = ρ g H per unit length.
//!
//! References: Timoshenko's linear deflection of the free end (eq. 62),
//!   δ = w L⁴ / (8 E I) + w L² / (2 κ G A), I = H³/12, A = H, κ = 5/6,
//! which is 0.67806 m for the paper's beam (L = 8 m, H = 1 m, ρ = 1000
//! kg/m³, E = 90 MPa, ν = 0, g = 9.81 m/s²), and the paper's nonlinear
//! value 0.67433 m at its finest mesh, which applies to that beam only.
//!
//! The measured deflection is the vertical displacement of the free end's
//! mid-height point (the paper's measurement point), which no particle
//! occupies: it is fitted from the particles within two cells of the free
//! end, u_y ≈ c0 + c1 ξ + c2 ξ² + c3 η (ξ, η the reference position
//! relative to the point), and evaluated at ξ = η = 0. The fit's error is
//! O(h³), below the O(h²) of the discretisation, so the mesh study sees the
//! method's order rather than the probe's offset.

use crate::model::Particles;
use crate::scene::Scene;
use serde::Serialize;

/// The paper's nonlinear deflection at its finest mesh (m).
pub const PAPER_NONLINEAR: f64 = 0.67433;
/// The paper's Timoshenko value, eq. 62 (m).
pub const PAPER_TIMOSHENKO: f64 = 0.67806;

#[derive(Debug, Clone, PartialEq)]
pub struct Cantilever {
    /// Free end's abscissa and mid-height in the reference configuration (m).
    pub tip: [f64; 2],
    pub length: f64,
    pub height: f64,
    /// Timoshenko's deflection for this scene (m, downward positive).
    pub timoshenko: f64,
    /// The paper's nonlinear value when the scene is the paper's beam.
    pub nonlinear: Option<f64>,
    /// Cell size (m): particles within 2h of the free end enter the fit.
    pub h: f64,
}

/// Figures for `summary.json`.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct CantileverErrors {
    /// Downward deflection of the free end's mid-height point (m).
    pub deflection: f64,
    /// Timoshenko's linear value for this beam (m).
    pub deflection_timoshenko: f64,
    /// |δ − δ_Timoshenko| / δ_Timoshenko.
    pub rel_error_timoshenko: f64,
    /// The paper's nonlinear reference 0.67433 m (the paper's beam only).
    pub deflection_reference: Option<f64>,
    /// |δ − 0.67433| / 0.67433 (the paper's beam only).
    pub rel_error: Option<f64>,
}

impl Cantilever {
    /// From the scene's bodies (their bounding box is the beam), its one
    /// material and its gravity (validated).
    pub fn from_scene(scene: &Scene) -> Cantilever {
        let bb = crate::scene::seed::bodies_bbox(scene);
        let m = scene.materials().next().expect("validated: one material").1;
        let g = scene.file.gravity.as_ref().map_or(0.0, |g| -g.g[1]);
        let (length, height) = (bb[2] - bb[0], bb[3] - bb[1]);
        let (e, nu) = (
            m.get("E").expect("validated: E"),
            m.get("nu").unwrap_or(0.0),
        );
        let timoshenko = timoshenko(length, height, m.density, e, nu, g);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs();
        let paper = close(length, 8.0)
            && close(height, 1.0)
            && close(m.density, 1000.0)
            && close(e, 90e6)
            && nu == 0.0
            && close(g, 9.81);
        Cantilever {
            tip: [bb[2], 0.5 * (bb[1] + bb[3])],
            length,
            height,
            timoshenko,
            nonlinear: paper.then_some(PAPER_NONLINEAR),
            h: scene.file.grid.h,
        }
    }

    /// Downward deflection of the tip point (m), from the particles' displacements.
    pub fn deflection(&self, p: &Particles) -> f64 {
        let near: Vec<usize> = (0..p.len())
            .filter(|&i| p.x0[i][0] >= self.tip[0] - 2.0 * self.h)
            .collect();
        // Normal equations of the 4-term fit, in units of h.
        let mut a = [[0.0; 4]; 4];
        let mut b = [0.0; 4];
        for &i in &near {
            let xi = (p.x0[i][0] - self.tip[0]) / self.h;
            let eta = (p.x0[i][1] - self.tip[1]) / self.h;
            let row = [1.0, xi, xi * xi, eta];
            let u = p.x[i][1] - p.x0[i][1];
            for r in 0..4 {
                b[r] += row[r] * u;
                for c in 0..4 {
                    a[r][c] += row[r] * row[c];
                }
            }
        }
        match solve4(a, b) {
            Some(c) if near.len() >= 4 => -c[0],
            // Too few particles to fit (never at two or more particles per
            // cell): the nearest particle's displacement.
            _ => {
                let i = p.nearest(self.tip);
                -(p.x[i][1] - p.x0[i][1])
            }
        }
    }

    pub fn score(&self, p: &Particles) -> CantileverErrors {
        let d = self.deflection(p);
        CantileverErrors {
            deflection: d,
            deflection_timoshenko: self.timoshenko,
            rel_error_timoshenko: (d - self.timoshenko).abs() / self.timoshenko.abs(),
            deflection_reference: self.nonlinear,
            rel_error: self.nonlinear.map(|r| (d - r).abs() / r),
        }
    }
}

/// Timoshenko's free-end deflection of a cantilever of length `l` and
/// height `h` (m) under its own weight (eq. 62), unit thickness (m).
pub fn timoshenko(l: f64, h: f64, rho: f64, e: f64, nu: f64, g: f64) -> f64 {
    let w = rho * g * h;
    let i = h.powi(3) / 12.0;
    let shear = e / (2.0 * (1.0 + nu));
    w * l.powi(4) / (8.0 * e * i) + w * l * l / (2.0 * (5.0 / 6.0) * shear * h)
}

/// Gaussian elimination with partial pivoting; None when singular.
fn solve4(mut a: [[f64; 4]; 4], mut b: [f64; 4]) -> Option<[f64; 4]> {
    let scale = a.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    for k in 0..4 {
        let piv = (k..4).max_by(|&i, &j| a[i][k].abs().total_cmp(&a[j][k].abs()))?;
        if a[piv][k].abs() <= 1e-12 * scale {
            return None;
        }
        a.swap(k, piv);
        b.swap(k, piv);
        let (top, rest) = a.split_at_mut(k + 1);
        let pivot = top[k];
        for (i, row) in rest.iter_mut().enumerate() {
            let f = row[k] / pivot[k];
            for (x, p) in row.iter_mut().zip(pivot).skip(k) {
                *x -= f * p;
            }
            b[k + 1 + i] -= f * b[k];
        }
    }
    let mut x = [0.0; 4];
    for k in (0..4).rev() {
        let s: f64 = (k + 1..4).map(|j| a[k][j] * x[j]).sum();
        x[k] = (b[k] - s) / a[k][k];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timoshenko_gives_the_papers_value() {
        let d = timoshenko(8.0, 1.0, 1000.0, 90e6, 0.0, 9.81);
        assert!((d - PAPER_TIMOSHENKO).abs() < 1e-5, "{d}");
    }

    #[test]
    fn the_fit_recovers_a_quadratic_field_at_the_tip() {
        // u_y = −(0.3 + 0.02 X + 0.001 X²) − 0.01 (Y − 0.5) on particles of
        // a beam [0, 8] × [0, 1], h = 0.25, 2 × 2 per cell.
        let mut p = Particles::default();
        let h = 0.25;
        for i in 0..32 {
            for j in 0..4 {
                for (a, b) in [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)] {
                    let x0 = [(i as f64 + a) * h, (j as f64 + b) * h];
                    let u = -(0.3 + 0.02 * x0[0] + 0.001 * x0[0] * x0[0]) - 0.01 * (x0[1] - 0.5);
                    p.x0.push(x0);
                    p.x.push([x0[0], x0[1] + u]);
                }
            }
        }
        let c = Cantilever {
            tip: [8.0, 0.5],
            length: 8.0,
            height: 1.0,
            timoshenko: 1.0,
            nonlinear: None,
            h,
        };
        let want = 0.3 + 0.02 * 8.0 + 0.001 * 64.0;
        assert!(
            (c.deflection(&p) - want).abs() < 1e-12,
            "{}",
            c.deflection(&p)
        );
    }
}
