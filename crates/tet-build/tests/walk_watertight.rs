//! Every walk is watertight on TetGen-built closed surfaces: a ray from
//! inside a closed, star-shaped surface must cross it exactly once, so any
//! miss, any hit farther along than the crossing, and any step cap is a
//! leak or a failure — no tolerance decides it. The rays are built to
//! hurt: aimed exactly at surface vertices, at points on surface edges,
//! at face centroids, and at midpoints of the tetrahedralization's own
//! edges (faces that are not scene triangles), from origins placed on
//! tet vertices and edges as well as in general position; the scenes are
//! bumpy spheres at unit scale, tiny, huge and far from the origin.

#![cfg(feature = "tetgen")]

use glam::Vec3;
use proptest::prelude::*;
use tet_build::pipeline::{BuildOptions, build};
use tet_build::procedural::icosphere;
use tet_build::scene::Scene;
use tet_core::TetMesh;
use tet_core::synthetic::SplitMix64;
use tet_trace_cpu::exact::ExactTracer;
use tet_trace_cpu::tet16::Tet16Tracer;
use tet_trace_cpu::tet20::Tet20Tracer;
use tet_trace_cpu::tet32::Tet32Tracer;
use tet_trace_cpu::tet80::Tet80ConsistentTracer;
use tet_trace_cpu::{DuffF32, Ray, Start, TraceOutcome, Tracer, locate};

/// A bumpy sphere: an icosphere with every vertex moved radially by up to
/// `bump` (relative), then scaled and moved. With `bump ≤ 0.06` every face
/// is seen from within radius 0.2 of the centre at a steep angle, so rays
/// from there cross the surface once.
fn bumpy_sphere(levels: u32, bump: f32, scale: f32, offset: Vec3, seed: u64) -> Scene {
    let s = icosphere(levels);
    let mut rng = SplitMix64(seed);
    let vertices = s
        .positions
        .iter()
        .map(|p| *p * (1.0 + bump * (rng.next_f64() as f32 * 2.0 - 1.0)) * scale + offset)
        .collect();
    Scene {
        name: "bumpy sphere".into(),
        vertices,
        triangles: s.triangles.clone(),
        ..Scene::default()
    }
}

/// The f64 crossing of `ray` with the closed surface: the smallest `t`
/// over the scene's triangles that the ray's line meets, each triangle
/// grown by `1e-9` of its size (an f64 test of a ray aimed exactly at an
/// edge may reject both triangles by rounding; the `t` of either is the
/// crossing).
fn crossing(scene: &Scene, ray: &Ray) -> Option<f64> {
    let (o, d) = (ray.origin.as_dvec3(), ray.direction.as_dvec3());
    scene
        .triangles
        .iter()
        .filter_map(|t| {
            let v = t.map(|k| scene.vertices[k as usize].as_dvec3());
            let q = v.map(|p| p - o);
            let w = [
                d.dot(q[1].cross(q[2])),
                d.dot(q[2].cross(q[0])),
                d.dot(q[0].cross(q[1])),
            ];
            let sum = w[0] + w[1] + w[2];
            if sum == 0.0 || w.iter().any(|x| x / sum < -1e-9) {
                return None;
            }
            let n = (v[1] - v[0]).cross(v[2] - v[0]);
            Some(n.dot(v[0] - o) / n.dot(d))
        })
        .filter(|&t| t >= 0.0)
        .min_by(f64::total_cmp)
}

