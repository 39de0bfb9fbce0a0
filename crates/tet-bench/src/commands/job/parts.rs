//! `build-part` and `merge`: one part of a job, and the finished parts
//! into one mesh file.

use anyhow::{Context, Result, bail};
use serde::Serialize;
use tet_build::outofcore::job::{
    DoneRecord, JobManifest, PartOutcome, build_part as run_part, merge_job, part_index,
};

use crate::cli::{BuildPartArgs, MergeArgs};
use crate::load::MESH_EXTENSION;
use crate::output::{outln, print_json};

/// The `build-part` document.
#[derive(Debug, Serialize)]
pub struct PartDoc {
    /// The part.
    pub part: usize,
    /// `built` or `skipped` (a valid result of this plan was there).
    pub outcome: &'static str,
    /// What the part's run recorded (`part-K.done.json`).
    pub record: DoneRecord,
}

/// `tet-bench build-part JOB_DIR [--index K]`.
pub fn build_part(args: &BuildPartArgs, json: bool) -> Result<()> {
    let dir = &args.job_dir;
    let job = JobManifest::load(dir)?;
    let k = part_index(args.index, |v| std::env::var(v).ok())?;
    let isolation = crate::load::worker_isolation(job.build.time_limit_s)?;
    let outcome = run_part(dir, &job, k, &isolation)
        .with_context(|| format!("part {k} of {} failed", dir.display()))?;
    let doc = PartDoc {
        part: k,
        outcome: match outcome {
            PartOutcome::Built(_) => "built",
            PartOutcome::Skipped(_) => "skipped",
        },
        record: outcome.record().clone(),
    };
    if json {
        return print_json(&doc);
    }
    let r = &doc.record;
    let kib = |k: Option<u64>| k.map_or("n/a".into(), |k| format!("{:.1} MiB", k as f64 / 1024.0));
    outln!(
        "part {k}: {} ({} tets; TetGen peak {} predicted {:.1} MiB; this process {}; {:.2} s)",
        doc.outcome,
        r.tets,
        kib(r.tetgen_peak_kib),
        r.predicted_peak_bytes as f64 / (1024.0 * 1024.0),
        kib(r.process_peak_kib),
        r.seconds
    )?;
    Ok(())
}

/// The `merge` document.
#[derive(Debug, Serialize)]
pub struct MergeDoc {
    /// The mesh file.
    pub output: String,
    /// Parts merged.
    pub parts: usize,
    /// Points.
    pub points: u64,
    /// Tets.
    pub tets: u64,
    /// Constrained faces.
    pub constrained_faces: u64,
    /// Bytes of the mesh file.
    pub file_bytes: u64,
    /// Largest number of bytes the merge held at once.
    pub max_resident_bytes: u64,
    /// Seconds.
    pub merge_s: f64,
}

/// `tet-bench merge JOB_DIR -o OUT.tmesh`.
pub fn merge(args: &MergeArgs, json: bool) -> Result<()> {
    if args.output.extension().is_none_or(|e| e != MESH_EXTENSION) {
        bail!(
            "the output file must end in .{MESH_EXTENSION} (got {})",
            args.output.display()
        );
    }
    let job = JobManifest::load(&args.job_dir)?;
    let s = merge_job(&args.job_dir, &job, &args.output)
        .with_context(|| format!("cannot merge {}", args.job_dir.display()))?;
    let doc = MergeDoc {
        output: args.output.display().to_string(),
        parts: job.parts.len(),
        points: s.points,
        tets: s.tets,
        constrained_faces: s.constrained,
        file_bytes: s.file_bytes,
        max_resident_bytes: s.max_resident_bytes,
        merge_s: s.merge_s,
    };
    if json {
        return print_json(&doc);
    }
    outln!(
        "{} parts: {} points, {} tets, {} constrained faces -> {} ({} bytes, {:.2} s, held at most {:.1} MiB)",
        doc.parts,
        doc.points,
        doc.tets,
        doc.constrained_faces,
        doc.output,
        doc.file_bytes,
        doc.merge_s,
        doc.max_resident_bytes as f64 / (1024.0 * 1024.0)
    )?;
    Ok(())
}
