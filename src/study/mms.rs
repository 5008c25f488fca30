//! Study `mms`: the manufactured 2D aligned vibration (B-spline paper,
//! SPEC benchmark 4) at 8, 16, 32 and 64 cells per side, 3 × 3 particles per
//! cell, Δt = 1e-5 s, T = 0.2 s, for linear, uGIMP, LME, bspline2,
//! bspline2 + MLS, bspline3 and bspline3 + MLS (NPC). Errors are RMS over
//! the particles (paper eq. 43) at T and, from a snapshot, after one period
//! (2L/c = 0.02 s). Charts: log-log convergence of displacement, velocity and
//! stress, and displacement error against wall time.

use super::runner::{Job, JobResult};
use super::{backend_slug, backends_of, image, sig, table};
use crate::cases::ALIGNED_VIBRATION;
use crate::chart::{LineChart, Series};
use crate::error::Result;
use crate::exact::Errors;
use crate::exact::mms::{AlignedVibration, MmsErrors};
use crate::scene::Scene;
use crate::simulation::BackendChoice;
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// Cells per side.
pub const CELLS_FULL: [usize; 4] = [8, 16, 32, 64];
/// `--quick`: two resolutions, one period.
pub const CELLS_QUICK: [usize; 2] = [8, 16];
/// One period of the vibration, 2L/c (s), for L = 1 m and c = 100 m/s.
pub const PERIOD: f64 = 0.02;
/// The rate the paper reports for B-spline MPM with MLS, and our goal for
/// bspline2 + MLS up to 64 cells (displacement).
pub const GOAL_RATE: f64 = 1.8;

/// (label, shape, MLS, LME γ) of each method.
pub const METHODS: [(&str, &str, bool, f64); 7] = [
    ("linear", "linear", false, 0.0),
    ("ugimp", "ugimp", false, 0.0),
    ("lme-g3", "lme", false, 3.0),
    ("bspline2", "bspline2", false, 0.0),
    ("bspline2-mls", "bspline2", true, 0.0),
    ("bspline3", "bspline3", false, 0.0),
    ("bspline3-mls", "bspline3", true, 0.0),
];

/// Chart colour of method `m`: an MLS variant shares its B-spline's colour, dashed.
fn color(m: usize) -> usize {
    [0, 1, 2, 3, 3, 4, 4][m]
}

pub fn job(backend: BackendChoice, cells: usize, method: usize, quick: bool) -> Job {
    let (label, shape, mls, gamma) = METHODS[method];
    let mut j = Job::new(
        format!("{}-{label}-n{cells}", backend_slug(backend)),
        ALIGNED_VIBRATION,
        "aligned_vibration",
    )
    .set(format!("grid.h={}", 1.0 / cells as f64))
    .set(format!("solver.shape={shape}"))
    .set(format!("solver.mls={mls}"))
    .tag("backend", backend_slug(backend))
    .tag("method", label)
    .tag("cells", cells);
    if gamma > 0.0 {
        j = j.set(format!("solver.lme_gamma={gamma}"));
    }
    if quick {
        j = j.set(format!("solver.t_end={PERIOD}"));
    } else {
        j.snapshot_times = vec![PERIOD];
    }
    j.backend = backend;
    j
}

pub fn jobs(quick: bool, backends: &[BackendChoice]) -> Vec<Job> {
    let cells: &[usize] = if quick { &CELLS_QUICK } else { &CELLS_FULL };
    let mut out = Vec::new();
    for &b in backends {
        // Finest first: the longest runs start early and do not trail.
        for &n in cells.iter().rev() {
            for m in 0..METHODS.len() {
                out.push(job(b, n, m, quick));
            }
        }
    }
    out
}

fn find<'a>(
    results: &'a [JobResult],
    backend: &str,
    method: &str,
    cells: usize,
) -> Option<&'a JobResult> {
    let n = cells.to_string();
    results.iter().find(|r| {
        r.job.tag_value("backend") == Some(backend)
            && r.job.tag_value("method") == Some(method)
            && r.job.tag_value("cells") == Some(n.as_str())
    })
}

/// Errors at T of a completed run.
pub fn final_errors(r: &JobResult) -> Option<&MmsErrors> {
    match r.data()?.errors.as_ref()? {
        Errors::Mms(e) if r.completed() => Some(e),
        _ => None,
    }
}

/// Errors after one period, from the run's snapshot (the run must have got
/// that far; quick runs end there).
fn period_errors(r: &JobResult, exact: &AlignedVibration) -> Option<MmsErrors> {
    let d = r.data()?;
    if let Some((t, p)) = d.snapshots.first() {
        return Some(crate::exact::mms::score(exact, p, *t));
    }
    (d.t_end <= PERIOD * (1.0 + 1e-9))
        .then(|| final_errors(r).cloned())
        .flatten()
}

