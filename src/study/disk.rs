//! Study `disk`: the disk rolling without slip down an incline (implicit-MPM
//! paper §5.2, Table 1) with linear, uGIMP, LME γ = 2.8 and quadratic
//! B-splines, each at three fixed time steps Δt1 = 2Δt2 = 4Δt3. The error is
//! eq. 67 (relative form, percent) over the centre-of-mass displacement
//! sampled every 0.01 s; charts: error against wall time (the speed–accuracy
//! front) and the displacement history at the smallest step.

use super::runner::{Job, JobResult};
use super::spec::Study;
use super::{Method, backend_slug, image, sig, table};
use crate::cases::ROLLING_DISK;
use crate::chart::{LineChart, Series};
use crate::error::Result;
use crate::exact::rolling::RollingDisk;
use crate::scene::Scene;
use crate::simulation::BackendChoice;
use crate::sweep::report::{self, Curve};
use std::path::{Path, PathBuf};

/// (label, shape, γ) of each method.
pub const METHODS: [Method; 4] = [
    ("linear", "linear", 0.0),
    ("ugimp", "ugimp", 0.0),
    ("lme-g2.8", "lme", 2.8),
    ("bspline2", "bspline2", 0.0),
];

/// Δt1 (s): a Courant number of 0.37 for the P wave at h = 0.025 m; Δt2
/// and Δt3 halve it twice.
pub const DT1: f64 = 5e-5;

/// The paper's Table 1 (error %, at Δt1, Δt2, Δt3).
pub const PAPER_MPM: [f64; 3] = [2.34, 1.27, 0.91];
pub const PAPER_LME_28: [f64; 3] = [0.52, 0.07, 0.06];

/// Interval between the sampled displacements (s).
const SAMPLE: f64 = 0.01;

pub fn t_end(quick: bool) -> f64 {
    if quick { 0.2 } else { 0.5 }
}

/// The time steps: Δt1, Δt2 = Δt1/2 and Δt3 = Δt1/4, or Δt1 alone for
/// `--quick` (the halved steps cost two thirds of a quick sweep).
fn steps(quick: bool) -> Vec<f64> {
    if quick {
        vec![DT1]
    } else {
        vec![DT1, DT1 / 2.0, DT1 / 4.0]
    }
}

/// The snapshot times of a run to `t_end`: every `SAMPLE`.
fn sample_times(t_end: f64) -> Vec<f64> {
    let n = (t_end / SAMPLE).round() as usize;
    (1..=n).map(|k| k as f64 * SAMPLE).collect()
}

/// One run of the disk: `method` (label, shape, γ) at the `k`-th time
/// step `dt` (k from 1) up to `t_end`, its centre sampled every `SAMPLE`.
pub fn job(b: BackendChoice, method: Method, k: usize, dt: f64, t_end: f64) -> Job {
    let mut j = Job::new(
        format!("{}-{}-dt{k}", backend_slug(b), method.0),
        ROLLING_DISK,
        "rolling_disk",
    )
    .set(format!("solver.dt={dt}"))
    .set(format!("solver.t_end={t_end}"))
    .set("output.vtk_interval=1e9")
    .on(b)
    .method(method)
    .tag("dt_index", k)
    .tag("dt", dt);
    j.snapshot_times = sample_times(t_end);
    j
}

/// `lme-mpm study disk`.
pub const STUDY: Study = Study {
    slug: "disk",
    help: "Rolling disk: linear, uGIMP, LME γ = 2.8, bspline2 × 3 time steps; error against wall \
         time beside the paper's Table 1",
    jobs: |quick, backends| Ok(jobs(quick, backends)),
    report,
};

