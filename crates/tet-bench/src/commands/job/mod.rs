//! The job commands: `build SCENE --plan JOB_DIR` ([`plan`]),
//! `build-part` ([`build_part`]), `merge` ([`merge`]), `job status`
//! ([`job`]) and `submit --engine slurm` ([`submit()`]). They are thin:
//! the job itself (plan, idempotent part runs, status, merge) is
//! `tet_build::outofcore::job`; the Slurm scripts are [`slurm`].

#[cfg(feature = "tetgen")]
mod parts;
#[cfg(feature = "tetgen")]
mod planning;
#[cfg(feature = "tetgen")]
pub mod slurm;
#[cfg(feature = "tetgen")]
mod status;
#[cfg(feature = "tetgen")]
mod submit;

#[cfg(feature = "tetgen")]
pub use parts::{build_part, merge};
#[cfg(feature = "tetgen")]
pub use planning::plan;
#[cfg(feature = "tetgen")]
pub use status::job;
#[cfg(feature = "tetgen")]
pub use submit::submit;

/// The job commands of a tet-bench built without TetGen: errors.
#[cfg(not(feature = "tetgen"))]
mod without_tetgen {
    use std::path::Path;

    use anyhow::{Result, bail};

    use crate::cli::{BuildArgs, BuildPartArgs, JobArgs, MergeArgs, SubmitArgs};

    /// The error of every job command without TetGen.
    fn no_tetgen<T>() -> Result<T> {
        bail!("jobs need the `tetgen` feature: this tet-bench was built without it")
    }

    /// Fails: no TetGen.
    pub fn plan(_: &BuildArgs, _: &Path, _: bool) -> Result<()> {
        no_tetgen()
    }
    /// Fails: no TetGen.
    pub fn build_part(_: &BuildPartArgs, _: bool) -> Result<()> {
        no_tetgen()
    }
    /// Fails: no TetGen.
    pub fn merge(_: &MergeArgs, _: bool) -> Result<()> {
        no_tetgen()
    }
    /// Fails: no TetGen.
    pub fn job(_: &JobArgs, _: bool) -> Result<()> {
        no_tetgen()
    }
    /// Fails: no TetGen.
    pub fn submit(_: &SubmitArgs, _: bool) -> Result<()> {
        no_tetgen()
    }
}
#[cfg(not(feature = "tetgen"))]
pub use without_tetgen::{build_part, job, merge, plan, submit};
