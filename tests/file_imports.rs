//! No import loop between any two files of `src/` (issue 22). `layers.rs`
//! checks the top-level layers; this test checks every file against every
//! other. Each file is parsed (syn), its module tree rebuilt from the `mod`
//! declarations of the two crate roots (`lib.rs`, and `main.rs` with
//! `cmd/`), and every path a file names — `use` trees, and paths in code
//! that start with `crate`, `super`, `self`, `lme_mpm` or a child module —
//! is resolved to the file that *defines* the item, following `pub use`
//! re-exports (so a child naming `super::X` where `mod.rs` only re-exports
//! `X` from a sibling depends on the sibling, not on `mod.rs`). A file that
//! declares `mod child;` does not depend on the child for that; naming its
//! items does. The test fails on any strongly connected set of two or more
//! files, printing one loop of each.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use syn::visit::Visit;

/// One module: a file, or an inline `mod x { .. }` inside one.
struct Module {
    file: PathBuf,
    parent: Option<usize>,
    /// Crate root of this module's crate.
    root: usize,
    children: BTreeMap<String, usize>,
    /// Names of items defined here (fn, struct, enum, const, trait, ...).
    defined: BTreeSet<String>,
    /// `use` aliases: name → the absolute-or-relative path it names.
    aliases: BTreeMap<String, Vec<String>>,
    /// `use path::*` targets.
    globs: Vec<Vec<String>>,
    /// Every path this module names (use trees and qualified paths in code).
    named: Vec<Vec<String>>,
}

struct Tree {
    modules: Vec<Module>,
    lib_root: usize,
    /// `#[macro_export]` macros: (crate root, name) → defining file; they
    /// live at their crate's root path (`crate::name!`).
    exported: BTreeMap<(usize, String), PathBuf>,
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

fn src_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// Flatten a use tree into (alias, path) pairs and glob paths.
fn flatten_use(
    tree: &syn::UseTree,
    prefix: &mut Vec<String>,
    out: &mut Vec<(String, Vec<String>)>,
    globs: &mut Vec<Vec<String>>,
) {
    match tree {
        syn::UseTree::Path(p) => {
            prefix.push(p.ident.to_string());
            flatten_use(&p.tree, prefix, out, globs);
            prefix.pop();
        }
        syn::UseTree::Name(n) => {
            let name = n.ident.to_string();
            if name == "self" {
                if let Some(last) = prefix.last() {
                    out.push((last.clone(), prefix.clone()));
                }
            } else {
                let mut p = prefix.clone();
                p.push(name.clone());
                out.push((name, p));
            }
        }
        syn::UseTree::Rename(r) => {
            let mut p = prefix.clone();
            let name = r.ident.to_string();
            if name != "self" {
                p.push(name);
            }
            out.push((r.rename.to_string(), p));
        }
        syn::UseTree::Glob(_) => globs.push(prefix.clone()),
        syn::UseTree::Group(g) => {
            for t in &g.items {
                flatten_use(t, prefix, out, globs);
            }
        }
    }
}

/// Collects the qualified paths named in code (not inside nested inline
/// modules, which are modules of their own).
struct PathCollector<'a> {
    paths: &'a mut Vec<Vec<String>>,
}

