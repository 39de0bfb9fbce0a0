//! Why a build can fail: every error names the element at fault.

use thiserror::Error;

/// A mesh or option that [`crate::RayStrips::build`] cannot accept.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum BuildError {
    /// A triangle refers to a vertex that does not exist.
    #[error(
        "triangle {triangle} refers to vertex {index}, but there are only {vertex_count} vertices"
    )]
    IndexOutOfRange {
        /// Index of the triangle in the input slice.
        triangle: usize,
        /// The offending vertex index.
        index: u32,
        /// Number of vertices given.
        vertex_count: usize,
    },
    /// A vertex has a NaN or infinite coordinate.
    #[error("vertex {vertex} has a non-finite coordinate {position:?}")]
    NonFiniteVertex {
        /// Index of the vertex in the input slice.
        vertex: usize,
        /// Its coordinates.
        position: [f32; 3],
    },
    /// More triangles than a strip's per-triangle word can name.
    #[error(
        "{count} triangles exceed the limit of {limit} (the triangle id shares a word with its vertex permutation)"
    )]
    TooManyTriangles {
        /// Number of triangles given.
        count: usize,
        /// The largest supported count.
        limit: usize,
    },
    /// `BuildOptions::chunk_triangles` is zero.
    #[error("chunk_triangles must be at least 1")]
    ZeroChunkTriangles,
    /// `BuildOptions::strips_per_leaf` is zero.
    #[error("strips_per_leaf must be at least 1")]
    ZeroStripsPerLeaf,
}
