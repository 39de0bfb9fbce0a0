//! Interpenetrating scenes build (their crossings resolved) and trace like
//! the user's triangles: every ray's hit is checked against an f64 brute
//! force over the ORIGINAL input triangles (same triangle id, same `t`),
//! away from the intersection curves and triangle edges, with no step cap.

#![cfg(feature = "tetgen")]

use glam::{DVec3, Vec3};
use tet_build::bbox::BoxSpec;
use tet_build::intersect::find_self_intersections;
use tet_build::pipeline::{BuildError, BuildOptions, build};
use tet_build::procedural::{TorusKnotParams, box_mesh, icosphere, torus_knot};
use tet_build::scene::{MeshData, Scene};
use tet_core::TetMesh;
use tet_core::synthetic::SplitMix64;
use tet_trace_cpu::reference::{Aim, random_ray, ray_triangle, segment_distance};
use tet_trace_cpu::tet16::Tet16Tracer;
use tet_trace_cpu::tet20::Tet20Tracer;
use tet_trace_cpu::tet32::Tet32Tracer;
use tet_trace_cpu::{DuffF32, Failure, Ray, Start, TraceOutcome, Tracer};

/// Rays whose reference hit lies within this distance (relative to the
/// scene's size) of an edge of its triangle, of an intersection curve, or
/// whose two nearest hits are this close in `t`, are skipped: there the
/// answer depends on rounding (pieces meet the curves at f32-rounded
/// points, so the pieces' surface is within a few ulps of the input).
const REL_TOL: f64 = 1e-4;

/// A scene of several meshes, each scaled and moved.
fn scene_of(name: &str, parts: &[(&MeshData, f32, Vec3)]) -> Scene {
    let mut scene = Scene {
        name: name.into(),
        ..Scene::default()
    };
    for (mesh, scale, offset) in parts {
        let base = scene.vertices.len() as u32;
        scene
            .vertices
            .extend(mesh.positions.iter().map(|p| *p * *scale + *offset));
        scene
            .triangles
            .extend(mesh.triangles.iter().map(|t| t.map(|v| v + base)));
    }
    scene
}

/// Three spheres overlapping pairwise, and all three near the middle.
fn three_spheres() -> Scene {
    let s = icosphere(2);
    scene_of(
        "three spheres",
        &[
            (&s, 1.0, Vec3::ZERO),
            (&s, 0.9, Vec3::new(1.1, 0.2, 0.1)),
            (&s, 0.8, Vec3::new(0.5, 0.9, -0.3)),
        ],
    )
}

/// A box whose walls cut through a torus-knot tube.
fn box_through_knot() -> Scene {
    let knot = torus_knot(&TorusKnotParams::default());
    let cube = box_mesh(Vec3::new(-0.7, -0.9, -3.0), Vec3::new(0.8, 0.6, 3.0));
    scene_of(
        "box through knot",
        &[(&knot, 1.0, Vec3::ZERO), (&cube, 1.0, Vec3::ZERO)],
    )
}

/// The f64 reference over the input triangles: the closest hit's triangle
/// and `t`, or `None` for a miss, or `Err(())` when the ray is too close
/// to call (near an edge or a crossing curve, or two hits at nearly the
/// same `t`).
fn reference(
    scene: &Scene,
    curves: &[[DVec3; 2]],
    ray: &Ray,
    tol: f64,
) -> Result<Option<(u32, f64)>, ()> {
    let mut hits: Vec<(f64, u32, DVec3)> = Vec::new();
    for (i, tri) in scene.triangles.iter().enumerate() {
        let v = tri.map(|k| scene.vertices[k as usize]);
        if let Some((t, b)) = ray_triangle(ray, v)
            && t >= ray.t_min as f64
            && t <= ray.t_max as f64
        {
            let p = v.map(|x| x.as_dvec3());
            hits.push((t, i as u32, p[0] * b[0] + p[1] * b[1] + p[2] * b[2]));
        }
    }
    hits.sort_by(|a, b| a.0.total_cmp(&b.0));
    let Some(&(t, tri, p)) = hits.first() else {
        return Ok(None);
    };
    let d = ray.direction.as_dvec3().length();
    if hits.get(1).is_some_and(|h| (h.0 - t) * d < tol) {
        return Err(());
    }
    let v = scene.triangles[tri as usize].map(|k| scene.vertices[k as usize].as_dvec3());
    let near_edge = (0..3).any(|e| segment_distance(p, v[e], v[(e + 1) % 3]) < tol);
    let near_curve = curves.iter().any(|c| segment_distance(p, c[0], c[1]) < tol);
    if near_edge || near_curve {
        return Err(());
    }
    Ok(Some((tri, t)))
}

/// Segments of the crossing curves, approximated from both sides: for
/// each intersecting pair, the parts of each triangle's edges inside the
/// other triangle's slab are not needed — the resolved mesh's pieces of
/// the two parents share their intersection edges, so the curves are the
/// mesh edges whose two constrained faces come from different parents.
fn crossing_curves(mesh: &TetMesh) -> Vec<[DVec3; 2]> {
    use std::collections::HashMap;
    let mut edges: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    for cf in &mesh.constrained {
        let v = cf.vertices;
        for e in 0..3 {
            let (a, b) = (v[e], v[(e + 1) % 3]);
            edges
                .entry((a.min(b), a.max(b)))
                .or_default()
                .push(cf.triangle);
        }
    }
    edges
        .into_iter()
        .filter(|(_, parents)| {
            let mut p = parents.clone();
            p.sort_unstable();
            p.dedup();
            p.len() > 2 || (p.len() == 2 && parents.len() > 2)
        })
        .map(|((a, b), _)| {
            [
                mesh.points[a as usize].as_dvec3(),
                mesh.points[b as usize].as_dvec3(),
            ]
        })
        .collect()
}

