//! The `lme-mpm` binary: bad input exits 2 with a message naming the key and
//! writes nothing; an unstable run exits 3 and keeps its outputs; a good run
//! exits 0 and writes every output file in its documented shape.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_lme-mpm"))
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("lme-mpm-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn run_with(scene: &Path, out: &Path, sets: &[&str]) -> Output {
    let mut c = bin();
    c.arg("run").arg(scene).arg("--out").arg(out).arg("--quiet");
    for s in sets {
        c.arg("--set").arg(s);
    }
    c.output().expect("binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Writes `text` as a scene file and returns its path.
fn scene_file(dir: &Path, text: &str) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let p = dir.join("scene.toml");
    std::fs::write(&p, text).unwrap();
    p
}

fn dyka_text() -> String {
    std::fs::read_to_string(common::case("dyka_bar.toml")).unwrap()
}

/// Every way of getting the input wrong: exit 2, the message names the key
/// (or the line), and no output folder appears.
#[test]
fn bad_input_exits_2_with_a_clear_message_and_writes_nothing() {
    let dyka = common::case("dyka_bar.toml");
    let mms = common::case("aligned_vibration.toml");
    let slump =
        std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/scenes/soil_slump.toml");
    // 300 bytes: more than a folder name holds (255).
    let long_name = format!("name={}", "n".repeat(300));
    let cases: Vec<(&str, PathBuf, Vec<&str>, &str)> = vec![
        (
            "malformed toml",
            scene_file(&tmp("s1"), "[grid\nh = 1"),
            vec![],
            "TOML parse error",
        ),
        (
            "unknown key",
            scene_file(
                &tmp("s2"),
                &dyka_text().replace("cfl = 0.1", "cfl = 0.1\ncfll = 3"),
            ),
            vec![],
            "unknown field `cfll`",
        ),
        (
            "negative density",
            dyka.clone(),
            vec!["materials.steel.density=-7833"],
            "materials.steel.density",
        ),
        ("cfl zero", dyka.clone(), vec!["solver.cfl=0"], "solver.cfl"),
        (
            "MLS weight support below 1.5 cells",
            dyka.clone(),
            vec!["solver.mls_support=1.0"],
            "solver.mls_support",
        ),
        (
            "unknown integrator",
            dyka.clone(),
            vec!["solver.integrator=usl"],
            "musl",
        ),
        (
            "cfl above one",
            dyka.clone(),
            vec!["solver.cfl=1.5"],
            "must be in (0, 1]",
        ),
        (
            "empty body",
            dyka.clone(),
            vec!["bodies.bar.rects=[]"],
            "bodies.bar",
        ),
        (
            "body outside the grid",
            dyka.clone(),
            vec!["grid.min=[0.05, -0.003]", "grid.max=[0.14, 0.004]"],
            "outside the grid",
        ),
        (
            "unknown shape",
            dyka.clone(),
            vec!["solver.shape=lmx"],
            "unknown variant `lmx`",
        ),
        (
            "bad --set syntax",
            dyka.clone(),
            vec!["solver.shape"],
            "expected dotted.key=value",
        ),
        (
            "a name longer than a folder name may be",
            dyka.clone(),
            vec![long_name.as_str()],
            "`name` must be a plain folder name",
        ),
        (
            "a name holding NUL",
            scene_file(
                &tmp("s-nul"),
                &dyka_text().replace("name = \"dyka_bar\"", "name = \"a\\u0000b\""),
            ),
            vec![],
            "`name` must be a plain folder name",
        ),
        (
            "a name holding a newline",
            scene_file(
                &tmp("s-newline"),
                &dyka_text().replace("name = \"dyka_bar\"", "name = \"a\\nb\""),
            ),
            vec![],
            "`name` must be a plain folder name",
        ),
        (
            "--set into a value",
            dyka.clone(),
            vec!["grid.h.x=1"],
            "not a table",
        ),
        (
            "unknown key via --set",
            dyka.clone(),
            vec!["solver.gama=3"],
            "unknown field `gama`",
        ),
        (
            "lme gamma out of range",
            dyka.clone(),
            vec!["solver.lme_gamma=50"],
            "solver.lme_gamma",
        ),
        (
            "missing material",
            dyka.clone(),
            vec!["bodies.bar.material=iron"],
            "bodies.bar.material",
        ),
        (
            "constraint matching no node",
            dyka.clone(),
            vec![
                "constraints.fixed_end.min=[5, -1]",
                "constraints.fixed_end.max=[6, 1]",
            ],
            "matches no node",
        ),
        (
            "disk holding no particle point",
            scene_file(
                &tmp("s3"),
                "[grid]\nh = 1.0\n[materials.m]\nmodel = \"linear_elastic\"\ndensity = 1.0\nE = 1.0\nnu = 0.0\n\
                 [bodies.a]\nmaterial = \"m\"\nrects = [[0, 0, 2, 2]]\n[bodies.dot]\nmaterial = \"m\"\n\
                 disks = [[5.5, 5.5, 0.05]]\n[solver]\nt_end = 1.0\n",
            ),
            vec![],
            "bodies.dot` is empty",
        ),
        (
            "mls with uGIMP",
            mms.clone(),
            vec!["solver.shape=ugimp", "solver.mls=true"],
            "solver.mls",
        ),
        (
            "mls with LME",
            mms.clone(),
            vec!["solver.shape=lme", "solver.mls=true"],
            "solver.mls",
        ),
        (
            "B-spline on a perturbed grid",
            mms.clone(),
            vec!["grid.perturb=0.1"],
            "grid.perturb",
        ),
        (
            "manufactured amplitude too large",
            mms.clone(),
            vec!["manufactured.amplitude=0.2"],
            "manufactured.amplitude",
        ),
        (
            "manufactured with a linear elastic material",
            mms.clone(),
            vec!["materials.rubber.model=linear_elastic"],
            "neo_hookean",
        ),
        (
            "manufactured with gravity",
            mms.clone(),
            vec!["gravity.g=[0, -9.81]"],
            "gravity",
        ),
        (
            "negative fixed dt",
            mms.clone(),
            vec!["solver.dt=-1e-5"],
            "solver.dt",
        ),
        (
            "negative cohesion",
            slump.clone(),
            vec!["materials.soil.cohesion=-1"],
            "materials.soil.cohesion",
        ),
        (
            "friction angle of 90 degrees",
            slump.clone(),
            vec!["materials.soil.friction_angle=90"],
            "materials.soil.friction_angle",
        ),
        (
            "dilation above friction",
            slump.clone(),
            vec!["materials.soil.dilation_angle=25"],
            "materials.soil.dilation_angle",
        ),
        (
            "negative dilation",
            slump.clone(),
            vec!["materials.soil.dilation_angle=-1"],
            "materials.soil.dilation_angle",
        ),
        (
            "tension cutoff above the apex",
            slump.clone(),
            vec!["materials.soil.tension_cutoff=3000"],
            "materials.soil.tension_cutoff",
        ),
        (
            "negative tension cutoff",
            slump.clone(),
            vec!["materials.soil.tension_cutoff=-5"],
            "materials.soil.tension_cutoff",
        ),
        (
            "plastic model without cohesion",
            dyka.clone(),
            vec![
                "materials.steel.model=mohr_coulomb",
                "materials.steel.friction_angle=30",
            ],
            "materials.steel.cohesion",
        ),
        (
            "plastic model without friction angle",
            dyka.clone(),
            vec![
                "materials.steel.model=drucker_prager",
                "materials.steel.cohesion=1e6",
            ],
            "materials.steel.friction_angle",
        ),
        (
            "plastic key on an elastic material",
            slump.clone(),
            vec!["materials.soil.model=linear_elastic"],
            "materials.soil.cohesion",
        ),
    ];
    for (what, scene, sets, needle) in cases {
        let out = tmp("never-written");
        let o = run_with(&scene, &out, &sets);
        let msg = stderr(&o);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{what}: exit {:?}, stderr: {msg}",
            o.status.code()
        );
        assert!(
            msg.contains(needle),
            "{what}: message lacks {needle:?}: {msg}"
        );
        assert!(msg.lines().count() <= 8, "{what}: message too long: {msg}");
        assert!(!out.exists(), "{what}: output folder was created");
        // `check` agrees with `run`.
        let mut c = bin();
        c.arg("check").arg(&scene);
        for s in &sets {
            c.arg("--set").arg(s);
        }
        assert_eq!(
            c.output().unwrap().status.code(),
            Some(2),
            "{what}: check disagrees"
        );
    }
}

