//! Out-of-core constrained tetrahedralization under a memory limit
//! (Erkoç et al., seed 003; issue 8).
//!
//! The paper's `TETRA` procedure (§3, Algorithm 1) tetrahedralizes a part
//! with TetGen when `CALCULATE_EXPECTED_MEMORY` fits the limit, and
//! otherwise `CLIP`s it by a plane and recurses on both halves, then
//! `MERGE`s the two meshes (repairing overlapping vertices/edges along the
//! cut and hashing centroids to find neighbours, §3.2–3.3). This module:
//!
//! * [`memory_model`]: `CALCULATE_EXPECTED_MEMORY` — TetGen's peak memory
//!   measured against its input size (worker `VmHWM`), a weighted linear
//!   fit ([`memory_model::MemoryModel::FITTED`], with the measurements) and
//!   [`memory_model::predict_peak_memory`] with a safety margin.
//! * [`split`]: the split planners. [`split::plan_split`] is the paper's
//!   recursive rule (plane through the mean of the axis of largest
//!   variance, moved to a nearby plane cutting fewer triangles — the
//!   paper's future work) as a [`split::SplitTree`] with the triangles cut
//!   at every node. [`split::plan_slabs`] is what the builder uses today:
//!   parallel planes on the axis of largest variance at corner quantiles,
//!   as many as needed for every slab's prediction to fit.
//! * [`seam`]: exact seams and the merge. Triangles crossing a plane are
//!   clipped with crossing points rounded once to f32 and lying exactly on
//!   the plane; one `spade` constrained Delaunay triangulation of the
//!   section (cut segments, in-plane scene edges and vertices as
//!   constraints) is given to both neighbouring parts as facets; TetGen
//!   `-pY` keeps every facet; the merge is exact point deduplication +
//!   [`tet_core::TetMesh::assemble`] — no repair step, no hashing of
//!   centroids. [`seam::build_slabs`] builds `k + 1` slabs (parts run
//!   concurrently in worker processes with `parallel_parts`),
//!   [`seam::build_with_memory_limit`] plans and builds under a limit.
//!
//! | paper (seed 003)                       | code                                   |
//! |----------------------------------------|----------------------------------------|
//! | `TETRA(vertices, faces)`               | [`seam::build_with_memory_limit`]      |
//! | `CALCULATE_EXPECTED_MEMORY`            | [`memory_model::predict_peak_memory`]  |
//! | `memory_limit`                         | `SplitOptions::limit_bytes`            |
//! | `CLIP` plane (mean, max-variance axis) | [`split::choose_plane`]                |
//! | `CLIP` of triangles                    | [`seam::clip_polygon`], [`seam::crossing_point`] |
//! | left / right parts                     | slabs `k`, `k + 1` of [`seam::build_slabs`] |
//! | `MERGE` (repairs, centroid hashing)    | exact dedup + `TetMesh::assemble` in [`seam::build_slabs`] |
//!
//! ## Limits of this first part
//! * Only parallel planes are built ([`seam::build_slabs`]). The recursive
//!   tree of [`split::plan_split`] has perpendicular planes, whose seams
//!   meet each other: a seam's triangulation would then need the traces of
//!   the other side's deeper planes (and their crossing points) as
//!   constraints so both sides agree; not done yet.
//! * Parts are held in memory and merged in memory (no streaming through
//!   mesh files yet), so the *caller's* process holds the whole mesh; the
//!   limit applies to each TetGen worker.
//! * A Steiner point whose f32 rounding flattens a tet is an error
//!   ([`seam::SeamError::RoundingFlattens`]); the in-core pipeline's
//!   snapping repair is not reused yet.
//! * A plane closer than [`seam::NEAR_PLANE`] × the box extent to a vertex
//!   (but not through it) is refused (TetGen would merge the crossing
//!   points with the vertex); [`split::plan_slabs`] avoids such planes.

pub mod memory_model;
pub mod report;
pub mod seam;
pub mod split;
pub mod tree;
