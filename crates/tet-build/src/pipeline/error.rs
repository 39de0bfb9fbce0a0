//! [`BuildError`]: every way a build fails, each naming what failed.

use tet_core::MeshError;
use thiserror::Error;

use crate::bbox::BoxError;
use crate::clean::CleanError;
use crate::intersect::{IntersectingPair, find_self_intersections};
use crate::resolve::ResolveError;
use crate::scene::Scene;
use crate::tetgen::TetgenError;

/// A failed build; each variant names what failed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum BuildError {
    /// The scene has no triangles left after cleaning.
    #[error("the scene has no triangles (after cleaning: {vertices} vertices)")]
    EmptyScene {
        /// Vertices left.
        vertices: usize,
    },
    /// Cleaning rejected the scene.
    #[error("cleaning: {0}")]
    Clean(#[from] CleanError),
    /// The enclosing box could not be built.
    #[error("enclosing box: {0}")]
    Box(#[from] BoxError),
    /// TetGen failed.
    #[error("TetGen: {0}")]
    Tetgen(#[from] TetgenError),
    /// The scene's triangles intersect each other (TetGen's code 3, with the
    /// offending pairs found by the exact check of [`crate::intersect`]).
    #[error(
        "the scene self-intersects: {total} pairs of input triangles intersect, e.g. {}",
        list_pairs(pairs)
    )]
    SelfIntersections {
        /// Up to 20 pairs, by input triangle index.
        pairs: Vec<IntersectingPair>,
        /// Number of intersecting pairs.
        total: usize,
    },
    /// A scene triangle is not exactly one constrained face of the mesh.
    #[error(
        "scene triangle {triangle} (cleaned {cleaned}) is covered by {faces} constrained faces, expected exactly one with its own vertices"
    )]
    TriangleNotPreserved {
        /// Input scene triangle id.
        triangle: u32,
        /// Index after cleaning.
        cleaned: u32,
        /// Number of TetGen faces carrying its marker.
        faces: usize,
    },
    /// TetGen returned a face with a marker that names no triangle.
    #[error("TetGen face {face} has marker {marker}, which names no scene triangle")]
    UnknownMarker {
        /// Face index in TetGen's output.
        face: usize,
        /// The marker.
        marker: i32,
    },
    /// TetGen changed input points (it must keep them, in order).
    #[error("TetGen moved or dropped input point {point}")]
    InputPointChanged {
        /// Point index.
        point: usize,
    },
    /// Rounding Steiner points to f32 still flattens or inverts tets after
    /// the allowed TetGen re-runs.
    #[error(
        "{count} tets are flat or inverted after rounding to f32 (after {rounds} TetGen runs), e.g. {tets:?}"
    )]
    RoundingFlattens {
        /// Number of bad tets.
        count: usize,
        /// Up to 16 of them (indices in the last TetGen output).
        tets: Vec<u32>,
        /// TetGen runs made.
        rounds: u32,
    },
    /// Resolving self-intersections failed (names input triangles).
    #[error("resolving self-intersections: {0}")]
    Resolve(#[from] ResolveError),
    /// The scene's extent along an axis overflows f32: differences of its
    /// coordinates (which building and tracing compute) are infinite.
    #[error(
        "the scene spans {min:e} to {max:e} along axis {axis} (vertex {vertex}): the extent overflows f32, whose largest value is {limit:e}",
        limit = f32::MAX
    )]
    ExtentOverflows {
        /// Axis (0 = x, 1 = y, 2 = z).
        axis: u8,
        /// Smallest coordinate on that axis.
        min: f32,
        /// Largest coordinate on that axis.
        max: f32,
        /// Input vertex at the end of larger magnitude.
        vertex: u32,
    },
    /// Every coordinate of the scene is below the smallest normal f32, where
    /// f32 keeps fewer than 24 significant bits: the stored points could not
    /// hold the scene's shape nor its Steiner points.
    #[error(
        "every coordinate of the scene is below the smallest normal f32 ({limit:e}); the largest, {largest:e}, is at vertex {vertex}: f32 subnormals keep fewer than 24 significant bits",
        limit = f32::MIN_POSITIVE
    )]
    SubnormalScene {
        /// Largest coordinate magnitude.
        largest: f32,
        /// Input vertex that has it.
        vertex: u32,
    },
    /// Assembly or validation failed (a bug in this pipeline or TetGen).
    #[error("mesh: {0}")]
    Mesh(#[from] MeshError),
}

fn list_pairs(pairs: &[IntersectingPair]) -> String {
    pairs
        .iter()
        .map(|p| format!("{} × {} ({:?})", p.first, p.second, p.kind))
        .collect::<Vec<_>>()
        .join(", ")
}

/// TetGen reported a self-intersection: name the pairs by input index.
pub(super) fn self_intersection_error(scene: &Scene) -> BuildError {
    let report = find_self_intersections(&scene.vertices, &scene.triangles);
    if report.pairs.is_empty() {
        // Only TetGen's own tolerance sees it (or it involves the box).
        return BuildError::Tetgen(TetgenError::SelfIntersection);
    }
    BuildError::SelfIntersections {
        total: report.pairs.len(),
        pairs: report.pairs.into_iter().take(20).collect(),
    }
}
