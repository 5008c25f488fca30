//! What a run's result means, for a reader: one sentence with its
//! reference (printed at the end of `run` and `resume`), and `result.png`
//! in the output folder: the probe histories against the exact solution
//! where the scene has one (else the energy history), beside the final
//! particles coloured by their displacement (or plastic strain).

use crate::backend::Sample;
use crate::chart::{LineChart, Panel, ParticleImage, Series};
use crate::error::{Error, Result};
use crate::exact::Errors;
use crate::model::Model;
use crate::model::material::StateColumn;
use crate::output::summary::Summary;
use crate::scene::{ExactKind, Scene};
use plotters::prelude::*;

/// The picture's file name in the output folder.
pub const FILE: &str = "result.png";

/// Pixels of `result.png`: the history on the left, the particles right.
const SIZE: (u32, u32) = (1300, 520);
const HISTORY_WIDTH: u32 = 720;

/// Where docs/methods.md explains why MLS errs more than plain B-splines
/// on the aligned vibration (the failure the README's MLS example shows).
pub const MLS_FAILURE_DOC: &str =
    "docs/methods.md, \"Why MLS is less accurate than plain B-splines on the vibration\"";

fn pct(x: f64) -> String {
    format!("{} %", num(100.0 * x))
}

/// Three significant digits, plain between 0.001 and 9999.
fn num(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let e = v.abs().log10().floor() as i32;
    if (-3..4).contains(&e) {
        let decimals = (2 - e).max(0) as usize;
        format!("{v:.decimals$}")
    } else {
        format!("{v:.2e}")
    }
}