#[test]
fn unstable_run_exits_3_and_keeps_its_outputs() {
    // An impactor at 2 km/s with no room left beyond the bar leaves the grid.
    let out = tmp("unstable");
    let o = run_with(
        &common::case("dyka_bar.toml"),
        &out,
        &["bodies.impactor.velocity=[-2000, 0]", "grid.margin=0"],
    );
    assert_eq!(o.status.code(), Some(3), "stderr: {}", stderr(&o));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(s["status"], "unstable");
    assert_eq!(s["reason_code"], "left_grid");
    assert!(s["unstable_particle"].is_u64());
    assert!(s["t"].as_f64().unwrap() < 1e-4);
    for f in [
        "probes.csv",
        "energy.csv",
        "particles.csv",
        "particles.pvd",
        "scene.resolved.toml",
    ] {
        assert!(out.join(f).exists(), "{f} missing after an unstable run");
    }
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn completed_run_writes_every_output() {
    let out = tmp("ok");
    let o = run_with(
        &common::case("dyka_bar.toml"),
        &out,
        &[
            "output.vtk_interval=5e-5",
            "grid.h=0.002",
            "bodies.impactor.rects=[[0,0,0.033325,0.002]]",
            "bodies.bar.rects=[[0.033325,0,0.1333,0.002]]",
        ],
    );
    assert_eq!(o.status.code(), Some(0), "stderr: {}", stderr(&o));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(s["status"], "completed");
    assert_eq!(s["t"].as_f64().unwrap(), 1e-4);
    assert_eq!(
        s["h"].as_f64().unwrap(),
        0.002,
        "--set grid.h did not reach the run"
    );
    let n = s["particles"].as_u64().unwrap() as usize;
    assert!(s["particle_steps_per_second"].as_f64().unwrap() > 0.0);
    assert!(s["errors"]["rms_velocity"].as_f64().unwrap() > 0.0);
    // Every error figure also relative to the field's scale (5 m/s here).
    let e = &s["errors"];
    for (abs, rel) in [
        ("rms_velocity", "rms_velocity_relative"),
        ("max_velocity", "max_velocity_relative"),
    ] {
        let (a, r) = (e[abs].as_f64().unwrap(), e[rel].as_f64().unwrap());
        assert!((a / 5.0 - r).abs() < 1e-12 * r, "{abs} {a} vs {rel} {r}");
    }
    // The preflight's figures reach the summary.
    assert!(s["memory_estimate_bytes"].as_u64().unwrap() > 1 << 20);
    assert_eq!(
        s["backend"].as_str().unwrap().split(' ').next(),
        Some("cpu")
    );

    let probes = std::fs::read_to_string(out.join("probes.csv")).unwrap();
    assert!(probes.starts_with("t,probe,x,y,vx,vy,sxx,syy,sxy\n"));
    assert!(probes.lines().skip(1).all(|l| l.split(',').count() == 9));
    assert!(probes.contains(",free_end,"));

    let parts = std::fs::read_to_string(out.join("particles.csv")).unwrap();
    let mut lines = parts.lines();
    assert_eq!(
        lines.next(),
        Some("id,body,x0,y0,x,y,vx,vy,sxx,syy,sxy,mass,volume")
    );
    assert_eq!(lines.clone().count(), n);
    let mass: f64 = lines
        .map(|l| l.split(',').nth(11).unwrap().parse::<f64>().unwrap())
        .sum();
    let bar_mass = 7833.0 * 0.1333 * 0.002;
    assert!(
        (mass - bar_mass).abs() < 1e-9 * bar_mass,
        "particle mass {mass} vs bar {bar_mass}"
    );

    // VTK: three snapshots (0, 5e-5, 1e-4), each with the right point count
    // and a complete appended block.
    let pvd = std::fs::read_to_string(out.join("particles.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 3, "{pvd}");
    for k in 0..3 {
        let bytes = std::fs::read(out.join(format!("vtk/particles_{k:05}.vtu"))).unwrap();
        let text = String::from_utf8_lossy(&bytes);
        assert!(text.contains(&format!("NumberOfPoints=\"{n}\"")));
        assert!(text.ends_with("</AppendedData>\n</VTKFile>\n"));
        // Header + payload sizes add up: 8 point arrays (velocity,
        // displacement, the stress tensor's 6 and its 3 in-plane
        // components, density, volume, speed, body), points, 3 cell arrays.
        let payload = n * (12 * 3 + 24 + 4 * 4) + n * 12 + n * (8 + 8 + 1) + 12 * 8;
        let start = text.find("<AppendedData encoding=\"raw\">\n_").unwrap() + 31;
        let end = bytes.len() - "\n</AppendedData>\n</VTKFile>\n".len();
        assert_eq!(end - start, payload);
        // Read back: the points, and the tensor's σzz = ν (σxx + σyy) of
        // plane-strain linear elasticity (f32 round-off: 1e-6 relative).
        let vtu = lme_mpm::output::vtk::read_vtu(&bytes).unwrap();
        assert_eq!(vtu.n, n);
        let (tensor, comps) = vtu.get("stress").unwrap();
        assert_eq!(comps, 6);
        let nu = s["scene_resolved"]["materials"]["steel"]["nu"]
            .as_f64()
            .unwrap();
        for s in tensor.chunks_exact(6) {
            let zz = nu * (f64::from(s[0]) + f64::from(s[1]));
            assert!(
                (f64::from(s[2]) - zz).abs() <= 1e-6 * (1.0 + zz.abs() + f64::from(s[0]).abs()),
                "{s:?}"
            );
        }
        let (vol, _) = vtu.get("volume").unwrap();
        assert!(vol.iter().all(|v| *v > 0.0));
    }
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn backend_choice_is_said_plainly_and_a_missing_adapter_fails_clearly() {
    let out = tmp("backend");
    // auto: says which path it took and why (a software adapter does not count as a GPU).
    let mut c = bin();
    c.args(["run", "--out"])
        .arg(&out)
        .arg(common::case("dyka_bar.toml"));
    let o = c.output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let msg = stderr(&o);
    let line = msg
        .lines()
        .find(|l| l.starts_with("backend:"))
        .unwrap_or_else(|| panic!("no backend line: {msg}"));
    assert!(line.contains("CPU path") || line.contains("gpu:"), "{line}");
    if line.contains("CPU path") {
        assert!(line.contains("auto found no usable GPU"), "{line}");
    }
    // gpu with an adapter name that matches nothing: exit 1, says what exists.
    let mut c = bin();
    c.args([
        "run",
        "--backend",
        "gpu",
        "--adapter",
        "no-such-adapter",
        "--quiet",
        "--out",
    ])
    .arg(&out)
    .arg(common::case("dyka_bar.toml"));
    let o = c.output().unwrap();
    assert_eq!(o.status.code(), Some(1));
    let msg = stderr(&o);
    assert!(
        msg.contains("no GPU adapter") && msg.contains("no-such-adapter"),
        "{msg}"
    );
    let _ = std::fs::remove_dir_all(&out);
}

/// Runs the binary with `args`, killing it after `limit`; returns the exit
/// code (None when it had to be killed), stderr and the time it took.
fn run_timed(args: &[&str], limit: std::time::Duration) -> (Option<i32>, String, f64) {
    use std::io::Read;
    let start = std::time::Instant::now();
    let mut child = bin()
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("binary runs");
    let code = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s.code();
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    };
    let mut err = String::new();
    let _ = child.stderr.take().unwrap().read_to_string(&mut err);
    (code, err, start.elapsed().as_secs_f64())
}

/// Every input of issue 10's "Seen" list that used to hang, spin or eat
/// memory: each ends in under 2 s with exit 2 and a message naming the key,
/// and writes nothing.
#[test]
fn absurd_sizes_end_at_once_with_exit_2_naming_the_key() {
    /// The bound: these must end within 2 s (they take ~10 ms).
    const LIMIT: std::time::Duration = std::time::Duration::from_secs(2);
    let dyka = common::case("dyka_bar.toml");
    let plate = common::case("plate_impact.toml");
    let (dyka, plate) = (dyka.to_str().unwrap(), plate.to_str().unwrap());
    let out = tmp("absurd");
    let out_s = out.to_str().unwrap();
    // 5,000 touching rectangles: the pairwise overlap check was quadratic.
    let rects: Vec<String> = (0..5000)
        .map(|i| format!("[{}, 0, {}, 1]", i, i + 1))
        .collect();
    let many = scene_file(
        &tmp("many-shapes"),
        &format!(
            "[grid]\nh = 1.0\n[materials.m]\nmodel = \"linear_elastic\"\ndensity = 1.0\nE = 1.0\n\
             nu = 0.0\n[bodies.a]\nmaterial = \"m\"\nrects = [{}]\n[solver]\nt_end = 1.0\n",
            rects.join(", ")
        ),
    );
    let many = many.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["run", dyka, "--set", "grid.h=1e-9"], "grid.h"),
        (vec!["check", dyka, "--set", "grid.h=1e-6"], "grid.h"),
        (vec!["check", plate, "--set", "grid.h=0.01"], "grid.h"),
        // The same plate on a machine with 1 GiB to spare.
        (
            vec!["run", plate, "--set", "grid.h=0.1", "--max-memory", "1G"],
            "--max-memory",
        ),
        (
            vec!["run", dyka, "--set", "materials.steel.E=1e308"],
            "materials.steel.E",
        ),
        (
            vec!["check", dyka, "--set", "materials.steel.E=1e308"],
            "materials.steel.E",
        ),
        (vec!["run", dyka, "--set", "solver.dt=1e-20"], "solver.dt"),
        // Weeks of work: refused when the script says how long it may take.
        (
            vec!["run", dyka, "--set", "grid.h=1e-5", "--max-hours", "1"],
            "grid.h",
        ),
        (vec!["run", dyka, "--max-steps", "1000"], "--max-steps 1000"),
        (
            vec!["run", dyka, "--set", "output.vtk_interval=1e-12"],
            "output.vtk_interval",
        ),
        (
            vec![
                "check",
                dyka,
                "--set",
                "bodies.bar.rects=[[-1e300, 0, 0.1333, 0.001]]",
            ],
            "bodies.bar.rects[0]",
        ),
        (
            vec!["run", dyka, "--set", "grid.margin=1e300"],
            "grid.margin",
        ),
        (
            vec!["run", dyka, "--set", "bodies.impactor.velocity=[-1e300, 0]"],
            "grid.margin",
        ),
        (vec!["check", "/dev/zero"], "16 MiB"),
        (vec!["check", many], "5000 shapes"),
        (
            vec!["run", dyka, "--set", "output.probes.far=[10, 10]"],
            "output.probes.far",
        ),
        (
            vec!["run", dyka, "--backend", "cpu", "--adapter", "nvidia"],
            "--adapter",
        ),
    ];
    for (args, needle) in cases {
        let mut args = args;
        if args[0] == "run" {
            args.extend(["--quiet", "--out", out_s]);
        }
        let (code, msg, secs) = run_timed(&args, LIMIT);
        assert_eq!(
            code,
            Some(2),
            "{args:?}: exit {code:?} after {secs:.2} s: {msg}"
        );
        assert!(secs < LIMIT.as_secs_f64(), "{args:?} took {secs:.2} s");
        assert!(
            msg.contains(needle),
            "{args:?}: message lacks {needle:?}: {msg}"
        );
        assert!(!out.exists(), "{args:?}: output folder was created");
        eprintln!("{:.3} s  {args:?}", secs);
    }
}

/// Intervals below the time step run correctly, once per step, with a
/// warning; they no longer spin in the sampling loop.
#[test]
fn intervals_below_a_step_are_clamped_to_one_per_step() {
    let out = tmp("clamped");
    let o = run_with(
        &common::case("dyka_bar.toml"),
        &out,
        &[
            "output.sample_interval=1e-18",
            "output.vtk_interval=1e-18",
            "solver.t_end=1e-6",
        ],
    );
    let msg = stderr(&o);
    assert_eq!(o.status.code(), Some(0), "{msg}");
    assert!(
        msg.contains("output.sample_interval = 1e-18 s is below the time step"),
        "{msg}"
    );
    assert!(
        msg.contains("output.vtk_interval = 1e-18 s is below the time step"),
        "{msg}"
    );
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let steps = s["steps"].as_u64().unwrap() as usize;
    let energy = std::fs::read_to_string(out.join("energy.csv")).unwrap();
    // A row at t = 0 and one per step (the last step is shortened to t_end).
    let rows = energy.lines().count() - 1;
    assert!(
        (steps..=steps + 1).contains(&rows),
        "{rows} rows for {steps} steps"
    );
    let snaps = std::fs::read_dir(out.join("vtk")).unwrap().count();
    assert!(
        (steps..=steps + 2).contains(&snaps),
        "{snaps} snapshots for {steps} steps"
    );
    // The resolved scene says what ran.
    let resolved = std::fs::read_to_string(out.join("scene.resolved.toml")).unwrap();
    assert!(!resolved.contains("1e-18"), "{resolved}");
    let _ = std::fs::remove_dir_all(&out);
}

/// `check` prints the preflight figures, and a long run's warning.
#[test]
fn check_prints_the_estimate_and_warns_of_long_runs() {
    let o = bin()
        .arg("check")
        .arg(common::case("plate_impact.toml"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("estimate    10000 particles, 57 x 63 = 3591 nodes"),
        "{text}"
    );
    assert!(text.contains("peak memory"), "{text}");
    let (code, msg, _) = run_timed(
        &[
            "check",
            common::case("dyka_bar.toml").to_str().unwrap(),
            "--set",
            "grid.h=2e-5",
        ],
        std::time::Duration::from_secs(30),
    );
    assert_eq!(code, Some(0), "{msg}");
    assert!(msg.contains("warning: a long run"), "{msg}");
}

/// Walls, prescribed velocities, tractions and point loads given wrong:
/// exit 2, the message names the key, nothing is written.
#[test]
fn bad_boundaries_exit_2_naming_the_key() {
    let sliding = common::case("sliding_block.toml");
    let bounds = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/scenes/boundaries.toml");
    let no_mu = std::fs::read_to_string(&sliding)
        .unwrap()
        .replace("friction = 0.3\n", "");
    let cases: Vec<(&str, PathBuf, Vec<&str>, &str)> = vec![
        (
            "zero normal",
            sliding.clone(),
            vec!["walls.floor.normal=[0, 0]"],
            "walls.floor.normal",
        ),
        (
            "negative friction",
            sliding.clone(),
            vec!["walls.floor.friction=-0.1"],
            "walls.floor.friction",
        ),
        (
            "friction without mu",
            scene_file(&tmp("nomu"), &no_mu),
            vec![],
            "walls.floor.friction",
        ),
        (
            "mu without friction",
            sliding.clone(),
            vec!["walls.floor.contact=slip"],
            "walls.floor.friction",
        ),
        (
            "non-finite wall point",
            sliding.clone(),
            vec!["walls.floor.point=[nan, 0]"],
            "walls.floor.point",
        ),
        (
            "wall behind no node",
            sliding.clone(),
            vec!["walls.floor.point=[0, -100]"],
            "walls.floor",
        ),
        (
            "negative constraint ramp",
            bounds.clone(),
            vec!["constraints.drive.ramp_time=-1"],
            "constraints.drive.ramp_time",
        ),
        (
            "non-finite prescribed velocity",
            bounds.clone(),
            vec!["constraints.drive.velocity=[inf, 0]"],
            "constraints.drive.velocity",
        ),
        (
            "negative traction ramp",
            bounds.clone(),
            vec!["tractions.top.ramp_time=-1"],
            "tractions.top.ramp_time",
        ),
        (
            "zero-length traction segment",
            bounds.clone(),
            vec!["tractions.top.to=[0.5, 2.5]"],
            "tractions.top.to",
        ),
        (
            "traction touching no particle",
            bounds.clone(),
            vec![
                "tractions.top.from=[0.5, 3.0]",
                "tractions.top.to=[3.5, 3.0]",
            ],
            "tractions.top",
        ),
        (
            "non-finite traction",
            bounds.clone(),
            vec!["tractions.top.traction=[nan, 0]"],
            "tractions.top.traction",
        ),
        (
            "point load outside every body",
            bounds.clone(),
            vec!["point_loads.side.at=[3.9, 2.9]"],
            "point_loads.side.at",
        ),
        (
            "negative point load ramp",
            bounds.clone(),
            vec!["point_loads.side.ramp_time=-2"],
            "point_loads.side.ramp_time",
        ),
        (
            "loads with MLS",
            bounds.clone(),
            vec!["solver.shape=bspline2", "solver.mls=true"],
            "solver.mls",
        ),
        (
            "sliding_block scored on a stick wall",
            scene_file(&tmp("stick"), &no_mu),
            vec!["walls.floor.contact=stick"],
            "exact",
        ),
    ];
    for (what, scene, sets, needle) in cases {
        let out = tmp("never-written-bc");
        let o = run_with(&scene, &out, &sets);
        let msg = stderr(&o);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{what}: exit {:?}, stderr: {msg}",
            o.status.code()
        );
        assert!(
            msg.contains(needle),
            "{what}: message lacks {needle:?}: {msg}"
        );
        assert!(!out.exists(), "{what}: output folder was created");
    }
}

#[test]
fn bench_runs_a_named_peer_after_ours_and_prints_the_ratio() {
    // A stand-in for ../shared/bench/peer.sh: it receives the particle
    // counts as one argument and prints one line per count (and noise).
    let dir = tmp("bench-peer");
    std::fs::create_dir_all(&dir).unwrap();
    let script = dir.join("peer.sh");
    std::fs::write(
        &script,
        "echo 'starting'\nfor n in $(echo \"$1\" | tr , ' '); do\n  echo \"fake-peer n=$n steps=10 wall=1.0 particle-steps/s=1.000e3\"\ndone\n",
    )
    .unwrap();
    let out = dir.join("bench");
    let peer = format!("sh {}", script.display());
    let o = bin()
        .args(["bench", "--backend", "cpu", "--cases", "linear"])
        .args(["--particles", "2000", "--seconds", "0.2", "--peer", &peer])
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("| fake-peer | 2000 | 10 |"), "{text}");
    // Our row over the peer's 1e3 particle-steps/s.
    let row = text
        .lines()
        .find(|l| l.starts_with("| cpu") && l.contains("1.000e3"))
        .unwrap_or_else(|| panic!("no ratio row: {text}"));
    let cells: Vec<&str> = row.split('|').map(str::trim).collect();
    let ours: f64 = cells[4].parse().unwrap();
    let ratio: f64 = cells[6].parse().unwrap();
    assert!((ratio - ours / 1e3).abs() <= 0.01 * ratio, "{row}");
    let csv = std::fs::read_to_string(out.join("bench.csv")).unwrap();
    assert!(csv.contains("fake-peer,2000,10,"), "{csv}");

    // A failing peer costs its rows only: ours are written, exit 1.
    let o = bin()
        .args(["bench", "--backend", "cpu", "--cases", "linear"])
        .args(["--particles", "2000", "--seconds", "0.2", "--peer", "false"])
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("peer"), "{}", stderr(&o));
    let csv = std::fs::read_to_string(out.join("bench.csv")).unwrap();
    assert!(
        csv.contains("linear,") && !csv.contains("fake-peer"),
        "{csv}"
    );
}

