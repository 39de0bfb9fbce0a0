//! Which scenes a run measures and which of them share a mesh: scenes
//! with the same geometry (the Armadillo Zoom series; Mix and Mix close)
//! are built once, in an enclosing box that holds every camera and light
//! of the group, and the mesh is reused.

use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::path::Path;

use anyhow::{Context, Result};
use glam::Vec3;
use tet_build::scene::Scene;
use tet_core::TetMesh;

use crate::cli::TablesArgs;
use crate::load::build_flags::BuildFlags;
use crate::load::{BuildSummary, Loaded, MESH_EXTENSION, build_scene_in, load, with_mesh};

/// The default run's flat-faced scene ("Flat Parts": CAD-like solids on one
/// shared plane, [`tet_build::flat::flat_parts`]), whose robustness rows
/// take the full run's 10⁸ rays like the first scene's.
pub const FLAT_SCENE: &str = "flat-parts";

/// The scenes of a run: those of `--scenes`, then those of `--scene`;
/// the procedural Torus Knots scenes and [`FLAT_SCENE`] when neither is
/// given.
pub fn scene_specs(args: &TablesArgs) -> Result<Vec<String>> {
    let mut specs = Vec::new();
    if let Some(path) = &args.scenes {
        let file = tet_build::scene::scenes_json::ScenesFile::open(path)?;
        specs.extend(
            file.scene_names()?
                .into_iter()
                .map(|n| format!("{}#{n}", path.display())),
        );
    }
    specs.extend(args.scene.iter().cloned());
    if specs.is_empty() {
        specs = vec![
            "torus-knots".into(),
            "torus-knots-box".into(),
            FLAT_SCENE.into(),
        ];
    }
    Ok(specs)
}

/// A scene of the run, with the scenes sharing its geometry.
#[derive(Clone, Debug)]
pub struct Planned {
    /// Scene spec.
    pub spec: String,
    /// Hash of the geometry (vertices and triangles, exact bits); `None`
    /// for mesh files and scenes that fail to load.
    pub key: Option<u64>,
    /// Cameras and lights of every scene of the group (inside the box).
    pub extra: Vec<Vec3>,
    /// Names of the other scenes of the group.
    pub shares_with: Vec<String>,
    /// First scene of its group.
    #[cfg_attr(not(feature = "tetgen"), allow(dead_code))]
    pub first: bool,
    /// Last scene of its group (the cached meshes are dropped after it).
    pub last: bool,
}

/// Exact hash of a scene's geometry.
fn geometry_key(scene: &Scene) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    scene.vertices.len().hash(&mut h);
    for v in &scene.vertices {
        v.to_array().map(f32::to_bits).hash(&mut h);
    }
    scene.triangles.hash(&mut h);
    h.finish()
}

/// Groups the scenes by geometry (scenes are loaded here once to hash
/// them; load errors are reported when the scene is measured).
pub fn plan(specs: &[String]) -> Vec<Planned> {
    // (name, (geometry key, cameras and lights)) per spec.
    type Hashed = (String, Option<(u64, Vec<Vec3>)>);
    let mut scenes: Vec<Hashed> = Vec::new();
    for spec in specs {
        let is_mesh = Path::new(spec)
            .extension()
            .is_some_and(|e| e == MESH_EXTENSION);
        let scene = if is_mesh {
            None
        } else {
            Scene::load(spec).ok()
        };
        scenes.push(match scene {
            Some(sc) => {
                let mut pts: Vec<Vec3> = sc.camera.iter().map(|c| c.position).collect();
                pts.extend(sc.lights.iter().map(|l| l.position));
                (sc.name.clone(), Some((geometry_key(&sc), pts)))
            }
            None => (spec.clone(), None),
        });
    }
    (0..specs.len())
        .map(|i| {
            let key = scenes[i].1.as_ref().map(|(k, _)| *k);
            let group: Vec<usize> = (0..specs.len())
                .filter(|&j| key.is_some() && scenes[j].1.as_ref().map(|(k, _)| *k) == key)
                .collect();
            Planned {
                spec: specs[i].clone(),
                key,
                extra: group
                    .iter()
                    .flat_map(|&j| scenes[j].1.as_ref().map_or(Vec::new(), |x| x.1.clone()))
                    .collect(),
                shares_with: group
                    .iter()
                    .filter(|&&j| j != i)
                    .map(|&j| scenes[j].0.clone())
                    .collect(),
                first: group.first().is_none_or(|&j| j == i),
                last: group.last().is_none_or(|&j| j == i),
            }
        })
        .collect()
}

/// Meshes built for a group of scenes with the same geometry, by build flags.
#[derive(Default)]
pub struct MeshCache {
    /// By geometry key and build flags (resolved, as `Debug` text).
    meshes: HashMap<(u64, String), (TetMesh, BuildSummary)>,
}

impl MeshCache {
    /// The scene's mesh: built (and kept) for the first scene of a group
    /// with these flags, cloned for the others. Scenes alone in their group
    /// are built as `load` does.
    pub fn load(&mut self, p: &Planned, flags: &BuildFlags, quiet: bool) -> Result<(Loaded, bool)> {
        let Some(key) = p.key.filter(|_| !p.shares_with.is_empty()) else {
            return Ok((load(&p.spec, flags, quiet)?, false));
        };
        let scene =
            Scene::load(&p.spec).with_context(|| format!("cannot load scene `{}`", p.spec))?;
        let fk = (key, format!("{:?}", flags.resolved()));
        if let Some((mesh, build)) = self.meshes.get(&fk) {
            let loaded = with_mesh(scene, mesh.clone(), Some(build.clone()));
            return Ok((loaded, true));
        }
        let (mesh, build) = build_scene_in(&scene, flags, quiet, &p.extra)?;
        self.meshes.insert(fk, (mesh.clone(), build.clone()));
        Ok((with_mesh(scene, mesh, Some(build)), false))
    }

    /// Drops the meshes of a group.
    pub fn evict(&mut self, key: u64) {
        self.meshes.retain(|(k, _), _| *k != key);
    }
}
