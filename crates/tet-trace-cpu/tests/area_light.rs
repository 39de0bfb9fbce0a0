//! Area and mesh lights against closed forms (irradiance from a rectangle
//! parallel to the receiving plane) and, with an occluder, against an
//! independent f64 brute-force visibility per sample.

use glam::{DVec3, Vec3};
use tet_core::TetMesh;
use tet_core::scene::Camera;
use tet_core::synthetic::{GridSpec, constrain_faces, kuhn_grid};
use tet_trace_cpu::area_light::{AreaLight, AreaLightError, geometry, irradiance, strata};
use tet_trace_cpu::reference::{edge_distance, trace_from};
use tet_trace_cpu::render::{Lights, RenderOptions, render_scene, render_scene_with};
use tet_trace_cpu::secondary::{MeshWalker, ShadowTracer, hit_point};
use tet_trace_cpu::tet20::Tet20Tracer;
use tet_trace_cpu::tet80::Tet80Tracer;
use tet_trace_cpu::{DuffF32, Hit, Start, Tracer, locate};

/// The unjittered 4³ grid with the tet faces whose three vertices satisfy
/// `on` marked constrained, one scene triangle per face, wound to face +z.
fn grid_with(on: impl Fn(Vec3) -> bool) -> TetMesh {
    let g = kuhn_grid(&GridSpec {
        cells: [4, 4, 4],
        jitter: 0.0,
        ..Default::default()
    });
    constrain_faces(g, |v| v.iter().all(|&p| on(p)), Some(Vec3::Z))
}

fn hit_of(t: &dyn Tracer, origin: Vec3, dir: Vec3) -> Hit {
    *trace_from(t, origin, dir).unwrap().hit().expect("hit")
}

/// Irradiance at a point whose normal passes through a corner of a parallel
/// `a × b` rectangle at height `h`, Lambertian radiance 1: `π F` with the
/// classic form factor
/// `F = 1/(2π) [X/√(1+X²) atan(Y/√(1+X²)) + Y/√(1+Y²) atan(X/√(1+Y²))]`.
fn corner_irradiance(a: f64, b: f64, h: f64) -> f64 {
    let (x, y) = (a / h, b / h);
    let sx = (1.0 + x * x).sqrt();
    let sy = (1.0 + y * y).sqrt();
    0.5 * (x / sx * (y / sx).atan() + y / sy * (x / sy).atan())
}

/// The same point under a rectangle `[x0, x1] × [y0, y1]` (containing the
/// point's projection `(px, py)`): the sum of the four corner rectangles.
fn rect_irradiance(px: f64, py: f64, x: [f64; 2], y: [f64; 2], h: f64) -> f64 {
    let mut e = 0.0;
    for a in [px - x[0], x[1] - px] {
        for b in [py - y[0], y[1] - py] {
            e += corner_irradiance(a, b, h);
        }
    }
    e
}

#[test]
fn closed_form_sanity() {
    // An infinite plane gives π (radiance 1); a tiny patch gives L A / h².
    let inf = rect_irradiance(0.0, 0.0, [-1e7, 1e7], [-1e7, 1e7], 1.0);
    assert!((inf - std::f64::consts::PI).abs() < 1e-5);
    let tiny = rect_irradiance(0.0, 0.0, [-1e-3, 1e-3], [-1e-3, 1e-3], 2.0);
    assert!((tiny - 4e-6 / 4.0).abs() < 1e-10);
}

#[test]
fn free_rectangle_above_a_floor_point_matches_the_closed_form() {
    let m = grid_with(|p| p.z == 1.0);
    let t = Tet20Tracer::<DuffF32>::new(&m).unwrap();
    let hit = hit_of(&t, Vec3::new(1.7, 2.2, 1.5), -Vec3::Z);
    let p = hit_point(&m, &hit).as_dvec3();
    assert!((p - DVec3::new(1.7, 2.2, 1.0)).length() < 1e-6);
    // A 1.2 × 0.8 lamp centred above p at height 1.5, facing down, and an
    // off-centre one (p under neither centre nor corner).
    for (x, y) in [([1.1, 2.3], [1.8, 2.6]), ([0.5, 3.5], [2.0, 3.0])] {
        let corner = Vec3::new(x[0] as f32, y[0] as f32, 2.5);
        let eu = Vec3::new(0.0, (y[1] - y[0]) as f32, 0.0);
        let ev = Vec3::new((x[1] - x[0]) as f32, 0.0, 0.0);
        let light = AreaLight::parallelogram(corner, eu, ev, Vec3::new(1.0, 2.0, 0.5)).unwrap();
        assert!(light.pieces()[0].normal().z < 0.0);
        let want = rect_irradiance(p.x, p.y, x, y, 1.5);
        for shadow in [
            Box::new(MeshWalker::new(&m)) as Box<dyn ShadowTracer>,
            Box::new(Tet20Tracer::<DuffF32>::new(&m).unwrap()),
            Box::new(Tet80Tracer::new(&m).unwrap()),
        ] {
            let e = irradiance(shadow.as_ref(), &hit, Vec3::Z, &light, 1024, 7);
            assert_eq!(e.samples, 1024);
            assert_eq!((e.rays, e.visible, e.failures), (1024, 1024, 0));
            let got = e.irradiance.x as f64;
            assert!(
                ((got - want) / want).abs() < 2e-3,
                "{got} vs closed form {want}"
            );
            assert!((e.irradiance.y as f64 / got - 2.0).abs() < 1e-5);
        }
        // Stratification pays: 64 samples are already within 2 %.
        let e = irradiance(&t, &hit, Vec3::Z, &light, 64, 3).irradiance.x as f64;
        assert!(((e - want) / want).abs() < 2e-2, "{e} vs {want}");
        // A lamp facing up (away from p) gives nothing and casts no ray.
        let up = AreaLight::parallelogram(corner, ev, eu, Vec3::ONE).unwrap();
        let e = irradiance(&t, &hit, Vec3::Z, &up, 64, 3);
        assert_eq!((e.irradiance, e.rays), (Vec3::ZERO, 0));
    }
}

