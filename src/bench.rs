//! Throughput benchmark: particle-steps per second of a whole step, per
//! backend, shape function and particle count, on a synthetic scene (an
//! elastic square set vibrating by its initial velocity field, so every
//! stage does real work). Used by `lme-mpm bench` and `benches/throughput.rs`.

use crate::backend::Backend;
use crate::error::Result;
use crate::model::Model;
use crate::scene::{Override, Scene};
use crate::simulation::{BackendChoice, BackendSpec, Simulation};
use std::fmt::Write;
use std::io::IsTerminal;
use std::time::Instant;

/// One benchmark configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    /// Label, e.g. "lme-g2".
    pub label: String,
    /// `--set` overrides applied to the synthetic scene.
    pub sets: Vec<String>,
    /// GPU-path choices (the CPU path ignores them).
    pub gpu: crate::gpu::GpuOptions,
}

impl Case {
    pub fn new(label: &str, sets: &[&str]) -> Self {
        Case {
            label: label.to_string(),
            sets: sets.iter().map(|s| s.to_string()).collect(),
            gpu: Default::default(),
        }
    }
}

/// The shape functions the issue's table asks for, with NPC.
pub fn standard_cases() -> Vec<Case> {
    vec![
        Case::new("linear", &["solver.shape=linear"]),
        Case::new("ugimp", &["solver.shape=ugimp"]),
        Case::new("lme-g2", &["solver.shape=lme", "solver.lme_gamma=2"]),
        Case::new("lme-g3", &["solver.shape=lme", "solver.lme_gamma=3"]),
        Case::new("lme-g4", &["solver.shape=lme", "solver.lme_gamma=4"]),
    ]
}

/// Extra cases: LME with weights stored per slot on the GPU (the
/// alternative to recomputing them from λ in each pass), elastoplastic LME
/// (Mohr–Coulomb), the B-splines with and without MLS reconstruction, and
/// `*-scatter`, `*-gather` and `*-patch`: p2g and forces on the GPU as
/// particle-centred scatters with float atomics, node-centred gathers or
/// per-bin scatters summing in registers first, whichever the case does not
/// run by default (`GpuOptions::gather`, `GpuOptions::patch`).
pub fn extra_cases() -> Vec<Case> {
    let mut stored = Case::new("lme-g3-stored", &["solver.shape=lme", "solver.lme_gamma=3"]);
    stored.gpu.lme_stored = true;
    let p2g = |label: &str, sets: &[&str], gather: bool, patch: bool| {
        let mut c = Case::new(label, sets);
        c.gpu.gather = Some(gather);
        c.gpu.patch = Some(patch);
        c
    };
    vec![
        stored,
        p2g("linear-scatter", &["solver.shape=linear"], false, false),
        p2g("linear-patch", &["solver.shape=linear"], false, true),
        p2g("bspline2-gather", &["solver.shape=bspline2"], true, false),
        p2g("bspline2-scatter", &["solver.shape=bspline2"], false, false),
        p2g(
            "lme-g3-scatter",
            &["solver.shape=lme", "solver.lme_gamma=3"],
            false,
            false,
        ),
        p2g(
            "lme-g3-gather",
            &["solver.shape=lme", "solver.lme_gamma=3"],
            true,
            false,
        ),
        // Elastoplastic LME: the square's impact stresses (about 50 kPa)
        // exceed this Mohr–Coulomb strength, so the return mapping runs.
        Case::new(
            "lme-g3-mohr-coulomb",
            &[
                "solver.shape=lme",
                "solver.lme_gamma=3",
                "materials.m.model=mohr_coulomb",
                "materials.m.cohesion=1e4",
                "materials.m.friction_angle=30",
            ],
        ),
        Case::new("bspline2", &["solver.shape=bspline2"]),
        Case::new("bspline3", &["solver.shape=bspline3"]),
        Case::new(
            "bspline2-mls",
            &["solver.shape=bspline2", "solver.mls=true"],
        ),
        Case::new(
            "bspline3-mls",
            &["solver.shape=bspline3", "solver.mls=true"],
        ),
    ]
}

