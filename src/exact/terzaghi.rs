//! Terzaghi's one-dimensional consolidation (`terzaghi`): a saturated
//! layer of height H on an impermeable, fixed base, drained at its top,
//! loaded there by p0 from t = 0 and held laterally (ν = 0 or rollers, so
//! the constrained modulus M acts). With the fluid's compressibility
//! kept and incompressible grains the load first goes into the water as
//! the undrained p_start = p0 / (1 + M n / K_w); then
//!   p(z, t) / p_start = Σ_m (2 / M_m) sin(M_m z / H) exp(−M_m² T_v),
//! M_m = π (2m + 1) / 2, z the depth below the drained top,
//! T_v = c_v t / H², c_v = κ / (1 / M + n / K_w), κ = k / γ_w; the degree
//! of consolidation U = 1 − Σ_m (2 / M_m²) exp(−M_m² T_v), and the
//! settlement s = (H / M) (p0 − p_start (1 − U)), from the undrained
//! p0 H / (M + K_w / n) to the final p0 H / M.

use crate::model::Particles;
use crate::model::pore::Fluid;
use crate::scene::Scene;
use serde::Serialize;

/// Terms of the series: at T_v ≥ 1e-4 the first dropped term is below
/// 1e-12 of the first.
const TERMS: usize = 400;

/// The layer and its soil.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Terzaghi {
    /// y of the impermeable base and of the drained top (m).
    pub base: f64,
    pub top: f64,
    /// The load on the top (Pa, compression positive).
    pub p0: f64,
    /// Constrained modulus M = λ + 2μ (Pa).
    pub m: f64,
    pub fluid: Fluid,
}

/// Figures for `summary.json`.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct TerzaghiErrors {
    /// T_v at the scored time.
    pub time_factor: f64,
    /// RMS over the particles of (p − p_exact) / p_start.
    pub pressure_rms: f64,
    /// U from the particles' mean pressure, and the series' U.
    pub consolidation: f64,
    pub consolidation_exact: f64,
    /// Settlement of the top (m), the exact one, and their relative error.
    pub settlement: f64,
    pub settlement_exact: f64,
    pub settlement_rel_error: f64,
}

impl Terzaghi {
    /// The layer of a scene `scene::validate` accepted for
    /// `exact = "terzaghi"`: its one rect, material and traction.
    pub fn from_scene(scene: &Scene) -> Terzaghi {
        let f = &scene.file;
        let rect = f.bodies.values().next().expect("validated: one body").rects[0];
        let (name, m) = f.materials.iter().next().expect("validated: one material");
        let fluid = Fluid::from_spec(name, m)
            .ok()
            .flatten()
            .expect("validated: saturated");
        let (lambda, mu) = crate::model::material::Material::from_spec(name, m)
            .map_or((f64::NAN, f64::NAN), |m| m.lame_shear());
        // The load: one traction [0, −p0] on the top, or one platen there
        // loaded by −F (N/m) over the layer's width.
        let p0 = match f.tractions.values().next() {
            Some(t) => -t.traction[1],
            None => {
                let platen = f.platens.values().next().expect("validated: one platen");
                -platen.force / (rect[2] - rect[0])
            }
        };
        Terzaghi {
            base: rect[1],
            top: rect[3],
            p0,
            m: lambda + 2.0 * mu,
            fluid,
        }
    }

    pub fn height(&self) -> f64 {
        self.top - self.base
    }

    /// The undrained pressure p_start (Pa).
    pub fn p_start(&self) -> f64 {
        self.p0 / (1.0 + self.m * self.fluid.storage())
    }

    /// c_v (m²/s).
    pub fn cv(&self) -> f64 {
        self.fluid.mobility() / (1.0 / self.m + self.fluid.storage())
    }

    /// T_v at time t (s).
    pub fn time_factor(&self, t: f64) -> f64 {
        self.cv() * t / (self.height() * self.height())
    }

    /// p(y, T_v) / p_start.
    pub fn pressure_ratio(&self, y: f64, tv: f64) -> f64 {
        let z = ((self.top - y) / self.height()).clamp(0.0, 1.0);
        if tv <= 0.0 {
            return if z > 0.0 { 1.0 } else { 0.0 };
        }
        (0..TERMS)
            .map(|m| {
                let mm = std::f64::consts::PI * (2 * m + 1) as f64 / 2.0;
                2.0 / mm * (mm * z).sin() * (-mm * mm * tv).exp()
            })
            .sum()
    }

