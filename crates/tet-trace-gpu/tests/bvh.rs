//! The GPU BVH baseline (`GpuBvh`) against the f64 brute-force reference
//! (`tet_trace_cpu::reference::closest_hit`) and against the GPU tet walk
//! on procedural meshes (`tet_core::synthetic::kuhn_grid`): random rays,
//! rays with a `[t_min, t_max]` window, rays from inside a closed shell,
//! camera rays made on the GPU and on the host, scenes at 1e-30 and 1e30,
//! split dispatches and the typed errors.
//!
//! Runs on any wgpu adapter; without a GPU, install lavapipe
//! (`apt-get install -y mesa-vulkan-drivers`). When no adapter is found the
//! tests print a skip message, unless `TET_GPU_REQUIRED=1` is set (CI), which
//! turns that into a failure.
//!
//! Tolerance: a ray is *grazing* when its line passes within [`GRAZE`] (times
//! the mesh's scale) of an edge of some constrained face
//! (`reference::grazes_an_edge`); only there may the hit triangle depend on
//! rounding (the BVH's Möller–Trumbore test is not watertight, the walk is).
//! Every other ray must hit the same triangle as the brute force, with `t`
//! within f32 rounding.

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::scene::Camera;
use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};
use tet_trace_cpu::reference::{closest_hit, grazes_an_edge, ray_triangle};
use tet_trace_cpu::render::PinholeCamera;
use tet_trace_cpu::{Ray, locate};
use tet_trace_gpu::{BvhHit, GpuBvh, GpuContext, GpuError, GpuLayout, GpuOptions, GpuTracer};

mod common;
use common::{GRAZE, gpu, gpu_with, random_rays, shell_in_view};

/// The mesh of the walk tests' random rays: 5³ jittered cells, 15 % of the
/// faces constrained.
fn scattered_faces(scale: f32) -> TetMesh {
    kuhn_grid(&GridSpec {
        cells: [5, 5, 5],
        jitter: 0.12,
        constrained_fraction: 0.15,
        scale,
        seed: 11,
        ..Default::default()
    })
}

/// True when some face's crossing lies within rounding of the ray's
/// `t_min` or `t_max` (a distance along the ray below [`GRAZE`] times the
/// mesh's `scale`), where whether it counts depends on rounding.
fn near_a_bound(mesh: &TetMesh, ray: &Ray, scale: f64) -> bool {
    let len = ray.direction.as_dvec3().length();
    let near = |t: f64, b: f32| {
        b.is_finite() && (t - b as f64).abs() * len <= GRAZE * (scale + t.abs() * len)
    };
    mesh.constrained.iter().any(|cf| {
        let v = cf.vertices.map(|k| mesh.points[k as usize]);
        ray_triangle(ray, v).is_some_and(|(t, _)| near(t, ray.t_min) || near(t, ray.t_max))
    })
}

/// Checks every non-grazing ray against the brute force (same triangle,
/// `t` within f32 rounding); returns the number of grazing rays.
fn check_reference(mesh: &TetMesh, rays: &[Ray], hits: &[Option<BvhHit>], scale: f64) -> usize {
    assert_eq!(rays.len(), hits.len());
    let mut grazing = 0;
    for (i, (ray, h)) in rays.iter().zip(hits).enumerate() {
        if grazes_an_edge(mesh, ray, GRAZE * scale) || near_a_bound(mesh, ray, scale) {
            grazing += 1;
            continue;
        }
        let r = closest_hit(mesh, ray);
        assert_eq!(
            h.map(|h| h.triangle),
            r.map(|r| r.triangle),
            "ray {i} {ray:?}: GPU BVH {h:?} vs brute force {r:?}"
        );
        if let (Some(h), Some(r)) = (h, r) {
            let len = ray.direction.as_dvec3().length();
            let err = (h.t as f64 - r.t).abs() * len;
            assert!(
                err <= 1e-5 * (scale + r.t * len),
                "ray {i} {ray:?}: t {} vs {}",
                h.t,
                r.t
            );
        }
    }
    grazing
}

