//! Building under a memory limit (issue 8): `build --predict-memory`,
//! `build --memory-limit`, and the out-of-core table of `tables`.
//!
//! The prediction is `tet_build`'s memory model
//! ([`tet_build::outofcore::memory_model::predict_peak_memory`], TetGen's
//! peak resident memory as a linear function of points + triangles of its
//! input, with a safety margin) on the cleaned scene plus the enclosing
//! box's 8 corners and 12 triangles. Over the limit, the scene is split
//! recursively by the paper's planes until every part's prediction fits
//! the limit divided by the parts run at once
//! ([`tet_build::outofcore::tree::build_tree_with_memory_limit`]), each
//! part is tetrahedralized by its own TetGen worker with exact seams and
//! the parts are merged; when no tree fits, parallel slabs are tried
//! ([`tet_build::outofcore::split::plan_slabs`]); `--planner tree|slabs`
//! forces one. Measured on Torus Knots in a Box, the tree cuts 12
//! triangles where slabs cut 14,012–28,340 and builds in 0.62–0.67× the
//! in-core time at ½–¼ of its peak.
//!
//! **Merging.** `build` streams by default ([`MergeMode::Stream`],
//! [`Limited::to_file`]): each part goes to a part file as soon as its
//! worker returns and the part files are merged into the output a part at
//! a time, so the process never holds the whole mesh — what the issue asks
//! of a build under a limit. The price is locality: each part is
//! Hilbert-sorted on its own and the parts follow each other in the tree's
//! leaf order, instead of one curve through the whole mesh.
//! `--merge memory` ([`Limited::in_memory`]) merges in memory and sorts the
//! whole mesh; the `tables` harness uses it (it traces the mesh right
//! away, so holds it anyway). `build --tet20` reads the written file back
//! and traces it, so the trade (memory, build time, render speed) of both
//! merges and of the in-core build is measured the same way
//! ([`tet20_speed`]).

use anyhow::Result;
use serde::Serialize;
use tet_build::scene::Scene;
use tet_core::TetMesh;

use crate::cli::BuildFlags;
use crate::load::BuildSummary;

/// Parses a memory size: a byte count, or a number with a unit `K`, `M`,
/// `G`, `T` (also `KB`/`KiB`, …, any case), all powers of 1024: `512M`,
/// `1.5G`, `2097152`.
pub fn parse_memory_limit(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let unit = unit.trim().to_ascii_lowercase();
    let scale: f64 = match unit.as_str() {
        "" | "b" => 1.0,
        "k" | "kb" | "kib" => 1024.0,
        "m" | "mb" | "mib" => 1024.0 * 1024.0,
        "g" | "gb" | "gib" => 1024.0 * 1024.0 * 1024.0,
        "t" | "tb" | "tib" => 1024.0 * 1024.0 * 1024.0 * 1024.0,
        _ => {
            return Err(format!(
                "unknown unit `{unit}` in `{s}`: give bytes or a number with K, M, G or T (powers of 1024), e.g. 512M or 1.5G"
            ));
        }
    };
    let value: f64 = num.parse().map_err(|_| {
        format!("`{s}` is not a memory size: give bytes or a number with K, M, G or T, e.g. 512M or 1.5G")
    })?;
    let bytes = value * scale;
    if !(bytes >= 1.0 && bytes < u64::MAX as f64) {
        return Err(format!(
            "memory limit `{s}` must be at least one byte and finite"
        ));
    }
    Ok(bytes.round() as u64)
}

/// Bytes as MiB.
fn mib(bytes: u64) -> f64 {
    bytes as f64 / (1024.0 * 1024.0)
}

/// `build --predict-memory` document.
#[derive(Clone, Debug, Serialize)]
pub struct Prediction {
    /// Scene name.
    pub name: String,
    /// Points given to TetGen (cleaned scene vertices + 8 box corners).
    pub points: usize,
    /// Triangles given to TetGen (cleaned scene triangles + 12 box triangles).
    pub triangles: usize,
    /// Predicted peak resident memory of the TetGen run, bytes (with margin).
    pub predicted_peak_bytes: u64,
    /// The model: `margin × (base_bytes + bytes_per_element × (points + triangles))`.
    pub model: ModelDoc,
}

/// The memory model's constants.
#[derive(Clone, Debug, Serialize)]
pub struct ModelDoc {
    /// Fixed part, bytes.
    pub base_bytes: f64,
    /// Bytes per input point or triangle.
    pub bytes_per_element: f64,
    /// Safety margin (multiplier).
    pub margin: f64,
}

