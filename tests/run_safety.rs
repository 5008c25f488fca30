//! Run safety (issue 10): an output folder holds one run, whole; a second
//! run into a folder in use is refused; SIGTERM stops a run with every
//! output at the same time and a checkpoint (exit 143); `resume` continues
//! it so that the CPU path's particles.csv is byte-identical to an
//! uninterrupted run; a damaged checkpoint is refused; progress lines
//! appear on a non-terminal stderr unless --quiet. Issue 25: two signals
//! at once, SIGHUP and GNU timeout still save everything; a closed or full
//! stderr costs nothing; the lock is an OS lock; planted links are not
//! followed; leftover `.tmp` files go; a completed run can be extended; an
//! implicit run with a wall resumes bit for bit.

use crate::common;

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn bin() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_lme-mpm"));
    c.env("NODEVICE_SELECT", "1");
    c
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("lme-mpm-safety-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn run(case: &str, out: &Path, sets: &[&str]) -> Output {
    let mut c = bin();
    c.args(["run", "--backend", "cpu", "--quiet", "--out"])
        .arg(out)
        .arg(common::case(case));
    for s in sets {
        c.arg("--set").arg(s);
    }
    c.output().expect("binary runs")
}

fn resume(dir: &Path, sets: &[&str]) -> Output {
    let mut c = bin();
    c.args(["resume", "--backend", "cpu", "--quiet"]).arg(dir);
    for s in sets {
        c.arg("--set").arg(s);
    }
    c.output().expect("binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&read(&dir.join("summary.json"))).unwrap()
}

/// The time of a CSV file's last row (its first column).
fn last_t(p: &Path) -> f64 {
    let text = read(p);
    let line = text.lines().last().unwrap();
    line.split(',').next().unwrap().parse().unwrap()
}

fn no_tmp_files(dir: &Path) {
    for e in walk(dir) {
        assert!(
            !e.to_string_lossy().ends_with(".tmp"),
            "left behind: {}",
            e.display()
        );
    }
}

fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            out.extend(walk(&p));
        }
        out.push(p);
    }
    out
}

/// Dyka's bar, short: enough steps to interrupt, quick in a debug build.
const DYKA_SHORT: &[&str] = &["solver.t_end=3e-5"];

#[test]
fn a_rerun_replaces_every_file_of_the_earlier_run_and_nothing_else() {
    let out = tmp("rerun");
    // First run: a snapshot every 1e-5 s (4 files with t = 0 and the end).
    let first = run(
        "dyka_bar.toml",
        &out,
        &["solver.t_end=3e-5", "output.vtk_interval=1e-5"],
    );
    assert!(first.status.success(), "{}", stderr(&first));
    assert_eq!(std::fs::read_dir(out.join("vtk")).unwrap().count(), 4);
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    // Second run: fewer snapshots, no particles.csv.
    let second = run(
        "dyka_bar.toml",
        &out,
        &["solver.t_end=1e-5", "output.particles_csv=false"],
    );
    assert!(second.status.success(), "{}", stderr(&second));
    let vtk: Vec<_> = std::fs::read_dir(out.join("vtk")).unwrap().collect();
    assert_eq!(vtk.len(), 1, "stale snapshots of the first run remain");
    assert!(
        !out.join("particles.csv").exists(),
        "the first run's particles.csv remains"
    );
    assert_eq!(
        read(&out.join("notes.txt")),
        "mine",
        "a user's file was touched"
    );
    assert_eq!(summary(&out)["t_end"], 1e-5);
    assert!(
        !out.join("lme-mpm.lock").exists(),
        "the lock outlives the run"
    );
    no_tmp_files(&out);
}