#[test]
fn random_rays_match_the_brute_force_and_the_walk() {
    let Some(ctx) = gpu() else { return };
    let mesh = scattered_faces(1.0);
    let bvh = GpuBvh::from_mesh(&ctx, &mesh).unwrap();
    let (mut rays, starts) = random_rays(&mesh, 2000, 5);
    // The same rays with a window: hits before t_min or after t_max do
    // not count.
    let windowed: Vec<Ray> = rays
        .iter()
        .take(600)
        .map(|r| Ray {
            t_min: 0.4,
            t_max: 2.5,
            ..*r
        })
        .collect();
    rays.extend(windowed);
    let (hits, stats) = bvh.trace_batch(&rays).unwrap();
    let grazing = check_reference(&mesh, &rays, &hits, 1.0);
    let n = rays.len() as u64;
    let hit_count = hits.iter().flatten().count() as u64;
    assert_eq!((stats.rays, stats.hits, stats.failures), (n, hit_count, 0));
    assert_eq!((stats.method.as_str(), stats.dispatches), ("gpu-bvh", 1));
    assert_eq!(stats.gpu_ms.is_some(), ctx.has_timestamps());
    // Every ray tests the root's box at least.
    assert!(stats.tets_visited >= n, "{stats:?}");
    assert!(hit_count > 1000, "too few hits to be a test: {stats:?}");
    // Nodes of 32 B, at least one 48 B triangle per face.
    assert!(bvh.gpu_bytes() >= 48 * mesh.constrained.len() as u64 + 32);
    assert!(bvh.build_ms() > 0.0);
    eprintln!(
        "{} rays ({grazing} grazing or at a window bound), {:.1} boxes/ray, {} B on the \
         GPU, built in {:.2} ms: {stats:?}",
        n,
        stats.tets_visited as f64 / n as f64,
        bvh.gpu_bytes(),
        bvh.build_ms()
    );

    // The GPU walk (Tet20) on the unwindowed rays: the same triangles
    // except on grazing rays.
    let walk = GpuTracer::new(&ctx, &mesh, GpuLayout::Tet20).unwrap();
    let k = starts.len();
    let (outcomes, _) = walk.trace_batch(&rays[..k], &starts).unwrap();
    let mut differ = 0;
    for (i, (o, h)) in outcomes.iter().zip(&hits[..k]).enumerate() {
        if o.hit().map(|x| x.triangle) != h.map(|h| h.triangle) {
            differ += 1;
            assert!(
                grazes_an_edge(&mesh, &rays[i], GRAZE),
                "ray {i} {:?}: walk {o:?}, BVH {h:?}",
                rays[i]
            );
        }
    }
    eprintln!("walk vs BVH: {differ} of {k} rays differ (all grazing)");

    // Invalid rays are misses that test no box.
    let invalid = [
        Ray::new(Vec3::splat(1.0), Vec3::new(f32::NAN, 0.0, 1.0)),
        Ray::new(Vec3::splat(1.0), Vec3::ZERO),
        Ray::new(Vec3::splat(f32::INFINITY), Vec3::X),
    ];
    let (out, s) = bvh.trace_batch(&invalid).unwrap();
    assert_eq!(out, vec![None; 3]);
    assert_eq!((s.rays, s.hits, s.tets_visited), (3, 0, 0));
}

#[test]
fn rays_from_inside_a_closed_shell_hit_it() {
    let Some(ctx) = gpu() else { return };
    let mesh = kuhn_grid(&GridSpec {
        cells: [5, 5, 5],
        jitter: 0.1,
        shell: Some(([1, 1, 1], [4, 4, 4])),
        seed: 3,
        ..Default::default()
    });
    let bvh = GpuBvh::from_mesh(&ctx, &mesh).unwrap();
    let (rays, _) = random_rays(&mesh, 1500, 9);
    let (hits, _) = bvh.trace_batch(&rays).unwrap();
    check_reference(&mesh, &rays, &hits, 1.0);
    // Jitter moves shell vertices by at most 0.15: an origin in
    // [1.2, 3.8]³ is strictly inside the shell.
    let mut inside = 0;
    for (r, h) in rays.iter().zip(&hits) {
        if r.origin.cmpgt(Vec3::splat(1.2)).all() && r.origin.cmplt(Vec3::splat(3.8)).all() {
            inside += 1;
            assert!(
                h.is_some() || grazes_an_edge(&mesh, r, GRAZE),
                "ray {r:?} escaped the shell"
            );
        }
    }
    assert!(inside > 100, "only {inside} rays inside the shell");
}