/// Rays from inside the sphere of centre `c` and radius `r` (at most 0.2
/// of the bumpy sphere's radius): origins in general position, on tet
/// vertices and on tet edge midpoints inside that ball; targets on surface
/// vertices, surface edges, face centroids and inner tet edge midpoints.
fn rays_from_inside(mesh: &TetMesh, scene: &Scene, c: Vec3, r: f32, seed: u64) -> Vec<Ray> {
    let mut rng = SplitMix64(seed);
    let inner: Vec<Vec3> = mesh
        .tets
        .iter()
        .flat_map(|t| {
            let p = t.map(|k| mesh.points[k as usize]);
            [
                p[0],
                (p[0] + p[1]) * 0.5,
                (p[1] + p[2]) * 0.5,
                (p[2] + p[3]) * 0.5,
            ]
        })
        .filter(|p| (*p - c).length() < r)
        .collect();
    let mut pick = |n: usize| (rng.next_u64() % n as u64) as usize;
    let mut out = Vec::new();
    for k in 0..240 {
        let origin = match k % 3 {
            0 if !inner.is_empty() => inner[pick(inner.len())],
            _ => {
                let u = Vec3::new(
                    pick(1000) as f32 / 1000.0 - 0.5,
                    pick(1000) as f32 / 1000.0 - 0.5,
                    pick(1000) as f32 / 1000.0 - 0.5,
                );
                c + u * r
            }
        };
        let tri = scene.triangles[pick(scene.triangles.len())].map(|v| scene.vertices[v as usize]);
        let target = match k % 4 {
            0 => tri[0],
            1 => tri[0] + (tri[1] - tri[0]) * (pick(1024) as f32 / 1024.0),
            2 => (tri[0] + tri[1] + tri[2]) / 3.0,
            _ if !inner.is_empty() => inner[pick(inner.len())],
            _ => tri[1],
        };
        if target != origin {
            out.push(Ray::new(origin, target - origin));
        }
    }
    out
}

/// Builds the scene and checks every walk on every ray: a hit at the f64
/// crossing (within `1e-4` of the scene's size plus `1e-6` of its largest
/// coordinate, a few f32 ulps, along the ray), never a miss, a farther hit
/// or a failure.
fn check(scene: &Scene, radius: f32, centre: Vec3, seed: u64) {
    let (mesh, _) = build(scene, &BuildOptions::default()).expect("the sphere builds");
    let tracers: Vec<Box<dyn Tracer + '_>> = vec![
        Box::new(Tet20Tracer::<DuffF32>::new(&mesh).unwrap()),
        Box::new(Tet16Tracer::<DuffF32>::new(&mesh).unwrap()),
        Box::new(Tet32Tracer::<DuffF32>::new(&mesh).unwrap()),
        Box::new(Tet80ConsistentTracer::consistent(&mesh).unwrap()),
        Box::new(ExactTracer::new(&mesh)),
    ];
    let rays = rays_from_inside(&mesh, scene, centre, 0.2 * radius, seed);
    assert!(rays.len() > 200);
    let (lo, hi) = mesh.point_bounds();
    let magnitude = lo.abs().max(hi.abs()).max_element() as f64;
    let size = (2.0 * radius) as f64;
    for ray in &rays {
        let t = crossing(scene, ray).expect("a ray from inside crosses the surface");
        let slack = (1e-4 * size + 1e-6 * magnitude) / ray.direction.as_dvec3().length();
        let start = Start::Tet(locate(&mesh, ray.origin, 0).unwrap());
        for tracer in &tracers {
            match tracer.trace(ray, start) {
                TraceOutcome::Hit(h) => assert!(
                    (h.t as f64 - t).abs() <= slack,
                    "{}: hit at t = {} where the surface is crossed at {t}: {ray:?}",
                    tracer.name(),
                    h.t
                ),
                other => panic!("{} leaked or failed on {ray:?}: {other:?}", tracer.name()),
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 8, .. ProptestConfig::default() })]

    #[test]
    fn no_walk_leaks_out_of_a_closed_surface(
        levels in 2u32..4,
        bump in 0.0f32..0.06,
        extreme in 0usize..4,
        seed in any::<u64>(),
    ) {
        let (scale, offset) = [
            (1.0, Vec3::ZERO),
            (1e-3, Vec3::ZERO),
            (1e3, Vec3::new(-2e3, 5e2, 1e3)),
            (1.0, Vec3::new(1e4, -1e4, 3e4)),
        ][extreme];
        let scene = bumpy_sphere(levels, bump, scale, offset, seed);
        check(&scene, scale * (1.0 - bump), offset, seed ^ 0x5eed);
    }
}

/// The same check on an exact, unbumped sphere whose rays pass through
/// vertices shared by five or six faces (the icosphere's own vertices).
#[test]
fn rays_through_icosphere_vertices_never_leak() {
    let scene = bumpy_sphere(3, 0.0, 1.0, Vec3::ZERO, 1);
    check(&scene, 1.0, Vec3::ZERO, 2);
}
