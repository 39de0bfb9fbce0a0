//! Scene input: transforms checked on hand-computed points, the orbit camera
//! against the positions stored in scenes.json, OBJ parsing and typed errors.

use std::io::Write;
use std::path::{Path, PathBuf};

use glam::{DVec3, Vec3};
use tet_build::scene::obj::{MeshData, parse_obj_bytes};
use tet_build::scene::scenes_json::ScenesFile;
use tet_build::scene::{Affine, ObjectPlacement, Scene, SceneError, Transform, orbit_camera};

/// The scenes' directory: `TET_SHARED_SCENES` when set (a copy of the
/// whole data set, the files the repository leaves out included), else the
/// repository's `scenes/` (see its README: some meshes are not there).
fn scenes_dir() -> PathBuf {
    std::env::var_os("TET_SHARED_SCENES")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes"))
}

/// `file` in [`scenes_dir`], if it is there.
fn shared(file: &str) -> Option<PathBuf> {
    let p = scenes_dir().join(file);
    if p.exists() {
        Some(p)
    } else {
        eprintln!("skipping: {} not present", p.display());
        None
    }
}

/// The mesh files scene `scene` of the scenes.json `root` needs.
fn scene_files(root: &serde_json::Value, scene: &serde_json::Value) -> Vec<String> {
    scene["objects"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|o| {
            o["file"].as_str().map(str::to_owned).or_else(|| {
                let key = o["mesh"].as_str()?;
                root["meshes"][key]["file"].as_str().map(str::to_owned)
            })
        })
        .collect()
}

fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
    (a - b).abs().max_element() <= tol
}

#[test]
fn transform_points_by_hand() {
    // S = (2,1,1), Ry(90°): (1,0,0) -> (2,0,0) -> (0,0,-2); + T(1,2,3) = (1,2,1).
    let t = Transform {
        translation: DVec3::new(1.0, 2.0, 3.0),
        rotation_deg: DVec3::new(0.0, 90.0, 0.0),
        scale: DVec3::new(2.0, 1.0, 1.0),
    };
    let a = Affine::compose(&t, None);
    assert!(close(a.point(Vec3::X), Vec3::new(1.0, 2.0, 1.0), 1e-6));
    // Order Ry·Rx·Rz: (0,1,0) -Rx(90)-> (0,0,1) -Ry(90)-> (1,0,0).
    // (The other order Rx·Ry would give (0,0,1).)
    let r = Transform {
        rotation_deg: DVec3::new(90.0, 90.0, 0.0),
        ..Transform::IDENTITY
    };
    let a = Affine::compose(&r, None);
    assert!(close(a.point(Vec3::Y), Vec3::X, 1e-6));
    // Rz(90): (1,0,0) -> (0,1,0); then Rx(90): (0,1,0) -> (0,0,1).
    let r = Transform {
        rotation_deg: DVec3::new(90.0, 0.0, 90.0),
        ..Transform::IDENTITY
    };
    assert!(close(
        Affine::compose(&r, None).point(Vec3::X),
        Vec3::Z,
        1e-6
    ));
    // Pre-transform applies first: pre = scale 10, object = translate (1,0,0):
    // (1,1,1) -> (10,10,10) -> (11,10,10). The other order gives (20,10,10).
    let pre = Transform {
        scale: DVec3::splat(10.0),
        ..Transform::IDENTITY
    };
    let obj = Transform::translate(DVec3::X);
    assert!(close(
        Affine::compose(&obj, Some(&pre)).point(Vec3::ONE),
        Vec3::new(11.0, 10.0, 10.0),
        1e-5
    ));
}

