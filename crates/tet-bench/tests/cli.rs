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
    assert_eq!(
        names,
        [
            "baseline32",
            "tet32",
            "tet20",
            "tet16",
            "tet80",
            "ray-strips"
        ]
    );
    // Ray-Strips over the 2880 triangles: its parts add up, and its
    // geometry holds at least a 4-byte word per triangle and a 12-byte
    // position per vertex of the tube (1440).
    let strips = &layouts[5];
    let part = |k: &str| strips[k].as_u64().unwrap() as usize;
    assert_eq!(
        part("geometry_bytes") + part("hierarchy_bytes") + part("top_level_bytes"),
        part("total_bytes")
    );
    assert!(part("geometry_bytes") >= 2880 * 4 + 1440 * 12);
    let per_triangle = strips["total_bytes_per_triangle"].as_f64().unwrap();
    assert!((per_triangle - part("total_bytes") as f64 / 2880.0).abs() < 1e-9);
    assert!(
        layouts[..5]
            .iter()
            .all(|l| l.get("geometry_bytes").is_none())
    );
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

    // The tight box leaves the camera and the light outside the mesh: rays
    // from there enter through the boundary, so the region around the tube
    // is kept and the tube's inside, which no ray reaches, is removed.
    let pruned = json(&["info", file, "--prune"]);
    let p = &pruned["pruned"];
    assert_eq!(p["regions_kept"], 1, "{p}");
    assert_eq!(p["regions_removed"], 1, "{p}");
    let removed = p["tets_removed"].as_u64().unwrap() as usize;
    assert!(removed > 0 && removed < tets / 2, "{removed} of {tets}");
    assert_eq!(
        p["constrained_removed"], 0,
        "the tube's faces keep their outer side"
    );
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
    // BVH nodes per ray: at least the root, for BVH methods only.
    assert!(r["nodes_per_ray"].is_null());
    let nodes = b["nodes_per_ray"].as_f64().unwrap();
    assert!(nodes >= 1.0, "{nodes}");

    let a = json(&[
        "accuracy",
        "--min-time",
        "0",
        "torus-knot",
        "--methods",
        "tet20,tet16,tet32,obvhs",
        "--rays",
        "2000",
        "--image",
        "32",
    ]);
    for m in a["cases"][0]["methods"].as_array().unwrap() {
        // Failures other than leaks: none for any method. Leaks (rays that
        // slip between two triangles of the closed knot) are failures too;
        // the walks have none, while obvhs's Möller–Trumbore test is not
        // watertight and may leak at shared edges.
        let failures = m["failures"].as_u64().unwrap();
        let leaks = m["leaks"].as_u64().unwrap();
        assert_eq!(failures - leaks, 0, "{m}");
        if m["method"].as_str().unwrap().starts_with("tet") {
            assert_eq!(m["failures"], 0, "{m}");
        }
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

/// Hands `tet-bench` a memory size that is not one.
fn stderr_of(args: &[&str]) -> String {
    let out = bench(args);
    assert!(!out.status.success(), "{args:?} should fail");
    assert!(out.stdout.is_empty(), "no document on failure");
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn predict_memory_counts_the_tetgen_input() {
    // The torus knot: 120 × 12 = 1440 vertices, 2880 triangles; the box
    // adds 8 corners and 12 triangles.
    let p = json(&["build", "torus-knot", "--predict-memory"]);
    assert_eq!(p["points"], 1448);
    assert_eq!(p["triangles"], 2892);
    let no_box = json(&["build", "torus-knot", "--predict-memory", "--no-box"]);
    assert_eq!(no_box["points"], 1440);
    assert_eq!(no_box["triangles"], 2880);
    let one = p["predicted_peak_bytes"].as_u64().unwrap();
    assert!(
        no_box["predicted_peak_bytes"].as_u64().unwrap() < one,
        "fewer inputs, less memory"
    );
    // 27 knots need more than one (and less than 27 × as much: the fixed part).
    let many = json(&["build", "torus-knots", "--predict-memory"])["predicted_peak_bytes"]
        .as_u64()
        .unwrap();
    assert!(many > 10 * one && many < 27 * one, "{one} vs {many}");
    // Text mode prints the prediction; no output file is needed.
    let out = bench(&["build", "torus-knot", "--predict-memory"]);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("predicted peak memory"));
}

#[test]
fn memory_limit_builds_in_parts_that_trace_like_the_in_core_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let whole = dir.path().join("whole.tmesh");
    let parts = dir.path().join("parts.tmesh");
    let (whole, parts) = (whole.to_str().unwrap(), parts.to_str().unwrap());
    let p = json(&["build", "torus-knot", "--predict-memory"]);
    let predicted = p["predicted_peak_bytes"].as_u64().unwrap();
    let builder = p["builder_bytes"].as_u64().unwrap();

    // Room for the builder and the whole prediction: in core, one part.
    let big = format!("{}K", (builder + predicted + predicted / 4) / 1024 + 1);
    let w = json(&["build", "torus-knot", "-o", whole, "--memory-limit", &big]);
    assert_eq!(w["memory"]["out_of_core"], false);
    assert_eq!(w["memory"]["parts"], 1);
    assert_eq!(w["build"]["scene_triangles"], 2880);

    // Less: parts, each predicted under what the limit leaves a worker.
    let limit = limit_for_workers(builder, predicted * 3 / 4);
    let limit_arg = limit.to_string();
    let b = json(&[
        "build",
        "torus-knot",
        "-o",
        parts,
        "--memory-limit",
        &limit_arg,
        "--threads",
        "2",
    ]);
    let m = &b["memory"];
    assert_eq!(m["out_of_core"], true);
    assert_eq!(m["limit_bytes"].as_u64().unwrap(), limit);
    let n = m["parts"].as_u64().unwrap() as usize;
    assert!(n >= 2, "{m}");
    assert_eq!(m["planes"].as_array().unwrap().len(), n - 1);
    // The parts running at once fit the limit together with the builder
    // and its quarter of each part's prediction.
    let at_once = m["parallel_parts"].as_u64().unwrap();
    assert!((1..=2).contains(&at_once), "{m}");
    let largest = m["part_predicted_bytes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p.as_u64().unwrap())
        .max()
        .unwrap();
    assert_eq!(m["own_bytes"].as_u64().unwrap(), builder);
    assert!(builder + at_once * (largest + largest / 4) <= limit, "{m}");
    assert!(m["tree_peak_kib"].as_u64().unwrap() * 1024 <= limit, "{m}");
    // No retry on this scene: nothing moved, nothing reused.
    assert_eq!(m["plane_moves"].as_u64(), Some(0), "{m}");
    assert_eq!(m["parts_reused"].as_u64(), Some(0), "{m}");
    assert_eq!(
        m["surface_relaxed"].as_array().map(Vec::len),
        Some(0),
        "{m}"
    );
    let part_tets: u64 = m["part_tets"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t.as_u64().unwrap())
        .sum();
    assert_eq!(
        b["tets"].as_u64().unwrap(),
        part_tets,
        "merging keeps every tet"
    );
    assert!(
        b["constrained_faces"].as_u64().unwrap() > 2880,
        "cut triangles are kept as pieces"
    );

    // Both meshes fill the same box around the same knot: the same camera
    // rays (framing the mesh) hit the knot in both, without failures.
    let render = |file: &str| {
        json(&[
            "render", file, "--method", "tet20", "--width", "48", "--height", "36", "--frames", "1",
        ])
    };
    let (a, c) = (render(whole), render(parts));
    assert_eq!(a["failures"], 0);
    assert_eq!(c["failures"], 0);
    let (ha, hc) = (a["hits"].as_i64().unwrap(), c["hits"].as_i64().unwrap());
    assert!(ha > 0);
    assert!((ha - hc).abs() <= 2, "in core {ha} hits, out of core {hc}");
}

/// The `--memory-limit` under which a local build of a scene whose
/// builder sets `builder` bytes aside gives one worker at a time exactly
/// `per_worker` bytes of predicted TetGen peak (with the builder's quarter
/// of it): `per_worker` rounded down to a multiple of 4.
fn limit_for_workers(builder: u64, per_worker: u64) -> u64 {
    let w = per_worker & !3;
    builder + w + w / 4
}

/// Under a limit the parts are streamed through part files by default;
/// `--merge memory` gives the same mesh (counts) merged in memory;
/// `--planner` forces the tree or slabs; `--tet20` traces the file written.
#[test]
fn memory_limit_streams_by_default_and_the_planner_can_be_chosen() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let p = json(&["build", "torus-knot", "--predict-memory"]);
    let (predicted, builder) = (
        p["predicted_peak_bytes"].as_u64().unwrap(),
        p["builder_bytes"].as_u64().unwrap(),
    );
    let limit = limit_for_workers(builder, predicted * 3 / 4).to_string();
    let build = |out: &str, extra: &[&str]| {
        let mut args = vec!["build", "torus-knot", "-o", out, "--memory-limit", &limit];
        args.extend_from_slice(extra);
        json(&args)
    };
    let (streamed, in_memory) = (path("s.tmesh"), path("m.tmesh"));
    let s = build(&streamed, &["--tet20"]);
    let m = build(&in_memory, &["--merge", "memory"]);
    let (sm, mm) = (&s["memory"], &m["memory"]);
    assert_eq!(sm["merge"], "stream");
    assert_eq!(mm["merge"], "memory");
    assert_eq!(sm["planner"], "tree");
    assert!(sm["parts"].as_u64().unwrap() >= 2, "{sm}");
    for k in ["points", "tets", "constrained_faces"] {
        assert_eq!(s[k], m[k], "{k}: streamed and in-memory merges agree");
    }
    assert_eq!(
        s["file_bytes"].as_u64().unwrap(),
        std::fs::metadata(&streamed).unwrap().len()
    );
    let held = sm["merge_max_resident_bytes"].as_u64().unwrap();
    let all = sm["merge_all_parts_bytes"].as_u64().unwrap();
    assert!(held > 0 && held < all, "{sm}");
    assert!(sm["part_file_bytes"].as_u64().unwrap() > 0);
    assert!(mm["merge_max_resident_bytes"].is_null());
    assert!(sm["process_peak_kib"].as_u64().is_some_and(|k| k > 0));
    // The streamed file traces: the camera stored with it, no failures.
    let t = &s["tet20"];
    assert!(t["mrays_per_s"].as_f64().unwrap() > 0.0, "{t}");
    assert_eq!(t["failures"], 0);
    assert!(m["tet20"].is_null());

    let slabs = build(&path("slabs.tmesh"), &["--planner", "slabs"]);
    assert_eq!(slabs["memory"]["planner"], "slabs");
    assert_eq!(slabs["memory"]["merge"], "stream");
    // Merge and planner only mean something under a limit.
    let err = stderr_of(&[
        "build",
        "torus-knot",
        "-o",
        &path("x.tmesh"),
        "--merge",
        "memory",
    ]);
    assert!(err.contains("--memory-limit"), "{err}");
}

