//! A small WGSL preprocessor, so each pipeline is built for its scene: only
//! the shape function, integrator and material the scene uses are compiled
//! in, and only the buffers they need are declared.
//!
//! - `#include "shared/name.wgsl"`: pasted in once per file (later includes
//!   of the same file are skipped); `#include "shared/x.wgsl" A=b C=d` adds
//!   values for that inclusion (a file included with different values is
//!   pasted once per set: a template, e.g. one atomic-add per array);
//! - `#if NAME` / `#elif NAME` / `#else` / `#endif`, also `#if !NAME`,
//!   nestable: NAME is a flag that is set or not;
//! - `{{NAME}}`: replaced by a value (binding numbers, stencil sizes).
//!
//! The sources are compiled into the binary (`include_str!`), so the
//! executable needs no files at run time.

use std::collections::{BTreeMap, BTreeSet};

/// Every WGSL file, by path relative to `shaders/`.
pub const SOURCES: &[(&str, &str)] = &[
    (
        "shared/types.wgsl",
        include_str!("../../shaders/shared/types.wgsl"),
    ),
    (
        "shared/common.wgsl",
        include_str!("../../shaders/shared/common.wgsl"),
    ),
    (
        "shared/shape_bindings.wgsl",
        include_str!("../../shaders/shared/shape_bindings.wgsl"),
    ),
    (
        "shared/material_bindings.wgsl",
        include_str!("../../shaders/shared/material_bindings.wgsl"),
    ),
    (
        "shared/atomics.wgsl",
        include_str!("../../shaders/shared/atomics.wgsl"),
    ),
    (
        "shared/shape.wgsl",
        include_str!("../../shaders/shared/shape.wgsl"),
    ),
    (
        "shared/shape_linear.wgsl",
        include_str!("../../shaders/shared/shape_linear.wgsl"),
    ),
    (
        "shared/shape_ugimp.wgsl",
        include_str!("../../shaders/shared/shape_ugimp.wgsl"),
    ),
    (
        "shared/shape_lme.wgsl",
        include_str!("../../shaders/shared/shape_lme.wgsl"),
    ),
    (
        "shared/shape_bspline.wgsl",
        include_str!("../../shaders/shared/shape_bspline.wgsl"),
    ),
    (
        "shared/material.wgsl",
        include_str!("../../shaders/shared/material.wgsl"),
    ),
    (
        "shared/body_force.wgsl",
        include_str!("../../shaders/shared/body_force.wgsl"),
    ),
    (
        "shared/mls.wgsl",
        include_str!("../../shaders/shared/mls.wgsl"),
    ),
    (
        "shared/bins.wgsl",
        include_str!("../../shaders/shared/bins.wgsl"),
    ),
    (
        "bin_clear.wgsl",
        include_str!("../../shaders/bin_clear.wgsl"),
    ),
    (
        "bin_count.wgsl",
        include_str!("../../shaders/bin_count.wgsl"),
    ),
    ("bin_scan.wgsl", include_str!("../../shaders/bin_scan.wgsl")),
    ("bin_fill.wgsl", include_str!("../../shaders/bin_fill.wgsl")),
    ("mls_p2g.wgsl", include_str!("../../shaders/mls_p2g.wgsl")),
    (
        "mls_forces.wgsl",
        include_str!("../../shaders/mls_forces.wgsl"),
    ),
    ("remap.wgsl", include_str!("../../shaders/remap.wgsl")),
    (
        "mls_remap.wgsl",
        include_str!("../../shaders/mls_remap.wgsl"),
    ),
    (
        "shared/material_linear_elastic.wgsl",
        include_str!("../../shaders/shared/material_linear_elastic.wgsl"),
    ),
    (
        "shared/material_neo_hookean.wgsl",
        include_str!("../../shaders/shared/material_neo_hookean.wgsl"),
    ),
    (
        "shared/material_plastic.wgsl",
        include_str!("../../shaders/shared/material_plastic.wgsl"),
    ),
    (
        "shared/material_mohr_coulomb.wgsl",
        include_str!("../../shaders/shared/material_mohr_coulomb.wgsl"),
    ),
    (
        "shared/material_drucker_prager.wgsl",
        include_str!("../../shaders/shared/material_drucker_prager.wgsl"),
    ),
    (
        "step_begin.wgsl",
        include_str!("../../shaders/step_begin.wgsl"),
    ),
    ("cfl.wgsl", include_str!("../../shaders/cfl.wgsl")),
    (
        "clear_grid.wgsl",
        include_str!("../../shaders/clear_grid.wgsl"),
    ),
    (
        "lme_newton.wgsl",
        include_str!("../../shaders/lme_newton.wgsl"),
    ),
    ("p2g.wgsl", include_str!("../../shaders/p2g.wgsl")),
    (
        "wall_touch.wgsl",
        include_str!("../../shaders/wall_touch.wgsl"),
    ),
    (
        "grid_update.wgsl",
        include_str!("../../shaders/grid_update.wgsl"),
    ),
    ("stress.wgsl", include_str!("../../shaders/stress.wgsl")),
    ("forces.wgsl", include_str!("../../shaders/forces.wgsl")),
    ("g2p.wgsl", include_str!("../../shaders/g2p.wgsl")),
    ("step_end.wgsl", include_str!("../../shaders/step_end.wgsl")),
    ("probes.wgsl", include_str!("../../shaders/probes.wgsl")),
    ("energy.wgsl", include_str!("../../shaders/energy.wgsl")),
];

