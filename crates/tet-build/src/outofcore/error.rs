//! Errors of the out-of-core builders: [`SeamError`] (cuts, parts, merge)
//! and [`StreamError`] (part files and the streaming merge). At the bottom
//! of the out-of-core modules: everything else may name them.

use std::io;
use std::path::PathBuf;

use glam::Vec3;
use tet_core::MeshError;
use tet_core::format::FormatError;
use tet_core::reorder::PermutationError;
use thiserror::Error;

use super::plane::SplitPlane;
use crate::bbox::BoxError;
use crate::clean::CleanError;
use crate::resolve::ResolveError;
use crate::tetgen::TetgenError;

/// A failure of [`build_split_once`](super::seam::build_split_once) and the other out-of-core builders.
#[derive(Debug, Error)]
pub enum SeamError {
    /// Cleaning rejected the scene.
    #[error("cleaning: {0}")]
    Clean(#[from] CleanError),
    /// Resolving the scene's self-intersections failed (triangle ids are
    /// the input scene's).
    #[error("resolving self-intersections: {0}")]
    Resolve(#[from] ResolveError),
    /// The scene has no triangles after cleaning.
    #[error("the scene has no triangles")]
    EmptyScene,
    /// The enclosing box could not be built.
    #[error("enclosing box: {0}")]
    Box(#[from] BoxError),
    /// The plane does not cross the box's interior.
    #[error("plane {plane:?} does not cross the box {min:?}..{max:?}")]
    PlaneOutsideBox {
        /// The plane.
        plane: SplitPlane,
        /// Box lower corner.
        min: Vec3,
        /// Box upper corner.
        max: Vec3,
    },
    /// A scene vertex lies off the plane but closer to it than TetGen's
    /// tolerance (its crossing points would be merged with it by TetGen).
    #[error(
        "scene vertex {vertex} {point:?} is {distance:e} off the plane {plane:?}; move the plane"
    )]
    PlaneNearVertex {
        /// The plane.
        plane: SplitPlane,
        /// Input scene vertex index (after cleaning).
        vertex: u32,
        /// Its position.
        point: Vec3,
        /// Its distance to the plane.
        distance: f64,
    },
    /// A point made by an earlier cut (or a scene vertex) lies off the
    /// plane but closer to it than TetGen's tolerance.
    #[error("point {point:?} is {distance:e} off the plane {plane:?}; move the plane")]
    PlaneNearPoint {
        /// The plane.
        plane: SplitPlane,
        /// The point.
        point: Vec3,
        /// Its distance to the plane.
        distance: f64,
    },
    /// A cut met a nearly degenerate configuration (two planes crossing a
    /// segment at points closer than f32 rounding, or a clipped piece no
    /// longer convex after rounding).
    #[error("degenerate cut by {plane:?} near {point:?} (scene triangle {triangle}): {what}")]
    DegenerateCut {
        /// The plane.
        plane: SplitPlane,
        /// Where.
        point: Vec3,
        /// Cleaned scene triangle involved.
        triangle: u32,
        /// What went wrong.
        what: &'static str,
    },
    /// Several planes of one clipping pass met a point within tolerance or
    /// a degenerate cut (each a [`SeamError::PlaneNearPoint`] or
    /// [`SeamError::DegenerateCut`], in the order met; never fewer than
    /// two): the planner moves all of them at once.
    #[error("{} planes to move off points; the first: {}", .0.len(), .0.first().map_or(String::new(), |e| e.to_string()))]
    PlanesNearPoints(Vec<SeamError>),
    /// A clipped piece of a scene triangle could not be triangulated
    /// (rounding made its outline self-intersect).
    #[error("piece of scene triangle {triangle} with {vertices} vertices cannot be triangulated")]
    PieceTriangulation {
        /// Cleaned scene triangle.
        triangle: u32,
        /// Vertices of the piece's outline.
        vertices: usize,
    },
    /// A clipped piece of part `part` could not be triangulated
    /// ([`SeamError::PieceTriangulation`]): moving the part's walls cuts
    /// the triangle elsewhere.
    #[error("part {part}: {source}")]
    PartPiece {
        /// Part index.
        part: usize,
        /// The failure.
        source: Box<SeamError>,
    },
    /// No slab plan fits the memory limit.
    #[error("no slab plan keeps every part under {limit_bytes} bytes")]
    LimitTooSmall {
        /// The limit.
        limit_bytes: u64,
    },
    /// Two seam constraints cross (the scene self-intersects on the plane,
    /// or rounding of crossing points made two segments cross).
    #[error("seam constraint {from:?}–{to:?} crosses another seam constraint")]
    SeamConstraintsCross {
        /// Segment start.
        from: Vec3,
        /// Segment end.
        to: Vec3,
    },
    /// spade refused a seam point.
    #[error("seam triangulation: point {point:?}: {message}")]
    SeamPoint {
        /// The point.
        point: Vec3,
        /// spade's error.
        message: String,
    },
    /// TetGen failed on one part (slab).
    #[error("TetGen on part {part}: {source}")]
    Tetgen {
        /// Part index (0 = lowest slab).
        part: usize,
        /// TetGen's error.
        source: TetgenError,
    },
    /// TetGen found intersecting facets in a part's PLC; the first pair
    /// found by [`crate::intersect::find_self_intersections`] on the PLC.
    #[error("part {part}: facets {first:?} and {second:?} intersect ({kind:?}; {pairs} pairs)")]
    PartSelfIntersects {
        /// Part index.
        part: usize,
        /// One facet (vertices) and what it is (scene triangle or seam).
        first: ([Vec3; 3], Option<u32>),
        /// The other.
        second: ([Vec3; 3], Option<u32>),
        /// How they meet.
        kind: crate::intersect::IntersectionKind,
        /// Intersecting pairs in the part.
        pairs: usize,
    },
    /// A facet of a part did not come back as exactly one face.
    #[error("part {part}: facet {facet} came back as {faces} faces, expected exactly one")]
    FacetNotPreserved {
        /// Part index (0 = lowest slab).
        part: usize,
        /// Facet index in the part's PLC.
        facet: usize,
        /// Faces carrying its marker.
        faces: usize,
    },
    /// TetGen split a scene piece of a part in a way the merge cannot take
    /// (see [`super::facet_faces`]).
    #[error("part {part}: facet {facet} came back as {faces} faces and {why}")]
    FacetSplitBadly {
        /// Part index (0 = lowest slab).
        part: usize,
        /// Facet index in the part's PLC.
        facet: usize,
        /// Faces carrying its marker.
        faces: usize,
        /// What is wrong with the split.
        why: String,
    },
    /// TetGen moved or dropped an input point.
    #[error("part {part}: TetGen moved or dropped input point {point}")]
    InputPointChanged {
        /// Part index (0 = lowest slab).
        part: usize,
        /// Point index.
        point: usize,
    },
    /// Rounding Steiner points to f32 flattened or inverted tets.
    #[error("part {part}: {count} tets are flat or inverted after rounding to f32")]
    RoundingFlattens {
        /// Part index (0 = lowest slab).
        part: usize,
        /// How many.
        count: usize,
    },
    /// Several parts failed in one attempt of a build that retries, each
    /// in a way that moving its walls may cure ([`SeamError::part_to_retry`]),
    /// in part order (never fewer than two).
    #[error("{} parts failed; the first: {}", .0.len(), .0.first().map_or(String::new(), |e| e.to_string()))]
    PartsFailed(Vec<SeamError>),
    /// Part `part` of a job planned again has an input that failed before
    /// (its digest `input_digest`; `message`: how it failed then), in a way
    /// moving its walls may cure: the planner moves them as it does for a
    /// part that fails in a local build.
    #[error(
        "part {part}: its input {input_digest} failed in an earlier run of the job ({message})"
    )]
    FailedBefore {
        /// Part index in the plan being made.
        part: usize,
        /// The input's digest.
        input_digest: String,
        /// The earlier failure, in words.
        message: String,
    },
    /// A build that retries parts TetGen failed on stopped retrying: `why`
    /// (a part failed after its moves, the retries ran out, or no wall of
    /// a part could move), and the failure that ended it.
    #[error("gave up retrying failed parts ({why}); the last failure: {last}")]
    GaveUp {
        /// Why it stopped.
        why: String,
        /// The failure of the last attempt.
        last: Box<SeamError>,
    },
    /// Assembly or validation of the merged mesh failed.
    #[error("merged mesh: {0}")]
    Mesh(#[from] MeshError),
    /// Writing a part file or streaming the parts into the mesh file failed.
    #[error("streaming merge: {0}")]
    Stream(#[from] StreamError),
}

impl SeamError {
    /// `found` as one error: none, the one, or `many` holding them all.
    fn one_or_many(
        mut found: Vec<SeamError>,
        many: fn(Vec<SeamError>) -> SeamError,
    ) -> Option<SeamError> {
        match found.len() {
            0 => None,
            1 => found.pop(),
            _ => Some(many(found)),
        }
    }

    /// `found` as one error: none, the one, or
    /// [`SeamError::PlanesNearPoints`].
    pub(crate) fn planes_to_move(found: Vec<SeamError>) -> Option<SeamError> {
        SeamError::one_or_many(found, SeamError::PlanesNearPoints)
    }

    /// `found` (part failures a retry may cure) as one error: none, the
    /// one, or [`SeamError::PartsFailed`].
    pub(crate) fn parts_failed(found: Vec<SeamError>) -> Option<SeamError> {
        SeamError::one_or_many(found, SeamError::PartsFailed)
    }

    /// Each plane a retry moves off a point, with the point, where this
    /// is a cut meeting a point within tolerance or a degenerate
    /// configuration ([`SeamError::PlaneNearPoint`],
    /// [`SeamError::DegenerateCut`], each of
    /// [`SeamError::PlanesNearPoints`]); empty otherwise.
    pub fn planes_near_points(&self) -> Vec<(SplitPlane, Vec3)> {
        match self {
            SeamError::PlaneNearPoint { plane, point, .. }
            | SeamError::DegenerateCut { plane, point, .. } => vec![(*plane, *point)],
            SeamError::PlanesNearPoints(all) => {
                all.iter().flat_map(SeamError::planes_near_points).collect()
            }
            _ => Vec::new(),
        }
    }

    /// The part whose walls a retry moves, where this is TetGen failing on
    /// one part in a way a slightly different PLC may not meet: running
    /// past its time limit (its boundary recovery under `-Y` looping), a
    /// crash, its own internal or small-feature errors, or Steiner points
    /// that flatten tets when rounded to f32; or a job's part whose input
    /// failed so before ([`SeamError::FailedBefore`]); or a piece of the
    /// part's clipped triangles that rounding left untriangulable
    /// ([`SeamError::PartPiece`]).
    pub fn part_to_retry(&self) -> Option<usize> {
        match self {
            SeamError::Tetgen {
                part,
                source:
                    TetgenError::Timeout { .. }
                    | TetgenError::Internal
                    | TetgenError::SmallFeature
                    | TetgenError::CloseFacets
                    | TetgenError::Other(_)
                    | TetgenError::WorkerDied { .. },
            }
            | SeamError::RoundingFlattens { part, .. }
            | SeamError::FailedBefore { part, .. }
            | SeamError::PartPiece { part, .. } => Some(*part),
            _ => None,
        }
    }

    /// Every part whose walls a retry moves ([`SeamError::part_to_retry`],
    /// also for each of [`SeamError::PartsFailed`]); empty when this
    /// failure is not one a retry may cure.
    pub fn parts_to_retry(&self) -> Vec<usize> {
        match self {
            SeamError::PartsFailed(all) => {
                all.iter().filter_map(SeamError::part_to_retry).collect()
            }
            e => e.part_to_retry().into_iter().collect(),
        }
    }
}

/// A failure of the part files or of the streaming merge; each names the
/// part (its index and file) and the element at fault.
#[derive(Debug, Error)]
pub enum StreamError {
    /// A part file or the mesh file could not be written or read, or is
    /// malformed.
    #[error(transparent)]
    Format(#[from] FormatError),
    /// The directory for the part files could not be made.
    #[error("{dir}: cannot make the part files' directory: {source}", dir = .dir.display())]
    WorkDir {
        /// The directory.
        dir: PathBuf,
        /// The underlying error.
        source: io::Error,
    },
    /// A part could not be Hilbert-sorted.
    #[error("part {part}: Hilbert sort: {source}")]
    Sort {
        /// Part index.
        part: usize,
        /// The reorder's error.
        source: PermutationError,
    },
    /// Two part files disagree on the number of scene triangles.
    #[error("part {part} ({path}) has {found} scene triangles, part 0 has {expected}", path = .path.display())]
    TriangleCount {
        /// Part index.
        part: usize,
        /// Its file.
        path: PathBuf,
        /// Triangles it records.
        found: u32,
        /// Triangles part 0 records.
        expected: u32,
    },
    /// An element of a part file refers past the end of what it indexes.
    #[error("part {part} ({path}): {element} {index} refers to {value}, past the {count} it may index", path = .path.display())]
    OutOfBounds {
        /// Part index.
        part: usize,
        /// Its file.
        path: PathBuf,
        /// What refers (`"tet vertex"`, `"neighbour link"`, …).
        element: &'static str,
        /// Index of the referring element within the part.
        index: u64,
        /// The value found.
        value: u64,
        /// How many there are to refer to.
        count: u64,
    },
    /// A point on a seam occurs twice in one part (two points of the part
    /// rounded to the same f32 position).
    #[error("part {part}: seam point {point} at {position:?} repeats an earlier point of the part")]
    RepeatedSeamPoint {
        /// Part index.
        part: usize,
        /// Local point index.
        point: u32,
        /// Its position.
        position: Vec3,
    },
    /// A part file changed between the merge's passes.
    #[error("part {part} ({path}) changed during the merge", path = .path.display())]
    Changed {
        /// Part index.
        part: usize,
        /// Its file.
        path: PathBuf,
    },
    /// A face lying in a seam does not match across it.
    #[error(
        "part {part}: face {face} of tet {tet} (global vertices {vertices:?}) lies in a seam but {detail}"
    )]
    SeamFace {
        /// Part index.
        part: usize,
        /// Local tet index.
        tet: u32,
        /// Face of the tet.
        face: u8,
        /// Global vertex ids of the face.
        vertices: [u32; 3],
        /// What is wrong.
        detail: &'static str,
    },
}
