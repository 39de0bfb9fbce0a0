//! The command line as users script it: `--json` documents, mesh files, and
//! errors. Scenes are small procedural ones, built through the TetGen worker.

use std::process::{Command, Output};

use serde_json::Value;

fn bench(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tet-bench"))
        .args(args)
        .output()
        .expect("tet-bench runs")
}

/// Runs with `--json` and parses stdout as exactly one JSON document.
fn json(args: &[&str]) -> Value {
    let mut all = args.to_vec();
    all.push("--json");
    let out = bench(&all);
    assert!(
        out.status.success(),
        "tet-bench {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "stdout of {args:?} is not one JSON document ({e}): {}",
            String::from_utf8_lossy(&out.stdout)
        )
    })
}

#[test]
fn build_then_info_reports_exact_layout_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("knot.tmesh");
    let file = file.to_str().unwrap();
    let built = json(&["build", "torus-knot", "-o", file]);
    assert_eq!(built["build"]["scene_triangles"], 2880);
    let tets = built["tets"].as_u64().unwrap() as usize;
    let points = built["points"].as_u64().unwrap() as usize;
    assert_eq!(built["constrained_faces"], 2880);

    let info = json(&["info", file]);
    assert_eq!(info["tets"].as_u64().unwrap() as usize, tets);
    assert_eq!(info["triangles"], 2880);
    assert!(
        info["build"].is_null(),
        "a mesh file carries no build report"
    );
    let layouts = info["layouts"].as_array().unwrap();
    let names: Vec<&str> = layouts
        .iter()
        .map(|l| l["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["baseline32", "tet32", "tet20", "tet16", "tet80"]);
    // Hot bytes are tet records plus points (none for Tet80, whose records
    // hold the positions), record sizes as the papers give them.
    for (l, record, pts) in [
        (0, 32, 12),
        (1, 32, 12),
        (2, 20, 12),
        (3, 16, 12),
        (4, 80, 0),
    ] {
        assert_eq!(
            layouts[l]["hot_bytes"].as_u64().unwrap() as usize,
            tets * record + points * pts,
            "{}",
            names[l]
        );
    }
    // The torus knot is closed: two regions (inside and outside the tube).
    assert_eq!(info["regions"]["count"], 2);
}

#[test]
fn render_and_accuracy_agree_with_the_reference() {
    let r = json(&[
        "render",
        "torus-knot",
        "--method",
        "tet20",
        "--width",
        "64",
        "--height",
        "48",
        "--frames",
        "1",
    ]);
    assert_eq!(r["rays"], 64 * 48);
    assert_eq!(r["failures"], 0);
    let hits = r["hits"].as_u64().unwrap();
    assert!(
        hits > 0 && hits < 64 * 48,
        "the knot covers part of the image"
    );
    let b = json(&[
        "render",
        "torus-knot",
        "--method",
        "obvhs",
        "--width",
        "64",
        "--height",
        "48",
        "--frames",
        "1",
    ]);
    assert_eq!(
        b["hits"], r["hits"],
        "same camera rays hit in the BVH and the walk"
    );

    let a = json(&[
        "accuracy",
        "torus-knot",
        "--methods",
        "tet20,tet16,tet32,obvhs",
        "--rays",
        "2000",
        "--image",
        "32",
    ]);
    for m in a["cases"][0]["methods"].as_array().unwrap() {
        assert_eq!(m["failures"], 0, "{m}");
        assert_eq!(m["rays"], 2000 + 32 * 32);
    }
}

#[test]
fn errors_are_reported_on_stderr_with_a_failure_code() {
    let out = bench(&["info", "no-such-scene"]);
    assert!(!out.status.success());
    assert!(out.stdout.is_empty());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("torus-knots"),
        "the error lists the procedural scenes: {err}"
    );

    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.tmesh");
    std::fs::write(&bad, b"not a mesh").unwrap();
    let out = bench(&["info", bad.to_str().unwrap(), "--json"]);
    assert!(!out.status.success());
    assert!(out.stdout.is_empty(), "no JSON document on failure");
    assert!(String::from_utf8_lossy(&out.stderr).contains("bad.tmesh"));
}
