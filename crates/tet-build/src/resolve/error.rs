//! Why [`super::resolve`] gave up, naming the input element at fault.

use thiserror::Error;

/// How many still-crossing pairs [`ResolveError::NotConverged`] lists.
pub const LISTED_PAIRS: usize = 20;

/// Invalid input to, or failure of, [`super::resolve`].
#[derive(Clone, Debug, PartialEq, Error)]
pub enum ResolveError {
    /// Rounding the new points to `f32` kept creating crossings.
    #[error(
        "self-intersections not resolved after {rounds} rounds: {total} pairs of input triangles still meet, e.g. {pairs:?}"
    )]
    NotConverged {
        /// Rounds run.
        rounds: u32,
        /// Pairs of input triangles (`first <= second`) whose pieces still
        /// meet; at most [`LISTED_PAIRS`].
        pairs: Vec<(u32, u32)>,
        /// Number of such pairs.
        total: usize,
    },
    /// A triangle names a vertex that does not exist.
    #[error("triangle {triangle} corner {corner}: vertex {vertex} out of range ({count} vertices)")]
    IndexOutOfRange {
        /// Input triangle.
        triangle: u32,
        /// Corner 0..3.
        corner: u8,
        /// The index.
        vertex: u32,
        /// Number of vertices.
        count: usize,
    },
    /// A vertex has a NaN or infinite coordinate.
    #[error("vertex {vertex} has a non-finite coordinate {position:?}")]
    NonFiniteVertex {
        /// Input vertex.
        vertex: u32,
        /// Its coordinates.
        position: [f32; 3],
    },
    /// A coordinate is too large for the exact arithmetic to stay clear of
    /// overflow.
    #[error("vertex {vertex} has a coordinate beyond ±{limit:e}: {position:?}")]
    CoordinateTooLarge {
        /// Input vertex.
        vertex: u32,
        /// Its coordinates.
        position: [f32; 3],
        /// The largest magnitude accepted.
        limit: f32,
    },
    /// A triangle's corners are exactly collinear (or repeated): it has no
    /// plane to cut it in. Cleaning removes such triangles.
    #[error("triangle {triangle} is degenerate (collinear or repeated corners)")]
    DegenerateTriangle {
        /// Input triangle.
        triangle: u32,
    },
    /// The planar triangulation of a triangle's pieces refused a point.
    #[error("triangle {triangle}: planar triangulation failed: {message}")]
    Triangulation {
        /// Input triangle the piece came from.
        triangle: u32,
        /// The triangulator's message.
        message: String,
    },
}