#[test]
fn a_foreign_folder_a_folder_in_use_and_an_unwritable_one_are_refused_before_stepping() {
    // A non-empty folder that is not an output folder: exit 2, named.
    let foreign = tmp("foreign");
    std::fs::create_dir_all(&foreign).unwrap();
    std::fs::write(foreign.join("thesis.tex"), "x").unwrap();
    let o = run("dyka_bar.toml", &foreign, DYKA_SHORT);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("not an lme-mpm output folder"),
        "{}",
        stderr(&o)
    );
    assert!(stderr(&o).contains(&foreign.display().to_string()));
    assert_eq!(std::fs::read_dir(&foreign).unwrap().count(), 1);

    // A folder of a version without a manifest: recognised by its
    // summary.json; lme-mpm's files go, the user's stay.
    let legacy = tmp("legacy");
    std::fs::create_dir_all(legacy.join("vtk")).unwrap();
    std::fs::write(legacy.join("summary.json"), "{}").unwrap();
    std::fs::write(legacy.join("vtk/particles_00007.vtu"), "old").unwrap();
    std::fs::write(legacy.join("probes.csv.tmp"), "half").unwrap();
    std::fs::write(legacy.join("mine.txt"), "keep").unwrap();
    let o = run("dyka_bar.toml", &legacy, &["solver.t_end=2e-6"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!legacy.join("vtk/particles_00007.vtu").exists());
    assert_eq!(read(&legacy.join("mine.txt")), "keep");
    no_tmp_files(&legacy);

    // A folder held by a live run: see
    // a_lock_is_the_os_lock_of_a_live_run_not_a_pid_in_a_file.
    // The lock file of a process that has ended is taken over.
    let busy = tmp("busy");
    std::fs::create_dir_all(&busy).unwrap();
    let mut gone = Command::new("true").spawn().unwrap();
    let dead = gone.id();
    gone.wait().unwrap();
    std::fs::write(busy.join("lme-mpm.lock"), format!("{dead}\n")).unwrap();
    let o = run("dyka_bar.toml", &busy, &["solver.t_end=2e-6"]);
    assert!(
        o.status.success(),
        "stale lock not taken over: {}",
        stderr(&o)
    );
    assert!(!busy.join("lme-mpm.lock").exists());

    // A file named `vtk` where snapshots go: an error before the first step.
    let blocked = tmp("vtkfile");
    let o = run("dyka_bar.toml", &blocked, &["solver.t_end=2e-6"]);
    assert!(o.status.success());
    std::fs::remove_dir_all(blocked.join("vtk")).unwrap();
    std::fs::write(blocked.join("vtk"), "not a folder").unwrap();
    let started = std::time::Instant::now();
    let o = run("dyka_bar.toml", &blocked, &["solver.t_end=1"]);
    assert!(matches!(o.status.code(), Some(1 | 2)), "{}", stderr(&o));
    assert!(stderr(&o).contains("vtk"), "{}", stderr(&o));
    assert!(started.elapsed().as_secs() < 30, "it computed first");
    assert!(
        !blocked.join("summary.json").exists(),
        "the earlier run's summary is still there"
    );
    no_tmp_files(&blocked);

    // An output path under a file.
    let o = run(
        "dyka_bar.toml",
        &blocked.join("vtk").join("sub"),
        &["solver.t_end=2e-6"],
    );
    assert!(matches!(o.status.code(), Some(1 | 2)), "{}", stderr(&o));
    assert!(stderr(&o).contains("error:"), "{}", stderr(&o));
}

/// Starts a CPU run with progress lines on a pipe, sends SIGTERM once
/// `after` lines have come, and returns its output.
fn interrupted(case: &str, out: &Path, sets: &[&str], after: usize) -> (Output, f64) {
    let mut c = bin();
    c.args(["run", "--backend", "cpu", "--out"])
        .arg(out)
        .arg(common::case(case));
    for s in sets {
        c.arg("--set").arg(s);
    }
    let mut child = c
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stderr.take().unwrap()).lines();
    let mut seen = Vec::new();
    for line in lines.by_ref() {
        let line = line.unwrap();
        let progress = line.starts_with("progress:");
        seen.push(line);
        if progress && seen.iter().filter(|l| l.starts_with("progress:")).count() == after {
            break;
        }
    }
    let sent = std::time::Instant::now();
    let kill = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    seen.extend(lines.map_while(|l| l.ok()));
    let status = child.wait().unwrap();
    let waited = sent.elapsed().as_secs_f64();
    (
        Output {
            status,
            stdout: Vec::new(),
            stderr: seen.join("\n").into_bytes(),
        },
        waited,
    )
}

#[test]
fn sigterm_stops_at_a_step_boundary_and_resume_matches_an_uninterrupted_run_bit_for_bit() {
    let sets = &["solver.t_end=3e-5", "output.vtk_interval=1e-5"];
    let whole = tmp("whole");
    let o = run("dyka_bar.toml", &whole, sets);
    assert!(o.status.success(), "{}", stderr(&o));
    // The CPU path repeats itself bit for bit.
    let again = tmp("again");
    assert!(run("dyka_bar.toml", &again, sets).status.success());
    for f in ["particles.csv", "probes.csv", "energy.csv", "reactions.csv"] {
        assert_eq!(
            read(&whole.join(f)),
            read(&again.join(f)),
            "{f} differs run to run"
        );
    }

    let cut = tmp("cut");
    let (o, waited) = interrupted("dyka_bar.toml", &cut, sets, 2);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(143), "{err}");
    println!("SIGTERM to exit: {waited:.3} s");
    let s = summary(&cut);
    assert_eq!(s["status"], "interrupted", "{s}");
    let t1 = s["t"].as_f64().unwrap();
    assert!(t1 > 0.0 && t1 < 3e-5, "t = {t1}");
    for f in ["probes.csv", "energy.csv", "reactions.csv"] {
        assert_eq!(
            last_t(&cut.join(f)),
            t1,
            "{f} does not end at the time reached"
        );
    }
    let pvd = read(&cut.join("particles.pvd"));
    assert!(
        pvd.contains(&format!("timestep=\"{t1}\"")),
        "no snapshot at {t1}: {pvd}"
    );
    assert!(cut.join("particles.csv").exists() && cut.join("checkpoint.lmeck").exists());
    assert!(!cut.join("lme-mpm.lock").exists());
    no_tmp_files(&cut);

    let o = resume(&cut, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(summary(&cut)["resumed_from"], t1);
    for f in [
        "particles.csv",
        "probes.csv",
        "energy.csv",
        "reactions.csv",
        "particles.pvd",
    ] {
        assert_eq!(
            read(&whole.join(f)),
            read(&cut.join(f)),
            "{f}: interrupted at {t1} and resumed differs from the uninterrupted run"
        );
    }
    let snaps = |d: &Path| std::fs::read_dir(d.join("vtk")).unwrap().count();
    assert_eq!(snaps(&whole), snaps(&cut));
}