/// A square of `cells`² cells, 2×2 particles per cell, h = 1 m, resting on
/// a wall; its two halves start towards each other at 0.5 m/s, so it
/// vibrates in place (zero net momentum) and every stage does real work.
/// No gravity; t_end far away so a benchmark never reaches it.
pub fn scene(particles: usize, case: &Case) -> Result<Scene> {
    let cells = ((particles as f64 / 4.0).sqrt().round() as usize).max(2);
    let side = cells as f64;
    let half = (cells / 2) as f64;
    let text = format!(
        r#"
name = "bench"
[grid]
h = 1.0
margin = 1.0
[materials.m]
model = "linear_elastic"
density = 1000.0
E = 1e7
nu = 0.3
[bodies.left]
material = "m"
velocity = [0.5, 0.0]
rects = [[0.0, 0.0, {half}, {side}]]
[bodies.right]
material = "m"
velocity = [-0.5, 0.0]
rects = [[{half}, 0.0, {side}, {side}]]
[constraints.wall]
min = [-inf, -inf]
max = [inf, 0.0]
fix = "y"
[solver]
t_end = 1e9
"#
    );
    let overrides = case
        .sets
        .iter()
        .map(|s| Override::parse(s))
        .collect::<std::result::Result<Vec<_>, _>>()?;
    Ok(Scene::from_str(&text, "bench scene", "bench", &overrides)?)
}

/// One measured point.
#[derive(Debug, Clone)]
pub struct Point {
    pub backend: String,
    pub case: String,
    pub particles: usize,
    pub steps: u64,
    pub seconds: f64,
    pub particle_steps_per_second: f64,
    pub bytes_per_particle: f64,
}

/// Times whole steps of `backend` for at least `min_seconds` (after one
/// warm-up step), at most `max_steps`.
pub fn time_steps(
    backend: &mut dyn Backend,
    min_seconds: f64,
    max_steps: u64,
) -> Result<(u64, f64)> {
    backend.advance_steps(1).map_err(halted)?;
    let start = Instant::now();
    let mut steps = 0u64;
    let mut batch = 1u64;
    while start.elapsed().as_secs_f64() < min_seconds && steps < max_steps {
        let b = batch.min(max_steps - steps);
        backend.advance_steps(b).map_err(halted)?;
        steps += b;
        // Grow batches so timer overhead stays small on fast backends.
        if start.elapsed().as_secs_f64() * 20.0 < min_seconds {
            batch = (batch * 2).min(1 << 16);
        }
    }
    Ok((steps, start.elapsed().as_secs_f64()))
}

fn halted(h: crate::backend::Halt) -> crate::Error {
    match h {
        crate::backend::Halt::Failed(e) => e,
        crate::backend::Halt::Unstable(f) => {
            crate::Error::Gpu(format!("the benchmark scene went unstable: {f}"))
        }
    }
}

/// Measures every (case, particle count) on `choice`.
pub fn run(
    choice: BackendChoice,
    adapter: Option<&str>,
    cases: &[Case],
    counts: &[usize],
    min_seconds: f64,
    mut on_point: impl FnMut(&Point),
) -> Result<Vec<Point>> {
    let mut out = Vec::new();
    for case in cases {
        for &n in counts {
            let scene = scene(n, case)?;
            let spec = BackendSpec {
                choice: Some(choice),
                adapter: adapter.map(str::to_string),
                gpu: case.gpu,
                verbose: false,
            };
            let mut sim = Simulation::new(&scene, &spec)?;
            let backend = sim.backend();
            let particles = backend.model().particles.len();
            let (steps, seconds) = time_steps(backend, min_seconds, 100_000)?;
            let p = Point {
                backend: backend.name(),
                case: case.label.clone(),
                particles,
                steps,
                seconds,
                particle_steps_per_second: particles as f64 * steps as f64 / seconds,
                bytes_per_particle: backend.bytes_per_particle(),
            };
            if !std::io::stderr().is_terminal() {
                // Off a terminal (a log), a line per point as it is measured.
                eprintln!(
                    "bench: {} n={} on {}: {:.3e} particle-steps/s ({}/{} points of this backend)",
                    p.case,
                    p.particles,
                    p.backend,
                    p.particle_steps_per_second,
                    out.len() + 1,
                    cases.len() * counts.len()
                );
            }
            on_point(&p);
            out.push(p);
        }
    }
    Ok(out)
}

