//! The stress update the implicit step asks of a material: the stress at
//! the end of a step from the incremental deformation gradient ΔF (relative
//! to the step's start configuration, [xx, xy, yx, yy]) and the state at
//! the step's start, with its derivative dσ/dΔF. Newton's quadratic
//! convergence rests on that derivative being the exact one of the update.
//!
//! - Linear elastic: σ = σ0 + D : sym(ΔF − I) (the explicit update's
//!   increment with Δt L = ΔF − I); dσ/dΔF is D on the symmetric part.
//! - Neo-Hookean: F = ΔF F0, σ = σ(F); dσ/dΔF from ∂σ/∂F (analytic, below).
//! - Every other model (Mohr–Coulomb, Drucker–Prager, …): its explicit update (Jaumann trial and
//!   return) with Δt L = ΔF − I; dσ/dΔF is the central difference of that
//!   update (`FD_STEP`), the algorithmic tangent of the return as coded,
//!   including which surfaces are active. An analytic one (de Souza Neto box
//!   8.4) would be cheaper; the difference is cost, not convergence.

use super::{DefGrad, Material, PlasticState};
use crate::model::fault::FaultKind;

/// dσ/dΔF: row = [σxx, σyy, σxy], column = ΔF component [xx, xy, yx, yy].
pub type StressTangent = [[f64; 4]; 3];

/// ΔF perturbation of the plastic models' finite-difference tangent: the
/// central difference's truncation error (~ε² σ''') and round-off
/// (~1e-16 σ / ε) balance near ε = 1e-5 for stresses of order E · 1e-3.
pub const FD_STEP: f64 = 1e-6;

/// The state a particle carries across a step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepState {
    /// Cauchy stress [xx, yy, xy] (Pa).
    pub stress: [f64; 3],
    /// Deformation gradient (Neo-Hookean; identity otherwise).
    pub f: DefGrad,
    /// Plastic state (plastic models; zeros otherwise).
    pub q: PlasticState,
}

impl Material {
    /// The state at the end of a step with incremental deformation
    /// gradient `df`, from `start`. Fails where det ΔF ≤ 0 or the
    /// material's own update fails.
    pub fn increment(&self, df: &[f64; 4], start: &StepState) -> Result<StepState, FaultKind> {
        let j = df[0] * df[3] - df[1] * df[2];
        if j.is_nan() {
            return Err(FaultKind::NonFinite {
                field: "deformation gradient",
            });
        }
        if j <= 0.0 {
            return Err(FaultKind::NonPositiveDensity);
        }
        let mut out = *start;
        match self {
            Material::LinearElastic(m) => {
                let de = [df[0] - 1.0, df[3] - 1.0, 0.5 * (df[1] + df[2])];
                m.update_stress(&mut out.stress, de);
            }
            Material::NeoHookean(m) => {
                out.f = mul(df, &start.f);
                out.stress = m.cauchy(&out.f).ok_or(FaultKind::NonPositiveDensity)?;
            }
            // Every other model: its explicit update with Δt L = ΔF − I.
            _ => {
                let l = [df[0] - 1.0, df[1], df[2], df[3] - 1.0];
                self.update(l, 1.0, &mut out.stress, &mut out.f, &mut out.q)?;
            }
        }
        Ok(out)
    }

    /// dσ/dΔF of `increment` at `df`.
    pub fn increment_tangent(
        &self,
        df: &[f64; 4],
        start: &StepState,
    ) -> Result<StressTangent, FaultKind> {
        match self {
            Material::LinearElastic(m) => {
                let (l, g) = (m.lame, m.shear);
                Ok([
                    [l + 2.0 * g, 0.0, 0.0, l],
                    [l, 0.0, 0.0, l + 2.0 * g],
                    [0.0, g, g, 0.0],
                ])
            }
            Material::NeoHookean(m) => {
                let f = mul(df, &start.f);
                let dsdf = neo_hookean_dsigma_df(m.lame, m.shear, &f)?;
                // dF_ab/dΔF_kl = δ_ak F0_lb.
                let f0 = &start.f;
                let mut t = [[0.0; 4]; 3];
                for (row, d) in t.iter_mut().zip(&dsdf) {
                    for k in 0..2 {
                        for l in 0..2 {
                            row[2 * k + l] = (0..2).map(|b| d[2 * k + b] * f0[2 * l + b]).sum();
                        }
                    }
                }
                Ok(t)
            }
            // Every other model: the central difference of its update.
            _ => {
                let mut t = [[0.0; 4]; 3];
                for c in 0..4 {
                    let (mut a, mut b) = (*df, *df);
                    a[c] += FD_STEP;
                    b[c] -= FD_STEP;
                    let sa = self.increment(&a, start)?.stress;
                    let sb = self.increment(&b, start)?.stress;
                    for r in 0..3 {
                        t[r][c] = (sa[r] - sb[r]) / (2.0 * FD_STEP);
                    }
                }
                Ok(t)
            }
        }
    }
}

/// A B for 2 × 2 matrices stored [xx, xy, yx, yy].
#[inline]
pub fn mul(a: &[f64; 4], b: &[f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] + a[1] * b[2],
        a[0] * b[1] + a[1] * b[3],
        a[2] * b[0] + a[3] * b[2],
        a[2] * b[1] + a[3] * b[3],
    ]
}

