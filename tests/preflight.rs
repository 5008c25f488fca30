//! The preflight's memory estimate against the measured peak: the release
//! binary runs each case briefly on the CPU path and writes both
//! `memory_estimate_bytes` and `peak_rss_bytes` (VmHWM) to summary.json;
//! they must agree within 25 % (issue 10), on the four cases, a scene
//! with contact pairs and a 1M-particle scene.

use crate::common;

use std::path::PathBuf;
use std::process::Command;

/// Issue 10's bound on |estimate − peak| / peak. Measured on 2 threads
/// (2026-11-25): −1.8 % (Dyka), +1.0 % (block), −2.9 % (plate), −2.0 %
/// (manufactured), −11.7 % (two bodies in contact; −18.9 % before the
/// contact fields were counted), +4.2 % (plate at h = 0.1, 1M particles).
const MEMORY_TOLERANCE: f64 = 0.25;

fn measure(name: &str, sets: &[&str]) -> Option<(f64, f64)> {
    let out = std::env::temp_dir().join(format!("lme-mpm-mem-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let mut c = Command::new(env!("CARGO_BIN_EXE_lme-mpm"));
    c.args(["run", "--backend", "cpu", "--quiet", "--out"])
        .arg(&out)
        .arg(common::case(name));
    for s in sets {
        c.arg("--set").arg(s);
    }
    let o = c.output().expect("binary runs");
    assert_eq!(
        o.status.code(),
        Some(0),
        "{name}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let _ = std::fs::remove_dir_all(PathBuf::from(&out));
    let est = s["memory_estimate_bytes"].as_f64().expect("an estimate");
    Some((est, s["peak_rss_bytes"].as_f64()?))
}

#[test]
fn memory_estimate_is_within_25_percent_of_the_peak_rss() {
    let runs: [(&str, &[&str]); 6] = [
        ("dyka_bar.toml", &["solver.t_end=1e-6"]),
        ("elastic_block.toml", &["solver.t_end=0.05"]),
        ("plate_impact.toml", &["solver.t_end=0.01"]),
        ("aligned_vibration.toml", &["solver.t_end=1e-4"]),
        // Contact pairs: a field per paired body, normals and gaps per pair.
        ("contact_rolling.toml", &["solver.t_end=2e-3"]),
        // 1,000,000 particles (50 m / 0.1 m, 2 x 2 per cell), three steps.
        (
            "plate_impact.toml",
            &["grid.h=0.1", "solver.t_end=3e-4", "output.vtk_interval=1"],
        ),
    ];
    let mut failed = Vec::new();
    for (name, sets) in runs {
        let Some((est, peak)) = measure(name, sets) else {
            eprintln!("SKIP: the OS reports no peak RSS (VmHWM); nothing to compare");
            return;
        };
        let rel = (est - peak) / peak;
        eprintln!(
            "{name} {sets:?}: estimate {:.1} MiB, peak {:.1} MiB ({:+.1} %)",
            est / 1048576.0,
            peak / 1048576.0,
            100.0 * rel
        );
        if rel.abs() > MEMORY_TOLERANCE {
            failed.push(format!("{name} {sets:?}: {:+.1} %", 100.0 * rel));
        }
    }
    assert!(
        failed.is_empty(),
        "estimate off by more than 25 %: {failed:?}"
    );
}
