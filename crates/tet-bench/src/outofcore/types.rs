//! The plain data of a build under a memory limit: the prediction, the
//! request ([`Limited`]) and what the build did ([`MemoryReport`]).

use serde::{Deserialize, Serialize};
use tet_build::scene::Scene;

use super::options::Planner;
use crate::load::build_flags::BuildFlags;

/// Bytes as MiB.
#[cfg_attr(not(feature = "tetgen"), allow(dead_code))]
pub fn mib(bytes: u64) -> f64 {
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
    /// What a local `build --memory-limit` of this scene sets aside for
    /// itself from the limit (its process; TetGen workers get the rest),
    /// bytes: the in-core build is taken when the limit is at least this
    /// plus 5/4 of `predicted_peak_bytes`.
    pub builder_bytes: u64,
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
#[derive(Clone, Debug, Serialize, Deserialize)]
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
    /// Scene pieces of each part that TetGen returned split in two or
    /// more faces by Steiner points it could not move off the surface
    /// (kept as constrained faces of the same input triangle).
    pub part_split_pieces: Vec<usize>,
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
    /// What this process set aside for itself from the limit before the
    /// workers' shares (a model of its own memory from the scene's
    /// triangles: `tet_build::outofcore::admission::builder_bytes`), bytes.
    pub own_bytes: u64,
    /// How many times the build moved planes and tried again (a cut too
    /// near a point, or TetGen failing on a part); 0 for slabs.
    pub plane_moves: usize,
    /// Each failure of TetGen on a part (its message: the part and why)
    /// that made the build move the part's walls and try again, in the
    /// order met; empty for slabs and one-piece builds.
    #[serde(default)]
    pub part_failures: Vec<String>,
    /// The parts built with their surface relaxed, as `{part, mode}`
    /// (`steiner-off-surface`: TetGen `-Y/2`; `unlocked`: without `-Y`),
    /// after their walls moved twice and TetGen still failed; empty when
    /// every part kept `-Y`.
    #[serde(default)]
    pub surface_relaxed: Vec<RelaxedPart>,
    /// Parts the retries took as the attempt before built them (their
    /// input unchanged by the moves), summed over retries.
    pub parts_reused: usize,
    /// Peak resident memory of the whole process tree during the build
    /// (this process and every TetGen worker together, sampled every
    /// 2 ms), KiB: what the limit bounds; `null` without `/proc`.
    pub tree_peak_kib: Option<u64>,
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

/// A part built with its surface relaxed ([`MemoryReport::surface_relaxed`]).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct RelaxedPart {
    /// The part.
    pub part: usize,
    /// `steiner-off-surface` or `unlocked`.
    pub mode: String,
}