/// The result in words with its reference, or None when the run has no
/// error figures (no exact solution, or it did not complete).
pub fn text(s: &Summary) -> Option<String> {
    if s.status != "completed" {
        return None;
    }
    let mls = if s.mls && s.mls_scope != Some(crate::scene::MlsScope::Force) {
        format!(
            " MLS on this case is the known failure: with the paper's weight it errs more \
             than plain B-splines at coarse grids and goes unstable over ten periods ({MLS_FAILURE_DOC})."
        )
    } else {
        String::new()
    };
    let line = match s.errors.as_ref()? {
        Errors::Dyka(e) => {
            let impact = if e.rms_velocity_relative > 0.0 {
                e.rms_velocity / e.rms_velocity_relative
            } else {
                0.0
            };
            format!(
                "RMS velocity error {} m/s = {} of the impact speed {} m/s (largest {} m/s); \
                 the paper's LME-NPC level, which LME γ = 4 with NPC at 1 mm cells meets in \
                 tests/benchmarks.rs, is below 0.55 m/s.",
                num(e.rms_velocity),
                pct(e.rms_velocity_relative),
                num(impact),
                num(e.max_velocity)
            )
        }
        Errors::Column(e) => format!(
            "top settlement {} m against {} m exact (logarithmic strain): {} off; σyy of the \
             bottom row {} off the exact ρ0 g H; the tests hold LME γ = 3 within 3 % and 5 %.",
            num(e.settlement_top),
            num(e.settlement_top_exact),
            pct(e.settlement_rel_error),
            pct(e.sigma_yy_bottom_rel_error)
        ),
        Errors::Sliding(e) if e.acceleration_exact > 0.0 => format!(
            "velocity along the wall {} m/s against {} m/s exact (a = g_t − μ g_n = {} m/s²): \
             {} off; the tests hold it within 2 % under ramped gravity (the cases' own) and \
             3.5 % under gravity applied at once, where the elastic block rings on its wall.",
            num(e.velocity),
            num(e.velocity_exact),
            num(e.acceleration_exact),
            pct(e.velocity_rel_error)
        ),
        Errors::Sliding(e) => format!(
            "the block should stay at rest (tan θ ≤ μ): its speed is {} of the frictionless \
             one ({} m/s along the wall).",
            pct(e.velocity_rel_error),
            num(e.velocity)
        ),
        Errors::Rolling(e) => format!(
            "centre displacement along x {} m against ½ a t² = {} m exact: {} off at t_end; \
             the paper's Table 1 gives 2.34 % for the error over the whole history (eq. 67), \
             which `lme-mpm study disk` computes.",
            num(e.u_x),
            num(e.u_x_exact),
            pct(e.u_x_rel_error)
        ),
        Errors::Cantilever(e) => match (e.deflection_reference, e.rel_error) {
            (Some(r), Some(rel)) => format!(
                "free-end deflection {} m against the paper's nonlinear {} m: {} off \
                 (Timoshenko's linear {} m: {} off).",
                num(e.deflection),
                num(r),
                pct(rel),
                num(e.deflection_timoshenko),
                pct(e.rel_error_timoshenko)
            ),
            _ => format!(
                "free-end deflection {} m against Timoshenko's linear {} m: {} off.",
                num(e.deflection),
                num(e.deflection_timoshenko),
                pct(e.rel_error_timoshenko)
            ),
        },
        Errors::ContactSliding(e) if e.acceleration_exact > 0.0 => format!(
            "slide on the slab {} m against g (sin θ − μ cos θ) t²/2 = {} m exact (a = {} m/s², \
             t² / 2 taken as ∫R over the gravity's ramp): {} off; relative velocity {} m/s against \
             {} m/s.",
            num(e.slide),
            num(e.slide_exact),
            num(e.acceleration_exact),
            pct(e.slide_rel_error),
            num(e.velocity),
            num(e.velocity_exact)
        ),
        Errors::ContactSliding(e) => format!(
            "the block should stay at rest on the slab (tan θ ≤ μ): it slid {} m, {} of the \
             frictionless slide.",
            num(e.slide),
            pct(e.slide_rel_error)
        ),
        Errors::ContactRolling(e) => format!(
            "the disk's centre rolled {} m against (2/3) g sin θ t²/2 = {} m exact: {} off \
             (slip at the contact {} m/s, 0 rolling without slip).",
            num(e.distance),
            num(e.distance_exact),
            pct(e.distance_rel_error),
            num(e.slip)
        ),
        Errors::DiskImpact(e) => format!(
            "momentum kept within {} of one disk's (exact: all of it); spin ω R {} / {} m/s \
             (exact 0: frictionless forces pass through the centres); velocity along the \
             contact tangent {} / {} m/s against {} / {} m/s at the start (kept by rigid disks); \
             separating at {} m/s after approaching at {} m/s.",
            pct(e.momentum_drift),
            num(e.spin_first),
            num(e.spin_second),
            num(e.tangential_first),
            num(e.tangential_second),
            num(e.tangential_first_start),
            num(e.tangential_second_start),
            num(e.separating),
            num(e.approaching)
        ),
        Errors::Footing(e) => format!(
            "peak bearing pressure q/c = {} at {} mm of settlement against Prandtl's 2 + π = {}: \
             {}{} (q/c {} at the end).",
            num(e.q_peak_over_c),
            num(1e3 * e.settlement_at_peak),
            num(e.q_exact_over_c),
            if e.q_rel_error >= 0.0 { "+" } else { "" },
            pct(e.q_rel_error),
            num(e.q_end_over_c)
        ),
        Errors::Terzaghi(e) => format!(
            "pore pressure at T_v = {} against Terzaghi's series: RMS {} of the undrained p_start; \
             degree of consolidation {} against {}; settlement {} mm against {} mm ({}{}).",
            num(e.time_factor),
            pct(e.pressure_rms),
            pct(e.consolidation),
            pct(e.consolidation_exact),
            num(1e3 * e.settlement),
            num(1e3 * e.settlement_exact),
            if e.settlement_rel_error >= 0.0 {
                "+"
            } else {
                ""
            },
            pct(e.settlement_rel_error)
        ),
        Errors::Mandel(e) => format!(
            "centre pore pressure at t c/a² = {}: {} p_start against Mandel's {} ({}{} of \
             p_start; the Mandel–Cryer rise peaks near 0.1); RMS over the specimen {} of p_start.",
            num(e.time_factor),
            num(e.centre),
            num(e.centre_exact),
            if e.centre_error >= 0.0 { "+" } else { "" },
            pct(e.centre_error),
            pct(e.pressure_rms)
        ),
        Errors::CriticalState(e) => format!(
            "stress ratio q/p′ = {} (p′ = {} kPa, q = {} kPa) at {} axial strain against the \
             critical state's M = {}: {} of the way; drained plane strain reaches q = M p′ only \
             near 100 % axial strain (docs/methods.md, \"Modified Cam-clay\").",
            num(e.stress_ratio),
            num(1e-3 * e.p),
            num(1e-3 * e.q),
            pct(e.axial_strain),
            num(e.m),
            pct(e.ratio_over_m)
        ),
        Errors::ColumnCollapse(e) => format!(
            "run-out {} m and height {} m at t = {} s against `lme-mpm study column`'s {}–{} m and \
             {}–{} m at 2 s (four shapes, the paper's two meshes; the paper compares with SPH by \
             pictures only): {}.",
            num(e.run_out),
            num(e.height),
            num(s.t),
            num(e.run_out_reference_low),
            num(e.run_out_reference_high),
            num(e.height_reference_low),
            num(e.height_reference_high),
            if e.run_out_rel_error == 0.0 && e.height_rel_error == 0.0 {
                "both inside".to_string()
            } else {
                format!(
                    "run-out {} and height {} outside",
                    pct(e.run_out_rel_error),
                    pct(e.height_rel_error)
                )
            }
        ),
        Errors::GranularCollapse(e) => format!(
            "run-out (L_f − W)/W = {} (L_f = {} m, height {} m) against the experiments' 1.2 a = {} \
             (a = {}; Lajeunesse et al. 2005): {}{} off, the acceptance is 25 %.",
            num(e.run_out_ratio),
            num(e.run_out),
            num(e.height),
            num(e.run_out_ratio_reference),
            num(e.aspect),
            if e.run_out_rel_error >= 0.0 { "+" } else { "" },
            pct(e.run_out_rel_error)
        ),
        Errors::Energy(e) => format!(
            "kinetic + strain energy {} J/m at the end, {} of the {} J/m at the start (nothing \
             does work: the rest went to the integrator's damping and the fixed nodes).",
            num(e.kinetic + e.strain),
            pct(e.kept),
            num(e.energy_start)
        ),
        Errors::Mms(e) => format!(
            "RMS error at t_end: displacement {}, velocity {}, stress {} of the exact field's \
             RMS (100 % = an error as large as the field); docs/verification.md gives every \
             method's figures by cell size (`lme-mpm study mms`).",
            pct(e.rms_displacement_relative),
            pct(e.rms_velocity_relative),
            pct(e.rms_stress_relative)
        ),
    };
    Some(line + &mls)
}

