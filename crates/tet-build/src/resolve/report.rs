//! What [`super::resolve`] did.

use serde::Serialize;

/// Counts of one resolution; all zero (and `rounds == 0`) for a scene that
/// was already free of self-intersections.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ResolveReport {
    /// Intersecting pairs found in the input.
    pub pairs: usize,
    /// Input triangles whose output differs from themselves (cut into
    /// pieces, or dropped where another triangle covers them).
    pub split_triangles: usize,
    /// Points added after the input vertices.
    pub added_points: usize,
    /// Pieces dropped because another piece covers the same region
    /// (coplanar overlaps, duplicate facets).
    pub merged_pieces: usize,
    /// Rounds of cutting and re-checking run (0: nothing to do).
    pub rounds: u32,
}
