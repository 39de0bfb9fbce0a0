//! Where each part of a job stands ([`part_state`], [`job_status`]), from
//! the files in the job directory alone: no scheduler is asked.

use std::path::Path;

use super::digest::digest_file;
use super::error::JobError;
use super::manifest::JobManifest;
use super::records::{DoneRecord, ErrorRecord, RunningRecord, read_json};

/// One part's state.
#[derive(Clone, Debug, PartialEq)]
pub enum PartState {
    /// Finished: a result of this plan, as recorded.
    Done(DoneRecord),
    /// The last run on the plan's input failed (and left no valid result).
    Failed(ErrorRecord),
    /// A result is there but not this plan's, or damaged: why.
    Stale(String),
    /// Being built now (a run's record, not known to have died).
    Running(RunningRecord),
    /// Not built (and not being built).
    Missing,
}

impl PartState {
    /// `done`, `failed`, `stale`, `running` or `missing`.
    pub fn name(&self) -> &'static str {
        match self {
            PartState::Done(_) => "done",
            PartState::Failed(_) => "failed",
            PartState::Stale(_) => "stale",
            PartState::Running(_) => "running",
            PartState::Missing => "missing",
        }
    }
}

/// Part `k`'s state: done when a result of this plan is there, else
/// running while a run's record says so (and, on its own host, its process
/// lives), else failed, stale or missing. With `verify`, a result counts as
/// done only when its bytes have the recorded digest (the file is read);
/// without, when its length is the recorded one.
pub fn part_state(
    dir: &Path,
    job: &JobManifest,
    k: usize,
    verify: bool,
) -> Result<PartState, JobError> {
    let paths = job.part_paths(dir, k);
    let done = read_json::<DoneRecord>(&paths.done);
    let stale = match done {
        Ok(Some(done)) => match check_done(&done, job, k, &paths.result, verify)? {
            None => return Ok(PartState::Done(done)),
            Some(why) => Some(why),
        },
        Ok(None) => None,
        Err(e) => Some(format!("unreadable done record: {e}")),
    };
    // A run in progress is the news, whatever an earlier run left.
    if let Ok(Some(running)) = read_json::<RunningRecord>(&paths.running)
        && !running.is_dead()
    {
        return Ok(PartState::Running(running));
    }
    // An error on another input is an earlier plan's: planning again
    // changed this part's input (see `replan`).
    if let Ok(Some(error)) = read_json::<ErrorRecord>(&paths.error)
        && error.input_digest == job.parts[k].input_digest
    {
        return Ok(PartState::Failed(error));
    }
    Ok(match stale {
        Some(why) => PartState::Stale(why),
        None => PartState::Missing,
    })
}

/// Why a done record does not stand for this plan's result (`None`: it does).
fn check_done(
    done: &DoneRecord,
    job: &JobManifest,
    k: usize,
    result: &Path,
    verify: bool,
) -> Result<Option<String>, JobError> {
    if done.part != k {
        return Ok(Some(format!("the done record is part {}'s", done.part)));
    }
    if done.input_digest != job.parts[k].input_digest {
        return Ok(Some(format!(
            "built from input {}, the plan's is {}",
            done.input_digest, job.parts[k].input_digest
        )));
    }
    let len = match std::fs::metadata(result) {
        Ok(m) => m.len(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Ok(Some("the result file is missing".into()));
        }
        Err(source) => {
            return Err(JobError::Io {
                path: result.to_path_buf(),
                source,
            });
        }
    };
    if len != done.result_bytes {
        return Ok(Some(format!(
            "the result file has {len} bytes, the record says {}",
            done.result_bytes
        )));
    }
    if verify {
        let (d, _) = digest_file(result).map_err(JobError::io(result))?;
        if d != done.result_digest {
            return Ok(Some(format!(
                "the result file's digest is {d}, the record says {}",
                done.result_digest
            )));
        }
    }
    Ok(None)
}

/// Every part's state, in index order (see [`part_state`]).
pub fn job_status(dir: &Path, job: &JobManifest, verify: bool) -> Result<Vec<PartState>, JobError> {
    (0..job.parts.len())
        .map(|k| part_state(dir, job, k, verify))
        .collect()
}

/// [`JobError::PartsNotReady`] listing the parts that are not done, or
/// `Ok` when every part is.
pub fn require_all_done(states: &[PartState]) -> Result<(), JobError> {
    let (mut missing, mut failed, mut stale, mut running) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (k, s) in states.iter().enumerate() {
        match s {
            PartState::Done(_) => {}
            PartState::Failed(_) => failed.push(k),
            PartState::Stale(_) => stale.push(k),
            PartState::Running(_) => running.push(k),
            PartState::Missing => missing.push(k),
        }
    }
    if missing.is_empty() && failed.is_empty() && stale.is_empty() && running.is_empty() {
        Ok(())
    } else {
        Err(JobError::PartsNotReady {
            missing,
            failed,
            stale,
            running,
        })
    }
}
