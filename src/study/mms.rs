//! Study `mms`: the B-spline paper's convergence study, the manufactured 2D
//! aligned vibration (SPEC benchmark 4) at 8, 16, 32 and 64 cells per side,
//! 3 × 3 particles per cell, 2 × 2 Gauss points per integration cell,
//! Δt = 1e-5 s, T = 0.2 s, with the paper's update (MUSL, eqs. 28–37) for
//! plain MPM (linear), bspline2, bspline3, and bspline2/3 + MLS in two
//! scopes: the paper's step (`solver.mls_scope = "all"`, "-mls") and the
//! fit as a correction of the internal force's quadrature only
//! (`"force"`, "-mlsf", issue 28). The paper
//! prints E as "10e^7 Pa", so both readings run: 1e7 and 1e8 Pa. Errors are
//! RMS over the particles (paper eq. 43) at T and, from a snapshot, after one
//! period 2L/c. Charts: log-log convergence of displacement, velocity and
//! stress per reading, and displacement error against wall time.
//!
//! Every B-spline method runs on both knot layouts (`solver.bspline_knots`:
//! the default midpoints, and "-cells", the paper's knots on the grid
//! lines, issue 28).
//!
//! The full sweep is 104 runs, many hours on 2 cores (a 64-cell run of the
//! force correction alone is about an hour and a half). Three variables
//! restrict it, and the report says which ran: `LME_MPM_MMS_CELLS=8,16,32`
//! (resolutions), `LME_MPM_MMS_METHODS=bspline2,bspline2-mlsf` (methods,
//! by label) and `LME_MPM_MMS_E=1e7` (readings).

use super::runner::{Job, JobResult};
use super::spec::Study;
use super::{backend_slug, backends_of, image, sig, table};
use crate::cases::ALIGNED_VIBRATION;
use crate::error::{Error, Result};
use crate::exact::Errors;
use crate::exact::mms::{AlignedVibration, MmsErrors};
use crate::scene::{Override, Scene};
use crate::simulation::BackendChoice;
use crate::sweep::report::{self, Curve};
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// Cells per side.
pub const CELLS_FULL: [usize; 4] = [8, 16, 32, 64];
/// `--quick`: two resolutions, one period, E = 1e7 Pa.
pub const CELLS_QUICK: [usize; 2] = [8, 16];
/// Restricts the full sweep's resolutions (comma-separated, from `CELLS_FULL`).
pub const CELLS_ENV: &str = "LME_MPM_MMS_CELLS";
/// Restricts the full sweep's methods (comma-separated labels of `METHODS`).
pub const METHODS_ENV: &str = "LME_MPM_MMS_METHODS";
/// Restricts the full sweep's readings of E (comma-separated labels of `E_READINGS`).
pub const E_ENV: &str = "LME_MPM_MMS_E";
/// The rate the paper reports for B-spline MPM with MLS, and the acceptance
/// goal for bspline2 + MLS (displacement, between successive resolutions).
pub const GOAL_RATE: f64 = 1.8;
/// Every method runs the paper's update.
pub const INTEGRATOR: &str = "musl";
/// The two readings of the paper's "E = 10e^7 Pa" (label, Pa).
pub const E_READINGS: [(&str, f64); 2] = [("1e7", 1e7), ("1e8", 1e8)];

/// One method of the study: its label, shape, `solver.mls_scope` (None
/// without MLS), and whether its knots sit on the grid lines
/// (`solver.bspline_knots = "cells"`).
#[derive(Debug, Clone, Copy)]
pub struct MmsMethod {
    pub label: &'static str,
    pub shape: &'static str,
    pub scope: Option<&'static str>,
    pub cells: bool,
}

const fn method(
    label: &'static str,
    shape: &'static str,
    scope: Option<&'static str>,
    cells: bool,
) -> MmsMethod {
    MmsMethod {
        label,
        shape,
        scope,
        cells,
    }
}

