//! `lme-mpm bench`: its arguments and handler (throughput points, the peer
//! command, bench.csv and the chart), over `lme_mpm::bench`.

use super::common::{adapter_without_gpu, fail};
use lme_mpm::run::BackendChoice;
use std::path::PathBuf;
use std::process::ExitCode;

/// `lme-mpm bench`'s arguments.
#[derive(clap::Args, Debug)]
pub struct BenchArgs {
    /// Backends to measure.
    #[arg(long, value_enum, default_value_t = BenchBackends::Both)]
    backend: BenchBackends,
    /// GPU adapter (part of its name); an error with --backend cpu.
    #[arg(long)]
    adapter: Option<String>,
    /// Particle counts, comma-separated, each at least 16 (the bench
    /// square's smallest: 2 × 2 cells of 2 × 2 particles).
    #[arg(long, value_delimiter = ',', value_parser = parse_particles, default_values_t = vec![10_000usize, 100_000, 1_000_000])]
    particles: Vec<usize>,
    /// Cases, comma-separated: linear, ugimp, lme-g2, lme-g3, lme-g4, and
    /// lme-g3-stored (GPU: LME weights stored per slot instead of recomputed),
    /// lme-g3-mohr-coulomb (elastoplastic), bspline2, bspline3, bspline2-mls, bspline3-mls,
    /// linear-scatter, linear-patch, bspline2-gather, bspline2-scatter, lme-g3-gather, lme-g3-scatter (GPU:
    /// p2g and forces scattered per particle with float atomics, gathered at nodes, or
    /// scattered per bin summing in registers first, whichever the case does not run by
    /// default).
    #[arg(long, value_delimiter = ',', default_values_t = ["linear", "ugimp", "lme-g2", "lme-g3", "lme-g4"].map(String::from).to_vec())]
    cases: Vec<String>,
    /// Seconds of stepping per point (after one warm-up step): more than 0,
    /// at most 3600.
    #[arg(long, default_value_t = 2.0, value_parser = parse_seconds)]
    seconds: f64,
    /// Folder for bench.csv.
    #[arg(long, default_value = "out/bench")]
    out: PathBuf,
    /// Also rewrite the measured tables in this markdown file (e.g. docs/performance.md).
    #[arg(long)]
    doc: Option<PathBuf>,
    /// Name of the doc section and chart (`bench-NAME`); default: the --backend value.
    #[arg(long)]
    section: Option<String>,
    /// Also run a peer's throughput script after ours, in the same run, and
    /// print our particle-steps/s over its at each size: `sh -c "COMMAND
    /// N1,N2,…"` with the --particles counts appended; it must print lines
    /// `NAME n=N steps=S wall=W particle-steps/s=X`. E.g. --peer
    /// "../shared/bench/peer.sh vulkan" (Taichi's MLS-MPM, installed on first use).
    #[arg(long, value_name = "COMMAND")]
    peer: Option<String>,
}

/// The smallest particle count the bench square holds (`bench::scene`:
/// at least 2 × 2 cells of 2 × 2 particles); a smaller request would
/// measure this many under another name.
const MIN_PARTICLES: usize = 16;
/// The longest `--seconds` per point: an hour.
const MAX_SECONDS: f64 = 3600.0;

/// `--seconds`: a finite time in (0, MAX_SECONDS]. NaN or 0 measured no
/// step and reported 0 particle-steps/s; infinity ran to the step cap.
fn parse_seconds(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number of seconds"))?;
    if v.is_finite() && v > 0.0 && v <= MAX_SECONDS {
        Ok(v)
    } else {
        Err(format!(
            "`{s}` is not a number of seconds in (0, {MAX_SECONDS}] (the stepping time of each point)"
        ))
    }
}

/// One `--particles` count: at least MIN_PARTICLES.
fn parse_particles(s: &str) -> Result<usize, String> {
    let n: usize = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a particle count"))?;
    if n >= MIN_PARTICLES {
        Ok(n)
    } else {
        Err(format!(
            "{n} particles: the bench square holds at least {MIN_PARTICLES} (2 x 2 cells of 2 x 2 particles)"
        ))
    }
}

/// `--backend` of `lme-mpm bench`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum BenchBackends {
    Cpu,
    Gpu,
    /// The CPU path and, when an adapter exists, the GPU (any adapter, software included).
    Both,
}