/// CSV of measured points.
pub fn csv(points: &[Point]) -> String {
    let mut s = String::from(
        "backend,case,particles,steps,seconds,particle_steps_per_second,bytes_per_particle\n",
    );
    for p in points {
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{}",
            p.backend,
            p.case,
            p.particles,
            p.steps,
            p.seconds,
            p.particle_steps_per_second,
            p.bytes_per_particle
        );
    }
    s
}

/// Markdown table row for a point (bytes per particle "-" where unknown:
/// the peer's).
pub fn table_row(p: &Point) -> String {
    let bytes = if p.bytes_per_particle.is_finite() {
        format!("{:.0}", p.bytes_per_particle)
    } else {
        "-".to_string()
    };
    format!(
        "| {} | {} | {} | {} | {:.3} | {:.3e} | {bytes} |",
        p.backend, p.case, p.particles, p.steps, p.seconds, p.particle_steps_per_second,
    )
}

pub const TABLE_HEADER: &str = "| backend | case | particles | steps | seconds | particle-steps/s | bytes/particle |\n|---|---|---|---|---|---|---|";

/// A line describing this machine for the docs: CPU model and thread count.
pub fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string());
    format!("{cpu}, {} threads", rayon::current_num_threads())
}

/// Today's date (UTC) as YYYY-MM-DD, from the system clock.
pub fn today() -> String {
    let days = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs() / 86_400) as i64;
    // Civil-from-days (Howard Hinnant's algorithm).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!("{y:04}-{m:02}-{d:02}")
}

/// GPU/CPU throughput ratio of one (case, particle count), both measured in
/// the same `lme-mpm bench` run.
#[derive(Debug, Clone)]
pub struct Ratio {
    pub case: String,
    pub particles: usize,
    pub cpu: f64,
    pub gpu: f64,
}

/// Pairs CPU and GPU points of the same case and size.
pub fn ratios(points: &[Point]) -> Vec<Ratio> {
    let mut out = Vec::new();
    for g in points.iter().filter(|p| p.backend.starts_with("gpu")) {
        if let Some(c) = points.iter().find(|c| {
            c.backend.starts_with("cpu") && c.case == g.case && c.particles == g.particles
        }) {
            out.push(Ratio {
                case: g.case.clone(),
                particles: g.particles,
                cpu: c.particle_steps_per_second,
                gpu: g.particle_steps_per_second,
            });
        }
    }
    out
}

/// Markdown table of ratios.
pub fn ratio_table(r: &[Ratio]) -> String {
    let mut s = String::from(
        "| case | particles | CPU particle-steps/s | GPU particle-steps/s | GPU / CPU |\n|---|---|---|---|---|\n",
    );
    for x in r {
        let _ = writeln!(
            s,
            "| {} | {} | {:.3e} | {:.3e} | {:.2} |",
            x.case,
            x.particles,
            x.cpu,
            x.gpu,
            x.gpu / x.cpu
        );
    }
    s
}

/// Backend name of the peer's points: `peer: COMMAND`.
pub const PEER_PREFIX: &str = "peer: ";

/// Runs a peer's throughput script, `sh -c "COMMAND N1,N2,…"` (the particle
/// counts appended as one comma-separated argument, as
/// `../shared/bench/peer.sh ARCH` takes them), and reads its points from
/// stdout lines of the form `NAME n=N steps=S wall=W particle-steps/s=X`
/// (the other lines are ignored). The project does not depend on the peer:
/// this only runs what the user names.
pub fn peer(command: &str, sizes: &[usize]) -> Result<Vec<Point>> {
    let list: Vec<String> = sizes.iter().map(usize::to_string).collect();
    let line = format!("{command} {}", list.join(","));
    let out = std::process::Command::new("sh")
        .arg("-c")
        .arg(&line)
        .stderr(std::process::Stdio::inherit())
        .output()
        .map_err(|e| crate::Error::Bench(format!("cannot start `sh -c {line:?}`: {e}")))?;
    if !out.status.success() {
        return Err(crate::Error::Bench(format!(
            "the peer `{line}` failed ({})",
            out.status
        )));
    }
    let points = parse_peer(command, &String::from_utf8_lossy(&out.stdout));
    if points.is_empty() {
        return Err(crate::Error::Bench(format!(
            "the peer `{line}` printed no line with n=… and particle-steps/s=…"
        )));
    }
    Ok(points)
}

