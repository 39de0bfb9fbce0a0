//! Typed errors of the canonical mesh: each names the offending element.

use thiserror::Error;

/// A violated invariant of [`crate::TetMesh`], or a failure to assemble one.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MeshError {
    /// The mesh holds more tets or constrained faces than a [`crate::Link`] can index.
    #[error("{what}: {count} exceeds the limit of {limit}")]
    TooMany {
        /// What was counted.
        what: &'static str,
        /// How many there are.
        count: usize,
        /// The limit.
        limit: usize,
    },
    /// A per-element array has the wrong length.
    #[error("{array} has {actual} entries, expected {expected}")]
    LengthMismatch {
        /// Name of the array.
        array: &'static str,
        /// Length found.
        actual: usize,
        /// Length expected.
        expected: usize,
    },
    /// A point coordinate is NaN or infinite.
    #[error("point {point} has a non-finite coordinate")]
    NonFinitePoint {
        /// Point index.
        point: u32,
    },
    /// A tet references a vertex that does not exist.
    #[error("tet {tet} slot {slot}: vertex {vertex} is out of bounds ({points} points)")]
    VertexOutOfBounds {
        /// Tet index.
        tet: u32,
        /// Vertex slot 0..4.
        slot: u8,
        /// Offending vertex index.
        vertex: u32,
        /// Number of points.
        points: usize,
    },
    /// A tet lists the same vertex twice.
    #[error("tet {tet} repeats vertex {vertex}")]
    RepeatedVertex {
        /// Tet index.
        tet: u32,
        /// The repeated vertex.
        vertex: u32,
    },
    /// A tet is not positively oriented (flat or inverted).
    #[error("tet {tet} is not positively oriented (exact orient3d = {orientation:e})")]
    NotPositive {
        /// Tet index.
        tet: u32,
        /// Exact orientation value (≤ 0).
        orientation: f64,
    },
    /// A neighbour link names a tet that does not exist.
    #[error("tet {tet} face {face}: neighbour {neighbor} is out of bounds ({tets} tets)")]
    NeighborOutOfBounds {
        /// Tet index.
        tet: u32,
        /// Face 0..4.
        face: u8,
        /// Offending neighbour index.
        neighbor: u32,
        /// Number of tets.
        tets: usize,
    },
    /// Neighbour `face` of `tet` is `neighbor`, but `neighbor` shares no face with `tet`
    /// pointing back.
    #[error("tet {tet} face {face}: neighbour {neighbor} does not link back")]
    NeighborNotSymmetric {
        /// Tet index.
        tet: u32,
        /// Face 0..4.
        face: u8,
        /// Neighbour that does not link back.
        neighbor: u32,
    },
    /// Two tets linked as neighbours do not share the face's three vertices.
    #[error("tet {tet} face {face} and neighbour {neighbor} do not share that face's vertices")]
    SharedFaceMismatch {
        /// Tet index.
        tet: u32,
        /// Face 0..4.
        face: u8,
        /// The neighbour.
        neighbor: u32,
    },
    /// A face (as a vertex triple) appears in more than two tets, or in two tets
    /// that are not linked to each other.
    #[error("face {vertices:?} of tet {tet} face {face} is not matched consistently ({detail})")]
    FaceNotManifold {
        /// Tet index.
        tet: u32,
        /// Face 0..4.
        face: u8,
        /// Sorted vertex triple.
        vertices: [u32; 3],
        /// What is wrong.
        detail: &'static str,
    },
    /// A link names a constrained face that does not exist.
    #[error("tet {tet} face {face}: constrained face {index} is out of bounds ({count} faces)")]
    ConstrainedOutOfBounds {
        /// Tet index.
        tet: u32,
        /// Face 0..4.
        face: u8,
        /// Offending index.
        index: u32,
        /// Number of constrained faces.
        count: usize,
    },
    /// The constrained-face table and the links disagree.
    #[error("constrained face {index}: {detail}")]
    ConstrainedBackReference {
        /// Constrained-face index.
        index: u32,
        /// What is wrong.
        detail: String,
    },
    /// A scene triangle given to [`crate::TetMesh::assemble`] matches no face of the mesh.
    #[error("triangle {triangle} (vertices {vertices:?}) is not a face of the tetrahedralization")]
    TriangleNotInMesh {
        /// Source triangle id.
        triangle: u32,
        /// Its vertices.
        vertices: [u32; 3],
    },
    /// Two scene triangles given to [`crate::TetMesh::assemble`] lie on the same face.
    #[error("triangles {first} and {second} lie on the same face {vertices:?}")]
    DuplicateTriangle {
        /// First triangle id.
        first: u32,
        /// Second triangle id.
        second: u32,
        /// Sorted vertex triple.
        vertices: [u32; 3],
    },
    /// An attribute array does not match the number of points or triangles.
    #[error("attribute {name} has {actual} entries, expected {expected}")]
    AttributeLength {
        /// Attribute name.
        name: &'static str,
        /// Length found.
        actual: usize,
        /// Length expected.
        expected: usize,
    },
    /// A scalar field's name cannot be stored.
    #[error("scalar field name {name:?}: {detail}")]
    ScalarName {
        /// The name (first 80 characters).
        name: String,
        /// What is wrong.
        detail: String,
    },
    /// A scalar field has no time step.
    #[error("scalar field {name:?} has no time step")]
    ScalarNoSteps {
        /// The field's name.
        name: String,
    },
    /// A time step of the scalar field does not have one value per point.
    #[error("scalar field step {step} has {actual} values, expected {expected} (one per point)")]
    ScalarLength {
        /// Time step.
        step: usize,
        /// Values found.
        actual: usize,
        /// Number of points.
        expected: usize,
    },
    /// A scalar value is NaN or infinite.
    #[error("scalar field step {step} point {point}: value {value} is not finite")]
    ScalarNotFinite {
        /// Time step.
        step: usize,
        /// Point index.
        point: u32,
        /// The value.
        value: f32,
    },
}
