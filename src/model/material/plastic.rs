//! What the elastoplastic models (Mohr–Coulomb, Drucker–Prager) share: the
//! per-particle plastic state, the elastic trial stress on the Jaumann rate,
//! the plastic strain measures and the elastic energy with σzz.
//! WGSL twin: the helpers at the top of `shaders/shared/material.wgsl`
//! (`jaumann_trial`, `plastic_increment`, `elastic_energy_3d`).

pub use super::state::PlasticState;

/// Index of each entry of `PlasticState`.
pub const SZZ: usize = 0;
pub const EPS_EQ: usize = 1;
pub const EPS_VOL: usize = 2;
pub const RETURN: usize = 3;

/// Bits of `PlasticState[RETURN]`. Mohr–Coulomb, in the sorted principal
/// stresses σ1 ≥ σ2 ≥ σ3: the main plane (σ1 with σ3), the plane of σ2 with
/// σ3 (active with the main one on the edge σ1 = σ2), the plane of σ1 with
/// σ2 (the edge σ2 = σ3), and the tension planes σi = t. Drucker–Prager
/// uses `ACTIVE_MAIN` for the cone and `ACTIVE_T1` for the tension cap.
/// The apex (with the default cutoff t = c / tan φ) is T1 | T2 | T3.
pub const ACTIVE_MAIN: u32 = 1;
pub const ACTIVE_EDGE_12: u32 = 2;
pub const ACTIVE_EDGE_23: u32 = 4;
pub const ACTIVE_T1: u32 = 8;
pub const ACTIVE_T2: u32 = 16;
pub const ACTIVE_T3: u32 = 32;
pub const ACTIVE_APEX: u32 = ACTIVE_T1 | ACTIVE_T2 | ACTIVE_T3;

/// Isotropic linear elasticity in 3D (the elastic part of the plastic models).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Elastic3 {
    /// Lamé λ (Pa).
    pub lame: f64,
    /// Shear modulus G (Pa).
    pub shear: f64,
    /// Bulk modulus K = λ + 2G/3 (Pa).
    pub bulk: f64,
}

impl Elastic3 {
    pub fn new(youngs: f64, nu: f64) -> Self {
        let lame = youngs * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let shear = youngs / (2.0 * (1.0 + nu));
        Elastic3 {
            lame,
            shear,
            bulk: lame + 2.0 * shear / 3.0,
        }
    }

    /// Elastic trial stress on the Jaumann rate, plane strain:
    /// σ_trial = σ + Δt (Wσ − σW) + D : Δε with W = skew(L), Δε = Δt sym(L),
    /// Δεzz = 0. Returns ([σxx, σyy, σxy], σzz). `l` = [xx, xy, yx, yy].
    #[inline]
    pub fn jaumann_trial(&self, l: [f64; 4], dt: f64, s: &[f64; 3], szz: f64) -> ([f64; 3], f64) {
        // W = [[0, w], [−w, 0]]: (Wσ − σW) = w [2σxy, −2σxy, σyy − σxx].
        let w = 0.5 * dt * (l[1] - l[2]);
        let de = [dt * l[0], dt * l[3], 0.5 * dt * (l[1] + l[2])];
        let vol = self.lame * (de[0] + de[1]);
        (
            [
                s[0] + 2.0 * w * s[2] + vol + 2.0 * self.shear * de[0],
                s[1] - 2.0 * w * s[2] + vol + 2.0 * self.shear * de[1],
                s[2] + w * (s[1] - s[0]) + 2.0 * self.shear * de[2],
            ],
            szz + vol,
        )
    }

    /// The plastic strain of a return from `trial` to `s` (both
    /// [xx, yy, zz, xy]): Δεp = C : (σ_trial − σ) (the elastic strain the
    /// return removed). Returns (Δε̄p = sqrt(2/3 Δεp : Δεp), Δεp_v = tr Δεp).
    #[inline]
    pub fn plastic_increment(&self, trial: [f64; 4], s: [f64; 4]) -> (f64, f64) {
        let d = [
            trial[0] - s[0],
            trial[1] - s[1],
            trial[2] - s[2],
            trial[3] - s[3],
        ];
        let dp = (d[0] + d[1] + d[2]) / 3.0;
        let g2 = 2.0 * self.shear;
        let dev = [
            (d[0] - dp) / g2,
            (d[1] - dp) / g2,
            (d[2] - dp) / g2,
            d[3] / g2,
        ];
        let dv = dp / self.bulk;
        let e = [dev[0] + dv / 3.0, dev[1] + dv / 3.0, dev[2] + dv / 3.0];
        let norm2 = e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + 2.0 * dev[3] * dev[3];
        ((2.0 / 3.0 * norm2).sqrt(), dv)
    }

    /// Elastic energy per unit volume of the stress `s` = [xx, yy, zz, xy]:
    /// ½ σ : C : σ = s : s / (4G) + p² / (2K) (J/m³).
    #[inline]
    pub fn energy(&self, s: [f64; 4]) -> f64 {
        let p = (s[0] + s[1] + s[2]) / 3.0;
        let d = [s[0] - p, s[1] - p, s[2] - p];
        let ss = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + 2.0 * s[3] * s[3];
        ss / (4.0 * self.shear) + p * p / (2.0 * self.bulk)
    }
}

