//! Building one part of a job ([`build_part`]): idempotent, atomic, and
//! leaving a record of what is happening (`part-K.running.json`) and of
//! what happened (`part-K.done.json` or `part-K.error.json`).

use std::path::Path;
use std::time::Instant;

use tet_core::TetMesh;

use super::digest::{digest, digest_file, format_digest};
use super::error::JobError;
use super::manifest::JobManifest;
use super::part_input::decode;
use super::records::{
    DoneRecord, ErrorRecord, RunningRecord, host_name, read_json, write_atomic, write_json,
};
use crate::outofcore::error::{SeamError, StreamError};
use crate::outofcore::parts::{SeamOptions, run_part, timed_for_part};
use crate::tetgen::{Isolation, TetgenOptions};

/// The environment variables that carry a part index, in the order read:
/// a Slurm array task's, then a Kubernetes Indexed Job's.
pub const INDEX_VARIABLES: [&str; 2] = ["SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX"];

/// The part to build: `explicit` when given, else the first of
/// [`INDEX_VARIABLES`] that `env` has.
pub fn part_index(
    explicit: Option<usize>,
    env: impl Fn(&str) -> Option<String>,
) -> Result<usize, JobError> {
    if let Some(k) = explicit {
        return Ok(k);
    }
    for variable in INDEX_VARIABLES {
        if let Some(value) = env(variable) {
            return value
                .trim()
                .parse()
                .map_err(|_| JobError::BadIndex { variable, value });
        }
    }
    Err(JobError::NoIndex)
}

/// What [`build_part`] did.
#[derive(Clone, Debug, PartialEq)]
pub enum PartOutcome {
    /// The part was built now.
    Built(DoneRecord),
    /// A valid result of this plan was there already.
    Skipped(DoneRecord),
}

impl PartOutcome {
    /// The part's record.
    pub fn record(&self) -> &DoneRecord {
        match self {
            PartOutcome::Built(r) | PartOutcome::Skipped(r) => r,
        }
    }
}

/// Part `k`'s done record when it is this plan's and its result file has
/// the recorded digest (the file is read once); `None` otherwise.
pub fn verified_done(
    dir: &Path,
    job: &JobManifest,
    k: usize,
) -> Result<Option<DoneRecord>, JobError> {
    let paths = job.part_paths(dir, k);
    let Ok(Some(done)) = read_json::<DoneRecord>(&paths.done) else {
        return Ok(None);
    };
    if done.part != k || done.input_digest != job.parts[k].input_digest {
        return Ok(None);
    }
    match digest_file(&paths.result) {
        Ok((d, len)) if d == done.result_digest && len == done.result_bytes => Ok(Some(done)),
        Ok(_) => Ok(None),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(source) => Err(JobError::Io {
            path: paths.result,
            source,
        }),
    }
}

/// Builds part `k` of the job in `dir` (TetGen in `isolation`; a worker
/// reports its own peak). Skips when [`verified_done`] finds this plan's
/// result; otherwise builds, writes the result (a mesh file, the format
/// of the streamed builder's part files) and then `part-K.done.json`,
/// both atomically, and removes an old `part-K.error.json`. On failure
/// writes `part-K.error.json` naming the part and why, and returns the
/// error.
pub fn build_part(
    dir: &Path,
    job: &JobManifest,
    k: usize,
    isolation: &Isolation,
) -> Result<PartOutcome, JobError> {
    if k >= job.parts.len() {
        return Err(JobError::NoSuchPart {
            part: k,
            parts: job.parts.len(),
        });
    }
    if let Some(done) = verified_done(dir, job, k)? {
        return Ok(PartOutcome::Skipped(done));
    }
    let paths = job.part_paths(dir, k);
    remove_if_present(&paths.done)?;
    write_json(&paths.running, &RunningRecord::this_process(k))?;
    let _running = RemoveOnDrop(&paths.running);
    match build(dir, job, k, isolation) {
        Ok(done) => {
            write_json(&paths.done, &done)?;
            remove_if_present(&paths.error)?;
            Ok(PartOutcome::Built(done))
        }
        Err(e) => {
            let record = ErrorRecord {
                part: k,
                kind: e.kind().into(),
                message: e.to_string(),
                input_digest: job.parts[k].input_digest.clone(),
                host: host_name(),
                retry: e.walls_may_cure(),
            };
            // The error itself is what the caller must see; a record that
            // cannot be written is secondary.
            let _ = write_json(&paths.error, &record);
            Err(e)
        }
    }
}

