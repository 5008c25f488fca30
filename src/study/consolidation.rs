//! Study `consolidation` (issue 52): saturated soil against its exact
//! solutions, explicit NPC on the CPU. Terzaghi's layer
//! (`cases/terzaghi.toml`): isochrones p/p_start over depth against the
//! series at T_v = 0.05, 0.1, 0.2, 0.5 and 1, and the degree of
//! consolidation U against T_v on a log axis, and the first method again
//! with the particle's own volumetric term (equal-order u–p), every
//! particle's pressure at T_v 0.1 charted against the nodal term's, to show
//! the oscillation the default removes; Mandel's specimen
//! (`cases/mandel.toml`): the centre's pressure against t c / a², the
//! Mandel–Cryer rise; and each method's error against its wall time. The
//! GPU path and the implicit u–p step have no pore pressure yet, so every
//! run is explicit on the CPU, whatever `--backend` says.

use super::runner::{Job, JobResult, Method};
use super::spec::Study;
use super::{image, sig, table};
use crate::chart::{LineChart, Series};
use crate::error::Result;
use crate::exact::mandel::Mandel;
use crate::exact::terzaghi::Terzaghi;
use crate::simulation::BackendChoice;
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// The shapes compared.
pub const METHODS: [Method; 3] = [
    ("linear", "linear", 0.0),
    ("bspline2", "bspline2", 0.0),
    ("LME γ = 4", "lme", 0.0),
];

/// Terzaghi's isochrones (T_v), and the two classic degrees of
/// consolidation (50 % and 90 % for incompressible water).
pub const ISOCHRONES: [f64; 5] = [0.05, 0.1, 0.2, 0.5, 1.0];
pub const CLASSIC_TV: [f64; 2] = [0.197, 0.848];

/// Mandel's scored times (t c / a²).
pub const MANDEL_TIMES: [f64; 4] = [0.01, 0.1, 0.5, 1.0];

/// `--quick`: linear only, both problems to 0.2 of their time scale.
pub const QUICK_END: f64 = 0.2;

/// `lme-mpm study consolidation`.
pub const STUDY: Study = Study {
    slug: "consolidation",
    help: "Saturated soil: Terzaghi's isochrones and degree of consolidation, Mandel's centre \
         pressure (the Mandel-Cryer rise), error against wall time for linear, bspline2 and LME, \
         and the oscillation of equal-order u-p (CPU, explicit; about 3 minutes on 2 cores)",
    jobs: |quick, _backends| Ok(jobs(quick)),
    report,
};

/// Log-spaced factors from 0.005 to `end` with the listed ones in: where
/// the snapshots are taken (T_v, or t c / a²).
fn times(end: f64, listed: &[f64]) -> Vec<f64> {
    let mut v: Vec<f64> = (0..=24)
        .map(|k| 0.005 * (200.0f64).powf(k as f64 / 24.0))
        .chain(listed.iter().copied())
        .filter(|&x| x <= end * (1.0 + 1e-9))
        .collect();
    v.sort_by(f64::total_cmp);
    v.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    v
}

