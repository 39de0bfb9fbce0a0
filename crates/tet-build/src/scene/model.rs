//! The scene itself: [`Scene`] (world-space triangles, camera, lights),
//! its objects, and assembling one from placed local meshes.

use std::path::Path;

use glam::{Vec2, Vec3};
use tet_core::scene::{Camera, PointLight};

use super::error::SceneError;
use super::obj::{self, MeshData};
use super::transform::{Affine, Transform};

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
        // The arrays at their final size from the start where no attribute
        // splits a vertex (a lower bound otherwise): grown by doubling,
        // they held up to twice the scene, on scenes of millions of
        // triangles the largest item of a planner's memory.
        let vertices: usize = objects.iter().map(|o| o.mesh.positions.len()).sum();
        let triangles: usize = objects.iter().map(|o| o.mesh.triangles.len()).sum();
        scene.vertices.reserve_exact(vertices);
        scene.triangles.reserve_exact(triangles);
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
