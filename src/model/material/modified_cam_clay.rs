//! Modified Cam-clay (Roscoe & Burland 1968), plane strain, tension
//! positive. Stresses σ = [σxx, σyy, σxy] with σzz carried in the plastic
//! state; effective stresses throughout (no pore pressure: "undrained" is
//! a constant-volume path).
//!
//! - Invariants over the 3D stress: p′ = −tr σ / 3 (compression positive),
//!   q = sqrt(3 J2) = sqrt(3/2 s : s).
//! - Yield and flow (associated): f = q²/M² + p′(p′ − p_c) ≤ 0.
//! - Elasticity: K = v p′ / κ, G from a constant ν (G = 3K(1 − 2ν) /
//!   (2(1 + ν))) or a constant G. The volumetric part is integrated exactly
//!   over a step in specific volume: Δv_e = −κ Δ ln p′ (the unloading line
//!   v + κ ln p′ = const); G is the start-of-step one (explicit in G).
//! - Hardening: Δv_p = −(λ − κ) Δ ln p_c (the normal compression line
//!   v + λ ln p_c = const along virgin loading). With Δv = v_n tr Δε and
//!   v_{n+1} = v_n (1 + tr Δε), the state keeps v + κ ln p′ + (λ − κ) ln p_c
//!   constant exactly (up to the return's tolerance), on any path.
//! - Return: closest point (backward Euler on the flow rule) with the
//!   exact nonlinear elastic predictor, after Borja & Lee (1990, CMAME 78)
//!   and Borja (1991, CMAME 88): here a 3×3 Newton on (ln p′, ln p_c, Δγ)
//!   scaled by p_c, steps limited to one e-fold in p′ and p_c. A step whose
//!   return does not converge in `MAX_ITER` is split into 8, then 64 parts
//!   (`SUBSTEPS`); past that it is the model's fault `NOT_CONVERGED`
//!   (`return_not_converged` in summary.json), never a NaN.
//! - Tension: the stiffness uses max(p′, p_floor). From p′ ≥ p_floor the
//!   trial p′ stays positive (p′ e^x); from below (a particle at zero
//!   stress) a trial with p′ ≤ 0 goes to the apex of the ellipse, σ = 0
//!   (p_c kept, v still v ρ_old/ρ), flagged `ACTIVE_APEX`.
//!
//! Plastic state `[σzz (Pa), p_c (Pa), v, return]`: the out-of-plane
//! stress, the preconsolidation pressure (compression positive), the
//! specific volume v = 1 + e, and the last return (0 elastic,
//! `ACTIVE_MAIN` the ellipse, `ACTIVE_APEX` the tension apex).
//!
//! WGSL twin: `shaders/shared/material_modified_cam_clay.wgsl`.

use super::plastic::{self, ACTIVE_APEX, ACTIVE_MAIN, PlasticState};
use crate::model::fault::{FaultKind, MaterialFault};

/// The model's one fault: the return did not converge even split into
/// `SUBSTEPS[last]` parts. Its WGSL twin reports
/// `MODIFIED_CAM_CLAY_FAULT_RETURN_NOT_CONVERGED` (generated from this).
pub const NOT_CONVERGED: MaterialFault = MaterialFault {
    code: "return_not_converged",
    what: "the material's stress return did not converge",
    value: "scaled residual",
    advice: "lower solver.cfl / solver.dt",
};

/// `NOT_CONVERGED` with its residual.
fn not_converged(residual: f64) -> FaultKind {
    FaultKind::Material {
        fault: NOT_CONVERGED,
        value: residual,
    }
}

/// Index of p_c (Pa) in the plastic state.
pub const PC: usize = 1;
/// Index of the specific volume v = 1 + e in the plastic state.
pub const VOLUME: usize = 2;

/// Reference pressure of N (Pa): N is v on the normal compression line at
/// p′ = 1 kPa.
pub const P_REF: f64 = 1.0e3;
/// Default floor of the pressure in the elastic stiffness (Pa): K = v
/// max(p′, p_floor) / κ, so a particle at zero stress can be loaded again.
pub const P_FLOOR: f64 = 1.0;
/// Newton converges when every scaled residual (ln p′, ln p_c, and
/// f / max(p_c, p_c at the step's start)²) is below this: the f64 round-off of the residuals is ~1e-15 · a Δγ
/// (2p′ − p_c) with a = v/κ ≤ ~1e3.
pub const RETURN_TOL_F64: f64 = 1e-11;
/// The same in the WGSL twin (`MCC_RETURN_TOL`): f32 residuals round off at
/// ~1e-7 · |ln p′| (≤ ~20), so 1e-5 is reached, and it bounds the error of
/// p′, p_c relative to themselves by about the same.
pub const RETURN_TOL_F32: f64 = 1e-5;
/// Newton iterations before the return is declared not converged.
pub const MAX_ITER: u32 = 40;
/// The splits of a step tried in turn when the return does not converge
/// (one part: the plain step; all returns converge up to 20 % strain per
/// step without a split, see `large_steps_converge`).
pub const SUBSTEPS: [u32; 3] = [1, 8, 64];

#[derive(Debug, Clone, PartialEq)]
pub struct ModifiedCamClay {
    /// Initial density ρ0 (kg/m³), at the initial specific volume `v0`.
    pub density: f64,
    /// Poisson's ratio ν (used when `shear` is `None`).
    pub nu: f64,
    /// Constant shear modulus G (Pa); `None`: G from K and ν.
    pub shear: Option<f64>,
    /// Slope κ of the unloading lines in v–ln p′.
    pub kappa: f64,
    /// Slope λ of the normal compression line in v–ln p′ (λ > κ).
    pub lambda: f64,
    /// Critical-state stress ratio M = q/p′.
    pub m_cs: f64,
    /// N: v on the normal compression line at p′ = `P_REF` (1 kPa).
    pub n_ncl: f64,
    /// Initial mean effective stress p′0 (Pa, compression positive).
    pub p0: f64,
    /// Initial preconsolidation p_c0 = ocr · p′0 (Pa).
    pub pc0: f64,
    /// Initial specific volume v0, on the unloading line through p_c0:
    /// v0 = N − λ ln(p_c0 / P_REF) + κ ln(p_c0 / p′0).
    pub v0: f64,
    /// Pressure floor of the elastic stiffness (Pa), `P_FLOOR` by default.
    pub p_floor: f64,
}

/// M of a critical-state friction angle φ_cs (degrees), the triaxial
/// compression match: M = 6 sin φ / (3 − sin φ).
pub fn m_from_friction_angle(phi_deg: f64) -> f64 {
    let s = phi_deg.to_radians().sin();
    6.0 * s / (3.0 - s)
}

/// The scene's keys of the model, as given (units as in `ModifiedCamClay`).
/// Exactly one of `nu`/`shear`, of `m`/`friction_angle` and of `n`/`e0`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CamClayKeys {
    pub density: f64,
    pub nu: Option<f64>,
    pub shear: Option<f64>,
    pub kappa: f64,
    pub lambda: f64,
    pub m: Option<f64>,
    /// Critical-state friction angle φ_cs (degrees).
    pub friction_angle: Option<f64>,
    pub n: Option<f64>,
    /// Initial void ratio e0 (v0 = 1 + e0).
    pub e0: Option<f64>,
    /// Initial mean effective stress p′0 (Pa).
    pub p0: f64,
    /// Overconsolidation ratio p_c0 / p′0 (≥ 1; default 1).
    pub ocr: Option<f64>,
}