#[test]
fn resume_from_a_periodic_checkpoint_gives_the_same_particles_on_the_block() {
    let out = tmp("block");
    // No checkpoint at t_end: the one at 2.2 s is what resume continues.
    let sets = &[
        "solver.t_end=3",
        "output.checkpoint_interval=1.1",
        "output.final_checkpoint=false",
    ];
    let o = run("elastic_block.toml", &out, sets);
    assert!(o.status.success(), "{}", stderr(&o));
    let whole = read(&out.join("particles.csv"));
    let probes = read(&out.join("probes.csv"));
    // The last checkpoint is at 2.2 s: resuming redoes 2.2 s → 3 s.
    let o = resume(&out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = summary(&out);
    let from = s["resumed_from"].as_f64().unwrap();
    assert!((2.2..2.5).contains(&from), "resumed from {from}");
    assert_eq!(read(&out.join("particles.csv")), whole);
    assert_eq!(read(&out.join("probes.csv")), probes);

    // Further: a later t_end continues the same run.
    let o = resume(&out, &["solver.t_end=3.5"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(summary(&out)["t"], 3.5);
    // Keys that would change the run are refused.
    let o = resume(&out, &["materials.soil.youngs_modulus=1e9"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

/// Saturated soil resumes too: the pore pressure is in the checkpoint
/// (particles and probes), so the resumed run's files are the whole run's.
#[test]
fn a_saturated_run_resumes_from_its_checkpoint_bit_for_bit() {
    let out = tmp("terzaghi");
    let sets = &[
        "solver.t_end=0.3",
        "output.checkpoint_interval=0.12",
        "output.final_checkpoint=false",
    ];
    let o = run("terzaghi.toml", &out, sets);
    assert!(o.status.success(), "{}", stderr(&o));
    let whole = read(&out.join("particles.csv"));
    let probes = read(&out.join("probes.csv"));
    assert!(whole.lines().next().unwrap().ends_with(",pore_pressure"));
    assert!(probes.lines().next().unwrap().ends_with(",pore_pressure"));
    let o = resume(&out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let from = summary(&out)["resumed_from"].as_f64().unwrap();
    assert!((0.2..0.3).contains(&from), "resumed from {from}");
    assert_eq!(read(&out.join("particles.csv")), whole);
    assert_eq!(read(&out.join("probes.csv")), probes);
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn a_resumed_implicit_run_reports_the_whole_runs_newton_statistics() {
    // The checkpoint carries the Newton counters and the per-sample Newton
    // columns, so summary.json and probes.csv of a resumed run are those
    // of the uninterrupted one (the timers aside).
    let out = tmp("implicit");
    let sets = &[
        "solver.integrator=implicit",
        "solver.cfl=1",
        "solver.t_end=2e-5",
        "output.sample_interval=2e-6",
        "output.checkpoint_interval=1.1e-5",
        "output.final_checkpoint=false",
    ];
    let o = run("dyka_bar.toml", &out, sets);
    assert!(o.status.success(), "{}", stderr(&o));
    let whole = summary(&out)["newton"].clone();
    let probes = read(&out.join("probes.csv"));
    assert!(probes.lines().next().unwrap().contains("newton_iterations"));
    let o = resume(&out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = summary(&out);
    assert!(s["resumed_from"].as_f64().unwrap() > 1e-5, "{s}");
    for key in [
        "steps",
        "iterations_mean",
        "iterations_max",
        "cuts",
        "last_step_residuals",
    ] {
        assert_eq!(s["newton"][key], whole[key], "{key}: {s}");
    }
    assert!(whole["steps"].as_u64().unwrap() > 50, "{whole}");
    assert_eq!(read(&out.join("probes.csv")), probes);
}

#[test]
fn a_damaged_or_missing_checkpoint_is_refused_with_exit_2() {
    let out = tmp("damaged");
    let o = run(
        "dyka_bar.toml",
        &out,
        &["solver.t_end=2e-6", "output.checkpoint_interval=1e-6"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let ck = out.join("checkpoint.lmeck");
    let mut bytes = std::fs::read(&ck).unwrap();
    let mid = bytes.len() / 2;
    bytes[mid] ^= 0x40;
    std::fs::write(&ck, &bytes).unwrap();
    let o = resume(&out, &[]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("checksum"), "{}", stderr(&o));

    std::fs::write(&ck, b"LMEMPMCK\x63\0\0\0rest of a future format....").unwrap();
    let o = resume(&out, &[]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("format 99"), "{}", stderr(&o));

    std::fs::remove_file(&ck).unwrap();
    let o = resume(&out, &[]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("checkpoint"), "{}", stderr(&o));
}

/// Dyka's bar to 1e-5 s on the CPU into `out`, progress lines on (no
/// `--quiet`; stderr is a pipe).
fn dyka_with_progress(out: &Path) -> Output {
    bin()
        .args(["run", "--backend", "cpu", "--out"])
        .arg(out)
        .arg(common::case("dyka_bar.toml"))
        .args(["--set", "solver.t_end=1e-5"])
        .output()
        .unwrap()
}

#[test]
fn progress_lines_on_a_pipe_unless_quiet() {
    let out = tmp("progress");
    let o = dyka_with_progress(&out);
    assert!(o.status.success());
    let err = stderr(&o);
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("progress:")).collect();
    assert!((9..=11).contains(&lines.len()), "{err}");
    assert!(
        lines
            .iter()
            .all(|l| l.contains("particle-steps/s") && l.contains("eta"))
    );
    assert!(lines.last().unwrap().contains("100 %"), "{err}");
    let quiet = run("dyka_bar.toml", &out, &["solver.t_end=1e-5"]);
    assert!(!stderr(&quiet).contains("progress:"));
}

/// Each progress line's percent and rate (particle-steps/s).
fn progress_of(err: &str) -> Vec<(String, f64)> {
    err.lines()
        .filter(|l| l.starts_with("progress:"))
        .map(|l| {
            let percent = l["progress:".len()..].split('%').next().unwrap().trim();
            let words: Vec<&str> = l.split_whitespace().collect();
            let at = words.iter().position(|w| w.starts_with("particle-steps/s"));
            let rate = at.and_then(|i| words[i - 1].parse::<f64>().ok());
            (
                percent.to_string(),
                rate.unwrap_or_else(|| panic!("no rate in {l}")),
            )
        })
        .collect()
}

/// Issue 51: a resumed run repeated its first progress line (the tenth it
/// starts in) and counted the I/O of its set-up against its stepping time,
/// reporting 5.9e12 particle-steps/s. Its lines now count only the steps
/// this process took over the time it stepped.
#[test]
fn a_resumed_runs_progress_counts_its_own_steps_and_repeats_no_line() {
    let out = tmp("progress-resume");
    let first = dyka_with_progress(&out);
    assert!(first.status.success(), "{}", stderr(&first));
    let before = progress_of(&stderr(&first));
    let fastest = before.iter().map(|p| p.1).fold(0.0, f64::max);
    assert!(fastest > 0.0, "{}", stderr(&first));
    let rate0 = summary(&out)["particle_steps_per_second"].as_f64().unwrap();

    let o = bin()
        .args(["resume", "--backend", "cpu"])
        .arg(&out)
        .args(["--set", "solver.t_end=2e-5"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let after = progress_of(&stderr(&o));
    assert!(after.len() >= 5, "{}", stderr(&o));
    assert_eq!(after[0].0, "50", "{}", stderr(&o));
    assert_eq!(after.last().unwrap().0, "100", "{}", stderr(&o));
    // One line a tenth: the one it starts in said once, at the start.
    let mut tenths: Vec<u32> = after
        .iter()
        .map(|p| p.0.parse::<u32>().unwrap() / 10)
        .collect();
    tenths.dedup();
    assert_eq!(tenths.len(), after.len(), "a tenth repeats: {}", stderr(&o));
    // The same scene on the same machine: the same order of speed (10x
    // leaves room for a loaded machine; the bug was 1e6x and more).
    for (percent, rate) in &after {
        assert!(
            *rate <= 10.0 * fastest,
            "{percent} %: {rate:e} particle-steps/s against at most {fastest:e} before: {}",
            stderr(&o)
        );
    }
    let rate1 = summary(&out)["particle_steps_per_second"].as_f64().unwrap();
    assert!(
        rate1 <= 10.0 * rate0,
        "summary: {rate1:e} against {rate0:e}"
    );
}

// ---- issue 25: a run never dies without a word ----

/// Starts a CPU run with progress lines on a pipe and waits for its first
/// progress line (it is stepping, its folder taken); returns the child and
/// the rest of its stderr lines.
fn started(
    case: &str,
    out: &Path,
    sets: &[&str],
) -> (
    std::process::Child,
    std::io::Lines<BufReader<std::process::ChildStderr>>,
) {
    let mut c = bin();
    c.args(["run", "--backend", "cpu", "--out"])
        .arg(out)
        .arg(common::case(case));
    for s in sets {
        c.arg("--set").arg(s);
    }
    let mut child = c
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stderr.take().unwrap()).lines();
    for line in lines.by_ref() {
        if line.unwrap().starts_with("progress:") {
            break;
        }
    }
    (child, lines)
}

/// Sends `signals` (e.g. "-TERM") to `pid` from one shell, back to back.
fn signal(pid: u32, signals: &[&str]) {
    let script: Vec<String> = signals.iter().map(|s| format!("kill {s} {pid}")).collect();
    let ok = Command::new("sh")
        .arg("-c")
        .arg(script.join("; "))
        .status()
        .unwrap();
    assert!(ok.success());
}

/// What an interrupted run must leave: `interrupted`, CSV files ending at
/// the time reached, a checkpoint `resume` accepts, no lock, no `.tmp`.
fn saved_and_unlocked(dir: &Path) {
    let s = summary(dir);
    assert_eq!(s["status"], "interrupted", "{s}");
    let t = s["t"].as_f64().unwrap();
    for f in ["probes.csv", "energy.csv", "reactions.csv"] {
        // serde_json (without its float_roundtrip feature) parses a
        // 17-digit number to within an ulp: seen 1 ulp apart.
        let last = last_t(&dir.join(f));
        assert!(
            (last - t).abs() <= CSV_DIGITS * t,
            "{f}: {last} against {t}"
        );
    }
    assert!(dir.join("checkpoint.lmeck").is_file(), "no checkpoint");
    assert!(
        !dir.join("lme-mpm.lock").exists(),
        "the lock outlives the run"
    );
    no_tmp_files(dir);
}

/// Relative difference allowed between a CSV file's time and summary.json's
/// `t` as this test reads them (serde_json's float parsing is within 1 ulp,
/// 1.1e-16 relative; the files hold the same shortest round-trip digits).
const CSV_DIGITS: f64 = 1e-15;

/// A run long enough to be interrupted (about 30 s alone on one core).
const DYKA_LONG: &[&str] = &["solver.t_end=1e-3"];

#[test]
fn two_signals_at_once_and_sighup_stop_the_run_with_everything_saved() {
    // Two SIGTERMs back to back (what GNU timeout and a process group's
    // kill send): the second must not cut the save short. Before issue
    // 25 the second ended the process at once with summary.json `running`.
    for k in 0..4 {
        let out = tmp(&format!("twice-{k}"));
        let (mut child, lines) = started("dyka_bar.toml", &out, DYKA_LONG);
        signal(child.id(), &["-TERM", "-TERM"]);
        let rest: Vec<String> = lines.map_while(|l| l.ok()).collect();
        let status = child.wait().unwrap();
        assert_eq!(status.code(), Some(143), "try {k}: {}", rest.join("\n"));
        saved_and_unlocked(&out);
        let o = resume(&out, &["solver.t_end=2e-5"]);
        assert!(
            o.status.code() == Some(2) || o.status.success(),
            "{}",
            stderr(&o)
        );
    }
    // SIGHUP (a closed terminal, a dropped SSH session) is a stop like
    // SIGTERM: exit 129, everything saved. Before: exit 129 at once.
    let out = tmp("hup");
    let (mut child, lines) = started("dyka_bar.toml", &out, DYKA_LONG);
    signal(child.id(), &["-HUP"]);
    let rest: Vec<String> = lines.map_while(|l| l.ok()).collect();
    assert_eq!(
        child.wait().unwrap().code(),
        Some(129),
        "{}",
        rest.join("\n")
    );
    saved_and_unlocked(&out);
    assert!(resume(&out, &["solver.t_end=3e-5"]).status.code().is_some());
}

#[test]
fn gnu_timeout_leaves_an_interrupted_resumable_run() {
    // `timeout` signals the process, then its process group: two at once.
    let has_timeout = Command::new("timeout").arg("--version").output();
    if has_timeout.is_err() {
        println!("skipped: no `timeout` command");
        return;
    }
    for k in 0..2 {
        let out = tmp(&format!("timeout-{k}"));
        let o = Command::new("timeout")
            .arg("3")
            .arg(env!("CARGO_BIN_EXE_lme-mpm"))
            .args(["run", "--backend", "cpu", "--quiet", "--out"])
            .arg(&out)
            .arg(common::case("dyka_bar.toml"))
            .args(["--set", DYKA_LONG[0]])
            .env("NODEVICE_SELECT", "1")
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(124), "{}", stderr(&o));
        saved_and_unlocked(&out);
    }
}

#[test]
fn a_closed_or_full_stderr_costs_nothing() {
    // `run … 2>&1 | head -1`: the reader goes after one line; the run
    // goes on to the end and exits 0. Before: exit 101 at the next
    // progress line, nothing written.
    let out = tmp("closed-pipe");
    let mut child = bin()
        .args(["run", "--backend", "cpu", "--out"])
        .arg(&out)
        .arg(common::case("dyka_bar.toml"))
        .args(["--set", "solver.t_end=2e-5"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    {
        let mut first = String::new();
        BufReader::new(child.stderr.take().unwrap())
            .read_line(&mut first)
            .unwrap();
        assert!(!first.is_empty());
    } // the read end closes here
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(0));
    assert_eq!(summary(&out)["status"], "completed");
    assert!(out.join("particles.csv").is_file());

    // 2>/dev/full: every write to stderr fails with ENOSPC.
    if let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") {
        let out = tmp("dev-full");
        let o = bin()
            .args(["run", "--backend", "cpu", "--out"])
            .arg(&out)
            .arg(common::case("dyka_bar.toml"))
            .args(["--set", "solver.t_end=2e-5"])
            .stderr(Stdio::from(full.try_clone().unwrap()))
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0));
        assert_eq!(summary(&out)["status"], "completed");
        // `check > /dev/full`: its product cannot be written: exit 1 and
        // a message, not a panic (101).
        let o = bin()
            .arg("check")
            .arg(common::case("dyka_bar.toml"))
            .stdout(Stdio::from(full))
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        assert!(stderr(&o).contains("cannot write to standard output"));
        assert!(!stderr(&o).contains("panicked"), "{}", stderr(&o));
    }
}

#[cfg(unix)]
#[test]
fn a_link_planted_in_the_folder_is_never_followed() {
    let out = tmp("symlink");
    let o = run("dyka_bar.toml", &out, &["solver.t_end=2e-6"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let victim = tmp("symlink-victim.txt");
    std::fs::write(&victim, "not yours").unwrap();
    for name in ["lme-mpm.manifest.tmp", "summary.json.tmp", "probes.csv.tmp"] {
        std::os::unix::fs::symlink(&victim, out.join(name)).unwrap();
    }
    let o = run("dyka_bar.toml", &out, &["solver.t_end=2e-6"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        read(&victim),
        "not yours",
        "a file outside the folder was written"
    );
    assert_eq!(summary(&out)["status"], "completed");
    no_tmp_files(&out);
    let _ = std::fs::remove_file(&victim);
}

#[test]
fn a_lock_is_the_os_lock_of_a_live_run_not_a_pid_in_a_file() {
    // A lock file naming a live process that is not a run (this test: pid
    // reuse) does not block the folder. Before: refused, exit 2.
    let out = tmp("pid-reuse");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(
        out.join("lme-mpm.lock"),
        format!("{}\n", std::process::id()),
    )
    .unwrap();
    let o = run("dyka_bar.toml", &out, &["solver.t_end=2e-6"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!out.join("lme-mpm.lock").exists());

    // A live run holds its folder: a second run there is refused, naming it.
    let busy = tmp("held");
    let (mut child, _lines) = started("dyka_bar.toml", &busy, DYKA_LONG);
    let o = run("dyka_bar.toml", &busy, &["solver.t_end=2e-6"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains(&format!("process {}", child.id())),
        "{}",
        stderr(&o)
    );
    let o = resume(&busy, &[]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    signal(child.id(), &["-TERM"]);
    assert_eq!(child.wait().unwrap().code(), Some(143));
    saved_and_unlocked(&busy);
}

#[test]
fn leftover_tmp_files_of_a_killed_write_are_removed_by_the_next_run() {
    // A kill during a checkpoint write leaves checkpoint.lmeck.tmp; a
    // completed run without a checkpoint does not list it. Before: kept forever.
    let out = tmp("leftovers");
    let sets = &["solver.t_end=2e-6", "output.final_checkpoint=false"];
    let o = run("dyka_bar.toml", &out, sets);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!out.join("checkpoint.lmeck").exists());
    std::fs::write(out.join("checkpoint.lmeck.tmp"), vec![7u8; 1 << 20]).unwrap();
    std::fs::write(out.join("lme-mpm.manifest.tmp"), "half").unwrap();
    std::fs::create_dir_all(out.join("vtk")).unwrap();
    std::fs::write(out.join("vtk/particles_00009.vtu.tmp"), "half").unwrap();
    std::fs::write(out.join("notes.tmp"), "mine").unwrap();
    let o = run("dyka_bar.toml", &out, sets);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!out.join("checkpoint.lmeck.tmp").exists());
    assert!(!out.join("lme-mpm.manifest.tmp").exists());
    assert!(!out.join("vtk/particles_00009.vtu.tmp").exists());
    assert_eq!(
        read(&out.join("notes.tmp")),
        "mine",
        "a user's file was touched"
    );
    // And a resume removes them too.
    let o = run("dyka_bar.toml", &out, &["solver.t_end=4e-6"]);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::write(out.join("checkpoint.lmeck.tmp"), "half").unwrap();
    let o = resume(&out, &["solver.t_end=6e-6"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!out.join("checkpoint.lmeck.tmp").exists());
}

#[test]
fn a_completed_run_can_be_extended_and_the_key_turns_it_off() {
    // The README's Use list: run, then resume with a later t_end. Before:
    // no checkpoint at the end, exit 2.
    let sets = &["solver.t_end=2e-5"];
    let out = tmp("extend");
    let o = run("dyka_bar.toml", &out, sets);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.join("checkpoint.lmeck").is_file());
    let rows = read(&out.join("probes.csv")).lines().count();
    let o = resume(&out, &["solver.t_end=3e-5"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = summary(&out);
    assert_eq!(
        (s["t"].as_f64(), s["resumed_from"].as_f64()),
        (Some(3e-5), Some(2e-5))
    );
    assert!(read(&out.join("probes.csv")).lines().count() > rows);
    assert_eq!(last_t(&out.join("probes.csv")), 3e-5);
    // Resuming a completed run without a later t_end says how to extend it.
    let o = resume(&out, &[]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("solver.t_end=LATER"), "{}", stderr(&o));

    // A checkpoint interval equal to t_end: one checkpoint, at the end.
    let at_end = tmp("extend-interval");
    let o = run(
        "dyka_bar.toml",
        &at_end,
        &["solver.t_end=2e-5", "output.checkpoint_interval=2e-5"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(resume(&at_end, &["solver.t_end=2.5e-5"]).status.success());

    // output.final_checkpoint = false: none, and resume says so.
    let off = tmp("extend-off");
    let o = run(
        "dyka_bar.toml",
        &off,
        &["solver.t_end=2e-5", "output.final_checkpoint=false"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!off.join("checkpoint.lmeck").exists());
    assert_eq!(resume(&off, &["solver.t_end=3e-5"]).status.code(), Some(2));
}

/// The rolling disk, implicit and coarse, run to 0.04 s with a checkpoint
/// at 0.02 s, then resumed from it in the same folder (with `more` keys):
/// the probes and particles must come out the same, byte for byte.
fn implicit_disk_resumes_bit_for_bit(name: &str, more: &[&str]) {
    let mut sets = vec![
        "solver.integrator=implicit",
        "solver.implicit_mass=lumped",
        "grid.h=0.1",
        "solver.dt=0.005",
        "solver.t_end=0.04",
        "output.sample_interval=0.005",
        "output.vtk_interval=0.04",
        "output.checkpoint_interval=0.02",
        "output.final_checkpoint=false",
    ];
    sets.extend_from_slice(more);
    let whole = tmp(name);
    let o = run("rolling_disk.toml", &whole, &sets);
    assert!(o.status.success(), "{}", stderr(&o));
    let particles = read(&whole.join("particles.csv"));
    let probes = read(&whole.join("probes.csv"));
    let o = resume(&whole, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = summary(&whole);
    assert_eq!(s["resumed_from"].as_f64(), Some(0.02), "{s}");
    assert_eq!(
        read(&whole.join("probes.csv")),
        probes,
        "probes differ after resume"
    );
    assert_eq!(
        read(&whole.join("particles.csv")),
        particles,
        "particles differ after resume"
    );
}

#[test]
fn an_interrupted_implicit_run_with_a_wall_resumes_bit_for_bit() {
    // A friction wall, Newton's held contact states: the checkpoint must
    // carry them, or the resumed steps start Newton elsewhere and end
    // 1e-13 apart.
    implicit_disk_resumes_bit_for_bit("disk-whole", &[]);
}

#[test]
fn an_interrupted_gmm_run_resumes_bit_for_bit() {
    // GMM's node cloud moves with the body and keeps its velocity and
    // acceleration (Newmark's predictor reads them) and each particle its
    // LME multiplier: the checkpoint must carry them all (left without
    // the nodes' acceleration, the probes differ from the 7th row on).
    implicit_disk_resumes_bit_for_bit("disk-gmm", &["solver.method=gmm"]);
}

#[test]
fn a_second_signal_long_after_the_first_ends_a_long_step_with_the_folder_saying_so() {
    // One static Newton step of the cantilever at h = 1.5 cm takes about
    // 11 s on two cores (1.4e5 particles, 1.4 GB; at h = 2.5 cm it took
    // under 3 s, too close to the test's 3 s of signals, and CI saw the
    // step end first): the first SIGTERM waits for its end; a second
    // one past the grace of 2 s ends the process at once, and the folder
    // must then say `interrupted` and hold no lock. Before: the second
    // signal ended it with summary.json `running` and a stale lock.
    let out = tmp("late-second");
    // Not quiet: stderr (a pipe) gets progress lines, the first when
    // stepping begins. A signal before it (during the set-up) would stop
    // the run at the first step boundary, which is not what is tested.
    let mut child = bin()
        .args(["run", "--backend", "cpu", "--out"])
        .arg(&out)
        .arg(common::case("cantilever.toml"))
        .args(["--set", "grid.h=0.015"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    let pipe = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut all = String::new();
        for line in std::io::BufRead::lines(std::io::BufReader::new(pipe)) {
            let line = line.unwrap_or_default();
            if line.starts_with("progress:") {
                let _ = tx.send(());
            }
            all.push_str(&line);
            all.push('\n');
        }
        all
    });
    rx.recv_timeout(std::time::Duration::from_secs(120))
        .expect("no progress line: the run never began stepping");
    // Past the t = 0 sample, inside the first (10 s) step.
    std::thread::sleep(std::time::Duration::from_millis(500));
    signal(child.id(), &["-TERM"]);
    std::thread::sleep(std::time::Duration::from_millis(2500));
    let sent = std::time::Instant::now();
    signal(child.id(), &["-TERM"]);
    let status = child.wait().unwrap();
    let waited = sent.elapsed().as_secs_f64();
    let err = reader.join().unwrap();
    assert_eq!(status.code(), Some(143), "{err}");
    let s = summary(&out);
    assert_eq!(s["status"], "interrupted", "{s}");
    assert!(
        s["reason"].as_str().unwrap().contains("repeated signal"),
        "the step ended before the second signal ({waited:.2} s to exit): {s}"
    );
    assert!(waited < 2.0, "{waited} s to exit after the second signal");
    assert!(
        !out.join("lme-mpm.lock").exists(),
        "the lock outlives the run"
    );
    no_tmp_files(&out);
}

/// summary.json's times read back as the f64 that was written: serde_json
/// parses floats to the nearest f64 only with its `float_roundtrip`
/// feature (Cargo.toml). Without it this value came back 1 ulp off, and
/// the SIGTERM test above failed about one run in six, its summary's t
/// one ulp from its CSVs' last t.
#[test]
fn summary_floats_read_back_exactly() {
    for text in ["3.3633438819843678e-6", "3.4029123262524866e-6", "0.1"] {
        let want: f64 = text.parse().unwrap();
        let got: f64 = serde_json::from_str(text).unwrap();
        assert_eq!(got.to_bits(), want.to_bits(), "{text}");
        let json = serde_json::json!({ "t": want }).to_string();
        let back: serde_json::Value = serde_json::from_str(&json).unwrap();
        assert_eq!(
            back["t"].as_f64().unwrap().to_bits(),
            want.to_bits(),
            "{json}"
        );
    }
}

/// Fails on the first line at which `got` and `want` differ (a whole
/// particles.csv is too long for an assertion message).
fn same_text(got: &str, want: &str, what: &str) {
    let (a, b): (Vec<&str>, Vec<&str>) = (got.lines().collect(), want.lines().collect());
    if let Some(k) = (0..a.len().max(b.len())).find(|&k| a.get(k) != b.get(k)) {
        panic!(
            "{what}: line {k} differs ({} and {} lines):\n got  {:?}\n want {:?}",
            a.len(),
            b.len(),
            a.get(k),
            b.get(k)
        );
    }
}

/// `case` run to `t_end` with one checkpoint at half-time (none at the end)
/// and resumed from it; and run to half-time, then extended to `t_end`:
/// both must give the uninterrupted run's particles and probes byte for
/// byte. Before the checkpoint held every field, resume refused every
/// scene with a contact pair ("the state holds 1600 particles and 3233
/// nodes, the scene 1600 and 9699").
fn contact_case_resumes_bit_for_bit(case: &str, name: &str, t_end: f64) {
    let end = format!("solver.t_end={t_end}");
    let half = format!("solver.t_end={}", t_end / 2.0);
    let every = format!("output.checkpoint_interval={}", t_end / 2.0);
    let csv = "output.particles_csv=true";
    let whole = tmp(&format!("{name}-whole"));
    let o = run(case, &whole, &[&end, csv]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (particles, probes) = (
        read(&whole.join("particles.csv")),
        read(&whole.join("probes.csv")),
    );

    let cut = tmp(&format!("{name}-cut"));
    let o = run(
        case,
        &cut,
        &[&end, csv, &every, "output.final_checkpoint=false"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let o = resume(&cut, &[]);
    assert!(o.status.success(), "{case}: resume failed: {}", stderr(&o));
    // The checkpoint is taken at the first step boundary past half-time.
    let from = summary(&cut)["resumed_from"].as_f64().unwrap();
    assert!(
        (t_end / 2.0..0.6 * t_end).contains(&from),
        "{case}: resumed from {from}"
    );
    same_text(
        &read(&cut.join("probes.csv")),
        &probes,
        &format!("{case} resumed: probes"),
    );
    same_text(
        &read(&cut.join("particles.csv")),
        &particles,
        &format!("{case} resumed: particles"),
    );

    // Extended: run to half-time (its last step shortened to land there),
    // then on to t_end. That shortened step makes it another run than the
    // uninterrupted one (its steps fall elsewhere in the impact), so it
    // cannot match it byte for byte; it must go on from where it stopped
    // and end near the same energy. The bound is 5 %: the disks' exchange
    // takes about a fifth of their energy (docs/methods.md), and where the
    // steps fall moves that loss by 2.8 % of the total (measured here on
    // 2026-12-01); the footing's totals, almost all the footing's own
    // kinetic energy, end 1.4e-11 apart.
    let extended = tmp(&format!("{name}-extended"));
    let o = run(case, &extended, &[&half, csv]);
    assert!(o.status.success(), "{}", stderr(&o));
    let rows = read(&extended.join("energy.csv")).lines().count();
    let o = resume(&extended, &[&end]);
    assert!(o.status.success(), "{case}: extend failed: {}", stderr(&o));
    let s = summary(&extended);
    assert_eq!(s["t"].as_f64(), Some(t_end), "{s}");
    assert!(read(&extended.join("energy.csv")).lines().count() > rows);
    let total = |d: &Path| -> f64 {
        let text = read(&d.join("energy.csv"));
        let last = text.lines().last().unwrap();
        last.rsplit(',').next().unwrap().parse().unwrap()
    };
    let (a, b) = (total(&extended), total(&whole));
    assert!(
        (a - b).abs() <= 0.05 * b.abs(),
        "{case}: extended run ends at total energy {a} J, the uninterrupted one at {b} J"
    );
}

#[test]
fn a_contact_run_resumes_and_extends_bit_for_bit() {
    // The disks meet at about 0.025 s: the checkpoint at 0.02 s is just
    // before, and the resumed part holds the whole impact.
    contact_case_resumes_bit_for_bit("contact_disks.toml", "contact-disks", 0.04);
}

#[test]
fn the_footing_resumes_and_extends_bit_for_bit() {
    // Soil and footing are a contact pair (3 fields' nodes on the grid).
    contact_case_resumes_bit_for_bit("footing.toml", "footing", 0.02);
}

#[test]
fn a_checkpoint_copied_from_another_run_is_refused_naming_both() {
    // Before: resume took it (exit 0) and the folder then held two scenes'
    // files.
    let bar = tmp("copied-bar");
    let o = run("dyka_bar.toml", &bar, &["solver.t_end=4e-6"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let disks = tmp("copied-disks");
    let o = run("contact_disks.toml", &disks, &["solver.t_end=0.002"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let before: Vec<(PathBuf, String)> = ["probes.csv", "summary.json", "energy.csv"]
        .iter()
        .map(|f| (disks.join(f), read(&disks.join(f))))
        .collect();
    std::fs::copy(bar.join("checkpoint.lmeck"), disks.join("checkpoint.lmeck")).unwrap();
    let o = resume(&disks, &["solver.t_end=0.004"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("'dyka_bar'") && err.contains("'contact_disks'"),
        "names neither scene: {err}"
    );
    for (path, text) in &before {
        assert_eq!(&read(path), text, "{} was touched", path.display());
    }

    // The same scene with another setting is another run too.
    let finer = tmp("copied-finer");
    let o = run(
        "dyka_bar.toml",
        &finer,
        &["solver.t_end=4e-6", "solver.cfl=0.2"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::copy(bar.join("checkpoint.lmeck"), finer.join("checkpoint.lmeck")).unwrap();
    let o = resume(&finer, &["solver.t_end=6e-6"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("solver.cfl"), "does not name the key: {err}");
}