/// Issue 25, item 10: input that was silently dropped, turned a limit off,
/// or was called the wrong thing.
#[test]
fn small_input_holes_exit_2_naming_what_is_wrong() {
    let dyka = common::case("dyka_bar.toml");
    // A --set value over several lines: the rest was dropped unsaid.
    let out = tmp("multiline");
    let o = run_with(&dyka, &out, &["solver.t_end=1e-5\n[grid]\nh=5"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("newline"), "{}", stderr(&o));
    assert!(!out.exists());

    // --max-hours nan (or inf, or not positive) turned the limit off.
    for v in ["nan", "inf", "0", "-1"] {
        let o = bin()
            .arg("check")
            .arg(&dyka)
            .arg(format!("--max-hours={v}"))
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "--max-hours {v}: {}", stderr(&o));
        assert!(stderr(&o).contains("--max-hours"), "{}", stderr(&o));
    }

    // A bound out of range is named with its value, not called NaN.
    let o = run_with(
        &dyka,
        &tmp("inf-bound"),
        &["constraints.fixed_end.min=[1e7,-inf]"],
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.contains("constraints.fixed_end"), "{err}");
    assert!(
        err.contains("10000000") && !err.contains("not NaN"),
        "{err}"
    );

    // A body wholly behind its wall (normal of the wrong sign) never moves.
    let out = tmp("behind");
    let o = run_with(
        &common::case("sliding_block.toml"),
        &out,
        &["walls.floor.normal=[0, -1]"],
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("walls.floor") && err.contains("wholly behind"),
        "{err}"
    );
    assert!(!out.exists());
}

