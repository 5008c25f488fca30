//! Mandel's problem (`mandel`): a saturated specimen 2a wide in plane
//! strain, squeezed between rigid, frictionless, impermeable plates by a
//! force 2F (per unit thickness) from t = 0, drained at its free sides
//! x = ±a. The scene models the quarter x ∈ [0, a], y ∈ [0, b] on its
//! symmetry planes (x = 0 and y = 0 on rollers, impermeable), the plate a
//! `[platens]` region at the top loaded by −F (N/m): σ = F / a.
//!
//! With incompressible grains (Biot's coefficient 1) the Biot modulus is
//! M_b = K_w / n, the undrained bulk modulus K_u = K + M_b, Skempton's
//! B = M_b / K_u and the undrained Poisson's ratio
//! ν_u = (3 K_u − 2G) / (2 (3 K_u + G)). The load first goes into the
//! water as the uniform p_start = B (1 + ν_u) F / (3a); then (Abousleiman
//! et al. 1996, eq. 8; Verruijt, *Theory and Problems of
//! Poroelasticity*, §3.4)
//!   p(x, t) = 2 p_start Σ_n sin α_n / (α_n − sin α_n cos α_n)
//!             (cos(α_n x / a) − cos α_n) exp(−α_n² c t / a²),
//! α_n the positive roots of tan α = α (1 − ν) / (ν_u − ν), and
//! c = κ M_b (λ + 2G) / (λ + 2G + M_b) the consolidation coefficient
//! (κ = k / γ_w), the same as Abousleiman's
//! 2κ B² G (1 − ν)(1 + ν_u)² / (9 (1 − ν_u)(ν_u − ν)). The centre's
//! pressure first rises above p_start (the Mandel–Cryer effect: the
//! drained sides soften, the plate sheds load onto the stiffer core),
//! then decays.

use crate::model::Particles;
use crate::model::pore::Fluid;
use crate::scene::Scene;
use serde::Serialize;

/// Roots of the series kept: at t c / a² ≥ 1e-3 the first dropped term
/// is below 1e-12 of the first.
const TERMS: usize = 400;

/// The specimen's quarter and its soil.
#[derive(Debug, Clone, PartialEq)]
pub struct Mandel {
    /// Half-width a (m): the drained side at x = a, the centre at x = 0.
    pub a: f64,
    /// The plate's pressure F / a (Pa, compression positive).
    pub load: f64,
    /// Drained Lamé parameters λ, G (Pa).
    pub lambda: f64,
    pub g: f64,
    pub fluid: Fluid,
    /// α_n, ascending.
    roots: Vec<f64>,
}

/// Figures for `summary.json`.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct MandelErrors {
    /// t c / a² at the scored time.
    pub time_factor: f64,
    /// The centre's pressure over p_start: the particles' (their column
    /// nearest x = 0) and the closed form's at their mean x.
    pub centre: f64,
    pub centre_exact: f64,
    /// (centre − centre_exact), in units of p_start.
    pub centre_error: f64,
    /// RMS over the particles of (p − p_exact) / p_start.
    pub pressure_rms: f64,
}

impl Mandel {
    /// The specimen of a scene `scene::validate` accepted for
    /// `exact = "mandel"`: its one rect from x = 0, material and platen.
    pub fn from_scene(scene: &Scene) -> Mandel {
        let f = &scene.file;
        let rect = f.bodies.values().next().expect("validated: one body").rects[0];
        let (name, m) = f.materials.iter().next().expect("validated: one material");
        let fluid = Fluid::from_spec(name, m)
            .ok()
            .flatten()
            .expect("validated: saturated");
        let (lambda, g) = crate::model::material::Material::from_spec(name, m)
            .map_or((f64::NAN, f64::NAN), |m| m.lame_shear());
        let a = rect[2] - rect[0];
        let force = f
            .platens
            .values()
            .next()
            .expect("validated: one platen")
            .force;
        Mandel::new(a, -force / a, lambda, g, fluid)
    }

    pub fn new(a: f64, load: f64, lambda: f64, g: f64, fluid: Fluid) -> Mandel {
        let mut m = Mandel {
            a,
            load,
            lambda,
            g,
            fluid,
            roots: Vec::new(),
        };
        let c = (1.0 - m.nu()) / (m.nu_undrained() - m.nu());
        m.roots = (0..TERMS).map(|n| root(n, c)).collect();
        m
    }

    /// Drained Poisson's ratio ν = λ / (2 (λ + G)).
    pub fn nu(&self) -> f64 {
        self.lambda / (2.0 * (self.lambda + self.g))
    }

    /// The undrained bulk modulus K_u = K + K_w / n (Pa).
    fn k_undrained(&self) -> f64 {
        self.lambda + 2.0 * self.g / 3.0 + self.fluid.undrained_modulus()
    }

    pub fn nu_undrained(&self) -> f64 {
        let ku = self.k_undrained();
        (3.0 * ku - 2.0 * self.g) / (2.0 * (3.0 * ku + self.g))
    }

    /// Skempton's B = M_b / K_u.
    pub fn skempton(&self) -> f64 {
        self.fluid.undrained_modulus() / self.k_undrained()
    }

    /// The undrained p_start = B (1 + ν_u) F / (3a) (Pa).
    pub fn p_start(&self) -> f64 {
        self.skempton() * (1.0 + self.nu_undrained()) * self.load / 3.0
    }

    /// The consolidation coefficient c (m²/s).
    pub fn c(&self) -> f64 {
        let mc = self.lambda + 2.0 * self.g;
        let mb = self.fluid.undrained_modulus();
        self.fluid.mobility() * mb * mc / (mc + mb)
    }