#[test]
fn bad_memory_limits_are_explained() {
    let err = stderr_of(&[
        "build",
        "torus-knot",
        "-o",
        "x.tmesh",
        "--memory-limit",
        "12Q",
    ]);
    assert!(
        err.contains("--memory-limit") && err.contains("12Q"),
        "{err}"
    );
    assert!(err.contains("512M"), "the error shows an example: {err}");
    let err = stderr_of(&[
        "build",
        "torus-knot",
        "-o",
        "x.tmesh",
        "--memory-limit",
        "lots",
    ]);
    assert!(err.contains("lots"), "{err}");
    // A limit below the model's fixed part cannot be met by any split.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.tmesh");
    let err = stderr_of(&[
        "build",
        "torus-knot",
        "-o",
        out.to_str().unwrap(),
        "--memory-limit",
        "1M",
    ]);
    assert!(err.contains("raise --memory-limit"), "{err}");
    assert!(err.contains("aside for itself"), "{err}");
    assert!(!out.exists(), "no mesh file is written");
    // Without -o (and without --predict-memory) clap asks for it.
    let err = stderr_of(&["build", "torus-knot"]);
    assert!(err.contains("--output"), "{err}");
}

/// An octahedron OBJ and a scenes.json with two cameras on it (a zoom
/// series sharing one mesh) and a moved copy.
fn tiny_scenes(dir: &std::path::Path) -> std::path::PathBuf {
    std::fs::write(
        dir.join("octa.obj"),
        "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n\
         f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n",
    )
    .unwrap();
    let scene = |name: &str, distance: f64, dx: f64| {
        format!(
            r#"{{"name": "{name}", "camera": {{"orbit_x_rad": 0.3, "orbit_y_rad": 1.0, "distance": {distance}, "target": [0, 0, 0]}},
              "lights": [{{"position": [3, 4, 5], "color": [1, 1, 1], "intensity": 1.0}}],
              "objects": [{{"name": "o", "file": "octa.obj", "translation": [{dx}, 0, 0], "rotation_deg": [0, 0, 0], "scale": [1, 1, 1]}}]}}"#
        )
    };
    let json = format!(
        r#"{{"scenes": [{}, {}, {}]}}"#,
        scene("Octa Zoom 0", 3.0, 0.0),
        scene("Octa Zoom 1", 9.0, 0.0),
        scene("Octa moved", 3.0, 0.5)
    );
    let path = dir.join("tiny.json");
    std::fs::write(&path, json).unwrap();
    path
}

