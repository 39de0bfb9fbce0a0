//! Triangle scenes: the builder's input.
//!
//! A [`Scene`] is world-space geometry (all object transforms applied), the
//! camera and the point lights. Sources:
//!
//! * a plain OBJ file ([`Scene::load_obj`]): a one-object scene;
//! * a named scene of `scenes.json` ([`scenes_json::load_scene`], or the spec
//!   string `path/scenes.json#Torus Knots` given to [`Scene::load`]); OBJ
//!   paths resolve relative to the json file;
//! * a procedural scene ([`crate::procedural::by_name`]), needing no files.
//!
//! Vertex normals and texture coordinates are kept only when *every* object
//! has them (a scene pays only for what it uses).

pub mod obj;
pub mod scenes_json;
pub mod transform;

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use tet_core::scene::{Camera, PointLight};
use thiserror::Error;

pub use obj::{FlatMesh, MeshData};
pub use transform::{Affine, Transform, orbit_camera};

/// A triangle scene in world space, after object transforms.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scene {
    /// Scene name (for reports).
    pub name: String,
    /// World-space vertex positions.
    pub vertices: Vec<Vec3>,
    /// Triangles as vertex indices, counter-clockwise = front (outward) side.
    pub triangles: Vec<[u32; 3]>,
    /// Per-vertex normals, when every object has them.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates, when every object has them.
    pub uvs: Option<Vec<Vec2>>,
    /// Objects in order; each owns a contiguous range of `triangles`.
    pub objects: Vec<SceneObject>,
    /// Camera, when the scene defines one.
    pub camera: Option<Camera>,
    /// Point lights.
    pub lights: Vec<PointLight>,
}

/// One object of a scene: a name and the range of triangles it contributed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneObject {
    /// Object name.
    pub name: String,
    /// First triangle index.
    pub first_triangle: u32,
    /// Number of triangles.
    pub triangle_count: u32,
    /// First vertex index (each object owns a contiguous vertex range too).
    pub first_vertex: u32,
    /// Number of vertices.
    pub vertex_count: u32,
    /// True when the object's transform mirrors it (negative determinant):
    /// its triangles face the other side of the original surface, e.g. the
    /// inward-facing box of the "in a Box" scenes.
    pub mirrored: bool,
}

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
    /// An object's mesh is not part of the data set.
    #[error(
        "{path}: scene {scene:?} object {object} ({name:?}) needs mesh {mesh:?}, which is not available"
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

/// Load a scene from a spec string (alias of [`Scene::load`]):
/// `path/scenes.json#Torus Knots`, `mesh.obj`, or a procedural name.
pub fn load_scene_spec(spec: &str) -> Result<Scene, SceneError> {
    Scene::load(spec)
}

/// One object to place into a scene: a local mesh and its transforms.
#[derive(Clone, Debug)]
pub struct ObjectPlacement<'a> {
    /// Object name.
    pub name: String,
    /// Local mesh.
    pub mesh: &'a MeshData,
    /// Object transform.
    pub transform: Transform,
    /// Mesh pre-transform, applied before `transform`.
    pub pre_transform: Option<Transform>,
}

impl Scene {
    /// Load from a spec string: `file.obj`, `scenes.json#Scene Name`, or a
    /// procedural name (see [`crate::procedural::NAMES`]).
    pub fn load(spec: &str) -> Result<Scene, SceneError> {
        if let Some((path, name)) = spec.rsplit_once('#') {
            return scenes_json::load_scene(Path::new(path), name);
        }
        if spec.to_ascii_lowercase().ends_with(".json") {
            let file = scenes_json::ScenesFile::open(Path::new(spec))?;
            return Err(SceneError::UnknownScene {
                path: spec.into(),
                name: String::new(),
                available: file.scene_names()?,
            });
        }
        if spec.to_ascii_lowercase().ends_with(".obj") {
            return Scene::load_obj(Path::new(spec));
        }
        if let Some(scene) = crate::procedural::by_name(spec) {
            return Ok(scene);
        }
        Err(SceneError::BadSpec {
            spec: spec.into(),
            message: format!(
                "expected an .obj path, `scenes.json#Scene Name`, or one of the procedural scenes: {}",
                crate::procedural::NAMES.join(", ")
            ),
        })
    }

