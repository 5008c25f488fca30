//! `lme-mpm study NAME`: the papers' comparisons as one command each. A
//! study builds its jobs (method × resolution × backend), runs them spread
//! over the cores, writes `results.csv` and charts (PNG, SVG) to its output
//! folder, and regenerates its section of docs/verification.md.

pub mod block;
pub mod column;
pub mod contact;
pub mod disk;
pub mod dyka;
pub mod granular;
pub mod implicit;
pub mod mms;
pub mod plate;
pub mod results;
pub mod runner;
pub mod stability;

pub use results::{
    Method, backend_slug, backends_of, failure_text, find_tagged, image, main_backend, on_backend,
    sig, table, tag_values,
};

use crate::error::{Error, Result};
use crate::simulation::BackendChoice;
use crate::sweep::record::Record;
use std::path::{Path, PathBuf};

/// Which study.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum StudyName {
    /// Dyka's bar: 7 cell sizes × linear, uGIMP, LME γ = 2, 3, 4 × FE, NPC.
    Dyka,
    /// Elastic block: linear, uGIMP, LME γ = 0.8 and 3 (NPC).
    Block,
    /// 2D plate impact: FE vs NPC fields; regular vs perturbed grids.
    PlateImpact,
    /// Stability map: shape × integrator × case × resolution.
    Stability,
    /// Manufactured aligned vibration, the B-spline paper's study: 8–64
    /// cells × linear, bspline2/3 with and without MLS, the paper's update,
    /// E = 1e7 and 1e8 Pa (hours on 2 cores; `LME_MPM_MMS_CELLS` restricts it).
    Mms,
    /// Rolling disk: linear, uGIMP, LME γ = 2.8, bspline2 × 3 time steps;
    /// error against wall time beside the paper's Table 1.
    Disk,
    /// Soil column collapse: 4 shapes × 2 meshes and GMM-LME on both,
    /// profiles, run-out (1 h 40 min on 2 cores on 2026-11-29, GMM on
    /// mesh 2 the longest run, on one thread the whole time).
    Column,
    /// Cohesionless column collapse from geostatic rest behind a gate:
    /// run-out against the experimental scaling 1.2 H/W for H/W = 0.5, 1
    /// and 2, 4 shapes, pure FLIP and 1 % PIC (about 5 minutes on one core).
    Granular,
    /// Implicit against explicit: the static cantilever (mesh study), Dyka's
    /// bar and the rolling disk, error against wall time per case, and the
    /// Newton iteration's cost split (CPU only).
    Implicit,
    /// Contact between bodies: block on a slab (μ = 0–0.7), two disks
    /// colliding head-on and off-centre, a disk rolling on an elastic slab
    /// (R/h = 10–40), each beside the single shared field; a strip footing
    /// on a Tresca soil against Prandtl's 5.14 c, smooth and rough, three
    /// grids (full run only) (CPU; about 15 minutes, --quick about 1).
    Contact,
    /// The Galerkin meshfree method: the static cantilever (GMM-LME and
    /// GMM-MLS, h = 0.5 … 0.03125, self-convergence and Richardson) and
    /// the rolling disk (GMM-LME γ = 0.8, 1.8, 2.8, GMM-MLS and implicit
    /// MPM Q4 × 3 time steps), the implicit study's GMM rows alone (about
    /// 20 minutes on 2 cores; --quick: seconds).
    Gmm,
    /// All of them, in that order.
    All,
}

impl StudyName {
    pub fn slug(self) -> &'static str {
        match self {
            StudyName::Dyka => "dyka",
            StudyName::Block => "block",
            StudyName::PlateImpact => "plate-impact",
            StudyName::Stability => "stability",
            StudyName::Mms => "mms",
            StudyName::Disk => "disk",
            StudyName::Column => "column",
            StudyName::Granular => "granular",
            StudyName::Implicit => "implicit",
            StudyName::Contact => "contact",
            StudyName::Gmm => "gmm",
            StudyName::All => "all",
        }
    }
}

/// `--backend` of a study.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum StudyBackend {
    /// The CPU path, plus the GPU when a hardware GPU adapter exists.
    Auto,
    Cpu,
    Gpu,
    /// The CPU path and any GPU adapter (software included).
    Both,
}

#[derive(Debug, Clone)]
pub struct StudyOptions {
    pub backend: StudyBackend,
    /// Each study writes into `<out>/<study>/`.
    pub out: PathBuf,
    /// The reduced sweep (a few minutes); never touches the docs.
    pub quick: bool,
    /// Simulations run at once.
    pub jobs: usize,
    /// Markdown file whose study sections are regenerated (full runs only).
    pub doc: Option<PathBuf>,
    /// The doc's section to write instead of `study-<slug>` (its charts then
    /// named `<section>-…` in place of `study-<slug>-…`).
    pub section: Option<String>,
    /// A progress bar (on a terminal).
    pub progress: bool,
    /// A line on stderr per finished run (off a terminal, for logs).
    pub progress_lines: bool,
}

/// What a study produced.
#[derive(Debug, Clone)]
pub struct Report {
    pub study: StudyName,
    /// Markdown for the study's section of docs/verification.md.
    pub markdown: String,
    /// Charts written (PNG, SVG), to copy next to the doc.
    pub charts: Vec<PathBuf>,
    pub results: Vec<runner::JobResult>,
}

