//! The scenes `gpu-bench` measures and where their meshes come from: the
//! five scenes of Aman et al. (2022) Table 3 by default, each mesh read
//! from `--meshes DIR/NAME.tmesh`, else built (TetGen compiled in), else
//! skipped with the reason; and `--prepare-meshes`, which builds the set
//! to carry to a GPU machine and checks its size.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};
use serde::Serialize;
use tet_core::scene::SceneInfo;

use crate::cli::GpuBenchArgs;
use crate::load::build_flags::BuildFlags;
use crate::load::{Loaded, MESH_EXTENSION, load, require_tets};
use crate::output::{outln, print_json};
use crate::tables::paper::paper_scene;

/// The scenes of a run: `--scene` as given, else Torus Knots, Torus Knots
/// in a Box and the Armadillo, Neptune and Mix of `--scenes`.
pub fn scene_specs(args: &GpuBenchArgs) -> Vec<String> {
    if !args.scene.is_empty() {
        return args.scene.clone();
    }
    let json = args.scenes.display();
    vec![
        "torus-knots".into(),
        "torus-knots-box".into(),
        format!("{json}#Armadillo"),
        format!("{json}#Neptune"),
        format!("{json}#Mix"),
    ]
}

/// The file name of a scene's mesh in `--meshes DIR`: the part after the
/// spec's last `#` (a scenes.json scene), an OBJ's file stem, or the
/// procedural name, in lower case with every run of other characters as
/// one `-`, and `.tmesh`; `None` for a spec that is a mesh file itself.
pub fn mesh_file_name(spec: &str) -> Option<String> {
    let path = Path::new(spec);
    if path.extension().is_some_and(|e| e == MESH_EXTENSION) {
        return None;
    }
    let base = match spec.rsplit_once('#') {
        Some((_, name)) => name.to_string(),
        None if path.extension().is_some() => path
            .file_stem()
            .map_or(spec.to_string(), |s| s.to_string_lossy().into_owned()),
        None => spec.to_string(),
    };
    let mut slug = String::new();
    for c in base.chars() {
        if c.is_ascii_alphanumeric() {
            slug.push(c.to_ascii_lowercase());
        } else if !slug.is_empty() && !slug.ends_with('-') {
            slug.push('-');
        }
    }
    let slug = slug.trim_end_matches('-');
    (!slug.is_empty()).then(|| format!("{slug}.{MESH_EXTENSION}"))
}

/// How missing meshes are built: the default build (walls, Hilbert
/// order), in the papers' wide box holding the camera and lights (primary
/// rays start in the camera's tet, on the GPU) unless `tight`.
pub fn build_flags(tight: bool) -> BuildFlags {
    BuildFlags {
        wide_box: !tight,
        ..crate::tables::TABLE_FLAGS
    }
}

/// Where a scene's mesh came from (JSON `scenes[].mesh`).
#[derive(Clone, Debug, Serialize)]
pub struct MeshDoc {
    /// `file` (read from `--meshes`), `built` (by this run) or `given` (the
    /// spec was a mesh file).
    pub source: &'static str,
    /// The file read, or `null` for a mesh built here.
    pub path: Option<String>,
    /// Its size, bytes (`null` for a mesh built here).
    pub file_bytes: Option<u64>,
    /// Seconds to read or build it.
    pub load_s: f64,
    /// Tets.
    pub tets: usize,
    /// Points.
    pub points: usize,
    /// Constrained faces (scene triangles, split where they cross).
    pub constrained_faces: usize,
}

/// A scene's name in reports: the paper's where it has one, else the
/// loaded scene's (a mesh file's stem).
#[cfg_attr(not(feature = "gpu"), allow(dead_code))]
pub fn display_name(spec: &str, loaded: &Loaded) -> String {
    paper_scene(spec).map_or_else(|| loaded.name.clone(), |p| p.name.to_string())
}