/// The BVH's GPU camera rays against the host's camera rays through the
/// same BVH, the brute force on the host's rays and the GPU tet walk's
/// frame: the same triangle on every pixel whose ray does not graze an
/// edge (the host's ray may differ from the GPU's in the last bit).
fn camera_case(ctx: &GpuContext, mesh: &TetMesh, camera: &Camera, w: u32, h: u32, centers: bool) {
    let bvh = GpuBvh::from_mesh(ctx, mesh).unwrap();
    let (image, stats) = bvh.render(camera, w, h, centers).unwrap();
    assert_eq!(image.len(), (w * h) as usize);
    assert_eq!((stats.rays, stats.dispatches), ((w * h) as u64, 1));
    assert_eq!(stats.hits, image.iter().flatten().count() as u64);
    let cam = PinholeCamera::new(camera, w, h, centers);
    let rays: Vec<Ray> = (0..w * h).map(|p| cam.ray(p % w, p / w)).collect();
    let (batch, _) = bvh.trace_batch(&rays).unwrap();
    let start = locate(mesh, camera.position, 0).unwrap();
    let walk = GpuTracer::new(ctx, mesh, GpuLayout::Tet20).unwrap();
    let frame = walk.render(camera, w, h, centers, start).unwrap();
    let walked = frame.triangles();
    let grazing = check_reference(mesh, &rays, &image, 1.0);
    let (mut differ_batch, mut differ_walk) = (0, 0);
    for (i, ray) in rays.iter().enumerate() {
        let tri = image[i].map_or(u32::MAX, |x| x.triangle);
        let (batch_tri, walk_tri) = (batch[i].map_or(u32::MAX, |x| x.triangle), walked[i]);
        differ_batch += (tri != batch_tri) as usize;
        differ_walk += (tri != walk_tri) as usize;
        if (tri != batch_tri || tri != walk_tri) && !grazes_an_edge(mesh, ray, GRAZE) {
            panic!(
                "pixel {i} {ray:?}: GPU camera {:?}, host camera {:?}, walk {:?}",
                image[i], batch[i], frame.outcomes[i]
            );
        }
        if let (Some(a), Some(b)) = (image[i], batch[i])
            && a.triangle == b.triangle
        {
            assert!(
                (a.t - b.t).abs() <= 1e-5 * (1.0 + b.t),
                "pixel {i}: {a:?} vs {b:?}"
            );
        }
    }
    let hits = image.iter().flatten().count();
    assert!(hits > w as usize * h as usize / 3, "only {hits} hits");
    eprintln!(
        "camera {w}x{h}: {grazing} grazing, {differ_batch} differ from the host's rays, \
         {differ_walk} from the walk (all grazing); {stats:?}"
    );
}

#[test]
fn camera_rays_match_the_host_rays_and_the_walk() {
    let Some(ctx) = gpu() else { return };
    let (mesh, camera) = shell_in_view();
    camera_case(&ctx, &mesh, &camera, 40, 30, false);
    // An odd size (a partial workgroup) through pixel centres.
    camera_case(&ctx, &mesh, &camera, 37, 23, true);
}

/// A scene of one face (and of two faces of one triangle): the root is a
/// leaf; rays aimed at points of the faces hit them, with their triangle id.
#[test]
fn a_leaf_root_is_traced() {
    let Some(ctx) = gpu() else { return };
    let mut mesh = scattered_faces(1.0);
    mesh.constrained.truncate(2);
    mesh.constrained[1].triangle = mesh.constrained[0].triangle;
    for faces in [1, 2] {
        let mut scene = mesh.clone();
        scene.constrained.truncate(faces);
        let bvh = GpuBvh::from_mesh(&ctx, &scene).unwrap();
        let mut rng = SplitMix64(3);
        let rays: Vec<Ray> = (0..200)
            .map(|i| {
                let v = scene.constrained[i % faces]
                    .vertices
                    .map(|k| scene.points[k as usize]);
                let (a, b) = (rng.next_f64() as f32, rng.next_f64() as f32);
                let (a, b) = if a + b > 1.0 {
                    (1.0 - a, 1.0 - b)
                } else {
                    (a, b)
                };
                let target = v[0] + (v[1] - v[0]) * a + (v[2] - v[0]) * b;
                let origin = Vec3::new(rng.next_f64() as f32, 2.5, rng.next_f64() as f32) * 5.0;
                Ray::new(origin, target - origin)
            })
            .collect();
        let (hits, stats) = bvh.trace_batch(&rays).unwrap();
        check_reference(&scene, &rays, &hits, 1.0);
        assert!(stats.hits > 150, "{faces} faces: {stats:?}");
        assert!(
            hits.iter()
                .flatten()
                .all(|h| h.triangle == scene.constrained[0].triangle)
        );
    }
}