pub fn jobs(quick: bool) -> Vec<Job> {
    let end = if quick { QUICK_END } else { 1.0 };
    let methods: &[Method] = if quick { &METHODS[..1] } else { &METHODS };
    // Terzaghi: T_v = c_v t / H²; Mandel: t c / a² (both t / 10 s here).
    let layer = terzaghi_of(crate::cases::TERZAGHI);
    let t_scale = layer.height() * layer.height() / layer.cv();
    let spec = mandel_of(crate::cases::MANDEL);
    let m_scale = spec.time_scale();
    let tv_listed: Vec<f64> = ISOCHRONES.iter().chain(&CLASSIC_TV).copied().collect();
    // One run of a shipped case on the CPU to `t_end` (s), tagged with its
    // problem.
    let job = |label: &str, case: &'static str, name: &'static str, problem: &str, t_end: f64| {
        Job::new(label, case, name)
            .set(format!("solver.t_end={t_end}"))
            .set("output.vtk_interval=1e9")
            .on(BackendChoice::Cpu)
            .tag("problem", problem)
    };
    let mut out = Vec::new();
    for &m in methods {
        let snaps = |f: &[f64], scale: f64| f.iter().map(|f| f * scale).collect();
        let terzaghi = |label: String, problem: &str| {
            let mut j = job(
                &label,
                crate::cases::TERZAGHI,
                "terzaghi",
                problem,
                end * t_scale,
            );
            j.snapshot_times = snaps(&times(end, &tv_listed), t_scale);
            j
        };
        if m.1 == METHODS[0].1 {
            // The equal-order u–p run beside it (the particle's own −tr L
            // term), whose pressure oscillates from particle to particle.
            let label = format!("cpu-terzaghi-particle-{}", m.1);
            out.push(
                terzaghi(label, PARTICLE_TERM)
                    .set("solver.pore_volumetric=particle")
                    .method(m),
            );
        }
        out.push(terzaghi(format!("cpu-terzaghi-{}", m.1), "terzaghi").method(m));
        let label = format!("cpu-mandel-{}", m.1);
        let mut j = job(
            &label,
            crate::cases::MANDEL,
            "mandel",
            "mandel",
            end * m_scale,
        )
        .method(m);
        j.snapshot_times = snaps(&times(end, &MANDEL_TIMES), m_scale);
        out.push(j);
        // Its first time on the specimen with k / 10: the case reaches
        // t c/a² = 0.01 at 0.1 s, within the sudden load's shear ringing
        // (period 0.25 s); with c / 10 it is 1 s, four periods later.
        let t_early = MANDEL_TIMES[0] * m_scale * EARLY_SLOWER;
        let label = format!("cpu-mandel-early-{}", m.1);
        let mut j = job(
            &label,
            crate::cases::MANDEL,
            "mandel",
            "mandel-early",
            t_early,
        )
        .set(format!(
            "materials.soil.permeability={}",
            spec.fluid.k / EARLY_SLOWER
        ))
        .method(m);
        j.snapshot_times = vec![t_early];
        out.push(j);
    }
    out
}

/// The tag of Terzaghi's run with the particle's own volumetric term
/// (`solver.pore_volumetric = "particle"`), first method only.
pub const PARTICLE_TERM: &str = "terzaghi-particle";

/// The isochrone the oscillation chart shows (T_v).
pub const OSCILLATION_TV: f64 = 0.1;

/// How much slower Mandel's early run consolidates (k / this).
pub const EARLY_SLOWER: f64 = 10.0;

fn scene_of(text: &str, name: &str) -> crate::scene::Scene {
    crate::scene::Scene::from_str(text, name, name, &[]).expect("the shipped case reads")
}

fn terzaghi_of(text: &str) -> Terzaghi {
    Terzaghi::from_scene(&scene_of(text, "terzaghi"))
}

fn mandel_of(text: &str) -> Mandel {
    Mandel::from_scene(&scene_of(text, "mandel"))
}

/// A problem's runs, one per method that ran.
fn runs<'a>(results: &'a [JobResult], problem: &str) -> Vec<&'a JobResult> {
    results
        .iter()
        .filter(|r| r.job.tag_value("problem") == Some(problem))
        .collect()
}

/// Terzaghi's largest pressure RMS over the isochrones run `r` reached.
fn worst_rms(layer: &Terzaghi, r: &JobResult, t_scale: f64) -> f64 {
    ISOCHRONES
        .iter()
        .filter_map(|&tv| at(r, tv, t_scale))
        .map(|(t, p)| layer.score(p, *t).pressure_rms)
        .fold(0.0, f64::max)
}

/// The snapshot at the factor `f` of `scale` (within 0.5 %), with its
/// time.
fn at(r: &JobResult, f: f64, scale: f64) -> Option<&(f64, crate::model::Particles)> {
    r.data()?
        .snapshots
        .iter()
        .find(|(t, _)| (t / scale / f - 1.0).abs() < 5e-3)
}