/// ∂σ_ij/∂F_ab of σ = λ ln J / J I + μ / J (F Fᵀ − I):
///   λ (1 − ln J)/J F⁻ᵀ_ab δ_ij − μ/J F⁻ᵀ_ab (b_ij − δ_ij) + μ/J (δ_ia F_jb + F_ib δ_ja).
fn neo_hookean_dsigma_df(lame: f64, mu: f64, f: &DefGrad) -> Result<StressTangent, FaultKind> {
    let j = f[0] * f[3] - f[1] * f[2];
    if j.is_nan() || j <= 0.0 {
        return Err(FaultKind::NonPositiveDensity);
    }
    // F⁻ᵀ_ab = (F⁻¹)_ba.
    let finv_t = [f[3] / j, -f[2] / j, -f[1] / j, f[0] / j];
    let b = [
        f[0] * f[0] + f[1] * f[1],
        f[0] * f[2] + f[1] * f[3],
        f[0] * f[2] + f[1] * f[3],
        f[2] * f[2] + f[3] * f[3],
    ];
    let vol = lame * (1.0 - j.ln()) / j;
    let s = mu / j;
    let delta = |i: usize, k: usize| if i == k { 1.0 } else { 0.0 };
    // σ rows as (i, j): xx, yy, xy.
    let comps = [(0, 0), (1, 1), (0, 1)];
    let mut t = [[0.0; 4]; 3];
    for (row, &(i, jj)) in t.iter_mut().zip(&comps) {
        for a in 0..2 {
            for bb in 0..2 {
                let ab = 2 * a + bb;
                row[ab] = vol * finv_t[ab] * delta(i, jj)
                    - s * finv_t[ab] * (b[2 * i + jj] - delta(i, jj))
                    + s * (delta(i, a) * f[2 * jj + bb] + f[2 * i + bb] * delta(jj, a));
            }
        }
    }
    Ok(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::MaterialSpec;

    /// Analytic tangents match the central difference of `increment` to
    /// this relative error (issue 12's bound).
    const TANGENT_REL: f64 = 1e-6;

    fn material(model: &str) -> Material {
        let mut spec = MaterialSpec::new(model, 1800.0)
            .with("E", 2.0e7)
            .with("nu", 0.3);
        if !model.contains("elastic") && model != "neo_hookean" {
            spec = spec
                .with("cohesion", 1.0e4)
                .with("friction_angle", 30.0)
                .with("dilation_angle", 10.0);
        }
        Material::from_spec("m", &spec).unwrap()
    }

    /// Largest |analytic − FD| over the largest |entry|.
    fn fd_mismatch(m: &Material, df: &[f64; 4], start: &StepState, eps: f64) -> f64 {
        let t = m.increment_tangent(df, start).unwrap();
        let scale = t.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
        let mut worst = 0.0f64;
        for c in 0..4 {
            let (mut a, mut b) = (*df, *df);
            a[c] += eps;
            b[c] -= eps;
            let sa = m.increment(&a, start).unwrap().stress;
            let sb = m.increment(&b, start).unwrap().stress;
            for r in 0..3 {
                let fd = (sa[r] - sb[r]) / (2.0 * eps);
                worst = worst.max((fd - t[r][c]).abs() / scale);
            }
        }
        worst
    }

    #[test]
    fn elastic_tangents_are_the_derivative_of_the_update() {
        let df = [1.03, 0.04, -0.02, 0.96];
        let start = StepState {
            stress: [1e5, -2e5, 3e4],
            f: [1.1, 0.05, 0.02, 0.93],
            q: [0.0; 4],
        };
        for model in ["linear_elastic", "neo_hookean"] {
            let e = fd_mismatch(&material(model), &df, &start, 1e-6);
            println!("{model:?}: tangent vs central difference {e:.2e}");
            assert!(e < TANGENT_REL, "{model:?}: {e:e}");
        }
    }

    #[test]
    fn plastic_tangents_are_the_derivative_of_the_return() {
        // A state on the yield surface loaded further in shear: the return
        // is active, and the tangent (a central difference at FD_STEP) must
        // agree with one at a tenth of the step.
        for model in ["mohr_coulomb", "drucker_prager"] {
            let m = material(model);
            let mut start = StepState {
                stress: [-5e4, -5e4, 0.0],
                f: [1.0, 0.0, 0.0, 1.0],
                q: [-5e4, 0.0, 0.0, 0.0],
            };
            for _ in 0..40 {
                start = m.increment(&[1.0, 1e-3, 1e-3, 1.0], &start).unwrap();
            }
            let df = [1.0, 1e-3, 1e-3, 1.0];
            let yielded = m.increment(&df, &start).unwrap().q[1] > start.q[1];
            assert!(yielded, "{model:?}: the test state must yield");
            let e = fd_mismatch(&m, &df, &start, 0.1 * FD_STEP);
            println!("{model:?}: FD tangent vs finer FD {e:.2e}");
            assert!(e < 1e-4, "{model:?}: {e:e}");
        }
    }
}