    /// The consolidation time scale a² / c (s).
    pub fn time_scale(&self) -> f64 {
        self.a * self.a / self.c()
    }

    /// p(x, t) / p_start at the time factor `tf` = t c / a².
    pub fn pressure_ratio(&self, x: f64, tf: f64) -> f64 {
        let xi = (x / self.a).clamp(0.0, 1.0);
        if tf <= 0.0 {
            return if xi < 1.0 { 1.0 } else { 0.0 };
        }
        self.roots
            .iter()
            .map(|&al| {
                let (s, c) = al.sin_cos();
                2.0 * s / (al - s * c) * ((al * xi).cos() - c) * (-al * al * tf).exp()
            })
            .sum()
    }

    /// Scores the particles at time t: the centre's pressure (the mean
    /// over the particles whose start is nearest x = 0, against the
    /// closed form at their mean x) and the RMS over every particle.
    pub fn score(&self, p: &Particles, t: f64) -> MandelErrors {
        let tf = t / self.time_scale();
        let ps = self.p_start();
        let mut se = 0.0f64;
        for i in 0..p.len() {
            let e = p.pore_pressure[i] / ps - self.pressure_ratio(p.x[i][0], tf);
            se += e * e;
        }
        let eps = 1e-9 * self.a;
        let col = (0..p.len()).map(|i| p.x0[i][0]).fold(f64::MAX, f64::min);
        let (mut sp, mut sx, mut k) = (0.0f64, 0.0f64, 0.0f64);
        for i in (0..p.len()).filter(|&i| (p.x0[i][0] - col).abs() <= eps) {
            sp += p.pore_pressure[i];
            sx += p.x[i][0];
            k += 1.0;
        }
        let k = k.max(1.0);
        let centre = sp / k / ps;
        let centre_exact = self.pressure_ratio(sx / k, tf);
        MandelErrors {
            time_factor: tf,
            centre,
            centre_exact,
            centre_error: centre - centre_exact,
            pressure_rms: (se / (p.len() as f64).max(1.0)).sqrt(),
        }
    }
}

/// The (n + 1)-th positive root of sin α − C α cos α = 0 (tan α = C α,
/// C > 1): in (0, π/2) for n = 0, in (nπ, nπ + π/2) after; by bisection.
fn root(n: usize, c: f64) -> f64 {
    let g = |a: f64| a.sin() - c * a * a.cos();
    let base = n as f64 * std::f64::consts::PI;
    let (mut lo, mut hi) = (base + 1e-9, base + std::f64::consts::FRAC_PI_2);
    let lo_neg = g(lo) < 0.0;
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if (g(mid) < 0.0) == lo_neg {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn specimen(nu: f64) -> Mandel {
        let e = 1e6;
        let g = e / (2.0 * (1.0 + nu));
        let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let fluid = Fluid {
            k: 1.0791e-3,
            n: 0.4,
            kw: 4e6,
            rho_w: 1000.0,
        };
        Mandel::new(1.0, 1e4, lambda, g, fluid)
    }

    #[test]
    fn the_closed_form_starts_uniform_rises_at_the_centre_and_drains() {
        for nu in [0.0, 0.2, 0.35] {
            let m = specimen(nu);
            // The two forms of c agree.
            let (b, nuu) = (m.skempton(), m.nu_undrained());
            let kappa = m.fluid.mobility();
            let c2 = 2.0 * kappa * b * b * m.g * (1.0 - nu) * (1.0 + nuu).powi(2)
                / (9.0 * (1.0 - nuu) * (nuu - nu));
            assert!((m.c() / c2 - 1.0).abs() < 1e-12, "nu {nu}");
            // Each root solves tan α = C α, ascending.
            let cc = (1.0 - nu) / (nuu - nu);
            for w in m.roots.windows(2) {
                assert!(w[1] > w[0]);
                assert!((w[0].tan() - cc * w[0]).abs() < 1e-6 * cc * w[0]);
            }
            // Early on the series is p_start everywhere inside (it has
            // not yet reached the centre); the drained side is at 0.
            assert!((m.pressure_ratio(0.0, 1e-3) - 1.0).abs() < 0.03, "nu {nu}");
            assert!((m.pressure_ratio(0.3, 1e-3) - 1.0).abs() < 0.03, "nu {nu}");
            assert!(m.pressure_ratio(1.0, 1e-3).abs() < 1e-9);
            // Mandel–Cryer: the centre rises above p_start (less as ν
            // grows: 1.13, 1.09, 1.05 at t c / a² = 0.05), then decays.
            assert!(m.pressure_ratio(0.0, 0.05) > 1.04, "nu {nu}");
            assert!(
                m.pressure_ratio(0.0, 0.05) > m.pressure_ratio(0.0, 1e-3),
                "nu {nu}"
            );
            assert!(m.pressure_ratio(0.0, 1.0) < 0.5, "nu {nu}");
        }
        // ν = 0 with K_w / n = 10 E: ν_u = 10/21, B = 30/31; the centre
        // peaks at 1.14 p_start near t c / a² = 0.1 (this series,
        // 2000 roots: 1.1407).
        let m = specimen(0.0);
        assert!((m.nu_undrained() - 10.0 / 21.0).abs() < 1e-12);
        assert!((m.skempton() - 30.0 / 31.0).abs() < 1e-12);
        assert!((m.pressure_ratio(0.0, 0.1) - 1.1407).abs() < 1e-3);
    }
}