fn source(path: &str) -> Result<&'static str, String> {
    SOURCES
        .iter()
        .find(|(p, _)| *p == path)
        .map(|(_, s)| *s)
        .ok_or_else(|| format!("unknown WGSL file {path:?}"))
}

/// Flags and values a file is expanded with.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Defines {
    pub flags: BTreeSet<String>,
    pub values: BTreeMap<String, String>,
}

impl Defines {
    pub fn flag(&mut self, name: &str, on: bool) -> &mut Self {
        if on {
            self.flags.insert(name.to_string());
        } else {
            self.flags.remove(name);
        }
        self
    }

    pub fn value(&mut self, name: &str, v: impl ToString) -> &mut Self {
        self.values.insert(name.to_string(), v.to_string());
        self
    }
}

/// Expands `path` with `defines` into one WGSL module.
pub fn expand(path: &str, defines: &Defines) -> Result<String, String> {
    let mut out = String::new();
    let mut seen = BTreeSet::new();
    expand_into(path, defines, &mut out, &mut seen)?;
    Ok(out)
}

/// Expands WGSL `text` (named `name` in errors) with `defines`: its
/// includes come from `SOURCES`. For kernels that are not passes, such as
/// the material test harness (`tests/material_returns.rs`).
pub fn expand_text(text: &str, name: &str, defines: &Defines) -> Result<String, String> {
    let mut out = String::new();
    let mut seen = BTreeSet::new();
    expand_source(text, name, defines, &mut out, &mut seen)?;
    Ok(out)
}

fn expand_into(
    path: &str,
    d: &Defines,
    out: &mut String,
    seen: &mut BTreeSet<String>,
) -> Result<(), String> {
    expand_include(path, &[], d, out, seen)
}

/// Pastes `path` expanded with `d` plus the inclusion's own `args`, once per
/// (path, args).
fn expand_include(
    path: &str,
    args: &[(String, String)],
    d: &Defines,
    out: &mut String,
    seen: &mut BTreeSet<String>,
) -> Result<(), String> {
    let key = std::iter::once(path.to_string())
        .chain(args.iter().map(|(k, v)| format!("{k}={v}")))
        .collect::<Vec<_>>()
        .join(" ");
    if !seen.insert(key) {
        return Ok(());
    }
    if args.is_empty() {
        return expand_source(source(path)?, path, d, out, seen);
    }
    let mut local = d.clone();
    for (k, v) in args {
        local.value(k, v);
    }
    expand_source(source(path)?, path, &local, out, seen)
}

