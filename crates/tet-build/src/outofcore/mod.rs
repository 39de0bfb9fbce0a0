//! Out-of-core constrained tetrahedralization under a memory limit
//! (Erkoç et al. 2021).
//!
//! The paper's `TETRA` procedure (§3, Algorithm 1) tetrahedralizes a part
//! with TetGen when `CALCULATE_EXPECTED_MEMORY` fits the limit, and
//! otherwise `CLIP`s it by a plane and recurses on both halves, then
//! `MERGE`s the two meshes (repairing overlapping vertices/edges along the
//! cut and hashing centroids to find neighbours, §3.2–3.3). This module:
//!
//! Modules, bottom up (each uses only modules above it):
//!
//! * [`error`]: [`error::SeamError`] and [`error::StreamError`].
//! * [`plane`]: the geometry of cuts. An axis-aligned [`plane::SplitPlane`];
//!   triangles crossing it are clipped with crossing points rounded once to
//!   f32 and lying exactly on the plane ([`plane::clip_polygon`],
//!   [`plane::crossing_point`]).
//! * [`memory_model`]: `CALCULATE_EXPECTED_MEMORY` — TetGen's peak memory
//!   measured against its input size (worker `VmHWM`), a weighted linear
//!   fit ([`memory_model::MemoryModel::FITTED`]) and
//!   [`memory_model::predict_peak_memory`] with a safety margin.
//! * [`split`]: part planning. [`split::plan_split`] is the paper's
//!   recursive rule (plane through the mean of the axis of largest
//!   variance, moved to a nearby plane cutting fewer triangles — the
//!   paper's future work; a thick empty margin around the scene's detail
//!   is cut off first, [`split::peel_plane`]) as a [`split::SplitTree`] with the triangles cut
//!   at every node; [`split::SplitOptions::shaped_for_rays`] also cuts
//!   toward the part size of a mesh shaped for rays within the limit (the
//!   default walled build, the local limited build and job plans); [`split::plan_slabs`] cuts parallel slabs on the axis
//!   of largest variance at corner quantiles, as many as needed for every
//!   slab's prediction to fit (the fallback when no tree fits).
//! * [`seam_index`]: which points and faces lie on a seam (exact), for the
//!   streamed merge and the seam [`report`].
//! * `section`: one `spade` constrained Delaunay triangulation of a plane's
//!   section (cut segments, in-plane scene edges and vertices as
//!   constraints), given to both neighbouring parts as facets; TetGen `-pY`
//!   keeps every facet.
//! * `prepare`: the whole scene cleaned and, by default, its
//!   self-intersections resolved ([`crate::resolve`]) before any cut.
//! * [`admission`]: parts start only while the process tree fits the
//!   limit ([`seam::SeamOptions::tree_limit_bytes`]).
//! * `parts`: each part's TetGen run (parts run concurrently in worker
//!   processes with `parallel_parts`) and the [`seam::SeamReport`].
//! * `split_parts`: a part's facets made when it is taken up: the cut
//!   clips ahead only the triangles the planes cut, and a triangle inside
//!   one part is read from the scene when that part is written or built,
//!   so no planner holds every part's facets at once.
//! * `merge`: what becomes of finished parts. In memory: exact point
//!   deduplication + [`tet_core::TetMesh::assemble`] (no repair step, no
//!   hashing of centroids; the caller holds the whole mesh).
//! * [`stream`]: the streamed merge: each part written to a part file as
//!   soon as its worker returns, the part files merged into the mesh file a
//!   part at a time, holding one part plus maps proportional to the seams'
//!   area ([`stream::merge_part_files`]). Both merges give the same mesh up
//!   to the order of its elements; the streamed one is Hilbert-sorted part
//!   by part, parts in leaf order.
//! * [`seam`]: builds with parallel planes: [`seam::build_slabs`] builds
//!   `k + 1` slabs, [`seam::build_with_memory_limit`] plans and builds
//!   under a limit, [`seam::build_slabs_to_file`] streams.
//! * [`tree`]: the paper's recursive tree with perpendicular planes. Where
//!   seams meet, every wall is triangulated with the traces of the other
//!   seams and the crossings registered on shared roots, so both sides of
//!   every wall receive the very same triangles
//!   ([`tree::build_tree`], [`tree::build_tree_with_memory_limit`], which
//!   moves a plane meeting a degenerate configuration and retries;
//!   [`tree::build_tree_to_file`],
//!   [`tree::build_tree_with_memory_limit_to_file`] stream).
//! * [`report`]: tet quality at the seams vs elsewhere.
//! * [`tree_memory`]: the resident memory of the whole process tree (the
//!   builder and its TetGen workers), what a limit on one machine bounds.
//! * [`job`]: the same build as a job any engine can run: a plan and one
//!   input file per part in a directory, each part built by its own
//!   process in any order ([`job::build_part`]), then the streamed merge
//!   ([`job::merge_job`]).
//!
//! | paper (Erkoç et al. 2021)                       | code                                   |
//! |----------------------------------------|----------------------------------------|
//! | `TETRA(vertices, faces)`               | [`tree::build_tree_with_memory_limit`] |
//! | `CALCULATE_EXPECTED_MEMORY`            | [`memory_model::predict_peak_memory`]  |
//! | `memory_limit`                         | `SplitOptions::limit_bytes`            |
//! | `CLIP` plane (mean, max-variance axis) | [`split::choose_plane`]                |
//! | `CLIP` of triangles                    | [`seam::clip_polygon`], [`seam::crossing_point`], tree-order clipping in [`tree`] |
//! | left / right parts                     | the leaves of [`tree::CutTree`] (slabs `k`, `k + 1` of [`seam::build_slabs`]) |
//! | `MERGE` (repairs, centroid hashing)    | exact vertex triples: in memory, or [`stream::merge_part_files`] |
//!
//! ## Limits
//! * The limit is honoured by every TetGen worker's *predicted* peak (and
//!   measured: see the tests); the caller's own memory is the planner's
//!   inputs (the cleaned scene, the pieces of the triangles the planes cut
//!   and the walls; a part's own triangles join its facets only while it
//!   is built) plus, while parts run, one finished part (TetGen's output,
//!   then its assembled and sorted [`tet_core::TetMesh`]) per worker
//!   thread; the streamed merge then holds one part plus the seam maps. The in-memory merge (and
//!   the whole-mesh Hilbert sort after it) holds the whole mesh. A caller
//!   that bounds its whole process tree plans with
//!   [`admission::worker_share`] and sets
//!   [`seam::SeamOptions::tree_limit_bytes`], so that workers start only
//!   while they fit beside it ([`admission`]).
//! * The streamed mesh is Hilbert-sorted within each part only: the
//!   whole-mesh order needs the whole mesh in memory.
//! * A Steiner point whose f32 rounding flattens a tet is first snapped,
//!   then fed back to TetGen (the in-core pipeline's repair); where that
//!   fails, [`seam::SeamError::RoundingFlattens`].
//! * A plane closer than [`seam::NEAR_PLANE`] × the box extent to a vertex
//!   (but not through it) is refused (TetGen would merge the crossing
//!   points with the vertex); [`split::plan_slabs`] avoids such planes and
//!   [`tree::build_tree_with_memory_limit`] moves them.

pub mod admission;
pub mod error;
pub mod facet_faces;
pub mod job;
pub mod memory_model;
mod merge;
mod part_cache;
mod parts;
pub mod plane;
mod prepare;
pub mod report;
pub mod seam;
pub mod seam_index;
mod section;
pub mod split;
mod split_parts;
pub mod stream;
pub mod tree;
pub mod tree_memory;
