//! [`SceneError`]: why a scene could not be loaded or assembled.

use std::path::PathBuf;

use thiserror::Error;

/// Failure to load or assemble a scene; every variant names the file and the
/// line, field or object at fault.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SceneError {
    /// A file could not be read.
    #[error("{path}: cannot read: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        message: String,
    },
    /// Malformed OBJ content.
    #[error("{path}{}: {message}", line.map(|l| format!(":{l}")).unwrap_or_default())]
    ObjParse {
        /// The file.
        path: PathBuf,
        /// 1-based line, when known.
        line: Option<usize>,
        /// What is wrong.
        message: String,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("{path}:{line}: vertex {vertex} has a non-finite coordinate")]
    NonFiniteCoordinate {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// 0-based vertex index.
        vertex: u32,
    },
    /// A vertex became NaN/inf after its object transform (or a procedural
    /// mesh produced one).
    #[error("scene {scene:?} object {object:?}: vertex {vertex} is non-finite after the transform")]
    NonFiniteTransformed {
        /// Scene name.
        scene: String,
        /// Object name.
        object: String,
        /// Vertex index within the object.
        vertex: u32,
    },
    /// A face index points outside the list it indexes.
    #[error("{path}:{line}: {kind} index {index} is out of range ({count} defined)")]
    IndexOutOfRange {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// Which list (position, normal, texture coordinate).
        kind: &'static str,
        /// The index as written (1-based or negative).
        index: i64,
        /// How many entries were defined.
        count: usize,
    },
    /// Invalid JSON syntax.
    #[error("{path}:{line}:{column}: invalid JSON: {message}")]
    Json {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// Parser message.
        message: String,
    },
    /// A JSON field is missing or has the wrong type or value.
    #[error("{path}: field `{field}`: {message}")]
    JsonField {
        /// The file.
        path: PathBuf,
        /// JSON path of the field, e.g. `scenes[1].objects[3].scale`.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// No scene of that name in the file.
    #[error("{path}: no scene named {name:?}; available: {}", available.join(", "))]
    UnknownScene {
        /// The file.
        path: PathBuf,
        /// Requested name.
        name: String,
        /// Scene names in the file.
        available: Vec<String>,
    },
    /// An object's mesh is not part of the data set (or not in the
    /// directory of the json file).
    #[error(
        "{path}: scene {scene:?} object {object} ({name:?}) needs mesh {mesh:?}, which is not available{}",
        obtain_from.as_deref().map(|h| format!(": {h}")).unwrap_or_default()
    )]
    MissingMesh {
        /// The json file.
        path: PathBuf,
        /// Scene name.
        scene: String,
        /// Object index in the scene.
        object: usize,
        /// Object name.
        name: String,
        /// The missing mesh file.
        mesh: String,
        /// Where to get it: the `obtain_from` of the mesh's entry in the
        /// json file's `meshes`, when it has one (boxed: the error stays
        /// small).
        obtain_from: Option<Box<str>>,
    },
    /// A spec string is neither an OBJ path, a `json#scene` spec nor a
    /// procedural scene name.
    #[error("cannot interpret scene spec {spec:?}: {message}")]
    BadSpec {
        /// The spec.
        spec: String,
        /// Why.
        message: String,
    },
    /// The scene is too large for 32-bit indices.
    #[error("scene {scene:?} has too many {what} for u32 indices")]
    TooLarge {
        /// Scene name.
        scene: String,
        /// What overflowed.
        what: &'static str,
    },
}
