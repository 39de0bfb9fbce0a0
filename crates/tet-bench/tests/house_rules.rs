//! The workspace's structural rules, checked on its own sources so that
//! they hold after every change:
//!
//! * no import circle between the modules of a crate (module `a` names
//!   `crate::b…` or `super::…b` and `b`, directly or through others, names
//!   `a`): modules sit in layers that point one way;
//! * no source file longer than [`MAX_LINES`] lines (its unit tests aside)
//!   unless its first lines say why (a line starting `//! Long file:`);
//! * no project issue numbers in user-facing text (README, module docs,
//!   comments, CLI help): users do not know what they are, so the text names
//!   the paper and section instead;
//! * a README of at most [`MAX_README_LINES`] lines: the rest lives in
//!   `docs/`;
//! * no paper named by an internal number (the word "seed" and 000 … 004)
//!   in the README, `docs/` or the crates' sources (doc comments, comments,
//!   string literals: table headings, figure titles, CLI help): papers are
//!   named by their authors and year;
//! * one module-file convention: a module with submodules in `name/mod.rs`.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// Longest source file, in lines before its `#[cfg(test)] mod tests`.
const MAX_LINES: usize = 800;

/// Longest README, in lines: what the project is, the two commands, the
/// crates, one results table and where everything else is.
const MAX_README_LINES: usize = 250;

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// Every file under `dir` whose name ends with one of `exts`.
fn files_ending(dir: &Path, exts: &[&str], out: &mut Vec<PathBuf>) {
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            files_ending(&p, exts, out);
        } else if exts
            .iter()
            .any(|x| p.to_string_lossy().ends_with(&format!(".{x}")))
        {
            out.push(p);
        }
    }
}

fn crate_src_dirs() -> Vec<PathBuf> {
    let mut dirs: Vec<PathBuf> = fs::read_dir(workspace().join("crates"))
        .expect("crates/")
        .flatten()
        .map(|e| e.path().join("src"))
        .filter(|p| p.is_dir())
        .collect();
    dirs.sort();
    assert!(
        dirs.len() >= 5,
        "expected the workspace's crates, found {dirs:?}"
    );
    dirs
}

type Module = Vec<String>;

/// Every `.rs` file under `src` with its module path.
fn modules(src: &Path) -> BTreeMap<Module, PathBuf> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    files
        .into_iter()
        .map(|path| {
            let rel = path.strip_prefix(src).unwrap().with_extension("");
            let mut m: Module = rel
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect();
            if m == ["main"] || m == ["lib"] || m.last().is_some_and(|l| l == "mod") {
                m.pop();
            }
            (m, path)
        })
        .collect()
}

/// The source before its unit-test module (`#[cfg(test)] mod tests`).
fn without_unit_tests(text: &str) -> &str {
    let end = text.find("#[cfg(test)]\nmod tests").unwrap_or(text.len());
    &text[..end]
}