/// The mesh of `spec`: `DIR/NAME.tmesh` of `--meshes` when present, the
/// spec itself when it is a mesh file, else built (an error without
/// TetGen, or when the scene's files are missing: the caller skips the
/// scene with it).
#[cfg_attr(not(feature = "gpu"), allow(dead_code))]
pub fn resolve(spec: &str, meshes: Option<&Path>, flags: &BuildFlags) -> Result<(Loaded, MeshDoc)> {
    let start = Instant::now();
    let file = match (meshes, mesh_file_name(spec)) {
        (_, None) => Some(("given", PathBuf::from(spec))),
        (Some(dir), Some(name)) if dir.join(&name).is_file() => Some(("file", dir.join(name))),
        _ => None,
    };
    let (mut loaded, source, path) = match file {
        Some((source, path)) => {
            let text = path.display().to_string();
            let loaded = load(&text, flags, true)
                .with_context(|| format!("cannot read the mesh file {text}"))?;
            (loaded, source, Some(path))
        }
        None => {
            let why = match (meshes, mesh_file_name(spec)) {
                (Some(dir), Some(name)) => format!("no {}: building it", dir.join(name).display()),
                _ => "building it".to_string(),
            };
            eprintln!("  {spec}: {why}");
            (load(spec, flags, true)?, "built", None)
        }
    };
    require_tets(&loaded)?;
    loaded.name = display_name(spec, &loaded);
    let mesh = &loaded.mesh;
    let doc = MeshDoc {
        source,
        file_bytes: path
            .as_ref()
            .and_then(|p| std::fs::metadata(p).ok())
            .map(|m| m.len()),
        path: path.map(|p| p.display().to_string()),
        load_s: start.elapsed().as_secs_f64(),
        tets: mesh.tets.len(),
        points: mesh.points.len(),
        constrained_faces: mesh.constrained.len(),
    };
    Ok((loaded, doc))
}

/// One scene of `--prepare-meshes` (JSON `meshes.json`'s `files[]`).
#[derive(Debug, Serialize)]
pub struct PreparedMesh {
    /// Scene spec.
    pub spec: String,
    /// The file written, `null` when skipped.
    pub path: Option<String>,
    /// Its size, bytes (0 when skipped).
    pub bytes: u64,
    /// Tets (0 when skipped).
    pub tets: usize,
    /// Seconds to build and write it.
    pub build_s: f64,
    /// Why there is no file, `null` when written.
    pub skipped: Option<String>,
}

/// `--prepare-meshes` (JSON `OUT_DIR/meshes.json`, and stdout with
/// `--json`).
#[derive(Debug, Serialize)]
pub struct PrepareDoc {
    /// The `--meshes` directory.
    pub dir: String,
    /// One per scene.
    pub files: Vec<PreparedMesh>,
    /// Sum of the files' sizes, bytes.
    pub total_bytes: u64,
    /// `--budget-mb` in bytes.
    pub budget_bytes: u64,
    /// `total_bytes <= budget_bytes`.
    pub fits: bool,
    /// When the set does not fit: the files to leave behind, largest
    /// first, until the rest fits (`gpu-bench` builds those scenes on the
    /// GPU machine, TetGen compiled in, in seconds to a minute each).
    pub leave_out: Vec<String>,
}

/// The largest of `files` to leave out, one by one, until the rest fits
/// in `budget` bytes.
fn leave_out(files: &[PreparedMesh], budget: u64) -> Vec<String> {
    let mut written: Vec<(&str, u64)> = files
        .iter()
        .filter_map(|f| Some((f.path.as_deref()?, f.bytes)))
        .collect();
    written.sort_by_key(|w| std::cmp::Reverse(w.1));
    let mut total: u64 = written.iter().map(|w| w.1).sum();
    let mut out = Vec::new();
    for (path, bytes) in written {
        if total <= budget {
            break;
        }
        total -= bytes;
        out.push(path.to_string());
    }
    out
}