#[test]
fn mesh_light_ceiling_matches_the_closed_form() {
    // Floor z = 1 and a glowing ceiling z = 3 covering [0, 4]² (constrained
    // faces of the mesh, wound to face up: two-sided to light the floor).
    let m = grid_with(|p| p.z == 1.0 || p.z == 3.0);
    let ceiling: Vec<u32> = m
        .constrained
        .iter()
        .filter(|cf| m.points[cf.vertices[0] as usize].z == 3.0)
        .map(|cf| cf.triangle)
        .collect();
    assert_eq!(ceiling.len(), 32);
    let light = AreaLight::from_mesh(&m, &ceiling, Vec3::ONE)
        .unwrap()
        .with_two_sided(true);
    assert!((light.area() - 16.0).abs() < 1e-9);
    let t = Tet20Tracer::<DuffF32>::new(&m).unwrap();
    for origin in [Vec3::new(1.7, 2.2, 1.5), Vec3::new(0.4, 3.3, 1.5)] {
        let hit = hit_of(&t, origin, -Vec3::Z);
        let p = hit_point(&m, &hit).as_dvec3();
        let want = rect_irradiance(p.x, p.y, [0.0, 4.0], [0.0, 4.0], 2.0);
        for shadow in [
            Box::new(MeshWalker::new(&m)) as Box<dyn ShadowTracer>,
            Box::new(Tet80Tracer::new(&m).unwrap()),
        ] {
            let e = irradiance(shadow.as_ref(), &hit, Vec3::Z, &light, 6400, 1);
            // Every sample reaches the ceiling: the shadow ray stops on the
            // sampled face itself.
            assert_eq!((e.visible, e.rays, e.failures), (6400, 6400, 0));
            let got = e.irradiance.x as f64;
            assert!(((got - want) / want).abs() < 3e-3, "{got} vs {want}");
        }
    }
    // A receiver facing away from the ceiling (normal −z) gets nothing.
    let hit = hit_of(&t, Vec3::new(1.7, 2.2, 2.0), -Vec3::Z);
    let e = irradiance(&t, &hit, -Vec3::Z, &light, 64, 1);
    assert_eq!(e.irradiance, Vec3::ZERO);
}

/// Brute-force visibility of `y` from `p` (on face `own`): `None` when a
/// triangle edge passes within `tol` of the segment.
fn brute_visible(m: &TetMesh, p: Vec3, own: u32, y: Vec3) -> Option<bool> {
    let tol = 1e-4;
    let (o, d) = (p.as_dvec3(), (y - p).as_dvec3());
    let mut vis = true;
    for (i, cf) in m.constrained.iter().enumerate() {
        if i as u32 == own {
            continue;
        }
        let v = cf.vertices.map(|k| m.points[k as usize].as_dvec3());
        let n = (v[1] - v[0]).cross(v[2] - v[0]);
        let den = n.dot(d);
        if den == 0.0 {
            continue;
        }
        let t = n.dot(v[0] - o) / den;
        // Faces through p itself (p lies on an edge of the floor) do not
        // occlude: the shadow ray starts on the floor.
        if !(0.0..=1.0).contains(&t) || t * d.length() < tol {
            continue;
        }
        let x = o + d * t;
        if edge_distance(x, v) < tol {
            return None;
        }
        if (0..3).all(|k| (v[(k + 1) % 3] - v[k]).cross(x - v[k]).dot(n) >= 0.0) {
            vis = false;
        }
    }
    Some(vis)
}