#[test]
fn negative_scale_mirrors_and_flips_normals() {
    let t = Transform {
        scale: DVec3::new(-2.1, -1.1, -2.1),
        ..Transform::IDENTITY
    };
    assert!(t.flips_winding());
    let a = Affine::compose(&t, None);
    assert!(a.mirrors);
    assert!(close(
        a.point(Vec3::splat(10.0)),
        Vec3::new(-21.0, -11.0, -21.0),
        1e-5
    ));
    // The +x face (outward normal +x) lands at x = -21; its triangle keeps its
    // index order, so its geometric normal is det(M)·M^{-T}·(1,0,0) ∝ +x,
    // i.e. pointing inward; the vertex normal flips with it.
    let n = a.normal(Vec3::X);
    assert!(close(n, Vec3::X, 1e-6), "{n}");
    // Triangle (10,-10,-10), (10,10,-10), (10,10,10) of box.obj has normal +x.
    let tri = [
        Vec3::new(10.0, -10.0, -10.0),
        Vec3::new(10.0, 10.0, -10.0),
        Vec3::new(10.0, 10.0, 10.0),
    ];
    let g0 = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
    assert!(g0.x > 0.0);
    let w = tri.map(|p| a.point(p));
    let g = (w[1] - w[0]).cross(w[2] - w[0]);
    assert!(g.x > 0.0 && w[0].x < 0.0, "mirrored face must face inward");
    assert!(!Transform::IDENTITY.flips_winding());
}

#[test]
fn orbit_camera_matches_hand_values() {
    // dir = (cos1·cos.5, sin.5, sin1·cos.5) · 20.
    let c = orbit_camera(0.5, 1.0, 20.0, DVec3::ZERO);
    let expect = Vec3::new(
        (1f32.cos() * 0.5f32.cos()) * 20.0,
        0.5f32.sin() * 20.0,
        (1f32.sin() * 0.5f32.cos()) * 20.0,
    );
    assert!(close(c.position, expect, 1e-4));
    assert_eq!(c.up, Vec3::Y);
    assert_eq!(c.vfov_deg, 45.0);
}

#[test]
fn orbit_camera_matches_every_stored_position() {
    let Some(path) = shared("scenes.json") else {
        return;
    };
    let file = ScenesFile::open(&path).unwrap();
    let names = file.scene_names().unwrap();
    assert_eq!(names.len(), 19);
    for name in &names {
        let spec = file.camera_spec(name).unwrap();
        let cam = orbit_camera(
            spec.orbit_x_rad,
            spec.orbit_y_rad,
            spec.distance,
            spec.target,
        );
        let stored = spec.stored_position.unwrap().as_vec3();
        assert!(
            close(cam.position, stored, 2e-4 * spec.distance.max(1.0) as f32),
            "{name}: {} vs {stored}",
            cam.position
        );
    }
}

fn obj(text: &str) -> Result<MeshData, SceneError> {
    parse_obj_bytes(text.as_bytes(), Path::new("test.obj"))
}

#[test]
fn obj_crlf_polygons_and_negative_indices() {
    let text = "# quad and pentagon\r\nv 0 0 0\r\nv 1 0 0\r\nv 1 1 0\r\nv 0 1 0\r\n\
                v 0 0 1\r\nv 1 0 1\r\nv 2 1 1\r\nv 1 2 1\r\nv 0 1 1\r\n\
                f 1 2 3 4\r\nf -5 -4 -3 -2 -1\r\n";
    let m = obj(text).unwrap();
    assert_eq!(m.triangles.len(), 2 + 3);
    assert_eq!(m.positions.len(), 9);
    assert!(m.normals.is_none() && m.uvs.is_none());
    // Fan triangulation keeps the polygon's first vertex in every triangle.
    let first = m.positions[m.triangles[2][0] as usize];
    assert_eq!(first, Vec3::new(0.0, 0.0, 1.0));
}

#[test]
fn obj_attributes_and_flatten() {
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvn 0 0 1\nvn 1 0 0\n\
                f 1//1 2//1 3//1\nf 1//2 2//2 4//2\n";
    let m = obj(text).unwrap();
    let (normals, idx) = m.normals.clone().unwrap();
    assert_eq!(normals.len(), 2);
    assert_eq!(idx.len(), 2);
    // Vertices 1 and 2 carry two different normals: 6 corners, 6 distinct combos.
    let flat = m.flatten(true, false);
    assert_eq!(flat.positions.len(), 6);
    assert_eq!(flat.normals.as_ref().unwrap().len(), 6);
    let plain = m.flatten(false, false);
    assert_eq!(plain.positions.len(), 4);
}

