//! The scene list `scenes/scenes.json` (in the repository root; transcribed
//! from the authors' renderer neptun): load any scene of it by name.
//!
//! Format (documented in the file itself): top-level `conventions`, `meshes`
//! (key → `file`, optional `pre_transform {scale, rotation_deg, translation}`)
//! and `scenes` (a list). Each scene has `name`, `camera` (`orbit_x_rad`,
//! `orbit_y_rad`, `distance`, `target`; the stored `position` is derived
//! from these), `lights` (`position`, `color`, `intensity`, `type: "point"`)
//! and `objects` (`name`, `mesh` key, `file`, `translation`, `rotation_deg`,
//! `scale`; objects with `mesh: null` and no `paper_mesh_file` are empty
//! placeholders and are skipped, while a `paper_mesh_file` without a `file`
//! means the mesh is not in the data set → [`SceneError::MissingMesh`]).
//! OBJ files are looked up beside the json file; a mesh entry may say where
//! to get a file that is not there (`in_repository: false`, `obtain_from`),
//! and [`SceneError::MissingMesh`] then repeats it.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::DVec3;
use serde_json::Value;
use tet_core::scene::PointLight;

use super::error::SceneError;
use super::model::{ObjectPlacement, Scene};
use super::obj::{MeshData, load_obj};
use super::transform::{Transform, orbit_camera};

/// Parsed `scenes.json`, kept as a JSON value with its path for messages.
#[derive(Clone, Debug)]
pub struct ScenesFile {
    path: PathBuf,
    root: Value,
}

/// Camera parameters of a scene as stored in the json file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitSpec {
    /// Elevation angle (radians).
    pub orbit_x_rad: f64,
    /// Azimuth angle (radians).
    pub orbit_y_rad: f64,
    /// Distance from the target.
    pub distance: f64,
    /// Look-at target.
    pub target: DVec3,
    /// The position stored in the file (for cross-checking the orbit formula).
    pub stored_position: Option<DVec3>,
}

/// Load scene `name` of the json file at `path`.
pub fn load_scene(path: &Path, name: &str) -> Result<Scene, SceneError> {
    ScenesFile::open(path)?.load(name)
}

