//! The repository's `scenes/` and how the command line names scenes:
//! `scenes/scenes.json` parses and every mesh file it references is in
//! `scenes/`, or is one the repository leaves out on purpose (its mesh
//! entry says `in_repository: false` and where to get it, `.gitignore`
//! keeps a local copy out of commits, and loading a scene without it says
//! where to get it); `scenes/README.md` names every file; the help of every
//! subcommand that takes a scene lists every procedural scene.

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;
use tet_build::procedural::SCENES;
use tet_build::scene::scenes_json::ScenesFile;

/// The repository's `scenes/`.
fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

/// The mesh file of every object of every scene: (scene, object, file,
/// the object's mesh entry), `file` `None` for an object whose mesh is not
/// in the data set at all (Rungholt, Exhaust Pipe).
fn referenced_files(root: &Value) -> Vec<(String, usize, Option<String>, Value)> {
    let mut out = Vec::new();
    for scene in root["scenes"].as_array().expect("scenes") {
        let name = scene["name"].as_str().expect("scene name").to_string();
        for (i, o) in scene["objects"]
            .as_array()
            .expect("objects")
            .iter()
            .enumerate()
        {
            let entry = o["mesh"]
                .as_str()
                .map(|k| root["meshes"][k].clone())
                .unwrap_or(Value::Null);
            let file = o["file"]
                .as_str()
                .or_else(|| entry["file"].as_str())
                .map(str::to_owned);
            if file.is_none() && o["paper_mesh_file"].is_null() {
                continue; // an empty placeholder object
            }
            out.push((name.clone(), i, file, entry));
        }
    }
    out
}

#[test]
fn scenes_json_parses_and_every_mesh_it_names_is_there_or_left_out_on_purpose() {
    let dir = scenes_dir();
    let path = dir.join("scenes.json");
    let file = ScenesFile::open(&path).unwrap_or_else(|e| panic!("{e}"));
    let names = file.scene_names().unwrap();
    assert_eq!(names.len(), 19, "{names:?}");
    let root: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let gitignore = std::fs::read_to_string(dir.join("../.gitignore")).unwrap();
    let readme = std::fs::read_to_string(dir.join("README.md")).unwrap();
    let refs = referenced_files(&root);
    assert!(refs.len() > 100, "{} objects", refs.len());
    let mut present = 0;
    for (scene, object, mesh_file, entry) in &refs {
        let what = format!("{scene:?} object {object}");
        let Some(mesh_file) = mesh_file else {
            // Not in the data set at all: the scene says so.
            let sc = root["scenes"]
                .as_array()
                .unwrap()
                .iter()
                .find(|s| s["name"] == scene.as_str())
                .unwrap();
            assert_eq!(sc["reconstructable"], false, "{what}");
            continue;
        };
        assert!(
            readme.contains(mesh_file.as_str()),
            "README misses {mesh_file}"
        );
        if entry["in_repository"] == false {
            let hint = entry["obtain_from"].as_str().unwrap_or_default();
            assert!(
                hint.contains("http"),
                "{what}: {mesh_file} has no source: {hint:?}"
            );
            assert!(
                gitignore
                    .lines()
                    .any(|l| l == format!("/scenes/{mesh_file}")),
                ".gitignore does not keep {mesh_file} out of commits"
            );
        } else {
            assert!(
                dir.join(mesh_file).is_file(),
                "{what}: {mesh_file} is not in scenes/"
            );
            present += 1;
        }
    }
    assert!(present > 0);
    // Every mesh entry the repository has is here too, and every OBJ here
    // is described in the README.
    for (key, entry) in root["meshes"].as_object().unwrap() {
        let f = entry["file"].as_str().unwrap();
        assert!(
            entry["in_repository"] == false || dir.join(f).is_file(),
            "meshes.{key}: {f}"
        );
    }
    for e in std::fs::read_dir(&dir).unwrap().flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if name.ends_with(".obj") {
            assert!(readme.contains(&name), "README misses {name}");
        }
    }
}

/// A scene whose mesh the repository leaves out fails with an error that
/// names the file and where to get it (skipped where a local copy is in
/// `scenes/`).
#[test]
fn a_scene_without_its_mesh_says_where_to_get_it() {
    let dir = scenes_dir();
    if dir.join("torus_knot.obj").exists() {
        eprintln!("skipping: scenes/torus_knot.obj is present");
        return;
    }
    let spec = format!("{}#Torus Knots", dir.join("scenes.json").display());
    let out = Command::new(env!("CARGO_BIN_EXE_tet-bench"))
        .args(["info", &spec])
        .output()
        .expect("tet-bench runs");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("torus_knot.obj"), "{err}");
    assert!(
        err.contains("https://raw.githubusercontent.com/aytekaman/neptun/"),
        "{err}"
    );
    assert!(err.contains("torus-knots"), "{err}");
}

/// `--help` of every subcommand that takes a scene lists every procedural
/// scene of [`SCENES`] (the list `by_name` parses against) with its line.
#[test]
fn help_lists_every_procedural_scene() {
    for sub in ["build", "info", "render", "accuracy", "tables"] {
        let out = Command::new(env!("CARGO_BIN_EXE_tet-bench"))
            .args([sub, "--help"])
            .output()
            .expect("tet-bench runs");
        assert!(out.status.success(), "{sub} --help");
        let help = String::from_utf8_lossy(&out.stdout);
        for p in SCENES {
            assert!(
                help.lines()
                    .any(|l| l.trim_start().starts_with(p.name) && l.contains(p.about)),
                "`{sub} --help` does not list {}:\n{help}",
                p.name
            );
        }
    }
}