#[test]
fn half_occluded_lamp_matches_brute_force_and_symmetry() {
    // Floor z = 1; an occluding half-plane z = 2, x ≤ 2; a lamp at z = 3
    // centred on x = 2 above the point (2, 2.2, 1): by symmetry about x = 2,
    // exactly half of the irradiance is blocked.
    let m = grid_with(|p| p.z == 1.0 || (p.z == 2.0 && p.x <= 2.0));
    let t = Tet20Tracer::<DuffF32>::new(&m).unwrap();
    let hit = hit_of(&t, Vec3::new(2.0, 2.2, 1.5), -Vec3::Z);
    let p = hit_point(&m, &hit);
    let light = AreaLight::parallelogram(
        Vec3::new(1.5, 1.8, 3.0),
        Vec3::new(0.0, 0.8, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::ONE,
    )
    .unwrap();
    let full = rect_irradiance(p.x as f64, p.y as f64, [1.5, 2.5], [1.8, 2.6], 2.0);
    let (n, seed) = (1024, 5);
    for shadow in [
        Box::new(MeshWalker::new(&m)) as Box<dyn ShadowTracer>,
        Box::new(Tet20Tracer::<DuffF32>::new(&m).unwrap()),
        Box::new(Tet80Tracer::new(&m).unwrap()),
    ] {
        let e = irradiance(shadow.as_ref(), &hit, Vec3::Z, &light, n, seed);
        let got = e.irradiance.x as f64;
        assert!((got / full - 0.5).abs() < 5e-3, "{got} vs half of {full}");
        assert!((e.unoccluded_fraction() - 0.5).abs() < 0.01);
        // Per sample, against the brute force (same samples, same seed).
        let mut brute = 0.0;
        let mut skipped = 0;
        for s in light.samples(n, seed) {
            match brute_visible(&m, p, hit.face, s.point) {
                Some(true) => brute += geometry(p, Vec3::Z, &s, false),
                Some(false) => {}
                None => skipped += 1,
            }
        }
        assert!(skipped < 8, "{skipped}");
        let brute = brute * light.area() / n as f64;
        assert!(
            (got - brute).abs() <= full * 0.5 * skipped as f64 / n as f64 * 4.0 + 1e-6,
            "{got} vs brute force {brute}"
        );
    }
}

#[test]
fn bad_lights_are_typed_errors() {
    let m = grid_with(|p| p.z == 1.0);
    assert!(matches!(
        AreaLight::parallelogram(Vec3::ZERO, Vec3::X, Vec3::X * 2.0, Vec3::ONE),
        Err(AreaLightError::Degenerate { piece: 0 })
    ));
    assert!(matches!(
        AreaLight::parallelogram(Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::splat(-1.0)),
        Err(AreaLightError::BadRadiance { .. })
    ));
    assert!(matches!(
        AreaLight::from_mesh(&m, &[9999], Vec3::ONE),
        Err(AreaLightError::UnknownTriangle { triangle: 9999 })
    ));
    assert!(matches!(
        AreaLight::new([], Vec3::ONE),
        Err(AreaLightError::Empty)
    ));
    assert_eq!(strata(16), (4, 4));
    assert_eq!(strata(10), (4, 3));
    assert_eq!(strata(0), (1, 1));
}

#[test]
fn renderer_adds_area_lights_and_point_scenes_pay_nothing() {
    let m = grid_with(|p| p.z == 1.0);
    let t = Tet20Tracer::<DuffF32>::new(&m).unwrap();
    let camera = Camera {
        position: Vec3::new(2.0, 2.0, 3.5),
        target: Vec3::new(2.0, 2.05, 1.0),
        up: Vec3::Y,
        vfov_deg: 45.0,
    };
    let lamp = AreaLight::parallelogram(
        Vec3::new(1.5, 1.5, 3.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::ONE,
    )
    .unwrap();
    let opts = RenderOptions {
        width: 8,
        height: 6,
        shadows: true,
        area_samples: 16,
        seed: 9,
        ..Default::default()
    };
    let areas = [lamp];
    let lights = Lights {
        points: &[],
        areas: &areas,
    };
    let f = render_scene(&t, &camera, &lights, &opts).unwrap();
    assert_eq!(f.stats.hits, 48);
    assert_eq!(f.stats.shadow_rays, 48 * 16);
    assert_eq!(f.stats.shadow_failures, 0);
    // Each pixel is E/π of its hit point, E from the same estimator.
    let cam = tet_trace_cpu::render::PinholeCamera::new(&camera, 8, 6, false);
    let start = locate(&m, camera.position, 0).unwrap();
    for j in 0..6 {
        for i in 0..8 {
            let hit = *t.trace(&cam.ray(i, j), Start::Tet(start)).hit().unwrap();
            let n = tet_trace_cpu::render::shading_normal(&m, &hit);
            let p = hit_point(&m, &hit).as_dvec3();
            let want =
                rect_irradiance(p.x, p.y, [1.5, 2.5], [1.5, 2.5], 2.0) / std::f64::consts::PI;
            let got = f.color[(j * 8 + i) as usize].x as f64;
            assert!(n.z.abs() > 0.99);
            assert!(
                ((got - want) / want).abs() < 0.05,
                "({i},{j}) {got} vs {want}"
            );
        }
    }
    // Deterministic: same seed, same image; the kernel as shadow tracer
    // gives the same image as the canonical walker here.
    let g = render_scene_with(&t, &t, &camera, &lights, &opts).unwrap();
    assert_eq!(f.color, g.color);
    // Point lights only: no area work, and `render` = `render_scene`.
    let none = Lights::default();
    let h = render_scene(&t, &camera, &none, &opts).unwrap();
    assert_eq!(h.stats.shadow_rays, 0);
    assert!(h.color.iter().all(|&c| c == Vec3::ZERO));
}
