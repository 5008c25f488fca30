//! The README's Use list, run top to bottom as a new user would follow it:
//! every line that finishes in seconds runs, in the order written, from a
//! scratch folder holding `cases/`, and must exit 0 (a `run` line with its
//! outputs and, where the scene has an exact solution, its result in
//! words). The lines left out are named in `LEFT_OUT` with why, and each
//! of those must still match a README line, so the list cannot go stale.

use std::path::{Path, PathBuf};
use std::process::Command;

/// README lines not run here (a part of the line, and why).
const LEFT_OUT: &[(&str, &str)] = &[
    ("--adapter nvidia", "needs an NVIDIA GPU"),
    (
        "lme-mpm bench",
        "two sizes × five cases × 2 s per backend: about a minute",
    ),
    ("lme-mpm study", "minutes to hours"),
    ("lme-mpm sweep", "a sweep of 6 or more runs: minutes"),
    (
        "lme-mpm run cases/aligned_vibration.toml  ",
        "ten periods of cubic B-splines: minutes on 2 cores (its one-period MLS line runs)",
    ),
    (
        "cases/rolling_disk.toml",
        "0.5 s of a disk: minutes on 2 cores",
    ),
    (
        "lme-mpm run cases/contact_block.toml",
        "0.5 s of a block sliding on a slab: a minute on 2 cores, and tests/contact.rs's \
         block_slides_on_a_slab_at_the_coulomb_rate runs the same scene to its end",
    ),
    (
        "cases/contact_rolling.toml",
        "0.5 s of a disk on a slab at R/h 20: a minute on 2 cores (tests/studies.rs runs it at R/h 10)",
    ),
    (
        "cases/column_collapse.toml",
        "2 s of soil collapse: about 6 minutes on 2 cores",
    ),
    (
        "lme-mpm render out/column_collapse",
        "needs the column collapse run above (tests/render.rs renders a small run)",
    ),
];

/// The Use block's command lines, comments stripped.
fn use_lines() -> Vec<String> {
    let readme = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md"))
        .expect("README.md");
    let start = readme.find("## Use").expect("a Use section");
    let block = &readme[start..];
    let open = block.find("```sh\n").expect("a sh block under Use") + 6;
    let close = block[open..].find("```").expect("the block closes") + open;
    block[open..close]
        .lines()
        .map(|l| l.split(" # ").next().unwrap_or("").trim_end().to_string())
        .filter(|l| !l.trim().is_empty())
        .collect()
}

fn left_out(line: &str) -> Option<&'static str> {
    // Match on the line padded as written, so "aligned_vibration.toml  "
    // (the plain run, followed by its comment's padding) is told apart
    // from the MLS line.
    let padded = format!("{line}  ");
    LEFT_OUT
        .iter()
        .find(|(part, _)| padded.contains(part))
        .map(|(_, why)| *why)
}

#[test]
fn the_use_lines_run_in_order() {
    let lines = use_lines();
    assert!(lines.len() > 10, "{lines:?}");
    for (part, _) in LEFT_OUT {
        assert!(
            lines.iter().any(|l| format!("{l}  ").contains(part)),
            "LEFT_OUT names `{part}`, which no README Use line holds any more"
        );
    }
    let dir = std::env::temp_dir().join(format!("lme-mpm-readme-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let cases = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("cases");
    std::os::unix::fs::symlink(&cases, dir.join("cases")).unwrap();
    let mut ran = 0;
    for line in &lines {
        let words: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(
            words[0], "lme-mpm",
            "a Use line that is not an lme-mpm command: {line}"
        );
        if let Some(why) = left_out(line) {
            eprintln!("README line left out ({why}): {line}");
            continue;
        }
        let start = std::time::Instant::now();
        let o = Command::new(env!("CARGO_BIN_EXE_lme-mpm"))
            .args(&words[1..])
            .current_dir(&dir)
            .env("NODEVICE_SELECT", "1")
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        let out = String::from_utf8_lossy(&o.stdout);
        assert!(
            o.status.success(),
            "README line failed ({:?}): {line}\nstderr:\n{err}\nstdout:\n{out}",
            o.status.code()
        );
        eprintln!(
            "README line ran in {:.1} s: {line}",
            start.elapsed().as_secs_f64()
        );
        ran += 1;
        match words[1] {
            "run" | "resume" => {
                let folder = match words.iter().position(|w| *w == "--out") {
                    Some(k) => dir.join(words[k + 1]),
                    None if words[1] == "resume" => dir.join(words[2]),
                    None => {
                        let stem = Path::new(words[2]).file_stem().unwrap();
                        dir.join("out").join(stem)
                    }
                };
                let summary: serde_json::Value = serde_json::from_str(
                    &std::fs::read_to_string(folder.join("summary.json")).unwrap(),
                )
                .unwrap();
                assert_eq!(summary["status"], "completed", "{line}");
                assert!(
                    folder.join("result.png").is_file(),
                    "{line}: no result.png in {folder:?}"
                );
                if !summary["errors"].is_null() {
                    assert!(
                        err.contains("result: "),
                        "{line}: no result in words:\n{err}"
                    );
                }
                if line.contains("solver.mls=true") && !line.contains("mls_scope=force") {
                    // The paper's MLS step shows the known failure, and
                    // the run says so where it prints the figure.
                    assert!(
                        err.contains("known failure") && err.contains("docs/methods.md"),
                        "{line}: the MLS failure is not named:\n{err}"
                    );
                }
                if line.contains("mls_scope=force") {
                    // The force correction is not the paper's failing step.
                    assert!(!err.contains("known failure"), "{line}:\n{err}");
                    assert_eq!(summary["mls_scope"], "force", "{line}");
                }
            }
            "check" => assert!(out.contains(": valid"), "{line}:\n{out}"),
            _ => {}
        }
    }
    // Both dyka runs kept their own folders: the FE run did not overwrite NPC's.
    let integrator = |p: &str| -> String {
        let s: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(dir.join(p).join("summary.json")).unwrap(),
        )
        .unwrap();
        s["integrator"].as_str().unwrap().to_string()
    };
    assert_eq!(integrator("out/dyka_bar"), "npc");
    assert_eq!(integrator("out/dyka_bar-fe"), "fe");
    assert!(ran >= 6, "only {ran} README lines ran");
    let _ = std::fs::remove_dir_all(&dir);
}