/// The source without unit tests and line comments.
fn code(text: &str) -> String {
    without_unit_tests(text)
        .lines()
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

/// The module graph of the crate in `src`. With `parents: false`, a
/// module's use of its ancestors (the items a parent `mod.rs` or the crate
/// root defines or re-exports for its children) is not an edge: only
/// imports between siblings and cousins are.
fn graph(src: &Path, parents: bool) -> BTreeMap<Module, BTreeSet<Module>> {
    let mods = modules(src);
    let mut edges = BTreeMap::new();
    for (m, file) in &mods {
        let text = code(&std::fs::read_to_string(file).unwrap());
        let targets: BTreeSet<Module> = paths(&text)
            .iter()
            .filter_map(|p| resolve(m, p, &mods))
            .filter(|t| t != m)
            .filter(|t| parents || !m.starts_with(t))
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

/// tet-bench, strictly: not even a module and its parent use each other.
#[test]
fn tet_bench_modules_lie_in_layers() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let edges = graph(&src, true);
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
    let edges = graph(src, true);
    let found = circles(&edges);
    let names: Vec<Vec<String>> = found.iter().map(|c| c.iter().map(name).collect()).collect();
    assert_eq!(names, [vec!["a".to_string(), "b::x".to_string()]]);
    assert!(edges[&vec!["c".to_string()]].is_empty());
}

#[test]
fn no_import_circle_in_any_crate() {
    let mut found = Vec::new();
    for src in crate_src_dirs() {
        for c in circles(&graph(&src, false)) {
            let names: Vec<String> = c.iter().map(name).collect();
            found.push(format!("{}: {}", src.display(), names.join(" <-> ")));
        }
    }
    assert!(found.is_empty(), "import circles:\n{}", found.join("\n"));
}

#[test]
fn no_source_file_longer_than_the_limit_without_a_reason() {
    let mut long = Vec::new();
    for src in crate_src_dirs() {
        let mut files = Vec::new();
        rust_files(&src, &mut files);
        for file in files {
            let text = fs::read_to_string(&file).expect("readable source");
            let lines = without_unit_tests(&text).lines().count();
            let explained = text
                .lines()
                .take(40)
                .any(|l| l.starts_with("//! Long file:"));
            if lines > MAX_LINES && !explained {
                long.push(format!("{} ({lines} lines)", file.display()));
            }
        }
    }
    assert!(
        long.is_empty(),
        "files over {MAX_LINES} lines:\n{}",
        long.join("\n")
    );
}

/// `issue 8`, `Issue 12`, `issue #4`: a project issue number.
fn issue_number_at(line: &str) -> Option<usize> {
    let lower = line.to_ascii_lowercase();
    let mut from = 0;
    while let Some(i) = lower[from..].find("issue") {
        let at = from + i;
        from = at + 5;
        if lower[..at].ends_with(|c: char| c.is_ascii_alphanumeric()) {
            continue;
        }
        let rest = lower[from..].trim_start_matches([' ', '#']);
        let skipped = lower.len() - from - rest.len();
        if skipped > 0 && rest.starts_with(|c: char| c.is_ascii_digit()) {
            return Some(at);
        }
    }
    None
}

#[test]
fn no_issue_numbers_in_user_facing_text() {
    let root = workspace();
    let mut files = vec![root.join("README.md"), root.join("fuzz/README.md")];
    for src in crate_src_dirs() {
        rust_files(&src, &mut files);
    }
    rust_files(&root.join("fuzz/targets_common"), &mut files);
    let mut hits = Vec::new();
    for file in files {
        let text = fs::read_to_string(&file).expect("readable text");
        for (n, line) in text.lines().enumerate() {
            if issue_number_at(line).is_some() {
                hits.push(format!("{}:{}: {}", file.display(), n + 1, line.trim()));
            }
        }
    }
    assert!(
        hits.is_empty(),
        "issue numbers in user text:\n{}",
        hits.join("\n")
    );
    assert!(issue_number_at("the memory model of issue 8").is_some());
    assert!(issue_number_at("see Issue #12.").is_some());
    assert!(issue_number_at("no issues here; tissue 3").is_none());
}

#[test]
fn readme_is_short() {
    let text = fs::read_to_string(workspace().join("README.md")).expect("README.md");
    let lines = text.lines().count();
    assert!(
        lines <= MAX_README_LINES,
        "README.md has {lines} lines, more than {MAX_README_LINES}: move the detail to docs/"
    );
}

/// The lines of `text` without their indentation and comment markers
/// (`//!`, `///`, `//`, a block comment's `*`), joined by single spaces and
/// lower-cased, so that a phrase wrapped across comment lines reads as one.
fn flowing(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        let t = line.trim_start();
        let t = ["//!", "///", "//", "*"]
            .iter()
            .find_map(|m| t.strip_prefix(m))
            .unwrap_or(t);
        for word in t.split_whitespace() {
            out.push_str(&word.to_lowercase());
            out.push(' ');
        }
    }
    out
}

/// Where `text` (as [`flowing`] gives it) names a paper by its internal
/// number: "seed" or "seeds", a space or hyphen, then "00".
fn seed_number_at(flowing: &str) -> Option<usize> {
    let mut from = 0;
    while let Some(i) = flowing[from..].find("seed") {
        let at = from + i;
        from = at + 4;
        if flowing[..at].ends_with(|c: char| c.is_ascii_alphanumeric()) {
            continue;
        }
        let rest = flowing[from..]
            .strip_prefix('s')
            .unwrap_or(&flowing[from..]);
        if let Some(rest) = rest.strip_prefix([' ', '-'])
            && rest.starts_with("00")
        {
            return Some(at);
        }
    }
    None
}

#[test]
fn papers_are_named_by_authors_not_numbers() {
    let root = workspace();
    let mut files = vec![root.join("README.md"), root.join("fuzz/README.md")];
    files_ending(&root.join("docs"), &["md"], &mut files);
    for src in crate_src_dirs() {
        files_ending(&src, &["rs", "wgsl"], &mut files);
    }
    let mut hits = Vec::new();
    for file in files {
        let rel = file.strip_prefix(&root).unwrap_or(&file);
        let rel = rel.to_string_lossy().replace('\\', "/");
        let text = fs::read_to_string(&file).expect("readable text");
        let text = flowing(&text);
        if let Some(at) = seed_number_at(&text) {
            let end = (at + 60).min(text.len());
            let end = (end..=text.len())
                .find(|&e| text.is_char_boundary(e))
                .unwrap_or(text.len());
            hits.push(format!("{rel}: …{}…", &text[at..end]));
        }
    }
    assert!(
        hits.is_empty(),
        "papers named by number (write e.g. \"Aman et al. (2022)\"):\n{}",
        hits.join("\n")
    );
    assert!(seed_number_at(&flowing("(Aman et al., seed\n//! 000 §5)")).is_some());
    assert!(seed_number_at(&flowing("Seeds 001 and 002")).is_some());
    assert!(seed_number_at(&flowing("/// Seed 004 Table 3")).is_some());
    assert!(seed_number_at(&flowing("--seed 7; XXH64, seed 0; fuzz/seeds/")).is_none());
}

/// The lockstep walk takes one request ([`tet_trace_cpu::lockstep::Batch`])
/// through one entry: no function of `tet-trace-cpu/src/lockstep` spells
/// out argument lists long enough to need `too_many_arguments`, and
/// `TET_LOCKSTEP` is read in one place (`Width::Auto`) of the whole
/// workspace.
#[test]
fn lockstep_takes_one_request_and_reads_its_width_once() {
    let root = workspace();
    let mut files = Vec::new();
    rust_files(&root.join("crates/tet-trace-cpu/src/lockstep"), &mut files);
    assert!(files.len() > 5, "lockstep sources: {files:?}");
    let allows: Vec<String> = files
        .iter()
        .filter(|f| {
            code(&fs::read_to_string(f).expect("readable source")).contains("too_many_arguments")
        })
        .map(|f| f.display().to_string())
        .collect();
    assert!(
        allows.is_empty(),
        "too_many_arguments in the lockstep module (pass a Batch):\n{}",
        allows.join("\n")
    );
    let mut readers = Vec::new();
    for src in crate_src_dirs() {
        let mut files = Vec::new();
        rust_files(&src, &mut files);
        for f in files {
            let text = code(&fs::read_to_string(&f).expect("readable source"));
            let n = text.matches("\"TET_LOCKSTEP\"").count();
            readers.extend(std::iter::repeat_n(f.display().to_string(), n));
        }
    }
    assert_eq!(readers.len(), 1, "readers of TET_LOCKSTEP: {readers:?}");
}

/// Every directory below `dir`, depth first.
fn dirs_below(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            out.push(p.clone());
            dirs_below(&p, out);
        }
    }
}

/// One module-file convention: a module with submodules lives in
/// `name/mod.rs`, never in `name.rs` beside a `name/` folder, so a reader
/// finds a module's root in one place.
#[test]
fn modules_with_submodules_live_in_mod_rs() {
    let root = workspace();
    let mut both = Vec::new();
    for src in crate_src_dirs() {
        let mut dirs = Vec::new();
        dirs_below(&src, &mut dirs);
        for d in dirs {
            if d.with_extension("rs").is_file() {
                let rel = d.strip_prefix(&root).unwrap_or(&d);
                both.push(format!("{0}.rs beside {0}/", rel.display()));
            }
        }
    }
    assert!(
        both.is_empty(),
        "move each module's root into its folder's mod.rs:\n{}",
        both.join("\n")
    );
}