pub fn jobs(quick: bool, backends: &[BackendChoice]) -> Vec<Job> {
    let t_end = t_end(quick);
    let times = sample_times(t_end);
    let methods: Vec<_> = if quick {
        METHODS.iter().filter(|m| m.1 != "ugimp").collect()
    } else {
        METHODS.iter().collect()
    };
    let mut out = Vec::new();
    for &b in backends {
        for &&m in &methods {
            for (k, dt) in steps(quick).into_iter().enumerate() {
                out.push(job(b, m, k + 1, dt, t_end));
            }
        }
        // A stick wall in place of the frictional one: no slip where in
        // contact, so it must roll as on friction; one linear run at Δt1.
        let mut j = Job::new(
            format!("{}-linear-stick", backend_slug(b)),
            stick_variant(),
            "rolling_disk",
        )
        .set(format!("solver.dt={DT1}"))
        .set(format!("solver.t_end={t_end}"))
        .set("output.vtk_interval=1e9")
        .on(b)
        .method(("linear-stick", "linear", 0.0))
        .tag("dt_index", 1)
        .tag("dt", DT1);
        j.snapshot_times = times.clone();
        out.push(j);
        // The error is spatial: one linear run on a grid twice as fine
        // (R/h = 40) shows by how much it shrinks with h.
        if !quick {
            let mut j = Job::new(
                format!("{}-linear-fine", backend_slug(b)),
                ROLLING_DISK,
                "rolling_disk",
            )
            .set(format!("grid.h={FINE_H}"))
            .set(format!("solver.dt={}", DT1 / 2.0))
            .set(format!("solver.t_end={t_end}"))
            .set("output.vtk_interval=1e9")
            .on(b)
            .method(("linear-fine", "linear", 0.0))
            .tag("dt_index", 2)
            .tag("dt", DT1 / 2.0);
            j.snapshot_times = times.clone();
            out.push(j);
        }
    }
    out
}

/// The disk case with its frictional wall made a stick wall (`friction`
/// is refused on a stick wall, and an override cannot remove a key).
pub fn stick_variant() -> String {
    let from = "contact = \"friction\"\nfriction = 0.5";
    assert!(
        ROLLING_DISK.contains(from),
        "cases/rolling_disk.toml changed"
    );
    ROLLING_DISK.replace(from, "contact = \"stick\"")
}

/// Cell size of the finer linear run (m): R/h = 40.
pub const FINE_H: f64 = 0.0125;

/// (t, centre-of-mass u_x) at the snapshots of a run.
pub fn history(r: &JobResult) -> Vec<(f64, f64)> {
    r.data().map_or(Vec::new(), |d| {
        d.snapshots
            .iter()
            .map(|(t, p)| (*t, RollingDisk::centre(p).0[0]))
            .collect()
    })
}

/// Eq. 67 (percent) for a completed run, None otherwise.
pub fn error_percent(exact: &RollingDisk, r: &JobResult) -> Option<f64> {
    if !r.completed() {
        return None;
    }
    let h = history(r);
    (!h.is_empty()).then(|| exact.history_error_percent(&h))
}

pub fn report(results: &[JobResult], dir: &Path, quick: bool) -> Result<(String, Vec<PathBuf>)> {
    let scene = Scene::from_str(ROLLING_DISK, "rolling_disk", "rolling_disk", &[])?;
    let main = super::main_backend(results);
    let runs = super::on_backend(results, &main);
    // The table's methods; the stick and fine runs are reported in the text.
    let mut methods = super::tag_values(runs.iter().copied(), "method");
    methods.retain(|m| *m != "linear-fine" && *m != "linear-stick");
    let d = Disk {
        exact: RollingDisk::from_scene(&scene),
        runs,
        methods,
        dts: steps(quick),
        t_end: t_end(quick),
        main,
    };
    let mut charts = d.error_time_chart(dir)?;
    charts.extend(d.history_chart(dir)?);
    let mut md = d.intro();
    md.push_str(&d.errors_table());
    md.push('\n');
    md.push_str(&d.findings());
    md.push_str(&d.stick());
    md.push_str(&image(
        "eq. 67 error against wall time",
        "study-disk-error-time.png",
    ));
    md.push('\n');
    md.push_str(&image("displacement history", "study-disk-history.png"));
    Ok((md, charts))
}

