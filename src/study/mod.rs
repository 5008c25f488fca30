//! `lme-mpm study NAME`: the papers' comparisons as one command each. A
//! study builds its jobs (method × resolution × backend), runs them spread
//! over the cores, writes `results.csv` and charts (PNG, SVG) to its output
//! folder, and regenerates its section of docs/verification.md.

pub mod block;
pub mod column;
pub mod consolidation;
pub mod contact;
pub mod disk;
pub mod dyka;
pub mod gmm;
pub mod granular;
pub mod implicit;
pub mod mms;
pub mod plate;
pub mod results;
pub mod runner;
pub mod spec;
pub mod stability;

pub use spec::Study;

pub use results::{
    Method, backend_slug, backends_of, failure_text, find_tagged, image, main_backend, on_backend,
    sig, table, tag_values,
};

use crate::error::{Error, Result};
use crate::simulation::BackendChoice;
use crate::sweep::record::Record;
use std::path::{Path, PathBuf};

/// The studies, one line each: `StudyName`'s variant and the study (its
/// file's `STUDY`), in the order of `lme-mpm study --help` and of
/// `all`. The CLI's names and help, `all` and the dispatch of jobs and
/// reports follow from this list; a new study is its file, its `pub mod`
/// above and one line here.
macro_rules! studies {
    ($($name:ident => $study:expr),* $(,)?) => {
        /// Which study.
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        pub enum StudyName {
            $($name,)*
            /// All of them, in that order.
            All,
        }

        /// Every study, in `StudyName`'s order (`all` aside).
        pub const STUDIES: &[&Study] = &[$(&$study),*];

        impl StudyName {
            /// Every name the CLI takes, in its order, `all` last.
            pub const NAMES: &[StudyName] = &[$(StudyName::$name,)* StudyName::All];
        }
    };
}

studies! {
    Dyka => dyka::STUDY,
    Block => block::STUDY,
    PlateImpact => plate::STUDY,
    Stability => stability::STUDY,
    Mms => mms::STUDY,
    Disk => disk::STUDY,
    Column => column::STUDY,
    Granular => granular::STUDY,
    Implicit => implicit::STUDY,
    Contact => contact::STUDY,
    Gmm => gmm::STUDY,
    Consolidation => consolidation::STUDY,
}

/// `all`'s line in `lme-mpm study --help`.
const ALL_HELP: &str = "All of them, in that order";

impl StudyName {
    /// The study; None for `all`.
    pub fn study(self) -> Option<&'static Study> {
        STUDIES.get(self as usize).copied()
    }

    pub fn slug(self) -> &'static str {
        self.study().map_or("all", |s| s.slug)
    }

    /// Its line in `lme-mpm study --help`.
    pub fn help(self) -> &'static str {
        self.study().map_or(ALL_HELP, |s| s.help)
    }

    /// The studies it runs: itself, or every one for `all`.
    pub fn each(self) -> Vec<StudyName> {
        match self {
            StudyName::All => StudyName::NAMES[..STUDIES.len()].to_vec(),
            n => vec![n],
        }
    }
}

impl clap::ValueEnum for StudyName {
    fn value_variants<'a>() -> &'a [Self] {
        StudyName::NAMES
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        Some(clap::builder::PossibleValue::new(self.slug()).help(self.help()))
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
    let names = name.each();
    let backends = backends(opts.backend);
    let mut reports = Vec::new();
    for n in names {
        let dir = opts.out.join(n.slug());
        std::fs::create_dir_all(&dir).map_err(|e| Error::io("cannot create", &dir, e))?;
        let study = n.study().expect("each names the studies, not all");
        let jobs = (study.jobs)(opts.quick, &backends)?;
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
        let (markdown, charts) = (study.report)(&results, &dir, opts.quick)?;
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

#[cfg(test)]
mod tests {
    use super::*;
    use clap::ValueEnum;

    /// One list: every study once under a slug of its own, `StudyName` in
    /// its order, and the CLI's names its slugs then `all`.
    #[test]
    fn the_study_list_names_the_cli() {
        let slugs: Vec<&str> = STUDIES.iter().map(|s| s.slug).collect();
        let unique: std::collections::BTreeSet<&str> = slugs.iter().copied().collect();
        assert_eq!(unique.len(), slugs.len(), "{slugs:?}");
        assert!(!unique.contains("all"), "{slugs:?}");
        for (k, n) in StudyName::NAMES.iter().enumerate() {
            assert_eq!(n.study().map(|s| s.slug), slugs.get(k).copied(), "{n:?}");
            assert_eq!(StudyName::from_str(n.slug(), false), Ok(*n));
            let help = n.help();
            assert!(!help.is_empty() && !help.ends_with('.'), "{n:?}: {help}");
        }
        let cli: Vec<String> = StudyName::value_variants()
            .iter()
            .map(|n| n.to_possible_value().unwrap().get_name().to_string())
            .collect();
        let mut want: Vec<String> = slugs.iter().map(|s| s.to_string()).collect();
        want.push("all".into());
        assert_eq!(cli, want);
        let each: Vec<&str> = StudyName::All.each().iter().map(|n| n.slug()).collect();
        assert_eq!(each, slugs);
        assert_eq!(StudyName::Gmm.each(), vec![StudyName::Gmm]);
    }
}