fn expand_source(
    text: &str,
    path: &str,
    d: &Defines,
    out: &mut String,
    seen: &mut BTreeSet<String>,
) -> Result<(), String> {
    // Stack of (this branch active, some branch of this #if already taken).
    let mut stack: Vec<(bool, bool)> = Vec::new();
    let active = |stack: &[(bool, bool)]| stack.iter().all(|(a, _)| *a);
    let eval = |cond: &str| -> bool {
        let c = cond.trim();
        match c.strip_prefix('!') {
            Some(n) => !d.flags.contains(n.trim()),
            None => d.flags.contains(c),
        }
    };
    for (lineno, line) in text.lines().enumerate() {
        let t = line.trim_start();
        let at = || format!("{path}:{}", lineno + 1);
        if let Some(rest) = t.strip_prefix("#include") {
            if active(&stack) {
                let mut words = rest.split_whitespace();
                let inc = words.next().unwrap_or("").trim_matches('"');
                let args = words
                    .map(|w| {
                        w.split_once('=')
                            .map(|(k, v)| (k.to_string(), v.to_string()))
                            .ok_or_else(|| {
                                format!("{}: #include argument {w:?} is not NAME=VALUE", at())
                            })
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                expand_include(inc, &args, d, out, seen).map_err(|e| format!("{}: {e}", at()))?;
            }
        } else if let Some(cond) = t.strip_prefix("#if ") {
            let on = active(&stack) && eval(cond);
            stack.push((on, on));
        } else if let Some(cond) = t.strip_prefix("#elif ") {
            let parent = active(&stack[..stack.len().saturating_sub(1)]);
            let top = stack
                .last_mut()
                .ok_or_else(|| format!("{}: #elif without #if", at()))?;
            let on = parent && !top.1 && eval(cond);
            *top = (on, top.1 || on);
        } else if t.starts_with("#else") {
            let parent = active(&stack[..stack.len().saturating_sub(1)]);
            let top = stack
                .last_mut()
                .ok_or_else(|| format!("{}: #else without #if", at()))?;
            *top = (parent && !top.1, true);
        } else if t.starts_with("#endif") {
            stack
                .pop()
                .ok_or_else(|| format!("{}: #endif without #if", at()))?;
        } else if active(&stack) {
            out.push_str(&substitute(line, d).map_err(|e| format!("{}: {e}", at()))?);
            out.push('\n');
        }
    }
    if !stack.is_empty() {
        return Err(format!("{path}: #if without #endif"));
    }
    Ok(())
}

fn substitute(line: &str, d: &Defines) -> Result<String, String> {
    let mut out = String::with_capacity(line.len());
    let mut rest = line;
    while let Some(i) = rest.find("{{") {
        out.push_str(&rest[..i]);
        let j = rest[i..].find("}}").ok_or("unclosed {{")? + i;
        let name = rest[i + 2..j].trim();
        let v = d
            .values
            .get(name)
            .ok_or_else(|| format!("no value for {{{{{name}}}}}"))?;
        out.push_str(v);
        rest = &rest[j + 2..];
    }
    out.push_str(rest);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conditionals_nest_and_else_branches_exclude_each_other() {
        let mut d = Defines::default();
        d.flag("A", true).value("N", 7);
        let src = "x\n#if A\na {{N}}\n#if B\nb\n#elif A\nab\n#else\nnotb\n#endif\n#else\nnota\n#endif\n#if !B\nnob\n#endif\n";
        let mut out = String::new();
        expand_source(src, "test.wgsl", &d, &mut out, &mut BTreeSet::new()).unwrap();
        assert_eq!(out, "x\na 7\nab\nnob\n");
    }

    #[test]
    fn errors_name_the_file_and_line() {
        let d = Defines::default();
        let mut out = String::new();
        let e =
            expand_source("a\n#endif\n", "f.wgsl", &d, &mut out, &mut BTreeSet::new()).unwrap_err();
        assert_eq!(e, "f.wgsl:2: #endif without #if");
        let e = expand_source("{{X}}\n", "f.wgsl", &d, &mut out, &mut BTreeSet::new()).unwrap_err();
        assert!(e.contains("no value for {{X}}"), "{e}");
    }
}