#[test]
fn tables_share_meshes_and_draw_one_mark_per_data_point() {
    let dir = tempfile::tempdir().unwrap();
    let scenes = tiny_scenes(dir.path());
    let obj = dir.path().join("octa.obj");
    let out = dir.path().join("out");
    let plots = dir.path().join("plots");
    let doc = json(&[
        "tables",
        "--scenes",
        scenes.to_str().unwrap(),
        "--quick",
        "--width",
        "32",
        "--height",
        "24",
        "--frames",
        "1",
        "--min-time",
        "0",
        "--out",
        out.to_str().unwrap(),
        "--plots",
        plots.to_str().unwrap(),
        "--scene",
        obj.to_str().unwrap(),
        "--large-models",
        "1k",
        "--large-models-limit",
        "96M",
    ]);
    let sc = doc["scenes"].as_array().unwrap();
    assert_eq!(sc.len(), 4, "three scenes of --scenes, one of --scene");
    for s in sc {
        assert!(s["error"].is_null(), "{}", s["error"]);
    }
    // The two zoom cameras and the bare OBJ (same geometry, no camera)
    // share one build; the moved copy is built alone.
    assert_eq!(sc[0]["mesh_reused"], false);
    assert_eq!(sc[1]["mesh_reused"], true);
    assert_eq!(sc[3]["mesh_reused"], true);
    assert_eq!(sc[1]["shares_mesh_with"][0], "Octa Zoom 0");
    assert_eq!(sc[0]["shares_mesh_with"].as_array().unwrap().len(), 2);
    assert_eq!(sc[2]["shares_mesh_with"].as_array().unwrap().len(), 0);
    assert_eq!(sc[0]["info"]["tets"], sc[1]["info"]["tets"]);
    assert_eq!(sc[0]["info"]["tets"], sc[3]["info"]["tets"]);
    // The shared box holds the far camera of Zoom 1 although Zoom 0 (near
    // camera) was built first: its walks start inside the mesh.
    for r in sc[1]["renders"].as_array().unwrap() {
        assert_eq!(r["failures"], 0, "{r}");
        assert_eq!(r["rays"], 32 * 24);
    }
    // Nodes per ray for the BVH only.
    for r in sc[0]["renders"].as_array().unwrap() {
        assert_eq!(r["nodes_per_ray"].is_null(), r["method"] != "obvhs", "{r}");
    }
    // Secondary rays (quick: not on a scene sharing an earlier scene's
    // mesh): every method casts the same AO rays, one per hit at most.
    let secondary = sc[0]["secondary"].as_array().unwrap();
    assert!(secondary.len() >= 3, "{secondary:?}");
    for r in secondary {
        assert_eq!(r["rays_kind"], "mixed", "{r}");
        let ao = &r["by_kind"]["ao"]["rays"];
        assert_eq!(ao, &secondary[0]["by_kind"]["ao"]["rays"], "{r}");
        assert!(ao.as_u64().unwrap() <= r["hits"].as_u64().unwrap(), "{r}");
    }
    assert!(secondary[0]["by_kind"]["ao"]["rays"].as_u64().unwrap() > 0);
    assert!(sc[1]["secondary"].as_array().unwrap().is_empty());
    // The build-choice tables time the default mesh again beside the
    // variant: the same mesh and rays as the render table's tet20 row.
    for s in sc {
        let tet20 = s["renders"]
            .as_array()
            .unwrap()
            .iter()
            .find(|r| r["method"] == "tet20")
            .unwrap();
        for (base, variant) in [
            ("sorted_tet20", "unsorted_tet20"),
            ("tight_box_tet20", "wide_box_tet20"),
        ] {
            assert_eq!(s[base]["method"], "tet20", "{base}: {}", s[base]);
            assert_eq!(s[variant]["method"], "tet20", "{variant}: {}", s[variant]);
            for k in ["rays", "hits", "tets_per_ray"] {
                assert_eq!(s[base][k], tet20[k], "{base}.{k}");
            }
        }
    }
    // The exit-face table: every method, every decision right.
    let stabs = doc["exit_face"]["stabs"].as_array().unwrap();
    assert_eq!(stabs.len(), 5);
    for r in stabs {
        assert_eq!(r["wrong"], 0, "{r}");
        assert!(r["ns_per_stab"].as_f64().unwrap() > 0.0);
    }
    assert_eq!(doc["exit_face"]["walks"].as_array().unwrap().len(), 7);
    // Quick mode says why there is no out-of-core table.
    assert!(
        doc["out_of_core_note"]
            .as_str()
            .unwrap()
            .contains("--quick")
    );
    let md = std::fs::read_to_string(out.join("tables.md")).unwrap();
    assert!(md.contains("Exit-face search (Maria et al. 2017, Table 5)"));
    assert!(md.contains("skipped in --quick"));

    // Figures: well-formed SVG with one mark per data point.
    let figures: Vec<&str> = doc["figures"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap())
        .collect();
    assert_eq!(figures.len(), 4);
    let marks = |name: &str| {
        let path = plots.join(name);
        assert!(figures.contains(&path.to_str().unwrap()), "{figures:?}");
        let text = std::fs::read_to_string(&path).unwrap();
        let svg = roxmltree::Document::parse(&text).expect("well-formed SVG");
        let root = svg.root_element();
        let (w, h) = (root.attribute("width"), root.attribute("height"));
        let circles = svg
            .descendants()
            .filter(|n| n.has_tag_name("circle"))
            .count();
        let bars = svg
            .descendants()
            .filter(|n| n.has_tag_name("rect"))
            .filter(|n| !(n.attribute("width") == w && n.attribute("height") == h))
            .count();
        (circles, bars)
    };
    let methods = sc[0]["renders"].as_array().unwrap().len();
    let accuracy_points: usize = sc
        .iter()
        .map(|s| s["accuracy"]["methods"].as_array().unwrap().len())
        .sum();
    assert_eq!(accuracy_points, 4 * methods);
    assert_eq!(marks("speed_vs_accuracy.svg"), (accuracy_points, 0));
    assert_eq!(marks("mrays_per_method.svg"), (0, 4 * methods));
    assert_eq!(marks("figure8_sorted_vs_unsorted.svg"), (0, 2 * 4));

    // Large models: the smallest dense knots are Torus Knots themselves
    // (77,760 triangles); Ray-Strips, the BVH and Tet20 see the same
    // image, and Ray-Strips is the smaller of the two triangle structures.
    let large = doc["large_models"].as_array().unwrap();
    assert_eq!(large.len(), 1);
    assert!(large[0]["error"].is_null(), "{}", large[0]["error"]);
    assert_eq!(large[0]["triangles"], 77_760);
    let structures = large[0]["structures"].as_array().unwrap();
    let names: Vec<&str> = structures
        .iter()
        .map(|s| s["structure"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["strips", "obvhs", "tet20"]);
    for s in structures {
        assert_eq!(s["render"]["failures"], 0, "{s}");
        assert_eq!(s["render"]["hits"], structures[0]["render"]["hits"], "{s}");
    }
    assert!(structures[0]["render"]["hits"].as_u64().unwrap() > 0);
    // Tet20 built out of core under the given limit, in parts, the whole
    // process tree under it; the triangle structures have no build report.
    let memory = &structures[2]["memory"];
    assert_eq!(memory["limit_bytes"], 96 << 20, "{memory}");
    assert!(memory["parts"].as_u64().unwrap() > 1, "{memory}");
    if let Some(peak) = memory["tree_peak_kib"].as_u64() {
        assert!(peak * 1024 <= 96 << 20, "{memory}");
    }
    assert!(structures[0]["memory"].is_null() && structures[1]["memory"].is_null());
    assert!(md.contains("out of core under 96 MiB"));
    let bpt = |i: usize| structures[i]["bytes_per_triangle"].as_f64().unwrap();
    assert!(
        bpt(0) < bpt(1),
        "Ray-Strips {} B/tri, BVH {}",
        bpt(0),
        bpt(1)
    );
    assert!(md.contains("Large models (Lauterbach et al. 2007, §6)"));
    // One mark per structure with bytes and a render: tet20, tet16, tet32,
    // Ray-Strips and obvhs per scene, plus the large model's three.
    assert_eq!(
        marks("bytes_per_triangle_vs_mrays.svg"),
        (4 * 5 + structures.len(), 0)
    );
}

/// `build` stores the scene's camera and lights in the mesh file, and
/// `render FILE` uses them: the file renders exactly the image of the scene
/// (same hits), which a camera framing the mesh would not.
#[test]
fn mesh_files_carry_the_scene_camera_and_lights() {
    let dir = tempfile::tempdir().unwrap();
    let scenes = tiny_scenes(dir.path());
    let spec = format!("{}#Octa Zoom 1", scenes.display());
    let file = dir.path().join("zoom1.tmesh");
    let file = file.to_str().unwrap();
    json(&["build", &spec, "-o", file]);
    let (mesh, stored) = tet_core::format::load_with_scene(std::path::Path::new(file)).unwrap();
    assert!(!mesh.tets.is_empty());
    let cam = stored.camera.expect("the scene's camera is stored");
    // Orbit distance 9 around the origin (scenes.json convention).
    assert!((cam.position.length() - 9.0).abs() < 1e-4, "{cam:?}");
    assert_eq!(stored.lights.len(), 1);
    assert_eq!(stored.lights[0].position, glam::Vec3::new(3.0, 4.0, 5.0));
    let render = |s: &str| {
        json(&[
            "render", s, "--method", "tet20", "--width", "40", "--height", "30", "--frames", "1",
        ])
    };
    let (a, b) = (render(&spec), render(file));
    assert!(a["hits"].as_u64().unwrap() > 0);
    assert_eq!(a["hits"], b["hits"]);
    assert_eq!(a["tets_per_ray"], b["tets_per_ray"]);
}

/// A closed unit cube centred on (0.5, 0.5, 0.5), outward-facing triangles.
fn cube_obj(dir: &std::path::Path) -> std::path::PathBuf {
    let path = dir.join("cube.obj");
    std::fs::write(
        &path,
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
         f 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\n\
         f 4 8 7\nf 4 7 3\nf 1 5 8\nf 1 8 4\nf 2 3 7\nf 2 7 6\n",
    )
    .unwrap();
    path
}

/// `render --json` at a small size, with extra arguments.
fn render_json(scene: &str, method: &str, extra: &[&str]) -> Value {
    let mut args = vec![
        "render", scene, "--method", method, "--width", "48", "--height", "36", "--frames", "1",
    ];
    args.extend_from_slice(extra);
    json(&args)
}

/// A scene without a camera (an OBJ, and the mesh file built from it) is
/// seen from outside: the default camera frames the whole closed cube, so
/// its hits cover a good part of the image but not all of it, and they
/// are the hits of the f64 brute-force reference.
#[test]
fn scenes_without_a_camera_are_framed_from_outside() {
    let dir = tempfile::tempdir().unwrap();
    let obj = cube_obj(dir.path());
    let obj = obj.to_str().unwrap();
    let file = dir.path().join("cube.tmesh");
    let file = file.to_str().unwrap();
    json(&["build", obj, "-o", file]);
    let rays = 48 * 36;
    for scene in [obj, file] {
        let walk = render_json(scene, "tet20", &[]);
        assert_eq!(walk["rays"], rays);
        assert_eq!(walk["failures"], 0, "{walk}");
        let hits = walk["hits"].as_u64().unwrap();
        // The cube's front face alone covers more than a tenth of the image.
        assert!(
            hits > rays / 10 && hits < rays,
            "{scene}: {hits} of {rays} rays hit"
        );
        let reference = render_json(scene, "brute", &[]);
        assert_eq!(walk["hits"], reference["hits"], "{scene}");
    }
    // The accuracy command checks every camera ray against the reference.
    let a = json(&[
        "accuracy",
        "--min-time",
        "0",
        file,
        "--methods",
        "tet20,tet80",
        "--rays",
        "0",
        "--image",
        "32",
    ]);
    let case = &a["cases"][0];
    assert_eq!(case["rays"], 32 * 32);
    for m in case["methods"].as_array().unwrap() {
        assert_eq!(m["failures"], 0, "{m}");
        assert_eq!(
            m["agree"].as_u64().unwrap() + m["ambiguous"].as_u64().unwrap(),
            32 * 32,
            "{m}"
        );
    }
}

/// `--eye`, `--target`, `--up`, `--fov` replace the camera: looking away
/// from the cube sees nothing, looking at it from another side sees it,
/// and impossible views are refused with a clear message.
#[test]
fn view_flags_move_the_camera_and_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let obj = cube_obj(dir.path());
    let file = dir.path().join("cube.tmesh");
    let file = file.to_str().unwrap();
    json(&["build", obj.to_str().unwrap(), "-o", file]);

    let away = render_json(
        file,
        "tet20",
        &["--eye", "0.5,0.5,4", "--target", "0.5,0.5,8"],
    );
    assert_eq!(away["hits"], 0, "{away}");
    assert_eq!(away["failures"], 0, "{away}");
    // From below (-y), up along +z, a narrow field of view that the cube fills.
    let below = [
        "--eye",
        "0.5,-3,0.5",
        "--target",
        "0.5,0.5,0.5",
        "--up",
        "0,0,1",
        "--fov",
        "10",
    ];
    let at = render_json(file, "tet20", &below);
    assert_eq!(at["failures"], 0, "{at}");
    assert_eq!(
        at["hits"],
        48 * 36,
        "a 10° view of the cube from 3.5 away is all cube"
    );
    let reference = render_json(file, "brute", &below);
    assert_eq!(at["hits"], reference["hits"]);
    // The same view through `accuracy`: every camera ray agrees.
    let mut args = vec![
        "accuracy",
        "--min-time",
        "0",
        file,
        "--methods",
        "tet20",
        "--rays",
        "0",
        "--image",
        "16",
    ];
    args.extend_from_slice(&below);
    let a = json(&args);
    assert_eq!(a["cases"][0]["methods"][0]["failures"], 0, "{a}");

    for (flags, words) in [
        (vec!["--eye", "1,2,3", "--target", "1,2,3"], "same point"),
        (vec!["--up", "0,0,1"], "parallel to the line of sight"),
        (vec!["--fov", "180"], "between 0 and 180"),
        (vec!["--fov", "0"], "between 0 and 180"),
        (vec!["--eye", "1,2"], "three numbers"),
        (vec!["--target", "1,inf,0"], "not finite"),
    ] {
        for command in ["render", "accuracy"] {
            let mut args = vec![command, file];
            args.extend_from_slice(&flags);
            let out = bench(&args);
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert!(!out.status.success(), "{args:?} succeeded");
            assert!(stderr.contains(words), "{args:?}: {stderr}");
            assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        }
    }
}