    /// A one-object scene from an OBJ file (identity transform, no camera,
    /// no lights).
    pub fn load_obj(path: &Path) -> Result<Scene, SceneError> {
        let mesh = obj::load_obj(path)?;
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        Scene::from_objects(
            &name,
            &[ObjectPlacement {
                name: name.clone(),
                mesh: &mesh,
                transform: Transform::IDENTITY,
                pre_transform: None,
            }],
            None,
            Vec::new(),
        )
    }

    /// Assemble a world-space scene from placed local meshes. Normals/uvs are
    /// kept only when every object has them.
    pub fn from_objects(
        name: &str,
        objects: &[ObjectPlacement<'_>],
        camera: Option<Camera>,
        lights: Vec<PointLight>,
    ) -> Result<Scene, SceneError> {
        let keep_normals = !objects.is_empty() && objects.iter().all(|o| o.mesh.normals.is_some());
        let keep_uvs = !objects.is_empty() && objects.iter().all(|o| o.mesh.uvs.is_some());
        let mut scene = Scene {
            name: name.into(),
            normals: keep_normals.then(Vec::new),
            uvs: keep_uvs.then(Vec::new),
            camera,
            lights,
            ..Scene::default()
        };
        for o in objects {
            let flat = o.mesh.flatten(keep_normals, keep_uvs);
            let affine = Affine::compose(&o.transform, o.pre_transform.as_ref());
            let too_large = |what| SceneError::TooLarge {
                scene: name.into(),
                what,
            };
            let base = u32::try_from(scene.vertices.len()).map_err(|_| too_large("vertices"))?;
            let first_triangle =
                u32::try_from(scene.triangles.len()).map_err(|_| too_large("triangles"))?;
            if scene.vertices.len() + flat.positions.len() > u32::MAX as usize
                || scene.triangles.len() + flat.triangles.len() > u32::MAX as usize
            {
                return Err(too_large("vertices or triangles"));
            }
            for (i, p) in flat.positions.iter().enumerate() {
                let w = affine.point(*p);
                if !w.is_finite() {
                    return Err(SceneError::NonFiniteTransformed {
                        scene: name.into(),
                        object: o.name.clone(),
                        vertex: i as u32,
                    });
                }
                scene.vertices.push(w);
            }
            if let (Some(out), Some(ns)) = (scene.normals.as_mut(), flat.normals.as_ref()) {
                out.extend(ns.iter().map(|n| affine.normal(*n)));
            }
            if let (Some(out), Some(us)) = (scene.uvs.as_mut(), flat.uvs.as_ref()) {
                out.extend_from_slice(us);
            }
            scene
                .triangles
                .extend(flat.triangles.iter().map(|t| t.map(|v| v + base)));
            scene.objects.push(SceneObject {
                name: o.name.clone(),
                first_triangle,
                triangle_count: flat.triangles.len() as u32,
                first_vertex: base,
                vertex_count: flat.positions.len() as u32,
                mirrored: affine.mirrors,
            });
        }
        Ok(scene)
    }

    /// Axis-aligned bounds `(min, max)` of the vertices referenced by
    /// triangles (`None` for a scene without triangles).
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut it = self.triangles.iter().flatten();
        let first = self.vertices[*it.next()? as usize];
        Some(it.fold((first, first), |(lo, hi), &i| {
            let p = self.vertices[i as usize];
            (lo.min(p), hi.max(p))
        }))
    }

    /// The object owning triangle `t` (binary search over the ranges).
    pub fn object_of_triangle(&self, t: u32) -> Option<usize> {
        let i = self
            .objects
            .partition_point(|o| o.first_triangle + o.triangle_count <= t);
        (i < self.objects.len() && self.objects[i].first_triangle <= t).then_some(i)
    }
}
