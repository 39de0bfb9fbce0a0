//! Out-of-core constrained tetrahedralization under a memory limit
//! (Erkoç et al., seed 003; issue 8).
//!
//! The paper's `TETRA` procedure (§3, Algorithm 1) tetrahedralizes a part
//! with TetGen when `CALCULATE_EXPECTED_MEMORY` fits the limit, and
//! otherwise `CLIP`s it by a plane and recurses on both halves, then
//! `MERGE`s the two meshes. This module provides, in order:
//!
//! * [`memory_model`]: `CALCULATE_EXPECTED_MEMORY` — TetGen's peak memory
//!   measured against its input size, a linear fit and
//!   [`memory_model::predict_peak_memory`] with a safety margin.
//! * [`split`]: the recursive split plan — the paper's plane through the
//!   mean of the axis of largest variance, moved to a nearby plane cutting
//!   fewer triangles when there is one (the paper's future work, §6), as a
//!   [`split::SplitTree`] with the triangles cut at every node.
//!
//! | paper (seed 003)              | code                                    |
//! |-------------------------------|-----------------------------------------|
//! | `TETRA(vertices, faces)`      | [`split::plan_split`] (planning only)   |
//! | `CALCULATE_EXPECTED_MEMORY`   | [`memory_model::predict_peak_memory`]   |
//! | `memory_limit`                | `limit_bytes`                           |
//! | `CLIP` plane (mean, max variance axis) | [`split::choose_plane`]        |
//! | left / right parts            | [`split::SplitTree::Split`] `below` / `above` |
//!
//! Not yet here (issue 8, items 3–5): exact seams, the merge, parallel
//! parts and the trade report.

pub mod memory_model;
pub mod seam;
pub mod split;