/// The methods: "-mls" is the paper's step (`"all"`), "-mlsf" the fit as a
/// correction of the internal force's quadrature only (`"force"`), "-cells"
/// the paper's knot layout.
pub const METHODS: [MmsMethod; 13] = [
    method("linear", "linear", None, false),
    method("bspline2", "bspline2", None, false),
    method("bspline2-mls", "bspline2", Some("all"), false),
    method("bspline2-mlsf", "bspline2", Some("force"), false),
    method("bspline3", "bspline3", None, false),
    method("bspline3-mls", "bspline3", Some("all"), false),
    method("bspline3-mlsf", "bspline3", Some("force"), false),
    method("bspline2-cells", "bspline2", None, true),
    method("bspline2-cells-mls", "bspline2", Some("all"), true),
    method("bspline2-cells-mlsf", "bspline2", Some("force"), true),
    method("bspline3-cells", "bspline3", None, true),
    method("bspline3-cells-mls", "bspline3", Some("all"), true),
    method("bspline3-cells-mlsf", "bspline3", Some("force"), true),
];

/// The methods a sweep runs, as indices into `METHODS`: all of them, or
/// `LME_MPM_MMS_METHODS`'s; for `--quick` the midpoints layout's but
/// bspline3's two MLS modes (126 of the quick sweep's 358 CPU seconds;
/// bspline2's modes, which the acceptance is about, stay), and plain
/// bspline2 on the cells layout (the other "-cells" methods cost minutes).
pub fn methods(quick: bool) -> Result<Vec<usize>> {
    if quick {
        return Ok((0..METHODS.len())
            .filter(|&m| {
                let x = METHODS[m];
                if x.cells {
                    x.label == "bspline2-cells"
                } else {
                    !(x.shape == "bspline3" && x.scope.is_some())
                }
            })
            .collect());
    }
    let all: Vec<&str> = METHODS.iter().map(|m| m.label).collect();
    Ok(restricted(METHODS_ENV, &all)?
        .into_iter()
        .map(|l| METHODS.iter().position(|m| m.label == l).expect("checked"))
        .collect())
}

/// The entries of `all` that `env` (a comma-separated list, each one of
/// `all`) names, in `all`'s order; all of them when it is not set.
fn restricted<'a>(env: &str, all: &[&'a str]) -> Result<Vec<&'a str>> {
    let Ok(list) = std::env::var(env) else {
        return Ok(all.to_vec());
    };
    let named: Vec<&str> = list.split(',').map(str::trim).collect();
    if let Some(bad) = named.iter().find(|n| !all.contains(n)) {
        return Err(Error::Scene(crate::error::SceneError::Override {
            arg: format!("{env}={list}"),
            message: format!("`{bad}` is not one of {all:?}"),
        }));
    }
    Ok(all.iter().copied().filter(|a| named.contains(a)).collect())
}

/// The method the acceptance figures are for.
pub const GOAL_METHOD: &str = "bspline2-mlsf";
/// What it must do at least as well as.
pub const GOAL_BASE: &str = "bspline2";

/// Chart colour of method `m`: an MLS variant shares its B-spline's colour,
/// dashed; the cells layout has colours of its own.
fn color(m: usize) -> usize {
    [0, 3, 3, 3, 4, 4, 4, 1, 1, 1, 2, 2, 2][m]
}

/// The resolutions of a sweep: `CELLS_QUICK`, or `CELLS_FULL` restricted by
/// `LME_MPM_MMS_CELLS`.
pub fn cells(quick: bool) -> Result<Vec<usize>> {
    if quick {
        return Ok(CELLS_QUICK.to_vec());
    }
    let Ok(list) = std::env::var(CELLS_ENV) else {
        return Ok(CELLS_FULL.to_vec());
    };
    let mut out = Vec::new();
    for s in list.split(',') {
        match s.trim().parse::<usize>() {
            Ok(n) if CELLS_FULL.contains(&n) => out.push(n),
            _ => {
                return Err(Error::Scene(crate::error::SceneError::Override {
                    arg: format!("{CELLS_ENV}={list}"),
                    message: format!("each entry must be one of {CELLS_FULL:?}"),
                }));
            }
        }
    }
    out.sort_unstable();
    out.dedup();
    Ok(out)
}