#[test]
fn obj_errors_name_the_line() {
    match obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 x 0\nf 1 2 3\n") {
        Err(SceneError::ObjParse { line: Some(4), .. }) => {}
        other => panic!("{other:?}"),
    }
    match obj("v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n") {
        Err(SceneError::NonFiniteCoordinate {
            line: 3, vertex: 2, ..
        }) => {}
        other => panic!("{other:?}"),
    }
    match obj("v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 3\nf 1 2 7\n") {
        Err(SceneError::IndexOutOfRange {
            line: 6,
            index: 7,
            count: 3,
            ..
        }) => {}
        other => panic!("{other:?}"),
    }
    match obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n") {
        Err(SceneError::IndexOutOfRange {
            line: 4, index: -4, ..
        }) => {}
        other => panic!("{other:?}"),
    }
    let e = Scene::load("/nonexistent/dir/x.obj").unwrap_err();
    assert!(matches!(e, SceneError::Io { .. }), "{e:?}");
    assert!(e.to_string().contains("/nonexistent/dir/x.obj"));
}

#[test]
fn obj_file_round_trip_through_tempfile() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tri.obj");
    let mut f = std::fs::File::create(&path).unwrap();
    write!(f, "o a\r\nv 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\no b\r\nv 0 0 5\r\nv 1 0 5\r\nv 0 1 5\r\nf 4 5 6\r\n").unwrap();
    drop(f);
    let s = Scene::load(path.to_str().unwrap()).unwrap();
    assert_eq!(s.objects.len(), 1, "a plain OBJ is one object");
    assert_eq!(s.triangles.len(), 2);
    assert_eq!(s.bounds(), Some((Vec3::ZERO, Vec3::new(1.0, 1.0, 5.0))));
}

#[test]
fn attributes_kept_only_when_every_object_has_them() {
    let with = MeshData::single_index(
        vec![Vec3::ZERO, Vec3::X, Vec3::Y],
        vec![[0, 1, 2]],
        Some(vec![Vec3::Z; 3]),
    );
    let without = MeshData::single_index(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]], None);
    let place = |m| ObjectPlacement {
        name: "o".into(),
        mesh: m,
        transform: Transform::IDENTITY,
        pre_transform: None,
    };
    let both = Scene::from_objects("s", &[place(&with), place(&with)], None, vec![]).unwrap();
    assert_eq!(both.normals.as_ref().map(Vec::len), Some(6));
    let mixed = Scene::from_objects("s", &[place(&with), place(&without)], None, vec![]).unwrap();
    assert!(mixed.normals.is_none());
    assert_eq!(mixed.vertices.len(), 6);
    assert_eq!(mixed.objects[1].first_triangle, 1);
    assert_eq!(mixed.object_of_triangle(1), Some(1));
    assert_eq!(mixed.object_of_triangle(2), None);
}

#[test]
fn json_errors() {
    let p = Path::new("dir/scenes.json");
    match ScenesFile::parse("{\"scenes\": [\n {\"name\": 1,}\n]}", p) {
        Err(SceneError::Json { line: 2, .. }) => {}
        other => panic!("{other:?}"),
    }
    let text = r#"{"meshes": {}, "scenes": [{"name": "A", "camera": {"orbit_x_rad": 0, "orbit_y_rad": 0,
        "distance": 1, "target": [0,0,0]}, "lights": [], "objects": [{"name": "o", "file": "a.obj",
        "translation": [0,0,0], "rotation_deg": [0,0,0], "scale": [1,"x",1]}]},
        {"name": "B", "camera": {"orbit_x_rad": 0, "orbit_y_rad": 0, "distance": 1, "target": [0,0]},
         "lights": [], "objects": []}]}"#;
    let f = ScenesFile::parse(text, p).unwrap();
    match f.load("A") {
        Err(SceneError::JsonField { field, .. }) => {
            assert_eq!(field, "scenes[0].objects[0].scale[1]")
        }
        other => panic!("{other:?}"),
    }
    match f.load("B") {
        Err(SceneError::JsonField { field, .. }) => assert_eq!(field, "scenes[1].camera.target"),
        other => panic!("{other:?}"),
    }
    match f.load("C") {
        Err(SceneError::UnknownScene { available, .. }) => assert_eq!(available, ["A", "B"]),
        other => panic!("{other:?}"),
    }
}

