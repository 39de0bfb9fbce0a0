//! A house rule of the workspace: every ignored test says why
//! (`#[ignore = "reason"]`: slow, a measurement, needs root or files the
//! repository leaves out), so that `cargo test` lists the reason beside each
//! test it skips and nobody has to read the test to know how to run it.

use std::path::{Path, PathBuf};

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        let name = e.file_name();
        if p.is_dir() {
            if name != "target" && !name.to_string_lossy().starts_with('.') {
                rust_files(&p, out);
            }
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// `file:line` of every `#[ignore]` without a reason (also inside
/// `cfg_attr`) in the Rust files under `dirs`.
fn bare_ignores(dirs: &[PathBuf]) -> Vec<String> {
    let mut files = Vec::new();
    for d in dirs {
        rust_files(d, &mut files);
    }
    files.sort();
    let mut bare = Vec::new();
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        for (i, line) in text.lines().enumerate() {
            let l: String = line.split_whitespace().collect();
            if l.starts_with("#[ignore]")
                || (l.starts_with("#[cfg_attr(") && l.ends_with(",ignore)]"))
            {
                bare.push(format!("{}:{}", f.display(), i + 1));
            }
        }
    }
    bare
}

#[test]
fn every_ignored_test_says_why() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let bare = bare_ignores(&[root.join("crates"), root.join("fuzz")]);
    assert!(
        bare.is_empty(),
        "ignored tests without a reason (write #[ignore = \"why, and how to run it\"]):\n{}",
        bare.join("\n")
    );
}

#[test]
fn the_scan_finds_a_bare_ignore() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("t.rs");
    let body = "#[test]\n#[ignore = \"slow\"]\nfn a() {}\n#[test]\n  #[ignore]\nfn b() {}\n\
                #[cfg_attr(miri, ignore)]\nfn c() {}\n";
    std::fs::write(&src, body).unwrap();
    let found = bare_ignores(&[dir.path().to_path_buf()]);
    let lines: Vec<&str> = found
        .iter()
        .map(|s| s.rsplit(':').next().unwrap())
        .collect();
    assert_eq!(lines, ["5", "7"]);
}