/// One probe history and its exact counterpart: (label, unit, numerical,
/// exact) as functions of the sample.
struct History {
    title: String,
    y_label: String,
    /// The x axis when it is not time (its unit in the label).
    x_label: Option<String>,
    series: Vec<Series>,
}

/// The history panel: probes against the exact solution where the scene
/// has one, else the energies.
fn history(scene: &Scene, model: &Model, samples: &[Sample]) -> History {
    let probes = &model.probes;
    let x0 = |k: usize| model.particles.x0[probes[k].particle];
    let mut series = Vec::new();
    let mut colors = 0;
    let mut add =
        |label: String, num: Vec<(f64, f64)>, exact: Option<Vec<(f64, f64)>>, style: Style| {
            // One colour per quantity, its exact counterpart dashed beside it.
            let color = colors;
            colors += 1;
            let s = Series::line(label.clone(), num, color);
            series.push(match style {
                Style::Solid => s,
                Style::Dashed => s.dashed(),
                Style::Markers => s.markers(),
            });
            if let Some(e) = exact {
                series.push(Series::line(format!("{label}, exact"), e, color).dashed());
            }
        };
    // The references read at the end, or over the samples without probes.
    match scene.file.exact {
        Some(ExactKind::Cantilever) => return cantilever(scene, model),
        Some(ExactKind::PrandtlFooting) => return footing(scene, model, samples),
        Some(ExactKind::CriticalState) => return critical_state(scene, model),
        Some(ExactKind::Terzaghi) => {
            let t = samples.last().map_or(scene.file.solver.t_end, |s| s.t);
            return terzaghi(scene, model, t);
        }
        Some(k @ (ExactKind::ColumnCollapse | ExactKind::GranularCollapse)) => {
            return collapse(scene, model, k);
        }
        _ => {}
    }
    let exact = if probes.is_empty() {
        None
    } else {
        scene.file.exact
    };
    let (title, y_label) = match exact {
        Some(ExactKind::DykaBar) => {
            let bar = crate::exact::dyka::DykaBar::from_scene(scene);
            for (k, p) in probes.iter().enumerate() {
                let n = samples.iter().map(|s| (s.t, s.probes[k].v[0])).collect();
                let e = samples
                    .iter()
                    .map(|s| (s.t, bar.velocity_stress(x0(k)[0], s.t).0))
                    .collect();
                add(p.name.clone(), n, Some(e), Style::Solid);
            }
            ("velocity at the probes", "velocity v_x (m/s)")
        }
        Some(ExactKind::ElasticColumn) => {
            let col = crate::exact::column::ElasticColumn::from_scene(scene, model);
            for (k, p) in probes.iter().enumerate() {
                let n = samples
                    .iter()
                    .map(|s| (s.t, x0(k)[1] - s.probes[k].x[1]))
                    .collect();
                let e = samples
                    .iter()
                    .map(|s| (s.t, col.settlement(x0(k)[1], s.t)))
                    .collect();
                add(p.name.clone(), n, Some(e), Style::Solid);
            }
            ("settlement at the probes", "settlement, down (m)")
        }
        Some(ExactKind::RollingDisk) => {
            let disk = crate::exact::rolling::RollingDisk::from_scene(scene);
            for (k, p) in probes.iter().enumerate() {
                let n = samples
                    .iter()
                    .map(|s| (s.t, s.probes[k].x[0] - x0(k)[0]))
                    .collect();
                let e = samples
                    .iter()
                    .map(|s| (s.t, disk.displacement(s.t)[0]))
                    .collect();
                add(p.name.clone(), n, Some(e), Style::Solid);
            }
            ("displacement at the probes", "displacement u_x (m)")
        }
        Some(ExactKind::SlidingBlock) => {
            let block = crate::exact::sliding::SlidingBlock::from_scene(scene);
            let tg = block.tangent;
            for (k, p) in probes.iter().enumerate() {
                let n = samples
                    .iter()
                    .map(|s| (s.t, s.probes[k].v[0] * tg[0] + s.probes[k].v[1] * tg[1]))
                    .collect();
                let e = samples.iter().map(|s| (s.t, block.velocity(s.t))).collect();
                add(p.name.clone(), n, Some(e), Style::Solid);
            }
            ("velocity along the wall at the probes", "velocity (m/s)")
        }
        Some(ExactKind::AlignedVibration) => {
            match crate::model::loads::AlignedVibration::from_scene(scene) {
                Some(field) => {
                    for (k, p) in probes.iter().enumerate() {
                        let n = samples
                            .iter()
                            .map(|s| (s.t, s.probes[k].x[0] - x0(k)[0]))
                            .collect();
                        let e = samples
                            .iter()
                            .map(|s| (s.t, field.displacement(x0(k), s.t)[0]))
                            .collect();
                        add(p.name.clone(), n, Some(e), Style::Solid);
                    }
                    ("displacement at the probes", "displacement u_x (m)")
                }
                None => energy(samples, &mut add),
            }
        }
        Some(ExactKind::ContactSliding) => {
            let block = crate::exact::contact::sliding(scene);
            let tg = block.tangent;
            for (k, p) in probes.iter().enumerate() {
                let n = samples
                    .iter()
                    .map(|s| {
                        let u = [s.probes[k].x[0] - x0(k)[0], s.probes[k].x[1] - x0(k)[1]];
                        (s.t, u[0] * tg[0] + u[1] * tg[1])
                    })
                    .collect();
                let e = dense(samples, |t| crate::exact::contact::slide_exact(&block, t));
                add(p.name.clone(), n, Some(e), Style::Solid);
            }
            (
                "slide along the face at the probes",
                "displacement along the face (m)",
            )
        }
        Some(ExactKind::ContactRolling) => {
            let disk = crate::exact::contact::rolling(scene);
            let a = disk.accel_along().max(f64::MIN_POSITIVE);
            let dir = [disk.accel[0] / a, disk.accel[1] / a];
            for (k, p) in probes.iter().enumerate() {
                let n = samples
                    .iter()
                    .map(|s| {
                        let u = [s.probes[k].x[0] - x0(k)[0], s.probes[k].x[1] - x0(k)[1]];
                        (s.t, u[0] * dir[0] + u[1] * dir[1])
                    })
                    .collect();
                let e = dense(samples, |t| 0.5 * a * t * t);
                add(p.name.clone(), n, Some(e), Style::Solid);
            }
            (
                "distance rolled at the probes",
                "displacement along the face (m)",
            )
        }
        Some(ExactKind::DiskImpact) => {
            // Along the contact tangent at the start's line of centres,
            // from the final particles' figures' geometry.
            let e = crate::exact::contact::score_impact(scene, &model.particles);
            let tg = impact_tangent(scene);
            let start = [e.tangential_first_start, e.tangential_second_start];
            for (k, p) in probes.iter().enumerate() {
                let n = samples
                    .iter()
                    .map(|s| (s.t, s.probes[k].v[0] * tg[0] + s.probes[k].v[1] * tg[1]))
                    .collect();
                let v0 = start[k.min(1)];
                let ex = samples.iter().map(|s| (s.t, v0)).collect();
                add(p.name.clone(), n, Some(ex), Style::Solid);
            }
            (
                "velocity along the contact tangent at the probes",
                "velocity (m/s)",
            )
        }
        Some(ExactKind::Mandel) => {
            let m = crate::exact::mandel::Mandel::from_scene(scene);
            let (ps, ts) = (m.p_start(), m.time_scale());
            for (k, p) in probes.iter().enumerate() {
                let n = samples
                    .iter()
                    .map(|s| (s.t, s.probes[k].pore_pressure.unwrap_or(0.0) / ps))
                    .collect();
                let x = x0(k)[0];
                let e = dense(samples, |t| m.pressure_ratio(x, t / ts));
                add(p.name.clone(), n, Some(e), Style::Solid);
            }
            (
                "pore pressure at the probes against Mandel's closed form",
                "p / p_start",
            )
        }
        Some(ExactKind::Energy) => {
            let r = energy(samples, &mut add);
            if let Some(first) = samples.first() {
                let e0 = first.energy.kinetic + first.energy.strain;
                let pts = samples.iter().map(|s| (s.t, e0)).collect();
                series
                    .push(Series::line("start's kinetic + strain (exact: kept)", pts, 7).dashed());
            }
            r
        }
        _ => energy(samples, &mut add),
    };
    History {
        title: title.to_string(),
        y_label: y_label.to_string(),
        x_label: None,
        series,
    }
}

