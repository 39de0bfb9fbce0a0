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
//!
//! Modules, bottom up: [`error`]; [`transform`] and [`obj`] (local meshes);
//! [`model`] (the [`Scene`] type, assembled from placed meshes);
//! [`scenes_json`] (named scenes of a json file). Spec strings
//! ([`Scene::load`]) are resolved by [`crate::source`], above these and the
//! procedural scenes.

pub mod error;
pub mod model;
pub mod obj;
pub mod scenes_json;
pub mod transform;

pub use error::SceneError;
pub use model::{ObjectPlacement, Scene, SceneObject};
pub use obj::{FlatMesh, MeshData};
pub use transform::{Affine, Transform, orbit_camera};
