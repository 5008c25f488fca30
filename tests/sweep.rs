//! `lme-mpm sweep`: a local sweep and the same sweep emitted as shell lines,
//! run by `sh` and collected, give the same table (wall times aside); runs
//! without an exact solution are scored against their series' finest run;
//! unstable, killed and missing runs are rows with their reason; bad input
//! exits 2 before anything runs. Small scenes (Dyka's bar at h = 1 cm, a
//! few hundred steps), so the file runs in seconds.

use crate::common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_lme-mpm"))
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("lme-mpm-sweep-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// `lme-mpm sweep --collect DIR`, which must succeed.
fn collect(dir: &Path) {
    let o = bin()
        .arg("sweep")
        .arg("--collect")
        .arg(dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
}

/// Dyka's bar without its exact solution: the sweep must fall back on
/// comparing runs with the finest of their series.
fn bar_without_exact(dir: &Path) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let text = std::fs::read_to_string(common::case("dyka_bar.toml")).unwrap();
    let text: String = text
        .lines()
        .filter(|l| !l.starts_with("exact"))
        .map(|l| format!("{l}\n"))
        .collect();
    let p = dir.join("bar.toml");
    std::fs::write(&p, text).unwrap();
    p
}

/// A CSV line split into fields (quotes honoured).
fn fields(line: &str) -> Vec<String> {
    let (mut out, mut cur, mut quoted) = (Vec::new(), String::new(), false);
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            '"' => quoted = !quoted,
            ',' if !quoted => out.push(std::mem::take(&mut cur)),
            c => cur.push(c),
        }
    }
    out.push(cur);
    out
}

/// sweep.csv as rows of column → value.
fn table(dir: &Path) -> Vec<BTreeMap<String, String>> {
    let text = std::fs::read_to_string(dir.join("sweep.csv")).unwrap();
    let mut lines = text.lines();
    let header = fields(lines.next().unwrap());
    lines
        .map(|l| header.iter().cloned().zip(fields(l)).collect())
        .collect()
}

/// Every column but what depends on the machine's speed and thread count.
fn without_timing(rows: &[BTreeMap<String, String>]) -> Vec<BTreeMap<String, String>> {
    rows.iter()
        .map(|r| {
            r.iter()
                .filter(|(k, _)| {
                    !["wall_seconds", "particle_steps_per_second", "backend"].contains(&k.as_str())
                })
                .map(|(k, v)| (k.clone(), v.clone()))
                .collect()
        })
        .collect()
}

/// The sweep both tests run: 2 integrators × 4 fixed time steps, the last
/// 20 times the Courant limit (it goes unstable within a few steps).
const SWEEP: [&str; 8] = [
    "--vary",
    "solver.integrator=fe,npc",
    "--vary",
    "solver.dt=5e-7,2.5e-7,1.25e-7,4e-6",
    "--set",
    "grid.h=0.01",
    "--set",
    "solver.shape=linear",
];

fn sweep_cmd(scene: &Path) -> Command {
    let mut c = bin();
    c.arg("sweep")
        .arg(scene)
        .args(SWEEP)
        .args(["--backend", "cpu"]);
    c
}

