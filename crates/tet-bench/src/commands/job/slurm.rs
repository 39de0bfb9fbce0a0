//! The Slurm scripts of `submit --engine slurm`: one `sbatch` script for
//! a job array with one task per part to build (`--array`), each task
//! running `tet-bench build-part JOB_DIR` (the index comes from
//! `SLURM_ARRAY_TASK_ID`), and one for the merge, submitted with
//! `--dependency=afterok:ARRAY_JOB` so that it starts only when every
//! task has succeeded. Slurm schedules, requeues and reports; nothing
//! here does. Plain text in, plain text out: the scripts are a pure
//! function of [`SlurmPlan`].

use std::fmt::Write;

/// What the scripts say.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SlurmPlan {
    /// The `tet-bench` executable (absolute).
    pub program: String,
    /// The job directory (absolute).
    pub job_dir: String,
    /// The merged mesh file (absolute).
    pub output: String,
    /// The parts to build (the array's indices).
    pub parts: Vec<usize>,
    /// Memory requested per part task, MiB.
    pub mem_mib: u64,
    /// Memory requested by the merge, MiB.
    pub merge_mem_mib: u64,
    /// Partition, if given.
    pub partition: Option<String>,
    /// Scene name (for job names).
    pub name: String,
}

/// `0-3,5,7-9`: sorted indices as Slurm's `--array` ranges.
pub fn array_ranges(indices: &[usize]) -> String {
    let mut out = Vec::new();
    let mut i = 0;
    while i < indices.len() {
        let start = indices[i];
        let mut end = start;
        while i + 1 < indices.len() && indices[i + 1] == end + 1 {
            i += 1;
            end += 1;
        }
        out.push(if start == end {
            start.to_string()
        } else {
            format!("{start}-{end}")
        });
        i += 1;
    }
    out.join(",")
}

/// `text` quoted for a POSIX shell.
pub fn shell_quote(text: &str) -> String {
    format!("'{}'", text.replace('\'', r"'\''"))
}

/// A job name Slurm shows: letters, digits, `-`, `_`, `.` of the scene's.
fn job_name(kind: &str, scene: &str) -> String {
    let clean: String = scene
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "-_.".contains(c) {
                c
            } else {
                '-'
            }
        })
        .take(40)
        .collect();
    format!("tet-{kind}-{clean}")
}

/// The `#SBATCH` lines both scripts share.
fn header(out: &mut String, plan: &SlurmPlan, kind: &str, mem_mib: u64, log: &str) {
    let _ = writeln!(out, "#!/bin/bash");
    let _ = writeln!(out, "#SBATCH --job-name={}", job_name(kind, &plan.name));
    let _ = writeln!(out, "#SBATCH --ntasks=1");
    let _ = writeln!(out, "#SBATCH --cpus-per-task=1");
    let _ = writeln!(out, "#SBATCH --mem={mem_mib}M");
    let _ = writeln!(out, "#SBATCH --output={}/logs/{log}", plan.job_dir);
    if let Some(p) = &plan.partition {
        let _ = writeln!(out, "#SBATCH --partition={p}");
    }
}

/// The array script: one task per part in `plan.parts`.
pub fn parts_script(plan: &SlurmPlan) -> String {
    let mut s = String::new();
    header(&mut s, plan, "parts", plan.mem_mib, "part-%a.log");
    let _ = writeln!(s, "#SBATCH --array={}", array_ranges(&plan.parts));
    let _ = writeln!(
        s,
        "# Part K = SLURM_ARRAY_TASK_ID; a finished part is skipped, so a rerun is safe."
    );
    let _ = writeln!(
        s,
        "exec {} build-part {}",
        shell_quote(&plan.program),
        shell_quote(&plan.job_dir)
    );
    s
}

/// The merge script (submitted with `--dependency=afterok:ARRAY_JOB`;
/// cancelled by Slurm when a part fails).
pub fn merge_script(plan: &SlurmPlan) -> String {
    let mut s = String::new();
    header(&mut s, plan, "merge", plan.merge_mem_mib, "merge.log");
    let _ = writeln!(s, "#SBATCH --kill-on-invalid-dep=yes");
    let _ = writeln!(
        s,
        "exec {} merge {} -o {}",
        shell_quote(&plan.program),
        shell_quote(&plan.job_dir),
        shell_quote(&plan.output)
    );
    s
}

/// `submit.sh`: the two `sbatch` calls, for submitting by hand what
/// `--dry-run` wrote.
pub fn submit_script(plan: &SlurmPlan, parts: &str, merge: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "#!/bin/sh");
    let _ = writeln!(s, "# Written by tet-bench submit --engine slurm.");
    let _ = writeln!(s, "set -e");
    if plan.parts.is_empty() {
        let _ = writeln!(s, "sbatch --parsable {}", shell_quote(merge));
    } else {
        let _ = writeln!(s, "parts=$(sbatch --parsable {})", shell_quote(parts));
        let _ = writeln!(s, "parts=${{parts%%;*}}");
        let _ = writeln!(
            s,
            "merge=$(sbatch --parsable --dependency=afterok:$parts {})",
            shell_quote(merge)
        );
        let _ = writeln!(s, "echo \"parts: $parts  merge: $merge\"");
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indices_become_slurm_ranges() {
        assert_eq!(array_ranges(&[0, 1, 2, 3]), "0-3");
        assert_eq!(array_ranges(&[0, 2, 3, 4, 7, 9, 10]), "0,2-4,7,9-10");
        assert_eq!(array_ranges(&[5]), "5");
        assert_eq!(array_ranges(&[]), "");
    }

    #[test]
    fn quoting_survives_quotes_and_spaces() {
        assert_eq!(shell_quote("/a b/it's"), r"'/a b/it'\''s'");
    }
}
