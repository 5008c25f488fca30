//! Column collapses, measured on the deposit: its run-out (the right edge
//! of the last column of width h, from x = 0, where the deposit is at
//! least one cell thick: a thin sheet of a few particles ahead does not
//! count, as in the experiments, where the run-out is the visible front)
//! and its height (the top of the highest particle).
//! - `column_collapse`: the cohesive column of the implicit-MPM paper
//!   §5.3 (2 m wide, 4 m high). The paper compares its results with the
//!   SPH of Bui et al. (2008) by pictures only, so the reference figures
//!   are `lme-mpm study column`'s at 2 s on the paper's two meshes
//!   (docs/verification.md, "Soil column collapse", 2026-11-29): the four
//!   explicit shapes' run-outs 4.85–5.06 m and heights 2.23–2.42 m, the
//!   paper's GMM (ours) 5.17–5.19 m and 2.05–2.23 m.
//! - `granular_collapse`: a cohesionless column W wide and H = a W high,
//!   against the experiments' run-out scaling (L_f − W)/W ≈ 1.2 a for
//!   a ≲ 3 (Lajeunesse et al. 2005; Lube et al. 2005).

use crate::model::Particles;
use crate::scene::Scene;
use serde::Serialize;

/// `study column`'s run-outs at 2 s, lowest and highest of the four
/// explicit shapes on both meshes (m).
pub const COLUMN_RUN_OUT: (f64, f64) = (4.85, 5.06);
/// Their heights at 2 s (m).
pub const COLUMN_HEIGHT: (f64, f64) = (2.23, 2.42);
/// The experiments' run-out scaling: (L_f − W)/W ≈ 1.2 a.
pub const RUN_OUT_SCALING: f64 = 1.2;

/// The furthest particle's reach (centre plus half a spacing), m.
pub fn front(p: &Particles, spacing: f64) -> f64 {
    p.x.iter().map(|x| x[0]).fold(f64::NEG_INFINITY, f64::max) + 0.5 * spacing
}

/// Run-out (m): see the module's note; `spacing` is the particles'.
pub fn run_out(p: &Particles, h: f64, spacing: f64) -> f64 {
    profile(p, h, spacing)
        .iter()
        .filter(|(_, y)| *y >= h)
        .map(|(x, _)| x + 0.5 * h)
        .fold(0.0, f64::max)
        .min(front(p, spacing))
}

/// Height: the largest y of the material, m.
pub fn height(p: &Particles, spacing: f64) -> f64 {
    p.x.iter().map(|x| x[1]).fold(f64::NEG_INFINITY, f64::max) + 0.5 * spacing
}

/// Free-surface profile: per column of width h from x = 0, the top of the
/// highest particle in it (m); columns without particles end the profile
/// at the run-out.
pub fn profile(p: &Particles, h: f64, spacing: f64) -> Vec<(f64, f64)> {
    let reach = front(p, spacing);
    let n = (reach / h).ceil().max(1.0) as usize;
    let mut top = vec![f64::NEG_INFINITY; n];
    for x in &p.x {
        let k = ((x[0] / h).floor().max(0.0) as usize).min(n - 1);
        top[k] = top[k].max(x[1] + 0.5 * spacing);
    }
    let mut pts: Vec<(f64, f64)> = top
        .iter()
        .enumerate()
        .filter(|(_, y)| y.is_finite())
        .map(|(k, y)| ((k as f64 + 0.5) * h, *y))
        .collect();
    pts.insert(0, (0.0, pts.first().map_or(0.0, |p| p.1)));
    pts.push((reach, 0.0));
    pts
}

/// The column's rectangle, its cell size and its particles' spacing.
pub fn geometry(scene: &Scene) -> ([f64; 4], f64, f64) {
    let (_, body) = scene.bodies().next().expect("validated: one body");
    let h = scene.file.grid.h;
    (
        crate::scene::seed::body_bbox(body),
        h,
        h / body.ppc.max(1) as f64,
    )
}

/// Figures for `summary.json` (`column_collapse`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ColumnCollapseErrors {
    /// Run-out and height at the end (m).
    pub run_out: f64,
    pub height: f64,
    /// `study column`'s ranges at 2 s (m).
    pub run_out_reference_low: f64,
    pub run_out_reference_high: f64,
    pub height_reference_low: f64,
    pub height_reference_high: f64,
    /// How far outside the ranges (0 inside), over the nearer bound.
    pub run_out_rel_error: f64,
    pub height_rel_error: f64,
}

fn outside(v: f64, (lo, hi): (f64, f64)) -> f64 {
    if v < lo {
        (v - lo) / lo
    } else if v > hi {
        (v - hi) / hi
    } else {
        0.0
    }
}

pub fn score_column(scene: &Scene, p: &Particles) -> ColumnCollapseErrors {
    let (_, h, spacing) = geometry(scene);
    let (r, y) = (run_out(p, h, spacing), height(p, spacing));
    ColumnCollapseErrors {
        run_out: r,
        height: y,
        run_out_reference_low: COLUMN_RUN_OUT.0,
        run_out_reference_high: COLUMN_RUN_OUT.1,
        height_reference_low: COLUMN_HEIGHT.0,
        height_reference_high: COLUMN_HEIGHT.1,
        run_out_rel_error: outside(r, COLUMN_RUN_OUT),
        height_rel_error: outside(y, COLUMN_HEIGHT),
    }
}

/// Figures for `summary.json` (`granular_collapse`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct GranularCollapseErrors {
    /// The column's width W and aspect ratio a = H/W.
    pub width: f64,
    pub aspect: f64,
    /// Run-out L_f (m, from the back wall at x = xmin) and height (m).
    pub run_out: f64,
    pub height: f64,
    /// (L_f − W)/W.
    pub run_out_ratio: f64,
    /// 1.2 a.
    pub run_out_ratio_reference: f64,
    /// run_out_ratio / (1.2 a) − 1.
    pub run_out_rel_error: f64,
}

pub fn score_granular(scene: &Scene, p: &Particles) -> GranularCollapseErrors {
    let (bb, h, spacing) = geometry(scene);
    let (w, a) = (bb[2] - bb[0], (bb[3] - bb[1]) / (bb[2] - bb[0]));
    let r = run_out(p, h, spacing) - bb[0];
    let ratio = (r - w) / w;
    let reference = RUN_OUT_SCALING * a;
    GranularCollapseErrors {
        width: w,
        aspect: a,
        run_out: r,
        height: height(p, spacing) - bb[1],
        run_out_ratio: ratio,
        run_out_ratio_reference: reference,
        run_out_rel_error: ratio / reference - 1.0,
    }
}