/// Volume ratio of a small-strain step, 1 + tr Δε, or the fault it signals.
#[inline]
pub fn volume_ratio(l: [f64; 4], dt: f64) -> Result<f64, crate::model::fault::FaultKind> {
    use crate::model::fault::FaultKind;
    let j = 1.0 + dt * (l[0] + l[3]);
    if j.is_nan() {
        return Err(FaultKind::NonFinite { field: "strain" });
    }
    if j <= 0.0 {
        return Err(FaultKind::NonPositiveDensity);
    }
    Ok(j)
}

/// Adds a return's plastic strain to `q` and records its active surfaces.
#[inline]
pub fn record(q: &mut PlasticState, e: &Elastic3, trial: [f64; 4], s: [f64; 4], active: u32) {
    let (deq, dvol) = if active == 0 {
        (0.0, 0.0)
    } else {
        e.plastic_increment(trial, s)
    };
    q[SZZ] = s[2];
    q[EPS_EQ] += deq;
    q[EPS_VOL] += dvol;
    q[RETURN] = active as f64;
}

/// `Constitutive` for an elastic-perfectly plastic model (Mohr–Coulomb,
/// Drucker–Prager): E, ν and the yield keys, the `Elastic3` moduli, the
/// elastic P-wave speed (which bounds the elastoplastic one), the elastic
/// energy with σzz from the state, and the model's own `update` and GPU
/// parameters. The type has `youngs`, `nu`, `density`, `elastic` and
/// `new(E, ν, ρ, c, φ, ψ, t)`.
macro_rules! elastoplastic_constitutive {
    ($ty:ident, $name:literal, [$($param:literal),*], |$m:ident| $pack:expr) => {
        impl super::Constitutive for $ty {
            const NAME: &'static str = $name;
            const KEYS: &'static [super::Key] = plastic::YIELD_KEYS;
            const STATE: super::StateKind = super::StateKind::Plastic;
            const GPU_PARAMS: &'static [&'static str] = &[$($param),*];
            const STATE_COLUMNS: &'static [super::StateColumn] = plastic::STRAIN_COLUMNS;

            fn from_keys(k: &super::Keys) -> Result<Self, crate::error::SceneError> {
                let (e, nu) = k.youngs_nu()?;
                let (c, phi, psi, t) = plastic::yield_keys(k)?;
                Ok($ty::new(e, nu, k.density(), c, phi, psi, t))
            }
            fn density(&self) -> f64 {
                self.density
            }
            fn lame_shear(&self) -> (f64, f64) {
                (self.elastic.lame, self.elastic.shear)
            }
            fn youngs_nu(&self) -> (f64, f64) {
                (self.youngs, self.nu)
            }
            #[inline]
            fn update(
                &self,
                l: [f64; 4],
                dt: f64,
                stress: &mut [f64; 3],
                _f: &mut super::DefGrad,
                q: &mut PlasticState,
            ) -> Result<f64, FaultKind> {
                $ty::update(self, l, dt, stress, q)
            }
            #[inline]
            fn wave_speed(&self, rho: f64, _s: &[f64; 3], _q: &PlasticState) -> f64 {
                ((self.elastic.lame + 2.0 * self.elastic.shear) / rho).sqrt()
            }
            #[inline]
            fn wave_speed_squared(&self, rho: f64, _s: &[f64; 3], _q: &PlasticState) -> f64 {
                (self.elastic.lame + 2.0 * self.elastic.shear) / rho
            }
            #[inline]
            fn strain_energy_density(
                &self,
                s: &[f64; 3],
                _f: &super::DefGrad,
                q: &PlasticState,
            ) -> f64 {
                self.elastic.energy([s[0], s[1], q[plastic::SZZ], s[2]])
            }
            fn gpu_params(&self) -> Vec<f32> {
                let $m = self;
                $pack
            }
            /// Carried in the plastic state.
            fn stress_zz(
                &self,
                _stress: &[f64; 3],
                _f: Option<&super::DefGrad>,
                _rho: f64,
                q: Option<&PlasticState>,
            ) -> f64 {
                q.map_or(0.0, |q| q[plastic::SZZ])
            }
        }
    };
}
pub(crate) use elastoplastic_constitutive;

/// What the elastic-perfectly plastic models (Mohr–Coulomb,
/// Drucker–Prager) keep in `PlasticState[EPS_EQ]` and `[EPS_VOL]`.
pub const STRAIN_COLUMNS: &[super::StateColumn] = &[
    super::StateColumn {
        column: "eps_p",
        array: "plastic_strain_eq",
        unit: "1",
        meaning: "equivalent plastic strain",
        symbol: "ε̄p",
        from_zero: true,
    },
    super::StateColumn {
        column: "eps_pv",
        array: "plastic_strain_vol",
        unit: "1",
        meaning: "volumetric plastic strain",
        symbol: "εp_v",
        from_zero: true,
    },
];