/// The E readings of a sweep (quick: the first only; else all, or
/// `LME_MPM_MMS_E`'s).
fn readings(quick: bool) -> Result<Vec<(&'static str, f64)>> {
    if quick {
        return Ok(E_READINGS[..1].to_vec());
    }
    let all: Vec<&str> = E_READINGS.iter().map(|r| r.0).collect();
    Ok(restricted(E_ENV, &all)?
        .into_iter()
        .map(|l| *E_READINGS.iter().find(|r| r.0 == l).expect("checked"))
        .collect())
}

/// One period 2L/c (s) of the case (L = 1 m, ρ0 = 1000 kg/m³) at modulus `e` (Pa).
pub fn period(e: f64) -> f64 {
    2.0 / (e / 1000.0).sqrt()
}

pub fn job(
    backend: BackendChoice,
    cells: usize,
    method: usize,
    reading: (&'static str, f64),
    quick: bool,
) -> Job {
    let MmsMethod {
        label,
        shape,
        scope,
        cells: on_lines,
    } = METHODS[method];
    let (e_label, e_pa) = reading;
    let mut j = Job::new(
        format!("{}-E{e_label}-{label}-n{cells}", backend_slug(backend)),
        ALIGNED_VIBRATION,
        "aligned_vibration",
    )
    .set(format!("grid.h={}", 1.0 / cells as f64))
    .set(format!("solver.shape={shape}"))
    .set(format!("solver.mls={}", scope.is_some()))
    .set(format!("solver.mls_scope={}", scope.unwrap_or("all")))
    .set(format!("solver.integrator={INTEGRATOR}"))
    .set(format!("materials.rubber.E={e_pa}"))
    .tag("backend", backend_slug(backend))
    .tag("E", e_label)
    .tag("method", label)
    .tag("cells", cells);
    if on_lines {
        j = j.set("solver.bspline_knots=cells");
    }
    if quick {
        j = j.set(format!("solver.t_end={}", period(e_pa)));
    } else {
        j.snapshot_times = vec![period(e_pa)];
    }
    j.backend = backend;
    j
}

/// `lme-mpm study mms`.
pub const STUDY: Study = Study {
    slug: "mms",
    help: "Manufactured aligned vibration, the B-spline paper's study: 8–64 cells × linear, \
         bspline2/3 with and without MLS, the paper's update, E = 1e7 and 1e8 Pa (hours on 2 \
         cores; `LME_MPM_MMS_CELLS` restricts it)",
    jobs,
    report,
};

pub fn jobs(quick: bool, backends: &[BackendChoice]) -> Result<Vec<Job>> {
    let (cells, methods, readings) = (cells(quick)?, methods(quick)?, readings(quick)?);
    let mut out = Vec::new();
    for &b in backends {
        // Finest first: the longest runs start early and do not trail.
        for &n in cells.iter().rev() {
            for &e in &readings {
                for &m in &methods {
                    out.push(job(b, n, m, e, quick));
                }
            }
        }
    }
    Ok(out)
}

fn find<'a>(
    results: &'a [JobResult],
    backend: &str,
    e: &str,
    method: &str,
    cells: usize,
) -> Option<&'a JobResult> {
    let n = cells.to_string();
    super::find_tagged(
        results,
        &[
            ("backend", backend),
            ("E", e),
            ("method", method),
            ("cells", &n),
        ],
    )
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
    let one = 2.0 * exact.length / exact.c;
    let d = r.data()?;
    if let Some((t, p)) = d.snapshots.first() {
        return Some(crate::exact::mms::score(exact, p, *t));
    }
    (d.t_end <= one * (1.0 + 1e-9))
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

const RELATIVE: [(&str, Pick); 3] = [
    ("displacement", |e| e.rms_displacement_relative),
    ("velocity", |e| e.rms_velocity_relative),
    ("stress", |e| e.rms_stress_relative),
];