/// A reader that stops reading (`tet-bench … | head -2`) ends the program
/// quietly and successfully, as Unix tools do: no panic, no backtrace, no
/// error message, for every command that writes to stdout.
#[test]
fn a_closed_stdout_ends_every_command_quietly() {
    use std::process::Stdio;
    let dir = tempfile::tempdir().unwrap();
    let obj = cube_obj(dir.path());
    let obj = obj.to_str().unwrap();
    let file = dir.path().join("cube.tmesh");
    let file = file.to_str().unwrap();
    json(&["build", obj, "-o", file]);
    let again = dir.path().join("again.tmesh");
    let tables = dir.path().join("tables");
    let small = ["--width", "16", "--height", "12", "--frames", "1"];
    let mut commands: Vec<Vec<&str>> = vec![
        vec!["info", file],
        vec!["info", file, "--json"],
        vec!["build", obj, "-o", again.to_str().unwrap()],
        vec!["render", file, "--json"],
        vec!["render", file],
        vec![
            "accuracy",
            file,
            "--rays",
            "100",
            "--image",
            "8",
            "--min-time",
            "0",
        ],
        vec![
            "accuracy",
            file,
            "--rays",
            "100",
            "--image",
            "8",
            "--min-time",
            "0",
            "--json",
        ],
    ];
    commands[3].extend_from_slice(&small);
    commands[4].extend_from_slice(&small);
    let mut t = vec![
        "tables",
        "--quick",
        "--min-time",
        "0",
        "--scene",
        file,
        "--out",
        tables.to_str().unwrap(),
    ];
    t.extend_from_slice(&small);
    commands.push(t);
    for args in commands {
        let mut child = Command::new(env!("CARGO_BIN_EXE_tet-bench"))
            .args(&args)
            .env("RUST_BACKTRACE", "1")
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("tet-bench runs");
        // Close the read end before the program writes its first line.
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            !stderr.contains("panicked")
                && !stderr.contains("Broken pipe")
                && !stderr.contains("error"),
            "{args:?}: {stderr}"
        );
        assert!(out.status.success(), "{args:?}: {:?} {stderr}", out.status);
    }
}