impl ModifiedCamClay {
    /// From N (v on the NCL at 1 kPa), p′0 (Pa) and the overconsolidation
    /// ratio; `shear` `None` takes G from ν.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        density: f64,
        nu: f64,
        shear: Option<f64>,
        kappa: f64,
        lambda: f64,
        m_cs: f64,
        n_ncl: f64,
        p0: f64,
        ocr: f64,
    ) -> Self {
        let pc0 = ocr * p0;
        ModifiedCamClay {
            density,
            nu,
            shear,
            kappa,
            lambda,
            m_cs,
            n_ncl,
            p0,
            pc0,
            v0: n_ncl - lambda * (pc0 / P_REF).ln() + kappa * ocr.ln(),
            p_floor: P_FLOOR,
        }
    }

    /// From the scene's keys; an error names the key at fault and why.
    pub fn from_keys(k: &CamClayKeys) -> Result<Self, (&'static str, String)> {
        let positive = |key: &'static str, v: f64| {
            if v > 0.0 && v.is_finite() {
                Ok(v)
            } else {
                Err((key, format!("must be a positive number, got {v}")))
            }
        };
        let density = positive("density", k.density)?;
        let kappa = positive("kappa", k.kappa)?;
        let lambda = positive("lambda", k.lambda)?;
        if lambda <= kappa {
            return Err((
                "lambda",
                format!("must exceed kappa = {kappa} (got {lambda})"),
            ));
        }
        let p0 = positive("p0", k.p0)?;
        let ocr = k.ocr.unwrap_or(1.0);
        if !(ocr >= 1.0 && ocr.is_finite()) {
            return Err(("ocr", format!("must be ≥ 1, got {ocr}")));
        }
        let (nu, shear) = match (k.nu, k.shear) {
            (Some(nu), None) if (0.0..0.5).contains(&nu) => (nu, None),
            (Some(nu), None) => return Err(("nu", format!("must be in [0, 0.5), got {nu}"))),
            (None, Some(g)) => (0.0, Some(positive("G", g)?)),
            _ => return Err(("nu", "give exactly one of nu and G".into())),
        };
        let m_cs = match (k.m, k.friction_angle) {
            (Some(m), None) => positive("M", m)?,
            (None, Some(phi)) if phi > 0.0 && phi < 90.0 => m_from_friction_angle(phi),
            (None, Some(phi)) => {
                return Err((
                    "friction_angle",
                    format!("must be in (0, 90) degrees, got {phi}"),
                ));
            }
            _ => return Err(("M", "give exactly one of M and friction_angle".into())),
        };
        let pc0 = ocr * p0;
        let n_ncl = match (k.n, k.e0) {
            (Some(n), None) => n,
            // v0 = 1 + e0 on the unloading line through p_c0.
            (None, Some(e0)) => {
                1.0 + positive("e0", e0)? + lambda * (pc0 / P_REF).ln() - kappa * ocr.ln()
            }
            _ => return Err(("N", "give exactly one of N and e0".into())),
        };
        let m = Self::new(density, nu, shear, kappa, lambda, m_cs, n_ncl, p0, ocr);
        if m.v0 <= 1.0 {
            return Err((
                "N",
                format!(
                    "gives an initial specific volume v0 = {:.4} ≤ 1 (a negative void ratio) at p_c0 = {pc0} Pa",
                    m.v0
                ),
            ));
        }
        Ok(m)
    }

    /// The initial stress and plastic state: isotropic p′0, p_c0, v0.
    pub fn initial_state(&self) -> ([f64; 3], PlasticState) {
        (
            [-self.p0, -self.p0, 0.0],
            [-self.p0, self.pc0, self.v0, 0.0],
        )
    }

    /// Bulk modulus K = v max(p′, p_floor) / κ (Pa).
    #[inline]
    pub fn bulk(&self, p: f64, v: f64) -> f64 {
        v * p.max(self.p_floor) / self.kappa
    }

    /// Shear modulus at bulk modulus `k` (Pa).
    #[inline]
    pub fn shear_at(&self, k: f64) -> f64 {
        self.shear
            .unwrap_or(1.5 * k * (1.0 - 2.0 * self.nu) / (1.0 + self.nu))
    }

    /// Lamé λ and shear modulus G (Pa) at p′ (Pa) and v: the tangent
    /// moduli there (`moduli(p0, v0)` for a scale of the initial state).
    pub fn moduli(&self, p: f64, v: f64) -> (f64, f64) {
        let k = self.bulk(p, v);
        let g = self.shear_at(k);
        (k - 2.0 * g / 3.0, g)
    }

    /// The yield function f = q²/M² + p′(p′ − p_c) (Pa²).
    #[inline]
    pub fn yield_fn(&self, p: f64, q: f64, pc: f64) -> f64 {
        q * q / (self.m_cs * self.m_cs) + p * (p - pc)
    }

    /// One step from the (already rotated) stress `s` = [xx, yy, zz, xy]
    /// with the strain increment `de` = [xx, yy, zz, xy] (tensor shear):
    /// the new stress and plastic state. Plane strain passes de[2] = 0;
    /// the full 3D increment is there for isotropic compression. Should
    /// the return not converge, the increment is split into `SUBSTEPS[k]`
    /// equal parts (their volume ratios multiplying to 1 + tr Δε, so v
    /// stays v0 ρ0/ρ) and tried again.
    pub fn step(
        &self,
        s: [f64; 4],
        de: [f64; 4],
        q: &PlasticState,
    ) -> Result<([f64; 4], PlasticState), FaultKind> {
        let mut last = not_converged(f64::INFINITY);
        for n in SUBSTEPS {
            let ev = de[0] + de[1] + de[2];
            // Diagonal scale c: (1 + c ev / n)^n = 1 + ev.
            let mut c = 1.0 / n as f64;
            if ev != 0.0 && n > 1 {
                c = ((1.0 + ev).powf(1.0 / n as f64) - 1.0) / ev;
            }
            let d = [c * de[0], c * de[1], c * de[2], de[3] / n as f64];
            let (mut sk, mut qk) = (s, *q);
            let mut failed = None;
            for _ in 0..n {
                match self.step_once(sk, d, &qk) {
                    Ok((s1, q1)) => (sk, qk) = (s1, q1),
                    Err(e) => {
                        failed = Some(e);
                        break;
                    }
                }
            }
            match failed {
                None => return Ok((sk, qk)),
                Some(e @ FaultKind::Material { .. }) => last = e,
                Some(e) => return Err(e),
            }
        }
        Err(last)
    }

    /// One step without substeps (`step`'s attempt with one part).
    // Index loops on purpose: they mirror mcc_step_once in the WGSL twin.
    #[allow(clippy::needless_range_loop)]
    pub fn step_once(
        &self,
        s: [f64; 4],
        de: [f64; 4],
        q: &PlasticState,
    ) -> Result<([f64; 4], PlasticState), FaultKind> {
        let v = q[VOLUME];
        let pc = q[PC];
        let p_n = -(s[0] + s[1] + s[2]) / 3.0;
        let pb = p_n.max(self.p_floor);
        let g = self.shear_at(self.bulk(p_n, v));
        let ev = de[0] + de[1] + de[2];
        let v_new = v * (1.0 + ev);
        // Elastic trial: p′ exact along the unloading line (from p_floor
        // below it), s by 2G Δe. p_n e^x, not p_n + p_n (e^x − 1): a large
        // extension must not cancel to 0 in f32.
        let ex = (-v * ev / self.kappa).exp();
        let p_tr = if p_n >= self.p_floor {
            p_n * ex
        } else {
            p_n + pb * (ex - 1.0)
        };
        let mut sd = [0.0; 4];
        for k in 0..3 {
            sd[k] = s[k] + p_n + 2.0 * g * (de[k] - ev / 3.0);
        }
        sd[3] = s[3] + 2.0 * g * de[3];
        let q_tr =
            (1.5 * (sd[0] * sd[0] + sd[1] * sd[1] + sd[2] * sd[2] + 2.0 * sd[3] * sd[3])).sqrt();
        if !(p_tr.is_finite() && q_tr.is_finite()) {
            return Err(FaultKind::NonFinite { field: "stress" });
        }
        if p_tr <= 0.0 {
            // Tension: the apex of the ellipse, where it admits no stress.
            return Ok(([0.0; 4], [0.0, pc, v_new, ACTIVE_APEX as f64]));
        }
        if self.yield_fn(p_tr, q_tr, pc) <= 0.0 {
            let out = [sd[0] - p_tr, sd[1] - p_tr, sd[2] - p_tr, sd[3]];
            return Ok((out, [out[2], pc, v_new, 0.0]));
        }
        // Closest point, scaled by p_c: P = p′/p_c,n = e^y, Pc = e^z,
        // w = Δγ p_c,n; d = ∂f/∂p′ / p_c,n = 2P − Pc; Q = q/p_c,n.
        let m2 = self.m_cs * self.m_cs;
        let a = v / self.kappa;
        let b = v / (self.lambda - self.kappa);
        let gn = g / pc;
        let qn = q_tr / pc;
        let yt = (p_tr / pc).ln();
        let (mut y, mut z, mut w) = (yt, 0.0f64, 0.0f64);
        let mut ratio = 1.0;
        let mut converged = false;
        let mut res = f64::INFINITY;
        for _ in 0..MAX_ITER {
            let pp = y.exp();
            let pcc = z.exp();
            let d = 2.0 * pp - pcc;
            let den = 1.0 + 6.0 * gn * w / m2;
            let qq = qn / den;
            let f = qq * qq / m2 + pp * (pp - pcc);
            // f over max(p_c, p_c,n)²: relative to the current p_c where
            // the step hardens (f64 and f32 then converge at any
            // hardening), to the start one where it softens (p_c → 0
            // would blow the residual up).
            let hard = pcc > 1.0;
            let e2 = if hard { 1.0 / (pcc * pcc) } else { 1.0 };
            let dz = if hard { 2.0 * f } else { 0.0 };
            let r = [y - yt + a * w * d, z - b * w * d, f * e2];
            res = r[0].abs().max(r[1].abs()).max(r[2].abs());
            ratio = 1.0 / den;
            if res <= RETURN_TOL_F64 {
                converged = true;
                break;
            }
            let jac = [
                [1.0 + 2.0 * a * w * pp, -a * w * pcc, a * d],
                [-2.0 * b * w * pp, 1.0 + b * w * pcc, -b * d],
                [
                    pp * d * e2,
                    -(pp * pcc + dz) * e2,
                    -12.0 * gn * qq * qq / (m2 * m2 * den) * e2,
                ],
            ];
            let Some(dx) = super::mohr_coulomb::solve3(jac, r) else {
                break;
            };
            // Steps of at most one e-fold in p′ and p_c; Δγ stays ≥ 0.
            let big = dx[0].abs().max(dx[1].abs());
            let t = if big > 1.0 { 1.0 / big } else { 1.0 };
            y -= t * dx[0];
            z -= t * dx[1];
            let w_new = w - t * dx[2];
            w = if w_new < 0.0 { 0.5 * w } else { w_new };
        }
        if !converged {
            return Err(not_converged(res));
        }
        let p = y.exp() * pc;
        let pc_new = z.exp() * pc;
        let out = [
            ratio * sd[0] - p,
            ratio * sd[1] - p,
            ratio * sd[2] - p,
            ratio * sd[3],
        ];
        Ok((out, [out[2], pc_new, v_new, ACTIVE_MAIN as f64]))
    }

    /// One step: Jaumann rotation of the stress, plane-strain increment,
    /// `step`. Updates the in-plane stress and the plastic state; returns
    /// V_new / V_old.
    #[inline]
    pub fn update(
        &self,
        l: [f64; 4],
        dt: f64,
        stress: &mut [f64; 3],
        q: &mut PlasticState,
    ) -> Result<f64, FaultKind> {
        debug_assert!(
            q[PC] > 0.0 && q[VOLUME] > 0.0,
            "modified Cam-clay state not initialised (p_c, v = {}, {}): seed it from initial_state()",
            q[PC],
            q[VOLUME]
        );
        let j = plastic::volume_ratio(l, dt)?;
        // σ + Δt (Wσ − σW), W = skew(L); σzz is not turned.
        let w = 0.5 * dt * (l[1] - l[2]);
        let s = *stress;
        let rot = [
            s[0] + 2.0 * w * s[2],
            s[1] - 2.0 * w * s[2],
            q[plastic::SZZ],
            s[2] + w * (s[1] - s[0]),
        ];
        let de = [dt * l[0], dt * l[3], 0.0, 0.5 * dt * (l[1] + l[2])];
        let (out, qn) = self.step(rot, de, q)?;
        *stress = [out[0], out[1], out[3]];
        *q = qn;
        Ok(j)
    }

    /// Speed of the fastest elastic wave at density `rho` (m/s): v = v0
    /// ρ0/ρ, and every state inside the ellipse with v + κ ln p′ + (λ − κ)
    /// ln p_c = N has p′ ≤ P_REF exp((N − v)/λ) (the NCL at that v), so
    /// K ≤ v P_REF exp((N − v)/λ) / κ bounds the stiffness.
    #[inline]
    pub fn wave_speed(&self, rho: f64) -> f64 {
        self.wave_speed_squared(rho).sqrt()
    }

    /// `wave_speed` squared.
    pub fn wave_speed_squared(&self, rho: f64) -> f64 {
        let v = self.v0 * self.density / rho;
        let p_max = P_REF * ((self.n_ncl - v) / self.lambda).exp();
        let k = self.bulk(p_max, v);
        (k + 4.0 / 3.0 * self.shear_at(k)) / rho
    }

    /// Elastic energy per unit volume (J/m³) of the stress with its σzz:
    /// ½ σ : C⁻¹ : σ = s : s / (4G) + p′² / (2K) at the current moduli (a
    /// hypo-elastic model has no potential; this is the energy the current
    /// stiffness stores, as for the other plastic models).
    #[inline]
    pub fn energy(&self, stress: &[f64; 3], q: &PlasticState) -> f64 {
        let s = [stress[0], stress[1], q[plastic::SZZ], stress[2]];
        let p = -(s[0] + s[1] + s[2]) / 3.0;
        let k = self.bulk(p, q[VOLUME]);
        let g = self.shear_at(k);
        let d = [s[0] + p, s[1] + p, s[2] + p];
        let ss = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + 2.0 * s[3] * s[3];
        ss / (4.0 * g) + p * p / (2.0 * k)
    }

    /// The parameters of the WGSL twin, in `MccParams` order: κ, λ, M, ν,
    /// G (Pa; 0 = from ν), p_floor (Pa), ρ0 v0 (kg/m³), N + λ ln(P_REF / 1 Pa)
    /// (v on the NCL at p′ = 1 Pa).
    pub fn packed(&self) -> [f64; 8] {
        [
            self.kappa,
            self.lambda,
            self.m_cs,
            self.nu,
            self.shear.unwrap_or(0.0),
            self.p_floor,
            self.density * self.v0,
            self.n_ncl + self.lambda * P_REF.ln(),
        ]
    }
}