fn fmt_orders(r: &[Option<f64>]) -> String {
    r.iter()
        .map(|x| x.map_or("-".into(), |v| format!("{v:.2}")))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The exact field of reading `e` (Pa).
fn exact_of(e: f64) -> Result<AlignedVibration> {
    let o = Override::parse(&format!("materials.rubber.E={e}"))?;
    let scene = Scene::from_str(
        ALIGNED_VIBRATION,
        "aligned_vibration",
        "aligned_vibration",
        &[o],
    )?;
    Ok(AlignedVibration::from_scene(&scene).expect("the case is manufactured"))
}

pub fn report(results: &[JobResult], dir: &Path, quick: bool) -> Result<(String, Vec<PathBuf>)> {
    let cells = super::tag_values(results, "cells")
        .iter()
        .filter_map(|c| c.parse::<usize>().ok())
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect::<Vec<_>>();
    let backends = backends_of(results);
    let main = backends.first().copied().unwrap_or("cpu");
    // The methods and readings that ran, in the study's order.
    let ran = super::tag_values(results, "method");
    let methods: Vec<usize> = (0..METHODS.len())
        .filter(|&m| ran.iter().any(|l| *l == METHODS[m].label))
        .collect();
    let ran_e = super::tag_values(results, "E");
    let readings: Vec<(&str, f64)> = E_READINGS
        .iter()
        .copied()
        .filter(|r| ran_e.contains(&r.0))
        .collect();
    let mut charts = Vec::new();
    let mut md = String::new();
    let s = Section {
        results,
        dir,
        quick,
        main,
        cells: &cells,
        methods: &methods,
        readings: &readings,
        t_label: if quick { "one period" } else { "T = 0.2 s" },
    };
    s.intro(&mut md, &backends);
    for &(e_label, e_pa) in &readings {
        let exact = exact_of(e_pa)?;
        let _ = writeln!(
            md,
            "### E = {e_label} Pa (c = {} m/s, one period 2L/c = {} s)\n",
            sig(exact.c),
            sig(period(e_pa))
        );
        charts.extend(s.convergence_charts(e_label)?);
        s.error_tables(&mut md, e_label);
        let goal = s.order_table(&mut md, e_label, &exact);
        s.acceptance(&mut md, e_label, goal);
        for (_, _, stem, _) in QUANTITIES {
            md.push_str(&image(
                &format!("MMS convergence ({stem}, E = {e_label} Pa)"),
                &format!("study-mms-{stem}-e{}.png", &e_label[2..]),
            ));
            md.push('\n');
        }
    }
    charts.extend(s.front(&mut md, &backends)?);
    Ok((md, charts))
}

/// What every part of the report reads.
struct Section<'a> {
    results: &'a [JobResult],
    dir: &'a Path,
    quick: bool,
    /// The backend the tables show.
    main: &'a str,
    cells: &'a [usize],
    /// The methods (indices into `METHODS`) and readings that ran.
    methods: &'a [usize],
    readings: &'a [(&'static str, f64)],
    /// When the errors are taken, in words.
    t_label: &'static str,
}

/// The `GOAL_METHOD` displacement orders at T and after one period.
type Goal = Option<(Vec<Option<f64>>, Vec<Option<f64>>)>;