/// `gpu-bench OUT_DIR --prepare-meshes --meshes DIR`: builds each scene's
/// mesh into DIR under its [`mesh_file_name`] (with the scene's camera and
/// lights), reports the sizes against `--budget-mb` and writes
/// `OUT_DIR/meshes.json`. A scene that cannot be built is reported and
/// skipped.
pub fn prepare(args: &GpuBenchArgs, json: bool) -> Result<()> {
    let dir = args
        .meshes
        .as_deref()
        .context("--prepare-meshes needs --meshes DIR")?;
    for d in [dir, &args.out_dir] {
        std::fs::create_dir_all(d).with_context(|| format!("cannot create {}", d.display()))?;
    }
    let flags = build_flags(args.tight_box);
    let mut files = Vec::new();
    for spec in scene_specs(args) {
        let start = Instant::now();
        let written = mesh_file_name(&spec)
            .with_context(|| format!("`{spec}` is a mesh file already: nothing to build"))
            .and_then(|name| {
                eprintln!("building {spec}");
                let loaded = load(&spec, &flags, true)?;
                let path = dir.join(name);
                let stored = SceneInfo {
                    camera: loaded.scene.as_ref().and_then(|s| s.camera),
                    lights: loaded
                        .scene
                        .as_ref()
                        .map(|s| s.lights.clone())
                        .unwrap_or_default(),
                };
                tet_core::format::save_with_scene(&path, &loaded.mesh, &stored)
                    .with_context(|| format!("cannot write {}", path.display()))?;
                let bytes = std::fs::metadata(&path).map_or(0, |m| m.len());
                Ok((path, bytes, loaded.mesh.tets.len()))
            });
        files.push(match written {
            Ok((path, bytes, tets)) => PreparedMesh {
                spec,
                path: Some(path.display().to_string()),
                bytes,
                tets,
                build_s: start.elapsed().as_secs_f64(),
                skipped: None,
            },
            Err(e) => PreparedMesh {
                spec,
                path: None,
                bytes: 0,
                tets: 0,
                build_s: start.elapsed().as_secs_f64(),
                skipped: Some(crate::output::error_chain(&e)),
            },
        });
    }
    let total_bytes = files.iter().map(|f| f.bytes).sum();
    let budget_bytes = (args.budget_mb.max(0.0) * 1e6) as u64;
    let doc = PrepareDoc {
        dir: dir.display().to_string(),
        leave_out: leave_out(&files, budget_bytes),
        files,
        total_bytes,
        budget_bytes,
        fits: total_bytes <= budget_bytes,
    };
    super::files::write_atomic(
        &args.out_dir.join("meshes.json"),
        serde_json::to_string_pretty(&doc)?.as_bytes(),
    )?;
    if json {
        return print_json(&doc);
    }
    for f in &doc.files {
        match (&f.path, &f.skipped) {
            (Some(p), _) => outln!(
                "{p}: {:.1} MB, {} tets, {:.1} s",
                mb(f.bytes),
                f.tets,
                f.build_s
            )?,
            (None, why) => outln!("{}: skipped: {}", f.spec, why.as_deref().unwrap_or("?"))?,
        }
    }
    let verdict = if doc.fits {
        "fits".to_string()
    } else {
        format!(
            "too large: leave out {} (gpu-bench builds a missing mesh on the GPU machine, \
             TetGen compiled in)",
            doc.leave_out.join(", ")
        )
    };
    outln!(
        "total {:.1} MB of the {:.1} MB the meshes may take (--budget-mb): {verdict}",
        mb(doc.total_bytes),
        mb(doc.budget_bytes)
    )
}

/// Bytes in (decimal) megabytes.
fn mb(bytes: u64) -> f64 {
    bytes as f64 / 1e6
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mesh_files_are_named_by_the_scene() {
        for (spec, name) in [
            ("torus-knots", Some("torus-knots.tmesh")),
            ("torus-knots-box", Some("torus-knots-box.tmesh")),
            ("scenes/scenes.json#Armadillo", Some("armadillo.tmesh")),
            (
                "x/scenes.json#Armadillo in a Box",
                Some("armadillo-in-a-box.tmesh"),
            ),
            ("scenes/scenes.json#Mix", Some("mix.tmesh")),
            ("dense-knots:1m", Some("dense-knots-1m.tmesh")),
            ("scenes/stanford-bunny.obj", Some("stanford-bunny.tmesh")),
            ("meshes/knot.tmesh", None),
            ("#", None),
        ] {
            assert_eq!(mesh_file_name(spec).as_deref(), name, "{spec}");
        }
    }

    #[test]
    fn the_largest_files_are_left_out_until_the_rest_fits() {
        let file = |path: &str, bytes| PreparedMesh {
            spec: path.into(),
            path: Some(path.into()),
            bytes,
            tets: 1,
            build_s: 0.0,
            skipped: None,
        };
        let files = [file("a", 10), file("b", 40), file("c", 20), file("d", 30)];
        assert!(leave_out(&files, 100).is_empty());
        assert_eq!(leave_out(&files, 60), ["b"]);
        assert_eq!(leave_out(&files, 30), ["b", "d"]);
        assert_eq!(leave_out(&files, 0), ["b", "d", "c", "a"]);
    }
}