/// An exact curve at 200 times from the first sample's to the last's:
/// smooth where the samples are few.
fn dense(samples: &[Sample], f: impl Fn(f64) -> f64) -> Vec<(f64, f64)> {
    let (t0, t1) = match (samples.first(), samples.last()) {
        (Some(a), Some(b)) => (a.t, b.t),
        _ => return Vec::new(),
    };
    (0..=200)
        .map(|k| {
            let t = t0 + (t1 - t0) * k as f64 / 200.0;
            (t, f(t))
        })
        .collect()
}

/// The contact tangent at the line of centres where the disks meet.
fn impact_tangent(scene: &Scene) -> [f64; 2] {
    let u = crate::exact::contact::impact_line(scene);
    [-u[1], u[0]]
}

/// The footing's q/c against settlement, with Prandtl's 2 + π.
fn footing(scene: &Scene, model: &Model, samples: &[Sample]) -> History {
    let f = crate::exact::footing::Footing::from_scene(scene, model);
    let curve: Vec<(f64, f64)> = samples
        .iter()
        .map(|s| (1e3 * f.settlement(s.t), f.q_over_c(s)))
        .collect();
    let end = curve.last().map_or(1.0, |p| p.0.max(1e-9));
    History {
        title: "bearing pressure against settlement".into(),
        y_label: "q / c".into(),
        x_label: Some("settlement (mm)".into()),
        series: vec![
            Series::line(
                format!("the pair's reaction / (B c), B = {} m", num(f.width)),
                curve,
                0,
            )
            .markers(),
            Series::line(
                "Prandtl, 2 + π = 5.14",
                vec![
                    (0.0, crate::exact::footing::PRANDTL),
                    (end, crate::exact::footing::PRANDTL),
                ],
                3,
            )
            .dashed(),
        ],
    }
}

