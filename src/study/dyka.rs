//! Study `dyka`: Dyka's bar over the paper's 7 cell sizes for linear, uGIMP
//! and LME γ = 2, 3, 4 with FE and NPC. Charts: RMS velocity error against
//! cell size (paper Fig. 6), error against wall time (the speed/accuracy
//! front), free-end velocity histories against the exact solution for FE vs
//! NPC (Fig. 8), the γ sweep (Fig. 9) and uGIMP vs LME (Fig. 10).

use super::runner::{Job, JobResult};
use super::spec::Study;
use super::{Method, backend_slug, backends_of, image, sig, table};
use crate::cases::{DYKA_BAR, DYKA_L};
use crate::chart::{LineChart, Series};
use crate::error::Result;
use crate::exact::Errors;
use crate::exact::dyka::DykaBar;
use crate::scene::Scene;
use crate::simulation::BackendChoice;
use crate::sweep::report::{self, Curve};
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// The paper's cell sizes (m).
pub const H_FULL: [f64; 7] = [1e-4, 3.325e-4, 5e-4, 1e-3, 3.3325e-3, 6.665e-3, 1e-2];
/// `--quick`: the three coarsest, which still show the trends (1 mm is
/// the histories' size). 0.5 mm, once in it, cost three quarters of the
/// quick sweep's time (a run costs 1/h²); the trend its test asserts
/// (NPC at or below FE at each size, for LME at every one) holds on these.
pub const H_QUICK: [f64; 3] = [1e-3, 3.3325e-3, 1e-2];
/// Cell size of the history charts (m), as in the paper's figures.
pub const H_HISTORY: f64 = 1e-3;

/// (label, shape, γ) of each method.
pub const METHODS: [Method; 5] = [
    ("linear", "linear", 0.0),
    ("ugimp", "ugimp", 0.0),
    ("lme-g2", "lme", 2.0),
    ("lme-g3", "lme", 3.0),
    ("lme-g4", "lme", 4.0),
];

pub const INTEGRATORS: [&str; 2] = ["fe", "npc"];

/// One job: the bar one cell thick (h × h cells, so 2 × 2 particles across).
pub fn job(backend: BackendChoice, h: f64, method: usize, integrator: &str) -> Job {
    let m = METHODS[method];
    bar_at(
        Job::new(
            format!(
                "{}-{}-{integrator}-h{}mm",
                backend_slug(backend),
                m.0,
                sig(h * 1e3)
            ),
            DYKA_BAR,
            "dyka_bar",
        ),
        h,
    )
    .set(format!("solver.integrator={integrator}"))
    .on(backend)
    .method(m)
    .tag("integrator", integrator)
    .tag("h_mm", sig(h * 1e3))
}

/// `j` (a job of the `dyka_bar` case) at cell size `h`: the bar one cell
/// thick (h × h cells, so 2 × 2 particles across), and the probes on the
/// bar's axis (the case file puts them at y = 0.5 mm, for h = 1 mm): the
/// paper's point A, the impactor's free end, and the middle.
pub fn bar_at(j: Job, h: f64) -> Job {
    j.set(format!("grid.h={h}"))
        .set(format!(
            "bodies.impactor.rects=[[0.0, 0.0, {}, {h}]]",
            DYKA_L / 4.0
        ))
        .set(format!(
            "bodies.bar.rects=[[{}, 0.0, {DYKA_L}, {h}]]",
            DYKA_L / 4.0
        ))
        .set(format!("output.probes.free_end=[0.0, {}]", h / 2.0))
        .set(format!(
            "output.probes.middle=[{}, {}]",
            DYKA_L / 2.0,
            h / 2.0
        ))
}

/// `lme-mpm study dyka`.
pub const STUDY: Study = Study {
    slug: "dyka",
    help: "Dyka's bar: 7 cell sizes × linear, uGIMP, LME γ = 2, 3, 4 × FE, NPC",
    jobs: |quick, backends| Ok(jobs(quick, backends)),
    report,
};

