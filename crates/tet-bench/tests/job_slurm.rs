//! A job on a real Slurm: `scripts/slurm/single-node.sh` starts a
//! one-node cluster on 127.0.0.1, a grid of 27 torus knots (311 040
//! triangles, written as an OBJ file) is planned, submitted as an array of parts and a merge depending on
//! it; one array task is cancelled while it builds (the merge is then
//! cancelled by Slurm), `submit` again runs only that part and the merge.
//! The merged mesh is byte for byte the single-process out-of-core build
//! that leaves its one worker the same limit, and traces without failures. Every
//! task's measured peak (its TetGen worker and itself) fits the memory
//! it asked for.
//!
//! Needs root on Debian/Ubuntu (the script installs the packages when
//! missing) and a few minutes:
//!
//! ```text
//! cargo test -p tet-bench --test job_slurm -- --ignored --nocapture
//! ```
//!
//! A cluster the script finds running is used and left running; one it
//! starts is stopped at the end (`scripts/slurm/stop.sh`).
#![cfg(feature = "tetgen")]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use serde_json::Value;

const TIMEOUT: Duration = Duration::from_secs(900);

fn scripts() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scripts/slurm")
}

/// Writes the 3×3×3 knot grid of the memory model's measurements as an OBJ file.
fn write_scene(path: &Path) {
    use std::fmt::Write;
    let scene = tet_build::outofcore::memory_model::knot_grid(3, 240, 24);
    let mut obj = String::new();
    for v in &scene.vertices {
        let _ = writeln!(obj, "v {:?} {:?} {:?}", v.x, v.y, v.z);
    }
    for t in &scene.triangles {
        let _ = writeln!(obj, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    std::fs::write(path, obj).unwrap();
}

fn slurm_conf() -> PathBuf {
    let dir = std::env::var("TET_SLURM_DIR").unwrap_or_else(|_| "/tmp/tet-slurm".into());
    Path::new(&dir).join("slurm.conf")
}

/// `program` with this test's Slurm configuration and no inherited task
/// index; an error when it cannot be started (e.g. not installed).
fn try_run(program: &str, args: &[&str]) -> std::io::Result<Output> {
    Command::new(program)
        .args(args)
        .env("SLURM_CONF", slurm_conf())
        .env_remove("SLURM_ARRAY_TASK_ID")
        .env_remove("JOB_COMPLETION_INDEX")
        .output()
}

fn run(program: &str, args: &[&str]) -> Output {
    try_run(program, args).unwrap_or_else(|e| panic!("cannot run {program}: {e}"))
}

fn text(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).trim().to_string()
}

fn json(args: &[&str]) -> Value {
    let mut all = args.to_vec();
    all.push("--json");
    let out = run(env!("CARGO_BIN_EXE_tet-bench"), &all);
    assert!(
        out.status.success(),
        "tet-bench {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// `squeue`'s state of a job (or array task), `None` once it has left the queue.
fn queued(id: &str) -> Option<String> {
    let out = run("squeue", &["-h", "-j", id, "-o", "%T"]);
    let states = text(&out);
    (out.status.success() && !states.is_empty()).then_some(states)
}

fn wait_until(what: &str, start: Instant, mut done: impl FnMut() -> bool) {
    while !done() {
        assert!(start.elapsed() < TIMEOUT, "timed out waiting for {what}");
        std::thread::sleep(Duration::from_millis(500));
    }
}

/// Stops the cluster at the end if this test started it.
struct Cluster {
    started: bool,
}

impl Drop for Cluster {
    fn drop(&mut self) {
        if self.started {
            let _ = Command::new(scripts().join("stop.sh")).status();
        }
    }
}

#[test]
#[ignore = "needs root: starts a single-node Slurm (installs munge and slurm-wlm when missing); .ci/run runs it"]
fn a_job_runs_on_slurm_and_a_cancelled_part_is_rerun_alone() {
    let start = Instant::now();
    // No `sinfo` at all (Slurm not installed yet) is a cluster to start:
    // single-node.sh installs it.
    let idle = try_run("sinfo", &["-h", "-o", "%T"])
        .is_ok_and(|out| out.status.success() && text(&out).starts_with("idle"));
    let started = !idle;
    let _cluster = Cluster { started };
    if started {
        let status = Command::new(scripts().join("single-node.sh"))
            .status()
            .expect("single-node.sh runs");
        assert!(status.success(), "single-node.sh failed");
    }
    println!("cluster up after {:.1} s", start.elapsed().as_secs_f64());

    let dir = tempfile::tempdir().unwrap();
    let scene_file = dir.path().join("knots27.obj");
    write_scene(&scene_file);
    let scene = scene_file.to_str().unwrap();
    let jobdir = dir.path().join("job");
    let j = jobdir.to_str().unwrap();
    let out = dir.path().join("slurm.tmesh");
    let limit = "300M";
    // Cut for the limit alone (`--walls none`): a few parts of seconds
    // each, where the default cut for rays would make ~100 small ones.
    let plan = json(&[
        "build",
        scene,
        "--plan",
        j,
        "--memory-limit",
        limit,
        "--walls",
        "none",
    ]);
    let n = plan["parts"].as_u64().unwrap() as usize;
    assert!(n >= 4, "{plan}");
    println!(
        "planned {n} parts after {:.1} s",
        start.elapsed().as_secs_f64()
    );

    let s = json(&[
        "submit",
        j,
        "--engine",
        "slurm",
        "-o",
        out.to_str().unwrap(),
    ]);
    let parts_job = s["parts_job"].as_str().unwrap().to_string();
    let merge_job = s["merge_job"].as_str().unwrap().to_string();
    let mem_mib = s["mem_mib"].as_u64().unwrap();

    // Cancel one task as soon as it runs (each part takes seconds).
    let victim = n - 1;
    let task = format!("{parts_job}_{victim}");
    wait_until("the last task to start", start, || {
        queued(&task).is_some_and(|s| s.contains("RUNNING"))
    });
    let cancel = run("scancel", &[&task]);
    assert!(
        cancel.status.success(),
        "{}",
        String::from_utf8_lossy(&cancel.stderr)
    );
    wait_until("the array and the merge to leave the queue", start, || {
        queued(&parts_job).is_none() && queued(&merge_job).is_none()
    });
    assert!(!out.exists(), "the merge ran although a part was cancelled");
    let status = json(&["job", "status", j]);
    assert_eq!(
        status["rerun"],
        serde_json::json!([victim]),
        "only the cancelled part is left: {status}"
    );
    println!(
        "array done, task {victim} cancelled, after {:.1} s",
        start.elapsed().as_secs_f64()
    );

    // Submit again: only the cancelled part, then the merge.
    let again = json(&[
        "submit",
        j,
        "--engine",
        "slurm",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(again["parts"], serde_json::json!([victim]));
    let (p2, m2) = (
        again["parts_job"].as_str().unwrap().to_string(),
        again["merge_job"].as_str().unwrap().to_string(),
    );
    wait_until("the rerun and the merge", start, || {
        queued(&p2).is_none() && queued(&m2).is_none()
    });
    let merge_log = std::fs::read_to_string(jobdir.join("logs/merge.log")).unwrap_or_default();
    assert!(out.exists(), "no merged mesh; merge log:\n{merge_log}");
    println!("merged after {:.1} s", start.elapsed().as_secs_f64());

    // Measured peaks against what each task asked for.
    let status = json(&["job", "status", j, "--verify"]);
    assert_eq!(status["done"], n);
    for p in status["parts"].as_array().unwrap() {
        let (tetgen, process) = (
            p["tetgen_peak_kib"].as_u64().unwrap(),
            p["process_peak_kib"].as_u64().unwrap(),
        );
        println!(
            "part {}: predicted TetGen peak {:.1} MiB, measured TetGen {:.1} MiB + build-part {:.1} MiB, asked {mem_mib} MiB, {:.1} s",
            p["index"],
            p["predicted_peak_bytes"].as_u64().unwrap() as f64 / (1 << 20) as f64,
            tetgen as f64 / 1024.0,
            process as f64 / 1024.0,
            p["seconds"].as_f64().unwrap()
        );
        let used = tetgen + process;
        assert!(
            used <= mem_mib * 1024,
            "part {}: {used} KiB of {mem_mib} MiB",
            p["index"]
        );
    }

    // The single-process build, one worker, under the limit on its
    // process tree that leaves that worker the job's 300 MiB per part
    // (beside what the builder sets aside for itself and its quarter of
    // the part).
    let builder = json(&["build", scene, "--predict-memory"])["builder_bytes"]
        .as_u64()
        .unwrap();
    let per_part: u64 = 300 << 20;
    let local_limit = (builder + per_part + per_part / 4).to_string();
    let local = dir.path().join("local.tmesh");
    json(&[
        "build",
        scene,
        "-o",
        local.to_str().unwrap(),
        "--memory-limit",
        &local_limit,
        "--threads",
        "1",
        "--walls",
        "none",
    ]);
    assert!(
        std::fs::read(&out).unwrap() == std::fs::read(&local).unwrap(),
        "the Slurm job's mesh differs from the single-process build's"
    );
    let r = json(&[
        "render",
        out.to_str().unwrap(),
        "--method",
        "tet20",
        "--width",
        "160",
        "--height",
        "120",
        "--frames",
        "1",
    ]);
    assert_eq!(r["failures"], 0);
    assert!(r["hits"].as_i64().unwrap() > 0);
    println!("done after {:.1} s", start.elapsed().as_secs_f64());
}