/// What a build under `--memory-limit` did (field `memory` of the `build`
/// document, and rows of the out-of-core table).
#[derive(Clone, Debug, Serialize)]
pub struct MemoryReport {
    /// The limit, bytes.
    pub limit_bytes: u64,
    /// Predicted peak of the in-core TetGen run, bytes.
    pub predicted_in_core_bytes: u64,
    /// True when the scene was built in parts.
    pub out_of_core: bool,
    /// Parts (1 in core).
    pub parts: usize,
    /// Parts run at once (their predictions together fit the limit).
    pub parallel_parts: usize,
    /// Cut axis (0 = x, 1 = y, 2 = z) of the first plane, when cut (the
    /// only axis for slabs).
    pub axis: Option<usize>,
    /// Cut plane offsets (n parts: n - 1 planes; a tree's in preorder).
    pub planes: Vec<f32>,
    /// Axis of each plane of `planes`.
    pub plane_axes: Vec<usize>,
    /// Scene triangles cut by the planes.
    pub triangles_cut: usize,
    /// How the scene was split: `in-core`, `tree` (the paper's recursive
    /// perpendicular planes; `axis`/`planes` then empty) or `slabs`.
    pub planner: String,
    /// Depth of the split (0 in core; for slabs, log2 of the parts, rounded up).
    pub depth: usize,
    /// Input points of each part's TetGen run.
    pub part_points: Vec<usize>,
    /// Input triangles of each part's TetGen run.
    pub part_triangles: Vec<usize>,
    /// Tets of each part.
    pub part_tets: Vec<usize>,
    /// Predicted peak of each part, bytes.
    pub part_predicted_bytes: Vec<u64>,
    /// Measured peak (worker `VmHWM`) of each part, KiB.
    pub part_peak_kib: Vec<Option<u64>>,
    /// Largest measured part peak, KiB.
    pub max_part_peak_kib: Option<u64>,
    /// Wall time of the build (parts, merge, validation), s.
    pub total_s: f64,
    /// How the parts were merged: `in-core` (one part), `memory` (the
    /// whole mesh in memory, then Hilbert-sorted as a whole) or `stream`
    /// (part files merged into the mesh file a part at a time, each part
    /// Hilbert-sorted on its own).
    pub merge: String,
    /// Seconds of the streaming merge after the last part (else `null`).
    pub merge_s: Option<f64>,
    /// Largest number of bytes the streaming merge held at once: one
    /// part's arrays and the seam maps (else `null`).
    pub merge_max_resident_bytes: Option<u64>,
    /// Bytes of every part's arrays together: what a merge holding all
    /// parts at once would need (streaming only, else `null`).
    pub merge_all_parts_bytes: Option<u64>,
    /// Bytes of all part files (streaming only, else `null`).
    pub part_file_bytes: Option<u64>,
    /// Peak resident memory (`VmHWM`, KiB) of this process when the build
    /// was done: planner, finished parts, merge (the TetGen workers are
    /// processes of their own: `part_peak_kib`); `null` without `/proc`.
    pub process_peak_kib: Option<u64>,
}

/// Cleaned scene size as TetGen would receive it (with the box unless `no_box`).
#[cfg(feature = "tetgen")]
pub fn tetgen_input_size(scene: &Scene, no_box: bool) -> Result<(usize, usize)> {
    let (cleaned, _) = tet_build::clean::clean_scene(scene)
        .map_err(|e| anyhow::anyhow!("cannot clean `{}`: {e}", scene.name))?;
    let extra = if no_box { (0, 0) } else { (8, 12) };
    Ok((
        cleaned.vertices.len() + extra.0,
        cleaned.triangles.len() + extra.1,
    ))
}

/// The prediction for `scene`.
#[cfg(feature = "tetgen")]
pub fn predict(scene: &Scene, no_box: bool) -> Result<Prediction> {
    use tet_build::outofcore::memory_model::{MemoryModel, predict_peak_memory};
    let (points, triangles) = tetgen_input_size(scene, no_box)?;
    let m = MemoryModel::FITTED;
    Ok(Prediction {
        name: scene.name.clone(),
        points,
        triangles,
        predicted_peak_bytes: predict_peak_memory(points, triangles),
        model: ModelDoc {
            base_bytes: m.base_bytes,
            bytes_per_element: m.bytes_per_element,
            margin: m.margin,
        },
    })
}

/// Without TetGen there is nothing to predict.
#[cfg(not(feature = "tetgen"))]
pub fn predict(scene: &Scene, _: bool) -> Result<Prediction> {
    anyhow::bail!(
        "`{}`: the memory model needs the `tetgen` feature",
        scene.name
    )
}

/// How `build --memory-limit` splits a scene whose prediction exceeds the
/// limit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Planner {
    /// The paper's recursive tree, parallel slabs when no tree fits.
    #[default]
    Auto,
    /// Only the paper's recursive tree (perpendicular planes).
    Tree,
    /// Only parallel slabs on the axis of largest variance.
    Slabs,
}

/// How the parts of an out-of-core build are merged.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum MergeMode {
    /// Part files merged into the mesh file a part at a time (each part
    /// Hilbert-sorted on its own): the merge holds one part and the seams.
    #[default]
    Stream,
    /// The whole mesh merged in memory and Hilbert-sorted as a whole.
    Memory,
}

/// A build under a memory limit.
#[cfg_attr(not(feature = "tetgen"), allow(dead_code))]
pub struct Limited<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// Build options.
    pub flags: &'a BuildFlags,
    /// The limit, bytes.
    pub limit_bytes: u64,
    /// Most TetGen workers at once.
    pub max_parallel: usize,
    /// No progress spinner.
    pub quiet: bool,
    /// Points (other cameras and lights) the enclosing box must hold with
    /// `--wide-box`.
    pub extra: &'a [glam::Vec3],
    /// How to split.
    pub planner: Planner,
}