/// The points in a peer's output (see [`peer`]).
pub fn parse_peer(command: &str, stdout: &str) -> Vec<Point> {
    stdout
        .lines()
        .filter_map(|l| {
            let mut words = l.split_whitespace();
            let name = words.next()?;
            let (mut n, mut steps, mut wall, mut rate) = (None, 0, f64::NAN, None);
            for w in words {
                match w.split_once('=') {
                    Some(("n", v)) => n = v.parse::<usize>().ok(),
                    Some(("steps", v)) => steps = v.parse().unwrap_or(0),
                    Some(("wall", v)) => wall = v.parse().unwrap_or(f64::NAN),
                    Some(("particle-steps/s", v)) => rate = v.parse::<f64>().ok(),
                    _ => {}
                }
            }
            Some(Point {
                backend: format!("{PEER_PREFIX}{command}"),
                case: name.to_string(),
                particles: n?,
                steps,
                seconds: wall,
                particle_steps_per_second: rate.filter(|r| r.is_finite() && *r > 0.0)?,
                bytes_per_particle: f64::NAN,
            })
        })
        .collect()
}

/// Markdown table of each of our points over the peer's at the nearest
/// particle count (within 10 %: a bench scene's count is the nearest
/// whole grid's), all measured in the same `lme-mpm bench` run.
pub fn peer_table(points: &[Point]) -> Option<String> {
    let (peers, ours): (Vec<&Point>, Vec<&Point>) = points
        .iter()
        .partition(|p| p.backend.starts_with(PEER_PREFIX));
    let mut s = String::from(
        "| backend | case | particles | particle-steps/s | peer particle-steps/s | ours / peer |\n|---|---|---|---|---|---|\n",
    );
    let mut any = false;
    for p in ours {
        let near = peers.iter().min_by(|a, b| {
            let d = |q: &Point| (q.particles as f64 / p.particles as f64).ln().abs();
            d(a).total_cmp(&d(b))
        });
        let Some(q) = near.filter(|q| (q.particles as f64 / p.particles as f64 - 1.0).abs() <= 0.1)
        else {
            continue;
        };
        any = true;
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.3e} | {:.3e} | {:.2} |",
            p.backend,
            p.case,
            p.particles,
            p.particle_steps_per_second,
            q.particle_steps_per_second,
            p.particle_steps_per_second / q.particle_steps_per_second
        );
    }
    any.then_some(s)
}

/// Log-log chart of particle-steps per second against particle count, one
/// line per backend and case; writes `<stem>.png` and `<stem>.svg`.
pub fn chart(points: &[Point], stem: &std::path::Path) -> Result<()> {
    use crate::chart::{LineChart, Series};
    let mut keys: Vec<(String, String)> = Vec::new();
    for p in points {
        let k = (short_backend(&p.backend), p.case.clone());
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    let cases: Vec<&String> = {
        let mut c: Vec<&String> = keys.iter().map(|k| &k.1).collect();
        c.dedup();
        c.sort();
        c.dedup();
        c
    };
    let mut c = LineChart::new(
        "Throughput of whole steps (NPC)",
        "particles",
        "particle-steps per second",
    )
    .log_log();
    for (backend, case) in &keys {
        let pts: Vec<(f64, f64)> = points
            .iter()
            .filter(|p| &short_backend(&p.backend) == backend && &p.case == case)
            .map(|p| (p.particles as f64, p.particle_steps_per_second))
            .collect();
        let color = cases.iter().position(|c| *c == case).unwrap_or(0);
        let s = Series::line(format!("{backend} {case}"), pts, color).markers();
        c.series.push(if backend == "cpu" { s } else { s.dashed() });
    }
    c.size = (900, 560);
    c.place_legend();
    c.save(stem)
}

/// "cpu" or "gpu" from a backend's full name; "gpu (software)" for a
/// software adapter such as llvmpipe (wgpu's device type `Cpu`), which is
/// no measure of a GPU.
fn short_backend(name: &str) -> String {
    let short = name.split([' ', ':']).next().unwrap_or(name);
    if short == "gpu" && name.contains(", Cpu)") {
        "gpu (software)".to_string()
    } else {
        short.to_string()
    }
}

/// Time spent in one stage (CPU) or pass (GPU), per particle-step.
#[derive(Debug, Clone)]
pub struct StageTime {
    pub name: String,
    /// Nanoseconds per particle-step.
    pub ns_per_particle_step: f64,
    /// CPU time of the whole process (every thread, the software
    /// adapter's included), nanoseconds per particle-step. On a shared
    /// machine this moves less with the load than the wall time does, so
    /// it is what A/B comparisons of a software adapter's passes use.
    pub cpu_ns_per_particle_step: f64,
}

/// CPU time (user + system) of this process so far, every thread (s).
fn process_cpu_seconds() -> f64 {
    // SAFETY: getrusage writes the struct it is given and nothing else.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    if unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) } != 0 {
        return 0.0;
    }
    let tv = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    tv(u.ru_utime) + tv(u.ru_stime)
}

