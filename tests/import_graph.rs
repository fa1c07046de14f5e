//! The file import graph of the library (`src/`, without the binaries under `src/bin/`) has no
//! cycle, and the independent verifier (`src/verify/`) imports nothing of the pipelines it
//! checks.
//!
//! Each file is a module (`a/b.rs` and `a/b/mod.rs` are `crate::a::b`). Its references are the
//! paths starting with `crate::`, `super::` or `self::`, in `use` items (trees expanded) and
//! inline in code; comments, string literals and `#[cfg(test)]` items (test modules, test-only
//! imports) are skipped.
//! `super`/`self` are resolved against the module the path is written in (inline modules such as
//! `mod imp { … }` included), and every path to the deepest module that is a file. References
//! from a file to itself are ignored.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// A module path (`["crate", "wrinkle", "cwf"]`).
type ModPath = Vec<String>;

fn src_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// Every `.rs` file under `dir` (recursively), `src/bin/` excluded.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut paths: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    paths.sort();
    for p in paths {
        if p.is_dir() {
            if p != src_dir().join("bin") {
                rust_files(&p, out);
            }
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// `src/a/b.rs` and `src/a/b/mod.rs` → `crate::a::b`; `src/lib.rs` → `crate`.
fn module_of(file: &Path) -> ModPath {
    let rel = file.strip_prefix(src_dir()).expect("under src/");
    let mut parts: Vec<String> = rel
        .iter()
        .map(|s| s.to_string_lossy().into_owned())
        .collect();
    let last = parts.pop().expect("a file name");
    let stem = last.trim_end_matches(".rs").to_string();
    if stem != "mod" && !(parts.is_empty() && stem == "lib") {
        parts.push(stem);
    }
    std::iter::once("crate".to_string()).chain(parts).collect()
}

/// The source with comments and the contents of string and char literals removed (a literal
/// becomes `""`), so paths inside them are not read as references.
fn strip_comments_and_strings(src: &str) -> String {
    let c: Vec<char> = src.chars().collect();
    let mut out = String::with_capacity(src.len());
    let mut i = 0;
    while i < c.len() {
        if c[i] == '/' && c.get(i + 1) == Some(&'/') {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if c[i] == '/' && c.get(i + 1) == Some(&'*') {
            let mut depth = 0;
            while i < c.len() {
                if c[i] == '/' && c.get(i + 1) == Some(&'*') {
                    depth += 1;
                    i += 2;
                } else if c[i] == '*' && c.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
            out.push(' ');
        } else if c[i] == 'r'
            && matches!(c.get(i + 1), Some('"') | Some('#'))
            && !ident_before(&c, i)
        {
            // raw string r"…" or r#"…"#
            let mut j = i + 1;
            let mut hashes = 0;
            while c.get(j) == Some(&'#') {
                hashes += 1;
                j += 1;
            }
            if c.get(j) != Some(&'"') {
                out.push(c[i]);
                i += 1;
                continue;
            }
            j += 1;
            loop {
                if j >= c.len() {
                    break;
                }
                if c[j] == '"' && (1..=hashes).all(|k| c.get(j + k) == Some(&'#')) {
                    j += 1 + hashes;
                    break;
                }
                j += 1;
            }
            out.push_str("\"\"");
            i = j;
        } else if c[i] == '"' {
            i += 1;
            while i < c.len() && c[i] != '"' {
                if c[i] == '\\' {
                    i += 1;
                }
                i += 1;
            }
            i += 1;
            out.push_str("\"\"");
        } else if c[i] == '\'' {
            // char literal ('x', '\n', '\u{..}') or a lifetime ('a)
            if c.get(i + 1) == Some(&'\\') {
                let mut j = i + 2;
                while j < c.len() && c[j] != '\'' {
                    j += 1;
                }
                i = j + 1;
                out.push_str("' '");
            } else if c.get(i + 2) == Some(&'\'') {
                i += 3;
                out.push_str("' '");
            } else {
                out.push('\'');
                i += 1;
            }
        } else {
            out.push(c[i]);
            i += 1;
        }
    }
    out
}

fn ident_before(c: &[char], i: usize) -> bool {
    i > 0 && (c[i - 1].is_alphanumeric() || c[i - 1] == '_')
}

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Ident(String),
    /// `::`
    Path,
    Punct(char),
}

fn tokenize(src: &str) -> Vec<Tok> {
    let c: Vec<char> = src.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < c.len() {
        if c[i].is_alphanumeric() || c[i] == '_' {
            let s = i;
            while i < c.len() && (c[i].is_alphanumeric() || c[i] == '_') {
                i += 1;
            }
            out.push(Tok::Ident(c[s..i].iter().collect()));
        } else if c[i] == ':' && c.get(i + 1) == Some(&':') {
            out.push(Tok::Path);
            i += 2;
        } else {
            if !c[i].is_whitespace() {
                out.push(Tok::Punct(c[i]));
            }
            i += 1;
        }
    }
    out
}

fn is_ident(t: Option<&Tok>, s: &str) -> bool {
    matches!(t, Some(Tok::Ident(x)) if x == s)
}

/// Removes every item under `#[cfg(test)]` (a `mod tests { … }` block, a test-only `use`, …):
/// after the attribute, everything up to the item's `;` or its closing brace (brace matching).
fn drop_test_items(toks: Vec<Tok>) -> Vec<Tok> {
    let attr = [
        Tok::Punct('#'),
        Tok::Punct('['),
        Tok::Ident("cfg".into()),
        Tok::Punct('('),
        Tok::Ident("test".into()),
        Tok::Punct(')'),
        Tok::Punct(']'),
    ];
    let mut out = Vec::with_capacity(toks.len());
    let mut i = 0;
    while i < toks.len() {
        if toks.len() < i + attr.len() || toks[i..i + attr.len()] != attr {
            out.push(toks[i].clone());
            i += 1;
            continue;
        }
        i += attr.len();
        let mut depth = 0usize;
        while i < toks.len() {
            let t = &toks[i];
            i += 1;
            match t {
                Tok::Punct('(' | '[' | '{') => depth += 1,
                Tok::Punct(')' | ']') => depth = depth.saturating_sub(1),
                Tok::Punct('}') => {
                    depth = depth.saturating_sub(1);
                    if depth == 0 {
                        break;
                    }
                }
                Tok::Punct(';') if depth == 0 => break,
                _ => {}
            }
        }
    }
    out
}

/// Parses a use tree at `toks[*i]` with the given prefix, appending every full path.
fn use_tree(toks: &[Tok], i: &mut usize, prefix: Vec<String>, out: &mut Vec<Vec<String>>) {
    let mut path = prefix;
    loop {
        match toks.get(*i) {
            Some(Tok::Ident(s)) => {
                path.push(s.clone());
                *i += 1;
                if is_ident(toks.get(*i), "as") {
                    *i += 2;
                }
                if toks.get(*i) == Some(&Tok::Path) {
                    *i += 1;
                    continue;
                }
                out.push(path);
                return;
            }
            Some(Tok::Punct('{')) => {
                *i += 1;
                loop {
                    match toks.get(*i) {
                        Some(Tok::Punct('}')) | None => {
                            *i += 1;
                            return;
                        }
                        Some(Tok::Punct(',')) => *i += 1,
                        _ => use_tree(toks, i, path.clone(), out),
                    }
                }
            }
            Some(Tok::Punct('*')) => {
                *i += 1;
                out.push(path);
                return;
            }
            Some(Tok::Path) => *i += 1, // leading `::`
            _ => {
                out.push(path);
                return;
            }
        }
    }
}

/// Absolute form of `path` written in module `at`, or `None` when it does not start with
/// `crate`, `super` or `self` (external crates, relative child paths).
fn absolute(at: &[String], path: &[String]) -> Option<ModPath> {
    let first = path.first()?;
    let (mut base, rest): (ModPath, &[String]) = match first.as_str() {
        "crate" => (vec!["crate".into()], &path[1..]),
        "self" => (at.to_vec(), &path[1..]),
        "super" => (at.to_vec(), path),
        _ => return None,
    };
    let mut rest = rest;
    while let Some(s) = rest.first() {
        match s.as_str() {
            "super" => {
                base.pop();
                rest = &rest[1..];
            }
            "self" => rest = &rest[1..],
            _ => break,
        }
    }
    base.extend(rest.iter().filter(|s| s.as_str() != "self").cloned());
    Some(base)
}

/// Every absolute path referenced by the file of module `module` with source `src`.
fn references(module: &ModPath, src: &str) -> Vec<ModPath> {
    let toks = drop_test_items(tokenize(&strip_comments_and_strings(src)));
    let mut out = Vec::new();
    // inline modules: (brace depth inside the module, module path)
    let mut scopes: Vec<(usize, ModPath)> = vec![(0, module.clone())];
    let mut depth = 0usize;
    let mut i = 0;
    while i < toks.len() {
        let here = scopes.last().expect("file scope").1.clone();
        match &toks[i] {
            Tok::Punct('{') => {
                depth += 1;
                i += 1;
            }
            Tok::Punct('}') => {
                if scopes.len() > 1 && scopes.last().unwrap().0 == depth {
                    scopes.pop();
                }
                depth = depth.saturating_sub(1);
                i += 1;
            }
            Tok::Ident(k) if k == "mod" => {
                if let (Some(Tok::Ident(name)), Some(Tok::Punct('{'))) =
                    (toks.get(i + 1), toks.get(i + 2))
                {
                    let mut inner = here.clone();
                    inner.push(name.clone());
                    depth += 1;
                    scopes.push((depth, inner));
                    i += 3;
                } else {
                    i += 1;
                }
            }
            Tok::Ident(k) if k == "use" => {
                i += 1;
                let mut paths = Vec::new();
                use_tree(&toks, &mut i, Vec::new(), &mut paths);
                out.extend(paths.iter().filter_map(|p| absolute(&here, p)));
                while i < toks.len() && toks[i] != Tok::Punct(';') {
                    i += 1;
                }
            }
            Tok::Ident(k)
                if matches!(k.as_str(), "crate" | "super" | "self")
                    && toks.get(i + 1) == Some(&Tok::Path) =>
            {
                let mut path = vec![k.clone()];
                i += 1;
                while toks.get(i) == Some(&Tok::Path) {
                    match toks.get(i + 1) {
                        Some(Tok::Ident(s)) => {
                            path.push(s.clone());
                            i += 2;
                        }
                        _ => break,
                    }
                }
                out.extend(absolute(&here, &path));
            }
            _ => i += 1,
        }
    }
    out
}

/// The library's files: module path → file.
fn modules() -> BTreeMap<ModPath, PathBuf> {
    let mut files = Vec::new();
    rust_files(&src_dir(), &mut files);
    files.into_iter().map(|f| (module_of(&f), f)).collect()
}

/// The deepest module of `mods` that `path` lies in.
fn resolve(mods: &BTreeMap<ModPath, PathBuf>, path: &ModPath) -> Option<ModPath> {
    (1..=path.len())
        .rev()
        .map(|n| path[..n].to_vec())
        .find(|p| mods.contains_key(p))
}

/// File-level edges `from → to` (module paths), self-references dropped.
fn graph(mods: &BTreeMap<ModPath, PathBuf>) -> BTreeMap<ModPath, BTreeSet<ModPath>> {
    let mut g = BTreeMap::new();
    for (m, file) in mods {
        let src = std::fs::read_to_string(file).expect("readable source");
        let targets: BTreeSet<ModPath> = references(m, &src)
            .iter()
            .filter_map(|p| resolve(mods, p))
            .filter(|t| t != m)
            .collect();
        g.insert(m.clone(), targets);
    }
    g
}

/// Strongly connected components with more than one node (Tarjan).
fn cycles(g: &BTreeMap<ModPath, BTreeSet<ModPath>>) -> Vec<Vec<ModPath>> {
    struct State<'a> {
        g: &'a BTreeMap<ModPath, BTreeSet<ModPath>>,
        index: BTreeMap<&'a ModPath, usize>,
        low: BTreeMap<&'a ModPath, usize>,
        stack: Vec<&'a ModPath>,
        on_stack: BTreeSet<&'a ModPath>,
        out: Vec<Vec<ModPath>>,
    }
    fn visit<'a>(s: &mut State<'a>, v: &'a ModPath) {
        let n = s.index.len();
        s.index.insert(v, n);
        s.low.insert(v, n);
        s.stack.push(v);
        s.on_stack.insert(v);
        for w in &s.g[v] {
            if !s.index.contains_key(w) {
                visit(s, w);
                let lw = s.low[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(lw);
            } else if s.on_stack.contains(w) {
                let iw = s.index[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(iw);
            }
        }
        if s.low[v] == s.index[v] {
            let mut comp = Vec::new();
            loop {
                let w = s.stack.pop().unwrap();
                s.on_stack.remove(w);
                comp.push(w.clone());
                if w == v {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                s.out.push(comp);
            }
        }
    }
    let mut s = State {
        g,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in g.keys() {
        if !s.index.contains_key(v) {
            visit(&mut s, v);
        }
    }
    s.out
}

fn show(mods: &BTreeMap<ModPath, PathBuf>, m: &ModPath) -> String {
    let file = mods[m].strip_prefix(src_dir()).unwrap_or(&mods[m]);
    format!("src/{} ({})", file.display(), m.join("::"))
}

#[test]
fn no_import_cycle_between_files() {
    let mods = modules();
    assert!(
        mods.len() > 10,
        "found only {} files under src/",
        mods.len()
    );
    let g = graph(&mods);
    let found = cycles(&g);
    let report: Vec<String> = found
        .iter()
        .map(|c| {
            let files: Vec<String> = c.iter().map(|m| show(&mods, m)).collect();
            let edges: Vec<String> = c
                .iter()
                .flat_map(|a| {
                    g[a].iter()
                        .filter(|b| c.contains(b))
                        .map(move |b| format!("{} → {}", a.join("::"), b.join("::")))
                })
                .collect();
            format!(
                "  cycle: {}\n    edges: {}",
                files.join(", "),
                edges.join("; ")
            )
        })
        .collect();
    assert!(
        found.is_empty(),
        "import cycles between files of src/:\n{}",
        report.join("\n")
    );
}

#[test]
fn verifier_imports_no_pipeline() {
    let mods = modules();
    let forbidden = ["lowpoly", "cage", "wrinkle"];
    let mut bad = Vec::new();
    for (m, file) in mods
        .iter()
        .filter(|(m, _)| m.get(1).is_some_and(|s| s == "verify"))
    {
        let src = std::fs::read_to_string(file).expect("readable source");
        for p in references(m, &src) {
            if p.get(1).is_some_and(|s| forbidden.contains(&s.as_str())) {
                bad.push(format!("{} references {}", show(&mods, m), p.join("::")));
            }
        }
    }
    bad.sort();
    bad.dedup();
    assert!(
        bad.is_empty(),
        "src/verify/ must not import the pipelines:\n{}",
        bad.join("\n")
    );
}

/// The reader itself: use trees, `super`, inline modules, comments, strings, test modules.
#[test]
fn references_are_read_like_rustc_resolves_them() {
    let m: ModPath = ["crate", "wrinkle", "knoppel"].map(String::from).to_vec();
    let src = r##"
        use super::{areas::barycentric_areas, topology::{self, Topology}};
        use crate::solve::{assemble as asm, Cholesky};
        // use crate::lowpoly::Fake;
        /* crate::cage::Fake */
        const S: &str = "crate::mesh::Fake";
        const R: &str = r#"crate::spatial::Fake"#;
        fn f<'a>(c: char) -> bool { c == '{' || crate::geom::lerp_ok() }
        mod imp { use super::super::cwf::Cwf; }
        #[cfg(test)]
        mod tests { use crate::ffi::Fake; fn g() { let _ = '}'; } }
        fn h() { self::inner(); super::super::report::Stats::new(); }
        #[cfg(test)]
        use crate::lowpoly::measure;
        #[cfg(test)]
        #[allow(dead_code)]
        fn only_in_tests(x: [u8; 2]) { crate::cage::check(); }
    "##;
    let got: BTreeSet<String> = references(&m, src).iter().map(|p| p.join("::")).collect();
    let want: BTreeSet<String> = [
        "crate::wrinkle::areas::barycentric_areas",
        "crate::wrinkle::topology",
        "crate::wrinkle::topology::Topology",
        "crate::solve::assemble",
        "crate::solve::Cholesky",
        "crate::geom::lerp_ok",
        "crate::wrinkle::cwf::Cwf",
        "crate::wrinkle::knoppel::inner",
        "crate::report::Stats::new",
    ]
    .map(String::from)
    .into();
    assert_eq!(got, want);
}

/// Tarjan finds exactly the cycles of a small graph (a 2-cycle, a 3-cycle, an acyclic tail).
#[test]
fn cycles_are_found() {
    let m = |s: &str| -> ModPath { vec!["crate".into(), s.into()] };
    let mut g: BTreeMap<ModPath, BTreeSet<ModPath>> = BTreeMap::new();
    for (a, b) in [
        ("a", "b"),
        ("b", "a"),
        ("c", "d"),
        ("d", "e"),
        ("e", "c"),
        ("e", "f"),
    ] {
        g.entry(m(a)).or_default().insert(m(b));
        g.entry(m(b)).or_default();
    }
    let mut found = cycles(&g);
    found.sort();
    assert_eq!(
        found,
        vec![vec![m("a"), m("b")], vec![m("c"), m("d"), m("e")]]
    );
}

/// The layer map of the crate (docs/guide/architecture.md): which top-level modules each
/// top-level module may import. Lower layers never import higher ones; `ffi` and the crate root
/// (`lib.rs`, which only declares modules and re-exports) sit on top. A new top-level module
/// must be added here, with the layers it may use.
const LAYERS: &[(&str, &[&str])] = &[
    ("geom", &[]),
    ("error", &[]),
    ("report", &["geom", "error"]),
    ("mesh", &["geom", "error", "report"]),
    ("spatial", &["geom", "error", "report", "mesh"]),
    ("verify", &["geom", "error", "report", "mesh", "spatial"]),
    ("solve", &["error", "report"]),
    (
        "lowpoly",
        &["geom", "error", "report", "mesh", "spatial", "verify"],
    ),
    (
        "cage",
        &[
            "geom", "error", "report", "mesh", "spatial", "verify", "lowpoly",
        ],
    ),
    ("wrinkle", &["geom", "error", "report", "mesh", "solve"]),
    (
        "tfw",
        &["geom", "error", "report", "mesh", "solve", "wrinkle"],
    ),
    (
        "transfer",
        &["geom", "error", "report", "mesh", "spatial", "verify"],
    ),
    (
        "bake",
        &[
            "geom", "error", "report", "mesh", "spatial", "verify", "lowpoly", "cage", "transfer",
        ],
    ),
    ("ffi", &["*"]),
];

#[test]
fn modules_import_only_lower_layers() {
    let mods = modules();
    let allowed: BTreeMap<&str, &[&str]> = LAYERS.iter().copied().collect();
    let mut bad = Vec::new();
    for (m, file) in &mods {
        let Some(top) = m.get(1) else { continue }; // the crate root re-exports everything
        let Some(may) = allowed.get(top.as_str()) else {
            bad.push(format!(
                "{}: top-level module `{top}` is not in LAYERS",
                show(&mods, m)
            ));
            continue;
        };
        if may.contains(&"*") {
            continue;
        }
        let src = std::fs::read_to_string(file).expect("readable source");
        for p in references(m, &src) {
            let Some(t) = resolve(&mods, &p) else {
                continue;
            };
            let Some(to) = t.get(1) else { continue }; // crate-root re-exports (Error, Result)
            if to != top && !may.contains(&to.as_str()) {
                bad.push(format!(
                    "{} imports {} (layer `{to}`)",
                    show(&mods, m),
                    p.join("::")
                ));
            }
        }
    }
    bad.sort();
    bad.dedup();
    assert!(
        bad.is_empty(),
        "imports against the layer map:\n{}",
        bad.join("\n")
    );
}