/// `accuracy --json`: every ray lands in exactly one counter (leaks
/// included), and failures are the sum of the failure counters.
#[test]
fn accuracy_counters_partition_the_rays_and_leaks_are_failures() {
    let a = json(&[
        "accuracy",
        "--min-time",
        "0",
        "torus-knot",
        "--methods",
        "tet20,obvhs",
        "--rays",
        "1000",
        "--image",
        "16",
    ]);
    let n = |m: &Value, k: &str| m[k].as_u64().unwrap_or_else(|| panic!("{k}: {m}"));
    for m in a["cases"][0]["methods"].as_array().unwrap() {
        let failures = [
            "leaks",
            "wrong_triangle",
            "false_misses",
            "false_hits",
            "step_cap",
            "lost",
            "invalid",
            "nans",
        ]
        .iter()
        .map(|k| n(m, k))
        .sum::<u64>();
        assert_eq!(n(m, "failures"), failures, "{m}");
        assert_eq!(
            n(m, "agree") + n(m, "ambiguous") + failures,
            n(m, "rays"),
            "{m}"
        );
        assert_eq!(n(m, "rays"), 1000 + 16 * 16);
        // The first failing rays are kept to reproduce them, each with
        // the verdict it was counted under.
        let kept = m["failed_rays"].as_array().unwrap();
        assert_eq!(kept.len() as u64, failures.min(8), "{m}");
        for f in kept {
            let key = match f["verdict"].as_str().unwrap() {
                "Leak" => "leaks",
                "WrongTriangle" => "wrong_triangle",
                "FalseMiss" => "false_misses",
                "FalseHit" => "false_hits",
                "StepCap" => "step_cap",
                "Lost" => "lost",
                "Invalid" => "invalid",
                "Nan" => "nans",
                v => panic!("not a failure: {v}"),
            };
            assert!(n(m, key) > 0, "{f}");
            assert_eq!(f["direction"].as_array().unwrap().len(), 3);
        }
    }
}

