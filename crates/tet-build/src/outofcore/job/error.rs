//! [`JobError`]: what can go wrong with a job directory, each naming the
//! file or part at fault; [`InputFault`]: why a part's input file is
//! refused.

use std::path::PathBuf;

use thiserror::Error;

use crate::outofcore::error::{SeamError, StreamError};

/// Why a part's input file is refused ([`JobError::PartInput`]).
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum InputFault {
    /// Shorter than a header and checksum.
    #[error("{len} bytes is shorter than the {min}-byte header and checksum")]
    Short {
        /// The file's length.
        len: u64,
        /// Header plus checksum.
        min: u64,
    },
    /// Not a part input file.
    #[error("wrong magic {found:?} (expected {expected:?})")]
    Magic {
        /// The first 8 bytes.
        found: [u8; 8],
        /// The magic of a part input file.
        expected: [u8; 8],
    },
    /// Written by another version of the format.
    #[error("version {found}, this reader knows version {expected}")]
    Version {
        /// The file's version.
        found: u32,
        /// The version this reader knows.
        expected: u32,
    },
    /// The header's flags word has a bit this reader does not know.
    #[error("header flags are {0:#x}; this reader knows bit 0 alone")]
    Flags(u32),
    /// The counts in the header do not add up to the file's length.
    #[error("{facets} facets and {box_faces} box faces need {expected} bytes, the file has {len}")]
    Length {
        /// Facets in the header.
        facets: u64,
        /// Box faces in the header.
        box_faces: u64,
        /// The length they imply.
        expected: u64,
        /// The file's length.
        len: u64,
    },
    /// The content does not match its checksum (a flipped or half-written byte).
    #[error("checksum {found:016x} does not match the content's {computed:016x}")]
    Checksum {
        /// The stored checksum.
        found: u64,
        /// XXH64 of the content.
        computed: u64,
    },
    /// A facet names a scene triangle the scene does not have.
    #[error("facet {facet} names scene triangle {triangle} of {count}")]
    Triangle {
        /// The facet.
        facet: u64,
        /// The triangle id.
        triangle: u32,
        /// The scene's triangles.
        count: u32,
    },
    /// A coordinate is NaN or infinite.
    #[error("{what} {index} has a non-finite coordinate")]
    NonFinite {
        /// `facet` or `box face`.
        what: &'static str,
        /// Its index.
        index: u64,
    },
    /// The file is another part's.
    #[error("the file is part {found}'s")]
    Part {
        /// The part index in the file.
        found: u32,
    },
}