pub fn jobs(quick: bool, backends: &[BackendChoice]) -> Vec<Job> {
    let hs: &[f64] = if quick { &H_QUICK } else { &H_FULL };
    let mut out = Vec::new();
    for &b in backends {
        // Finest first: the longest runs start early and do not trail.
        for &h in hs {
            for m in 0..METHODS.len() {
                for i in INTEGRATORS {
                    out.push(job(b, h, m, i));
                }
            }
        }
    }
    out
}

fn rms_of(r: &JobResult) -> Option<f64> {
    match r.data()?.errors.as_ref()? {
        Errors::Dyka(e) if r.completed() => Some(e.rms_velocity),
        _ => None,
    }
}

fn find<'a>(
    results: &'a [JobResult],
    backend: &str,
    method: &str,
    integrator: &str,
    h: f64,
) -> Option<&'a JobResult> {
    let h_mm = sig(h * 1e3);
    super::find_tagged(
        results,
        &[
            ("backend", backend),
            ("method", method),
            ("integrator", integrator),
            ("h_mm", &h_mm),
        ],
    )
}

/// (t, value) points of a chart line.
type Line = Vec<(f64, f64)>;

/// Free-end velocity history of a run, and the exact one at the same probe.
fn history(r: &JobResult, exact: &DykaBar) -> Option<(Line, Line)> {
    let d = r.data()?;
    let x0 = d.probe_x0.iter().find(|(n, _)| n == "free_end")?.1[0];
    let sim: Vec<(f64, f64)> = d
        .probe("free_end")
        .iter()
        .map(|(t, s)| (t * 1e6, s.v[0]))
        .collect();
    let ex: Vec<(f64, f64)> = (0..=1000)
        .map(|k| {
            let t = d.t_end * k as f64 / 1000.0;
            (t * 1e6, exact.velocity_stress(x0, t).0)
        })
        .collect();
    Some((sim, ex))
}

/// RMS over the history of (simulated − exact) free-end velocity (m/s).
fn history_rms(r: &JobResult, exact: &DykaBar) -> Option<f64> {
    let d = r.data()?;
    let x0 = d.probe_x0.iter().find(|(n, _)| n == "free_end")?.1[0];
    let p = d.probe("free_end");
    let s: f64 = p
        .iter()
        .map(|(t, st)| (st.v[0] - exact.velocity_stress(x0, *t).0).powi(2))
        .sum();
    Some((s / p.len().max(1) as f64).sqrt())
}

/// What every part of the report reads.
struct Report<'a> {
    results: &'a [JobResult],
    hs: &'a [f64],
    /// The backend whose runs the tables and histories show.
    main: &'a str,
    exact: DykaBar,
    dir: &'a Path,
}

pub fn report(results: &[JobResult], dir: &Path, quick: bool) -> Result<(String, Vec<PathBuf>)> {
    let hs: &[f64] = if quick { &H_QUICK } else { &H_FULL };
    let scene = Scene::from_str(DYKA_BAR, "dyka_bar", "dyka_bar", &[])?;
    let backends = backends_of(results);
    let r = Report {
        results,
        hs,
        main: backends.first().copied().unwrap_or("cpu"),
        exact: DykaBar::from_scene(&scene),
        dir,
    };
    let mut charts = r.convergence_chart()?;
    charts.extend(r.front_chart(&backends)?);
    let hist = r.history_charts()?;
    for stem in hist.iter().flatten() {
        charts.push(dir.join(format!("{stem}.png")));
        charts.push(dir.join(format!("{stem}.svg")));
    }
    let mut md = String::new();
    r.write_table(&mut md, quick);
    r.write_npc_against_fe(&mut md);
    r.write_front(&mut md);
    r.write_histories(&mut md, &hist);
    Ok((md, charts))
}

