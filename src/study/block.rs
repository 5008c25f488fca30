//! Study `block`: the elastic block under the gravity ramp with linear,
//! uGIMP and LME γ = 0.8 and 3 (NPC), as in the paper's Fig. 13. Charts:
//! top settlement against time with the exact quasi-static value, and σ_yy
//! against depth at t_end with the exact line.

use super::runner::{Job, JobResult};
use super::spec::Study;
use super::{Method, backend_slug, image, sig, table};
use crate::cases::ELASTIC_BLOCK;
use crate::chart::{LineChart, Series};
use crate::error::Result;
use crate::exact::Errors;
use crate::exact::column::ElasticColumn;
use crate::model::Model;
use crate::scene::Scene;
use crate::simulation::BackendChoice;
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// (label, shape, γ) of each method.
pub const METHODS: [Method; 4] = [
    ("linear", "linear", 0.0),
    ("ugimp", "ugimp", 0.0),
    ("lme-g0.8", "lme", 0.8),
    ("lme-g3", "lme", 3.0),
];

/// `lme-mpm study block`.
pub const STUDY: Study = Study {
    slug: "block",
    help: "Elastic block: linear, uGIMP, LME γ = 0.8 and 3 (NPC)",
    jobs: |quick, backends| Ok(jobs(quick, backends)),
    report,
};

pub fn jobs(_quick: bool, backends: &[BackendChoice]) -> Vec<Job> {
    // The block is cheap (100 particles): the quick sweep is the full one.
    let mut out = Vec::new();
    for &b in backends {
        for m in METHODS {
            let mut j = Job::new(
                format!("{}-{}", backend_slug(b), m.0),
                ELASTIC_BLOCK,
                "elastic_block",
            )
            .on(b)
            .method(m);
            j.keep_final = true;
            out.push(j);
        }
    }
    out
}

fn column(r: &JobResult) -> Option<&crate::exact::column::ColumnErrors> {
    match r.data()?.errors.as_ref()? {
        Errors::Column(e) => Some(e),
        _ => None,
    }
}

pub fn report(results: &[JobResult], dir: &Path, _quick: bool) -> Result<(String, Vec<PathBuf>)> {
    let scene = Scene::from_str(ELASTIC_BLOCK, "elastic_block", "elastic_block", &[])?;
    let model = Model::new(&scene)?;
    let exact = ElasticColumn::from_scene(&scene, &model);
    let main = super::main_backend(results);
    let mine = super::on_backend(results, &main);
    let mut charts = settlement_chart(&scene, &exact, &mine, dir)?;
    charts.extend(stress_chart(&scene, &exact, &mine, dir)?);
    Ok((text(&scene, &exact, &mine), charts))
}

/// The top probe's settlement against time, each method beside the exact
/// log-strain and small-strain answers.
fn settlement_chart(
    scene: &Scene,
    exact: &ElasticColumn,
    mine: &[&JobResult],
    dir: &Path,
) -> Result<Vec<PathBuf>> {
    let mut c = LineChart::new(
        "Elastic block: settlement of the top probe",
        "t (s)",
        "settlement (m)",
    );
    let mut y_top = None;
    for (k, r) in mine.iter().enumerate() {
        if let Some(d) = r.data() {
            let Some((_, x0)) = d.probe_x0.iter().find(|(n, _)| n == "top") else {
                continue;
            };
            y_top = Some(x0[1]);
            let pts: Vec<(f64, f64)> = d
                .probe("top")
                .iter()
                .map(|(t, s)| (*t, x0[1] - s.x[1]))
                .collect();
            c.series.push(Series::line(
                r.job.tag_value("method").unwrap_or(""),
                pts,
                k,
            ));
        }
    }
    if let Some(y) = y_top {
        let t_end = scene.file.solver.t_end;
        let ts: Vec<f64> = (0..=400).map(|k| t_end * k as f64 / 400.0).collect();
        c.series.push(
            Series::line(
                "exact, log strain",
                ts.iter().map(|&t| (t, exact.settlement(y, t))).collect(),
                7,
            )
            .dashed(),
        );
        c.series.push(
            Series::line(
                "small-strain theory",
                ts.iter()
                    .map(|&t| (t, exact.settlement_small_strain(y, t)))
                    .collect(),
                8,
            )
            .dashed(),
        );
    }
    c.size = (900, 480);
    c.save(&dir.join("study-block-settlement"))?;
    Ok(["study-block-settlement.png", "study-block-settlement.svg"]
        .map(|f| dir.join(f))
        .to_vec())
}