pub fn report(results: &[JobResult], dir: &Path, quick: bool) -> Result<(String, Vec<PathBuf>)> {
    let layer = terzaghi_of(crate::cases::TERZAGHI);
    let spec = mandel_of(crate::cases::MANDEL);
    let t_scale = layer.height() * layer.height() / layer.cv();
    let m_scale = spec.time_scale();
    let (terz, mand) = (runs(results, "terzaghi"), runs(results, "mandel"));
    let mut md = String::new();
    let _ = writeln!(
        md,
        "Saturated soil, explicit NPC on the CPU (the GPU path and the implicit u–p step have no \
         pore pressure yet). **Terzaghi** (`cases/terzaghi.toml`): a layer H = {} m on H/h = 20, \
         c_v = {} m²/s, T_v = c_v t / H²; RMS of (p − p_exact)/p_start over the particles at \
         each T_v, U from their mean pressure, the top's settlement against the series. \
         **Mandel** (`cases/mandel.toml`): a = {} m on a/h = 20, c = {} m²/s; the centre's \
         pressure over p_start against the closed form, the error in units of p_start (the \
         issue's bound: 3 %); its first column is a run of the same specimen with k/10, whose \
         t c/a² = 0.01 comes four periods of the sudden load's shear ringing after the start \
         (on the case's it comes within the first half period; the chart shows the case's \
         runs). Wall time: the run's stepping on its threads.{}\n",
        sig(layer.height()),
        sig(layer.cv()),
        sig(spec.a),
        sig(spec.c()),
        if quick {
            " Quick: linear only, to 0.2 of each time scale."
        } else {
            ""
        }
    );
    // Terzaghi's table.
    let mut header: Vec<String> = vec!["method".into(), "status".into()];
    header.extend(ISOCHRONES.iter().map(|tv| format!("RMS at T_v {tv}")));
    header.extend(CLASSIC_TV.iter().map(|tv| format!("U at {tv} (exact)")));
    header.extend(["settlement at 0.197".into(), "wall (s)".into()]);
    let particle = runs(results, PARTICLE_TERM);
    let rows: Vec<Vec<String>> = terz
        .iter()
        .chain(&particle)
        .map(|r| {
            let method = r.job.tag_value("method").unwrap_or("");
            let mut row = vec![
                if r.job.tag_value("problem") == Some(PARTICLE_TERM) {
                    format!("{method}, particle term")
                } else {
                    method.to_string()
                },
                super::failure_text(r),
            ];
            for &tv in &ISOCHRONES {
                row.push(at(r, tv, t_scale).map_or("–".into(), |(t, p)| {
                    format!("{} %", sig(100.0 * layer.score(p, *t).pressure_rms))
                }));
            }
            for &tv in &CLASSIC_TV {
                row.push(at(r, tv, t_scale).map_or("–".into(), |(t, p)| {
                    let e = layer.score(p, *t);
                    format!(
                        "{} % ({} %)",
                        sig(100.0 * e.consolidation),
                        sig(100.0 * e.consolidation_exact)
                    )
                }));
            }
            row.push(at(r, 0.197, t_scale).map_or("–".into(), |(t, p)| {
                format!("{:+.1} %", 100.0 * layer.score(p, *t).settlement_rel_error)
            }));
            row.push(r.data().map_or("–".into(), |d| sig(d.wall_seconds)));
            row
        })
        .collect();
    md.push_str(&table(&header, &rows));
    md.push('\n');
    let worst = |r: &JobResult| worst_rms(&layer, r, t_scale);
    if let Some(r) = particle.first() {
        let nodal = terz.iter().map(|r| worst(r)).fold(0.0, f64::max);
        let _ = writeln!(
            md,
            "The row \"particle term\" is equal-order u–p (`solver.pore_volumetric = \
             \"particle\"`: each particle's pressure takes its own −tr L_p / S): its pressure \
             oscillates from particle to particle, worst RMS {} % of p_start, against at most \
             {} % for the nodal term (the default, the rows above); the oscillation chart shows \
             every particle at T_v {OSCILLATION_TV}.\n",
            sig(100.0 * worst(r)),
            sig(100.0 * nodal)
        );
    }
    // Mandel's table.
    let mut header: Vec<String> = vec!["method".into(), "status".into()];
    header.extend(
        MANDEL_TIMES
            .iter()
            .map(|f| format!("centre at t c/a² {f} (exact)")),
    );
    header.push("wall (s)".into());
    let rows: Vec<Vec<String>> = mand
        .iter()
        .map(|r| {
            let mut row = vec![
                r.job.tag_value("method").unwrap_or("").to_string(),
                super::failure_text(r),
            ];
            let early = results.iter().find(|e| {
                e.job.tag_value("problem") == Some("mandel-early")
                    && e.job.tag_value("method") == r.job.tag_value("method")
            });
            for &f in &MANDEL_TIMES {
                let snap = if f == MANDEL_TIMES[0] {
                    early.and_then(|e| at(e, f, m_scale * EARLY_SLOWER).map(|s| (s, EARLY_SLOWER)))
                } else {
                    at(r, f, m_scale).map(|s| (s, 1.0))
                };
                row.push(snap.map_or("–".into(), |((t, p), slower)| {
                    let e = spec.score(p, *t / slower);
                    format!(
                        "{} ({}): {:+.2} %",
                        sig(e.centre),
                        sig(e.centre_exact),
                        100.0 * e.centre_error
                    )
                }));
            }
            row.push(r.data().map_or("–".into(), |d| sig(d.wall_seconds)));
            row
        })
        .collect();
    md.push_str(&table(&header, &rows));
    md.push('\n');
    let mut charts = Vec::new();
    let mut save = |c: &mut LineChart, stem: &str, alt: &str, md: &mut String| -> Result<()> {
        if c.series.is_empty() {
            return Ok(());
        }
        c.place_legend();
        c.size = (900, 520);
        c.save(&dir.join(stem))?;
        charts.extend(["png", "svg"].map(|e| dir.join(format!("{stem}.{e}"))));
        md.push_str(&image(alt, &format!("{stem}.png")));
        Ok(())
    };
    save(
        &mut isochrones(&layer, &terz, t_scale),
        "study-consolidation-isochrones",
        "Terzaghi's isochrones: the particles' pressure over depth against the series",
        &mut md,
    )?;
    save(
        &mut oscillation(&layer, &terz, &particle, t_scale),
        "study-consolidation-oscillation",
        "Terzaghi at T_v 0.1: every particle's pressure, the particle term's oscillating about \
         the series, the nodal term's on it",
        &mut md,
    )?;
    save(
        &mut degree(&terz, &layer, t_scale),
        "study-consolidation-degree",
        "Terzaghi's degree of consolidation U against T_v",
        &mut md,
    )?;
    save(
        &mut mandel_chart(&spec, &mand),
        "study-consolidation-mandel",
        "Mandel's centre pressure against t c/a², the Mandel–Cryer rise",
        &mut md,
    )?;
    save(
        &mut error_time(&layer, &spec, &terz, &mand, t_scale, m_scale),
        "study-consolidation-error-time",
        "each method's error against its wall time",
        &mut md,
    )?;
    Ok((md, charts))
}