impl<'ast> Visit<'ast> for PathCollector<'_> {
    fn visit_item_mod(&mut self, _: &'ast syn::ItemMod) {}
    fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
        let (mut out, mut globs) = (Vec::new(), Vec::new());
        flatten_use(&u.tree, &mut Vec::new(), &mut out, &mut globs);
        self.paths.extend(out.into_iter().map(|(_, p)| p));
        self.paths.extend(globs);
    }
    fn visit_path(&mut self, p: &'ast syn::Path) {
        if p.segments.len() >= 2 {
            self.paths
                .push(p.segments.iter().map(|s| s.ident.to_string()).collect());
        }
        syn::visit::visit_path(self, p);
    }
    fn visit_macro(&mut self, m: &'ast syn::Macro) {
        // Paths inside macro calls (format!, assert!, vec!...) are tokens:
        // read the `a::b::c` runs out of them.
        fn flush(run: &mut Vec<String>, paths: &mut Vec<Vec<String>>) {
            if run.len() >= 2 {
                paths.push(std::mem::take(run));
            }
            run.clear();
        }
        fn walk(
            ts: proc_macro2::TokenStream,
            run: &mut Vec<String>,
            last_colon: &mut bool,
            paths: &mut Vec<Vec<String>>,
        ) {
            let mut colons = 0;
            for tt in ts {
                match tt {
                    proc_macro2::TokenTree::Ident(i) => {
                        if !*last_colon {
                            flush(run, paths);
                        }
                        run.push(i.to_string());
                        *last_colon = false;
                        colons = 0;
                    }
                    proc_macro2::TokenTree::Punct(p) if p.as_char() == ':' => {
                        colons += 1;
                        if colons == 2 {
                            *last_colon = true;
                        }
                    }
                    proc_macro2::TokenTree::Group(g) => {
                        flush(run, paths);
                        *last_colon = false;
                        walk(g.stream(), run, last_colon, paths);
                        flush(run, paths);
                        colons = 0;
                    }
                    _ => {
                        flush(run, paths);
                        *last_colon = false;
                        colons = 0;
                    }
                }
            }
        }
        let mut run: Vec<String> = Vec::new();
        walk(m.tokens.clone(), &mut run, &mut false, self.paths);
        flush(&mut run, self.paths);
        syn::visit::visit_macro(self, m);
    }
}

fn item_name(item: &syn::Item) -> Option<String> {
    Some(match item {
        syn::Item::Const(i) => i.ident.to_string(),
        syn::Item::Enum(i) => i.ident.to_string(),
        syn::Item::Fn(i) => i.sig.ident.to_string(),
        syn::Item::Static(i) => i.ident.to_string(),
        syn::Item::Struct(i) => i.ident.to_string(),
        syn::Item::Trait(i) => i.ident.to_string(),
        syn::Item::Type(i) => i.ident.to_string(),
        syn::Item::Union(i) => i.ident.to_string(),
        syn::Item::Macro(i) => i.ident.as_ref()?.to_string(),
        _ => return None,
    })
}

impl Tree {
    /// Add the module whose items are `items`, in `file`, whose child
    /// files live in `dir`.
    fn add(
        &mut self,
        items: &[syn::Item],
        file: &Path,
        dir: &Path,
        parent: Option<usize>,
        root: Option<usize>,
    ) -> usize {
        let id = self.modules.len();
        self.modules.push(Module {
            file: file.to_path_buf(),
            parent,
            root: root.unwrap_or(id),
            children: BTreeMap::new(),
            defined: BTreeSet::new(),
            aliases: BTreeMap::new(),
            globs: Vec::new(),
            named: Vec::new(),
        });
        let root = root.unwrap_or(id);
        let mut named = Vec::new();
        for item in items {
            if let Some(n) = item_name(item) {
                if let syn::Item::Macro(mac) = item
                    && mac.attrs.iter().any(|a| a.path().is_ident("macro_export"))
                {
                    self.exported.insert((root, n.clone()), file.to_path_buf());
                }
                self.modules[id].defined.insert(n);
            }
            match item {
                syn::Item::Mod(m) => {
                    let name = m.ident.to_string();
                    let child = if let Some((_, inner)) = &m.content {
                        self.add(inner, file, &dir.join(&name), Some(id), Some(root))
                    } else {
                        let flat = dir.join(format!("{name}.rs"));
                        let nested = dir.join(&name).join("mod.rs");
                        let (path, child_dir) = if flat.exists() {
                            (flat, dir.join(&name))
                        } else {
                            (nested, dir.join(&name))
                        };
                        let text = std::fs::read_to_string(&path)
                            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
                        let parsed = syn::parse_file(&text)
                            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
                        self.add(&parsed.items, &path, &child_dir, Some(id), Some(root))
                    };
                    self.modules[id].children.insert(name, child);
                }
                syn::Item::Use(u) => {
                    let (mut out, mut globs) = (Vec::new(), Vec::new());
                    flatten_use(&u.tree, &mut Vec::new(), &mut out, &mut globs);
                    for (alias, path) in out {
                        named.push(path.clone());
                        self.modules[id].aliases.insert(alias, path);
                    }
                    named.extend(globs.iter().cloned());
                    self.modules[id].globs.extend(globs);
                }
                other => PathCollector { paths: &mut named }.visit_item(other),
            }
        }
        self.modules[id].named = named;
        id
    }

