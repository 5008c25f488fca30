//! Study `gmm` (issue 27): the Galerkin meshfree method alone, the
//! implicit study's GMM rows without its explicit and B-spline runs. GMM's
//! cantilever runs (GMM-LME and GMM-MLS) with their table, mesh chart,
//! orders and acceptance, implicit MPM with Q4 on the same scenes for the
//! cost per step; and the rolling disk, GMM's four bases and implicit MPM
//! with Q4 at the three Δt, through the implicit study's disk section.
//!
//! The runs, the disk section and the acceptance are the implicit study's
//! (`super::implicit`), which names nothing here.

use super::implicit::{
    GMM_METHODS, Report, SHAPES, cantilever_error, cantilever_h, cantilever_job, deflection,
    disk_jobs, find, gmm_disk_jobs, gmm_only_jobs, wall,
};
use super::runner::{Job, JobResult};
use super::spec::Study;
use super::{failure_text, image, sig, table};
use crate::error::Result;
use crate::exact::cantilever::PAPER_NONLINEAR;
use crate::sweep::report::{self, Curve};
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// `lme-mpm study gmm`.
pub const STUDY: Study = Study {
    slug: "gmm",
    help: "The Galerkin meshfree method: the static cantilever (GMM-LME and GMM-MLS, h = 0.5 … \
         0.03125, self-convergence and Richardson) and the rolling disk (GMM-LME γ = 0.8, 1.8, \
         2.8, GMM-MLS and implicit MPM Q4 × 3 time steps), the implicit study's GMM rows alone \
         (about 20 minutes on 2 cores; --quick: seconds)",
    jobs: |quick, _| Ok(jobs(quick)),
    report,
};

/// `lme-mpm study gmm`: GMM's cantilever runs, and implicit MPM with Q4
/// on the same scenes for the cost per step (seconds in all); and the
/// rolling disk, GMM's four bases and implicit MPM with Q4 at the three
/// Δt (the implicit study's disk rows without its explicit and B-spline
/// runs; 16 minutes on 2 cores on 2026-11-28; `--quick`: Δt1 to 0.03 s).
pub fn jobs(quick: bool) -> Vec<Job> {
    // The longest first, so they do not trail.
    let mut out: Vec<Job> = gmm_disk_jobs(quick).into_iter().rev().collect();
    out.extend(disk_jobs("implicit", SHAPES[0], quick));
    out.extend(gmm_only_jobs(quick));
    for &h in cantilever_h(quick).iter().rev() {
        out.push(cantilever_job("implicit", SHAPES[0], h));
    }
    out
}

/// `lme-mpm study gmm`'s section.
pub fn report(results: &[JobResult], dir: &Path, quick: bool) -> Result<(String, Vec<PathBuf>)> {
    let r = Report {
        results,
        quick,
        dir,
    };
    let mut md = String::new();
    let charts = section(&r, &mut md)?;
    Ok((md, charts))
}

