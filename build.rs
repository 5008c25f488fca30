//! Discovers the WGSL sources under `shaders/` and writes the table
//! `gpu::preprocess::SOURCES` compiles in (`$OUT_DIR/shaders.rs`): a new
//! `.wgsl` file needs no list edit. Fails the build, naming the file, when
//! a shader is used by nothing: every top-level `shaders/*.wgsl` is a
//! pass, `shaders/shared/material_*.wgsl` are included by the material
//! registry's generated dispatch, and every other file must be reached by
//! `#include` from one of those (whatever the `#if` around it; which pass
//! uses which file is checked by the tests).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn wgsl_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("reading {}: {e}", dir.display()))
        .map(|e| e.expect("a directory entry").path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            wgsl_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "wgsl") {
            out.push(p);
        }
    }
}

/// The files `text` includes (`#include "path" ARGS`).
fn includes(text: &str) -> Vec<String> {
    text.lines()
        .filter_map(|l| l.trim_start().strip_prefix("#include"))
        .filter_map(|rest| rest.split_whitespace().next())
        .map(|w| w.trim_matches('"').to_string())
        .collect()
}

fn main() {
    let root = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    let dir = root.join("shaders");
    println!("cargo:rerun-if-changed=shaders");
    let mut files = Vec::new();
    wgsl_files(&dir, &mut files);
    let mut sources: BTreeMap<String, (PathBuf, String)> = BTreeMap::new();
    for f in &files {
        println!("cargo:rerun-if-changed={}", f.display());
        let rel = f
            .strip_prefix(&dir)
            .expect("under shaders/")
            .to_string_lossy()
            .replace('\\', "/");
        let text =
            std::fs::read_to_string(f).unwrap_or_else(|e| panic!("reading {}: {e}", f.display()));
        sources.insert(rel, (f.clone(), text));
    }

    // Reachability from the roots.
    let is_root = |rel: &str| {
        !rel.contains('/')
            || rel
                .strip_prefix("shared/material_")
                .is_some_and(|r| r.ends_with(".wgsl"))
    };
    let mut reached: BTreeSet<String> = sources.keys().filter(|r| is_root(r)).cloned().collect();
    let mut todo: Vec<String> = reached.iter().cloned().collect();
    while let Some(r) = todo.pop() {
        for inc in includes(&sources[&r].1) {
            if inc.starts_with("generated/") {
                continue;
            }
            if !sources.contains_key(&inc) {
                panic!("shaders/{r} includes {inc:?}, which is not a file under shaders/");
            }
            if reached.insert(inc.clone()) {
                todo.push(inc);
            }
        }
    }
    let unused: Vec<&String> = sources.keys().filter(|r| !reached.contains(*r)).collect();
    if !unused.is_empty() {
        panic!(
            "shaders used by nothing (no pass file shaders/*.wgsl or material includes them): {}; \
             include them where they are needed or remove them",
            unused
                .iter()
                .map(|r| format!("shaders/{r}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }

    let mut table = String::from(
        "/// Every WGSL file under `shaders/`, by path relative to it (found by build.rs).\n\
         pub const SOURCES: &[(&str, &str)] = &[\n",
    );
    for (rel, (path, _)) in &sources {
        table += &format!(
            "    ({rel:?}, include_str!({:?})),\n",
            path.display().to_string()
        );
    }
    table += "];\n";
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets it")).join("shaders.rs");
    std::fs::write(&out, table).unwrap_or_else(|e| panic!("writing {}: {e}", out.display()));
}
