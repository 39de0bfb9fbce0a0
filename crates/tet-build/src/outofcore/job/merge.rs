//! The job's merge ([`merge_job`]): every part checked against the plan
//! (its record's input digest, its result's digest), then the streamed
//! merge of the single-process builder
//! ([`crate::outofcore::stream::merge_part_files`]).

use std::path::{Path, PathBuf};

use super::error::JobError;
use super::manifest::JobManifest;
use super::status::{job_status, require_all_done};
use crate::outofcore::stream::{StreamSummary, merge_part_files};

/// Merges the finished parts of the job in `dir` into the mesh file
/// `output` (replaced atomically). Any part missing, failed or stale
/// (not this plan's, or a result whose bytes are not the recorded ones)
/// is a [`JobError::PartsNotReady`] listing the parts to run again, and
/// nothing is written.
pub fn merge_job(dir: &Path, job: &JobManifest, output: &Path) -> Result<StreamSummary, JobError> {
    let states = job_status(dir, job, true)?;
    require_all_done(&states)?;
    let files: Vec<PathBuf> = job
        .merge
        .order
        .iter()
        .map(|&k| job.part_paths(dir, k).result)
        .collect();
    let seams: Vec<_> = job.merge.seams.iter().map(|s| s.seam()).collect();
    merge_part_files(&files, &seams, output, &job.merge.scene_info()).map_err(JobError::Merge)
}