/// The first method's particles at each isochrone's T_v, averaged per row
/// (depth below the top over H), beside the series.
fn isochrones(layer: &Terzaghi, terz: &[&JobResult], scale: f64) -> LineChart {
    let mut c = LineChart::new(
        "Terzaghi: isochrones, particles (markers) against the series (dashed)",
        "p / p_start",
        "depth / H",
    );
    let Some(r) = terz.first() else { return c };
    let label = r.job.tag_value("method").unwrap_or("");
    let ps = layer.p_start();
    for (k, &tv) in ISOCHRONES.iter().enumerate() {
        let Some((_, p)) = at(r, tv, scale) else {
            continue;
        };
        let mut rows: Vec<(f64, f64, f64)> = Vec::new(); // (y0, Σ p, n)
        for i in 0..p.len() {
            let y0 = p.x0[i][1];
            match rows.iter_mut().find(|r| (r.0 - y0).abs() < 1e-9) {
                Some(row) => {
                    row.1 += p.pore_pressure[i];
                    row.2 += 1.0;
                }
                None => rows.push((y0, p.pore_pressure[i], 1.0)),
            }
        }
        rows.sort_by(|a, b| a.0.total_cmp(&b.0));
        let depth = |y: f64| (layer.top - y) / layer.height();
        let pts = rows
            .iter()
            .map(|&(y, s, n)| (s / n / ps, depth(y)))
            .collect();
        c.series
            .push(Series::line(format!("{label}, T_v {tv}"), pts, k).markers());
        let exact = (0..=50)
            .map(|j| {
                let y = layer.base + layer.height() * j as f64 / 50.0;
                (layer.pressure_ratio(y, tv), depth(y))
            })
            .collect();
        c.series.push(Series::line("", exact, k).dashed());
    }
    c
}