impl Report<'_> {
    /// Error against cell size, one series per method and integrator, each
    /// with its fitted order (the shared convergence chart).
    fn convergence_chart(&self) -> Result<Vec<PathBuf>> {
        let (results, hs, main, dir) = (self.results, self.hs, self.main, self.dir);
        let mut curves = Vec::new();
        for (m, (label, _, _)) in METHODS.iter().enumerate() {
            for integ in INTEGRATORS {
                curves.push(Curve {
                    label: format!("{label} {integ}"),
                    points: hs
                        .iter()
                        .filter_map(|&h| {
                            find(results, main, label, integ, h)
                                .and_then(rms_of)
                                .map(|e| (h * 1e3, e))
                        })
                        .collect(),
                    color: m,
                    dashed: integ == "fe",
                });
            }
        }
        let (files, _) = report::convergence_chart(
            "Dyka's bar: RMS velocity error at t_end (solid NPC, dashed FE)",
            "cell size h (mm)",
            "RMS velocity error (m/s)",
            &curves,
            &dir.join("study-dyka-convergence"),
        )?;
        Ok(files)
    }

    /// Error against wall time, per backend, method and integrator, with
    /// the Pareto front (the shared front chart).
    fn front_chart(&self, backends: &[&str]) -> Result<Vec<PathBuf>> {
        let (results, hs, dir) = (self.results, self.hs, self.dir);
        let mut curves = Vec::new();
        for b in backends {
            for (m, (label, _, _)) in METHODS.iter().enumerate() {
                for integ in INTEGRATORS {
                    curves.push(Curve {
                        label: if backends.len() > 1 {
                            format!("{b} {label} {integ}")
                        } else {
                            format!("{label} {integ}")
                        },
                        points: hs
                            .iter()
                            .filter_map(|&h| {
                                let r = find(results, b, label, integ, h)?;
                                Some((r.data()?.wall_seconds, rms_of(r)?))
                            })
                            .collect(),
                        color: m,
                        dashed: integ == "fe",
                    });
                }
            }
        }
        let (files, _) = report::front_chart(
            "Dyka's bar: accuracy against cost (each point one cell size)",
            "RMS velocity error (m/s)",
            &curves,
            &dir.join("study-dyka-front"),
        )?;
        Ok(files)
    }

    /// Free-end velocity histories at 1 mm: the stems of the charts drawn
    /// (FE/NPC, γ sweep, uGIMP/LME), None where the runs are missing.
    fn history_charts(&self) -> Result<[Option<String>; 3]> {
        let (results, main, dir) = (self.results, self.main, self.dir);
        let exact = &self.exact;
        // --- histories at 1 mm ---------------------------------------------
        let hist_chart = |title: &str,
                          stem: &str,
                          runs: &[(&str, &str, &str, usize)]|
         -> Result<Option<String>> {
            let mut c = LineChart::new(title, "t (µs)", "free-end velocity (m/s)");
            let mut exact_pts = None;
            for (label, method, integ, color) in runs {
                if let Some(r) = find(results, main, method, integ, H_HISTORY) {
                    if let Some((sim, ex)) = history(r, exact) {
                        c.series.push(Series::line(*label, sim, *color));
                        exact_pts = Some(ex);
                    }
                }
            }
            let Some(ex) = exact_pts else { return Ok(None) };
            c.series.push(Series::line("exact", ex, 7).dashed());
            c.size = (900, 420);
            c.save(&dir.join(stem))?;
            Ok(Some(stem.to_string()))
        };
        let h1 = hist_chart(
            "Free-end velocity, LME γ = 4, h = 1 mm: FE against NPC",
            "study-dyka-fe-npc",
            &[("FE", "lme-g4", "fe", 3), ("NPC", "lme-g4", "npc", 0)],
        )?;
        let h2 = hist_chart(
            "Free-end velocity, NPC, h = 1 mm: LME γ = 2, 3, 4",
            "study-dyka-gamma",
            &[
                ("γ = 2", "lme-g2", "npc", 2),
                ("γ = 3", "lme-g3", "npc", 3),
                ("γ = 4", "lme-g4", "npc", 4),
            ],
        )?;
        let h3 = hist_chart(
            "Free-end velocity, NPC, h = 1 mm: uGIMP against LME γ = 4",
            "study-dyka-ugimp-lme",
            &[
                ("uGIMP", "ugimp", "npc", 1),
                ("LME γ = 4", "lme-g4", "npc", 4),
            ],
        )?;
        Ok([h1, h2, h3])
    }

    /// The opening sentence and the error table.
    fn write_table(&self, md: &mut String, quick: bool) {
        let (results, hs, main) = (self.results, self.hs, self.main);
        // --- text ----------------------------------------------------------------
        let _ = writeln!(
            md,
            "Dyka's bar (SPEC benchmark 1) at {} cell sizes from {} to {} mm, 2 × 2 particles per cell, CFL 0.1, \
             t_end = 1e-4 s, {} runs{}. Error: RMS particle-velocity error at t_end against the exact solution \
             (paper eq. 44). Raw results: `results.csv` of the study's output folder.\n",
            hs.len(),
            sig(hs[0] * 1e3),
            sig(hs[hs.len() - 1] * 1e3),
            results.len(),
            if quick { " (quick sweep)" } else { "" }
        );
        let mut header = vec!["h (mm)".to_string()];
        for (label, _, _) in METHODS {
            for integ in INTEGRATORS {
                header.push(format!("{label} {integ}"));
            }
        }
        let rows: Vec<Vec<String>> = hs
            .iter()
            .map(|&h| {
                let mut row = vec![sig(h * 1e3)];
                for (label, _, _) in METHODS {
                    for integ in INTEGRATORS {
                        row.push(match find(results, main, label, integ, h) {
                            Some(r) if r.completed() => rms_of(r).map_or("-".into(), sig),
                            Some(r) => super::failure_text(r),
                            None => "-".into(),
                        });
                    }
                }
                row
            })
            .collect();
        let _ = writeln!(
            md,
            "RMS velocity error (m/s), {main} backend:\n\n{}",
            table(&header, &rows)
        );
    }

    /// NPC against FE wherever both completed, and the grid-crossing remark.
    fn write_npc_against_fe(&self, md: &mut String) {
        let (results, hs, main) = (self.results, self.hs, self.main);
        // NPC against FE wherever both completed, per pair and per cell size
        // (the mean over methods).
        let (mut wins, mut pairs) = (0, 0);
        let mut exceptions = Vec::new();
        let mut per_h = Vec::new();
        for &h in hs {
            let (mut sn, mut sf, mut k) = (0.0, 0.0, 0);
            for (label, _, _) in METHODS {
                if let (Some(a), Some(b)) = (
                    find(results, main, label, "npc", h).and_then(rms_of),
                    find(results, main, label, "fe", h).and_then(rms_of),
                ) {
                    pairs += 1;
                    sn += a;
                    sf += b;
                    k += 1;
                    if a <= b {
                        wins += 1;
                    } else {
                        exceptions.push(format!(
                            "{label} at {} mm ({} against {})",
                            sig(h * 1e3),
                            sig(a),
                            sig(b)
                        ));
                    }
                }
            }
            if k > 0 {
                per_h.push((h, sn / k as f64, sf / k as f64));
            }
        }
        let failed: Vec<String> = results
            .iter()
            .filter(|r| !r.completed())
            .map(|r| format!("{} ({})", r.job.label, super::failure_text(r)))
            .collect();
        md.push_str(&image(
            "RMS error against cell size",
            "study-dyka-convergence.png",
        ));
        let means: Vec<String> = per_h
            .iter()
            .map(|(h, n, f)| format!("{} mm: {} against {}", sig(h * 1e3), sig(*n), sig(*f)))
            .collect();
        let _ = writeln!(
            md,
            "\n**Error against cell size.** NPC's error is at or below FE's in {wins} of {pairs} (method, cell size) \
             pairs where both completed{}. Averaged over the methods, NPC against FE: {}. The paper (Fig. 6) finds \
             NPC below FE throughout, LME comparable to uGIMP and better where particles cross cells, and uGIMP \
             unstable at 0.3325 and 0.5 mm. Runs that did not complete here: {}.\n",
            if exceptions.is_empty() {
                String::new()
            } else {
                format!("; the exceptions: {}", exceptions.join(", "))
            },
            means.join("; "),
            if failed.is_empty() {
                "none".to_string()
            } else {
                failed.join(", ")
            }
        );
        // Grid crossing: at 0.1 mm the free end moves further than the cell
        // size; compare each method there with its best.
        let finest = hs[0];
        if finest <= 1e-4 {
            let mut crossing = Vec::new();
            for (label, _, _) in METHODS {
                let errs: Vec<f64> = hs
                    .iter()
                    .filter_map(|&h| find(results, main, label, "npc", h).and_then(rms_of))
                    .collect();
                if let (Some(f), Some(best)) = (
                    find(results, main, label, "npc", finest).and_then(rms_of),
                    errs.iter().copied().reduce(f64::min),
                ) {
                    crossing.push(format!(
                        "{label} {} ({}× its smallest)",
                        sig(f),
                        sig(f / best)
                    ));
                }
            }
            let _ = writeln!(
                md,
                "At {} mm the free end travels several cells (grid crossing), and NPC errors are: {}.\n",
                sig(finest * 1e3),
                if crossing.is_empty() {
                    "none (no NPC run completed at that size)".to_string()
                } else {
                    crossing.join(", ")
                }
            );
        }
    }

    /// The accuracy-against-cost front.
    fn write_front(&self, md: &mut String) {
        let results = self.results;
        md.push_str(&image(
            "RMS error against wall time",
            "study-dyka-front.png",
        ));
        // The front: completed runs no other run beats on both time and error.
        let runs: Vec<(f64, f64, String)> = results
            .iter()
            .filter_map(|r| {
                let d = r.data()?;
                let e = rms_of(r)?;
                Some((d.wall_seconds, e, r.job.label.clone()))
            })
            .collect();
        let pts: Vec<(f64, f64)> = runs.iter().map(|(w, e, _)| (*w, *e)).collect();
        let front_runs: Vec<String> = report::pareto(&pts)
            .into_iter()
            .map(|i| {
                let (w, e, l) = &runs[i];
                format!("{l} ({} s, {} m/s)", sig(*w), sig(*e))
            })
            .collect();
        let _ = writeln!(
            md,
            "\n**Accuracy against cost.** Each point is one run ({} thread(s) per run); further down and left is \
             better. The runs on the front, from cheapest to most accurate: {}.\n",
            results
                .iter()
                .find_map(|r| r.data())
                .map_or(0, |d| d.threads),
            front_runs.join(", ")
        );
    }

    /// Remarks on the history charts that were drawn.
    fn write_histories(&self, md: &mut String, hist: &[Option<String>; 3]) {
        let (results, main) = (self.results, self.main);
        let exact = &self.exact;
        let [h1, h2, h3] = hist;
        if h1.is_some() {
            md.push_str(&image(
                "free-end velocity, FE and NPC",
                "study-dyka-fe-npc.png",
            ));
            let e = |m: &str, i: &str| {
                find(results, main, m, i, H_HISTORY).and_then(|r| history_rms(r, exact))
            };
            if let (Some(fe), Some(npc)) = (e("lme-g4", "fe"), e("lme-g4", "npc")) {
                let _ = writeln!(
                    md,
                    "\n**FE against NPC** (paper Fig. 8): over the whole history the free-end velocity departs from \
                     the exact one by {} m/s RMS with FE and {} m/s with NPC; NPC damps the ripple behind each \
                     front, FE keeps it, as in the paper.\n",
                    sig(fe),
                    sig(npc)
                );
            }
        }
        if h2.is_some() {
            md.push_str(&image("free-end velocity, γ sweep", "study-dyka-gamma.png"));
            let e = |m: &str| {
                find(results, main, m, "npc", H_HISTORY).and_then(|r| history_rms(r, exact))
            };
            let _ = writeln!(
                md,
                "\n**γ sweep** (paper Fig. 9): history RMS departure from the exact solution γ = 2: {}, γ = 3: {}, \
                 γ = 4: {} m/s. The paper finds lower γ damps the oscillations faster.\n",
                e("lme-g2").map_or("-".into(), sig),
                e("lme-g3").map_or("-".into(), sig),
                e("lme-g4").map_or("-".into(), sig)
            );
        }
        if h3.is_some() {
            md.push_str(&image(
                "free-end velocity, uGIMP and LME",
                "study-dyka-ugimp-lme.png",
            ));
            let e = |m: &str| {
                find(results, main, m, "npc", H_HISTORY).and_then(|r| history_rms(r, exact))
            };
            let _ = writeln!(
                md,
                "\n**uGIMP against LME γ = 4** (paper Fig. 10): history RMS departure {} (uGIMP) and {} m/s (LME). \
                 The paper sees no remarkable difference on a regular grid, LME fitting slightly better after the jumps.\n",
                e("ugimp").map_or("-".into(), sig),
                e("lme-g4").map_or("-".into(), sig)
            );
        }
    }
}