#[test]
fn shared_json_unknown_and_missing() {
    let Some(path) = shared("scenes.json") else {
        return;
    };
    let e = Scene::load(&format!("{}#Nope", path.display())).unwrap_err();
    match &e {
        SceneError::UnknownScene { available, .. } => {
            assert!(available.iter().any(|n| n == "Torus Knots in a Box"))
        }
        other => panic!("{other:?}"),
    }
    // A json path without `#Name` lists the scenes.
    match Scene::load(path.to_str().unwrap()) {
        Err(SceneError::UnknownScene { available, .. }) => assert_eq!(available.len(), 19),
        other => panic!("{other:?}"),
    }
    match Scene::load(&format!("{}#Rungholt", path.display())) {
        Err(SceneError::MissingMesh {
            mesh, object: 0, ..
        }) => assert_eq!(mesh, "rungholt.obj"),
        other => panic!("{other:?}"),
    }
    // A mesh the repository leaves out (see scenes/README.md): the error
    // names the file and says where to get it.
    if !path.with_file_name("torus_knot.obj").exists() {
        let e = Scene::load(&format!("{}#Torus Knots", path.display())).unwrap_err();
        let SceneError::MissingMesh {
            mesh, obtain_from, ..
        } = &e
        else {
            panic!("{e:?}")
        };
        assert!(mesh.ends_with("torus_knot.obj"), "{mesh}");
        let hint = obtain_from.as_deref().unwrap_or_default();
        assert!(
            hint.contains("aytekaman/neptun") && hint.contains("torus-knots"),
            "{hint}"
        );
        assert!(e.to_string().contains(hint), "{e}");
        // The OBJ file named directly says the same.
        let obj = path.with_file_name("torus_knot.obj");
        let e = Scene::load(obj.to_str().unwrap()).unwrap_err();
        assert!(
            matches!(e, SceneError::Io { .. }) && e.to_string().contains(hint),
            "{e}"
        );
    }
}

#[test]
fn shared_torus_knot_scenes_load() {
    let Some(path) = shared("scenes.json") else {
        return;
    };
    if shared("torus_knot.obj").is_none() || shared("box.obj").is_none() {
        return;
    }
    let s = Scene::load(&format!("{}#Torus Knots", path.display())).unwrap();
    assert_eq!(s.triangles.len(), 77_760);
    assert_eq!(s.objects.len(), 27);
    assert_eq!(s.lights.len(), 1);
    assert_eq!(s.lights[0].position, Vec3::new(6.0, 10.0, 8.0));
    assert!(s.normals.is_some(), "torus_knot.obj has vn");
    let (lo, hi) = s.bounds().unwrap();
    assert!(
        close(lo, Vec3::new(-7.0856, -6.4265, -6.9389), 1e-4),
        "{lo}"
    );
    assert!(close(hi, Vec3::new(6.5645, 6.4265, 6.9389), 1e-4), "{hi}");

    let b = Scene::load(&format!("{}#Torus Knots in a Box", path.display())).unwrap();
    assert_eq!(b.triangles.len(), 77_772);
    assert_eq!(b.objects[0].name, "box");
    assert!(b.objects[0].mirrored);
    assert!(b.normals.is_some(), "box.obj has vn too");
    // Box: 12 triangles; with per-face normals its 8 corners become 24 vertices.
    assert_eq!(b.objects[0].triangle_count, 12);
    assert_eq!(b.objects[0].vertex_count, 24);
    let (lo, hi) = b.bounds().unwrap();
    assert_eq!(
        (lo, hi),
        (Vec3::new(-21.0, -11.0, -21.0), Vec3::new(21.0, 11.0, 21.0))
    );
}