/// `iso`: the paper's IBVH (BIH and SAH, single rays and 16×16 packets)
/// and the iso walks over three layouts find the isosurface on the same
/// pixels of a synthetic volume (to a handful of grazing pixels), none
/// fails, and a time step the field does not have is an error.
#[test]
fn iso_methods_agree() {
    let mut hits = Vec::new();
    for m in [
        "ibvh",
        "ibvh-sah",
        "ibvh-packets",
        "walk-tet20",
        "walk-tet16",
        "walk-tet32",
    ] {
        let d = json(&[
            "iso",
            "linear",
            "--method",
            m,
            "--width",
            "48",
            "--height",
            "40",
            "--frames",
            "1",
            "--threads",
            "1",
        ]);
        assert_eq!(d["failures"], 0, "{m}");
        assert_eq!(d["rays"], 48 * 40, "{m}");
        assert!(d["bytes"].as_u64().unwrap() > 0, "{m}");
        hits.push(d["hits"].as_u64().unwrap());
    }
    let h0 = hits[0];
    assert!(h0 > 200, "{hits:?}");
    assert!(hits.iter().all(|&h| h.abs_diff(h0) <= h0 / 100), "{hits:?}");
    let out = bench(&[
        "iso",
        "linear",
        "--time-step",
        "3",
        "--width",
        "8",
        "--height",
        "8",
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("time step 3"));
    // The bucky cube grows by whole balls (Wald et al. 2007, Table 3): 1 ball is
    // one 27×33×33 grid in six, 8 balls eight of them.
    for (n, tets) in [("1", 6 * 27 * 33 * 33), ("2", 8 * 6 * 27 * 33 * 33)] {
        let d = json(&[
            "iso",
            "buckycube",
            "--replications",
            n,
            "--method",
            "walk-tet20",
            "--width",
            "16",
            "--height",
            "16",
            "--frames",
            "1",
        ]);
        assert_eq!(d["tets"], tets, "{n}");
        assert!(d["hits"].as_u64().unwrap() > 0, "{n}");
    }
    let err = stderr_of(&["iso", "buckycube", "--replications", "0"]);
    assert!(err.contains("replications"), "{err}");
}

/// `convert`: a volume with a scalar field goes to `.vtu`, back to a mesh
/// file, to TetGen's files and back again, and arrives unchanged (points,
/// tets, neighbours and the field's values, bit for bit).
#[test]
fn convert_round_trips_through_vtk_and_tetgen() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    for (from, to) in [
        ("linear".to_string(), p("a.tmesh")),
        (p("a.tmesh"), p("a.vtu")),
        (p("a.vtu"), p("b.tmesh")),
        (p("b.tmesh"), p("c.vtk")),
        (p("c.vtk"), p("c.tmesh")),
        (p("c.tmesh"), p("d.node")),
        (p("d.node"), p("e.tmesh")),
    ] {
        let d = json(&["convert", &from, &to]);
        assert_eq!(d["scalar_steps"], 1, "{from} -> {to}");
    }
    let a = tet_core::format::load(p("a.tmesh")).unwrap();
    let field = |m: &tet_core::TetMesh| m.attributes.scalars.as_ref().unwrap().steps.clone();
    for other in ["b.tmesh", "c.tmesh", "e.tmesh"] {
        let m = tet_core::format::load(p(other)).unwrap();
        assert_eq!(m.points, a.points, "{other}");
        assert_eq!(m.tets, a.tets, "{other}");
        assert_eq!(m.neighbors, a.neighbors, "{other}");
        assert_eq!(field(&m), field(&a), "{other}");
    }
    let out = bench(&["convert", &p("missing.vtu"), &p("x.tmesh")]);
    assert!(!out.status.success());
}

