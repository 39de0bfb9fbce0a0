//! The job commands as a user scripts them: `build --plan`, `build-part`
//! with the index from the engine's environment, `job status`, `merge`,
//! `submit --dry-run`. The merged mesh is byte for byte the single-process
//! `build --memory-limit` of the same scene that leaves its one worker the
//! job's per-part limit, and traces without failures.

use std::path::Path;
use std::process::{Command, Output};

use serde_json::Value;

fn bench(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_tet-bench"));
    c.args(args)
        .env_remove("SLURM_ARRAY_TASK_ID")
        .env_remove("JOB_COMPLETION_INDEX");
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("tet-bench runs")
}

fn json_env(args: &[&str], env: &[(&str, &str)]) -> Value {
    let mut all = args.to_vec();
    all.push("--json");
    let out = bench(&all, env);
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

fn json(args: &[&str]) -> Value {
    json_env(args, &[])
}

/// Part `k`'s input digest in the plan of `jobdir`.
fn plan_digest(jobdir: &Path, k: usize) -> String {
    let job: Value = serde_json::from_str(&read(&jobdir.join("job.json"))).unwrap();
    job["parts"][k]["input_digest"]
        .as_str()
        .unwrap()
        .to_string()
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap()
}

#[test]
fn a_planned_job_runs_part_by_part_and_merges_into_the_local_build() {
    let dir = tempfile::tempdir().unwrap();
    let jobdir = dir.path().join("job");
    let j = jobdir.to_str().unwrap();
    let p = json(&["build", "torus-knot", "--predict-memory"]);
    let predicted = p["predicted_peak_bytes"].as_u64().unwrap();
    // A job's limit is on each part's predicted TetGen peak (each part
    // runs on its own); a multiple of 4, for the local build below.
    let per_part = (predicted * 3 / 4) & !3;
    let limit = per_part.to_string();
    let plan = json(&["build", "torus-knot", "--plan", j, "--memory-limit", &limit]);
    let n = plan["parts"].as_u64().unwrap() as usize;
    assert!(n >= 2, "{plan}");
    for p in plan["part_predicted_bytes"].as_array().unwrap() {
        assert!(p.as_u64().unwrap() <= predicted * 3 / 4, "{plan}");
    }
    assert!(jobdir.join("job.json").exists());

    // No index anywhere: a clear error.
    let out = bench(&["build-part", j], &[]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("SLURM_ARRAY_TASK_ID"), "{err}");

    // Parts in reverse order, the index from Slurm's or Kubernetes'
    // variable.
    for k in (0..n).rev() {
        let var = if k % 2 == 0 {
            "SLURM_ARRAY_TASK_ID"
        } else {
            "JOB_COMPLETION_INDEX"
        };
        let r = json_env(&["build-part", j], &[(var, &k.to_string())]);
        assert_eq!(r["part"], k);
        assert_eq!(r["outcome"], "built");
        assert!(r["record"]["tetgen_peak_kib"].as_u64().unwrap() > 0);
    }
    let again = json(&["build-part", j, "--index", "0"]);
    assert_eq!(again["outcome"], "skipped");
    let status = json(&["job", "status", j, "--verify"]);
    assert_eq!(status["done"], n);
    assert_eq!(status["rerun"], Value::Array(vec![]));

    let merged = dir.path().join("merged.tmesh");
    let m = json(&["merge", j, "-o", merged.to_str().unwrap()]);
    assert_eq!(m["parts"], n);

    // The single-process out-of-core build, one worker at a time, under
    // the limit on its process tree that leaves that worker the job's
    // per-part limit (beside what the builder sets aside for itself and
    // its quarter of the part): the same plan, the same file.
    let builder = p["builder_bytes"].as_u64().unwrap();
    let local_limit = (builder + per_part + per_part / 4).to_string();
    let local = dir.path().join("local.tmesh");
    let b = json(&[
        "build",
        "torus-knot",
        "-o",
        local.to_str().unwrap(),
        "--memory-limit",
        &local_limit,
        "--threads",
        "1",
    ]);
    assert_eq!(b["memory"]["parts"], n);
    assert_eq!(
        std::fs::read(&merged).unwrap(),
        std::fs::read(&local).unwrap()
    );
    let r = json(&[
        "render",
        merged.to_str().unwrap(),
        "--method",
        "tet20",
        "--width",
        "48",
        "--height",
        "36",
        "--frames",
        "1",
    ]);
    assert_eq!(r["failures"], 0);
    assert!(r["hits"].as_i64().unwrap() > 0);

    // A part lost: status and merge name it; submit writes an array of it
    // alone, with the memory asked from the plan.
    let last = n - 1;
    std::fs::remove_file(jobdir.join(format!("part-{last}.done.json"))).unwrap();
    let status = json(&["job", "status", j]);
    assert_eq!(status["missing"], 1);
    assert_eq!(status["rerun"], serde_json::json!([last]));
    let out = bench(&["merge", j, "-o", merged.to_str().unwrap()], &[]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(&format!("run again {last} (missing {last})")),
        "{err}"
    );
    // Being built on another node: running, and not to be run again.
    let running = jobdir.join(format!("part-{last}.running.json"));
    let record = serde_json::json!({
        "part": last, "host": "another-node", "pid": 4242, "process_start": null,
        "started_unix_s": 0, "slurm_task": "77_3",
    });
    std::fs::write(&running, record.to_string()).unwrap();
    let status = json(&["job", "status", j]);
    assert_eq!(
        (status["running"].clone(), status["missing"].clone()),
        (1.into(), 0.into())
    );
    assert_eq!(status["rerun"], serde_json::json!([]));
    let reason = status["parts"][last]["reason"]
        .as_str()
        .unwrap()
        .to_string();
    assert!(
        reason.starts_with("on another-node (pid 4242, Slurm task 77_3)"),
        "{reason}"
    );
    std::fs::remove_file(&running).unwrap();
    // TetGen stuck on it: to be planned again, not merely run again; an
    // error on another input is an earlier plan's and does not count.
    let digest = plan_digest(&jobdir, last);
    let error = jobdir.join(format!("part-{last}.error.json"));
    let record = |input_digest: &str| {
        serde_json::json!({
            "part": last, "kind": "build", "message": "part stuck", "input_digest": input_digest,
            "host": "another-node", "retry": true,
        })
        .to_string()
    };
    std::fs::write(&error, record(&digest)).unwrap();
    let status = json(&["job", "status", j]);
    assert_eq!(status["failed"], 1);
    assert_eq!(status["replan"], serde_json::json!([last]));
    let text = String::from_utf8_lossy(&bench(&["job", "status", j], &[]).stdout).to_string();
    assert!(
        text.contains(&format!("plan again (build SCENE --plan {j})")),
        "{text}"
    );
    std::fs::write(&error, record("xxh64:0000000000000000")).unwrap();
    let status = json(&["job", "status", j]);
    assert_eq!(
        (status["failed"].clone(), status["missing"].clone()),
        (0.into(), 1.into())
    );
    assert_eq!(status["replan"], serde_json::json!([]));
    std::fs::remove_file(&error).unwrap();

    let s = json(&[
        "submit",
        j,
        "--engine",
        "slurm",
        "--dry-run",
        "--partition",
        "debug",
    ]);
    assert_eq!(s["parts"], serde_json::json!([last]));
    assert_eq!(s["parts_job"], Value::Null);
    let job: Value = serde_json::from_str(&read(&jobdir.join("job.json"))).unwrap();
    let max_predicted = job["parts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["predicted_peak_bytes"].as_u64().unwrap())
        .max()
        .unwrap();
    // Auto: 1.5 × the largest predicted TetGen peak + 64 MiB.
    let mib = (max_predicted + max_predicted / 2 + (64 << 20)).div_ceil(1 << 20);
    assert_eq!(s["mem_mib"], mib);
    let parts = read(Path::new(s["parts_script"].as_str().unwrap()));
    assert!(
        parts.contains(&format!("#SBATCH --array={last}\n")),
        "{parts}"
    );
    assert!(
        parts.contains(&format!("#SBATCH --mem={mib}M\n")),
        "{parts}"
    );
    assert!(parts.contains("#SBATCH --partition=debug\n"), "{parts}");
    assert!(parts.contains("build-part"), "{parts}");
    let merge = read(Path::new(s["merge_script"].as_str().unwrap()));
    assert!(
        merge.contains(" merge ") && merge.contains("mesh.tmesh"),
        "{merge}"
    );
    let submit = read(Path::new(s["submit_script"].as_str().unwrap()));
    assert!(submit.contains("--dependency=afterok:$parts"), "{submit}");
    // With every part missing, the array covers 0..n.
    for k in 0..n {
        std::fs::remove_file(jobdir.join(format!("part-{k}.done.json"))).ok();
    }
    let s = json(&[
        "submit",
        j,
        "--engine",
        "slurm",
        "--dry-run",
        "--mem-per-part",
        "3G",
    ]);
    let parts = read(Path::new(s["parts_script"].as_str().unwrap()));
    assert!(
        parts.contains(&format!("#SBATCH --array=0-{}\n", n - 1)),
        "{parts}"
    );
    assert!(parts.contains("#SBATCH --mem=3072M\n"), "{parts}");
}

#[test]
fn a_broken_job_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let j = dir.path().to_str().unwrap();
    let out = bench(&["job", "status", j], &[]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("job.json"));
    std::fs::write(
        dir.path().join("job.json"),
        "{\"schema\": \"tet-job\", \"version\": 9}",
    )
    .unwrap();
    let out = bench(&["build-part", j, "--index", "0"], &[]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("version 9, this reader knows version 1"),
        "{err}"
    );
}
