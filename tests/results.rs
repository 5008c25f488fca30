//! Every shipped case ends with its result in words against its reference
//! (`output::result::text`), and what the pictures and snapshots call a
//! modified Cam-clay particle's state is what it is (p_c, not ε̄p).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_lme-mpm"))
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("lme-mpm-results-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn run(case: &str, out: &Path, sets: &[&str]) -> Output {
    let mut c = bin();
    c.arg("run")
        .arg(format!("{}/cases/{case}.toml", env!("CARGO_MANIFEST_DIR")))
        .arg("--out")
        .arg(out);
    for s in sets {
        c.arg("--set").arg(s);
    }
    c.env("NODEVICE_SELECT", "1").output().expect("binary runs")
}

fn said(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr)
}

fn errors(out: &Path) -> serde_json::Value {
    let s = std::fs::read_to_string(out.join("summary.json")).unwrap();
    serde_json::from_str::<serde_json::Value>(&s).unwrap()["errors"].clone()
}

/// Each case, the end time that keeps its run short, and what its result
/// line must name: the reference figure it is held against.
const CASES: &[(&str, &str, &str)] = &[
    ("aligned_vibration", "0.004", "of the exact field's RMS"),
    ("cantilever", "1.0", "Timoshenko's linear"),
    (
        "clay_biaxial",
        "0.2",
        "against the critical state's M = 1.20",
    ),
    (
        "column_collapse",
        "0.01",
        "`lme-mpm study column`'s 4.85–5.06 m and 2.23–2.42 m at 2 s",
    ),
    ("contact_block", "0.1", "against g (sin θ − μ cos θ) t²/2 ="),
    ("contact_disks", "0.04", "spin ω R"),
    ("contact_rolling", "0.05", "against (2/3) g sin θ t²/2 ="),
    ("dyka_bar", "2e-6", "is below 0.55 m/s"),
    ("elastic_block", "0.1", "off the exact ρ0 g H"),
    ("footing", "0.02", "against Prandtl's 2 + π = 5.14"),
    (
        "granular_collapse",
        "0.01",
        "against the experiments' 1.2 a = 2.40",
    ),
    ("mandel", "0.2", "against Mandel's"),
    ("plate_impact", "0.04", "J/m at the start"),
    ("rolling_disk", "0.02", "against ½ a t² ="),
    ("sliding_block", "0.05", "exact (a = g_t − μ g_n"),
    ("sliding_block_incline", "0.05", "exact (a = g_t − μ g_n"),
    ("terzaghi", "0.2", "against Terzaghi's series"),
];

#[test]
fn every_case_ends_with_its_result_against_its_reference() {
    // A case added without a line here fails: every case has a reference.
    let mut shipped: Vec<String> =
        std::fs::read_dir(format!("{}/cases", env!("CARGO_MANIFEST_DIR")))
            .unwrap()
            .filter_map(|e| {
                let p = e.ok()?.path();
                let stem = p.file_stem()?.to_string_lossy().into_owned();
                (p.extension()? == "toml").then_some(stem)
            })
            .collect();
    shipped.sort();
    let listed: Vec<String> = CASES.iter().map(|c| c.0.to_string()).collect();
    assert_eq!(
        shipped, listed,
        "every case in cases/ has its line in CASES"
    );
    let mut failed = Vec::new();
    for &(case, t_end, reference) in CASES {
        let out = tmp(case);
        let o = run(case, &out, &[&format!("solver.t_end={t_end}")]);
        let text = said(&o);
        let line = text.lines().find(|l| l.starts_with("result: "));
        match line {
            Some(l) if o.status.success() && l.contains(reference) => {}
            _ => failed.push(format!(
                "{case}: exit {:?}, wanted a result line naming {reference:?}, got:\n{text}",
                o.status.code()
            )),
        }
        let png = std::fs::read(out.join("result.png")).unwrap_or_default();
        if !png.starts_with(b"\x89PNG") {
            failed.push(format!("{case}: no result.png"));
        }
        let _ = std::fs::remove_dir_all(&out);
    }
    assert!(failed.is_empty(), "{}", failed.join("\n\n"));
}

