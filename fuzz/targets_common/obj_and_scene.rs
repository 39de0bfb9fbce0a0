// Body of the `obj_and_scene` fuzz target: arbitrary bytes as OBJ text
// (`tet_build::scene::obj::parse_obj_bytes`) and as `scenes.json` text
// (`tet_build::scene::scenes_json::ScenesFile::parse`, then every scene of a
// file that parses is built).
//
// Property: a typed `SceneError` that names the file, or a mesh / scene whose
// indices are all in range, whose coordinates are finite and whose
// attribute arrays match — never a panic.
//
// Scenes load their OBJ files relative to the json file: here a fixture
// directory of generated meshes (`tet.obj`, `quad.obj`). Inputs naming a
// path with a separator are parsed but not loaded, so the fuzzer cannot make
// the loader read arbitrary files of the machine (e.g. `/dev/zero`, as
// fuzzing found).

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use tet_build::scene::obj::parse_obj_bytes;
use tet_build::scene::scenes_json::ScenesFile;
use tet_build::scene::{MeshData, ObjectPlacement, Scene, SceneError, Transform};

/// A tetrahedron surface, positions only.
pub const TET_OBJ: &str =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
/// A quad (fan-triangulated) with normals and texture coordinates, CRLF.
pub const QUAD_OBJ: &str = "# quad\r\nv -1 -1 0\r\nv 1 -1 0\r\nv 1 1 0\r\nv -1 1 0\r\nvn 0 0 1\r\nvt 0 0\r\nvt 1 0\r\nvt 1 1\r\nvt 0 1\r\nf 1/1/1 2/2/1 3/3/1 4/4/1\r\n";

/// Directory holding the fixture OBJ files (created once per process).
pub fn fixture_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("tetrays-fuzz-scenes-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("create the fixture directory");
        std::fs::write(dir.join("tet.obj"), TET_OBJ).expect("write tet.obj");
        std::fs::write(dir.join("quad.obj"), QUAD_OBJ).expect("write quad.obj");
        dir
    })
}

/// Runs both properties on `data`.
pub fn check(data: &[u8]) {
    check_obj(data);
    check_scenes_json(data);
}

/// `data` as an OBJ file.
pub fn check_obj(data: &[u8]) -> bool {
    let path = Path::new("fuzz.obj");
    match parse_obj_bytes(data, path) {
        Ok(mesh) => {
            check_mesh(&mesh);
            for transform in [
                Transform::IDENTITY,
                Transform {
                    translation: glam::DVec3::new(1e5, -3.0, 0.5),
                    rotation_deg: glam::DVec3::new(30.0, -45.0, 400.0),
                    scale: glam::DVec3::new(-1.0, 2.0, 1e30),
                },
            ] {
                let placed = [ObjectPlacement {
                    name: "fuzz".into(),
                    mesh: &mesh,
                    transform,
                    pre_transform: None,
                }];
                match Scene::from_objects("fuzz", &placed, None, Vec::new()) {
                    Ok(scene) => check_scene(&scene),
                    Err(e) => named(&e, "fuzz"),
                }
            }
            true
        }
        Err(e) => {
            named(&e, "fuzz.obj");
            false
        }
    }
}

/// `data` (lossily decoded as UTF-8) as a `scenes.json` file; returns the
/// number of scenes that loaded.
pub fn check_scenes_json(data: &[u8]) -> usize {
    let text = String::from_utf8_lossy(data);
    let path = fixture_dir().join("scenes.json");
    let file = match ScenesFile::parse(&text, &path) {
        Ok(f) => f,
        Err(e) => {
            named(&e, "scenes.json");
            return 0;
        }
    };
    let names = match file.scene_names() {
        Ok(n) => n,
        Err(e) => {
            named(&e, "scenes.json");
            return 0;
        }
    };
    let may_load = !text.contains('/') && !text.contains('\\');
    let mut loaded = 0;
    for name in names.iter().take(8) {
        match file.camera_spec(name) {
            Ok(c) => {
                let _ = (c.orbit_x_rad, c.distance, c.target);
            }
            Err(e) => named(&e, "scenes.json"),
        }
        if may_load {
            match file.load(name) {
                Ok(scene) => {
                    check_scene(&scene);
                    assert_eq!(&scene.name, name);
                    loaded += 1;
                }
                Err(e) => {
                    let _ = e.to_string();
                }
            }
        }
    }
    // An unknown name is a typed error listing the available ones.
    let unknown = format!("{}\u{1}", names.concat());
    match file.load(&unknown) {
        Err(SceneError::UnknownScene { available, .. }) => assert_eq!(available, names),
        Err(e) => panic!("unknown scene gave {e}"),
        Ok(_) => panic!("a scene named {unknown:?} loaded"),
    }
    loaded
}

