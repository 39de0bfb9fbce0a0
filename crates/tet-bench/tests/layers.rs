//! The modules of `tet-bench` lie in layers that point one way: no module
//! uses another that uses it back, directly or through a chain (an import
//! circle). Edges are the module paths the source names (`use crate::…`,
//! `super::…`, `self::…`, `child::…`, and such paths inline), each taken to
//! the longest prefix that is a module of the crate; unit tests are left out.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

type Module = Vec<String>;

/// Every `.rs` file under `src` with its module path.
fn modules(src: &Path) -> BTreeMap<Module, PathBuf> {
    fn walk(dir: &Path, src: &Path, out: &mut BTreeMap<Module, PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, src, out);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let rel = path.strip_prefix(src).unwrap().with_extension("");
                let mut m: Module = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                if m == ["main"] || m == ["lib"] || m.last().is_some_and(|l| l == "mod") {
                    m.pop();
                }
                out.insert(m, path);
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(src, src, &mut out);
    out
}

/// The source without unit tests and line comments.
fn code(text: &str) -> String {
    let text = match text.find("#[cfg(test)]\nmod tests") {
        Some(i) => &text[..i],
        None => text,
    };
    text.lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

fn is_ident(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// Every path `a::b::c` in `text`, use-groups `a::{b, c::{d}}` expanded.
fn paths(text: &str) -> Vec<Vec<String>> {
    let chars: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let starts = is_ident(chars[i])
            && !chars[i].is_ascii_digit()
            && (i == 0 || !(is_ident(chars[i - 1]) || chars[i - 1] == ':'));
        if starts {
            i = path_at(&chars, i, Vec::new(), &mut out);
        } else {
            i += 1;
        }
    }
    out
}

/// Reads the path starting at `i` (after `prefix`), pushes its expansions
/// to `out`, and returns where it ends.
fn path_at(chars: &[char], mut i: usize, prefix: Vec<String>, out: &mut Vec<Vec<String>>) -> usize {
    let mut segs = prefix;
    loop {
        let start = i;
        while i < chars.len() && is_ident(chars[i]) {
            i += 1;
        }
        if i == start {
            break;
        }
        segs.push(chars[start..i].iter().collect());
        if chars.get(i) == Some(&':') && chars.get(i + 1) == Some(&':') {
            i += 2;
            if chars.get(i) == Some(&'{') {
                // A group: each item is a path below `segs`.
                i += 1;
                loop {
                    while i < chars.len() && (chars[i].is_whitespace() || chars[i] == ',') {
                        i += 1;
                    }
                    if i >= chars.len() || chars[i] == '}' {
                        return i + 1;
                    }
                    if is_ident(chars[i]) {
                        i = path_at(chars, i, segs.clone(), out);
                        // Skip `as alias`.
                        while i < chars.len() && chars[i] != ',' && chars[i] != '}' {
                            i += 1;
                        }
                    } else {
                        i += 1;
                    }
                }
            }
            continue;
        }
        break;
    }
    if segs.len() > 1 {
        out.push(segs);
    }
    i
}

/// The module of the crate that `path`, written in module `cur`, names.
fn resolve(cur: &Module, path: &[String], mods: &BTreeMap<Module, PathBuf>) -> Option<Module> {
    let (mut base, rest): (Module, &[String]) = match path[0].as_str() {
        "crate" => (Vec::new(), &path[1..]),
        "super" | "self" => (cur.clone(), path),
        _ => {
            // A child module named without `self::` (`use doc::X`).
            let mut child = cur.clone();
            child.push(path[0].clone());
            if !mods.contains_key(&child) {
                return None;
            }
            (cur.clone(), path)
        }
    };
    let mut k = 0;
    while k < rest.len() && (rest[k] == "super" || rest[k] == "self") {
        if rest[k] == "super" {
            base.pop();
        }
        k += 1;
    }
    base.extend(rest[k..].iter().cloned());
    (0..=base.len())
        .rev()
        .map(|n| base[..n].to_vec())
        .find(|m| mods.contains_key(m))
}

/// The module graph of the crate in `src`.
fn graph(src: &Path) -> BTreeMap<Module, BTreeSet<Module>> {
    let mods = modules(src);
    let mut edges = BTreeMap::new();
    for (m, file) in &mods {
        let text = code(&std::fs::read_to_string(file).unwrap());
        let targets: BTreeSet<Module> = paths(&text)
            .iter()
            .filter_map(|p| resolve(m, p, &mods))
            .filter(|t| t != m)
            .collect();
        edges.insert(m.clone(), targets);
    }
    edges
}

/// Every circle, as the set of modules on it (strongly connected
/// components of more than one module).
fn circles(edges: &BTreeMap<Module, BTreeSet<Module>>) -> Vec<BTreeSet<Module>> {
    let reach = |from: &Module| {
        let mut seen = BTreeSet::new();
        let mut stack = vec![from.clone()];
        while let Some(m) = stack.pop() {
            for t in edges.get(&m).into_iter().flatten() {
                if seen.insert(t.clone()) {
                    stack.push(t.clone());
                }
            }
        }
        seen
    };
    let reaches: BTreeMap<&Module, BTreeSet<Module>> =
        edges.keys().map(|m| (m, reach(m))).collect();
    let mut out: Vec<BTreeSet<Module>> = Vec::new();
    for m in edges.keys() {
        let component: BTreeSet<Module> = edges
            .keys()
            .filter(|o| *o == m || (reaches[m].contains(*o) && reaches[*o].contains(m)))
            .cloned()
            .collect();
        if component.len() > 1 && !out.contains(&component) {
            out.push(component);
        }
    }
    out
}

fn name(m: &Module) -> String {
    if m.is_empty() {
        "crate".into()
    } else {
        m.join("::")
    }
}

#[test]
fn modules_have_no_import_circles() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let edges = graph(&src);
    // The scan sees the layers: a command uses a measurement module, which
    // uses plumbing, and a table module uses the tables' data.
    let has = |a: &str, b: &str| {
        let m = |s: &str| -> Module { s.split("::").map(String::from).collect() };
        edges[&m(a)].contains(&m(b))
    };
    assert!(has("commands::render", "timing"));
    assert!(has("timing", "load"));
    assert!(has("tables::zoom", "tables::doc"));
    assert!(has("tables", "tables::plan"));
    let found: Vec<String> = circles(&edges)
        .iter()
        .map(|c| c.iter().map(name).collect::<Vec<_>>().join(" <-> "))
        .collect();
    assert!(found.is_empty(), "import circles: {found:#?}");
}

#[test]
fn the_scan_finds_circles_through_chains_groups_and_super() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path();
    std::fs::create_dir(src.join("b")).unwrap();
    let files = [
        (
            "main.rs",
            "mod a;\nmod b;\nmod c;\nfn main() { a::run(); }\n",
        ),
        ("a.rs", "use crate::{b::x::Thing, c};\n"),
        ("b.rs", "pub mod x;\n"),
        // b::x reaches a through its parent's sibling.
        (
            "b/x.rs",
            "pub struct Thing;\nfn f() { super::super::a::g(); }\n",
        ),
        ("c.rs", "// use crate::a; (a comment is no edge)\n"),
    ];
    for (path, text) in files {
        std::fs::write(src.join(path), text).unwrap();
    }
    let edges = graph(src);
    let found = circles(&edges);
    let names: Vec<Vec<String>> = found.iter().map(|c| c.iter().map(name).collect()).collect();
    assert_eq!(names, [vec!["a".to_string(), "b::x".to_string()]]);
    assert!(edges[&vec!["c".to_string()]].is_empty());
}