/// The clay's final state in the p′–q plane, with the critical state line.
fn critical_state(scene: &Scene, model: &Model) -> History {
    let p = &model.particles;
    let pts: Vec<(f64, f64)> = (0..p.len())
        .step_by((p.len() / 4000).max(1))
        .map(|i| {
            let szz = p.plastic.get(i).map_or(0.0, |q| q[0]);
            let (pp, q) = crate::exact::critical_state::p_q(p.stress[i], szz);
            (1e-3 * pp, 1e-3 * q)
        })
        .collect();
    let m = crate::exact::critical_state::m_of(scene);
    let p_max = pts.iter().map(|q| q.0).fold(0.0, f64::max) * 1.1;
    History {
        title: "final stresses against the critical state line".into(),
        y_label: "q = sqrt(3 J2) (kPa)".into(),
        x_label: Some("p′ (kPa)".into()),
        series: vec![
            Series::line("particles at the end", pts, 0).scatter(),
            Series::line(
                format!("critical state line q = M p′, M = {}", num(m)),
                vec![(0.0, 0.0), (p_max, m * p_max)],
                3,
            )
            .dashed(),
        ],
    }
}

/// Saturated layer: the pore pressure over height at the end against
/// Terzaghi's isochrone.
fn terzaghi(scene: &Scene, model: &Model, t: f64) -> History {
    let layer = crate::exact::terzaghi::Terzaghi::from_scene(scene);
    let p = &model.particles;
    let ps = layer.p_start();
    let tv = layer.time_factor(t);
    let pts: Vec<(f64, f64)> = (0..p.len())
        .step_by((p.len() / 4000).max(1))
        .map(|i| (p.pore_pressure[i] / ps, p.x[i][1]))
        .collect();
    let exact: Vec<(f64, f64)> = (0..=100)
        .map(|k| {
            let y = layer.base + layer.height() * k as f64 / 100.0;
            (layer.pressure_ratio(y, tv), y)
        })
        .collect();
    History {
        title: format!(
            "pore pressure at T_v = {} against Terzaghi's series",
            num(tv)
        ),
        y_label: "y (m)".into(),
        x_label: Some("p / p_start".into()),
        series: vec![
            Series::line("particles at the end", pts, 0).scatter(),
            Series::line("Terzaghi's series", exact, 3).dashed(),
        ],
    }
}

