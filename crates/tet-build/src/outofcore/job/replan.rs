//! Planning a job again over its failed parts. A part whose build failed
//! in a way moving its walls may cure (TetGen failing, crashing or running
//! past the part's time limit on its input: [`ErrorRecord::retry`]) fails
//! again on the same input, so building it again is no remedy; planning
//! again is. [`plan_job`](super::plan_job) reads the inputs known to fail
//! (`known_failures`: `job.json`'s `failed_inputs` and the error records
//! of its parts) and the planner moves the walls of every part whose new
//! input is one of them (met as the planner writes the inputs), as a local
//! build moves the walls of a part that fails in it
//! (`tree::plan_tree_with_moves`); a part whose walls moved twice is
//! planned with its surface relaxed, which makes it another input.
//!
//! Planning is deterministic and the plan keeps every input known to fail
//! (`failed_inputs`), so planning again reaches the same moved walls and
//! never goes back to an input that failed; parts whose input the moves
//! did not change keep their results (their done records name the same
//! input digest). Only the tree planner moves walls; a slab plan keeps
//! its planes.

use std::path::Path;

use super::error::JobError;
use super::manifest::{FailedInput, JobManifest};
use super::records::{ErrorRecord, read_json};

/// The part inputs known to fail in the job planned in `dir` from the
/// scene of digest `scene_digest`: those its `job.json` keeps and those
/// its parts' error records name as failed on the plan's input with
/// [`ErrorRecord::retry`]. None without a `job.json` or when that job is
/// of another scene; an unreadable error record is passed over (as `job
/// status` does).
pub(super) fn known_failures(dir: &Path, scene_digest: &str) -> Result<Vec<FailedInput>, JobError> {
    let old = match JobManifest::load(dir) {
        Ok(old) => old,
        Err(JobError::Io { source, .. }) if source.kind() == std::io::ErrorKind::NotFound => {
            return Ok(Vec::new());
        }
        Err(e) => return Err(e),
    };
    if old.scene.digest != scene_digest {
        return Ok(Vec::new());
    }
    let mut failed = old.failed_inputs.clone();
    for (k, planned) in old.parts.iter().enumerate() {
        let Ok(Some(e)) = read_json::<ErrorRecord>(&old.part_paths(dir, k).error) else {
            continue;
        };
        if e.retry
            && e.input_digest == planned.input_digest
            && !failed.iter().any(|f| f.input_digest == e.input_digest)
        {
            failed.push(FailedInput {
                input_digest: e.input_digest,
                part: k,
                message: e.message,
            });
        }
    }
    Ok(failed)
}