/// GMM's cantilever runs alone, their table, mesh chart and acceptance;
/// then the disk's section and the cost split when the disk ran.
fn section(rep: &Report, md: &mut String) -> Result<Vec<PathBuf>> {
    let _ = writeln!(
        md,
        "### GMM on the static cantilever\n\nThe static cantilever (`cases/cantilever.toml`, one load step) on \
         GMM's node cloud instead of the grid, the paper's §5.1 settings; the same runs are rows of \
         `lme-mpm study implicit`'s cantilever beside implicit MPM.\n"
    );
    let header: Vec<String> = [
        "method",
        "h (m)",
        "particles",
        "Newton iterations",
        "deflection (m)",
        "error vs 0.67433 (%)",
        "wall (s)",
    ]
    .map(String::from)
    .to_vec();
    let mut rows = Vec::new();
    for (m, _) in GMM_METHODS {
        for (h, r) in rep.runs("implicit", m) {
            let d = r.data();
            rows.push(vec![
                m.to_string(),
                sig(h),
                d.map_or("-".into(), |d| d.particles.to_string()),
                d.and_then(|d| d.newton.as_ref())
                    .map_or("-".into(), |n| n.iterations.to_string()),
                deflection(r).map_or_else(|| failure_text(r), |v| format!("{v:.5}")),
                cantilever_error(r).map_or("-".into(), |e| sig(100.0 * e)),
                wall(r),
            ]);
        }
    }
    md.push_str(&table(&header, &rows));
    md.push('\n');
    let pct = |r: &JobResult| cantilever_error(r).map(|e| 100.0 * e);
    let mut curves = Vec::new();
    for (k, (m, _)) in GMM_METHODS.iter().enumerate() {
        let defl = rep.over_h("implicit", m, deflection);
        curves.push(Curve {
            label: format!("{m} vs 0.67433"),
            points: rep.over_h("implicit", m, pct),
            color: k,
            dashed: false,
        });
        curves.push(Curve {
            label: format!("{m} |δ(h) − δ(h/2)|"),
            points: defl
                .windows(2)
                .map(|w| (w[0].0, 100.0 * (w[0].1 - w[1].1).abs() / PAPER_NONLINEAR))
                .collect(),
            color: k,
            dashed: true,
        });
    }
    let (charts, orders) = report::convergence_chart(
        "Cantilever on GMM's node cloud: free-end deflection error against cell size",
        "cell size h (m)",
        "error relative to 0.67433 m (%)",
        &curves,
        &rep.dir.join("study-gmm-cantilever-mesh"),
    )?;
    md.push_str(&image(
        "GMM cantilever error against cell size",
        "study-gmm-cantilever-mesh.png",
    ));
    let fitted: Vec<String> = curves
        .iter()
        .zip(&orders)
        .filter_map(|(c, p)| Some(format!("{}: {:.2}", c.label, (*p)?)))
        .collect();
    let _ = writeln!(
        md,
        "\n**Orders.** Least-squares slopes over all cell sizes: {}.\n",
        fitted.join("; ")
    );
    let gmm: Vec<_> = GMM_METHODS
        .iter()
        .filter_map(|(m, _)| rep.richardson(m).map(|(p, l, h, d)| (*m, p, l, h, d)))
        .collect();
    rep.gmm_acceptance(md, &gmm);
    cost(rep, md);
    let mut charts = charts;
    if find(rep.results, &[("case", "disk")]).is_some() {
        charts.extend(rep.disk(md, "study-gmm-disk-time")?);
        rep.cost(md);
    }
    Ok(charts)
}

/// GMM's cost against implicit MPM's (Q4) on the same scene: one
/// static step each, so the run's stepping time is the step's.
fn cost(rep: &Report, md: &mut String) {
    let (q4, _) = SHAPES[0];
    let mut rows = Vec::new();
    for (h, r) in rep.runs("implicit", q4) {
        let Some(base) = r.data().map(|d| d.wall_seconds) else {
            continue;
        };
        let mut row = vec![
            sig(h),
            sig(base),
            cantilever_error(r).map_or("-".into(), |e| sig(100.0 * e)),
        ];
        for (m, _) in GMM_METHODS {
            row.push(
                rep.cant("implicit", m, h)
                    .and_then(|g| g.data())
                    .map_or("-".into(), |d| {
                        format!("{} ({}×)", sig(d.wall_seconds), sig(d.wall_seconds / base))
                    }),
            );
        }
        rows.push(row);
    }
    let header: Vec<String> = [
        "h (m)",
        "MPM Q4 step (s)",
        "MPM Q4 error (%)",
        "GMM-LME step (s)",
        "GMM-MLS step (s)",
    ]
    .map(String::from)
    .to_vec();
    let _ = writeln!(
        md,
        "\n**Cost.** One static step each (the run's stepping time), GMM against implicit MPM with Q4 on the \
         same scene; runs share the machine with each other (`--jobs`) and any other work, so compare within a row. The paper measured GMM \
         +10 % (MLS) and +8.5 to 16 % (LME) over MPM on the rolling disk. GMM pays for its neighbour search \
         and basis over clouds of about 6 nodes (Q4: 4), and a Jacobian with more couplings.\n\n{}",
        table(&header, &rows)
    );
}
