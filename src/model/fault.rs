//! Why a run went unstable, and which particle showed it first. A fault is
//! a result of the run (status `unstable`), never a panic.

use crate::model::shape::ShapeFault;

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FaultKind {
    /// The shape function could not be evaluated (left the grid, LME Newton failed).
    Shape(ShapeFault),
    /// A field became NaN or infinite.
    NonFinite { field: &'static str },
    /// 1 + tr(Δε) ≤ 0: the particle's volume would vanish or turn negative.
    NonPositiveDensity,
    /// Kinetic + strain energy grew past `ENERGY_RUNAWAY` times the energy the
    /// run could have received (initial energy plus a bound on the work of gravity).
    EnergyRunaway { ratio: f64 },
    /// MLS: the moment matrix at a Gauss point (m) is singular, fewer than
    /// three non-collinear particles within its 3h support.
    MlsSingular { at: [f64; 2] },
    /// Implicit: Newton did not converge within `solver.newton_max_iter`
    /// iterations even after `cuts` halvings of Δt; `ratio` is the last
    /// residual norm over the step's reference norm, NaN when the last
    /// attempt stopped at a particle that faulted at an iterate, whose
    /// fault's code `iterate` then names (`Fault::particle` the particle).
    NewtonDiverged {
        cuts: u32,
        ratio: f64,
        iterate: Option<&'static str>,
    },
    /// A fault its material model declares (`Constitutive::FAULTS`), e.g.
    /// modified Cam-clay's stress return that did not converge; `value` is
    /// the figure the model reports with it (NaN when the GPU found it: the
    /// shaders report the code alone).
    Material { fault: MaterialFault, value: f64 },
}

/// A fault a material model can report, declared in the model's own file
/// (`Constitutive::FAULTS`) so no other file names it: the CPU returns
/// `FaultKind::Material`, the GPU reports code `GPU_FAULT_BASE + i` for the
/// model's i-th fault (the WGSL constant `<NAME>_FAULT_<CODE>` is generated
/// by `material::registry::wgsl`) and `gpu::GpuBackend` decodes it through
/// the faulting particle's material.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MaterialFault {
    /// Machine-friendly reason in `summary.json` (snake_case; also the
    /// suffix of the WGSL constant).
    pub code: &'static str,
    /// What happened, as a sentence fragment ("the material's stress return
    /// did not converge").
    pub what: &'static str,
    /// Name of the figure reported beside it ("scaled residual"), or "".
    pub value: &'static str,
    /// What the user can do about it, or "".
    pub advice: &'static str,
}

/// The first problem a step found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fault {
    /// Particle index (`id` in particles.csv), when one particle is to blame.
    pub particle: Option<usize>,
    pub kind: FaultKind,
}

impl Fault {
    pub fn at(particle: usize, kind: FaultKind) -> Self {
        Fault {
            particle: Some(particle),
            kind,
        }
    }

    /// Keeps the fault of the lowest particle index, so parallel stages
    /// report the same particle every run.
    pub fn first(a: Option<Fault>, b: Option<Fault>) -> Option<Fault> {
        match (a, b) {
            (Some(x), Some(y)) => Some(if y.particle < x.particle { y } else { x }),
            (x, None) => x,
            (None, y) => y,
        }
    }

    /// `first` for a loop's running fault: `*acc` changes only when `f`
    /// holds one, so the hot path (no fault) moves nothing (an
    /// `Option<Fault>` is tens of bytes, copied per particle otherwise).
    #[inline(always)]
    pub fn note(acc: &mut Option<Fault>, f: Option<Fault>) {
        if f.is_some() {
            Self::note_cold(acc, f);
        }
    }

    #[cold]
    #[inline(never)]
    fn note_cold(acc: &mut Option<Fault>, f: Option<Fault>) {
        *acc = Self::first(acc.take(), f);
    }

    /// Short machine-friendly reason for `summary.json`.
    pub fn code(&self) -> &'static str {
        match self.kind {
            FaultKind::Shape(ShapeFault::OutsideGrid) => "left_grid",
            FaultKind::Shape(ShapeFault::MlsSingular { .. }) => "mls_singular",
            FaultKind::Shape(_) => "lme_newton",
            FaultKind::NonFinite { .. } => "non_finite",
            FaultKind::NonPositiveDensity => "non_positive_density",
            FaultKind::EnergyRunaway { .. } => "energy_runaway",
            FaultKind::MlsSingular { .. } => "mls_singular",
            FaultKind::NewtonDiverged { .. } => "newton_diverged",
            FaultKind::Material { fault, .. } => fault.code,
        }
    }
}

impl std::fmt::Display for Fault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.kind {
            FaultKind::Shape(s) => write!(f, "{s}")?,
            FaultKind::NonFinite { field } => write!(f, "{field} became NaN or infinite")?,
            FaultKind::NonPositiveDensity => {
                write!(f, "density would become non-positive (1 + tr Δε ≤ 0)")?
            }
            FaultKind::EnergyRunaway { ratio } => write!(
                f,
                "energy runaway: kinetic + strain energy is {ratio:.1} times what the loads could supply"
            )?,
            FaultKind::MlsSingular { at } => write!(
                f,
                "MLS reconstruction singular at the Gauss point ({:.4}, {:.4}) m: fewer than 3 non-collinear particles within 3h",
                at[0], at[1]
            )?,
            FaultKind::NewtonDiverged {
                cuts,
                iterate: Some(code),
                ..
            } => write!(
                f,
                "Newton did not converge: after {cuts} halvings of the time step an iterate still \
                 faulted at a particle ({code}), at every Δt tried"
            )?,
            FaultKind::NewtonDiverged {
                cuts,
                ratio,
                iterate: None,
            } => write!(
                f,
                "Newton did not converge (residual {ratio:.3e} of the step's reference) after {cuts} \
                 halvings of the time step: lower solver.cfl / solver.dt, raise solver.load_steps or \
                 solver.newton_max_iter"
            )?,
            FaultKind::Material { fault, value } => {
                write!(f, "{}", fault.what)?;
                if !fault.value.is_empty() && value.is_finite() {
                    write!(f, " ({} {value:.3e})", fault.value)?;
                }
                if !fault.advice.is_empty() {
                    write!(f, ": {}", fault.advice)?;
                }
            }
        }
        if let Some(p) = self.particle {
            write!(f, " (particle {p})")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Newton's failure says whether it stopped at a faulting particle
    /// (and which, with the fault's code) or on its residual.
    #[test]
    fn newton_failures_say_what_stopped_them() {
        let at = Fault {
            particle: Some(157),
            kind: FaultKind::NewtonDiverged {
                cuts: 6,
                ratio: f64::NAN,
                iterate: Some("non_positive_density"),
            },
        };
        let text = at.to_string();
        assert!(text.contains("non_positive_density"), "{text}");
        assert!(text.contains("particle 157"), "{text}");
        assert!(!text.contains("NaN"), "{text}");
        assert_eq!(at.code(), "newton_diverged");
        let residual = Fault {
            particle: None,
            kind: FaultKind::NewtonDiverged {
                cuts: 6,
                ratio: 3.5,
                iterate: None,
            },
        };
        let text = residual.to_string();
        assert!(text.contains("residual 3.500e0"), "{text}");
        assert!(!text.contains("particle"), "{text}");
    }
}
