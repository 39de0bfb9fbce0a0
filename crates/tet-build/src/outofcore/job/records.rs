//! What a part's run leaves beside its result: `part-K.running.json`
//! ([`RunningRecord`]) while it runs, `part-K.done.json` ([`DoneRecord`])
//! after a success, `part-K.error.json` ([`ErrorRecord`]) after a failure.
//! All are written atomically (temporary file, rename).

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::error::JobError;

/// `part-K.done.json`: a finished part.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DoneRecord {
    /// The part.
    pub part: usize,
    /// Digest of the input it was built from (the plan's, when current).
    pub input_digest: String,
    /// Digest of the result file.
    pub result_digest: String,
    /// Bytes of the result file.
    pub result_bytes: u64,
    /// Points of the part's mesh.
    pub points: usize,
    /// Tets.
    pub tets: usize,
    /// Constrained faces.
    pub constrained: usize,
    /// The plan's prediction of the TetGen peak, bytes.
    pub predicted_peak_bytes: u64,
    /// Measured peak resident memory (`VmHWM`) of the TetGen worker, KiB
    /// (`null` when TetGen ran in process).
    pub tetgen_peak_kib: Option<u64>,
    /// Measured peak resident memory (`VmHWM`) of the process that ran
    /// the part (reading the input, assembling, sorting and writing the
    /// result), KiB; `null` without `/proc`.
    pub process_peak_kib: Option<u64>,
    /// Seconds the part took.
    pub seconds: f64,
    /// Host that built it.
    pub host: String,
}

/// `part-K.error.json`: why the last run of a part failed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ErrorRecord {
    /// The part.
    pub part: usize,
    /// The kind of failure ([`JobError::kind`]): `input`, `stale-input`,
    /// `build`, `io`, …
    pub kind: String,
    /// The error, in words.
    pub message: String,
    /// The plan's digest of the part's input.
    pub input_digest: String,
    /// Host that ran it.
    pub host: String,
    /// Moving the part's walls may cure the failure (TetGen failed,
    /// crashed or ran past the part's time limit on this input): planning
    /// the job again into its directory moves them ([`super::plan_job`]);
    /// building the part again would meet the same input. Absent (false)
    /// in records written before it existed.
    #[serde(default)]
    pub retry: bool,
}

/// `part-K.running.json`: a run of a part in progress, written when it
/// starts and removed when it ends (whatever the outcome). A process
/// killed outright leaves it behind: [`RunningRecord::is_dead`] tells on
/// the host that ran it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunningRecord {
    /// The part.
    pub part: usize,
    /// Host running it.
    pub host: String,
    /// Its process id there.
    pub pid: u32,
    /// When that process started, in clock ticks since boot (field 22 of
    /// `/proc/PID/stat`), so that a reused pid is not taken for it;
    /// `null` without `/proc`.
    pub process_start: Option<u64>,
    /// When the run started, seconds since the Unix epoch.
    pub started_unix_s: u64,
    /// The Slurm job and array task running it (`JOB_ARRAYTASK`), if any.
    pub slurm_task: Option<String>,
}

impl RunningRecord {
    /// The record of this process running part `k` now.
    pub fn this_process(part: usize) -> RunningRecord {
        let pid = std::process::id();
        let env = |v: &str| std::env::var(v).ok().filter(|s| !s.is_empty());
        RunningRecord {
            part,
            host: host_name(),
            pid,
            process_start: process_start(pid),
            started_unix_s: std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_secs()),
            slurm_task: env("SLURM_ARRAY_JOB_ID")
                .zip(env("SLURM_ARRAY_TASK_ID"))
                .map(|(j, t)| format!("{j}_{t}")),
        }
    }

    /// True when the run is known to have ended without removing its
    /// record: it ran on this host and its process is gone (or the pid
    /// now belongs to another process). A run on another host is never
    /// known dead here.
    pub fn is_dead(&self) -> bool {
        if self.host != host_name() || !Path::new("/proc/self/stat").exists() {
            return false;
        }
        match process_start(self.pid) {
            None => true,
            Some(start) => self.process_start.is_some_and(|s| s != start),
        }
    }
}

/// Start time of process `pid` in clock ticks since boot (`/proc/PID/stat`
/// field 22), `None` when there is no such process (or no `/proc`).
fn process_start(pid: u32) -> Option<u64> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // The command name (field 2) may hold spaces: count after its `)`.
    stat.rsplit_once(')')?
        .1
        .split_whitespace()
        .nth(19)?
        .parse()
        .ok()
}

/// This machine's name (for the records), `unknown` when unreadable.
pub fn host_name() -> String {
    std::env::var("HOSTNAME")
        .ok()
        .filter(|h| !h.is_empty())
        .or_else(|| {
            std::fs::read_to_string("/proc/sys/kernel/hostname")
                .ok()
                .map(|h| h.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into())
}

/// Writes `value` as pretty JSON to `path` atomically.
pub fn write_json<T: Serialize>(path: &Path, value: &T) -> Result<(), JobError> {
    let text = serde_json::to_string_pretty(value).expect("a record serializes") + "\n";
    write_atomic(path, text.as_bytes())
}

/// Writes `bytes` to `path` atomically (the codebase's temporary file and
/// rename: [`crate::tetgen_files`]).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), JobError> {
    crate::tetgen_files::atomic_write(path, bytes).map_err(|e| match e {
        crate::tetgen_files::FilesError::Io { path, source } => JobError::Io { path, source },
        other => JobError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::other(other.to_string()),
        },
    })
}

/// Reads a record; `Ok(None)` when the file does not exist, an error
/// naming the file when it is not a record.
pub fn read_json<T: for<'de> Deserialize<'de>>(path: &Path) -> Result<Option<T>, JobError> {
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(source) => {
            return Err(JobError::Io {
                path: path.to_path_buf(),
                source,
            });
        }
    };
    serde_json::from_str(&text)
        .map(Some)
        .map_err(|e| JobError::Manifest {
            path: path.to_path_buf(),
            detail: e.to_string(),
        })
}