/// What went wrong with a job.
#[derive(Debug, Error)]
pub enum JobError {
    /// A file of the job could not be read or written.
    #[error("{path}: {source}", path = .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// `job.json` is not a job description this reader can use.
    #[error("{path}: {detail}", path = .path.display())]
    Manifest {
        /// The file.
        path: PathBuf,
        /// What is wrong, naming the field.
        detail: String,
    },
    /// A part's input file is corrupt, truncated or another part's.
    #[error("part {part}: input {path}: {fault}", path = .path.display())]
    PartInput {
        /// The part.
        part: usize,
        /// The file.
        path: PathBuf,
        /// What is wrong.
        fault: InputFault,
    },
    /// A part's input file is intact but not the one the plan names.
    #[error("part {part}: input {path} has digest {found}, the plan says {planned}: plan again", path = .path.display())]
    StaleInput {
        /// The part.
        part: usize,
        /// The file.
        path: PathBuf,
        /// Its digest.
        found: String,
        /// The plan's digest.
        planned: String,
    },
    /// The part index is not in the plan.
    #[error("part {part} is not in the plan ({parts} parts: 0..{parts})")]
    NoSuchPart {
        /// The index asked for.
        part: usize,
        /// Parts in the plan.
        parts: usize,
    },
    /// No part index was given and none is in the environment.
    #[error(
        "no part index: give --index K, or run as a Slurm array task (SLURM_ARRAY_TASK_ID) or a Kubernetes Indexed Job (JOB_COMPLETION_INDEX)"
    )]
    NoIndex,
    /// An index variable is set but is not a number.
    #[error("{variable}={value:?} is not a part index")]
    BadIndex {
        /// The environment variable.
        variable: &'static str,
        /// Its value.
        value: String,
    },
    /// Planning (clipping, seams) failed.
    #[error("planning: {0}")]
    Plan(SeamError),
    /// No split keeps every part's prediction under the limit.
    #[error("no split keeps every part's predicted TetGen peak under {limit_bytes} bytes")]
    LimitTooSmall {
        /// The per-part limit, bytes.
        limit_bytes: u64,
    },
    /// A part's TetGen run or assembly failed.
    #[error("part {part}: {source}")]
    Build {
        /// The part.
        part: usize,
        /// What failed.
        source: SeamError,
    },
    /// Parts are not finished (or not this plan's): the merge cannot run.
    #[error("{}", not_ready(.missing, .failed, .stale, .running))]
    PartsNotReady {
        /// Parts with no result.
        missing: Vec<usize>,
        /// Parts whose last run failed (a `part-K.error.json`).
        failed: Vec<usize>,
        /// Parts whose result is not this plan's or is damaged.
        stale: Vec<usize>,
        /// Parts being built now (wait for them rather than run them again).
        running: Vec<usize>,
    },
    /// The streamed merge failed.
    #[error("merge: {0}")]
    Merge(StreamError),
}

impl JobError {
    /// The kind of error as written in `part-K.error.json`.
    pub fn kind(&self) -> &'static str {
        match self {
            JobError::Io { .. } => "io",
            JobError::Manifest { .. } => "manifest",
            JobError::PartInput { .. } => "input",
            JobError::StaleInput { .. } => "stale-input",
            JobError::NoSuchPart { .. } | JobError::NoIndex | JobError::BadIndex { .. } => "index",
            JobError::Plan(_) | JobError::LimitTooSmall { .. } => "plan",
            JobError::Build { .. } => "build",
            JobError::PartsNotReady { .. } => "not-ready",
            JobError::Merge(_) => "merge",
        }
    }

    /// Moving the part's walls may cure this failure of a part's build
    /// ([`SeamError::part_to_retry`]): the job is to be planned again
    /// rather than the part run again on the same input.
    pub fn walls_may_cure(&self) -> bool {
        matches!(self, JobError::Build { source, .. } if source.part_to_retry().is_some())
    }

    /// Every part to run again before the merge can succeed (sorted).
    pub fn rerun(&self) -> Vec<usize> {
        match self {
            JobError::PartsNotReady {
                missing,
                failed,
                stale,
                ..
            } => {
                let mut all: Vec<usize> =
                    missing.iter().chain(failed).chain(stale).copied().collect();
                all.sort_unstable();
                all
            }
            _ => Vec::new(),
        }
    }
}

/// `parts not finished: run again 1, 4 (missing 1; failed 4); running 2`.
fn not_ready(missing: &[usize], failed: &[usize], stale: &[usize], running: &[usize]) -> String {
    let list = |v: &[usize]| {
        v.iter()
            .map(|k| k.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut all: Vec<usize> = missing.iter().chain(failed).chain(stale).copied().collect();
    all.sort_unstable();
    let mut why = Vec::new();
    for (name, v) in [("missing", missing), ("failed", failed), ("stale", stale)] {
        if !v.is_empty() {
            why.push(format!("{name} {}", list(v)));
        }
    }
    let mut text = String::from("parts not finished");
    if !all.is_empty() {
        text += &format!(": run again {} ({})", list(&all), why.join("; "));
    }
    if !running.is_empty() {
        text += &format!("; running {}", list(running));
    }
    text
}

impl JobError {
    /// An [`JobError::Io`] on `path`.
    pub(crate) fn io(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> JobError {
        let path = path.into();
        move |source| JobError::Io { path, source }
    }
}