/// p′ (compression positive) and q = sqrt(3 J2) of [xx, yy, zz, xy].
pub fn p_q(s: [f64; 4]) -> (f64, f64) {
    let p = -(s[0] + s[1] + s[2]) / 3.0;
    let d = [s[0] + p, s[1] + p, s[2] + p];
    let ss = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + 2.0 * s[3] * s[3];
    (p, (1.5 * ss).sqrt())
}

/// The model's scene keys (besides `density`).
const KEYS: &[super::Key] = &[
    super::Key {
        name: "kappa",
        unit: "1",
        doc: "slope κ of the unloading lines in v–ln p′, > 0; required",
    },
    super::Key {
        name: "lambda",
        unit: "1",
        doc: "slope λ of the normal compression line, > κ; required",
    },
    super::Key {
        name: "M",
        unit: "1",
        doc: "critical-state stress ratio q/p′; or friction_angle",
    },
    super::Key {
        name: "friction_angle",
        unit: "degrees",
        doc: "critical-state friction angle φ_cs (M = 6 sin φ / (3 − sin φ)); or M",
    },
    super::Key {
        name: "N",
        unit: "1",
        doc: "specific volume on the NCL at p′ = 1 kPa; or e0",
    },
    super::Key {
        name: "e0",
        unit: "1",
        doc: "initial void ratio; or N",
    },
    super::Key {
        name: "p0",
        unit: "Pa",
        doc: "initial mean effective stress p′0 (compression positive), > 0; required",
    },
    super::Key {
        name: "ocr",
        unit: "1",
        doc: "overconsolidation ratio p_c0 / p′0, ≥ 1; default 1",
    },
    super::Key {
        name: "nu",
        unit: "1",
        doc: "Poisson's ratio in [0, 0.5) (G from K); or G",
    },
    super::Key {
        name: "G",
        unit: "Pa",
        doc: "constant shear modulus; or nu",
    },
];

