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
    series: Vec<Series>,
}

/// The history panel: probes against the exact solution where the scene
/// has one, else the energies.
fn history(scene: &Scene, model: &Model, samples: &[Sample]) -> History {
    let probes = &model.probes;
    let x0 = |k: usize| model.particles.x0[probes[k].particle];
    let mut series = Vec::new();
    let mut add = |label: String, num: Vec<(f64, f64)>, exact: Option<Vec<(f64, f64)>>| {
        let color = series.len() / 2;
        series.push(Series::line(label.clone(), num, color));
        if let Some(e) = exact {
            series.push(Series::line(format!("{label}, exact"), e, color).dashed());
        }
    };
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
                add(p.name.clone(), n, Some(e));
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
                add(p.name.clone(), n, Some(e));
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
                add(p.name.clone(), n, Some(e));
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
                add(p.name.clone(), n, Some(e));
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
                        add(p.name.clone(), n, Some(e));
                    }
                    ("displacement at the probes", "displacement u_x (m)")
                }
                None => energy(samples, &mut add),
            }
        }
        Some(ExactKind::Cantilever) => {
            return cantilever(scene, model);
        }
        None => energy(samples, &mut add),
    };
    History {
        title: title.to_string(),
        y_label: y_label.to_string(),
        series,
    }
}

fn energy(
    samples: &[Sample],
    add: &mut impl FnMut(String, Vec<(f64, f64)>, Option<Vec<(f64, f64)>>),
) -> (&'static str, &'static str) {
    let of = |f: fn(&Sample) -> f64| samples.iter().map(|s| (s.t, f(s))).collect::<Vec<_>>();
    add("kinetic".into(), of(|s| s.energy.kinetic), None);
    add("strain".into(), of(|s| s.energy.strain), None);
    add(
        "kinetic + strain".into(),
        of(|s| s.energy.kinetic + s.energy.strain),
        None,
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
        series,
    }
}

/// The final particles, coloured by equivalent plastic strain when a
/// material is plastic, else by displacement magnitude.
fn particles_panel(model: &Model, summary: &Summary) -> ParticleImage {
    let p = &model.particles;
    let plastic = !p.plastic.is_empty();
    let value = |i: usize| {
        if plastic {
            p.plastic[i][1]
        } else {
            (p.x[i][0] - p.x0[i][0]).hypot(p.x[i][1] - p.x0[i][1])
        }
    };
    let points: Vec<(f64, f64, f64)> = (0..p.len())
        .map(|i| (p.x[i][0], p.x[i][1], value(i)))
        .collect();
    let (lo, hi) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), q| {
            (a.min(q.2), b.max(q.2))
        });
    // Both fields are magnitudes: the scale starts at zero.
    let range = if lo.is_finite() && hi > 0.0 {
        (0.0, hi)
    } else {
        (0.0, 1.0)
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
        value_label: if plastic {
            "ε̄p".into()
        } else {
            "|u| (m)".into()
        },
        panels: vec![Panel {
            title: format!(
                "particles at t = {} s, coloured by {}",
                num(summary.t),
                if plastic {
                    "equivalent plastic strain"
                } else {
                    "displacement magnitude"
                }
            ),
            points,
            size,
        }],
        cols: 1,
        range,
        panel_size: (SIZE.0 - HISTORY_WIDTH - 90, SIZE.1 - 40),
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
    let static_beam = matches!(scene.file.exact, Some(ExactKind::Cantilever));
    // Times in the unit that keeps the tick labels plain decimals.
    let t_max = samples.last().map_or(0.0, |s| s.t);
    let (unit, scale) = if static_beam || t_max >= 0.1 {
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
    if static_beam {
        chart.x_label = "x along the beam (m)".into();
    }
    chart.series = h.series;
    chart.place_legend();
    let image = particles_panel(model, summary);
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