impl Section<'_> {
    /// The study's set-up in words.
    fn intro(&self, md: &mut String, backends: &[&str]) {
        let (results, quick, cells) = (self.results, self.quick, self.cells);
        let _ = writeln!(
            md,
            "The B-spline paper's study (SPEC benchmark 4, `cases/aligned_vibration.toml`): unit square, \
     Neo-Hookean, ν = 0.3, ρ0 = 1000 kg/m³, A = 0.1 m, the paper's update (`solver.integrator = \
     \"musl\"`, eqs. 28–37) for every method, Δt = 1e-5 s, t_end = {}, 3 × 3 particles per cell, \
     2 × 2 Gauss points per integration cell for MLS; cells per side: {}{}; E = {} Pa (the two \
     readings of the paper's \"10e^7\"); {} runs{}. Errors: RMS over particles of |u − u_exact|, \
     |v − v_exact| and the Cauchy stress difference (paper eq. 43), and the same divided by the \
     exact field's RMS (1 = an error as large as the field). A run that went unstable shows when \
     and why (`energy_runaway`: kinetic + stored energy above 10 times the exact field's peak). \
     Raw results: `results.csv` of the study's output folder.\n",
            if quick {
                "one period 2L/c (quick sweep)"
            } else {
                "0.2 s"
            },
            cells
                .iter()
                .map(|c| c.to_string())
                .collect::<Vec<_>>()
                .join(", "),
            if !quick && cells.len() < CELLS_FULL.len() {
                format!(" (restricted by {CELLS_ENV}; the full sweep is {CELLS_FULL:?})")
            } else {
                String::new()
            },
            self.readings
                .iter()
                .map(|r| r.0)
                .collect::<Vec<_>>()
                .join(" and "),
            results.len(),
            if backends.len() > 1 {
                " (tables: the first backend)"
            } else {
                ""
            }
        );
        let names: Vec<&str> = self.methods.iter().map(|&m| METHODS[m].label).collect();
        let _ = writeln!(
            md,
            "Methods: {}{}. \"-mls\": the paper's step (`solver.mls_scope = \"all\"`); \"-mlsf\": the fit \
             as a correction of the internal force only (`\"force\"`); \"-cells\": the paper's knot \
             layout, a knot on every grid line (`solver.bspline_knots = \"cells\"`), the others the \
             midpoints layout.\n",
            names.join(", "),
            if !quick
                && (self.methods.len() < METHODS.len() || self.readings.len() < E_READINGS.len())
            {
                format!(" (restricted by {METHODS_ENV} / {E_ENV})")
            } else {
                String::new()
            }
        );
    }

    /// One convergence chart per quantity at E = `e_label`.
    fn convergence_charts(&self, e_label: &str) -> Result<Vec<PathBuf>> {
        let (results, main, cells, t_label, dir) =
            (self.results, self.main, self.cells, self.t_label, self.dir);
        let mut charts = Vec::new();
        // --- convergence charts, one per quantity -------------------------
        for (name, unit, stem, pick) in QUANTITIES {
            let curves: Vec<Curve> = self
                .methods
                .iter()
                .map(|&m| (m, METHODS[m].label, METHODS[m].scope))
                .map(|(m, label, scope)| Curve {
                    label: label.to_string(),
                    points: cells
                        .iter()
                        .filter_map(|&n| {
                            let e = final_errors(find(results, main, e_label, label, n)?)?;
                            Some((1.0 / n as f64, pick(e)))
                        })
                        .collect(),
                    color: color(m),
                    dashed: scope.is_some(),
                })
                .collect();
            let (files, _) = report::convergence_chart(
                &format!("Aligned vibration, E = {e_label} Pa: RMS {name} error at {t_label}"),
                "cell size h (m)",
                &format!("RMS {name} error ({unit})"),
                &curves,
                &dir.join(format!("study-mms-{stem}-e{}", &e_label[2..])),
            )?;
            charts.extend(files);
        }
        Ok(charts)
    }

    /// The absolute and relative error tables at E = `e_label`.
    fn error_tables(&self, md: &mut String, e_label: &str) {
        let (results, main, cells, t_label) = (self.results, self.main, self.cells, self.t_label);
        // --- tables ----------------------------------------------------------
        let mut header = vec!["cells".to_string()];
        header.extend(self.methods.iter().map(|&m| METHODS[m].label.to_string()));
        let cell_text = |r: Option<&JobResult>, pick: Pick| match r {
            Some(r) if r.completed() => final_errors(r).map_or("-".into(), |e| sig(pick(e))),
            Some(r) => super::failure_text(r),
            None => "-".into(),
        };
        for (name, unit, _, pick) in QUANTITIES {
            let rows: Vec<Vec<String>> = cells
                .iter()
                .map(|&n| {
                    let mut row = vec![n.to_string()];
                    for &m in self.methods {
                        let label = METHODS[m].label;
                        row.push(cell_text(find(results, main, e_label, label, n), pick));
                    }
                    row
                })
                .collect();
            let _ = writeln!(
                md,
                "RMS {name} error ({unit}) at {t_label}, E = {e_label} Pa, {main} backend:\n\n{}",
                table(&header, &rows)
            );
        }
        let rows: Vec<Vec<String>> = cells
            .iter()
            .map(|&n| {
                let mut row = vec![n.to_string()];
                for &m in self.methods {
                    let r = find(results, main, e_label, METHODS[m].label, n);
                    row.push(match r.and_then(final_errors) {
                        Some(e) => RELATIVE
                            .iter()
                            .map(|(_, pick)| format!("{:.3}", pick(e)))
                            .collect::<Vec<_>>()
                            .join(" / "),
                        None => cell_text(r, |e| e.rms_displacement),
                    });
                }
                row
            })
            .collect();
        let _ = writeln!(
            md,
            "Relative errors (displacement / velocity / stress, each over the exact field's RMS) at \
         {t_label}, E = {e_label} Pa:\n\n{}",
            table(&header, &rows)
        );
    }

    /// The observed orders at E = `e_label`; returns `GOAL_METHOD`'s.
    fn order_table(&self, md: &mut String, e_label: &str, exact: &AlignedVibration) -> Goal {
        let (results, main, cells, t_label, quick) = (
            self.results,
            self.main,
            self.cells,
            self.t_label,
            self.quick,
        );
        // --- orders ----------------------------------------------------------
        let spans: Vec<String> = cells
            .windows(2)
            .map(|w| format!("{}→{}", w[0], w[1]))
            .collect();
        let mut rate_rows = Vec::new();
        let mut goal = None;
        for label in self.methods.iter().map(|&m| METHODS[m].label) {
            for (name, _, _, pick) in QUANTITIES {
                let at = |f: &dyn Fn(&JobResult) -> Option<f64>| -> Vec<Option<f64>> {
                    cells
                        .iter()
                        .map(|&n| find(results, main, e_label, label, n).and_then(f))
                        .collect()
                };
                let at_t = at(&|r| final_errors(r).map(pick));
                let at_p = at(&|r| period_errors(r, exact).map(|e| pick(&e)));
                let (rt, rp) = (rates(&at_t), rates(&at_p));
                if label == GOAL_METHOD && name == "displacement" {
                    goal = Some((rt.clone(), rp.clone()));
                }
                let mut row = vec![label.to_string(), name.to_string(), fmt_orders(&rt)];
                if !quick {
                    row.push(fmt_orders(&rp));
                }
                rate_rows.push(row);
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
            "Observed orders of convergence, log₂(e_h / e_h/2), between successive resolutions \
         (\"-\": a run did not complete), E = {e_label} Pa:\n\n{}",
            table(&rh, &rate_rows)
        );
        goal
    }

    /// The acceptance figures for `GOAL_METHOD`, as measured:
    /// completes every resolution; displacement and stress errors at T at
    /// or below `GOAL_BASE`'s at every resolution; displacement order
    /// ≥ `GOAL_RATE` over one period (and at T, reported).
    fn acceptance(&self, md: &mut String, e_label: &str, goal: Goal) {
        let (results, main, cells, t_label, quick) = (
            self.results,
            self.main,
            self.cells,
            self.t_label,
            self.quick,
        );
        let done: Vec<String> = cells
            .iter()
            .map(|&n| match find(results, main, e_label, GOAL_METHOD, n) {
                Some(r) if r.completed() => format!("{n}: completed"),
                Some(r) => format!("{n}: {}", super::failure_text(r)),
                None => format!("{n}: not run"),
            })
            .collect();
        let mut beats = Vec::new();
        for (name, _, _, pick) in [QUANTITIES[0], QUANTITIES[2]] {
            for &n in cells {
                let e = |m| {
                    find(results, main, e_label, m, n)
                        .and_then(final_errors)
                        .map(pick)
                };
                beats.push(match (e(GOAL_METHOD), e(GOAL_BASE)) {
                    (Some(a), Some(b)) => format!(
                        "{name} {n}: {} vs {} ({})",
                        sig(a),
                        sig(b),
                        if a <= b { "at or below" } else { "above" }
                    ),
                    (Some(a), None) => {
                        format!("{name} {n}: {} vs {GOAL_BASE} not completed", sig(a))
                    }
                    _ => format!("{name} {n}: {GOAL_METHOD} did not complete"),
                });
            }
        }
        let _ = writeln!(
            md,
            "Acceptance figures for {GOAL_METHOD} (bspline2, MLS as the force correction) at E = \
             {e_label} Pa: completes every resolution? {}. RMS errors at {t_label} at or below \
             plain {GOAL_BASE}'s? {}. Displacement order ≥ {GOAL_RATE} between successive \
             resolutions? {}at {t_label} (reported): {}.\n",
            done.join("; "),
            beats.join("; "),
            if quick {
                String::new()
            } else {
                format!(
                    "after one period: {}; ",
                    goal.as_ref().map_or("-".into(), |(_, p)| verdict(p))
                )
            },
            goal.as_ref().map_or("-".into(), |(t, _)| verdict(t)),
        );
    }

    /// Error against wall time over every backend and reading.
    fn front(&self, md: &mut String, backends: &[&str]) -> Result<Vec<PathBuf>> {
        let (results, cells, t_label, dir) = (self.results, self.cells, self.t_label, self.dir);
        let mut charts = Vec::new();
        // --- error against wall time -----------------------------------------------
        let mut curves = Vec::new();
        for b in backends {
            for &(e_label, _) in self.readings {
                for (m, label, scope) in self
                    .methods
                    .iter()
                    .map(|&m| (m, METHODS[m].label, METHODS[m].scope))
                {
                    let points: Vec<(f64, f64)> = cells
                        .iter()
                        .filter_map(|&n| {
                            let r = find(results, b, e_label, label, n)?;
                            Some((r.data()?.wall_seconds, final_errors(r)?.rms_displacement))
                        })
                        .collect();
                    if points.is_empty() {
                        continue;
                    }
                    let mut name = format!("E {e_label} {label}");
                    if backends.len() > 1 {
                        name = format!("{b} {name}");
                    }
                    curves.push(Curve {
                        label: name,
                        points,
                        color: color(m),
                        dashed: scope.is_some(),
                    });
                }
            }
        }
        let (files, _) = report::front_chart(
            &format!("Aligned vibration: displacement error at {t_label} against cost"),
            "RMS displacement error (m)",
            &curves,
            &dir.join("study-mms-front"),
        )?;
        charts.extend(files);
        md.push_str(&image("MMS error against wall time", "study-mms-front.png"));
        Ok(charts)
    }
}

/// "met" / "not met" with the orders.
fn verdict(g: &[Option<f64>]) -> String {
    let orders = fmt_orders(g);
    if !g.is_empty() && g.iter().all(|r| r.is_some_and(|v| v >= GOAL_RATE)) {
        format!("met (orders {orders})")
    } else if g.iter().any(Option::is_none) {
        format!("not met (orders {orders}; \"-\": a run did not complete)")
    } else {
        format!("not met (orders {orders})")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rates_are_log2_ratios() {
        let r = rates(&[Some(4.0), Some(1.0), None, Some(0.1)]);
        assert_eq!(r, vec![Some(2.0), None, None]);
    }

    #[test]
    fn period_of_the_two_readings() {
        assert!((period(1e7) - 0.02).abs() < 1e-15);
        assert!((period(1e8) - 0.02 / 10f64.sqrt()).abs() < 1e-15);
    }
}
