//! Triangle scenes: the builder's input.

use glam::{Vec2, Vec3};
use tet_core::scene::{Camera, PointLight};

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
}
pub mod obj;
pub mod scenes_json;
pub mod transform;