/// Every particle's p / p_start over depth at `OSCILLATION_TV`: the first
/// method's nodal run and its particle-term run, beside the series.
fn oscillation(
    layer: &Terzaghi,
    terz: &[&JobResult],
    particle: &[&JobResult],
    scale: f64,
) -> LineChart {
    let tv = OSCILLATION_TV;
    let mut c = LineChart::new(
        format!("Terzaghi at T_v {tv}: every particle, nodal against particle volumetric term"),
        "p / p_start",
        "depth / H",
    );
    let ps = layer.p_start();
    let depth = |y: f64| (layer.top - y) / layer.height();
    for (k, (r, what)) in particle
        .first()
        .map(|r| (*r, "particle term"))
        .into_iter()
        .chain(terz.first().map(|r| (*r, "nodal term")))
        .enumerate()
    {
        let Some((_, p)) = at(r, tv, scale) else {
            continue;
        };
        let pts = (0..p.len())
            .map(|i| (p.pore_pressure[i] / ps, depth(p.x0[i][1])))
            .collect();
        let label = format!("{}, {what}", r.job.tag_value("method").unwrap_or(""));
        c.series.push(Series::line(label, pts, [3, 0][k]).scatter());
    }
    let exact = (0..=50)
        .map(|j| {
            let y = layer.base + layer.height() * j as f64 / 50.0;
            (layer.pressure_ratio(y, tv), depth(y))
        })
        .collect();
    c.series
        .push(Series::line("Terzaghi's series", exact, 7).dashed());
    c
}

fn degree(terz: &[&JobResult], layer: &Terzaghi, scale: f64) -> LineChart {
    let mut c = LineChart::new("Terzaghi: degree of consolidation against T_v", "T_v", "U");
    c.log_x = true;
    for (k, r) in terz.iter().enumerate() {
        let Some(d) = r.data() else { continue };
        let pts = d
            .snapshots
            .iter()
            .map(|(t, p)| (t / scale, layer.score(p, *t).consolidation))
            .collect();
        let label = r.job.tag_value("method").unwrap_or("");
        c.series.push(Series::line(label, pts, k).markers());
    }
    let exact = (0..=60)
        .map(|j| {
            let tv = 0.005 * (200.0f64).powf(j as f64 / 60.0);
            (tv, Terzaghi::consolidation(tv))
        })
        .collect();
    c.series
        .push(Series::line("Terzaghi's series", exact, 7).dashed());
    c
}

fn mandel_chart(spec: &Mandel, mand: &[&JobResult]) -> LineChart {
    let mut c = LineChart::new(
        "Mandel: the centre's pore pressure against t c/a²",
        "t c / a²",
        "p / p_start at the centre",
    );
    c.log_x = true;
    let mut x_centre = 0.0;
    for (k, r) in mand.iter().enumerate() {
        let Some(d) = r.data() else { continue };
        let pts = d
            .snapshots
            .iter()
            .map(|(t, p)| {
                let e = spec.score(p, *t);
                (e.time_factor, e.centre)
            })
            .collect();
        x_centre = d.snapshots.first().map_or(0.0, |(_, p)| {
            (0..p.len()).map(|i| p.x0[i][0]).fold(f64::MAX, f64::min)
        });
        let label = r.job.tag_value("method").unwrap_or("");
        c.series.push(Series::line(label, pts, k).markers());
    }
    let exact = (0..=60)
        .map(|j| {
            let f = 0.005 * (200.0f64).powf(j as f64 / 60.0);
            (f, spec.pressure_ratio(x_centre, f))
        })
        .collect();
    c.series
        .push(Series::line("closed form", exact, 7).dashed());
    c
}

/// Per method: Terzaghi's largest isochrone RMS and Mandel's largest
/// centre error (t c/a² ≥ 0.1), each against its run's wall time.
fn error_time(
    layer: &Terzaghi,
    spec: &Mandel,
    terz: &[&JobResult],
    mand: &[&JobResult],
    t_scale: f64,
    m_scale: f64,
) -> LineChart {
    let mut c = LineChart::new(
        "Error against wall time (CPU, explicit)",
        "wall time (s)",
        "error / p_start",
    )
    .log_log();
    for (k, r) in terz.iter().enumerate() {
        let Some(d) = r.data() else { continue };
        let worst = worst_rms(layer, r, t_scale);
        if worst > 0.0 {
            let label = format!("{}, Terzaghi RMS", r.job.tag_value("method").unwrap_or(""));
            c.series
                .push(Series::line(label, vec![(d.wall_seconds, worst)], k).markers());
        }
    }
    for (k, r) in mand.iter().enumerate() {
        let Some(d) = r.data() else { continue };
        let worst = MANDEL_TIMES[1..]
            .iter()
            .filter_map(|&f| at(r, f, m_scale))
            .map(|(t, p)| spec.score(p, *t).centre_error.abs())
            .fold(0.0, f64::max);
        if worst > 0.0 {
            let label = format!("{}, Mandel centre", r.job.tag_value("method").unwrap_or(""));
            c.series
                .push(Series::line(label, vec![(d.wall_seconds, worst)], k).scatter());
        }
    }
    c
}