/// Removes the running record when the run ends, however it ends (a
/// panic included; a process killed outright leaves it, see
/// [`RunningRecord::is_dead`]).
struct RemoveOnDrop<'p>(&'p Path);

impl Drop for RemoveOnDrop<'_> {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(self.0);
    }
}

fn remove_if_present(path: &Path) -> Result<(), JobError> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(JobError::Io {
            path: path.to_path_buf(),
            source: e,
        }),
        _ => Ok(()),
    }
}

/// The build itself: input checked, TetGen, the part's mesh assembled,
/// validated, sorted and written.
fn build(
    dir: &Path,
    job: &JobManifest,
    k: usize,
    isolation: &Isolation,
) -> Result<DoneRecord, JobError> {
    let start = Instant::now();
    let record = &job.parts[k];
    let paths = job.part_paths(dir, k);
    let bytes = std::fs::read(&paths.input).map_err(JobError::io(&paths.input))?;
    let fault = |fault| JobError::PartInput {
        part: k,
        path: paths.input.clone(),
        fault,
    };
    let (input, sum) = decode(&bytes).map_err(fault)?;
    drop(bytes);
    if input.part as usize != k {
        return Err(fault(super::error::InputFault::Part { found: input.part }));
    }
    if format_digest(sum) != record.input_digest {
        return Err(JobError::StaleInput {
            part: k,
            path: paths.input.clone(),
            found: format_digest(sum),
            planned: record.input_digest.clone(),
        });
    }
    let options = SeamOptions {
        tetgen: TetgenOptions {
            quality: job.build.quality,
            max_steiner: job.build.max_steiner,
            min_dihedral: job
                .build
                .min_dihedral
                .or(TetgenOptions::default().min_dihedral),
            optimization: job
                .build
                .optimization
                .or(TetgenOptions::default().optimization),
            max_dihedral: job
                .build
                .max_dihedral
                .or(TetgenOptions::default().max_dihedral),
            ..TetgenOptions::default()
        },
        // A stuck part fails after a time scaled to its size, as in a
        // local build, so that planning again can move its walls soon.
        isolation: timed_for_part(isolation, record.points, record.triangles),
        surface_relaxed_parts: if input.surface_relaxed {
            vec![k]
        } else {
            Vec::new()
        },
        ..SeamOptions::default()
    };
    let built = |source: SeamError| JobError::Build { part: k, source };
    let facets = input.facet_kinds();
    let mesh = run_part(k, &facets, &input.box_faces, &options).map_err(built)?;
    drop(facets);
    let tetgen_peak_kib = mesh.stats.peak_kib;
    let mut local = TetMesh::assemble(
        mesh.points,
        mesh.tets,
        &mesh.constrained,
        input.triangle_count,
    )
    .map_err(|e| built(e.into()))?;
    drop(input);
    local.validate().map_err(|e| built(e.into()))?;
    if job.build.sort_parts {
        tet_core::reorder::hilbert_reorder(&mut local)
            .map_err(|source| built(StreamError::Sort { part: k, source }.into()))?;
    }
    let out = tet_core::format::to_bytes(&local);
    let (points, tets, constrained) = (
        local.points.len(),
        local.tets.len(),
        local.constrained.len(),
    );
    drop(local);
    write_atomic(&paths.result, &out)?;
    Ok(DoneRecord {
        part: k,
        input_digest: record.input_digest.clone(),
        result_digest: digest(&out),
        result_bytes: out.len() as u64,
        points,
        tets,
        constrained,
        predicted_peak_bytes: record.predicted_peak_bytes,
        tetgen_peak_kib,
        process_peak_kib: crate::tetgen::worker::peak_memory_kib(),
        seconds: start.elapsed().as_secs_f64(),
        host: host_name(),
    })
}
