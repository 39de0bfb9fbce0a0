//! `job status JOB_DIR`: each part done, failed, stale, running or
//! missing, with predicted and measured peak memory, from the job
//! directory alone.

use anyhow::Result;
use serde::Serialize;
use tet_build::outofcore::job::{JobManifest, PartState, RunningRecord, job_status};

use crate::cli::{JobArgs, JobCommand};
use crate::output::{outln, print_json};

/// One part in the `job status` document.
#[derive(Debug, Serialize)]
pub struct PartStatusDoc {
    /// The part.
    pub index: usize,
    /// `done`, `failed`, `stale`, `running` or `missing`.
    pub state: &'static str,
    /// Why (failed: the error kind and message; stale: what differs;
    /// running: where, since when).
    pub reason: Option<String>,
    /// The plan's prediction of the TetGen peak, bytes.
    pub predicted_peak_bytes: u64,
    /// Measured TetGen worker peak, KiB (done parts).
    pub tetgen_peak_kib: Option<u64>,
    /// Measured peak of the process that ran the part, KiB (done parts).
    pub process_peak_kib: Option<u64>,
    /// Seconds the part took (done parts).
    pub seconds: Option<f64>,
}

/// The `job status` document.
#[derive(Debug, Serialize)]
pub struct StatusDoc {
    /// The job directory.
    pub job_dir: String,
    /// Scene name.
    pub scene: String,
    /// Parts.
    pub parts: Vec<PartStatusDoc>,
    /// Parts done.
    pub done: usize,
    /// Parts whose last run failed.
    pub failed: usize,
    /// Parts with a result that is not this plan's or is damaged.
    pub stale: usize,
    /// Parts being built now.
    pub running: usize,
    /// Parts not built (and not being built).
    pub missing: usize,
    /// Every part not done and not running: what to run again.
    pub rerun: Vec<usize>,
    /// The failed parts whose failure moving their walls may cure
    /// (TetGen failed, crashed or ran past the part's time limit): run
    /// `build SCENE --plan JOB_DIR` again, which moves their walls, then
    /// the parts not done.
    pub replan: Vec<usize>,
}

/// `tet-bench job …`.
pub fn job(args: &JobArgs, json: bool) -> Result<()> {
    let JobCommand::Status(a) = &args.command;
    let job = JobManifest::load(&a.job_dir)?;
    let states = job_status(&a.job_dir, &job, a.verify)?;
    let parts: Vec<PartStatusDoc> = states
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let done = match s {
                PartState::Done(r) => Some(r),
                _ => None,
            };
            PartStatusDoc {
                index: k,
                state: s.name(),
                reason: match s {
                    PartState::Failed(e) => Some(format!("{}: {}", e.kind, e.message)),
                    PartState::Stale(why) => Some(why.clone()),
                    PartState::Running(r) => Some(running_since(r)),
                    _ => None,
                },
                predicted_peak_bytes: job.parts[k].predicted_peak_bytes,
                tetgen_peak_kib: done.and_then(|r| r.tetgen_peak_kib),
                process_peak_kib: done.and_then(|r| r.process_peak_kib),
                seconds: done.map(|r| r.seconds),
            }
        })
        .collect();
    let count = |name: &str| parts.iter().filter(|p| p.state == name).count();
    let doc = StatusDoc {
        job_dir: a.job_dir.display().to_string(),
        scene: job.scene.name.clone(),
        done: count("done"),
        failed: count("failed"),
        stale: count("stale"),
        running: count("running"),
        missing: count("missing"),
        rerun: parts
            .iter()
            .filter(|p| p.state != "done" && p.state != "running")
            .map(|p| p.index)
            .collect(),
        replan: states
            .iter()
            .enumerate()
            .filter(|(_, s)| matches!(s, PartState::Failed(e) if e.retry))
            .map(|(k, _)| k)
            .collect(),
        parts,
    };
    if json {
        return print_json(&doc);
    }
    print_status(&doc)
}

/// Where and since when a part is being built: `on HOST (pid P, Slurm
/// task T) for 42 s`.
fn running_since(r: &RunningRecord) -> String {
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let task = r
        .slurm_task
        .as_ref()
        .map_or(String::new(), |t| format!(", Slurm task {t}"));
    format!(
        "on {} (pid {}{task}) for {} s",
        r.host,
        r.pid,
        now.saturating_sub(r.started_unix_s)
    )
}

/// The text form of the status.
fn print_status(doc: &StatusDoc) -> Result<()> {
    let mib = |b: u64| b as f64 / (1024.0 * 1024.0);
    let kib = |k: Option<u64>| k.map_or("-".into(), |k| format!("{:.1}", k as f64 / 1024.0));
    outln!(
        "{} ({}): {} parts: {} done, {} failed, {} stale, {} running, {} missing",
        doc.job_dir,
        doc.scene,
        doc.parts.len(),
        doc.done,
        doc.failed,
        doc.stale,
        doc.running,
        doc.missing
    )?;
    outln!("  part  state    predicted MiB  TetGen MiB  process MiB  seconds")?;
    for p in &doc.parts {
        outln!(
            "  {:>4}  {:<7}  {:>13.1}  {:>10}  {:>11}  {:>7}{}",
            p.index,
            p.state,
            mib(p.predicted_peak_bytes),
            kib(p.tetgen_peak_kib),
            kib(p.process_peak_kib),
            p.seconds.map_or("-".into(), |s| format!("{s:.2}")),
            p.reason
                .as_ref()
                .map_or(String::new(), |r| format!("  ({r})"))
        )?;
    }
    if !doc.replan.is_empty() {
        outln!(
            "  plan again (build SCENE --plan {}): walls to move around {}",
            doc.job_dir,
            super::slurm::array_ranges(&doc.replan)
        )?;
    }
    if !doc.rerun.is_empty() {
        outln!("  to run: {}", super::slurm::array_ranges(&doc.rerun))?;
    }
    Ok(())
}