impl super::Constitutive for ModifiedCamClay {
    const NAME: &'static str = "modified_cam_clay";
    const KEYS: &'static [super::Key] = KEYS;
    const STATE: super::StateKind = super::StateKind::Plastic;
    const GPU_PARAMS: &'static [&'static str] = &[
        "kappa", "lambda", "m_cs", "nu", "shear", "p_floor", "rho_v0", "n_pa",
    ];
    const FAULTS: &'static [MaterialFault] = &[NOT_CONVERGED];
    const STATE_COLUMNS: &'static [super::StateColumn] = &[
        super::StateColumn {
            column: "p_c",
            array: "preconsolidation_pressure",
            unit: "Pa",
            meaning: "preconsolidation pressure p_c",
            symbol: "p_c",
            from_zero: false,
        },
        super::StateColumn {
            column: "v",
            array: "specific_volume",
            unit: "1",
            meaning: "specific volume v = 1 + e",
            symbol: "v",
            from_zero: false,
        },
    ];
    const OWN_START: bool = true;

    fn from_keys(k: &super::Keys) -> Result<Self, crate::error::SceneError> {
        let keys = CamClayKeys {
            density: k.density(),
            nu: k.optional("nu")?,
            shear: k.optional("G")?,
            kappa: k.required("kappa")?,
            lambda: k.required("lambda")?,
            m: k.optional("M")?,
            friction_angle: k.optional("friction_angle")?,
            n: k.optional("N")?,
            e0: k.optional("e0")?,
            p0: k.required("p0")?,
            ocr: k.optional("ocr")?,
        };
        ModifiedCamClay::from_keys(&keys).map_err(|(key, msg)| k.invalid(key, msg))
    }
    fn density(&self) -> f64 {
        self.density
    }
    /// At the initial state: K = v0 p′0 / κ and its G.
    fn lame_shear(&self) -> (f64, f64) {
        let k = self.bulk(self.p0, self.v0);
        let g = self.shear_at(k);
        (k - 2.0 * g / 3.0, g)
    }
    fn youngs_nu(&self) -> (f64, f64) {
        let k = self.bulk(self.p0, self.v0);
        let g = self.shear_at(k);
        (
            9.0 * k * g / (3.0 * k + g),
            (3.0 * k - 2.0 * g) / (2.0 * (3.0 * k + g)),
        )
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
        ModifiedCamClay::update(self, l, dt, stress, q)
    }
    #[inline]
    fn wave_speed(&self, rho: f64, _s: &[f64; 3], _q: &PlasticState) -> f64 {
        ModifiedCamClay::wave_speed(self, rho)
    }
    fn wave_speed_squared(&self, rho: f64, _s: &[f64; 3], _q: &PlasticState) -> f64 {
        ModifiedCamClay::wave_speed_squared(self, rho)
    }
    #[inline]
    fn strain_energy_density(&self, s: &[f64; 3], _f: &super::DefGrad, q: &PlasticState) -> f64 {
        self.energy(s, q)
    }
    /// κ, λ, M, ν, G (0: from ν), p_floor, ρ0 v0, N + λ ln(1000) (`packed`).
    fn gpu_params(&self) -> Vec<f32> {
        self.packed().iter().map(|&v| v as f32).collect()
    }
    fn initial_state(&self) -> ([f64; 3], PlasticState) {
        ModifiedCamClay::initial_state(self)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::material::plastic::{RETURN, SZZ};

    /// A soft clay: ρ0 = 1800 kg/m³, ν = 0.3, κ = 0.04, λ = 0.2,
    /// M = 1.2 (φ_cs = 30°), N = 2.5 at 1 kPa.
    fn clay(p0: f64, ocr: f64) -> ModifiedCamClay {
        ModifiedCamClay::new(1800.0, 0.3, None, 0.04, 0.2, 1.2, 2.5, p0, ocr)
    }

    /// v on the NCL at p′ (Pa).
    fn ncl(m: &ModifiedCamClay, p: f64) -> f64 {
        m.n_ncl - m.lambda * (p / P_REF).ln()
    }

    /// The bounds: NCL and critical state within 1 %, the
    /// undrained path within 2 %.
    const NCL_REL: f64 = 0.01;
    const CSL_REL: f64 = 0.01;
    const UNDRAINED_REL: f64 = 0.02;

    #[test]
    fn isotropic_compression_follows_the_ncl() {
        // Δε = −δ/3 on xx, yy and zz (3D isotropic), from p′0 = 50 kPa to
        // past 2 MPa, normally consolidated and from ocr = 4 (elastic on
        // the unloading line first, then on the NCL past p_c0).
        for (ocr, delta) in [(1.0, 1e-4), (1.0, 1e-2), (4.0, 1e-4)] {
            let m = clay(5.0e4, ocr);
            let (s0, mut q) = m.initial_state();
            let mut s = [s0[0], s0[1], q[SZZ], s0[2]];
            let mut worst: f64 = 0.0;
            let mut on_ncl = 0;
            let mut steps = 0;
            while -s[0] < 2.0e6 {
                let de = [-delta / 3.0, -delta / 3.0, -delta / 3.0, 0.0];
                let (s1, q1) = m.step(s, de, &q).unwrap();
                (s, q) = (s1, q1);
                steps += 1;
                let (p, qd) = p_q(s);
                assert!(qd < 1e-9 * p, "isotropic stays isotropic: q = {qd}");
                if q[RETURN] == ACTIVE_MAIN as f64 {
                    on_ncl += 1;
                    let err = (q[VOLUME] - ncl(&m, p)).abs() / q[VOLUME];
                    worst = worst.max(err);
                    // On the NCL the stress is the preconsolidation.
                    assert!((p - q[PC]).abs() < 1e-9 * p, "{p} vs {}", q[PC]);
                } else {
                    // Elastic: on the unloading line through p_c0.
                    let url = m.v0 - m.kappa * (p / m.p0).ln();
                    assert!((q[VOLUME] - url).abs() < 1e-12, "{} vs {url}", q[VOLUME]);
                }
            }
            println!(
                "NCL ocr {ocr}, δ = {delta:.0e}: {steps} steps, {on_ncl} on the NCL, \
                 worst |v − (N − λ ln p′)| / v = {worst:.2e}"
            );
            assert!(on_ncl > steps / 2, "{on_ncl} of {steps}");
            assert!(worst < NCL_REL, "{worst}");
            // The integration is exact along the NCL: only the return's
            // tolerance is left (measured ≤ 1e-14).
            assert!(worst < 1e-10, "{worst}");
        }
    }

    #[test]
    fn plane_strain_one_dimensional_compression_parallels_the_ncl() {
        // Δεyy alone (plane strain, εxx = εzz = 0): the stress ratio settles
        // to a constant η and v follows a line of slope −λ in v–ln p′,
        // below the NCL by (λ − κ) ln(1 + η²/M²).
        let m = clay(5.0e4, 1.0);
        let (mut s, mut q) = m.initial_state();
        let mut path = Vec::new();
        // To ε_yy = −0.3 (v stays above 1).
        for _ in 0..3000 {
            m.update([0.0, 0.0, 0.0, -1.0], 1e-4, &mut s, &mut q)
                .unwrap();
            let (p, qd) = p_q([s[0], s[1], q[SZZ], s[2]]);
            path.push((p, qd, q[VOLUME]));
        }
        let (p1, _, v1) = path[path.len() / 2];
        let (p2, q2, v2) = *path.last().unwrap();
        let slope = -(v2 - v1) / (p2 / p1).ln();
        let eta = q2 / p2;
        let want = ncl(&m, p2) - (m.lambda - m.kappa) * (1.0 + eta * eta / (m.m_cs * m.m_cs)).ln();
        println!(
            "1D: p′ {p1:.0} → {p2:.0} Pa, slope {slope:.5} (λ = {}), η = {eta:.4}, \
             v {v2:.6} vs {want:.6}",
            m.lambda
        );
        assert!(v2 > 1.0, "{v2}");
        assert!((slope - m.lambda).abs() < NCL_REL * m.lambda, "{slope}");
        assert!((v2 - want).abs() < 1e-10 * v2, "{v2} vs {want}");
    }

    /// One drained biaxial state along the test.
    #[derive(Debug, Clone, Copy)]
    struct Point {
        axial: f64,
        vol: f64,
        p: f64,
        q: f64,
    }

    /// Drained plane-strain biaxial compression: the lateral stress σxx
    /// held at −σc (secant method on ∂vx/∂x each step, as in
    /// `material::tests::biaxial_peak`), Δεyy = −`d_eps` per step, from the
    /// model's initial state. Returns the path.
    fn biaxial(m: &ModifiedCamClay, steps: usize, d_eps: f64) -> Vec<Point> {
        let (mut s, mut q) = m.initial_state();
        let sigma_c = m.p0;
        let (dt, lyy) = (d_eps, -1.0);
        let (mut axial, mut vol) = (0.0, 0.0);
        let mut out = Vec::with_capacity(steps);
        let mut lxx_prev = 0.3 / 0.7;
        for _ in 0..steps {
            let trial = |lxx: f64| {
                let (mut s1, mut q1) = (s, q);
                m.update([lxx, 0.0, 0.0, lyy], dt, &mut s1, &mut q1)
                    .unwrap();
                (s1, q1)
            };
            let r = |lxx: f64| trial(lxx).0[0] + sigma_c;
            let mut a = lxx_prev;
            let mut b = a * 1.01 + 1e-3;
            let (mut ra, mut rb) = (r(a), r(b));
            for _ in 0..60 {
                if rb.abs() < 1e-10 * sigma_c || rb == ra {
                    break;
                }
                let c = b - rb * (b - a) / (rb - ra);
                (a, ra) = (b, rb);
                (b, rb) = (c, r(c));
            }
            assert!(rb.abs() < 1e-7 * sigma_c, "lateral stress not held: {rb}");
            lxx_prev = b;
            (s, q) = trial(b);
            axial += dt * lyy;
            vol += dt * (b + lyy);
            let (p, qd) = p_q([s[0], s[1], q[SZZ], s[2]]);
            out.push(Point {
                axial,
                vol,
                p,
                q: qd,
            });
        }
        out
    }

    /// |Δε_v / Δε_axial| over the last `n` steps (5 % axial strain for
    /// n = 100 at 5e-4 a step).
    fn vol_rate(path: &[Point], n: usize) -> f64 {
        let (a, b) = (path[path.len() - 1 - n], path[path.len() - 1]);
        ((b.vol - a.vol) / (b.axial - a.axial)).abs()
    }

    /// Volumetric strain rate at the end of the biaxial tests: below this
    /// fraction of the axial rate (the issue: "stops").
    const VOL_RATE_END: f64 = 1e-2;

    #[test]
    fn drained_biaxial_of_normally_consolidated_clay_ends_on_the_csl() {
        let m = clay(1.0e5, 1.0);
        // Δεyy = 5e-4 per step to an axial (logarithmic) strain of 2: the
        // approach to the critical state is asymptotic, and with σxx held
        // in plane strain the ratio q/p′ climbs slowly (within 1 % of M
        // from ε_a ≈ 1.2; the same path to 4 digits with 1e-4 per step).
        let path = biaxial(&m, 4000, 5e-4);
        let end = path.last().unwrap();
        let eta = end.q / end.p;
        let err = (eta - m.m_cs) / m.m_cs;
        let rate = vol_rate(&path, 100);
        // At the critical state the strain is deviatoric and εzz = 0, so
        // s_zz = 0: σzz = −p′, p′ = (σc + σa)/2, q = sqrt(3)(σa − σc)/2, and
        // q/p′ = M gives σa/σc = (sqrt 3 + M)/(sqrt 3 − M).
        let r3 = 3f64.sqrt();
        let p_cs = m.p0 * (1.0 + (r3 + m.m_cs) / (r3 - m.m_cs)) / 2.0;
        let err_p = (end.p - p_cs) / p_cs;
        println!(
            "NC biaxial: q/p′ = {eta:.5} (M = {}, {err:+.2e}), p′ {:.0} vs {p_cs:.0} Pa \
             ({err_p:+.2e}), ε_v = {:.4}, |dε_v/dε_a| over the last 5 % {rate:.2e}",
            m.m_cs, end.p, end.vol
        );
        assert!(err.abs() < CSL_REL, "{eta}");
        assert!(err_p.abs() < CSL_REL, "{} vs {p_cs}", end.p);
        assert!(rate < VOL_RATE_END, "{rate}");
        // Contractive all along (tension positive: ε_v falls), hardening.
        assert!(path.windows(2).all(|w| w[1].vol <= w[0].vol + 1e-15));
        assert!(path.windows(2).all(|w| w[1].q >= w[0].q - 1e-9 * w[0].q));
    }

    #[test]
    fn heavily_overconsolidated_clay_dilates_and_softens_to_the_csl() {
        let m = clay(2.0e4, 10.0);
        // As the NC test: to ε_a = 2 in steps of 5e-4 (within 1 % of M
        // from ε_a ≈ 0.6).
        let path = biaxial(&m, 4000, 5e-4);
        let end = path.last().unwrap();
        let (ipk, peak) = path
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.q.total_cmp(&b.1.q))
            .unwrap();
        let eta = end.q / end.p;
        let err = (eta - m.m_cs) / m.m_cs;
        let rate = vol_rate(&path, 100);
        let min_vol = path.iter().map(|p| p.vol).fold(f64::INFINITY, f64::min);
        println!(
            "OC 10 biaxial: peak q/p′ = {:.4} at ε_a = {:.4}, q {:.0} → {:.0} Pa; \
             ε_v min {min_vol:.5} → {:.5}; end q/p′ = {eta:.5} ({err:+.2e}), \
             |dε_v/dε_a| {rate:.2e}",
            peak.q / peak.p,
            -peak.axial,
            peak.q,
            end.q,
            end.vol
        );
        // Yields on the dry side (q/p′ > M), then softens ...
        assert!(peak.q / peak.p > 1.2 * m.m_cs, "{}", peak.q / peak.p);
        assert!(
            ipk < path.len() / 2 && end.q < 0.9 * peak.q,
            "{ipk} {peak:?} {end:?}"
        );
        // ... and dilates (ε_v grows past its minimum, to expansion) ...
        assert!(end.vol > min_vol + 1e-3 && end.vol > 0.0, "{end:?}");
        // ... to the critical state line, where the volume stops changing.
        assert!(err.abs() < CSL_REL, "{eta}");
        assert!(rate < VOL_RATE_END, "{rate}");
    }

    #[test]
    fn constant_volume_loading_follows_the_undrained_path() {
        // ε_v = 0 (Δεxx = −Δεyy, plane strain) from isotropic NC p′0.
        // With v constant on the yield surface (derived here; the classical
        // undrained path of modified Cam-clay, e.g. Wood 1990, Soil
        // Behaviour and Critical State Soil Mechanics, CUP, on undrained
        // tests of Cam clay): v = N − λ ln p_c + κ ln(p_c/p′) = v0
        // = N − λ ln p′0 gives p_c^(λ−κ) p′^κ = p′0^λ, and f = 0 gives
        // p_c = p′ (1 + η²/M²), so
        //     p′ / p′0 = (M² / (M² + η²))^Λ, Λ = (λ − κ)/λ,
        // ending at the critical state p′_f = p′0 2^−Λ, q_f = M p′_f.
        let m = clay(2.0e5, 1.0);
        let (mut s, mut q) = m.initial_state();
        let big_l = (m.lambda - m.kappa) / m.lambda;
        let m2 = m.m_cs * m.m_cs;
        let mut worst: f64 = 0.0;
        for _ in 0..3000 {
            m.update([1.0, 0.0, 0.0, -1.0], 1e-4, &mut s, &mut q)
                .unwrap();
            let (p, qd) = p_q([s[0], s[1], q[SZZ], s[2]]);
            let eta = qd / p;
            let want = m.p0 * (m2 / (m2 + eta * eta)).powf(big_l);
            worst = worst.max((p - want).abs() / want);
            assert_eq!(q[VOLUME], m.v0, "constant volume");
        }
        let (p, qd) = p_q([s[0], s[1], q[SZZ], s[2]]);
        let pf = m.p0 * 0.5f64.powf(big_l);
        let (ep, eq) = ((p - pf) / pf, (qd - m.m_cs * pf) / (m.m_cs * pf));
        println!(
            "undrained: worst |p′ − p′(η)| / p′(η) = {worst:.2e}; end p′ {p:.1} vs {pf:.1} \
             ({ep:+.2e}), q {qd:.1} vs {:.1} ({eq:+.2e})",
            m.m_cs * pf
        );
        assert!(worst < UNDRAINED_REL, "{worst}");
        // Exact but for the return's tolerance (measured ≤ 1e-12).
        assert!(worst < 1e-9, "{worst}");
        assert!(ep.abs() < CSL_REL && eq.abs() < CSL_REL, "{ep} {eq}");
    }

    /// Golden inputs: (label, model, rotated stress [xx, yy, zz, xy] (Pa),
    /// strain increment [xx, yy, zz, xy], p_c (Pa), v).
    #[allow(clippy::type_complexity)]
    pub fn golden_inputs() -> Vec<(&'static str, ModifiedCamClay, [f64; 4], [f64; 4], f64, f64)> {
        let nc = clay(1.0e5, 1.0);
        let g = ModifiedCamClay::new(1800.0, 0.0, Some(5.0e6), 0.04, 0.2, 1.2, 2.5, 1.0e5, 1.5);
        vec![
            (
                "elastic",
                nc.clone(),
                [-1.0e5, -1.2e5, -1.1e5, 5.0e3],
                [1e-4, -2e-4, 0.0, 5e-5],
                1.5e5,
                1.6,
            ),
            (
                "wet",
                nc.clone(),
                [-1.0e5, -1.0e5, -1.0e5, 0.0],
                [2e-3, -4e-3, 0.0, 1e-3],
                1.0e5,
                nc.v0,
            ),
            (
                "dry",
                nc.clone(),
                [-1.0e4, -6.0e4, -2.0e4, 1.0e4],
                [2e-3, -4e-3, 0.0, 1e-3],
                9.0e4,
                1.6,
            ),
            (
                "const G",
                g.clone(),
                [-8.0e4, -1.2e5, -1.0e5, 1.0e4],
                [-1e-3, -2e-3, 0.0, 3e-3],
                1.5e5,
                g.v0,
            ),
            (
                "low p′",
                nc.clone(),
                [-1.0e3, -1.0e3, -1.0e3, 0.0],
                [0.1, 0.1, 0.0, 0.0],
                1.0e5,
                1.6,
            ),
            (
                "apex",
                nc.clone(),
                [0.0; 4],
                [1e-3, 1e-3, 0.0, 0.0],
                1.0e5,
                1.6,
            ),
            (
                "from zero",
                nc,
                [0.0; 4],
                [-1e-2, -2e-2, 0.0, 0.0],
                1.0e5,
                1.6,
            ),
        ]
    }

    /// Golden outputs agree to this fraction of max(|σ|, p_c): they are
    /// this code's own f64 results (printed by the test), kept to catch
    /// changes; the return's tolerance is 1e-11.
    const GOLDEN_REL: f64 = 1e-9;

    #[test]
    fn golden_values() {
        // `step` at fixed inputs: [xx, yy, zz, xy] (Pa), p_c (Pa), v,
        // return. tests/modified_cam_clay.rs runs the same inputs on the
        // WGSL twin.
        let want: [([f64; 4], f64, f64, u32); 7] = [
            (
                [
                    -99899.34271296914,
                    -121117.80425143069,
                    -110305.496559123,
                    5203.076923076923,
                ],
                150000.0,
                1.59984,
                0,
            ),
            (
                [
                    -91492.43420377927,
                    -110379.4366063249,
                    -97788.10167129447,
                    3147.8337337576068,
                ],
                102022.2347722528,
                1.5758080308767768,
                ACTIVE_MAIN,
            ),
            (
                [
                    -11688.143893875531,
                    -65033.69662325237,
                    -23191.77476490356,
                    10460.480464587203,
                ],
                89450.51761186124,
                1.5968,
                ACTIVE_MAIN,
            ),
            (
                [
                    -92248.40806103597,
                    -139817.56997342862,
                    -101762.2404435145,
                    38055.32952991412,
                ],
                150251.9411883046,
                1.5095492708685603,
                ACTIVE_MAIN,
            ),
            (
                [
                    590.9399446420591,
                    590.9399446420591,
                    -1725.7251869709712,
                    0.0,
                ],
                20740.656811132558,
                1.92,
                ACTIVE_MAIN,
            ),
            ([0.0; 4], 100000.0, 1.6032, ACTIVE_APEX),
            (
                [
                    -2.3201169227365472,
                    -2.6893476919673165,
                    -1.950886153505778,
                    0.0,
                ],
                100000.0,
                1.552,
                0,
            ),
        ];
        for ((label, m, s, de, pc, v), (ws, wpc, wv, wret)) in golden_inputs().into_iter().zip(want)
        {
            let (out, q) = m.step(s, de, &[s[2], pc, v, 0.0]).unwrap();
            println!("{label}: {out:?} {} {} {}", q[PC], q[VOLUME], q[RETURN]);
            let scale = out.iter().fold(q[PC], |a, x| a.max(x.abs()));
            for k in 0..4 {
                assert!(
                    (out[k] - ws[k]).abs() <= GOLDEN_REL * scale,
                    "{label}: {out:?}"
                );
            }
            assert!((q[PC] - wpc).abs() <= GOLDEN_REL * scale, "{label}: {q:?}");
            assert!((q[VOLUME] - wv).abs() <= 1e-12, "{label}: {q:?}");
            assert_eq!(q[RETURN], wret as f64, "{label}");
            assert_eq!(q[SZZ], out[2], "{label}");
            let (p, qd) = p_q(out);
            let f = m.yield_fn(p, qd, q[PC]) / (q[PC] * q[PC]);
            if wret == ACTIVE_MAIN {
                assert!(f.abs() < 1e-10, "{label}: on the ellipse, f/p_c² = {f:e}");
            } else {
                assert!(f <= 0.0, "{label}: inside, f/p_c² = {f:e}");
            }
        }
    }

    #[test]
    fn random_returns_land_on_the_ellipse_and_keep_the_invariant() {
        // States inside the ellipse (p′ in (0, p_c), q up to the surface),
        // random velocity gradients with steps up to 2 % strain: every
        // return converges, lands on f = 0, and v + κ ln p′ + (λ − κ) ln p_c
        // is kept (the exact volumetric integration).
        let mut seed = 4242u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let models = [
            clay(1.0e5, 1.0),
            ModifiedCamClay::new(1800.0, 0.25, Some(2.0e6), 0.02, 0.3, 0.9, 3.0, 1.0e5, 1.0),
        ];
        let (mut plastic, mut worst_f, mut worst_inv) = (0, 0.0f64, 0.0f64);
        for k in 0..20000 {
            let m = &models[k % 2];
            let pc = 1.0e4 + rnd() * 5.0e5;
            let p = pc * (0.02 + 0.96 * rnd());
            let q_max = m.m_cs * (p * (pc - p)).sqrt();
            // A deviator of norm q · (random fraction) in a random direction.
            let d = [rnd() - 0.5, rnd() - 0.5, rnd() - 0.5, rnd() - 0.5];
            let dm = (d[0] + d[1] + d[2]) / 3.0;
            let dev = [d[0] - dm, d[1] - dm, d[2] - dm, d[3]];
            let (_, qd) = p_q(dev);
            let sc = q_max * rnd() / qd;
            let s4 = [
                sc * dev[0] - p,
                sc * dev[1] - p,
                sc * dev[2] - p,
                sc * dev[3],
            ];
            let v = 1.3 + rnd();
            let mut q = [s4[2], pc, v, 0.0];
            let mut st = [s4[0], s4[1], s4[3]];
            let dt = 0.02 * rnd();
            let l = [
                rnd() * 2.0 - 1.0,
                rnd() * 2.0 - 1.0,
                rnd() * 2.0 - 1.0,
                rnd() * 2.0 - 1.0,
            ];
            let inv0 = v + m.kappa * p.ln() + (m.lambda - m.kappa) * pc.ln();
            m.update(l, dt, &mut st, &mut q).unwrap();
            let (p1, q1) = p_q([st[0], st[1], q[SZZ], st[2]]);
            let f = m.yield_fn(p1, q1, q[PC]) / (q[PC] * q[PC]);
            assert!(f <= 1e-10, "case {k}: f/p_c² = {f:e}");
            if q[RETURN] == ACTIVE_MAIN as f64 {
                plastic += 1;
                worst_f = worst_f.max(f.abs());
                let inv1 = q[VOLUME] + m.kappa * p1.ln() + (m.lambda - m.kappa) * q[PC].ln();
                worst_inv = worst_inv.max((inv1 - inv0).abs());
            }
        }
        println!(
            "20000 random steps, {plastic} plastic: worst |f|/p_c² {worst_f:.1e}, \
             worst drift of v + κ ln p′ + (λ−κ) ln p_c {worst_inv:.1e}"
        );
        assert!(plastic > 5000, "{plastic}");
        assert!(worst_f < 1e-10 && worst_inv < 1e-9, "{worst_f} {worst_inv}");
    }

    #[test]
    fn wave_speed_bounds_the_stiffness_along_the_paths() {
        // The bound from the density alone holds at every state of the
        // drained tests (K and G at the state, ρ = ρ0 v0 / v).
        for (m, reach) in [(clay(1.0e5, 1.0), 0.99), (clay(2.0e4, 10.0), 0.8)] {
            let (mut s, mut q) = m.initial_state();
            let mut tight: f64 = 0.0;
            for k in 0..2000 {
                let l = if k < 1000 {
                    [0.3, 0.0, 0.0, -1.0]
                } else {
                    [0.5, 0.2, 0.0, -1.0]
                };
                m.update(l, 5e-4, &mut s, &mut q).unwrap();
                let (p, _) = p_q([s[0], s[1], q[SZZ], s[2]]);
                let k_bulk = m.bulk(p, q[VOLUME]);
                let rho = m.density * m.v0 / q[VOLUME];
                let c = ((k_bulk + 4.0 / 3.0 * m.shear_at(k_bulk)) / rho).sqrt();
                let bound = m.wave_speed(rho);
                assert!(c <= bound * (1.0 + 1e-12), "{c} > {bound}");
                tight = tight.max(c / bound);
            }
            println!("wave speed: state / bound up to {tight:.4}");
            // On the NCL (the NC sample) the bound is reached; it is not loose elsewhere.
            assert!(tight > reach, "{tight}");
        }
    }

    #[test]
    fn large_steps_converge() {
        // Random states inside the ellipse and velocity gradients with
        // steps up to `emax` strain: the plain return (`step_once`)
        // converges for all up to 20 %; `step` (split when needed) for all
        // up to 50 % (save volumes that would vanish, J ≤ 0).
        let mut seed = 99u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let m = clay(1.0e5, 1.0);
        for (emax, split) in [(0.2, false), (0.5, true)] {
            let (mut runs, mut worst_f) = (0, 0.0f64);
            for _ in 0..20000 {
                let pc = 1.0e5;
                let p = pc * (0.01 + 0.98 * rnd());
                let qm = m.m_cs * (p * (pc - p)).sqrt() * rnd();
                let r = qm / 3f64.sqrt();
                let s = [-p - r, -p + r, -p, 0.0];
                let q = [s[2], pc, 1.6, 0.0];
                let dt = emax * rnd();
                let l = [
                    rnd() * 2.0 - 1.0,
                    rnd() * 2.0 - 1.0,
                    rnd() * 2.0 - 1.0,
                    rnd() * 2.0 - 1.0,
                ];
                if plastic::volume_ratio(l, dt).is_err() {
                    continue;
                }
                let de = [dt * l[0], dt * l[3], 0.0, 0.5 * dt * (l[1] + l[2])];
                let (out, q1) = if split {
                    m.step(s, de, &q)
                } else {
                    m.step_once(s, de, &q)
                }
                .unwrap_or_else(|e| panic!("{s:?} {de:?}: {e:?}"));
                let (p1, qd) = p_q(out);
                worst_f = worst_f.max(m.yield_fn(p1, qd, q1[PC]) / (q1[PC] * q1[PC]));
                assert!((q1[VOLUME] - 1.6 * (1.0 + de[0] + de[1])).abs() < 1e-12);
                runs += 1;
            }
            println!("steps up to {emax}: {runs} converged, worst f/p_c² {worst_f:.1e}");
            assert!(worst_f < 1e-10, "{worst_f}");
        }
    }

    #[test]
    fn keys_energy_and_faults() {
        // e0 instead of N gives the same model.
        let m = clay(1.0e5, 2.0);
        let keys = CamClayKeys {
            density: 1800.0,
            nu: Some(0.3),
            kappa: 0.04,
            lambda: 0.2,
            friction_angle: Some(30.0),
            e0: Some(m.v0 - 1.0),
            p0: 1.0e5,
            ocr: Some(2.0),
            ..Default::default()
        };
        let k = ModifiedCamClay::from_keys(&keys).unwrap();
        assert!(
            (k.n_ncl - 2.5).abs() < 1e-12 && (k.m_cs - 1.2).abs() < 1e-12,
            "{k:?}"
        );
        let bad = |f: fn(&mut CamClayKeys)| {
            let mut k = keys.clone();
            f(&mut k);
            ModifiedCamClay::from_keys(&k).unwrap_err().0
        };
        assert_eq!(bad(|k| k.lambda = 0.03), "lambda");
        assert_eq!(bad(|k| k.ocr = Some(0.5)), "ocr");
        assert_eq!(bad(|k| k.shear = Some(1e6)), "nu");
        assert_eq!(bad(|k| k.m = Some(1.0)), "M");
        assert_eq!(bad(|k| k.n = Some(2.0)), "N");
        assert_eq!(bad(|k| k.e0 = Some(-0.5)), "e0");
        assert_eq!(bad(|k| k.p0 = 0.0), "p0");
        // Energy: ½ σ : C⁻¹ : σ with K = v p′/κ and G from ν.
        let (s, q) = ([-1.2e5, -0.8e5, 2.0e4], [-1.0e5, 2.0e5, 1.7, 0.0]);
        let (kb, g) = (1.7 * 1.0e5 / 0.04, 1.5 * 1.7 * 1.0e5 / 0.04 * 0.4 / 1.3);
        let want =
            (2.0e4f64.powi(2) * 2.0 + 2.0 * 2.0e4f64.powi(2)) / (4.0 * g) + 1.0e10 / (2.0 * kb);
        assert!(
            (m.energy(&s, &q) - want).abs() < 1e-12 * want,
            "{} vs {want}",
            m.energy(&s, &q)
        );
        let (lame, g0) = m.moduli(1.0e5, 1.7);
        assert!((lame + 2.0 * g0 - (kb + 4.0 / 3.0 * g)).abs() < 1e-6 && (g0 - g).abs() < 1e-6);
        // Faults, not NaN: a non-finite strain, a vanishing volume.
        let (mut s, mut q) = m.initial_state();
        let e = m.update([f64::NAN, 0.0, 0.0, 0.0], 1e-3, &mut s, &mut q);
        assert_eq!(e, Err(FaultKind::NonFinite { field: "strain" }));
        let e = m.update([0.0, f64::INFINITY, 0.0, 0.0], 1e-3, &mut s, &mut q);
        assert_eq!(e, Err(FaultKind::NonFinite { field: "stress" }));
        let e = m.update([-2000.0, 0.0, 0.0, 0.0], 1e-3, &mut s, &mut q);
        assert_eq!(e, Err(FaultKind::NonPositiveDensity));
    }
}