#[test]
fn emitted_lines_run_by_sh_collect_to_the_local_table() {
    let dir = tmp("emit");
    let scene = bar_without_exact(&dir);
    let (local, remote) = (dir.join("local"), dir.join("remote"));
    // --jobs 1: each run gets every core, as a line run alone by sh does
    // (the CPU path's sums depend on the thread count, not on anything else).
    let o = sweep_cmd(&scene)
        .args(["--jobs", "1", "--quiet", "--out"])
        .arg(&local)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));

    let jobs = dir.join("jobs.txt");
    let o = sweep_cmd(&scene)
        .arg("--out")
        .arg(&remote)
        .arg("--emit-jobs")
        .arg(&jobs)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    // Nothing ran: only the plan and each run's plan entry exist.
    assert!(!remote.join("sweep.csv").exists());
    for e in std::fs::read_dir(remote.join("runs")).unwrap() {
        let names: Vec<_> = std::fs::read_dir(e.unwrap().path())
            .unwrap()
            .map(|f| f.unwrap().file_name())
            .collect();
        assert_eq!(names, ["sweep-run.json"]);
    }
    assert_eq!(std::fs::read_dir(remote.join("runs")).unwrap().count(), 8);
    let text = std::fs::read_to_string(&jobs).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 8, "one line per run:\n{text}");
    for l in &lines {
        assert!(
            l.contains(" run ") && l.contains("--out") && l.contains("--set"),
            "{l}"
        );
    }
    // Each line on its own, as a scheduler would (a failing line does not stop the rest).
    for l in &lines {
        let o = Command::new("sh").arg("-c").arg(l).output().unwrap();
        let code = o.status.code();
        assert!(
            code == Some(0) || code == Some(3),
            "{l}: exit {code:?}\n{}",
            stderr(&o)
        );
    }
    collect(&remote);

    let (a, b) = (table(&local), table(&remote));
    assert_eq!(a.len(), 8);
    assert_eq!(without_timing(&a), without_timing(&b));

    // What the table says, on its own terms.
    for r in &a {
        let dt: f64 = r["solver.dt"].parse().unwrap();
        if dt > 1e-6 {
            assert_eq!(r["status"], "unstable", "{r:?}");
            assert_eq!(r["reason_code"], "energy_runaway", "{r:?}");
            assert!(!r["reason"].is_empty());
        } else {
            assert_eq!(r["status"], "completed", "{r:?}");
        }
        if dt == 1.25e-7 {
            assert_eq!(r["error_source"], "reference");
        } else if dt < 1e-6 {
            // Same particles at every Δt: probes and final fields both compare.
            assert!(r["error_source"].starts_with("finest run "), "{r:?}");
            for k in [
                "ref_probe_u_rms",
                "ref_particles_v_rms",
                "ref_probe_stress_rms",
            ] {
                let e: f64 = r[k].parse().unwrap();
                assert!(e > 0.0 && e.is_finite(), "{k} = {e}");
            }
        }
    }
    // Halving Δt towards the reference shrinks the difference from it.
    for integ in ["fe", "npc"] {
        let e = |dt: &str| -> f64 {
            a.iter()
                .find(|r| r["solver.integrator"] == integ && r["solver.dt"] == dt)
                .unwrap()["ref_probe_u_rms"]
                .parse()
                .unwrap()
        };
        assert!(e("2.5e-7") < e("5e-7"), "{integ}");
    }
    let md = std::fs::read_to_string(local.join("sweep.md")).unwrap();
    assert!(md.contains("no exact solution") && md.contains("ref_probe_u_rms"));
    assert!(md.contains("energy runaway"), "the reason is in the grid");
    for chart in ["sweep-front", "sweep-convergence", "sweep-stability"] {
        for ext in ["png", "svg"] {
            let p = local.join(format!("{chart}.{ext}"));
            assert!(std::fs::metadata(&p).unwrap().len() > 1000, "{p:?}");
        }
        assert!(
            md.contains(&format!("({chart}.png)")),
            "{chart} not in sweep.md"
        );
    }

    // A run killed mid-way (its summary still says running) and one that
    // never ran are listed as such, not dropped.
    let runs: Vec<PathBuf> = {
        let mut v: Vec<PathBuf> = std::fs::read_dir(remote.join("runs"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        v.sort();
        v
    };
    std::fs::write(
        runs[0].join("summary.json"),
        r#"{"status": "running", "pid": 4242}"#,
    )
    .unwrap();
    std::fs::remove_dir_all(&runs[1]).unwrap();
    collect(&remote);
    let b = table(&remote);
    assert_eq!(b.len(), 8);
    assert_eq!(b[0]["status"], "running");
    assert!(b[0]["reason"].contains("4242"), "{:?}", b[0]);
    assert_eq!(b[1]["status"], "missing");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_exact_scene_charts_its_error_against_cost_and_cell_size() {
    let dir = tmp("exact");
    let out = dir.join("out");
    let o = bin()
        .arg("sweep")
        .arg(common::case("dyka_bar.toml"))
        .args([
            "--vary",
            "solver.shape=linear,ugimp",
            "--vary",
            "grid.h=0.01,0.005,0.0025",
            "--metric",
            "rms_velocity_relative",
            "--backend",
            "cpu",
            "--jobs",
            "2",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let rows = table(&out);
    assert_eq!(rows.len(), 6);
    for r in &rows {
        assert_eq!(r["status"], "completed", "{r:?}");
        assert_eq!(r["error_source"], "exact");
        let e: f64 = r["rms_velocity_relative"].parse().unwrap();
        assert!(e > 0.0 && e < 1.0, "{r:?}");
        for k in [
            "steps",
            "particles",
            "bytes_per_particle",
            "wall_seconds",
            "t",
        ] {
            assert!(r[k].parse::<f64>().unwrap() > 0.0, "{k}: {r:?}");
        }
    }
    let md = std::fs::read_to_string(out.join("sweep.md")).unwrap();
    assert!(
        md.contains("Charted figure: `rms_velocity_relative`"),
        "{md}"
    );
    // One fitted order per shape, and it is a refinement that helps (p > 0).
    for shape in ["linear", "ugimp"] {
        let label = format!("shape={shape}: ");
        let at = md.find(&label).expect("an order per series") + label.len();
        let p: String = md[at..]
            .chars()
            .take_while(|c| c.is_ascii_digit() || *c == '.' || *c == '-')
            .collect();
        let p: f64 = p.trim_end_matches('.').parse().unwrap();
        assert!(p > 0.1 && p < 3.0, "{shape}: order {p}");
    }
    // The Pareto front lists runs none of which another run beats on both
    // wall time and error.
    let front = md
        .split("cheapest first: ")
        .nth(1)
        .unwrap()
        .lines()
        .next()
        .unwrap();
    let num = |r: &BTreeMap<String, String>, k: &str| r[k].parse::<f64>().unwrap();
    let on_front: Vec<&BTreeMap<String, String>> = rows
        .iter()
        .filter(|r| front.contains(&format!("`{}`", r["run"])))
        .collect();
    assert!(!on_front.is_empty(), "{front}");
    for f in &on_front {
        for r in &rows {
            let beats = num(r, "wall_seconds") < num(f, "wall_seconds")
                && num(r, "rms_velocity_relative") < num(f, "rms_velocity_relative");
            assert!(!beats, "{} beats {} on the front", r["run"], f["run"]);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_sweep_input_exits_2_naming_the_key_and_value_before_any_run() {
    let dir = tmp("bad");
    let dyka = common::case("dyka_bar.toml");
    let cases: &[(&[&str], &str)] = &[
        (&["--vary", "solver.shap=lme,linear"], "shap"),
        (&["--vary", "grid.h=0.01,-1"], "grid.h=-1"),
        (&["--vary", "grid.h="], "empty list"),
        (&["--vary", "grid.h=0.01,,0.005"], "is empty"),
        (&["--vary", "solver.shape=lme,quadratic"], "quadratic"),
        (
            &["--vary", "grid.h=0.01", "--vary", "grid.h=0.005"],
            "varied twice",
        ),
        (
            &["--vary", "solver.shape=lme", "--metric", "nope"],
            "--metric nope",
        ),
        (
            &["--vary", "solver.shape=lme", "--resolution", "solver.shape"],
            "not a number",
        ),
    ];
    for (args, needle) in cases {
        let out = dir.join("out");
        let o = bin()
            .arg("sweep")
            .arg(&dyka)
            .args(*args)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: `{needle}` not in {err}");
        assert!(!out.exists(), "{args:?} wrote {out:?}");
    }
    // A folder that is not a sweep is neither collected nor taken over.
    std::fs::create_dir_all(dir.join("foreign")).unwrap();
    std::fs::write(dir.join("foreign/notes.txt"), "mine").unwrap();
    let o = bin()
        .arg("sweep")
        .arg("--collect")
        .arg(dir.join("foreign"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let o = bin()
        .arg("sweep")
        .arg(&dyka)
        .args(["--vary", "grid.h=0.01", "--out"])
        .arg(dir.join("foreign"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("not empty"), "{}", stderr(&o));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 25, item 4: the runs running at once fit in memory together; a
/// folder written by another plan is flagged, not tabled as this plan's;
/// `--emit-jobs` refuses a folder holding another plan; an unreadable
/// summary.json is `failed`, garbage or cut alike.
#[test]
fn sweeps_check_memory_together_and_flag_folders_of_another_plan() {
    let dir = tmp("safety");
    let scene = bar_without_exact(&dir);
    let small = [
        "--vary",
        "solver.dt=5e-7,2.5e-7",
        "--set",
        "grid.h=0.01",
        "--set",
        "solver.t_end=2e-5",
        "--backend",
        "cpu",
    ];
    // --max-memory below one run: refused before anything runs.
    let out = dir.join("tiny");
    let o = bin()
        .arg("sweep")
        .arg(&scene)
        .args(small)
        .args(["--max-memory", "1K", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--max-memory"), "{}", stderr(&o));
    assert!(!out.exists(), "written before refusing");

    // Room for one run at a time: two jobs asked, one at once.
    let plan_out = dir.join("plan");
    let o = bin()
        .arg("sweep")
        .arg(&scene)
        .args(small)
        .args(["--emit-jobs"])
        .arg(dir.join("probe-jobs.txt"))
        .arg("--out")
        .arg(&plan_out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let plan: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(plan_out.join("sweep-plan.json")).unwrap())
            .unwrap();
    let one = plan["runs"][0]["memory_bytes"].as_u64().unwrap();
    assert!(one > 0, "{plan}");
    let local = dir.join("local");
    let o = bin()
        .arg("sweep")
        .arg(&scene)
        .args(small)
        .args(["--jobs", "2", "--max-memory"])
        .arg(format!("{}", one * 3 / 2))
        .arg("--out")
        .arg(&local)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("running 1 at once, not 2"),
        "{}",
        stderr(&o)
    );
    let rows = table(&local);
    assert!(rows.iter().all(|r| r["status"] == "completed"), "{rows:?}");
    // Each run folder records its plan entry.
    let entry = std::fs::read_to_string(local.join("runs/00-5e-7/sweep-run.json")).unwrap();
    assert!(entry.contains("solver.dt=5e-7"), "{entry}");

    // A folder another plan wrote (another value of a --set key): flagged.
    let foreign = local.join("runs/01-2.5e-7");
    let o = bin()
        .arg("run")
        .arg(&scene)
        .args(["--backend", "cpu", "--quiet", "--out"])
        .arg(&foreign)
        .args(["--set", "grid.h=0.02", "--set", "solver.t_end=2e-5"])
        .args(["--set", "solver.dt=2.5e-7"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::remove_file(foreign.join("sweep-run.json")).unwrap();
    collect(&local);
    let rows = table(&local);
    assert_eq!(rows[0]["status"], "completed", "{:?}", rows[0]);
    assert_eq!(rows[1]["status"], "failed", "{:?}", rows[1]);
    assert!(
        rows[1]["reason"].contains("not this plan's run") && rows[1]["reason"].contains("grid.h"),
        "{:?}",
        rows[1]
    );

    // Summary garbage and a cut summary: both failed, both unreadable.
    std::fs::write(
        local.join("runs/00-5e-7/summary.json"),
        [0xffu8, 0xfe, 0, 7],
    )
    .unwrap();
    std::fs::write(foreign.join("summary.json"), "{\"status\": \"compl").unwrap();
    collect(&local);
    for r in table(&local) {
        assert_eq!(r["status"], "failed", "{r:?}");
        assert!(r["reason"].contains("unreadable"), "{r:?}");
    }

    // --emit-jobs into the folder of another plan: refused; the same plan: fine.
    let o = bin()
        .arg("sweep")
        .arg(&scene)
        .args([
            "--vary",
            "solver.dt=1e-7",
            "--backend",
            "cpu",
            "--emit-jobs",
        ])
        .arg(dir.join("other-jobs.txt"))
        .arg("--out")
        .arg(&plan_out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("another sweep's plan"),
        "{}",
        stderr(&o)
    );
    let o = bin()
        .arg("sweep")
        .arg(&scene)
        .args(small)
        .args(["--emit-jobs"])
        .arg(dir.join("again-jobs.txt"))
        .arg("--out")
        .arg(&plan_out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let _ = std::fs::remove_dir_all(&dir);
}