/// The disk study's runs on one backend and what its report shows of them.
struct Disk<'a> {
    exact: RollingDisk,
    runs: Vec<&'a JobResult>,
    /// The table's methods (not the fine and stick runs).
    methods: Vec<&'a str>,
    dts: Vec<f64>,
    t_end: f64,
    /// The backend the report is about.
    main: String,
}

impl Disk<'_> {
    /// The run of method `m` at the time step of index `k` (0: Δt1).
    fn get(&self, m: &str, k: usize) -> Option<&JobResult> {
        self.runs.iter().copied().find(|r| {
            r.job.tag_value("method") == Some(m)
                && r.job.tag_value("dt_index") == Some((k + 1).to_string().as_str())
        })
    }

    /// The run tagged `method = m` (the fine and stick runs).
    fn tagged(&self, m: &str) -> Option<&JobResult> {
        self.runs
            .iter()
            .copied()
            .find(|r| r.job.tag_value("method") == Some(m))
    }

    fn error(&self, r: &JobResult) -> Option<f64> {
        error_percent(&self.exact, r)
    }

    /// Eq. 67 error against wall time, one curve per method over the steps.
    fn error_time_chart(&self, dir: &Path) -> Result<Vec<PathBuf>> {
        let curves: Vec<Curve> = self
            .methods
            .iter()
            .enumerate()
            .map(|(k, m)| Curve {
                label: m.to_string(),
                points: (0..self.dts.len())
                    .filter_map(|i| {
                        let r = self.get(m, i)?;
                        Some((r.data()?.wall_seconds, self.error(r)?))
                    })
                    .collect(),
                color: k,
                dashed: false,
            })
            .collect();
        let (files, _) = report::front_chart(
            &format!(
                "Rolling disk ({}): eq. 67 error against wall time, Δt1 = 2Δt2 = 4Δt3",
                self.main
            ),
            "error (%)",
            &curves,
            &dir.join("study-disk-error-time"),
        )?;
        Ok(files)
    }

    /// The centre's displacement at the smallest step against the exact one.
    fn history_chart(&self, dir: &Path) -> Result<Vec<PathBuf>> {
        let last = self.dts.len() - 1;
        let mut c = LineChart::new(
            "Rolling disk: centre displacement along x at the smallest Δt",
            "t (s)",
            "u_x (m)",
        );
        for (k, m) in self.methods.iter().enumerate() {
            if let Some(r) = self.get(m, last) {
                c.series.push(Series::line(*m, history(r), k));
            }
        }
        c.series.push(
            Series::line(
                "exact ½ a cos θ t²",
                (0..=100)
                    .map(|i| {
                        let t = self.t_end * i as f64 / 100.0;
                        (t, self.exact.displacement(t)[0])
                    })
                    .collect(),
                7,
            )
            .dashed(),
        );
        c.size = (800, 480);
        c.save(&dir.join("study-disk-history"))?;
        Ok(["study-disk-history.png", "study-disk-history.svg"]
            .map(|f| dir.join(f))
            .to_vec())
    }

    /// What was run, the exact solution and the error measure.
    fn intro(&self) -> String {
        format!(
            "A Neo-Hookean disk (ρ = 7800 kg/m³, E = 200 MPa, ν = 0.3, R = {} m, h = 0.025 m, 2 × 2 particles \
             per cell, NPC) starts at rest on a `friction` wall (μ = 0.5, above the tan θ / 3 that rolling \
             without slip needs) inclined at θ = {}° under vertical gravity. Exact (paper eq. 64): \
             a = (2/3) g sin θ = {} m/s² along the plane. The error is eq. 67 in relative form, \
             100 · sqrt(Σ (u_x − u_x,num)²) / sqrt(Σ u_x²) over the centre-of-mass displacement every {} s \
             up to t = {} s (the paper's figure gives no dimensions; ours are in `cases/rolling_disk.toml`). \
             The paper's Table 1 comes from an implicit code on a triangular mesh with h = 0.01, its time \
             steps unstated; ours are explicit at Δt1 = {} s, Δt2 = Δt1/2, Δt3 = Δt1/4.\n\n",
            sig(self.exact.radius),
            sig(self.exact.theta.to_degrees()),
            sig(self.exact.accel_along()),
            SAMPLE,
            sig(self.t_end),
            DT1
        )
    }

    /// Error and wall time of every method at every step, the paper's rows below.
    fn errors_table(&self) -> String {
        let n = self.dts.len();
        let mut header: Vec<String> = vec!["method".into()];
        for k in 0..n {
            header.push(format!("error Δt{} (%)", k + 1));
            header.push(format!("wall Δt{} (s)", k + 1));
        }
        let mut rows: Vec<Vec<String>> = self
            .methods
            .iter()
            .map(|m| {
                let mut row = vec![m.to_string()];
                for k in 0..n {
                    match self.get(m, k) {
                        Some(r) if r.completed() => {
                            row.push(self.error(r).map_or("-".into(), sig));
                            row.push(r.data().map_or("-".into(), |d| sig(d.wall_seconds)));
                        }
                        Some(r) => {
                            row.push(super::failure_text(r));
                            row.push("-".into());
                        }
                        None => {
                            row.push("-".into());
                            row.push("-".into());
                        }
                    }
                }
                row
            })
            .collect();
        for (name, fig) in [
            ("paper: MPM (implicit)", PAPER_MPM),
            ("paper: GMM-LME γ = 2.8", PAPER_LME_28),
        ] {
            let mut row = vec![name.to_string()];
            for f in fig.iter().take(n) {
                row.push(sig(*f));
                row.push("-".into());
            }
            rows.push(row);
        }
        table(&header, &rows)
    }

    /// What the figures say: does Δt matter, does h?
    fn findings(&self) -> String {
        let last = self.dts.len() - 1;
        let spread: Vec<String> = self
            .methods
            .iter()
            .filter_map(|m| {
                let a = self.error(self.get(m, 0)?)?;
                let b = self.error(self.get(m, last)?)?;
                Some(format!("{m} {} → {} %", sig(a), sig(b)))
            })
            .collect();
        let finer = match (
            self.get("linear", 1).and_then(|r| self.error(r)),
            self.tagged("linear-fine").and_then(|r| self.error(r)),
        ) {
            (Some(a), Some(b)) => format!(
                " Halving h (R/h from 20 to 40, linear at Δt2) takes the error from {} to {} %.",
                sig(a),
                sig(b)
            ),
            _ => String::new(),
        };
        format!(
            "**Findings.** From Δt1 to Δt{}: {}. The explicit step is bounded by the Courant limit, far \
             below what the time integration's accuracy needs, so the error left is spatial, and most of it is \
             the wall's contact. The wall acts at the contact points, the particles whose domain reaches past \
             the plane, with a penalty normal force and Coulomb friction capped by it (docs/methods.md, \
             \"Walls\"): the penalty's damping and the partial slip at the contact's edges, where the normal \
             force is small, slow the disk a little, and the particles' lattice makes its rim a staircase.{finer}\n\n",
            last + 1,
            spread.join("; "),
        )
    }

    /// The stick wall's run, when there is one.
    fn stick(&self) -> String {
        let Some(r) = self.tagged("linear-stick") else {
            return String::new();
        };
        let moved = history(r)
            .last()
            .map_or(0.0, |&(t, u)| u / self.exact.displacement(t)[0]);
        format!(
            "\nWith a `stick` wall instead (linear, Δt1) the disk {}: its centre covers {} % of the exact \
             distance. A stick wall stops the slip at the contact points that press on it (Coulomb with \
             μ = 20), so the disk rolls on it as on the frictional wall.\n\n",
            if r.completed() {
                "completes"
            } else {
                "does not complete"
            },
            sig(100.0 * moved)
        )
    }
}
