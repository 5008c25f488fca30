//! Every case file shipped in `cases/`, as a user meets it: `lme-mpm check`
//! and `lme-mpm run` exit 0 and print no line starting with "warning". A
//! case is read from the folder, so a new one is covered without a line
//! here. What a case's run finds (its result line) is other tests' matter.
//!
//! The same runs show that a change moves no number (issue 54): with
//! `LME_MPM_CASE_DIGESTS=FILE` the test writes a digest of every case's
//! CPU outputs (`DIGESTED`) to FILE when FILE does not exist, and fails,
//! naming the cases and files that differ, when it does:
//!   LME_MPM_CASE_DIGESTS=/tmp/d.txt cargo test --release --test suite cases::
//! once on the commit before and once after, on the same machine (the
//! sums' order depends on the thread count).

use lme_mpm::preflight::{self, Limits};
use lme_mpm::scene::Scene;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A case whose whole run would take longer than this (s) at the
/// preflight's conservative speed (`Estimate::hours`, about half the
/// slowest measured throughput) runs to the share of `t_end` that takes
/// this long, so all fifteen stay within about a minute on 2 cores. Its
/// preflight warnings are those of the whole run: `check` reads the case
/// as shipped.
const RUN_SECONDS: f64 = 1.5;

fn cases() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases");
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    v.sort();
    v
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// The lines of `o`'s stdout and stderr that start with "warning".
fn warnings(o: &Output) -> Vec<String> {
    text(o)
        .lines()
        .filter(|l| l.trim_start().to_lowercase().starts_with("warning"))
        .map(String::from)
        .collect()
}

/// `--set` lines that cut `scene`'s run to about `RUN_SECONDS`, with the
/// whole run's sample interval (its default is t_end / 500, which a
/// shorter t_end would bring below the time step), at most a tenth of the
/// shorter run and never below its first time step; none when the whole
/// run is short.
fn shortened(scene: &Scene) -> Vec<String> {
    let plan = preflight::plan(scene, &Limits::default(), rayon::current_num_threads())
        .unwrap_or_else(|e| panic!("{}: preflight: {e}", scene.name));
    let seconds = plan.estimate.hours * 3600.0;
    if seconds <= RUN_SECONDS {
        return Vec::new();
    }
    let t_end = scene.file.solver.t_end * RUN_SECONDS / seconds;
    let sample = plan
        .scene
        .sample_interval
        .min(t_end / 10.0)
        .max(plan.estimate.dt);
    vec![
        format!("solver.t_end={t_end:e}"),
        format!("output.sample_interval={sample:e}"),
    ]
}

/// The outputs whose bytes `LME_MPM_CASE_DIGESTS` compares: the numbers
/// a run writes (summary.json also holds wall-clock times).
const DIGESTED: &[&str] = &["particles.csv", "probes.csv", "energy.csv", "reactions.csv"];

/// 64-bit FNV-1a of `bytes`: stable across toolchains and machines.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// One line per case: its name, then `file=hash` for each `DIGESTED`
/// file the run wrote.
fn digest(name: &str, dir: &Path) -> String {
    let mut line = name.to_string();
    for f in DIGESTED {
        if let Ok(bytes) = std::fs::read(dir.join(f)) {
            line.push_str(&format!(" {f}={:016x}", fnv1a(&bytes)));
        }
    }
    line
}

/// With `LME_MPM_CASE_DIGESTS=FILE`: writes `lines` to FILE when it does
/// not exist, else the cases whose line differs from FILE's.
fn compare_digests(lines: &[String]) -> Vec<String> {
    let Some(file) = std::env::var_os("LME_MPM_CASE_DIGESTS") else {
        return Vec::new();
    };
    let file = PathBuf::from(file);
    let Ok(before) = std::fs::read_to_string(&file) else {
        std::fs::write(&file, lines.join("\n") + "\n").unwrap();
        println!("wrote {} case digests to {}", lines.len(), file.display());
        return Vec::new();
    };
    let before: Vec<&str> = before.lines().collect();
    let mut differ: Vec<String> = lines
        .iter()
        .filter(|l| !before.contains(&l.as_str()))
        .map(|l| format!("outputs differ from {}: now {l}", file.display()))
        .collect();
    if before.len() != lines.len() {
        differ.push(format!(
            "{} cases in {}, {} now",
            before.len(),
            file.display(),
            lines.len()
        ));
    }
    differ
}

#[test]
fn every_case_checks_and_runs_without_a_warning() {
    let bin = env!("CARGO_BIN_EXE_lme-mpm");
    let out = std::env::temp_dir().join(format!("lme-mpm-cases-{}", std::process::id()));
    let cases = cases();
    assert!(cases.len() >= 15, "cases/ holds {} scenes", cases.len());
    let mut failures = Vec::new();
    let mut digests = Vec::new();
    for case in &cases {
        let name = case.file_stem().unwrap().to_string_lossy().into_owned();
        let check = Command::new(bin).arg("check").arg(case).output().unwrap();
        if !check.status.success() {
            failures.push(format!("check {name}: {}\n{}", check.status, text(&check)));
        }
        for w in warnings(&check) {
            failures.push(format!("check {name}: {w}"));
        }
        let scene = Scene::load(case, &[]).unwrap_or_else(|e| panic!("{name}: {e}"));
        let sets = shortened(&scene);
        let dir = out.join(&name);
        let mut run = Command::new(bin);
        run.arg("run")
            .arg(case)
            .args(["--backend", "cpu", "--out"])
            .arg(&dir);
        for s in &sets {
            run.arg("--set").arg(s);
        }
        let o = run.output().unwrap();
        println!("{name}: {sets:?}, exit {}", o.status);
        if !o.status.success() {
            failures.push(format!("run {name} {sets:?}: {}\n{}", o.status, text(&o)));
        }
        for w in warnings(&o) {
            failures.push(format!("run {name} {sets:?}: {w}"));
        }
        digests.push(digest(&name, &dir));
        let _ = std::fs::remove_dir_all(&dir);
    }
    let _ = std::fs::remove_dir_all(&out);
    failures.extend(compare_digests(&digests));
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
