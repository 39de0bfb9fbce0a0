//! [`TetgenError`]: TetGen's failure codes and our own checks, as typed
//! errors.

use thiserror::Error;

use super::ffi;

/// A failure to tetrahedralize, with TetGen's meaning where TetGen reported it.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum TetgenError {
    /// The PLC has no points or no triangles.
    #[error("empty input: {points} points, {triangles} triangles")]
    EmptyInput {
        /// Number of points.
        points: usize,
        /// Number of triangles.
        triangles: usize,
    },
    /// More elements than TetGen's 32-bit indices hold.
    #[error("input too large: {what} = {count}")]
    TooLarge {
        /// What was counted.
        what: &'static str,
        /// How many.
        count: usize,
    },
    /// `markers` does not have one entry per triangle.
    #[error("{markers} markers for {triangles} triangles")]
    MarkerCount {
        /// Number of markers.
        markers: usize,
        /// Number of triangles.
        triangles: usize,
    },
    /// A point coordinate is NaN or infinite.
    #[error("point {point} has a non-finite coordinate {coords:?}")]
    NonFinitePoint {
        /// Point index.
        point: u32,
        /// Its coordinates.
        coords: [f64; 3],
    },
    /// A triangle names a point that does not exist.
    #[error("triangle {triangle}: vertex {vertex} is out of range ({points} points)")]
    VertexOutOfRange {
        /// Triangle index.
        triangle: u32,
        /// Offending vertex id.
        vertex: u32,
        /// Number of points.
        points: usize,
    },
    /// A triangle repeats a vertex id.
    #[error("triangle {triangle} repeats vertex {vertex}")]
    RepeatedVertex {
        /// Triangle index.
        triangle: u32,
        /// The repeated vertex.
        vertex: u32,
    },
    /// A triangle's three points are collinear (exact test).
    #[error("triangle {triangle} {vertices:?} is degenerate (collinear points)")]
    DegenerateTriangle {
        /// Triangle index.
        triangle: u32,
        /// Its vertices.
        vertices: [u32; 3],
    },
    /// Two triangles have the same three vertices.
    #[error("triangles {first} and {second} are the same facet {vertices:?}")]
    DuplicateTriangle {
        /// First triangle index.
        first: u32,
        /// Second triangle index.
        second: u32,
        /// Sorted vertex ids.
        vertices: [u32; 3],
    },
    /// An option value is invalid.
    #[error("invalid TetGen option: {0}")]
    BadOption(String),
    /// TetGen rejected the switch string.
    #[error("TetGen rejected the switches {0:?}")]
    BadSwitches(String),
    /// All input points are coplanar: no tetrahedron exists.
    #[error("input is flat: all points are coplanar")]
    FlatInput,
    /// TetGen code 1.
    #[error("TetGen ran out of memory (code 1)")]
    OutOfMemory,
    /// TetGen code 2: an internal inconsistency (TetGen asks for a bug report).
    #[error("TetGen internal error (code 2)")]
    Internal,
    /// TetGen code 3: input facets intersect each other.
    #[error("TetGen detected a self-intersection of the input (code 3)")]
    SelfIntersection,
    /// TetGen code 4: a feature smaller than the tolerance (`-T`).
    #[error(
        "TetGen detected a very small input feature (code 4); try a smaller coplanar tolerance"
    )]
    SmallFeature,
    /// TetGen code 5: two facets are (nearly) coincident.
    #[error("TetGen detected two very close input facets (code 5)")]
    CloseFacets,
    /// TetGen code 10: an input error (e.g. an invalid PLC).
    #[error("TetGen detected an input error (code 10)")]
    InputError,
    /// Another code from `terminatetetgen`, or an unexpected C++ exception (-4).
    #[error("TetGen stopped with code {0}")]
    Other(i32),
    /// The worker exceeded its time limit and was killed.
    #[error("TetGen worker exceeded its time limit of {seconds:.1} s and was killed")]
    Timeout {
        /// The limit.
        seconds: f64,
    },
    /// The worker died without a reply (crash, abort, signal).
    #[error("TetGen worker died: {status}; stderr tail: {stderr}")]
    WorkerDied {
        /// Exit status in words.
        status: String,
        /// Last lines of its stderr.
        stderr: String,
    },
    /// The worker could not be started or talked to.
    #[error("TetGen worker I/O: {0}")]
    WorkerIo(String),
    /// The worker's reply (or a request) is malformed.
    #[error("TetGen worker protocol: {0}")]
    Protocol(String),
}

impl TetgenError {
    /// Maps a shim status code to an error.
    pub fn from_code(code: i32, switches: &str) -> TetgenError {
        match code {
            ffi::BAD_SWITCHES => TetgenError::BadSwitches(switches.to_string()),
            ffi::FLAT_INPUT => TetgenError::FlatInput,
            1 => TetgenError::OutOfMemory,
            2 => TetgenError::Internal,
            3 => TetgenError::SelfIntersection,
            4 => TetgenError::SmallFeature,
            5 => TetgenError::CloseFacets,
            10 => TetgenError::InputError,
            c => TetgenError::Other(c),
        }
    }

    /// The status code this error travels as between worker and host (inverse
    /// of [`TetgenError::from_code`] for TetGen's own failures).
    pub(super) fn code(&self) -> Option<i32> {
        Some(match self {
            TetgenError::BadSwitches(_) => ffi::BAD_SWITCHES,
            TetgenError::FlatInput => ffi::FLAT_INPUT,
            TetgenError::OutOfMemory => 1,
            TetgenError::Internal => 2,
            TetgenError::SelfIntersection => 3,
            TetgenError::SmallFeature => 4,
            TetgenError::CloseFacets => 5,
            TetgenError::InputError => 10,
            TetgenError::Other(c) => *c,
            _ => return None,
        })
    }
}