/// Issue 51: `bench --seconds nan` measured no step and reported 0
/// particle-steps/s; 0 particles measured 16 under another count.
#[test]
fn bench_refuses_times_and_counts_it_cannot_measure() {
    let out = tmp("bench-bad");
    for (flag, v) in [
        ("--seconds", "nan"),
        ("--seconds", "inf"),
        ("--seconds", "0"),
        ("--seconds", "-1"),
        ("--seconds", "1e9"),
        ("--particles", "0"),
        ("--particles", "2000,15"),
    ] {
        let o = bin()
            .args(["bench", "--backend", "cpu", "--cases", "linear"])
            .arg(format!("{flag}={v}"))
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{flag} {v}: {err}");
        assert!(err.contains(flag), "{flag} {v}: {err}");
        assert!(!out.exists(), "{flag} {v}: wrote {}", out.display());
    }
}

/// Issue 51: a key that no setting of the scene reads is refused (exit 2)
/// naming it and what would make it apply, as `bspline_knots` and
/// `pic_fraction` already were; with that setting it is taken.
#[test]
fn keys_that_do_not_apply_are_refused_naming_what_would_apply_them() {
    let dyka = common::case("dyka_bar.toml");
    // Gravity, ramped in or not, and no exact solution that needs either.
    let slump =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes/soil_slump.toml");
    let cantilever = common::case("cantilever.toml");
    let check = |scene: &Path, sets: &[&str]| {
        let mut c = bin();
        c.arg("check").arg(scene);
        for s in sets {
            c.arg("--set").arg(s);
        }
        c.output().unwrap()
    };
    #[rustfmt::skip]
    let cases: [(&Path, &str, &str, &[&str]); 12] = [
        (&slump, "gravity.ramp_period=0.2", "gravity.ramp = \"sine\"", &["gravity.ramp=sine"]),
        (&dyka, "solver.mls_support=2", "solver.mls = true", &["solver.mls=true", "solver.shape=bspline2"]),
        (&dyka, "solver.mls_scope=force", "solver.mls = true", &["solver.mls=true", "solver.shape=bspline2"]),
        (&dyka, "solver.newmark_beta=0.3", "integrator = \"implicit\"", &["solver.integrator=implicit"]),
        (&dyka, "solver.newton_max_iter=5", "integrator = \"implicit\"", &["solver.integrator=implicit"]),
        (&dyka, "solver.implicit_mass=lumped", "integrator = \"implicit\"", &["solver.integrator=implicit"]),
        (&dyka, "solver.npc_gamma=0.6", "integrator = \"npc\"", &[]),
        (&cantilever, "solver.gmm_basis=mls", "method = \"gmm\"", &["solver.method=gmm"]),
        (&cantilever, "solver.load_steps=3", "solver.static = true", &[]),
        (&cantilever, "solver.gmm_dilation=1.0", "gmm_basis = \"mls\"", &["solver.method=gmm", "solver.gmm_basis=mls"]),
        (&dyka, "solver.lme_gamma=3", "solver.shape = \"lme\"", &[]),
        (&dyka, "solver.lme_tol=1e-8", "solver.shape = \"lme\"", &[]),
    ];
    for (scene, set, needs, apply) in cases {
        // Under settings that do not read it (dyka runs NPC; its npc_gamma
        // is refused under FE).
        let mut sets = vec![set];
        if set.starts_with("solver.npc_gamma") {
            sets.push("solver.integrator=fe");
        }
        if set.starts_with("solver.load_steps") {
            sets.push("solver.static=false");
        }
        if set.starts_with("solver.lme_") {
            sets.push("solver.shape=linear");
        }
        let o = check(scene, &sets);
        let err = stderr(&o);
        let key = set.split('=').next().unwrap();
        assert_eq!(o.status.code(), Some(2), "{set}: {err}");
        assert!(
            err.contains(&format!("`{key}` has no effect")) && err.contains(needs),
            "{set}: {err}"
        );
        // And taken where it applies.
        let mut sets: Vec<&str> = apply.to_vec();
        sets.push(set);
        if set.starts_with("solver.load_steps") {
            sets.push("solver.static=true");
        }
        let o = check(scene, &sets);
        assert!(o.status.success(), "{set} with {apply:?}: {}", stderr(&o));
    }
}