/// A collapse's final free surface, with its reference run-out.
fn collapse(scene: &Scene, model: &Model, kind: ExactKind) -> History {
    use crate::exact::collapse;
    let (bb, h, spacing) = collapse::geometry(scene);
    let p = &model.particles;
    let mut series = vec![
        Series::line(
            "free surface at the end",
            collapse::profile(p, h, spacing),
            0,
        ),
        Series::line(
            "column at the start",
            vec![(bb[0], bb[3]), (bb[2], bb[3]), (bb[2], bb[1])],
            7,
        ),
    ];
    let top = bb[3] - bb[1];
    if kind == ExactKind::ColumnCollapse {
        let (lo, hi) = collapse::COLUMN_RUN_OUT;
        let (ylo, yhi) = collapse::COLUMN_HEIGHT;
        series.push(
            Series::line(
                format!("study column, 2 s: run-out {}–{} m", num(lo), num(hi)),
                vec![(lo, 0.0), (lo, 0.5 * top), (hi, 0.5 * top), (hi, 0.0)],
                3,
            )
            .dashed(),
        );
        series.push(
            Series::line(
                format!("height {}–{} m", num(ylo), num(yhi)),
                vec![(0.0, ylo), (0.5, ylo), (0.5, yhi), (0.0, yhi)],
                2,
            )
            .dashed(),
        );
    } else {
        let w = bb[2] - bb[0];
        let a = top / w;
        let lf = bb[0] + w * (1.0 + collapse::RUN_OUT_SCALING * a);
        series.push(
            Series::line(
                format!("experiments: L_f = W (1 + 1.2 a) = {} m", num(lf)),
                vec![(lf, 0.0), (lf, 0.5 * top)],
                3,
            )
            .dashed(),
        );
        for (k, f) in [0.75, 1.25].into_iter().enumerate() {
            let x = bb[0] + w * (1.0 + f * collapse::RUN_OUT_SCALING * a);
            let label = if k == 0 { "± 25 %" } else { "" };
            series.push(Series::line(label, vec![(x, 0.0), (x, 0.25 * top)], 8).dashed());
        }
    }
    History {
        title: "deposit at the end".into(),
        y_label: "height y (m)".into(),
        x_label: Some("x (m)".into()),
        series,
    }
}

/// How an energy line is drawn.
#[derive(Clone, Copy)]
enum Style {
    Solid,
    Dashed,
    Markers,
}

fn energy(
    samples: &[Sample],
    add: &mut impl FnMut(String, Vec<(f64, f64)>, Option<Vec<(f64, f64)>>, Style),
) -> (&'static str, &'static str) {
    let of = |f: fn(&Sample) -> f64| samples.iter().map(|s| (s.t, f(s))).collect::<Vec<_>>();
    // Each its own colour and line style (solid, dashed, with markers),
    // so they read apart where they overlap.
    add(
        "kinetic".into(),
        of(|s| s.energy.kinetic),
        None,
        Style::Solid,
    );
    add(
        "strain".into(),
        of(|s| s.energy.strain),
        None,
        Style::Dashed,
    );
    add(
        "kinetic + strain".into(),
        of(|s| s.energy.kinetic + s.energy.strain),
        None,
        Style::Markers,
    );
    ("energy history", "energy (J per m of thickness)")
}

/// The cantilever is static: its deflection along the beam (the particles
/// nearest the mid-height line) with the references at the free end.
fn cantilever(scene: &Scene, model: &Model) -> History {
    let c = crate::exact::cantilever::Cantilever::from_scene(scene);
    let p = &model.particles;
    let mid = c.tip[1];
    let nearest = (0..p.len())
        .map(|i| (p.x0[i][1] - mid).abs())
        .fold(f64::INFINITY, f64::min);
    let mut line: Vec<(f64, f64)> = (0..p.len())
        .filter(|&i| (p.x0[i][1] - mid).abs() <= nearest + 1e-9 * c.h)
        .map(|i| (p.x0[i][0], -(p.x[i][1] - p.x0[i][1])))
        .collect();
    line.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut series = vec![Series::line("particles nearest mid-height", line, 0).markers()];
    series.push(
        Series::line(
            "Timoshenko (linear), free end",
            vec![(c.tip[0], c.timoshenko)],
            1,
        )
        .scatter(),
    );
    if let Some(r) = c.nonlinear {
        series.push(Series::line("paper's nonlinear, free end", vec![(c.tip[0], r)], 2).scatter());
    }
    History {
        title: "deflection along the beam".into(),
        y_label: "deflection, down (m)".into(),
        x_label: Some("x along the beam (m)".into()),
        series,
    }
}

