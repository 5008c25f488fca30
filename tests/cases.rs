//! Every case file shipped in `cases/`, as a user meets it: `lme-mpm check`
//! and `lme-mpm run` exit 0 and print no line starting with "warning". A
//! case is read from the folder, so a new one is covered without a line
//! here. What a case's run finds (its result line) is other tests' matter.

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

#[test]
fn every_case_checks_and_runs_without_a_warning() {
    let bin = env!("CARGO_BIN_EXE_lme-mpm");
    let out = std::env::temp_dir().join(format!("lme-mpm-cases-{}", std::process::id()));
    let cases = cases();
    assert!(cases.len() >= 15, "cases/ holds {} scenes", cases.len());
    let mut failures = Vec::new();
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
        let _ = std::fs::remove_dir_all(&dir);
    }
    let _ = std::fs::remove_dir_all(&out);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
