//! Particle state as a structure of arrays, one `Vec` per field, holding only
//! the fields the scene uses: `a` only for NPC, `lambda` only for LME,
//! `f` only for finite-strain materials, `plastic` only for plastic ones.

use crate::model::material::PlasticState;
use crate::scene::seed::Seed;

/// A particle's force on one node (N per unit thickness), paper eq. 14:
/// −V_p σ_p ∇N_I + N_I m_p b, with `wk` = [N_I, ∂N_I/∂x, ∂N_I/∂y], `vol`
/// V_p (m² per unit thickness), `s` [σ_xx, σ_yy, σ_xy] (Pa) and `mb`
/// m_p b (N). The one formula of `cpu::forces` and `model::preload_fit`.
#[inline(always)]
pub fn node_force(vol: f64, s: [f64; 3], wk: &[f64; 3], mb: [f64; 2]) -> [f64; 2] {
    [
        -vol * (s[0] * wk[1] + s[2] * wk[2]) + wk[0] * mb[0],
        -vol * (s[2] * wk[1] + s[1] * wk[2]) + wk[0] * mb[1],
    ]
}

#[derive(Debug, Clone, Default)]
pub struct Particles {
    /// Position (m).
    pub x: Vec<[f64; 2]>,
    /// Velocity (m/s).
    pub v: Vec<[f64; 2]>,
    /// Acceleration (m/s²); NPC only, else empty.
    pub a: Vec<[f64; 2]>,
    /// Mass (kg per unit thickness).
    pub mass: Vec<f64>,
    /// Current density (kg/m³); volume = mass / rho.
    pub rho: Vec<f64>,
    /// Cauchy stress [σxx, σyy, σxy] (Pa).
    pub stress: Vec<[f64; 3]>,
    /// LME Lagrange multiplier λ (1/m); LME only, else empty.
    pub lambda: Vec<[f64; 2]>,
    /// Deformation gradient [xx, xy, yx, yy]; only when a material needs it, else empty.
    pub f: Vec<[f64; 4]>,
    /// Plastic state [σzz (Pa), ε̄p, εp_v, last return's active surfaces]
    /// (`material::plastic`); only when a material is plastic, else empty.
    pub plastic: Vec<PlasticState>,
    /// Pore pressure p (Pa, compression positive); saturated scenes only
    /// (`model::pore`), else empty.
    pub pore_pressure: Vec<f64>,
    /// Body index (scene order).
    pub body: Vec<u32>,
    /// Initial position (m).
    pub x0: Vec<[f64; 2]>,
}

impl Particles {
    /// Builds particles from seeds; `density(body)` and `velocity(body)` give
    /// the initial values per body.
    pub fn from_seeds(
        seeds: &[Seed],
        density: impl Fn(u32) -> f64,
        velocity: impl Fn(u32) -> [f64; 2],
        with_acceleration: bool,
        with_lambda: bool,
        with_f: bool,
        with_plastic: bool,
    ) -> Self {
        let n = seeds.len();
        let rho: Vec<f64> = seeds.iter().map(|s| density(s.body)).collect();
        Particles {
            x: seeds.iter().map(|s| s.x).collect(),
            v: seeds.iter().map(|s| velocity(s.body)).collect(),
            a: if with_acceleration {
                vec![[0.0; 2]; n]
            } else {
                Vec::new()
            },
            mass: seeds.iter().zip(&rho).map(|(s, r)| s.volume * r).collect(),
            rho,
            stress: vec![[0.0; 3]; n],
            lambda: if with_lambda {
                vec![[0.0; 2]; n]
            } else {
                Vec::new()
            },
            f: if with_f {
                vec![[1.0, 0.0, 0.0, 1.0]; n]
            } else {
                Vec::new()
            },
            plastic: if with_plastic {
                vec![[0.0; 4]; n]
            } else {
                Vec::new()
            },
            pore_pressure: Vec::new(),
            body: seeds.iter().map(|s| s.body).collect(),
            x0: seeds.iter().map(|s| s.x).collect(),
        }
    }

    pub fn len(&self) -> usize {
        self.x.len()
    }

    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Index of the particle nearest to `point` (first one on ties).
    pub fn nearest(&self, point: [f64; 2]) -> usize {
        let d2 = |x: &[f64; 2]| (x[0] - point[0]).powi(2) + (x[1] - point[1]).powi(2);
        (0..self.len())
            .min_by(|&a, &b| d2(&self.x[a]).total_cmp(&d2(&self.x[b])))
            .unwrap_or(0)
    }

    /// The lightest particle's mass (kg per unit thickness; ∞ when empty):
    /// what both backends scale `MASS_EPS_REL` by.
    pub fn min_mass(&self) -> f64 {
        self.mass.iter().copied().fold(f64::INFINITY, f64::min)
    }

    /// Volume of particle `p` (m² per unit thickness).
    #[inline]
    pub fn volume(&self, p: usize) -> f64 {
        self.mass[p] / self.rho[p]
    }
}