/// Issue 51: a scene file's keys of its own shape function are dropped,
/// with a note, when an override replaces the shape (`--set
/// solver.shape=linear` on an LME case, as the cases' own comments show),
/// but the same key in a file whose shape does not read it is refused.
#[test]
fn a_shape_override_drops_the_replaced_shapes_keys_with_a_note() {
    let block = common::case("elastic_block.toml");
    let o = bin()
        .arg("check")
        .arg(&block)
        .args(["--set", "solver.shape=linear"])
        .output()
        .unwrap();
    let all = format!("{}{}", String::from_utf8_lossy(&o.stdout), stderr(&o));
    assert!(o.status.success(), "{all}");
    assert!(
        all.contains("solver.lme_gamma of the scene file dropped"),
        "{all}"
    );
    // Written into the file: linear shapes with lme_gamma = 3.
    let text = std::fs::read_to_string(&block)
        .unwrap()
        .replace("shape = \"lme\"", "shape = \"linear\"");
    let dir = tmp("shape_keys");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("linear_with_gamma.toml");
    std::fs::write(&path, text).unwrap();
    let o = bin().arg("check").arg(&path).output().unwrap();
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("`solver.lme_gamma` has no effect"), "{err}");
}

/// Shapes of different bodies that overlap, whatever their kinds, exit 2
/// naming both and where (the seeder would cut the overlap from one body
/// in silence); the shipped contact cases, whose bodies are flush, pass.
#[test]
fn overlapping_bodies_exit_2_naming_both_and_where() {
    let check = |case: &str, sets: &[&str]| {
        let mut c = bin();
        c.arg("check").arg(common::case(case));
        for s in sets {
            c.arg("--set").arg(s);
        }
        let o = c.output().unwrap();
        (o.status.code(), stderr(&o))
    };
    // (what, case, --set, the two shapes named, where)
    type Overlap<'a> = (&'a str, &'a str, Vec<&'a str>, [&'a str; 2], &'a str);
    let cases: Vec<Overlap> = vec![
        (
            "disk sunk into a slab",
            "contact_rolling.toml",
            vec!["bodies.disk.disks=[[0.0, 0.65, 0.5]]"],
            ["bodies.disk.disks[0]", "bodies.slab.rects[0]"],
            "at (0.000000, 0.250000), 0.100000 m deep",
        ),
        (
            "ring-seeded disks overlapping",
            "contact_disks.toml",
            vec!["bodies.right.disks=[[0.6, 0.5, 0.2]]"],
            ["bodies.left.disks[0]", "bodies.right.disks[0]"],
            "at (0.450000, 0.500000), 0.100000 m deep",
        ),
        (
            "a disk wholly inside another body's",
            "contact_disks.toml",
            vec!["bodies.right.disks=[[0.3, 0.5, 0.1]]"],
            ["bodies.left.disks[0]", "bodies.right.disks[0]"],
            "0.200000 m deep",
        ),
        (
            "a polygon inside another body's disk",
            "contact_disks.toml",
            vec!["bodies.right.polygons=[[[0.2, 0.4], [0.4, 0.4], [0.3, 0.6]]]"],
            ["bodies.left.disks[0]", "bodies.right.polygons[0]"],
            "at (0.300000, 0.500000)",
        ),
        (
            "a polygon crossing another body's rectangle",
            "footing.toml",
            vec!["bodies.footing.polygons=[[[-0.2, 2.0], [0.2, 2.0], [0.0, 1.8]]]"],
            ["bodies.footing.polygons[0]", "bodies.soil.rects[0]"],
            "another body",
        ),
        (
            "rectangles of two bodies",
            "contact_block.toml",
            vec!["bodies.block.rects=[[0.2, 0.4, 1.2, 0.9]]"],
            ["bodies.block.rects[0]", "bodies.slab.rects[0]"],
            "over [0.2, 0.4, 1.2, 0.5]",
        ),
    ];
    for (what, case, sets, names, place) in &cases {
        let (code, msg) = check(case, sets);
        assert_eq!(code, Some(2), "{what}: {msg}");
        for n in names {
            assert!(msg.contains(n), "{what}: {msg}");
        }
        assert!(msg.contains(place), "{what}: {msg}");
        assert!(msg.contains("may touch but not overlap"), "{what}: {msg}");
    }
    // Flush bodies (the rolling disk on its slab, the block and the footing
    // on theirs) and a body's own overlapping shapes are accepted.
    for case in [
        "contact_block.toml",
        "contact_disks.toml",
        "contact_rolling.toml",
        "footing.toml",
    ] {
        let (code, msg) = check(case, &[]);
        assert_eq!(code, Some(0), "{case}: {msg}");
    }
    let (code, msg) = check(
        "footing.toml",
        &["bodies.soil.polygons=[[[0.3, 0.6], [0.5, 0.6], [0.4, 0.8]]]"],
    );
    assert_eq!(code, Some(0), "own shapes: {msg}");
}