#[test]
fn short_contact_and_energy_runs_give_the_real_figures() {
    // The block slides from the start (μ = 0.2 < tan 30°): by 0.1 s the
    // slide is the exact one within 2 % (0.43 % measured, 2026-12-01).
    let out = tmp("block");
    assert!(
        run("contact_block", &out, &["solver.t_end=0.1"])
            .status
            .success()
    );
    let e = errors(&out);
    let rel = e["slide_rel_error"].as_f64().unwrap();
    assert!(rel < 0.02, "slide off by {rel}: {e}");
    assert!(e["slide"].as_f64().unwrap() > 0.004, "{e}");
    // At rest with μ = 0.7 > tan 30°: the "at rest" form of the line.
    let o = run(
        "contact_block",
        &out,
        &["solver.t_end=0.05", "contact.interface.friction=0.7"],
    );
    assert!(
        said(&o).contains("should stay at rest on the slab"),
        "{}",
        said(&o)
    );
    // The disks have met by 0.04 s: no external force, so the momentum
    // is kept to round-off.
    assert!(
        run("contact_disks", &out, &["solver.t_end=0.04"])
            .status
            .success()
    );
    let e = errors(&out);
    assert!(e["momentum_drift"].as_f64().unwrap() < 1e-9, "{e}");
    assert!(e["separating"].as_f64().unwrap() > 0.0, "they rebound: {e}");
    // The plate loses energy only where it meets the wall's fixed nodes.
    assert!(
        run("plate_impact", &out, &["solver.t_end=0.04"])
            .status
            .success()
    );
    let e = errors(&out);
    let kept = e["kept"].as_f64().unwrap();
    assert!(kept > 0.9 && kept <= 1.0 + 1e-9, "{e}");
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn cam_clay_is_labelled_by_its_preconsolidation_pressure() {
    let out = tmp("clay");
    let o = run(
        "clay_biaxial",
        &out,
        &["solver.t_end=0.2", "output.vtk_interval=0.1"],
    );
    assert!(o.status.success(), "{}", said(&o));
    // The snapshots name the state as what it is.
    let vtu = std::fs::read_dir(out.join("vtk"))
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| p.extension().is_some_and(|x| x == "vtu"))
        .expect("a snapshot");
    let v = lme_mpm::output::vtk::read_vtu(&std::fs::read(&vtu).unwrap()).unwrap();
    let pc = v.get("preconsolidation_pressure").expect("p_c array").0;
    // Normally consolidated at p' = 100 kPa: p_c starts there and hardens.
    assert!(pc.iter().all(|&x| x >= 0.99e5), "{:?}", &pc[..4]);
    assert!(v.get("specific_volume").is_some());
    assert!(v.get("plastic_strain_eq").is_none(), "no ε̄p for Cam-clay");
    // So does particles.csv: p_c and v, not the strain columns' names.
    let csv = std::fs::read_to_string(out.join("particles.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(header.ends_with(",szz,p_c,v,plastic"), "{header}");
    // `render` colours by p_c and refuses eps_p, naming p_c.
    let r = bin()
        .arg("render")
        .arg(&out)
        .args(["--field", "p_c", "--width", "320"])
        .output()
        .unwrap();
    assert!(r.status.success(), "{}", said(&r));
    let words = said(&r);
    assert!(
        words.contains("preconsolidation pressure p_c (Pa) from "),
        "{words}"
    );
    // The scale starts at the least p_c (about p′0 = 100 kPa), not at 0.
    let from: f64 = words
        .split(" from ")
        .nth(1)
        .and_then(|w| w.split_whitespace().next())
        .and_then(|w| w.parse().ok())
        .unwrap_or(0.0);
    assert!(from > 0.9e5, "{words}");
    let r = bin()
        .arg("render")
        .arg(&out)
        .args(["--field", "eps_p", "--width", "320"])
        .output()
        .unwrap();
    assert_eq!(r.status.code(), Some(2), "{}", said(&r));
    assert!(said(&r).contains("--field p_c"), "{}", said(&r));
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn a_reference_the_scene_cannot_have_is_refused_naming_exact() {
    for (case, set, why) in [
        ("sliding_block", "exact=energy", "remove gravity"),
        ("contact_block", "exact=disk_impact", "one disk each"),
        (
            "rolling_disk",
            "exact=contact_rolling",
            "one [contact.<name>] pair",
        ),
        (
            "footing",
            "materials.clay.friction_angle=20",
            "friction_angle = 0 (Tresca)",
        ),
        (
            "column_collapse",
            "bodies.column.rects=[[0.0,0.0,1.0,2.0]]",
            "2 m x 4 m column",
        ),
        (
            "granular_collapse",
            "bodies.column.rects=[[0.5,0.0,1.5,2.0]]",
            "from x = 0",
        ),
        ("plate_impact", "exact=critical_state", "modified_cam_clay"),
    ] {
        let o = bin()
            .arg("check")
            .arg(format!("{}/cases/{case}.toml", env!("CARGO_MANIFEST_DIR")))
            .args(["--set", set])
            .output()
            .unwrap();
        let e = said(&o);
        assert_eq!(o.status.code(), Some(2), "{case} {set}: {e}");
        assert!(
            e.contains("`exact`") && e.contains(why),
            "{case} {set}: {e}"
        );
    }
}