/// Builds `scene` (resolved, in an enclosing box) and checks `rays` random
/// rays from inside the box on tet20, tet16 and tet32 against the
/// reference over the input triangles.
fn check_scene(scene: &Scene, rays: usize, seed: u64) {
    assert!(
        !find_self_intersections(&scene.vertices, &scene.triangles).is_clean(),
        "{}: the test scene should self-intersect",
        scene.name
    );
    // Without resolving, the build refuses the scene, naming the pairs.
    let refuse = BuildOptions {
        resolve: None,
        enclosing_box: Some(BoxSpec::default()),
        ..BuildOptions::default()
    };
    assert!(matches!(
        build(scene, &refuse),
        Err(BuildError::SelfIntersections { .. })
    ));
    let options = BuildOptions {
        enclosing_box: Some(BoxSpec::default()),
        ..BuildOptions::default()
    };
    let (mesh, report) = build(scene, &options).expect("resolved scene builds");
    mesh.validate().unwrap();
    assert!(report.resolve.pairs > 0 && report.resolve.split_triangles > 0);
    assert_eq!(mesh.triangle_count as usize, scene.triangles.len());
    assert!(mesh.constrained.len() > scene.triangles.len());
    // The first points are the scene's vertices, unmoved.
    for (p, v) in mesh.points.iter().zip(&scene.vertices) {
        assert_eq!(
            p.to_array().map(f32::to_bits),
            v.to_array().map(f32::to_bits)
        );
    }

    let (lo, hi) = mesh.point_bounds();
    let tol = REL_TOL * (hi - lo).as_dvec3().length();
    let curves = crossing_curves(&mesh);
    assert!(
        !curves.is_empty(),
        "{}: no crossing curve in the mesh",
        scene.name
    );
    let tracers: Vec<Box<dyn Tracer + '_>> = vec![
        Box::new(Tet20Tracer::<DuffF32>::new(&mesh).unwrap()),
        Box::new(Tet16Tracer::<DuffF32>::new(&mesh).unwrap()),
        Box::new(Tet32Tracer::<DuffF32>::new(&mesh).unwrap()),
    ];
    let mut rng = SplitMix64(seed);
    let (mut checked, mut hits) = (0usize, 0usize);
    for _ in 0..rays {
        let (ray, tet) = random_ray(&mesh, &mut rng, Aim::Random);
        let expected = reference(scene, &curves, &ray, tol);
        for tracer in &tracers {
            let outcome = tracer.trace(&ray, Start::Tet(tet));
            if let TraceOutcome::Failed { failure, .. } = outcome {
                assert_ne!(
                    failure,
                    Failure::StepCap,
                    "{}: step cap on {ray:?}",
                    scene.name
                );
            }
            let Ok(expected) = expected else { continue };
            match (expected, outcome) {
                (None, TraceOutcome::Miss { .. }) => {}
                (Some((tri, t)), TraceOutcome::Hit(h)) => {
                    assert_eq!(h.triangle, tri, "{}: wrong triangle on {ray:?}", scene.name);
                    let d = ray.direction.as_dvec3().length();
                    assert!(
                        (h.t as f64 - t).abs() * d < tol,
                        "{}: t {} against {t} on {ray:?}",
                        scene.name,
                        h.t
                    );
                }
                (e, o) => panic!("{}: expected {e:?}, got {o:?} on {ray:?}", scene.name),
            }
        }
        if let Ok(e) = expected {
            checked += 1;
            hits += e.is_some() as usize;
        }
    }
    // Most rays are clear of edges and curves, and many hit something.
    assert!(
        checked * 10 >= rays * 8,
        "{}: only {checked} of {rays} rays checked",
        scene.name
    );
    assert!(
        hits * 4 >= checked,
        "{}: only {hits} of {checked} rays hit",
        scene.name
    );
}

#[test]
fn three_overlapping_spheres_trace_like_their_input_triangles() {
    check_scene(&three_spheres(), 3000, 11);
}

#[test]
fn a_box_cutting_through_a_knot_traces_like_its_input_triangles() {
    check_scene(&box_through_knot(), 3000, 12);
}

#[test]
fn a_clean_scene_builds_identically_with_and_without_resolving() {
    let scene = tet_build::procedural::by_name("torus-knot").unwrap();
    let with = build(&scene, &BuildOptions::default()).unwrap();
    let without = build(
        &scene,
        &BuildOptions {
            resolve: None,
            ..BuildOptions::default()
        },
    )
    .unwrap();
    assert_eq!(with.0, without.0);
    assert_eq!(with.1.resolve, Default::default());
    assert_eq!(
        tet_core::format::to_bytes(&with.0),
        tet_core::format::to_bytes(&without.0)
    );
}