/// Every reconstructable scene: per-object world bbox equals the
/// `world_bbox_with_this_dataset` stored in the json, triangle totals match.
#[test]
fn shared_all_scenes_match_stored_bboxes() {
    let Some(path) = shared("scenes.json") else {
        return;
    };
    let root: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    for sc in root["scenes"].as_array().unwrap() {
        if !sc["reconstructable"].as_bool().unwrap() {
            continue;
        }
        let name = sc["name"].as_str().unwrap();
        if let Some(f) = scene_files(&root, sc)
            .into_iter()
            .find(|f| !path.with_file_name(f).exists())
        {
            eprintln!("skipping {name}: {f} not present");
            continue;
        }
        let s = Scene::load(&format!("{}#{name}", path.display())).unwrap();
        assert_eq!(
            s.triangles.len() as u64,
            sc["triangles_with_this_dataset"].as_u64().unwrap(),
            "{name}"
        );
        let objs: Vec<_> = sc["objects"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|o| o["world_bbox_with_this_dataset"].is_array())
            .collect();
        assert_eq!(objs.len(), s.objects.len(), "{name}");
        for (o, so) in objs.iter().zip(&s.objects) {
            let bb = &o["world_bbox_with_this_dataset"];
            let v = |i: usize| {
                Vec3::new(
                    bb[i][0].as_f64().unwrap() as f32,
                    bb[i][1].as_f64().unwrap() as f32,
                    bb[i][2].as_f64().unwrap() as f32,
                )
            };
            let tris = &s.triangles
                [so.first_triangle as usize..(so.first_triangle + so.triangle_count) as usize];
            let mut lo = Vec3::splat(f32::MAX);
            let mut hi = Vec3::splat(f32::MIN);
            for t in tris {
                for &i in t {
                    lo = lo.min(s.vertices[i as usize]);
                    hi = hi.max(s.vertices[i as usize]);
                }
            }
            assert!(
                close(lo, v(0), 2e-4) && close(hi, v(1), 2e-4),
                "{name}/{}: {lo} {hi}",
                so.name
            );
        }
    }
}

#[test]
fn plain_obj_scene_from_shared_folder() {
    let Some(path) = shared("teapot.obj") else {
        return;
    };
    let s = Scene::load(path.to_str().unwrap()).unwrap();
    assert_eq!(s.triangles.len(), 6_320);
    assert_eq!(s.objects.len(), 1);
    assert!(s.camera.is_none());
    let Some(path) = shared("beast.obj") else {
        return;
    };
    let s = Scene::load(path.to_str().unwrap()).unwrap();
    assert_eq!(s.triangles.len(), 64_618, "quads fan-triangulated");
    assert!(s.uvs.is_some() && s.normals.is_none());
}

#[test]
fn spec_errors() {
    match Scene::load("no-such-procedural-scene") {
        Err(SceneError::BadSpec { message, .. }) => assert!(message.contains("torus-knots-box")),
        other => panic!("{other:?}"),
    }
}

proptest::proptest! {
    /// Arbitrary OBJ-like text never panics the loader: it parses or fails
    /// with a typed error.
    #[test]
    fn obj_parser_never_panics(lines in proptest::collection::vec(
        proptest::prop_oneof![
            "v( -?[0-9]{1,2}(\\.[0-9])?){3}",
            "v( [a-z0-9.]{0,4}){0,4}",
            "vn( -?[0-9]){3}",
            "vt( [0-9]){2}",
            "f( -?[0-9]{1,2}(/-?[0-9]?){0,2}){0,5}",
            "(o|g|s|usemtl|mtllib) [a-z]{0,5}",
            "[ -~]{0,12}",
        ], 0..20)) {
        let text = lines.join("\r\n");
        let _ = parse_obj_bytes(text.as_bytes(), Path::new("fuzz.obj"));
    }
}

#[test]
fn non_finite_after_transform_names_the_object() {
    let m = MeshData::single_index(
        vec![Vec3::ZERO, Vec3::X, Vec3::splat(3e38)],
        vec![[0, 1, 2]],
        None,
    );
    let placed = ObjectPlacement {
        name: "huge".into(),
        mesh: &m,
        transform: Transform {
            scale: DVec3::splat(10.0),
            ..Transform::IDENTITY
        },
        pre_transform: None,
    };
    match Scene::from_objects("s", &[placed], None, vec![]) {
        Err(SceneError::NonFiniteTransformed {
            object, vertex: 2, ..
        }) => assert_eq!(object, "huge"),
        other => panic!("{other:?}"),
    }
}