    /// The file that defines what `path` names, seen from module `at`;
    /// `None` for paths outside this crate (std, wgpu, ...) or local names.
    fn resolve(&self, at: usize, path: &[String], depth: usize) -> Option<PathBuf> {
        if depth > 16 || path.is_empty() {
            return None;
        }
        let m = &self.modules[at];
        let (mut cur, rest) = match path[0].as_str() {
            "crate" => (m.root, &path[1..]),
            "lme_mpm" => (self.lib_root, &path[1..]),
            "self" => (at, &path[1..]),
            "super" => {
                let mut cur = at;
                let mut i = 0;
                while path.get(i).is_some_and(|s| s == "super") {
                    cur = self.modules[cur].parent?;
                    i += 1;
                }
                (cur, &path[i..])
            }
            first => {
                if let Some(&c) = m.children.get(first) {
                    (c, &path[1..])
                } else if let Some(target) = m.aliases.get(first) {
                    if target.as_slice() == path {
                        return None;
                    }
                    let mut p = target.clone();
                    p.extend_from_slice(&path[1..]);
                    return self.resolve(at, &p, depth + 1);
                } else {
                    return None;
                }
            }
        };
        for (i, seg) in rest.iter().enumerate() {
            if let Some(&c) = self.modules[cur].children.get(seg) {
                cur = c;
                continue;
            }
            return Some(self.item(cur, seg, &rest[i + 1..], depth));
        }
        Some(self.modules[cur].file.clone())
    }

    /// The file defining item `name` of module `m` (following re-exports).
    fn item(&self, m: usize, name: &str, tail: &[String], depth: usize) -> PathBuf {
        let module = &self.modules[m];
        if module.root == m
            && let Some(f) = self.exported.get(&(m, name.to_string()))
        {
            return f.clone();
        }
        if module.defined.contains(name) {
            return module.file.clone();
        }
        if let Some(target) = module.aliases.get(name) {
            let mut p = target.clone();
            p.extend_from_slice(tail);
            if let Some(f) = self.resolve(m, &p, depth + 1) {
                return f;
            }
        }
        for g in &module.globs {
            let mut p = g.clone();
            p.push(name.to_string());
            if let Some(f) = self.resolve(m, &p, depth + 1)
                && f != module.file
            {
                return f;
            }
        }
        module.file.clone()
    }
}

