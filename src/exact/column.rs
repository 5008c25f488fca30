//! Elastic column on a fixed base under gravity (Andersen's block; paper
//! §3.2). At equilibrium the Cauchy stress at a particle of reference height
//! Y above the base is σ_yy = −ρ0 g (H − Y), the weight above it. With ν = 0
//! the column is 1D. Settlement depends on the strain measure:
//! - small strain: u(Y) = −k (H Y − Y²/2), top: k H²/2 (0.5886 m for the block);
//! - our incremental (hypoelastic) law integrates to logarithmic strain,
//!   ln(stretch) = σ/E, so u(Y) = −(Y − (e^{−k(H−Y)} − e^{−kH})/k),
//!   top: H − (1 − e^{−kH})/k (0.5662 m), with k = ρ0 g / E.

use crate::model::{Model, Particles};
use crate::scene::Scene;
use serde::Serialize;

#[derive(Debug, Clone)]
pub struct ElasticColumn {
    /// Base height (m).
    pub base: f64,
    /// Height H (m).
    pub height: f64,
    /// ρ0 (kg/m³).
    pub density: f64,
    /// E (Pa).
    pub youngs: f64,
    /// Gravity magnitude at the time of scoring is taken from the model (m/s²).
    gravity: crate::model::Gravity,
    /// Thickness of the top and bottom particle rows (m).
    row: f64,
}

/// Figures for `summary.json`.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ColumnErrors {
    /// Mean settlement of the top particle row (m, positive down).
    pub settlement_top: f64,
    /// Exact settlement of that row for our (logarithmic-strain) law (m).
    pub settlement_top_exact: f64,
    /// Same row, small-strain theory (m).
    pub settlement_top_small_strain: f64,
    /// |settlement_top − exact| / exact.
    pub settlement_rel_error: f64,
    /// Mean σ_yy of the bottom particle row (Pa).
    pub sigma_yy_bottom: f64,
    /// −ρ0 g (H − Y) at that row (Pa).
    pub sigma_yy_bottom_exact: f64,
    /// |σ_yy bottom − exact| / |exact|.
    pub sigma_yy_bottom_rel_error: f64,
    /// RMS over all particles of σ_yy − exact, divided by ρ0 g H.
    pub sigma_yy_rms_relative: f64,
}

impl ElasticColumn {
    pub fn from_scene(scene: &Scene, model: &Model) -> ElasticColumn {
        let m = scene.materials().next().expect("validated: one material").1;
        let bb = crate::scene::seed::bodies_bbox(scene);
        let ppc = scene.bodies().next().map_or(2, |(_, b)| b.ppc);
        ElasticColumn {
            base: bb[1],
            height: bb[3] - bb[1],
            density: m.density,
            youngs: m.get("E").expect("validated: E"),
            gravity: model.gravity.expect("validated: gravity present"),
            row: scene.file.grid.h / ppc as f64,
        }
    }

    fn g(&self, t: f64) -> f64 {
        -self.gravity.at(t)[1]
    }

    /// Exact σ_yy at reference height `y` (m) at time `t` (quasi-static).
    pub fn sigma_yy(&self, y: f64, t: f64) -> f64 {
        -self.density * self.g(t) * (self.height - (y - self.base))
    }

    /// Exact settlement (positive down) at reference height `y`, logarithmic strain.
    pub fn settlement(&self, y: f64, t: f64) -> f64 {
        let k = self.density * self.g(t) / self.youngs;
        let (yy, hh) = (y - self.base, self.height);
        if k == 0.0 {
            return 0.0;
        }
        yy - ((-k * (hh - yy)).exp() - (-k * hh).exp()) / k
    }

    /// Small-strain settlement at reference height `y`.
    pub fn settlement_small_strain(&self, y: f64, t: f64) -> f64 {
        let k = self.density * self.g(t) / self.youngs;
        let yy = y - self.base;
        k * (self.height * yy - 0.5 * yy * yy)
    }

    pub fn score(&self, p: &Particles, t: f64) -> ColumnErrors {
        let n = p.len();
        let ymax = p.x0.iter().map(|x| x[1]).fold(f64::NEG_INFINITY, f64::max);
        let ymin = p.x0.iter().map(|x| x[1]).fold(f64::INFINITY, f64::min);
        let tol = 0.25 * self.row;
        let mean = |sel: &dyn Fn(usize) -> bool, f: &dyn Fn(usize) -> f64| {
            let (s, c) = (0..n)
                .filter(|&i| sel(i))
                .fold((0.0, 0usize), |(s, c), i| (s + f(i), c + 1));
            s / c.max(1) as f64
        };
        let top = |i: usize| p.x0[i][1] > ymax - tol;
        let bottom = |i: usize| p.x0[i][1] < ymin + tol;
        let settlement_top = mean(&top, &|i| p.x0[i][1] - p.x[i][1]);
        let settlement_top_exact = mean(&top, &|i| self.settlement(p.x0[i][1], t));
        let settlement_top_small_strain =
            mean(&top, &|i| self.settlement_small_strain(p.x0[i][1], t));
        let sigma_yy_bottom = mean(&bottom, &|i| p.stress[i][1]);
        let sigma_yy_bottom_exact = mean(&bottom, &|i| self.sigma_yy(p.x0[i][1], t));
        let scale = self.density * self.g(t) * self.height;
        let rms = ((0..n)
            .map(|i| (p.stress[i][1] - self.sigma_yy(p.x0[i][1], t)).powi(2))
            .sum::<f64>()
            / n.max(1) as f64)
            .sqrt();
        ColumnErrors {
            settlement_top,
            settlement_top_exact,
            settlement_top_small_strain,
            settlement_rel_error: (settlement_top - settlement_top_exact).abs()
                / settlement_top_exact.abs().max(f64::MIN_POSITIVE),
            sigma_yy_bottom,
            sigma_yy_bottom_exact,
            sigma_yy_bottom_rel_error: (sigma_yy_bottom - sigma_yy_bottom_exact).abs()
                / sigma_yy_bottom_exact.abs().max(f64::MIN_POSITIVE),
            sigma_yy_rms_relative: if scale > 0.0 { rms / scale } else { rms },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Gravity;
    use crate::scene::Ramp;

    fn block() -> ElasticColumn {
        ElasticColumn {
            base: 0.0,
            height: 10.0,
            density: 6000.0,
            youngs: 5e6,
            gravity: Gravity {
                g: [0.0, -9.81],
                ramp: Ramp::Sine,
                period: 20.0,
            },
            row: 1.0,
        }
    }

    #[test]
    fn block_settlements_match_the_spec_figures() {
        let b = block();
        assert!((b.settlement_small_strain(10.0, 20.0) - 0.5886).abs() < 5e-5);
        assert!((b.settlement(10.0, 20.0) - 0.56617).abs() < 1e-5);
        assert_eq!(b.settlement(0.0, 20.0), 0.0);
        assert!((b.sigma_yy(0.0, 20.0) + 6000.0 * 9.81 * 10.0).abs() < 1e-6);
    }

    #[test]
    fn settlement_satisfies_the_log_strain_law() {
        // d(x)/dY = exp(σ/E): finite differences of the deformed height.
        let b = block();
        let x = |y: f64| y - b.settlement(y, 20.0);
        for y in [0.5, 3.0, 7.5, 9.9] {
            let d = 1e-5;
            let stretch = (x(y + d) - x(y - d)) / (2.0 * d);
            assert!((stretch - (b.sigma_yy(y, 20.0) / b.youngs).exp()).abs() < 1e-8);
        }
    }
}
