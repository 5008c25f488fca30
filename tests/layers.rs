//! The layers of `src/` point one way (docs/architecture.md): scene and
//! limits → model → backends (cpu/, gpu/) → driver → commands, with exact/
//! scoring above what it scores. This test reads every `crate::` path in
//! `src/**/*.rs` (in `use` lines and inline) and fails on an import cycle
//! between top-level modules, on a backend importing the other, and on
//! anything below the driver importing the CPU backend or the scoring.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Top-level module of a file under `src/`: `src/gpu/mod.rs` → `gpu`,
/// `src/run.rs` → `run`; the crate roots count as `lib` / `main`.
fn module_of(src: &Path, file: &Path) -> String {
    let rel = file.strip_prefix(src).unwrap();
    let first = rel
        .components()
        .next()
        .unwrap()
        .as_os_str()
        .to_string_lossy();
    first.trim_end_matches(".rs").to_string()
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// Top-level modules named after each `crate::` in `text`, including the
/// members of a grouped `crate::{a, b::c}`. Comments are skipped.
fn imports(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for line in text.lines() {
        let code = line.split("//").next().unwrap_or("");
        let mut rest = code;
        while let Some(k) = rest.find("crate::") {
            rest = &rest[k + "crate::".len()..];
            if let Some(group) = rest.strip_prefix('{') {
                // Names at brace depth 0 of the group (one line is enough
                // for rustfmt's grouped imports of top-level modules).
                let mut depth = 0;
                let mut name = String::new();
                let mut at_start = true;
                for c in group.chars() {
                    match c {
                        '{' => depth += 1,
                        '}' if depth == 0 => break,
                        '}' => depth -= 1,
                        ',' if depth == 0 => {
                            at_start = true;
                            name.clear();
                            continue;
                        }
                        _ => {}
                    }
                    if depth == 0 && at_start {
                        if c.is_alphanumeric() || c == '_' {
                            name.push(c);
                        } else if !name.is_empty() {
                            out.insert(std::mem::take(&mut name));
                            at_start = false;
                        }
                    }
                }
                if at_start && !name.is_empty() {
                    out.insert(name);
                }
            } else {
                let name: String = rest
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if !name.is_empty() {
                    out.insert(name);
                }
            }
        }
    }
    out
}

/// Module → modules it imports, and per file the modules it imports.
type Graph = BTreeMap<String, BTreeSet<String>>;
type FileImports = Vec<(PathBuf, BTreeSet<String>)>;

fn graph() -> (Graph, FileImports) {
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut per_file = Vec::new();
    for f in files {
        let m = module_of(&src, &f);
        let text = std::fs::read_to_string(&f).unwrap();
        let deps: BTreeSet<String> = imports(&text).into_iter().filter(|d| *d != m).collect();
        g.entry(m).or_default().extend(deps.iter().cloned());
        per_file.push((f, deps));
    }
    (g, per_file)
}

/// A cycle through `start`, if any (depth-first search).
fn cycle_from(g: &BTreeMap<String, BTreeSet<String>>, start: &str) -> Option<Vec<String>> {
    fn dfs(
        g: &BTreeMap<String, BTreeSet<String>>,
        at: &str,
        start: &str,
        path: &mut Vec<String>,
        seen: &mut BTreeSet<String>,
    ) -> bool {
        for next in g.get(at).into_iter().flatten() {
            if next == start {
                path.push(next.clone());
                return true;
            }
            if seen.insert(next.clone()) {
                path.push(next.clone());
                if dfs(g, next, start, path, seen) {
                    return true;
                }
                path.pop();
            }
        }
        false
    }
    let mut path = vec![start.to_string()];
    let mut seen = BTreeSet::new();
    dfs(g, start, start, &mut path, &mut seen).then_some(path)
}

#[test]
fn top_level_modules_form_no_cycle() {
    let (g, _) = graph();
    let cycles: Vec<String> = g
        .keys()
        .filter(|m| *m != "lib" && *m != "main")
        .filter_map(|m| cycle_from(&g, m))
        .map(|c| c.join(" -> "))
        .collect();
    assert!(cycles.is_empty(), "import cycles in src/: {cycles:#?}");
}

#[test]
fn layers_point_one_way() {
    let (_, files) = graph();
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src");
    // (module, what it must not import, why)
    let rules: &[(&str, &[&str], &str)] = &[
        (
            "gpu",
            &["cpu", "run", "simulation", "study", "exact"],
            "a backend never imports the other backend or anything above it",
        ),
        (
            "cpu",
            &["gpu", "run", "simulation", "study", "exact"],
            "a backend never imports the other backend or anything above it",
        ),
        (
            "backend",
            &["cpu", "gpu", "exact"],
            "the backend contract is neutral",
        ),
        (
            "solver",
            &["cpu", "gpu", "exact"],
            "the driver steps any backend",
        ),
        (
            "step",
            &[
                "cpu", "gpu", "backend", "solver", "exact", "run", "output", "study",
            ],
            "the step plan is read by both backends and built from the model alone",
        ),
        (
            "model",
            &[
                "cpu", "gpu", "backend", "solver", "exact", "run", "output", "study", "step",
            ],
            "the model layer is the bottom",
        ),
        (
            "gmm",
            &[
                "cpu",
                "gpu",
                "backend",
                "solver",
                "exact",
                "run",
                "output",
                "study",
                "step",
                "simulation",
            ],
            "GMM's cloud and bases sit beside the grid, above the model: any backend may use them",
        ),
        (
            "scene",
            &["model", "cpu", "gpu", "backend", "solver", "exact", "run"],
            "a scene is validated without the model",
        ),
        (
            "limits",
            &["model", "scene", "cpu", "gpu"],
            "limits import nothing",
        ),
        (
            "exact",
            &["cpu", "gpu", "run", "simulation", "study"],
            "scoring sits above what it scores, never on a backend",
        ),
    ];
    let mut broken = Vec::new();
    for (file, deps) in &files {
        let m = module_of(&src, file);
        for (module, banned, why) in rules {
            if m != *module {
                continue;
            }
            for b in deps.iter().filter(|d| banned.contains(&d.as_str())) {
                broken.push(format!(
                    "{} imports crate::{b}: {why}",
                    file.strip_prefix(&src).unwrap().display()
                ));
            }
        }
    }
    assert!(
        broken.is_empty(),
        "layer rules broken:\n{}",
        broken.join("\n")
    );
}

/// The parser itself: grouped imports and inline paths are seen.
#[test]
fn import_parser_sees_groups_and_paths() {
    let text = "use crate::{cpu::CpuBackend, model::{Grid, Model}, error};\n\
                let x = crate::gpu::context::open(); // crate::study in a comment\n";
    let got: Vec<String> = imports(text).into_iter().collect();
    assert_eq!(got, ["cpu", "error", "gpu", "model"]);
}

/// The `Material` variants `register!` declares in
/// `src/model/material/mod.rs`: the `Variant(module::Type)` lines of its
/// invocation.
fn registered_variants(src: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(src.join("model/material/mod.rs")).unwrap();
    let start = text
        .find("\nregister! {")
        .expect("the register! invocation");
    let body = &text[start..];
    let body = &body[..body.find("\n}").expect("its end")];
    body.lines()
        .skip(2)
        .filter_map(|l| {
            let l = l.trim();
            let (variant, rest) = l.split_once('(')?;
            rest.contains("::").then(|| variant.to_string())
        })
        .collect()
}

/// A material is its own files and one line of `register!`
/// (docs/architecture.md, "Adding a material"): no file outside
/// `src/model/material/` matches on a `Material` variant (σzz, state
/// columns, name lists all come through `Constitutive` and the registry).
#[test]
fn materials_are_matched_only_in_their_own_files() {
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src");
    let variants = registered_variants(&src);
    for v in [
        "LinearElastic",
        "NeoHookean",
        "MohrCoulomb",
        "DruckerPrager",
        "ModifiedCamClay",
    ] {
        assert!(variants.iter().any(|r| r == v), "{v} in {variants:?}");
    }
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let own = src.join("model").join("material");
    let mut found = Vec::new();
    for f in files.iter().filter(|f| !f.starts_with(&own)) {
        let text = std::fs::read_to_string(f).unwrap();
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            for v in &variants {
                let pat = format!("Material::{v}");
                let hit = code.match_indices(&pat).any(|(k, _)| {
                    let after = code[k + pat.len()..].chars().next();
                    !after.is_some_and(|c| c.is_alphanumeric() || c == '_')
                });
                if hit {
                    found.push(format!("{}:{}: {}", f.display(), n + 1, line.trim()));
                }
            }
        }
    }
    assert!(
        found.is_empty(),
        "material variants named outside src/model/material/ (give the model a \
         `Constitutive` item instead):\n{}",
        found.join("\n")
    );
}