/// The keys of the elastic-perfectly plastic models (Mohr–Coulomb,
/// Drucker–Prager): E and ν, then the yield keys.
pub const YIELD_KEYS: &[super::Key] = &[
    super::Key {
        name: "E",
        unit: "Pa",
        doc: "Young's modulus, > 0",
    },
    super::Key {
        name: "nu",
        unit: "1",
        doc: "Poisson's ratio, in (-1, 0.5)",
    },
    super::Key {
        name: "cohesion",
        unit: "Pa",
        doc: "cohesion c, ≥ 0; required",
    },
    super::Key {
        name: "friction_angle",
        unit: "degrees",
        doc: "friction angle φ, in [0, 90); required",
    },
    super::Key {
        name: "dilation_angle",
        unit: "degrees",
        doc: "dilation angle ψ, in [0, φ]; default 0",
    },
    super::Key {
        name: "tension_cutoff",
        unit: "Pa",
        doc: "tension cutoff t, in [0, c / tan φ]; default the apex",
    },
];

/// The yield keys read and checked: (c (Pa), φ (degrees), ψ (degrees),
/// tension cutoff (Pa) if given).
pub fn yield_keys(
    k: &super::Keys,
) -> Result<(f64, f64, f64, Option<f64>), crate::error::SceneError> {
    let c = k.required("cohesion")?;
    let c = k.within("cohesion", c, 0.0, f64::INFINITY, false, "≥ 0 Pa")?;
    let phi = k.required("friction_angle")?;
    let phi = k.within(
        "friction_angle",
        phi,
        0.0,
        90.0,
        false,
        "in [0, 90) degrees",
    )?;
    let psi = match k.optional("dilation_angle")? {
        Some(psi) => k.within(
            "dilation_angle",
            psi,
            0.0,
            phi,
            true,
            &format!("in [0, friction_angle = {phi}] degrees"),
        )?,
        None => 0.0,
    };
    let t = match k.optional("tension_cutoff")? {
        Some(t) => {
            let t = k.within("tension_cutoff", t, 0.0, f64::INFINITY, false, "≥ 0 Pa")?;
            if phi > 0.0 {
                let apex = c / phi.to_radians().tan();
                // A value written from a hand-computed apex may round a few
                // ulps above it; the material clamps t to the apex.
                if t > apex * (1.0 + 1e-9) {
                    return Err(k.invalid(
                        "tension_cutoff",
                        format!(
                            "must not exceed the apex c / tan(friction_angle) = {apex} Pa, got {t}"
                        ),
                    ));
                }
            }
            Some(t)
        }
        None => None,
    };
    Ok((c, phi, psi, t))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::material::linear_elastic::LinearElastic;

    #[test]
    fn energy_matches_plane_strain_linear_elastic() {
        let e = Elastic3::new(2.0e7, 0.3);
        let le = LinearElastic::new(2.0e7, 0.3, 1000.0);
        let s = [-1.2e5, 3.0e4, 2.5e4];
        let szz = 0.3 * (s[0] + s[1]);
        let w3 = e.energy([s[0], s[1], szz, s[2]]);
        let w2 = le.strain_energy_density(&s);
        assert!((w3 - w2).abs() < 1e-12 * w2.abs(), "{w3} vs {w2}");
    }

    #[test]
    fn jaumann_trial_without_spin_is_the_linear_elastic_step() {
        let e = Elastic3::new(2.0e7, 0.3);
        let le = LinearElastic::new(2.0e7, 0.3, 1000.0);
        let s = [-1.0e5, 2.0e4, 3.0e4];
        let (l, dt) = ([0.3, 0.2, 0.2, -0.1], 1e-4);
        let (t, tzz) = e.jaumann_trial(l, dt, &s, 0.3 * (s[0] + s[1]));
        let mut r = s;
        le.update_stress(&mut r, [dt * l[0], dt * l[3], 0.5 * dt * (l[1] + l[2])]);
        for k in 0..3 {
            assert!((t[k] - r[k]).abs() < 1e-9, "{t:?} vs {r:?}");
        }
        // σzz follows ν(σxx + σyy) while elastic.
        assert!((tzz - 0.3 * (t[0] + t[1])).abs() < 1e-9);
    }

    #[test]
    fn jaumann_spin_rotates_without_straining() {
        // A rigid rotation (L skew) turns the stress, keeping its invariants
        // to first order: tr and the in-plane norm change by O(Δt²).
        let e = Elastic3::new(2.0e7, 0.3);
        let s = [-1.0e5, 2.0e4, 3.0e4];
        let omega = 2.0;
        let (t, _) = e.jaumann_trial([0.0, omega, -omega, 0.0], 1e-4, &s, 0.0);
        assert!((t[0] + t[1] - s[0] - s[1]).abs() < 1e-9);
        let n0 = 0.25 * (s[0] - s[1]).powi(2) + s[2] * s[2];
        let n1 = 0.25 * (t[0] - t[1]).powi(2) + t[2] * t[2];
        assert!((n1 - n0).abs() < 1e-6 * n0, "{n0} {n1}");
        // σxy changes by Δt ω (σyy − σxx).
        assert!((t[2] - s[2] - 1e-4 * omega * (s[1] - s[0])).abs() < 1e-9);
    }
}
