//! `submit JOB_DIR --engine slurm`: the scripts of [`super::slurm`]
//! written to `JOB_DIR/slurm/`, then (unless `--dry-run`) submitted with
//! `sbatch`: the array of parts not yet done, and the merge depending on
//! it.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail};
use serde::Serialize;
use tet_build::outofcore::job::{JobManifest, PartState, job_status};

use super::slurm::{SlurmPlan, merge_script, parts_script, submit_script};
use crate::cli::{Engine, SubmitArgs};
use crate::outofcore::options::MemPerPart;
use crate::output::{outln, print_json};

/// Memory a part task asks for with `--mem-per-part auto`, from the plan's
/// largest predicted TetGen peak `predicted` (bytes, with the model's
/// margin): the TetGen worker and `build-part` itself, which receives the
/// worker's output and assembles, sorts and writes the part's mesh. On a
/// 311k-triangle knot grid in 9 parts, TetGen's measured peak was 0.81–0.83
/// of the prediction and `build-part`'s own 0.16–0.20 of TetGen's (both
/// together at most 0.99 of the prediction): half the prediction again
/// plus 64 MiB for the two processes' code covers that with room.
pub fn auto_mem_bytes(predicted: u64) -> u64 {
    predicted + predicted / 2 + (64 << 20)
}

/// The `submit` document.
#[derive(Debug, Serialize)]
pub struct SubmitDoc {
    /// The job directory.
    pub job_dir: String,
    /// `slurm`.
    pub engine: &'static str,
    /// The array script.
    pub parts_script: String,
    /// The merge script.
    pub merge_script: String,
    /// `submit.sh` (the `sbatch` calls).
    pub submit_script: String,
    /// Parts in the array (not yet done).
    pub parts: Vec<usize>,
    /// Memory per part task, MiB.
    pub mem_mib: u64,
    /// The merged mesh file.
    pub output: String,
    /// The array's Slurm job id (`null` with `--dry-run` or nothing to build).
    pub parts_job: Option<String>,
    /// The merge's Slurm job id (`null` with `--dry-run`).
    pub merge_job: Option<String>,
}

/// `p` made absolute (the scripts run in another directory).
fn absolute(p: &Path) -> Result<PathBuf> {
    std::path::absolute(p).with_context(|| format!("cannot make {} absolute", p.display()))
}

/// Runs `sbatch --parsable ARGS`; the job id.
fn sbatch(args: &[&str]) -> Result<String> {
    let out = Command::new("sbatch")
        .arg("--parsable")
        .args(args)
        .output()
        .context("cannot run sbatch (is Slurm installed and SLURM_CONF set?)")?;
    if !out.status.success() {
        bail!(
            "sbatch {} failed: {}",
            args.join(" "),
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let id = text.trim().split(';').next().unwrap_or("").to_string();
    if id.is_empty() || !id.chars().all(|c| c.is_ascii_digit()) {
        bail!("sbatch printed no job id: {text:?}");
    }
    Ok(id)
}

/// `tet-bench submit JOB_DIR --engine slurm`.
pub fn submit(args: &SubmitArgs, json: bool) -> Result<()> {
    let Engine::Slurm = args.engine;
    let dir = absolute(&args.job_dir)?;
    let job = JobManifest::load(&dir)?;
    let states = job_status(&dir, &job, false)?;
    let parts: Vec<usize> = states
        .iter()
        .enumerate()
        .filter(|(_, s)| !matches!(s, PartState::Done(_)))
        .map(|(k, _)| k)
        .collect();
    let mem_bytes = match args.mem_per_part {
        MemPerPart::Auto => auto_mem_bytes(job.max_predicted_bytes()),
        MemPerPart::Bytes(b) => b,
    };
    let mib = |b: u64| b.div_ceil(1 << 20).max(1);
    let output = absolute(
        &args
            .output
            .clone()
            .unwrap_or_else(|| dir.join("mesh.tmesh")),
    )?;
    let program = std::env::current_exe().context("cannot find this executable")?;
    let plan = SlurmPlan {
        program: program.display().to_string(),
        job_dir: dir.display().to_string(),
        output: output.display().to_string(),
        parts: parts.clone(),
        mem_mib: mib(mem_bytes),
        merge_mem_mib: mib(mem_bytes),
        partition: args.partition.clone(),
        name: job.scene.name.clone(),
    };
    let scripts = dir.join("slurm");
    for d in [&scripts, &dir.join("logs")] {
        std::fs::create_dir_all(d).with_context(|| format!("cannot create {}", d.display()))?;
    }
    let (parts_path, merge_path, submit_path) = (
        scripts.join("parts.sbatch"),
        scripts.join("merge.sbatch"),
        scripts.join("submit.sh"),
    );
    let (p, m) = (
        parts_path.display().to_string(),
        merge_path.display().to_string(),
    );
    for (path, text) in [
        (&parts_path, parts_script(&plan)),
        (&merge_path, merge_script(&plan)),
        (&submit_path, submit_script(&plan, &p, &m)),
    ] {
        tet_build::outofcore::job::records::write_atomic(path, text.as_bytes())?;
    }
    let (mut parts_job, mut merge_job) = (None, None);
    if !args.dry_run {
        let mut merge_args = Vec::new();
        let dependency;
        if !parts.is_empty() {
            let id = sbatch(&[&p])?;
            dependency = format!("--dependency=afterok:{id}");
            merge_args.push(dependency.as_str());
            parts_job = Some(id);
        }
        merge_args.push(&m);
        merge_job = Some(sbatch(&merge_args)?);
    }
    let doc = SubmitDoc {
        job_dir: plan.job_dir.clone(),
        engine: "slurm",
        parts_script: p,
        merge_script: m,
        submit_script: submit_path.display().to_string(),
        parts,
        mem_mib: plan.mem_mib,
        output: plan.output.clone(),
        parts_job,
        merge_job,
    };
    if json {
        return print_json(&doc);
    }
    let array = super::slurm::array_ranges(&doc.parts);
    match (&doc.parts_job, &doc.merge_job) {
        (_, None) => outln!(
            "wrote {} (array {array}, {} MiB per task) and {}; submit with: sh {}",
            doc.parts_script,
            doc.mem_mib,
            doc.merge_script,
            doc.submit_script
        )?,
        (Some(a), Some(b)) => outln!(
            "submitted parts {array} as Slurm job {a} ({} MiB per task) and the merge as job {b} (after every part) -> {}",
            doc.mem_mib,
            doc.output
        )?,
        (None, Some(b)) => outln!(
            "every part is done: submitted the merge as Slurm job {b} -> {}",
            doc.output
        )?,
    }
    Ok(())
}
