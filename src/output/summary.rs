//! `summary.json`: how the run ended, how fast it ran, and its error against
//! the exact solution when the scene has one. Fields are documented in
//! docs/outputs.md.

use crate::exact::Errors;
use crate::scene::{
    BsplineKnots, ExactKind, IntegratorKind, MlsScope, NpcPosition, SceneFile, ShapeKind,
};
use serde::Serialize;
use std::collections::BTreeMap;

#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// `completed`, `unstable` or `interrupted` (while running: a short
    /// summary with `running`; after an error: `failed`).
    pub status: &'static str,
    /// Why the run stopped early (unstable only).
    pub reason: Option<String>,
    /// Machine-friendly reason: left_grid, lme_newton, non_finite, non_positive_density, energy_runaway, mls_singular.
    pub reason_code: Option<&'static str>,
    /// Particle that showed the fault first, if one did.
    pub unstable_particle: Option<usize>,
    pub scene: String,
    /// Time reached (s).
    pub t: f64,
    pub t_end: f64,
    /// The checkpoint time this run was resumed from (s); null for a fresh run.
    pub resumed_from: Option<f64>,
    pub steps: u64,
    pub particles: usize,
    pub nodes: usize,
    /// Wall time spent stepping (s), outputs excluded.
    pub wall_seconds: f64,
    /// Wall time of the whole run, setup and outputs included (s).
    pub wall_seconds_total: f64,
    /// particles × steps / wall_seconds.
    pub particle_steps_per_second: f64,
    pub backend: String,
    pub bytes_per_particle: f64,
    pub shape: ShapeKind,
    pub lme_gamma: Option<f64>,
    /// MLS reconstruction at Gauss points.
    pub mls: bool,
    /// What the fit did (`solver.mls_scope`); null without MLS.
    pub mls_scope: Option<MlsScope>,
    /// Where the B-splines' knots sat (`solver.bspline_knots`); null for
    /// other shapes.
    pub bspline_knots: Option<BsplineKnots>,
    pub integrator: IntegratorKind,
    pub npc_gamma: Option<f64>,
    pub npc_position: Option<NpcPosition>,
    pub cfl: f64,
    /// Fixed time step (s); null when Δt comes from the CFL condition.
    pub dt: Option<f64>,
    /// Grid spacing (m).
    pub h: f64,
    pub perturb: f64,
    /// Final kinetic and strain energy (J per metre of thickness).
    pub energy: BTreeMap<&'static str, f64>,
    /// Final reaction per constraint (N per metre of thickness).
    pub reactions: BTreeMap<String, [f64; 2]>,
    pub exact: Option<ExactKind>,
    /// Error figures against the exact solution (when `exact` is set).
    pub errors: Option<Errors>,
    /// The scene as run (overrides applied, defaults filled in).
    pub scene_resolved: SceneFile,
    pub version: &'static str,
    /// Peak resident memory the preflight estimated for the run (bytes).
    pub memory_estimate_bytes: u64,
    /// Peak resident memory of the process when the summary was written
    /// (VmHWM, bytes); null where the OS does not report it.
    pub peak_rss_bytes: Option<u64>,
    /// The implicit integrator's Newton iterations (null for the explicit ones).
    pub newton: Option<NewtonSummary>,
}

/// Newton iterations of an implicit run.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct NewtonSummary {
    /// Converged steps over the whole run (a resumed run included).
    pub steps: u64,
    /// Iterations per step: mean and most.
    pub iterations_mean: f64,
    pub iterations_max: u32,
    /// Halvings of Δt (steps retried after Newton failed).
    pub cuts: u64,
    /// Jacobians assembled and factored over the run (one per iteration
    /// with full Newton; fewer with `solver.newton_jacobian = "reuse"`).
    pub factorizations: u64,
    /// The last step's residual norms over its reference, one per iterate
    /// (the first is the predictor's): quadratic convergence squares them.
    pub last_step_residuals: Vec<f64>,
    /// The last step's correction norms |δ| / |Δu|, one per iteration.
    pub last_step_corrections: Vec<f64>,
    /// Wall time of the step's parts over the run (s): `map`, `symbolic`,
    /// `residual`, `jacobian`, `factor` (numeric LU), `solve`, `convect`.
    pub seconds: crate::backend::NewtonSeconds,
}

impl NewtonSummary {
    pub fn from_stats(s: &crate::backend::NewtonStats) -> Self {
        NewtonSummary {
            steps: s.steps,
            iterations_mean: s.mean_iterations(),
            iterations_max: s.max_iterations,
            cuts: s.cuts,
            factorizations: s.factorizations,
            last_step_residuals: s.last_residuals.clone(),
            last_step_corrections: s.last_corrections.clone(),
            seconds: s.seconds,
        }
    }
}