/// Counts of a mesh written to a file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Written {
    /// Points.
    pub points: usize,
    /// Tets.
    pub tets: usize,
    /// Constrained faces.
    pub constrained: usize,
    /// Bytes of the file.
    pub file_bytes: u64,
}

#[cfg(feature = "tetgen")]
mod limited;
mod trace_speed;

pub use trace_speed::tet20_speed;

/// Builds `scene` so that every TetGen run's predicted peak fits
/// `limit_bytes`, the parts merged in memory ([`Limited::in_memory`] with
/// the default planner: the paper's tree, slabs when no tree fits).
pub fn build_limited(
    scene: &Scene,
    flags: &BuildFlags,
    limit_bytes: u64,
    max_parallel: usize,
    quiet: bool,
    extra: &[glam::Vec3],
) -> Result<(TetMesh, BuildSummary, MemoryReport)> {
    Limited {
        scene,
        flags,
        limit_bytes,
        max_parallel,
        quiet,
        extra,
        planner: Planner::Auto,
    }
    .in_memory()
}

/// Without TetGen, scenes cannot be built.
#[cfg(not(feature = "tetgen"))]
impl Limited<'_> {
    fn no_tetgen<T>(&self) -> Result<T> {
        anyhow::bail!(
            "`{}` is a scene, but this tet-bench was built without the `tetgen` feature",
            self.scene.name
        )
    }

    /// Fails: no TetGen.
    pub fn in_memory(&self) -> Result<(TetMesh, BuildSummary, MemoryReport)> {
        self.no_tetgen()
    }

    /// Fails: no TetGen.
    pub fn to_file(
        &self,
        _: &std::path::Path,
        _: &tet_core::scene::SceneInfo,
    ) -> Result<(Written, BuildSummary, MemoryReport)> {
        self.no_tetgen()
    }
}

/// Prints a memory report.
pub fn print_memory(m: &MemoryReport) {
    let mb = mib;
    if !m.out_of_core {
        println!(
            "  memory: predicted in-core peak {:.1} MiB fits the limit {:.1} MiB: built in core (measured peak {})",
            mb(m.predicted_in_core_bytes),
            mb(m.limit_bytes),
            m.max_part_peak_kib
                .map_or("n/a".into(), |k| format!("{:.1} MiB", k as f64 / 1024.0))
        );
        return;
    }
    println!(
        "  memory: predicted in-core peak {:.1} MiB > limit {:.1} MiB: {} parts along {} ({} at a time), {} scene triangles cut, {:.2} s",
        mb(m.predicted_in_core_bytes),
        mb(m.limit_bytes),
        m.parts,
        ["x", "y", "z"][m.axis.unwrap_or(0).min(2)],
        m.parallel_parts,
        m.triangles_cut,
        m.total_s
    );
    for k in 0..m.parts {
        println!(
            "    part {k}: {} points, {} triangles -> {} tets; peak predicted {:.1} MiB, measured {}",
            m.part_points.get(k).copied().unwrap_or(0),
            m.part_triangles.get(k).copied().unwrap_or(0),
            m.part_tets.get(k).copied().unwrap_or(0),
            mb(m.part_predicted_bytes.get(k).copied().unwrap_or(0)),
            m.part_peak_kib
                .get(k)
                .copied()
                .flatten()
                .map_or("n/a".into(), |k| format!("{:.1} MiB", k as f64 / 1024.0))
        );
    }
    let process = m
        .process_peak_kib
        .map_or("n/a".into(), |k| format!("{:.1} MiB", k as f64 / 1024.0));
    match (
        m.merge_s,
        m.merge_max_resident_bytes,
        m.merge_all_parts_bytes,
    ) {
        (Some(s), Some(held), Some(all)) => println!(
            "  merge: streamed through {:.1} MiB of part files in {s:.2} s, holding at most {:.1} MiB (all parts: {:.1} MiB); this process's peak {process}",
            mb(m.part_file_bytes.unwrap_or(0)),
            mb(held),
            mb(all)
        ),
        _ => println!("  merge: {}; this process's peak {process}", m.merge),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn memory_sizes_parse_with_binary_units() {
        assert_eq!(parse_memory_limit("2097152"), Ok(2_097_152));
        assert_eq!(parse_memory_limit("512M"), Ok(512 << 20));
        assert_eq!(parse_memory_limit("512mb"), Ok(512 << 20));
        assert_eq!(parse_memory_limit("1.5G"), Ok(3 << 29));
        assert_eq!(parse_memory_limit("64 KiB"), Ok(64 << 10));
        for bad in ["", "M", "12X", "-5M", "1.2.3G", "0", "0.1"] {
            let e = parse_memory_limit(bad).unwrap_err();
            assert!(e.contains(bad.trim()), "{bad}: {e}");
        }
    }
}