/// `--walls N`: the scene cut into N parts with walls between them traces
/// with no failure against the f64 reference, and hits what the one-piece
/// mesh (`--walls none`) hits (the walls are no scene faces). Builds are
/// walled by default, and `--walls none` is one TetGen run.
#[test]
fn walls_build_parts_that_trace_like_the_in_core_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let walled = dir.path().join("walled.tmesh");
    let walled = walled.to_str().unwrap();
    let b = json(&["build", "torus-knot", "--walls", "8", "-o", walled]);
    let switches = b["build"]["switches"].as_str().unwrap();
    assert!(switches.ends_with("in 8 parts"), "{switches}");
    let a = json(&[
        "accuracy",
        "--min-time",
        "0",
        walled,
        "--methods",
        "tet20,tet16,tet32",
        "--rays",
        "2000",
        "--image",
        "32",
    ]);
    for m in a["cases"][0]["methods"].as_array().unwrap() {
        assert_eq!(m["failures"], 0, "{m}");
        assert_eq!(m["rays"], 2000 + 32 * 32);
    }
    let image = ["--method", "tet20", "--width", "64", "--height", "48"];
    let hits = |scene: &[&str]| {
        let mut args = vec!["render"];
        args.extend(scene);
        args.extend(image);
        args.extend(["--frames", "1"]);
        json(&args)["hits"].as_u64().unwrap()
    };
    assert_eq!(hits(&[walled]), hits(&["torus-knot", "--walls", "none"]));
    let one_piece = dir.path().join("one.tmesh");
    let one_piece = one_piece.to_str().unwrap();
    let switches = |extra: &[&str]| {
        let mut args = vec!["build", "torus-knot", "-o", one_piece];
        args.extend(extra);
        json(&args)["build"]["switches"]
            .as_str()
            .unwrap()
            .to_owned()
    };
    assert!(switches(&[]).ends_with(" parts"), "{}", switches(&[]));
    let s = switches(&["--walls", "none"]);
    assert!(!s.contains("parts"), "{s}");
    // Parts are chosen by memory or by --walls, not both.
    let err = stderr_of(&[
        "build",
        "torus-knot",
        "--walls",
        "8",
        "--memory-limit",
        "1G",
        "-o",
        walled,
    ]);
    assert!(err.contains("--walls and --memory-limit"), "{err}");
}