/// The backends a study's jobs run on.
pub fn backends(b: StudyBackend) -> Vec<BackendChoice> {
    match b {
        StudyBackend::Cpu => return vec![BackendChoice::Cpu],
        StudyBackend::Gpu => return vec![BackendChoice::Gpu],
        _ => {}
    }
    let adapters = crate::gpu::context::adapters();
    let hardware = adapters.iter().any(|a| !a.is_software());
    match b {
        StudyBackend::Cpu => vec![BackendChoice::Cpu],
        StudyBackend::Gpu => vec![BackendChoice::Gpu],
        StudyBackend::Auto if hardware => vec![BackendChoice::Cpu, BackendChoice::Gpu],
        StudyBackend::Auto => vec![BackendChoice::Cpu],
        StudyBackend::Both if !adapters.is_empty() => vec![BackendChoice::Cpu, BackendChoice::Gpu],
        StudyBackend::Both => vec![BackendChoice::Cpu],
    }
}

/// Runs one study (or all) and writes its outputs.
pub fn run(name: StudyName, opts: &StudyOptions) -> Result<Vec<Report>> {
    let names = match name {
        StudyName::All => vec![
            StudyName::Dyka,
            StudyName::Block,
            StudyName::PlateImpact,
            StudyName::Stability,
            StudyName::Mms,
            StudyName::Disk,
            StudyName::Column,
            StudyName::Granular,
            StudyName::Implicit,
            StudyName::Contact,
            StudyName::Gmm,
        ],
        n => vec![n],
    };
    let backends = backends(opts.backend);
    let mut reports = Vec::new();
    for n in names {
        let dir = opts.out.join(n.slug());
        std::fs::create_dir_all(&dir).map_err(|e| Error::io("cannot create", &dir, e))?;
        let jobs = match n {
            StudyName::Dyka => dyka::jobs(opts.quick, &backends),
            StudyName::Block => block::jobs(opts.quick, &backends),
            StudyName::PlateImpact => plate::jobs(opts.quick, &backends),
            StudyName::Stability => stability::jobs(opts.quick, &backends),
            StudyName::Mms => mms::jobs(opts.quick, &backends)?,
            StudyName::Disk => disk::jobs(opts.quick, &backends),
            StudyName::Column => column::jobs(opts.quick, &backends),
            StudyName::Granular => granular::jobs(opts.quick, &backends),
            StudyName::Implicit => implicit::jobs(opts.quick),
            StudyName::Contact => contact::jobs(opts.quick, &backends),
            StudyName::Gmm => implicit::gmm_jobs(opts.quick),
            StudyName::All => unreachable!(),
        };
        if opts.progress || opts.progress_lines {
            crate::say!("study {}: {} runs on {:?}", n.slug(), jobs.len(), backends);
        }
        let label = format!("study {}", n.slug());
        let results = runner::run_jobs(
            jobs,
            opts.jobs,
            opts.progress,
            opts.progress_lines.then_some(label.as_str()),
        );
        let records: Vec<Record> = results.iter().map(Record::from_job).collect();
        crate::output::write_atomic(
            &dir.join("results.csv"),
            crate::sweep::report::csv(&records).as_bytes(),
        )?;
        let (markdown, charts) = match n {
            StudyName::Dyka => dyka::report(&results, &dir, opts.quick)?,
            StudyName::Block => block::report(&results, &dir, opts.quick)?,
            StudyName::PlateImpact => plate::report(&results, &dir, opts.quick)?,
            StudyName::Stability => stability::report(&results, &dir, opts.quick)?,
            StudyName::Mms => mms::report(&results, &dir, opts.quick)?,
            StudyName::Disk => disk::report(&results, &dir, opts.quick)?,
            StudyName::Column => column::report(&results, &dir, opts.quick)?,
            StudyName::Granular => granular::report(&results, &dir, opts.quick)?,
            StudyName::Implicit => implicit::report(&results, &dir, opts.quick)?,
            StudyName::Contact => contact::report(&results, &dir, opts.quick)?,
            StudyName::Gmm => implicit::gmm_report(&results, &dir, opts.quick)?,
            StudyName::All => unreachable!(),
        };
        // The charts sit beside report.md; the markdown links them in
        // `charts/` as the docs keep them.
        let local = markdown.replace("](charts/", "](");
        crate::output::write_atomic(&dir.join("report.md"), local.as_bytes())?;
        if let (Some(doc), false) = (&opts.doc, opts.quick) {
            publish(doc, n, opts.section.as_deref(), &markdown, &charts)?;
        }
        reports.push(Report {
            study: n,
            markdown,
            charts,
            results,
        });
    }
    Ok(reports)
}

/// Copies the charts next to `doc` (into `charts/`) and replaces the study's
/// section, or `section` with its charts renamed to match.
fn publish(
    doc: &Path,
    n: StudyName,
    section: Option<&str>,
    markdown: &str,
    charts: &[PathBuf],
) -> Result<()> {
    let own = format!("study-{}", n.slug());
    let name = section.unwrap_or(&own);
    let dir = doc.parent().unwrap_or(Path::new(".")).join("charts");
    std::fs::create_dir_all(&dir).map_err(|e| Error::io("cannot create", &dir, e))?;
    let mut markdown = markdown.to_string();
    for c in charts {
        let file = c
            .file_name()
            .expect("chart files have names")
            .to_string_lossy()
            .into_owned();
        let to = file.replacen(&own, name, 1);
        if to != file {
            markdown = markdown.replace(&format!("charts/{file}"), &format!("charts/{to}"));
        }
        std::fs::copy(c, dir.join(&to)).map_err(|e| Error::io("cannot copy", c, e))?;
    }
    let stamp = format!(
        "Generated {} by `lme-mpm study {}` on {}.\n\n",
        crate::bench::today(),
        n.slug(),
        crate::bench::machine()
    );
    crate::docgen::replace_section(doc, name, &(stamp + &markdown))
}
