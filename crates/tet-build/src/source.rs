//! Scene sources named by a spec string: a plain OBJ file, a named scene of
//! a `scenes.json` file, or a procedural scene. Above [`crate::scene`] and
//! [`crate::procedural`], which it chooses between.

use std::path::Path;

use crate::procedural;
use crate::scene::{Scene, SceneError, scenes_json};

/// Load a scene from a spec string (alias of [`Scene::load`]):
/// `path/scenes.json#Torus Knots`, `mesh.obj`, or a procedural name.
pub fn load_scene_spec(spec: &str) -> Result<Scene, SceneError> {
    Scene::load(spec)
}

impl Scene {
    /// Load from a spec string: `file.obj`, `scenes.json#Scene Name`, or a
    /// procedural name (see [`procedural::SCENES`]).
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
            return Scene::load_obj(Path::new(spec))
                .map_err(|e| scenes_json::with_obtain_from(e, Path::new(spec)));
        }
        if let Some(scene) = procedural::by_name(spec) {
            return Ok(scene);
        }
        Err(SceneError::BadSpec {
            spec: spec.into(),
            message: format!(
                "expected an .obj path, `scenes.json#Scene Name`, or one of the procedural scenes: {}",
                procedural::SCENES
                    .iter()
                    .map(|p| p.name)
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        })
    }
}