    /// U(T_v).
    pub fn consolidation(tv: f64) -> f64 {
        if tv <= 0.0 {
            return 0.0;
        }
        1.0 - (0..TERMS)
            .map(|m| {
                let mm = std::f64::consts::PI * (2 * m + 1) as f64 / 2.0;
                2.0 / (mm * mm) * (-mm * mm * tv).exp()
            })
            .sum::<f64>()
    }

    /// The top's settlement (m) at T_v.
    pub fn settlement(&self, tv: f64) -> f64 {
        self.height() / self.m * (self.p0 - self.p_start() * (1.0 - Self::consolidation(tv)))
    }

    /// Scores the particles at time t: their pore pressure against the
    /// series, U from their volume-weighted mean pressure, the settlement
    /// of the top: the mean displacement of the two highest rows of
    /// particles (by their start), extrapolated linearly to the surface.
    pub fn score(&self, p: &Particles, t: f64) -> TerzaghiErrors {
        let tv = self.time_factor(t);
        let ps = self.p_start();
        let (mut se, mut pv, mut v) = (0.0f64, 0.0f64, 0.0f64);
        for i in 0..p.len() {
            let e = p.pore_pressure[i] / ps - self.pressure_ratio(p.x[i][1], tv);
            se += e * e;
            let vol = p.volume(i);
            pv += vol * p.pore_pressure[i];
            v += vol;
        }
        // The rows: the highest start, then the highest below it.
        let eps = 1e-9 * self.height();
        let row0 = (0..p.len()).map(|i| p.x0[i][1]).fold(f64::MIN, f64::max);
        let row1 = (0..p.len())
            .map(|i| p.x0[i][1])
            .filter(|&y| y < row0 - eps)
            .fold(f64::MIN, f64::max);
        let mean_u = |row: f64| {
            let (mut s, mut k) = (0.0f64, 0.0f64);
            for i in (0..p.len()).filter(|&i| (p.x0[i][1] - row).abs() <= eps) {
                s += p.x0[i][1] - p.x[i][1];
                k += 1.0;
            }
            s / k.max(1.0)
        };
        let (u0, u1) = (mean_u(row0), mean_u(row1));
        let settlement = if row1 > f64::MIN {
            u0 + (u0 - u1) * (self.top - row0) / (row0 - row1)
        } else {
            u0
        };
        let s_exact = self.settlement(tv);
        TerzaghiErrors {
            time_factor: tv,
            pressure_rms: (se / (p.len() as f64).max(1.0)).sqrt(),
            consolidation: 1.0 - pv / v.max(f64::MIN_POSITIVE) / ps,
            consolidation_exact: Self::consolidation(tv),
            settlement,
            settlement_exact: s_exact,
            settlement_rel_error: settlement / s_exact - 1.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_series_gives_terzaghis_classic_degrees_of_consolidation() {
        // U = 50 % at T_v = 0.197 and 90 % at 0.848 (incompressible water).
        assert!((Terzaghi::consolidation(0.197) - 0.5).abs() < 2e-3);
        assert!((Terzaghi::consolidation(0.848) - 0.9).abs() < 1e-3);
        let layer = Terzaghi {
            base: 0.0,
            top: 1.0,
            p0: 1e4,
            m: 1e6,
            fluid: Fluid {
                k: 1e-3,
                n: 0.4,
                kw: 4e6,
                rho_w: 1000.0,
            },
        };
        // Undrained: p0 / (1 + M n / K_w) = p0 / 1.1; the drained top at 0.
        assert!((layer.p_start() - 1e4 / 1.1).abs() < 1e-9);
        assert!(layer.pressure_ratio(1.0, 0.1).abs() < 1e-12);
        // The mean of p / p_start over the layer is 1 − U.
        let tv = 0.1;
        let mean: f64 = (0..2000)
            .map(|i| layer.pressure_ratio((i as f64 + 0.5) / 2000.0, tv))
            .sum::<f64>()
            / 2000.0;
        assert!((mean - (1.0 - Terzaghi::consolidation(tv))).abs() < 1e-6);
    }
}