/// `check` says what a scene models: the contact pairs and the nodes each
/// backend holds (one copy per field), walls and their laws, gravity and
/// its ramp, initial stress, disk layouts, how far a prescribed region
/// travels; units only where there are units.
#[test]
fn check_describes_what_the_scene_models() {
    let check = |case: &str| {
        let o = bin().arg("check").arg(common::case(case)).output().unwrap();
        assert_eq!(o.status.code(), Some(0), "{case}: {}", stderr(&o));
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    let disks = check("contact_disks.toml");
    for want in [
        "nodes       3233 per field x 3 fields (one per body in a contact pair, one for the rest) = 9699, on the CPU and the GPU alike",
        "contact     impact: left / right (slip (frictionless))",
        "disks on rings at spacing h/ppc",
        "gravity     none",
        "3233 nodes x 3 fields",
        "E = 10000000 Pa, nu = 0.3)",
    ] {
        assert!(disks.contains(want), "no `{want}` in\n{disks}");
    }
    let footing = check("footing.toml");
    for want in [
        "= 16059, on",
        "5353 per field x 3 fields",
        "contact     interface: ",
    ] {
        assert!(footing.contains(want), "no `{want}` in\n{footing}");
    }
    let block = check("contact_block.toml");
    for want in [
        "walls       floor (through (0, 0) m, normal (0, 1); stick;",
        "contact     interface: block / slab (friction, mu = 0.2)",
        "gravity     g = (4.905, -8.495709211) m/s^2, ramped (sine) to full at t = 0.1 s",
    ] {
        assert!(block.contains(want), "no `{want}` in\n{block}");
    }
    let clay = check("clay_biaxial.toml");
    assert!(
        clay.contains(
            "platen (fixes y; 51 nodes; at v = (0, -0.02) m/s, ramped over 0.5 s, its region \
             travels (0.000000, -0.095000) m by t_end (0.76 cells)"
        ),
        "{clay}"
    );
    // No key's value followed by the unit "1" (it printed "nu = 0.3 1").
    for text in [&disks, &footing, &block, &clay] {
        let line = text.lines().find(|l| l.starts_with("materials")).unwrap();
        for kv in line.split([',', '(', ')']).filter(|kv| kv.contains(" = ")) {
            let after = kv.split(" = ").nth(1).unwrap().trim();
            assert!(!after.ends_with(" 1"), "`{kv}` has the unit 1 in\n{line}");
        }
    }
}