impl ScenesFile {
    /// Read and parse the json file.
    pub fn open(path: &Path) -> Result<ScenesFile, SceneError> {
        let text = std::fs::read_to_string(path).map_err(|e| SceneError::Io {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        ScenesFile::parse(&text, path)
    }

    /// Parse json text; `path` is used to resolve OBJ files and in messages.
    pub fn parse(text: &str, path: &Path) -> Result<ScenesFile, SceneError> {
        let root: Value = serde_json::from_str(text).map_err(|e| SceneError::Json {
            path: path.to_path_buf(),
            line: e.line(),
            column: e.column(),
            message: e.to_string(),
        })?;
        let file = ScenesFile {
            path: path.to_path_buf(),
            root,
        };
        file.scenes()?;
        Ok(file)
    }

    fn err(&self, field: impl Into<String>, message: impl Into<String>) -> SceneError {
        SceneError::JsonField {
            path: self.path.clone(),
            field: field.into(),
            message: message.into(),
        }
    }

    fn scenes(&self) -> Result<&Vec<Value>, SceneError> {
        self.root
            .get("scenes")
            .and_then(Value::as_array)
            .ok_or_else(|| self.err("scenes", "missing or not a list"))
    }

    /// Names of all scenes, in file order.
    pub fn scene_names(&self) -> Result<Vec<String>, SceneError> {
        self.scenes()?
            .iter()
            .enumerate()
            .map(|(i, s)| self.string(s, &format!("scenes[{i}]"), "name"))
            .collect()
    }

    fn find(&self, name: &str) -> Result<(usize, &Value), SceneError> {
        let scenes = self.scenes()?;
        for (i, s) in scenes.iter().enumerate() {
            if s.get("name").and_then(Value::as_str) == Some(name) {
                return Ok((i, s));
            }
        }
        Err(SceneError::UnknownScene {
            path: self.path.clone(),
            name: name.into(),
            available: self.scene_names()?,
        })
    }

    fn string(&self, v: &Value, ctx: &str, key: &str) -> Result<String, SceneError> {
        v.get(key)
            .and_then(Value::as_str)
            .map(str::to_owned)
            .ok_or_else(|| self.err(format!("{ctx}.{key}"), "missing or not a string"))
    }

    fn number(&self, v: &Value, ctx: &str, key: &str) -> Result<f64, SceneError> {
        v.get(key)
            .and_then(Value::as_f64)
            .ok_or_else(|| self.err(format!("{ctx}.{key}"), "missing or not a number"))
    }

    fn vec3(&self, v: &Value, ctx: &str, key: &str) -> Result<DVec3, SceneError> {
        let field = format!("{ctx}.{key}");
        let arr = v
            .get(key)
            .and_then(Value::as_array)
            .ok_or_else(|| self.err(&field, "missing or not a list of 3 numbers"))?;
        if arr.len() != 3 {
            return Err(self.err(&field, format!("has {} entries, expected 3", arr.len())));
        }
        let mut out = [0.0; 3];
        for (k, x) in arr.iter().enumerate() {
            out[k] = x
                .as_f64()
                .ok_or_else(|| self.err(format!("{field}[{k}]"), "not a number"))?;
        }
        Ok(DVec3::from_array(out))
    }

    fn transform(&self, v: &Value, ctx: &str) -> Result<Transform, SceneError> {
        let t = Transform {
            translation: self.vec3(v, ctx, "translation")?,
            rotation_deg: self.vec3(v, ctx, "rotation_deg")?,
            scale: self.vec3(v, ctx, "scale")?,
        };
        if t.scale.x * t.scale.y * t.scale.z == 0.0 {
            return Err(self.err(format!("{ctx}.scale"), "a scale factor is zero"));
        }
        Ok(t)
    }

    /// Where to get mesh file `file` when it is not beside the json file:
    /// the `obtain_from` of the mesh entry `key`, else of any mesh entry
    /// whose `file` is `file`.
    pub fn obtain_from(&self, key: Option<&str>, file: &str) -> Option<String> {
        let meshes = self.root.get("meshes")?.as_object()?;
        let hint = |m: &Value| m.get("obtain_from")?.as_str().map(str::to_owned);
        key.and_then(|k| meshes.get(k)).and_then(hint).or_else(|| {
            meshes
                .values()
                .filter(|m| m.get("file").and_then(Value::as_str) == Some(file))
                .find_map(hint)
        })
    }

    /// The orbit camera parameters of scene `name`.
    pub fn camera_spec(&self, name: &str) -> Result<OrbitSpec, SceneError> {
        let (i, s) = self.find(name)?;
        let ctx = format!("scenes[{i}].camera");
        let cam = s.get("camera").ok_or_else(|| self.err(&ctx, "missing"))?;
        Ok(OrbitSpec {
            orbit_x_rad: self.number(cam, &ctx, "orbit_x_rad")?,
            orbit_y_rad: self.number(cam, &ctx, "orbit_y_rad")?,
            distance: self.number(cam, &ctx, "distance")?,
            target: self.vec3(cam, &ctx, "target")?,
            stored_position: self.vec3(cam, &ctx, "position").ok(),
        })
    }

    /// Build scene `name`: loads each distinct OBJ once, applies the mesh
    /// pre-transform and the object transform.
    pub fn load(&self, name: &str) -> Result<Scene, SceneError> {
        let (si, s) = self.find(name)?;
        let sctx = format!("scenes[{si}]");
        let cam = self.camera_spec(name)?;
        let camera = orbit_camera(cam.orbit_x_rad, cam.orbit_y_rad, cam.distance, cam.target);

        let mut lights = Vec::new();
        if let Some(list) = s.get("lights") {
            let list = list
                .as_array()
                .ok_or_else(|| self.err(format!("{sctx}.lights"), "not a list"))?;
            for (li, l) in list.iter().enumerate() {
                let ctx = format!("{sctx}.lights[{li}]");
                if let Some(ty) = l.get("type").and_then(Value::as_str)
                    && ty != "point"
                {
                    return Err(self.err(
                        format!("{ctx}.type"),
                        format!("unsupported light type {ty:?}"),
                    ));
                }
                lights.push(PointLight {
                    position: self.vec3(l, &ctx, "position")?.as_vec3(),
                    color: self.vec3(l, &ctx, "color")?.as_vec3(),
                    intensity: self.number(l, &ctx, "intensity")? as f32,
                });
            }
        }

        let objects = s
            .get("objects")
            .and_then(Value::as_array)
            .ok_or_else(|| self.err(format!("{sctx}.objects"), "missing or not a list"))?;
        let base_dir = self.path.parent().unwrap_or(Path::new("."));
        let mut cache: HashMap<String, MeshData> = HashMap::new();
        // (name, file key, transform, pre-transform)
        let mut placements: Vec<(String, String, Transform, Option<Transform>)> = Vec::new();
        for (oi, o) in objects.iter().enumerate() {
            let ctx = format!("{sctx}.objects[{oi}]");
            let oname = o
                .get("name")
                .and_then(Value::as_str)
                .unwrap_or("")
                .to_owned();
            let mesh_key = o.get("mesh").and_then(Value::as_str);
            let mut file = o.get("file").and_then(Value::as_str).map(str::to_owned);
            let mut pre = None;
            if let Some(key) = mesh_key {
                let mctx = format!("meshes.{key}");
                let m = self
                    .root
                    .get("meshes")
                    .and_then(|ms| ms.get(key))
                    .ok_or_else(|| {
                        self.err(format!("{ctx}.mesh"), format!("unknown mesh key {key:?}"))
                    })?;
                if file.is_none() {
                    file = Some(self.string(m, &mctx, "file")?);
                }
                if let Some(p) = m.get("pre_transform").filter(|p| !p.is_null()) {
                    pre = Some(self.transform(p, &format!("{mctx}.pre_transform"))?);
                }
            }
            let Some(file) = file else {
                if let Some(paper) = o.get("paper_mesh_file").and_then(Value::as_str) {
                    return Err(SceneError::MissingMesh {
                        path: self.path.clone(),
                        scene: name.into(),
                        object: oi,
                        name: oname,
                        mesh: paper.into(),
                        obtain_from: None,
                    });
                }
                continue; // empty placeholder object
            };
            let transform = self.transform(o, &ctx)?;
            if !cache.contains_key(&file) {
                let full = base_dir.join(&file);
                if !full.exists() {
                    return Err(SceneError::MissingMesh {
                        path: self.path.clone(),
                        scene: name.into(),
                        object: oi,
                        name: oname,
                        mesh: full.display().to_string(),
                        obtain_from: self
                            .obtain_from(mesh_key, &file)
                            .map(String::into_boxed_str),
                    });
                }
                cache.insert(file.clone(), load_obj(&full)?);
            }
            placements.push((oname, file, transform, pre));
        }
        let placed: Vec<ObjectPlacement<'_>> = placements
            .iter()
            .map(|(n, f, t, p)| ObjectPlacement {
                name: n.clone(),
                mesh: &cache[f],
                transform: *t,
                pre_transform: *p,
            })
            .collect();
        let mut scene = Scene::from_objects(name, &placed, Some(camera), lights)?;
        scene.name = name.into();
        Ok(scene)
    }
}

/// `error` with, for an OBJ file that does not exist, where to get it when
/// a `scenes.json` beside it says so (`obtain_from` of the mesh entry whose
/// `file` is the file's name); any other error as it is.
pub fn with_obtain_from(error: SceneError, obj: &Path) -> SceneError {
    let SceneError::Io { path, message } = error else {
        return error;
    };
    let hint = (!obj.exists())
        .then(|| {
            let json = obj.parent().unwrap_or(Path::new(".")).join("scenes.json");
            let file = obj.file_name()?.to_str()?;
            ScenesFile::open(&json).ok()?.obtain_from(None, file)
        })
        .flatten();
    SceneError::Io {
        path,
        message: match hint {
            Some(h) => format!("{message}; {h}"),
            None => message,
        },
    }
}