/// Per-stage breakdown of the CPU path: `steps` whole steps, each stage
/// timed on its own (`CpuBackend::run_stage_passes`), after one warm-up step.
pub fn profile_cpu(particles: usize, case: &Case, steps: u64) -> Result<Vec<StageTime>> {
    use crate::cpu::CpuBackend;
    use crate::step::STEP;
    let model = Model::new(&scene(particles, case)?)?;
    let n = model.particles.len() as f64;
    let mut cpu = CpuBackend::new(model);
    cpu.step().map_err(|f| halted(f.into()))?;
    let mut t = vec![0.0f64; STEP.len()];
    for _ in 0..steps {
        for (k, stage) in STEP.iter().enumerate() {
            let start = Instant::now();
            cpu.run_stage_passes(*stage).map_err(|f| halted(f.into()))?;
            t[k] += start.elapsed().as_secs_f64();
        }
    }
    Ok(STEP
        .iter()
        .zip(t)
        .map(|(s, t)| StageTime {
            name: format!("{s:?}"),
            ns_per_particle_step: t * 1e9 / (n * steps as f64),
            cpu_ns_per_particle_step: f64::NAN,
        })
        .collect())
}

/// Per-pass breakdown of the GPU path: `steps` whole steps, each pass
/// submitted on its own and waited for (the wait's own cost, measured on
/// an empty submission, is subtracted).
pub fn profile_gpu(
    adapter: Option<&str>,
    particles: usize,
    case: &Case,
    steps: u64,
) -> Result<Vec<StageTime>> {
    use crate::gpu::GpuBackend;
    use crate::gpu::pipelines::Pass;
    let model = Model::new(&scene(particles, case)?)?;
    let n = model.particles.len() as f64;
    let ctx = crate::gpu::context::open(&crate::gpu::context::AdapterRequest {
        name: adapter.map(str::to_string),
        allow_software: true,
        force_cas: false,
    })?;
    let mut gpu = GpuBackend::with_options(ctx, model, case.gpu)?;
    gpu.advance_steps(1).map_err(halted)?;
    let passes: Vec<Pass> = gpu.plan().gpu_step.clone();
    // Cost of a submission and wait alone.
    let start = Instant::now();
    let cpu_start = process_cpu_seconds();
    for _ in 0..20 {
        gpu.read_sim()?;
    }
    let wait = start.elapsed().as_secs_f64() / 20.0;
    let cpu_wait = (process_cpu_seconds() - cpu_start) / 20.0;
    let mut t = vec![0.0f64; passes.len()];
    let mut c = vec![0.0f64; passes.len()];
    for _ in 0..steps {
        for (k, pass) in passes.iter().enumerate() {
            let start = Instant::now();
            let cpu_start = process_cpu_seconds();
            gpu.run_pass(*pass);
            gpu.read_sim()?;
            t[k] += (start.elapsed().as_secs_f64() - wait).max(0.0);
            c[k] += (process_cpu_seconds() - cpu_start - cpu_wait).max(0.0);
        }
    }
    if let Some(f) = gpu.fault() {
        return Err(halted(f.into()));
    }
    Ok(passes
        .iter()
        .zip(t.iter().zip(c))
        .map(|(p, (t, c))| StageTime {
            name: format!("{p:?}"),
            ns_per_particle_step: t * 1e9 / (n * steps as f64),
            cpu_ns_per_particle_step: c * 1e9 / (n * steps as f64),
        })
        .collect())
}
