//! `tet-bench gpu-bench` as a GPU machine runs it, at CI's size: meshes
//! prepared first (`--prepare-meshes`), then the quick run on them, on
//! whatever adapter there is (lavapipe in CI: a test of the command and
//! its documents, not of speed). Without an adapter the test is skipped,
//! unless `TET_GPU_REQUIRED=1` (CI) makes that a failure.

#[cfg(feature = "gpu")]
use std::path::Path;
use std::process::{Command, Output};

#[cfg(feature = "gpu")]
use serde_json::Value;

fn bench(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tet-bench"))
        .args(args)
        .output()
        .expect("tet-bench runs")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[cfg(feature = "gpu")]
fn read_json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{} is not JSON: {e}", path.display()))
}

/// Without the `gpu` feature the command says how to get it.
#[cfg(not(feature = "gpu"))]
#[test]
fn gpu_bench_names_the_feature_it_needs() {
    let dir = tempfile::tempdir().unwrap();
    let out = bench(&["gpu-bench", dir.path().to_str().unwrap(), "--quick"]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("--features gpu"), "{}", stderr(&out));
}

/// True when `TET_GPU_REQUIRED` asks for an adapter.
#[cfg(feature = "gpu")]
fn adapter_required() -> bool {
    std::env::var("TET_GPU_REQUIRED").is_ok_and(|v| !v.is_empty() && v != "0")
}

#[cfg(feature = "gpu")]
#[test]
fn quick_run_writes_checked_documents() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let meshes = dir.path().join("meshes");
    let (out_s, meshes_s) = (out_dir.to_str().unwrap(), meshes.to_str().unwrap());

    // The adapter check: its document, and a software adapter refused
    // unless allowed.
    let out = bench(&[
        "gpu-bench",
        out_s,
        "--adapter-only",
        "--allow-software",
        "--json",
    ]);
    if !out.status.success() {
        let err = stderr(&out);
        assert!(
            !adapter_required() && err.contains("no Vulkan adapter"),
            "the adapter check failed: {err}"
        );
        eprintln!("skipped: no Vulkan adapter ({err})");
        return;
    }
    let adapter: Value = serde_json::from_slice(&out.stdout).expect("one JSON document");
    let name = adapter["name"].as_str().unwrap().to_string();
    assert!(!name.is_empty());
    for key in ["backend", "device_type", "driver"] {
        assert!(adapter[key].is_string(), "adapter.{key}: {adapter}");
    }
    let software = adapter["software"].as_bool().unwrap();
    let timestamps = adapter["timestamps"].as_bool().unwrap();
    let strict = bench(&["gpu-bench", out_s, "--adapter-only"]);
    assert_eq!(strict.status.success(), !software, "{}", stderr(&strict));
    if software {
        assert!(
            stderr(&strict).contains("software adapter"),
            "{}",
            stderr(&strict)
        );
    }

    // The meshes a GPU machine takes along.
    let out = bench(&[
        "gpu-bench",
        out_s,
        "--prepare-meshes",
        "--meshes",
        meshes_s,
        "--scene",
        "torus-knot",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let prepared = read_json(&out_dir.join("meshes.json"));
    assert!(meshes.join("torus-knot.tmesh").is_file());
    let bytes = prepared["total_bytes"].as_u64().unwrap();
    assert!(bytes > 0 && prepared["fits"] == true, "{prepared}");

    // The run: the prepared mesh, and a scene whose file is missing.
    let absent = dir.path().join("absent.obj");
    let out = bench(&[
        "gpu-bench",
        out_s,
        "--quick",
        "--meshes",
        meshes_s,
        "--scene",
        "torus-knot",
        "--scene",
        absent.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let doc = read_json(&out_dir.join("gpu.json"));
    assert_eq!(doc["schema"], "tet-gpu-bench");
    assert_eq!(doc["version"], 1);
    assert_eq!(doc["adapter"]["name"], name.as_str());
    let md = std::fs::read_to_string(out_dir.join("gpu.md")).unwrap();
    assert!(md.contains("Table 3") && md.contains(&name), "{md}");

    let scenes = doc["scenes"].as_array().unwrap();
    assert_eq!(scenes.len(), 2, "{doc:#}");
    assert_eq!(scenes[0]["mesh"]["source"], "file", "{:#}", scenes[0]);
    assert!(scenes[0]["skipped"].is_null(), "{:#}", scenes[0]);
    let why = scenes[1]["skipped"]
        .as_str()
        .expect("the missing scene is skipped");
    assert!(why.contains("absent.obj"), "{why}");

    let timing = if timestamps { "timestamp" } else { "wall" };
    let check = |row: &Value| {
        let at = format!("{} {} {}", row["scene"], row["method"], row["kind"]);
        assert_eq!(row["timing"], timing, "{at}");
        assert!(row["kernel_ms"].as_f64().unwrap() > 0.0, "{at}");
        assert!(row["mrays_per_s"].as_f64().unwrap() > 0.0, "{at}");
        let d = &row["differences"];
        assert_eq!(d["unexplained"], 0, "{at}: {d:#}");
        if d["rays"] == 0 {
            assert_eq!(row["hits"], row["cpu_hits"], "{at}");
        }
        assert!(row["gpu_bytes"]["total"].as_u64().unwrap() > 0, "{at}");
    };
    let table3 = doc["table3"].as_array().unwrap();
    let methods: Vec<&str> = table3
        .iter()
        .map(|r| r["method"].as_str().unwrap())
        .collect();
    assert_eq!(
        methods,
        ["gpu-tet20", "gpu-tet16", "gpu-tet32", "gpu-tet80"]
    );
    for row in table3 {
        check(row);
        assert_eq!(row["rays"], 160 * 120);
        assert_eq!(row["kind"], "primary");
        assert!(
            row["hits"].as_u64().unwrap() > 0,
            "the camera sees the knot"
        );
        assert_eq!(row["dispatches"], 3);
    }
    let secondary = doc["secondary"].as_array().unwrap();
    assert_eq!(secondary.len(), 8, "shadow and bounce rays of each layout");
    for row in secondary {
        check(row);
        assert!(["shadow", "bounce"].contains(&row["kind"].as_str().unwrap()));
    }
    let bvh = doc["bvh"].as_array().unwrap();
    assert_eq!(bvh.len(), 1, "bvh_note: {}", doc["bvh_note"]);
    check(&bvh[0]);
    assert_eq!(bvh[0]["method"], "gpu-bvh");
    assert_eq!(bvh[0]["reference"], "tet20");
}