/// `render --rays`: each kind's rays are cast and reported apart, the
/// same rays for a tet walk and a BVH (same hits, so the same AO rays),
/// and `--shadows` adds shadow rays to the kinds asked for.
#[test]
fn render_reports_each_kind_of_ray_apart() {
    let mut ao_rays = Vec::new();
    for method in ["tet20", "obvhs"] {
        for kind in ["primary", "ao", "shadow", "mixed"] {
            let r = render_json("torus-knot", method, &["--rays", kind]);
            assert_eq!(r["rays_kind"], kind, "{r}");
            let by = &r["by_kind"];
            assert_eq!(by["primary"]["rays"], 48 * 36, "{r}");
            let hits = r["hits"].as_u64().unwrap();
            let ao = by["ao"]["rays"].as_u64().unwrap();
            let shadow = by["shadow"]["rays"].as_u64().unwrap();
            let with_ao = kind == "ao" || kind == "mixed";
            let with_shadows = kind == "shadow" || kind == "mixed";
            assert_eq!(ao > 0, with_ao, "{r}");
            assert!(ao <= hits, "{r}");
            assert_eq!(shadow > 0, with_shadows, "{r}");
            assert_eq!(shadow, r["shadow_rays"].as_u64().unwrap(), "{r}");
            for k in ["primary", "ao", "shadow"] {
                let rays = by[k]["rays"].as_u64().unwrap();
                let speed = by[k]["mrays_per_s"].as_f64().unwrap();
                assert_eq!(speed > 0.0, rays > 0, "{k}: {r}");
            }
            // Tets per AO ray: counted for the walk, not for the BVH.
            assert_eq!(
                by["ao"]["tets_per_ray"].is_null(),
                method == "obvhs" || !with_ao
            );
            if with_ao {
                ao_rays.push(ao);
            }
        }
    }
    assert!(ao_rays.iter().all(|&n| n == ao_rays[0]), "{ao_rays:?}");
    let both = render_json("torus-knot", "tet20", &["--rays", "ao", "--shadows"]);
    assert_eq!(both["rays_kind"], "mixed");
}
