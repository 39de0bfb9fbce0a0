//! The out-of-core build as a *job* that any engine can run: a plan
//! written to a directory, parts built by independent processes in any
//! order (Slurm array tasks, Kubernetes Indexed Job pods, a shell loop),
//! and a merge. Nothing here schedules or retries: the engine runs the
//! parts, each part's run is idempotent, and the merge names the parts
//! still to run.
//!
//! The parts are exactly those of the single-process builders
//! ([`super::tree::build_tree_to_file`],
//! [`super::seam::build_slabs_to_file`]): the same clipping, seams and
//! PLC per part, the same TetGen run, the same part files and streamed
//! merge ([`super::stream::merge_part_files`]). A job's merged mesh is
//! therefore the single-process streamed build of the same plan.
//!
//! **The job directory.**
//!
//! | file | written by | content |
//! |------|------------|---------|
//! | `job.json` | [`plan_job`] (last) | [`JobManifest`]: schema and version, scene digest, the partition (tree or slabs), one entry per part (input file, its digest, predicted peak memory), the merge plan (seams, order, camera and lights) |
//! | `part-K.input` | [`plan_job`] | part K's facets ([`part_input`]: binary, magic, version, sizes, checksum) |
//! | `part-K.tmesh` | [`build_part`] | part K's mesh (mesh file format), Hilbert-sorted on its own |
//! | `part-K.done.json` | [`build_part`] (after the result) | [`DoneRecord`]: input and result digests, measured peaks (`VmHWM`) |
//! | `part-K.error.json` | [`build_part`] on failure | [`ErrorRecord`]: the part, the kind of error, the message, whether moving its walls may cure it |
//!
//! Every file is written atomically (temporary file, rename): a killed
//! run leaves a previous file or none, never half of one. A part is *done*
//! when its done record names the plan's input digest and its result has
//! the recorded digest; [`build_part`] skips a done part and rebuilds any
//! other, so running a part twice, or after a crash, is safe. A part
//! TetGen fails on, crashes on or is stuck on (each part's run has a time
//! limit scaled to its size) is cured by planning the job again into its
//! directory: [`plan_job`] moves that part's walls ([`replan`]) and keeps
//! every other part's input, and so its result.
//!
//! Modules, bottom up:
//!
//! * [`digest`]: XXH64 content digests.
//! * [`error`]: [`JobError`], [`InputFault`].
//! * [`part_input`]: a part's input file.
//! * [`manifest`]: the job description, `job.json`.
//! * [`records`]: done and error records, atomic writes.
//! * [`plan`]: planning, [`plan_job`].
//! * [`replan`]: planning again over parts that failed.
//! * [`run`]: [`build_part`], the part index from Slurm or Kubernetes.
//! * [`status`]: each part's state from the directory.
//! * [`merge`]: the merge, [`merge_job`].

pub mod digest;
pub mod error;
pub mod manifest;
pub mod merge;
pub mod part_input;
pub mod plan;
pub mod records;
pub mod replan;
pub mod run;
pub mod status;

pub use error::{InputFault, JobError};
pub use manifest::{FailedInput, JOB_FILE, JobManifest, PartPaths};
pub use merge::merge_job;
pub use plan::{PlanOptions, Planner, plan_job, scene_digest};
pub use records::{DoneRecord, ErrorRecord, RunningRecord};
pub use run::{INDEX_VARIABLES, PartOutcome, build_part, part_index, verified_done};
pub use status::{PartState, job_status, part_state, require_all_done};