/// What colours the final particles: the plastic materials' first state
/// column where every plastic body has the same one (`STATE_COLUMNS`: ε̄p
/// for Mohr–Coulomb and Drucker–Prager, the preconsolidation pressure p_c
/// for modified Cam-clay), else the displacement magnitude.
#[derive(Clone, Copy, PartialEq)]
enum Colour {
    State(StateColumn),
    Displacement,
}

fn colour_of(model: &Model) -> Colour {
    if model.particles.plastic.is_empty() {
        return Colour::Displacement;
    }
    let first: Vec<Option<StateColumn>> = model
        .body_material
        .iter()
        .map(|&m| &model.materials[m as usize])
        .filter(|m| m.needs_plastic_state())
        .map(|m| m.entry().state_columns.first().copied())
        .collect();
    match first.first() {
        Some(&Some(c)) if first.iter().all(|f| *f == Some(c)) => Colour::State(c),
        _ => Colour::Displacement,
    }
}

/// The final particles, coloured as `colour_of` says.
fn particles_panel(model: &Model, t: f64) -> ParticleImage {
    let p = &model.particles;
    let colour = colour_of(model);
    let value = |i: usize| match colour {
        Colour::State(_) => p.plastic[i][1],
        Colour::Displacement => (p.x[i][0] - p.x0[i][0]).hypot(p.x[i][1] - p.x0[i][1]),
    };
    let points: Vec<(f64, f64, f64)> = (0..p.len())
        .map(|i| (p.x[i][0], p.x[i][1], value(i)))
        .collect();
    let (lo, hi) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), q| {
            (a.min(q.2), b.max(q.2))
        });
    // Magnitudes start the scale at zero; p_c starts at its least.
    let from_least = matches!(colour, Colour::State(c) if !c.from_zero);
    let range = match colour {
        _ if from_least && lo.is_finite() && hi > lo => (lo, hi),
        _ if from_least && lo.is_finite() => (lo, lo + lo.abs().max(1.0)),
        _ if lo.is_finite() && hi > 0.0 => (0.0, hi),
        _ => (0.0, 1.0),
    };
    // The particles' side: the median of sqrt(volume), volume = m / ρ.
    let mut sides: Vec<f64> = (0..p.len())
        .step_by((p.len() / 2000).max(1))
        .map(|i| (p.mass[i] / p.rho[i]).sqrt())
        .collect();
    sides.sort_by(f64::total_cmp);
    let size = sides.get(sides.len() / 2).copied().unwrap_or(0.0);
    ParticleImage {
        title: String::new(),
        value_label: match colour {
            Colour::State(c) => c.short_label(),
            Colour::Displacement => "|u| (m)".into(),
        },
        panels: vec![Panel {
            title: format!(
                "particles at t = {} s, coloured by {}",
                num(t),
                match colour {
                    Colour::State(c) => c.meaning,
                    Colour::Displacement => "displacement magnitude",
                }
            ),
            points,
            size,
        }],
        cols: 1,
        range,
        panel_size: (SIZE.0 - HISTORY_WIDTH - 90, SIZE.1 - 40),
        axes: true,
    }
}

/// `result.png` of a finished run, as PNG bytes.
pub fn picture(
    scene: &Scene,
    model: &Model,
    samples: &[Sample],
    summary: &Summary,
) -> Result<Vec<u8>> {
    crate::chart::register_font();
    let mut h = history(scene, model, samples);
    let not_time = h.x_label.is_some();
    // Times in the unit that keeps the tick labels plain decimals.
    let t_max = samples.last().map_or(0.0, |s| s.t);
    let (unit, scale) = if not_time || t_max >= 0.1 {
        ("s", 1.0)
    } else if t_max >= 1e-3 {
        ("ms", 1e3)
    } else {
        ("µs", 1e6)
    };
    if scale != 1.0 {
        for s in &mut h.series {
            for p in &mut s.points {
                p.0 *= scale;
            }
        }
    }
    let mut chart = LineChart::new(
        format!("{}: {}", scene.name, h.title),
        format!("time t ({unit})"),
        h.y_label,
    );
    if let Some(x) = h.x_label {
        chart.x_label = x;
    }
    chart.series = h.series;
    chart.place_legend();
    let image = particles_panel(model, summary.t);
    let mut buf = vec![255u8; (SIZE.0 * SIZE.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, SIZE).into_drawing_area();
        let (left, right) = root.split_horizontally(HISTORY_WIDTH);
        chart.draw(&left).map_err(draw_error)?;
        image.draw(&right, 1).map_err(draw_error)?;
        root.present().map_err(|e| draw_error(e.to_string()))?;
    }
    crate::chart::png_bytes(&buf, SIZE)
}

