//! The build pipeline end to end: procedural scenes build and validate, every
//! scene triangle is covered by exactly one constrained face (checked against
//! the scene's own coordinates), the tets fill the domain (volume), and bad
//! scenes come back as typed errors.

#![cfg(feature = "tetgen")]

use std::sync::{Arc, Mutex};
use std::time::Duration;

use glam::{DVec3, Vec3};
use tet_build::bbox::BoxSpec;
use tet_build::clean::CleanError;
use tet_build::pipeline::{Assembly, BuildError, BuildOptions, Reorder, Stage, Validation, build};
use tet_build::scene::Scene;
use tet_build::tetgen::{Isolation, TetgenError, WorkerCommand};
use tet_core::TetMesh;

fn scene(vertices: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Scene {
    Scene {
        name: "test".into(),
        vertices,
        triangles,
        ..Scene::default()
    }
}

fn worker() -> Isolation {
    Isolation::Worker(WorkerCommand {
        program: env!("CARGO_BIN_EXE_tet-build-worker").into(),
        args: vec![],
        timeout: Some(Duration::from_secs(60)),
    })
}

/// Independent coverage check: for every scene triangle, exactly one
/// constrained face names it, and that face's points are the triangle's
/// points (as coordinates, in the same cyclic order).
fn assert_covers_scene(mesh: &TetMesh, scene: &Scene, dropped: &[u32]) {
    let mut hits = vec![0usize; scene.triangles.len()];
    for cf in &mesh.constrained {
        let t = cf.triangle as usize;
        hits[t] += 1;
        let want = scene.triangles[t].map(|v| scene.vertices[v as usize]);
        let got = cf.vertices.map(|v| mesh.points[v as usize]);
        let rotations = [got, [got[1], got[2], got[0]], [got[2], got[0], got[1]]];
        assert!(
            rotations.contains(&want),
            "triangle {t}: {got:?} vs {want:?}"
        );
    }
    for (t, &h) in hits.iter().enumerate() {
        let expect = usize::from(!dropped.contains(&(t as u32)));
        assert_eq!(h, expect, "scene triangle {t} covered {h} times");
    }
}

fn volume(mesh: &TetMesh) -> f64 {
    mesh.tets
        .iter()
        .map(|t| {
            let [a, b, c, d] = t.map(|v| mesh.points[v as usize].as_dvec3());
            (b - a).cross(c - a).dot(d - a) / 6.0
        })
        .sum()
}

#[test]
fn torus_knot_in_enclosing_box_builds_and_covers_every_triangle() {
    let scene = tet_build::procedural::by_name("torus-knot").unwrap();
    let stages = Arc::new(Mutex::new(Vec::new()));
    let s2 = stages.clone();
    let options = BuildOptions {
        enclosing_box: Some(BoxSpec::Relative { margin: 0.2 }),
        progress: Some(Arc::new(move |p| s2.lock().unwrap().push(p.stage))),
        ..BuildOptions::default()
    };
    let (mesh, report) = build(&scene, &options).unwrap();
    mesh.validate().unwrap();
    assert_eq!(mesh.triangle_count as usize, scene.triangles.len());
    assert_covers_scene(&mesh, &scene, &[]);
    assert_eq!(report.constrained_faces, scene.triangles.len());
    assert_eq!(report.boundary_triangles, 12);
    // The tets fill the enclosing box exactly (box corners are the extreme points).
    let (lo, hi) = mesh.points.iter().fold(
        (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
        |(lo, hi), p| (lo.min(p.as_dvec3()), hi.max(p.as_dvec3())),
    );
    let boxv = (hi - lo).x * (hi - lo).y * (hi - lo).z;
    assert!(
        (volume(&mesh) - boxv).abs() < 1e-9 * boxv,
        "{} vs {boxv}",
        volume(&mesh)
    );
    // Box triangles are boundary, not constrained: exactly 12 boundary faces.
    let boundary = mesh
        .neighbors
        .iter()
        .flatten()
        .filter(|l| l.is_boundary())
        .count();
    assert_eq!(boundary, 12);
    let stages = stages.lock().unwrap();
    assert_eq!(stages.first(), Some(&Stage::Clean));
    assert!(stages.contains(&Stage::Tetgen { round: 1 }));
    assert_eq!(stages.last(), Some(&Stage::Validate));
    assert!(report.times.total >= report.times.tetgen);
    assert!(report.peak_memory_kib.unwrap() > 0);
    // The torus knot has normals: one per mesh point.
    if scene.normals.is_some() {
        assert_eq!(
            mesh.attributes.normals.as_ref().unwrap().len(),
            mesh.points.len()
        );
    }
}

#[test]
fn isolated_build_matches_in_process_build() {
    let scene = tet_build::procedural::by_name("sphere").unwrap();
    let base = BuildOptions {
        enclosing_box: Some(BoxSpec::default()),
        ..BuildOptions::default()
    };
    let (a, _) = build(&scene, &base).unwrap();
    let (b, rb) = build(
        &scene,
        &BuildOptions {
            isolation: worker(),
            ..base.clone()
        },
    )
    .unwrap();
    assert_eq!(a, b);
    assert!(rb.worker_peak_memory_kib.unwrap() > 0);
}

#[test]
fn closed_surface_without_box_keeps_its_convex_hull() {
    // No enclosing box: -c keeps the convex hull, so a non-convex closed
    // surface (the torus knot) still has tets outside it.
    let scene = tet_build::procedural::by_name("sphere").unwrap();
    let (mesh, _) = build(&scene, &BuildOptions::default()).unwrap();
    mesh.validate().unwrap();
    assert_covers_scene(&mesh, &scene, &[]);
    // A sphere's surface is its convex hull: every boundary face is constrained.
    assert!(mesh.neighbors.iter().flatten().all(|l| !l.is_boundary()));
}

/// Field-by-field equality (clearer failures than one `assert_eq!` on the mesh).
fn assert_same_mesh(a: &TetMesh, b: &TetMesh, what: &str) {
    assert_eq!(a.points, b.points, "{what}: points");
    assert_eq!(a.tets, b.tets, "{what}: tets");
    assert_eq!(a.neighbors, b.neighbors, "{what}: neighbors");
    assert_eq!(a.constrained, b.constrained, "{what}: constrained");
    assert_eq!(a.triangle_count, b.triangle_count, "{what}: triangle_count");
    assert_eq!(a.attributes, b.attributes, "{what}: attributes");
}

/// Scenes of different kinds: closed surfaces with and without an enclosing
/// box, normals, open surfaces, cleaned input, Steiner points and f32 rounding.
fn assembly_scenes() -> Vec<(&'static str, Scene, Option<BoxSpec>)> {
    let knot = tet_build::procedural::by_name("torus-knot").unwrap();
    let sphere = tet_build::procedural::by_name("sphere").unwrap();
    let open = scene(
        vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::new(1.0, 1.0, 0.3),
            Vec3::new(0.5, 0.5, 0.0), // unused
        ],
        vec![[0, 1, 2], [1, 3, 2]],
    );
    let mut dirty = sphere.clone();
    dirty.triangles.push(dirty.triangles[3]); // duplicate
    dirty.vertices.push(dirty.vertices[0]); // merged copy
    let n = dirty.vertices.len() as u32 - 1;
    let t = dirty.triangles[5];
    dirty.triangles[5] = [n, t[1], t[2]].map(|v| if v == 0 { n } else { v });
    if let Some(normals) = dirty.normals.as_mut() {
        normals.push(normals[0]);
    }
    vec![
        ("torus knot, box", knot.clone(), Some(BoxSpec::default())),
        ("torus knot, convex hull", knot, None),
        ("sphere", sphere, None),
        ("dirty sphere, box", dirty, Some(BoxSpec::default())),
        ("open surface, box", open, Some(BoxSpec::default())),
        (
            "Schönhardt at 2^20",
            schoenhardt(1048576.0, 40.0, 60.0),
            Some(BoxSpec::Relative { margin: 0.5 }),
        ),
        (
            "Schönhardt at 2^24",
            schoenhardt(16777216.0, 30.0, 6.0),
            Some(BoxSpec::Relative { margin: 0.5 }),
        ),
    ]
}

#[test]
fn tetgen_adjacency_assembly_equals_sorted_face_key_assembly() {
    for (name, s, bbox) in assembly_scenes() {
        let reference = BuildOptions {
            enclosing_box: bbox,
            assembly: Assembly::SortFaceKeys,
            validation: Validation::Full,
            ..BuildOptions::default()
        };
        let (a, ra) = build(&s, &reference).unwrap();
        let (b, rb) = build(
            &s,
            &BuildOptions {
                assembly: Assembly::TetgenNeighbors,
                validation: Validation::Construction,
                ..reference.clone()
            },
        )
        .unwrap();
        assert_same_mesh(&a, &b, name);
        b.validate().unwrap();
        assert!(!ra.switches.contains('n'), "{}", ra.switches);
        assert!(rb.switches.contains("nn"), "{}", rb.switches);
        assert_eq!(ra.tetgen_rounds, rb.tetgen_rounds, "{name}");
    }
}

#[test]
fn hilbert_reorder_in_build_equals_tet_core_reorder() {
    for (name, s, bbox) in assembly_scenes().into_iter().take(4) {
        let options = BuildOptions {
            enclosing_box: bbox,
            ..BuildOptions::default()
        };
        let (mut a, ra) = build(&s, &options).unwrap();
        assert!(ra.reordering.is_none());
        let order = tet_core::reorder::hilbert_reorder(&mut a).unwrap();
        let stages = Arc::new(Mutex::new(Vec::new()));
        let s2 = stages.clone();
        let (b, rb) = build(
            &s,
            &BuildOptions {
                reorder: Reorder::Hilbert,
                progress: Some(Arc::new(move |p| s2.lock().unwrap().push(p.stage))),
                ..options.clone()
            },
        )
        .unwrap();
        assert_same_mesh(&a, &b, name);
        assert_eq!(rb.reordering.as_ref(), Some(&order), "{name}");
        b.validate().unwrap();
        assert_covers_scene(
            &b,
            &s,
            &ra.clean
                .duplicate_triangles
                .iter()
                .map(|d| d.dropped)
                .collect::<Vec<_>>(),
        );
        let stages = stages.lock().unwrap();
        let at = |st| stages.iter().position(|x| *x == st).unwrap();
        assert!(
            at(Stage::Assemble) < at(Stage::Reorder) && at(Stage::Reorder) < at(Stage::Validate)
        );
    }
}

/// Schönhardt's twisted prism cannot be tetrahedralized without Steiner
/// points, so TetGen must add some; with a coarse f32 grid (coordinates near
/// 2^20) their rounding is large, which exercises the rounding repair.
fn schoenhardt(offset: f32, scale: f32, height: f32) -> Scene {
    let mut v = Vec::new();
    for (z, twist) in [(0.0f32, 0.0f32), (1.0, 0.25)] {
        for k in 0..3 {
            let a = (k as f32 + twist) * std::f32::consts::TAU / 3.0;
            let p = Vec3::new(a.cos() * scale, a.sin() * scale, z * height) + Vec3::splat(offset);
            v.push(p.round());
        }
    }
    let t = vec![
        [0, 2, 1],
        [3, 4, 5],
        // Side quads (A_k, A_k+1, B_k+1, B_k) split along the diagonals
        // A_k–B_k+1, which make the twisted prism untetrahedralizable.
        [0, 1, 4],
        [0, 4, 3],
        [1, 2, 5],
        [1, 5, 4],
        [2, 0, 3],
        [2, 3, 5],
    ];
    scene(v, t)
}

#[test]
fn steiner_points_are_rounded_soundly() {
    // Representable prisms: one Steiner point, rounded harmlessly.
    for (offset, scale, height) in [
        (0.0, 64.0, 96.0),
        (1048576.0, 40.0, 60.0),
        (16777216.0, 30.0, 6.0),
    ] {
        let s = schoenhardt(offset, scale, height);
        let options = BuildOptions {
            enclosing_box: Some(BoxSpec::Relative { margin: 0.5 }),
            ..BuildOptions::default()
        };
        let (mesh, report) = build(&s, &options).unwrap();
        mesh.validate().unwrap();
        assert_covers_scene(&mesh, &s, &[]);
        assert!(
            report.steiner_points >= 1,
            "Schönhardt's prism needs a Steiner point"
        );
    }
    // At 2^24 the f32 spacing is 2: a prism of height 2 has no f32 value
    // strictly between its caps, so every rounding of the interior Steiner
    // point flattens tets. The build must refuse with a typed error (after
    // trying to snap and to re-run TetGen), never return a bad mesh.
    let s = schoenhardt(16777216.0, 1000.0, 2.0);
    let options = BuildOptions {
        enclosing_box: Some(BoxSpec::Relative { margin: 0.5 }),
        ..BuildOptions::default()
    };
    match build(&s, &options) {
        Err(BuildError::RoundingFlattens { count, tets, .. }) => {
            assert!(count > 0 && !tets.is_empty());
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn bad_scenes_are_typed_errors() {
    let opts = BuildOptions::default();
    assert!(matches!(
        build(&scene(vec![], vec![]), &opts),
        Err(BuildError::EmptyScene { .. })
    ));
    let tet = || {
        (
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
            vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        )
    };
    let (mut v, t) = tet();
    v[2].y = f32::NAN;
    assert!(matches!(
        build(&scene(v, t), &opts),
        Err(BuildError::Clean(CleanError::NonFiniteVertex {
            vertex: 2,
            ..
        }))
    ));
    let (mut v, t) = tet();
    v[1].x = f32::INFINITY;
    assert!(matches!(
        build(&scene(v, t), &opts),
        Err(BuildError::Clean(CleanError::NonFiniteVertex {
            vertex: 1,
            ..
        }))
    ));
    // A single triangle without a box: nothing to tetrahedralize.
    let flat = scene(vec![Vec3::X, Vec3::Y, Vec3::Z], vec![[0, 1, 2]]);
    assert!(matches!(
        build(&flat, &opts),
        Err(BuildError::Tetgen(TetgenError::FlatInput))
    ));
    // Crossing triangles: TetGen's self-intersection, in the isolated worker.
    let (mut v, mut t) = tet();
    v.extend([
        Vec3::new(0.1, 0.1, -0.5),
        Vec3::new(0.2, 0.15, 0.5),
        Vec3::new(0.6, 0.1, 0.2),
    ]);
    v.extend([Vec3::new(-1.0, -1.0, -1.0), Vec3::new(2.0, 2.0, 2.0)]);
    t.push([4, 5, 6]);
    let crossing = scene(v, t);
    // Resolved by default: the crossing triangles are split and it builds.
    let resolving = BuildOptions {
        isolation: worker(),
        enclosing_box: Some(BoxSpec::default()),
        ..BuildOptions::default()
    };
    let (mesh, report) = build(&crossing, &resolving).unwrap();
    mesh.validate().unwrap();
    assert!(report.resolve.pairs >= 1 && report.resolve.split_triangles >= 2);
    // Without resolving, the error names the pairs by input index: only the
    // added triangle (4) crosses the tet's faces (0..4).
    let isolated = BuildOptions {
        resolve: None,
        ..resolving
    };
    match build(&crossing, &isolated) {
        Err(BuildError::SelfIntersections { pairs, total }) => {
            assert!(total >= 1 && total == pairs.len());
            assert!(
                pairs.iter().all(|p| p.first < 4 && p.second == 4),
                "{pairs:?}"
            );
        }
        other => panic!("expected SelfIntersections, got {other:?}"),
    }
}

#[test]
fn degenerate_and_duplicate_triangles_are_cleaned_then_built() {
    let mut v = vec![
        Vec3::ZERO,
        Vec3::X,
        Vec3::Y,
        Vec3::Z,
        Vec3::new(0.5, 0.0, 0.0),
    ];
    let t = vec![
        [0, 2, 1],
        [0, 1, 3],
        [1, 2, 3],
        [0, 3, 2],
        [0, 4, 1], // collinear: zero area
        [3, 1, 0], // duplicate of triangle 1, other winding
    ];
    v.push(Vec3::new(0.1, 0.1, 0.1)); // unused vertex
    let s = scene(v, t);
    let options = BuildOptions {
        enclosing_box: Some(BoxSpec::default()),
        ..BuildOptions::default()
    };
    let (mesh, report) = build(&s, &options).unwrap();
    mesh.validate().unwrap();
    assert_eq!(report.clean.zero_area_triangles, vec![4]);
    assert_eq!(report.clean.duplicate_triangles.len(), 1);
    assert_covers_scene(&mesh, &s, &[4, 5]);
    assert_eq!(mesh.triangle_count, 6);
}

/// The full "Torus Knots in a Box" scene (27 knots + box object, 77,772
/// triangles): builds, validates, every triangle covered once (~5 s in
/// debug: TetGen itself is always compiled optimised).
#[test]
fn torus_knots_in_a_box_builds_and_covers_every_triangle() {
    let scene = tet_build::procedural::by_name("torus-knots-box").unwrap();
    assert_eq!(scene.triangles.len(), 77_772);
    let (mesh, report) = build(&scene, &BuildOptions::default()).unwrap();
    mesh.validate().unwrap();
    assert_covers_scene(&mesh, &scene, &[]);
    // The box object is the convex hull: the tets fill it.
    let (lo, hi) = scene.bounds().unwrap();
    let d = (hi - lo).as_dvec3();
    let boxv = d.x * d.y * d.z;
    assert!((volume(&mesh) - boxv).abs() < 1e-6 * boxv);
    let q = tet_build::quality::mesh_quality(&mesh).unwrap();
    eprintln!("{report:?}\n{q:?}");
    // Normals: the box object's 8 corners merge copies with three different
    // face normals each, so they carry none (zero: shade with the face
    // normal); every knot vertex keeps its own normal.
    let normals = mesh.attributes.normals.as_ref().unwrap();
    let input_normals = scene.normals.as_ref().unwrap();
    let b = &scene.objects[0];
    assert_eq!(b.name, "box");
    let box_corners: Vec<Vec3> = scene.vertices
        [b.first_vertex as usize..(b.first_vertex + b.vertex_count) as usize]
        .to_vec();
    let mut zero = 0;
    for (p, n) in mesh.points.iter().zip(normals) {
        if box_corners.contains(p) {
            assert_eq!(*n, Vec3::ZERO, "box corner {p}");
            zero += 1;
        } else if let Some(i) = scene.vertices.iter().position(|v| v == p) {
            assert_eq!(*n, input_normals[i], "knot vertex {p}");
        }
    }
    assert_eq!(zero, 8);
}

/// Pipeline vs bare TetGen on the paper's scenes. Heavy: run in release with
/// `cargo test --release -p tet-build --test pipeline -- --ignored --nocapture measure`.
///
/// Per scene and repetition (interleaved, so load changes hit all alike):
/// bare TetGen (`-pYcQz` on the very input the pipeline gives it), the
/// default pipeline with Hilbert reordering (TetGen adjacency, construction
/// check, parallel reorder) and the reference pipeline (sorted face keys,
/// full `validate`, then `tet_core::reorder::hilbert_reorder`). Reported:
/// best-of-N wall times, their ratios, and the overhead outside TetGen
/// (total − TetGen stage) whose best-of-N is less sensitive to a shared
/// machine than the TetGen time itself. `TET_MEASURE_REPS` sets N (default 3).
#[test]
#[ignore = "measurement, not a check: pipeline vs bare TetGen timings; run in release with --nocapture"]
fn measure_pipeline_against_bare_tetgen() {
    use std::time::Instant;
    use tet_build::tetgen::{TetgenInput, TetgenOptions, tetrahedralize};
    let reps: usize = std::env::var("TET_MEASURE_REPS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(3);
    let bunny = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/stanford-bunny.obj"
    );
    let mut cases: Vec<(String, Scene, Option<BoxSpec>)> = vec![(
        "Torus Knots in a Box".into(),
        tet_build::procedural::by_name("torus-knots-box").unwrap(),
        None,
    )];
    if std::path::Path::new(bunny).exists() {
        let s = Scene::load_obj(std::path::Path::new(bunny)).unwrap();
        cases.push(("bunny (convex hull, -c)".into(), s.clone(), None));
        cases.push((
            "bunny (enclosing box, margin 0.1)".into(),
            s,
            Some(BoxSpec::default()),
        ));
    }
    let min = |v: &[f64]| v.iter().cloned().fold(f64::MAX, f64::min);
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    for (name, scene, bbox) in cases {
        let fast = BuildOptions {
            enclosing_box: bbox,
            reorder: Reorder::Hilbert,
            ..BuildOptions::default()
        };
        let reference = BuildOptions {
            enclosing_box: bbox,
            assembly: Assembly::SortFaceKeys,
            validation: Validation::Full,
            ..BuildOptions::default()
        };
        // Bare TetGen on the very input the pipeline gives it (scene already clean).
        let (cleaned, _) = tet_build::clean::clean_scene(&scene).unwrap();
        let mut v = cleaned.vertices.clone();
        let mut t = cleaned.triangles.clone();
        let n = t.len();
        if let Some(spec) = bbox {
            tet_build::bbox::EnclosingBox::new(cleaned.bounds(), spec)
                .unwrap()
                .append_to(&mut v, &mut t);
        }
        let input = TetgenInput {
            points: v.iter().map(|p| p.as_dvec3().to_array()).collect(),
            markers: (0..t.len())
                .map(|i| if i < n { i as i32 + 1 } else { 0 })
                .collect(),
            triangles: t,
        };
        let (mut bare, mut new, mut old) = (Vec::new(), Vec::new(), Vec::new());
        let (mut new_over, mut old_over) = (Vec::new(), Vec::new());
        let mut last = None;
        for _ in 0..reps {
            let s = Instant::now();
            let out =
                tetrahedralize(&input, &TetgenOptions::default(), &Isolation::InProcess).unwrap();
            bare.push(s.elapsed().as_secs_f64());
            drop(out);

            let s = Instant::now();
            let (mesh, report) = build(&scene, &fast).unwrap();
            let total = s.elapsed();
            new.push(total.as_secs_f64());
            new_over.push((total - report.times.tetgen).as_secs_f64());

            let s = Instant::now();
            let (mut reference_mesh, old_report) = build(&scene, &reference).unwrap();
            let r = Instant::now();
            tet_core::reorder::hilbert_reorder(&mut reference_mesh).unwrap();
            let reorder = r.elapsed();
            let total = s.elapsed();
            old.push(total.as_secs_f64());
            old_over.push((total - old_report.times.tetgen).as_secs_f64());
            assert!(
                mesh == reference_mesh,
                "{name}: fast and reference meshes differ"
            );
            last = Some((report, old_report, reorder, mesh));
        }
        let (r, o, old_reorder, mesh) = last.unwrap();
        let q = tet_build::quality::mesh_quality(&mesh);
        println!(
            "{name}: {} triangles -> {} points ({} Steiner), {} tets, {} constrained faces",
            scene.triangles.len(),
            r.points,
            r.steiner_points,
            r.tets,
            r.constrained_faces
        );
        println!("    quality (Erkoç Table 3 metrics): {q:?}");
        let b = min(&bare);
        println!(
            "    best of {reps}: bare TetGen {b:.3} s; pipeline+Hilbert {:.3} s ({:.2}×); reference pipeline+Hilbert {:.3} s ({:.2}×)",
            min(&new),
            min(&new) / b,
            min(&old),
            min(&old) / b
        );
        println!(
            "    overhead outside TetGen (best of {reps}): {:.0} ms = {:.1} % of bare (new) vs {:.0} ms = {:.1} % (reference); bare+overhead ratio {:.3}× vs {:.3}×",
            min(&new_over) * 1e3,
            100.0 * min(&new_over) / b,
            min(&old_over) * 1e3,
            100.0 * min(&old_over) / b,
            (b + min(&new_over)) / b,
            (b + min(&old_over)) / b
        );
        println!("    all runs: bare {bare:.3?} new {new:.3?} reference {old:.3?}");
        let st = |t: &tet_build::pipeline::StageTimes, reorder: Duration| {
            format!(
                "clean {:.1} ms, tetgen {:.0} ms (inside {:.0}), rounding {:.1} ms, faces {:.1} ms, assemble {:.1} ms, reorder {:.1} ms, validate {:.1} ms",
                ms(t.clean),
                ms(t.tetgen),
                ms(t.tetgen_inside),
                ms(t.rounding),
                ms(t.constrained_faces),
                ms(t.assemble),
                ms(reorder),
                ms(t.validate)
            )
        };
        println!(
            "    last new stages:       {}",
            st(&r.times, r.times.reorder)
        );
        println!("    last reference stages: {}", st(&o.times, old_reorder));
        println!("    peak {:?} KiB", r.peak_memory_kib);
        // Isolated build, once.
        let iso = BuildOptions {
            isolation: worker(),
            ..fast.clone()
        };
        let s = Instant::now();
        let (_, ri) = build(&scene, &iso).unwrap();
        println!(
            "    isolated pipeline {:.3} s (tetgen {:?}, inside worker {:?}), worker peak {:?} KiB",
            s.elapsed().as_secs_f64(),
            ri.times.tetgen,
            ri.times.tetgen_inside,
            ri.worker_peak_memory_kib
        );
    }
}