/// The error's message names `what` (the file or scene at fault).
fn named(e: &SceneError, what: &str) {
    let msg = e.to_string();
    assert!(msg.contains(what), "error does not name {what:?}: {msg}");
}

/// Invariants of a parsed OBJ mesh.
fn check_mesh(mesh: &MeshData) {
    let n = mesh.positions.len();
    assert!(!mesh.triangles.is_empty(), "Ok without triangles");
    assert!(
        mesh.positions.iter().all(|p| p.is_finite()),
        "non-finite position"
    );
    for t in &mesh.triangles {
        assert!(
            t.iter().all(|&v| (v as usize) < n),
            "triangle {t:?}, {n} positions"
        );
    }
    if let Some((values, idx)) = &mesh.normals {
        assert_eq!(idx.len(), mesh.triangles.len());
        assert!(idx.iter().flatten().all(|&i| (i as usize) < values.len()));
    }
    if let Some((values, idx)) = &mesh.uvs {
        assert_eq!(idx.len(), mesh.triangles.len());
        assert!(idx.iter().flatten().all(|&i| (i as usize) < values.len()));
    }
    let (lo, hi) = mesh.bounds().expect("a mesh with triangles has bounds");
    assert!(lo.cmple(hi).all());
    for (kn, ku) in [(false, false), (true, false), (false, true), (true, true)] {
        let flat = mesh.flatten(kn, ku);
        assert_eq!(flat.triangles.len(), mesh.triangles.len());
        let m = flat.positions.len();
        for (ft, t) in flat.triangles.iter().zip(&mesh.triangles) {
            for k in 0..3 {
                assert!((ft[k] as usize) < m);
                // Same position, bit for bit, as the multi-index corner.
                let a = flat.positions[ft[k] as usize].to_array().map(f32::to_bits);
                let b = mesh.positions[t[k] as usize].to_array().map(f32::to_bits);
                assert_eq!(a, b);
            }
        }
        if let Some(v) = &flat.normals {
            assert_eq!(v.len(), m);
        }
        if let Some(v) = &flat.uvs {
            assert_eq!(v.len(), m);
        }
    }
}

/// Invariants of an assembled scene.
fn check_scene(scene: &Scene) {
    let n = scene.vertices.len();
    assert!(
        scene.vertices.iter().all(|p| p.is_finite()),
        "non-finite vertex"
    );
    for t in &scene.triangles {
        assert!(
            t.iter().all(|&v| (v as usize) < n),
            "triangle {t:?}, {n} vertices"
        );
    }
    if let Some(v) = &scene.normals {
        assert_eq!(v.len(), n);
    }
    if let Some(v) = &scene.uvs {
        assert_eq!(v.len(), n);
    }
    let mut next_triangle = 0u64;
    let mut next_vertex = 0u64;
    for o in &scene.objects {
        assert_eq!(u64::from(o.first_triangle), next_triangle);
        assert_eq!(u64::from(o.first_vertex), next_vertex);
        next_triangle += u64::from(o.triangle_count);
        next_vertex += u64::from(o.vertex_count);
    }
    assert_eq!(next_triangle, scene.triangles.len() as u64);
    assert_eq!(next_vertex, n as u64);
    for t in 0..scene.triangles.len() as u32 {
        let o = scene
            .object_of_triangle(t)
            .expect("every triangle has an object");
        let obj = &scene.objects[o];
        assert!(obj.first_triangle <= t && t - obj.first_triangle < obj.triangle_count);
    }
    if scene.triangles.is_empty() {
        assert!(scene.bounds().is_none());
    } else {
        let (lo, hi) = scene.bounds().expect("bounds");
        assert!(lo.cmple(hi).all());
    }
}