pub fn bench(args: &BenchArgs) -> ExitCode {
    use lme_mpm::bench;
    let (backends, adapter, particles, seconds) = (
        args.backend,
        args.adapter.as_deref(),
        &args.particles,
        args.seconds,
    );
    let (cases, out, peer) = (&args.cases, args.out.as_path(), args.peer.as_deref());
    let doc = args.doc.as_deref().map(|d| (d, args.section.as_deref()));
    if let Some(code) =
        adapter_without_gpu(&adapter.map(String::from), backends == BenchBackends::Cpu)
    {
        return code;
    }
    let all: Vec<_> = bench::standard_cases()
        .into_iter()
        .chain(bench::extra_cases())
        .collect();
    let mut chosen = Vec::new();
    for c in cases {
        match all.iter().find(|k| &k.label == c) {
            Some(k) => chosen.push(k.clone()),
            None => {
                let known: Vec<_> = all.iter().map(|k| k.label.as_str()).collect();
                eprintln!(
                    "error: unknown bench case `{c}`; known: {}",
                    known.join(", ")
                );
                return ExitCode::from(2);
            }
        }
    }
    let choices: Vec<BackendChoice> = match backends {
        BenchBackends::Cpu => vec![BackendChoice::Cpu],
        BenchBackends::Gpu => vec![BackendChoice::Gpu],
        BenchBackends::Both => {
            let gpu = !lme_mpm::gpu::context::adapters().is_empty();
            if !gpu {
                eprintln!("bench: no GPU adapter, measuring the CPU path only");
            }
            if gpu {
                vec![BackendChoice::Cpu, BackendChoice::Gpu]
            } else {
                vec![BackendChoice::Cpu]
            }
        }
    };
    println!("{}", bench::TABLE_HEADER);
    let mut points = Vec::new();
    for choice in choices {
        match bench::run(choice, adapter, &chosen, particles, seconds, |p| {
            println!("{}", bench::table_row(p))
        }) {
            Ok(p) => points.extend(p),
            Err(e) => return fail(&e),
        }
    }
    let ratios = bench::ratios(&points);
    if !ratios.is_empty() {
        println!("\n{}", bench::ratio_table(&ratios));
    }
    // The peer right after ours, so both see the same machine; a failing
    // peer costs its rows only, never ours.
    let mut peer_failed = None;
    if let Some(command) = peer {
        eprintln!("bench: running the peer `{command}`");
        match bench::peer(command, particles) {
            Ok(p) => {
                for q in &p {
                    println!("{}", bench::table_row(q));
                }
                points.extend(p);
            }
            Err(e) => {
                eprintln!("error: {e}; bench.csv keeps our points");
                peer_failed = Some(e);
            }
        }
    }
    let against_peer = bench::peer_table(&points);
    if let Some(t) = &against_peer {
        println!("\n{t}");
    }
    if let Err(e) = std::fs::create_dir_all(out) {
        eprintln!("error: cannot create {}: {e}", out.display());
        return ExitCode::from(1);
    }
    if let Err(e) =
        lme_mpm::output::write_atomic(&out.join("bench.csv"), bench::csv(&points).as_bytes())
    {
        return fail(&e);
    }
    if let Err(e) = bench::chart(&points, &out.join("bench")) {
        return fail(&e);
    }
    eprintln!(
        "outputs: {0}/bench.csv, {0}/bench.png (and .svg)",
        out.display()
    );
    if let Some((doc, section)) = doc {
        let name = section.map_or_else(|| format!("{backends:?}").to_lowercase(), String::from);
        let charts = doc
            .parent()
            .unwrap_or(std::path::Path::new("."))
            .join("charts");
        if let Err(e) = std::fs::create_dir_all(&charts).map_err(|e| lme_mpm::Error::Io {
            action: "cannot create",
            path: charts.clone(),
            source: e,
        }) {
            return fail(&e);
        }
        if let Err(e) = bench::chart(&points, &charts.join(format!("bench-{name}"))) {
            return fail(&e);
        }
        let adapters: Vec<String> = points
            .iter()
            .filter(|p| p.backend.starts_with("gpu"))
            .map(|p| p.backend.clone())
            .collect::<std::collections::BTreeSet<_>>()
            .into_iter()
            .collect();
        // The command as given, so the table says how to remake it.
        let command: Vec<String> = std::iter::once("lme-mpm".to_string())
            .chain(std::env::args().skip(1))
            .collect();
        let with_gpu = if adapters.is_empty() {
            String::new()
        } else {
            format!(" and {}", adapters.join(", "))
        };
        let mut body = format!(
            "Measured {} on {}{with_gpu} with `{}` (release build).\n\n{}\n",
            bench::today(),
            bench::machine(),
            command.join(" "),
            bench::TABLE_HEADER
        );
        for p in &points {
            body.push_str(&bench::table_row(p));
            body.push('\n');
        }
        if !ratios.is_empty() {
            body.push('\n');
            body.push_str(&bench::ratio_table(&ratios));
        }
        if let Some(t) = &against_peer {
            body.push('\n');
            body.push_str(t);
        }
        body.push_str(&format!(
            "\n![particle-steps per second against particles](charts/bench-{name}.png)\n"
        ));
        let section = format!("bench-{name}");
        if let Err(e) = lme_mpm::docgen::replace_section(doc, &section, &body) {
            return fail(&e);
        }
    }
    match peer_failed {
        // Said above, when it failed.
        Some(e) => ExitCode::from(e.exit_code() as u8),
        None => ExitCode::SUCCESS,
    }
}