/// Observed orders log2(e_n / e_2n) between successive resolutions.
pub fn rates(errors: &[Option<f64>]) -> Vec<Option<f64>> {
    errors
        .windows(2)
        .map(|w| match (w[0], w[1]) {
            (Some(a), Some(b)) if a > 0.0 && b > 0.0 => Some((a / b).log2()),
            _ => None,
        })
        .collect()
}

type Pick = fn(&MmsErrors) -> f64;

const QUANTITIES: [(&str, &str, &str, Pick); 3] = [
    ("displacement", "m", "u", |e| e.rms_displacement),
    ("velocity", "m/s", "v", |e| e.rms_velocity),
    ("stress", "Pa", "sigma", |e| e.rms_stress),
];

pub fn report(results: &[JobResult], dir: &Path, quick: bool) -> Result<(String, Vec<PathBuf>)> {
    let cells: &[usize] = if quick { &CELLS_QUICK } else { &CELLS_FULL };
    let scene = Scene::from_str(
        ALIGNED_VIBRATION,
        "aligned_vibration",
        "aligned_vibration",
        &[],
    )?;
    let exact = AlignedVibration::from_scene(&scene).expect("the case is manufactured");
    let backends = backends_of(results);
    let main = backends.first().copied().unwrap_or("cpu");
    let mut charts = Vec::new();
    let mut md = String::new();
    let t_label = if quick {
        "one period (0.02 s)"
    } else {
        "T = 0.2 s"
    };

    // --- convergence charts, one per quantity ----------------------------
    for (name, unit, stem, pick) in QUANTITIES {
        let mut c = LineChart::new(
            format!("Aligned vibration: RMS {name} error at {t_label}"),
            "cell size h (m)",
            format!("RMS {name} error ({unit})"),
        )
        .log_log();
        for (m, (label, _, mls, _)) in METHODS.iter().enumerate() {
            let pts: Vec<(f64, f64)> = cells
                .iter()
                .filter_map(|&n| {
                    let e = final_errors(find(results, main, label, n)?)?;
                    Some((1.0 / n as f64, pick(e)))
                })
                .collect();
            let s = Series::line(*label, pts, color(m)).markers();
            c.series.push(if *mls { s.dashed() } else { s });
        }
        // Slope-2 guide through the finest bspline2-mls point, or any point.
        if let Some(&(h, e)) = c
            .series
            .iter()
            .find(|s| s.label == "bspline2-mls")
            .and_then(|s| s.points.last())
            .or_else(|| c.series.iter().find_map(|s| s.points.last()))
        {
            let h0 = 1.0 / cells[0] as f64;
            c.series.push(
                Series::line("slope 2", vec![(h0, e * (h0 / h).powi(2)), (h, e)], 7).dashed(),
            );
        }
        c.size = (900, 560);
        c.legend = plotters::chart::SeriesLabelPosition::LowerRight;
        let stem = format!("study-mms-{stem}");
        c.save(&dir.join(&stem))?;
        charts.extend([format!("{stem}.png"), format!("{stem}.svg")].map(|f| dir.join(f)));
    }

    // --- error against wall time -------------------------------------------
    let mut front = LineChart::new(
        format!("Aligned vibration: displacement error at {t_label} against cost"),
        "wall time of the run (s)",
        "RMS displacement error (m)",
    )
    .log_log();
    for b in &backends {
        for (m, (label, _, mls, _)) in METHODS.iter().enumerate() {
            let mut pts: Vec<(f64, f64)> = cells
                .iter()
                .filter_map(|&n| {
                    let r = find(results, b, label, n)?;
                    Some((r.data()?.wall_seconds, final_errors(r)?.rms_displacement))
                })
                .collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            let name = if backends.len() > 1 {
                format!("{b} {label}")
            } else {
                label.to_string()
            };
            let s = Series::line(name, pts, color(m)).markers();
            front.series.push(if *mls { s.dashed() } else { s });
        }
    }
    front.size = (900, 560);
    front.legend = plotters::chart::SeriesLabelPosition::UpperRight;
    front.save(&dir.join("study-mms-front"))?;
    charts.extend(["study-mms-front.png", "study-mms-front.svg"].map(|f| dir.join(f)));

    // --- text ----------------------------------------------------------------
    let _ = writeln!(
        md,
        "The manufactured aligned vibration (SPEC benchmark 4, `cases/aligned_vibration.toml`): unit square, \
         Neo-Hookean E = 1e7 Pa, ν = 0.3, ρ0 = 1000 kg/m³, A = 0.1 m, NPC, Δt = 1e-5 s, t_end = {}, \
         {} to {} cells per side, 3 × 3 particles per cell, {} runs{}. Errors: RMS over particles of \
         |u − u_exact|, |v − v_exact| and the Cauchy stress difference (paper eq. 43). LME uses γ = 3. \
         A run that went unstable shows when and why (`energy_runaway`: kinetic + stored energy above 10 \
         times the exact field's peak). Raw results: `results.csv` of the study's output folder.\n",
        if quick {
            "0.02 s (one period; quick sweep)"
        } else {
            "0.2 s (ten periods)"
        },
        cells[0],
        cells[cells.len() - 1],
        results.len(),
        if backends.len() > 1 {
            " (tables: the first backend)"
        } else {
            ""
        }
    );
    let mut header = vec!["cells".to_string()];
    header.extend(METHODS.iter().map(|m| m.0.to_string()));
    for (name, unit, _, pick) in QUANTITIES {
        let rows: Vec<Vec<String>> = cells
            .iter()
            .map(|&n| {
                let mut row = vec![n.to_string()];
                for (label, _, _, _) in METHODS {
                    row.push(match find(results, main, label, n) {
                        Some(r) if r.completed() => {
                            final_errors(r).map_or("-".into(), |e| sig(pick(e)))
                        }
                        Some(r) => super::failure_text(r),
                        None => "-".into(),
                    });
                }
                row
            })
            .collect();
        let _ = writeln!(
            md,
            "RMS {name} error ({unit}) at {t_label}, {main} backend:\n\n{}",
            table(&header, &rows)
        );
    }

    // Observed rates of every quantity, at T and after one period.
    let mut rate_rows = Vec::new();
    let spans: Vec<String> = cells
        .windows(2)
        .map(|w| format!("{}→{}", w[0], w[1]))
        .collect();
    let mut goal = None;
    for (label, _, _, _) in METHODS {
        for (name, _, _, pick) in QUANTITIES {
            let at_t: Vec<Option<f64>> = cells
                .iter()
                .map(|&n| {
                    find(results, main, label, n)
                        .and_then(final_errors)
                        .map(pick)
                })
                .collect();
            let at_p: Vec<Option<f64>> = cells
                .iter()
                .map(|&n| {
                    find(results, main, label, n)
                        .and_then(|r| period_errors(r, &exact))
                        .map(|e| pick(&e))
                })
                .collect();
            let (rt, rp) = (rates(&at_t), rates(&at_p));
            if label == "bspline2-mls" && name == "displacement" {
                goal = Some((rt.clone(), rp.clone()));
            }
            let fmt = |r: &[Option<f64>]| {
                r.iter()
                    .map(|x| x.map_or("-".into(), |v| format!("{v:.2}")))
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            if quick {
                rate_rows.push(vec![label.to_string(), name.to_string(), fmt(&rt)]);
            } else {
                rate_rows.push(vec![
                    label.to_string(),
                    name.to_string(),
                    fmt(&rt),
                    fmt(&rp),
                ]);
            }
        }
    }
    let mut rh = vec![
        "method".to_string(),
        "quantity".to_string(),
        format!("order at {t_label} ({})", spans.join(", ")),
    ];
    if !quick {
        rh.push(format!("order after one period ({})", spans.join(", ")));
    }
    let _ = writeln!(
        md,
        "Observed orders of convergence, log₂(e_h / e_h/2), between successive resolutions (\"-\": a run \
         did not complete):\n\n{}",
        table(&rh, &rate_rows)
    );
    if let Some((at_t, at_p)) = goal {
        // Over one period and over the whole run: the quick sweep's T is
        // one period, so it reports one line.
        let verdict = |g: &[Option<f64>]| {
            let orders = g
                .iter()
                .map(|x| x.map_or("-".into(), |v| format!("{v:.2}")))
                .collect::<Vec<_>>()
                .join(", ");
            if !g.is_empty() && g.iter().all(|r| r.is_some_and(|v| v >= GOAL_RATE)) {
                format!("met (orders {orders})")
            } else if g.iter().any(Option::is_none) {
                format!("not met (orders {orders}; \"-\": a run did not complete)")
            } else {
                format!("not met (orders {orders})")
            }
        };
        let _ = write!(
            md,
            "Goal: bspline2 + MLS keeps an order ≥ {GOAL_RATE} in displacement up to {} cells. \
             At {t_label}: {}.",
            cells[cells.len() - 1],
            verdict(&at_t)
        );
        if !quick {
            let _ = write!(md, " After one period (0.02 s): {}.", verdict(&at_p));
        }
        md.push_str("\n\n");
    }
    for (_, _, stem, _) in QUANTITIES {
        md.push_str(&image(
            &format!("MMS convergence ({stem})"),
            &format!("study-mms-{stem}.png"),
        ));
        md.push('\n');
    }
    md.push_str(&image("MMS error against wall time", "study-mms-front.png"));
    Ok((md, charts))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rates_are_log2_ratios() {
        let r = rates(&[Some(4.0), Some(1.0), None, Some(0.1)]);
        assert_eq!(r, vec![Some(2.0), None, None]);
    }
}