fn draw_error(e: String) -> Error {
    Error::io(
        "cannot draw",
        std::path::Path::new(FILE),
        std::io::Error::other(e),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::ProbeState;
    use crate::model::energy::Energy;

    fn model_of(text: &str) -> (Scene, Model) {
        let scene = Scene::from_str(text, "case", "case", &[]).unwrap();
        let model = Model::new(&scene).unwrap();
        (scene, model)
    }

    /// Samples at rest, a growing reaction, and energies in a 2:1 ratio.
    fn samples(model: &Model, n: usize) -> Vec<Sample> {
        (0..n)
            .map(|k| Sample {
                t: 0.01 * k as f64,
                probes: model
                    .probes
                    .iter()
                    .map(|p| ProbeState {
                        x: model.particles.x0[p.particle],
                        v: [0.0; 2],
                        stress: [0.0; 3],
                        pore_pressure: None,
                    })
                    .collect(),
                energy: Energy {
                    kinetic: 2.0 * k as f64,
                    strain: k as f64,
                    ..Default::default()
                },
                reactions: vec![[0.0, 1e3 * k as f64]; model.reaction_names().len()],
                newton: None,
            })
            .collect()
    }

    #[test]
    fn each_case_with_a_reference_draws_it_and_not_the_energy() {
        use crate::cases::*;
        for (text, title, reference) in [
            (
                FOOTING,
                "bearing pressure against settlement",
                "Prandtl, 2 + π = 5.14",
            ),
            (
                CLAY_BIAXIAL,
                "critical state line",
                "critical state line q = M p′, M = 1.20",
            ),
            (
                COLUMN_COLLAPSE,
                "deposit at the end",
                "study column, 2 s: run-out 4.85–5.06 m",
            ),
            (
                GRANULAR_COLLAPSE,
                "deposit at the end",
                "experiments: L_f = W (1 + 1.2 a) = 3.40 m",
            ),
            (CONTACT_BLOCK, "slide along the face", "block, exact"),
            (CONTACT_ROLLING, "distance rolled", "centre, exact"),
            (CONTACT_DISKS, "contact tangent", "left_centre, exact"),
        ] {
            let (scene, model) = model_of(text);
            let h = history(&scene, &model, &samples(&model, 5));
            assert!(h.title.contains(title), "{}: {}", scene.name, h.title);
            let r = h.series.iter().find(|s| s.label == reference);
            assert!(
                r.is_some_and(|s| s.dashed && !s.points.is_empty()),
                "{}: no dashed {reference:?} in {:?}",
                scene.name,
                h.series.iter().map(|s| &s.label).collect::<Vec<_>>()
            );
            assert!(
                !h.series.iter().any(|s| s.label == "kinetic"),
                "{}",
                scene.name
            );
        }
    }

    #[test]
    fn the_energies_differ_in_colour_and_line_style() {
        let text = crate::cases::PLATE_IMPACT.replace("exact = \"energy\"", "");
        let (scene, model) = model_of(&text);
        let h = history(&scene, &model, &samples(&model, 5));
        let find = |l: &str| h.series.iter().find(|s| s.label == l).unwrap();
        let (k, s, sum) = (find("kinetic"), find("strain"), find("kinetic + strain"));
        assert!(k.color != s.color && s.color != sum.color && k.color != sum.color);
        let style = |x: &Series| (x.dashed, x.markers);
        assert!(style(k) != style(s) && style(s) != style(sum) && style(k) != style(sum));
        // With `exact = "energy"` the start's energy is drawn beside them.
        let (scene, model) = model_of(crate::cases::PLATE_IMPACT);
        let h = history(&scene, &model, &samples(&model, 5));
        assert!(
            h.series
                .iter()
                .any(|s| s.dashed && s.label.starts_with("start's"))
        );
    }

    #[test]
    fn cam_clay_particles_are_coloured_and_labelled_by_p_c() {
        let (_, model) = model_of(crate::cases::CLAY_BIAXIAL);
        let img = particles_panel(&model, 0.0);
        assert_eq!(img.value_label, "p_c (Pa)");
        assert!(
            img.panels[0]
                .title
                .contains("preconsolidation pressure p_c")
        );
        // p_c0 = ocr p′0 = 100 kPa: the scale spans the values, not 0.
        assert!(img.range.0 > 0.9e5, "{:?}", img.range);
        assert!(img.axes);
        let (_, model) = model_of(crate::cases::COLUMN_COLLAPSE);
        let img = particles_panel(&model, 0.0);
        assert_eq!(img.value_label, "ε̄p");
    }
}