fn build() -> Tree {
    let src = src_dir();
    let mut tree = Tree {
        modules: Vec::new(),
        lib_root: 0,
        exported: BTreeMap::new(),
    };
    for root in ["lib.rs", "main.rs"] {
        let path = src.join(root);
        let parsed = syn::parse_file(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let id = tree.add(&parsed.items, &path, &src, None, None);
        if root == "lib.rs" {
            tree.lib_root = id;
        }
    }
    // Files whose `mod` is declared by a macro (the material registry's
    // `register!`) are not seen above: attach them to their directory's
    // module, as rustc's file layout says they are.
    let mut all = Vec::new();
    rust_files(&src, &mut all);
    all.sort_by_key(|p| p.components().count());
    for file in all {
        if tree.modules.iter().any(|m| m.file == file) {
            continue;
        }
        let dir = file.parent().unwrap();
        let parent = tree
            .modules
            .iter()
            .position(|m| m.file == dir.join("mod.rs") || m.file == dir.with_extension("rs"))
            .unwrap_or_else(|| panic!("{}: no module declares it", file.display()));
        let name = file.file_stem().unwrap().to_string_lossy().into_owned();
        let (name, child_dir) = if name == "mod" {
            unreachable!("{}: a mod.rs no module declares", file.display())
        } else {
            (name.clone(), dir.join(&name))
        };
        let parsed = syn::parse_file(&std::fs::read_to_string(&file).unwrap()).unwrap();
        let root = tree.modules[parent].root;
        let id = tree.add(&parsed.items, &file, &child_dir, Some(parent), Some(root));
        tree.modules[parent].children.insert(name, id);
    }
    tree
}

type Graph = BTreeMap<PathBuf, BTreeSet<PathBuf>>;
/// (from, to) → the first path that made the dependency, for messages.
type Why = BTreeMap<(PathBuf, PathBuf), String>;

/// File → files it depends on.
fn file_graph(tree: &Tree) -> (Graph, Why) {
    let mut g: Graph = BTreeMap::new();
    let mut why = Why::new();
    for (id, m) in tree.modules.iter().enumerate() {
        let entry = g.entry(m.file.clone()).or_default();
        for p in &m.named {
            if let Some(f) = tree.resolve(id, p, 0)
                && f != m.file
            {
                why.entry((m.file.clone(), f.clone()))
                    .or_insert_with(|| p.join("::"));
                entry.insert(f);
            }
        }
    }
    (g, why)
}

/// Strongly connected sets of two or more files (Tarjan).
fn loops(g: &BTreeMap<PathBuf, BTreeSet<PathBuf>>) -> Vec<Vec<PathBuf>> {
    let nodes: Vec<&PathBuf> = g.keys().collect();
    let index_of: BTreeMap<&PathBuf, usize> =
        nodes.iter().enumerate().map(|(i, n)| (*n, i)).collect();
    let adj: Vec<Vec<usize>> = nodes
        .iter()
        .map(|n| {
            g[*n]
                .iter()
                .filter_map(|d| index_of.get(d).copied())
                .collect()
        })
        .collect();
    struct St {
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        on: Vec<bool>,
        stack: Vec<usize>,
        next: usize,
        out: Vec<Vec<usize>>,
    }
    fn strong(v: usize, adj: &[Vec<usize>], s: &mut St) {
        s.index[v] = Some(s.next);
        s.low[v] = s.next;
        s.next += 1;
        s.stack.push(v);
        s.on[v] = true;
        for &w in &adj[v] {
            match s.index[w] {
                None => {
                    strong(w, adj, s);
                    s.low[v] = s.low[v].min(s.low[w]);
                }
                Some(iw) if s.on[w] => s.low[v] = s.low[v].min(iw),
                _ => {}
            }
        }
        if Some(s.low[v]) == s.index[v] {
            let mut comp = Vec::new();
            loop {
                let w = s.stack.pop().unwrap();
                s.on[w] = false;
                comp.push(w);
                if w == v {
                    break;
                }
            }
            if comp.len() > 1 {
                s.out.push(comp);
            }
        }
    }
    let n = nodes.len();
    let mut s = St {
        index: vec![None; n],
        low: vec![0; n],
        on: vec![false; n],
        stack: Vec::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in 0..n {
        if s.index[v].is_none() {
            strong(v, &adj, &mut s);
        }
    }
    s.out
        .into_iter()
        .map(|c| c.into_iter().map(|i| nodes[i].clone()).collect())
        .collect()
}

/// One loop through the first file of a strongly connected set, for the
/// message.
fn one_loop(g: &BTreeMap<PathBuf, BTreeSet<PathBuf>>, set: &[PathBuf]) -> Vec<PathBuf> {
    let inside: BTreeSet<&PathBuf> = set.iter().collect();
    let start = &set[0];
    // Breadth-first from start back to start, inside the set.
    let mut prev: BTreeMap<&PathBuf, &PathBuf> = BTreeMap::new();
    let mut queue = std::collections::VecDeque::from([start]);
    while let Some(at) = queue.pop_front() {
        for next in &g[at] {
            if !inside.contains(next) {
                continue;
            }
            if next == start {
                let mut path = vec![start.clone()];
                let mut cur = at;
                while cur != start {
                    path.push(cur.clone());
                    cur = prev[cur];
                }
                path.push(start.clone());
                path.reverse();
                return path;
            }
            if !prev.contains_key(next) {
                prev.insert(next, at);
                queue.push_back(next);
            }
        }
    }
    set.to_vec()
}

#[test]
fn no_import_loop_between_files() {
    let tree = build();
    let (g, why) = file_graph(&tree);
    let src = src_dir();
    let show = |p: &PathBuf| p.strip_prefix(&src).unwrap().display().to_string();
    let found: Vec<String> = loops(&g)
        .iter()
        .map(|set| {
            let path = one_loop(&g, set);
            let mut text = show(&path[0]);
            for w in path.windows(2) {
                let via = why.get(&(w[0].clone(), w[1].clone())).cloned();
                text += &format!(" -> {} ({})", show(&w[1]), via.unwrap_or_default());
            }
            let mut members: Vec<String> = set.iter().map(show).collect();
            members.sort();
            format!("{text}\n    all files of this loop: {}", members.join(", "))
        })
        .collect();
    assert!(
        found.is_empty(),
        "{} import loop(s) between files of src/:\n{}",
        found.len(),
        found.join("\n")
    );
}

/// The resolver itself: a re-export is followed to the defining file, a
/// `mod` declaration alone is no dependency, naming a child's item is one.
#[test]
fn resolver_follows_reexports() {
    let tree = build();
    let (g, _) = file_graph(&tree);
    let src = src_dir();
    let lib = src.join("lib.rs");
    // lib.rs re-exports Error from error.rs: a file naming `crate::Error`
    // depends on error.rs, not on lib.rs.
    let lib_id = tree.lib_root;
    assert_eq!(
        tree.resolve(lib_id, &["crate".into(), "Error".into()], 0),
        Some(src.join("error.rs"))
    );
    // lib.rs declares every top-level module but names only what it
    // re-exports.
    assert!(g[&lib].len() <= 3, "lib.rs depends on {:?}", g[&lib]);
    // External paths resolve to nothing.
    assert_eq!(
        tree.resolve(lib_id, &["std".into(), "fs".into(), "read".into()], 0),
        None
    );
    // The graph is not empty: the run driver names the scene.
    assert!(
        g[&src.join("run.rs")]
            .iter()
            .any(|f| f.starts_with(src.join("scene"))),
        "run.rs -> scene/ not seen"
    );
}

/// The loop finder itself, on a small graph: a → b → c → a is one loop of
/// three files, d → a is outside it, e alone is none.
#[test]
fn loop_finder_finds_loops() {
    let p = |s: &str| PathBuf::from(s);
    let mut g = Graph::new();
    for (from, to) in [("a", "b"), ("b", "c"), ("c", "a"), ("d", "a")] {
        g.entry(p(from)).or_default().insert(p(to));
        g.entry(p(to)).or_default();
    }
    g.entry(p("e")).or_default();
    let found = loops(&g);
    assert_eq!(found.len(), 1, "{found:?}");
    let mut set = found[0].clone();
    set.sort();
    assert_eq!(set, [p("a"), p("b"), p("c")]);
    let path = one_loop(&g, &found[0]);
    assert_eq!(path.first(), path.last());
    assert_eq!(path.len(), 4, "{path:?}");
}