/// Scenes at 2⁻¹⁰⁰ and 2¹⁰⁰ (about 1e-30 and 1e30), traced in the BVH's
/// frame scaled back near 1: the unit scene's rays scaled with the scene
/// (origin and direction, so `t` stays) hit what they hit in the unit
/// scene, and rays of unit length made in the scaled scene agree with the
/// brute force.
#[test]
fn scenes_far_from_unit_size_are_traced_at_scale() {
    let Some(ctx) = gpu() else { return };
    let unit = scattered_faces(1.0);
    let (rays, _) = random_rays(&unit, 1000, 7);
    let (expected, _) = GpuBvh::from_mesh(&ctx, &unit)
        .unwrap()
        .trace_batch(&rays)
        .unwrap();
    for scale in [2f32.powi(-100), 2f32.powi(100)] {
        let mesh = scattered_faces(scale);
        let bvh = GpuBvh::from_mesh(&ctx, &mesh).unwrap();
        let scaled: Vec<Ray> = rays
            .iter()
            .map(|r| Ray::new(r.origin * scale, r.direction * scale))
            .collect();
        let (hits, _) = bvh.trace_batch(&scaled).unwrap();
        let mut identical = 0;
        for (i, (h, e)) in hits.iter().zip(&expected).enumerate() {
            identical += (h == e) as usize;
            if h.map(|h| h.triangle) != e.map(|e| e.triangle) {
                assert!(
                    grazes_an_edge(&unit, &rays[i], GRAZE),
                    "scale {scale}, ray {i}: {h:?}, unit scene {e:?}"
                );
            } else if let (Some(h), Some(e)) = (h, e) {
                assert!((h.t - e.t).abs() <= 1e-6 * e.t, "ray {i}: {h:?} vs {e:?}");
            }
        }
        let (own, _) = random_rays(&mesh, 400, 7);
        let (own_hits, _) = bvh.trace_batch(&own).unwrap();
        let grazing = check_reference(&mesh, &own, &own_hits, scale as f64);
        let count = own_hits.iter().flatten().count();
        assert!(count > 200, "scale {scale}: only {count} hits");
        eprintln!(
            "scale {scale:e}: {identical} of {} scaled rays hit bit for bit as in the unit \
             scene; own rays: {count} hits, {grazing} grazing",
            rays.len()
        );
    }
}

#[test]
fn limits_split_dispatches_and_errors_are_typed() {
    let mesh = kuhn_grid(&GridSpec {
        cells: [3, 3, 3],
        jitter: 0.1,
        constrained_fraction: 0.3,
        seed: 4,
        ..Default::default()
    });
    let Some(tiny) = gpu_with(&GpuOptions {
        max_buffer_bytes: Some(256),
        ..Default::default()
    }) else {
        return;
    };
    match GpuBvh::from_mesh(&tiny, &mesh) {
        Err(GpuError::TooLarge {
            buffer,
            bytes,
            value,
            ..
        }) => {
            assert!(buffer.starts_with("BVH"), "{buffer}");
            assert!(bytes > 256);
            assert_eq!(value, 256);
        }
        Err(e) => panic!("wrong error: {e}"),
        Ok(_) => panic!("a BVH over the limit was accepted"),
    }
    // A 64 KiB cap: 65536 / 40 = 1638 rays per dispatch (the per-ray
    // bound of every kernel); results equal the unsplit run.
    let small = gpu_with(&GpuOptions {
        max_buffer_bytes: Some(1 << 16),
        ..Default::default()
    })
    .unwrap();
    let full = gpu().unwrap();
    let (split_bvh, full_bvh) = (
        GpuBvh::from_mesh(&small, &mesh).unwrap(),
        GpuBvh::from_mesh(&full, &mesh).unwrap(),
    );
    let (rays, _) = random_rays(&mesh, 3000, 8);
    let (a, sa) = split_bvh.trace_batch(&rays).unwrap();
    let (b, sb) = full_bvh.trace_batch(&rays).unwrap();
    assert_eq!((sa.dispatches, sb.dispatches), (2, 1));
    assert_eq!(a, b);
    assert!(a.iter().flatten().count() > 500);
    let camera = Camera {
        position: Vec3::new(0.4, 0.5, 0.6),
        target: Vec3::splat(1.5),
        up: Vec3::Z,
        vfov_deg: 60.0,
    };
    let (a, sa) = split_bvh.render(&camera, 64, 48, true).unwrap();
    let (b, sb) = full_bvh.render(&camera, 64, 48, true).unwrap();
    assert_eq!((sa.dispatches, sb.dispatches), (2, 1));
    assert_eq!(a, b);

    // Empty inputs.
    let (none, s) = full_bvh.trace_batch(&[]).unwrap();
    assert!(none.is_empty());
    assert_eq!((s.rays, s.dispatches), (0, 0));
    for (w, h) in [(0, 10), (10, 0), (1 << 16, 1 << 16)] {
        assert!(
            matches!(
                full_bvh.render(&camera, w, h, false),
                Err(GpuError::Camera { .. })
            ),
            "{w}x{h}"
        );
    }
    let degenerate = Camera {
        target: camera.position,
        ..camera
    };
    assert!(matches!(
        full_bvh.render(&degenerate, 8, 8, false),
        Err(GpuError::Camera { .. })
    ));
    let empty = kuhn_grid(&GridSpec::default());
    assert!(empty.constrained.is_empty());
    assert!(matches!(
        GpuBvh::from_mesh(&full, &empty),
        Err(GpuError::EmptyScene)
    ));
}