/// Every particle's −σ_yy at t_end against its depth, with the exact
/// weight above it.
fn stress_chart(
    scene: &Scene,
    exact: &ElasticColumn,
    mine: &[&JobResult],
    dir: &Path,
) -> Result<Vec<PathBuf>> {
    let h_block = exact.height;
    let mut c = LineChart::new(
        "Elastic block: σ_yy at t_end against depth",
        "depth below the top, H − Y (m)",
        "−σ_yy (kPa)",
    );
    for (k, r) in mine.iter().enumerate() {
        let Some(p) = r.data().and_then(|d| d.final_particles.as_ref()) else {
            continue;
        };
        let pts: Vec<(f64, f64)> = (0..p.len())
            .map(|i| (h_block - (p.x0[i][1] - exact.base), -p.stress[i][1] / 1e3))
            .collect();
        c.series
            .push(Series::line(r.job.tag_value("method").unwrap_or(""), pts, k).scatter());
    }
    let t_end = scene.file.solver.t_end;
    c.series.push(
        Series::line(
            "exact −ρ0 g (H − Y)",
            vec![
                (0.0, 0.0),
                (h_block, -exact.sigma_yy(exact.base, t_end) / 1e3),
            ],
            7,
        )
        .dashed(),
    );
    c.size = (900, 480);
    c.save(&dir.join("study-block-stress"))?;
    Ok(["study-block-stress.png", "study-block-stress.svg"]
        .map(|f| dir.join(f))
        .to_vec())
}

/// The text: the setup, the table of errors and what the paper found.
fn text(scene: &Scene, exact: &ElasticColumn, mine: &[&JobResult]) -> String {
    let mut md = String::new();
    let h_block = exact.height;
    let t_end = scene.file.solver.t_end;
    let _ = writeln!(
        md,
        "The elastic block (SPEC benchmark 2): 10 m × 10 m, E = 5 MPa, ν = 0, ρ0 = 6000 kg/m³, h = 2 m, 2 × 2 \
         particles per cell, NPC, CFL 0.1, gravity ramped by eq. 45 over T = 20 s. Exact at rest: \
         σ_yy = −ρ0 g (H − Y); top settlement {} m for our incremental (logarithmic-strain) law, {} m in \
         small-strain theory.\n",
        sig(exact.settlement(exact.base + h_block, t_end)),
        sig(exact.settlement_small_strain(exact.base + h_block, t_end))
    );
    let header: Vec<String> = [
        "method",
        "status",
        "top settlement (m)",
        "settlement error",
        "σ_yy bottom error",
        "σ_yy RMS / ρ0gH",
    ]
    .map(String::from)
    .to_vec();
    let rows: Vec<Vec<String>> = mine
        .iter()
        .map(|r| {
            let m = r.job.tag_value("method").unwrap_or("").to_string();
            match column(r) {
                Some(e) if r.completed() => vec![
                    m,
                    "completed".into(),
                    sig(e.settlement_top),
                    sig(e.settlement_rel_error),
                    sig(e.sigma_yy_bottom_rel_error),
                    sig(e.sigma_yy_rms_relative),
                ],
                _ => vec![
                    m,
                    super::failure_text(r),
                    "-".into(),
                    "-".into(),
                    "-".into(),
                    "-".into(),
                ],
            }
        })
        .collect();
    md.push_str(&table(&header, &rows));
    md.push('\n');
    md.push_str(&image(
        "top settlement against time",
        "study-block-settlement.png",
    ));
    let status = |m: &str| {
        mine.iter()
            .find(|r| r.job.tag_value("method") == Some(m))
            .map(|r| {
                if r.completed() {
                    format!(
                        "completes with a settlement error of {}",
                        column(r).map_or("-".into(), |e| sig(e.settlement_rel_error))
                    )
                } else {
                    super::failure_text(r)
                }
            })
    };
    let _ = writeln!(
        md,
        "\n**Settlement.** The paper (Fig. 13) finds Q4 unstable within the first steps, uGIMP more stable than \
         Q4 and close to LME, and LME γ = 0.8 and 3 stable with minimal oscillations and no appreciable \
         difference. Here Q4 {}; uGIMP {}; LME γ = 0.8 {}; LME γ = 3 {}.\n",
        status("linear").unwrap_or_default(),
        status("ugimp").unwrap_or_default(),
        status("lme-g0.8").unwrap_or_default(),
        status("lme-g3").unwrap_or_default()
    );
    md.push_str(&image("σ_yy against depth", "study-block-stress.png"));
    let _ = writeln!(
        md,
        "\n**Stress.** Every particle's −σ_yy at t_end against its reference depth; the exact line is the weight \
         above it. The relative RMS departures are in the table's last column.\n"
    );
    md
}
