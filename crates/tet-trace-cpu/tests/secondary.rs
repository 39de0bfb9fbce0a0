//! Secondary rays on scenes with analytically known hits: a mirror, a glass
//! slab, and a shadow occluder, all planes of an unjittered 4×4×4 grid.

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::synthetic::{GridSpec, constrain_faces, kuhn_grid};
use tet_trace_cpu::secondary::{light_visible, reflect, refract};
use tet_trace_cpu::tet16::Tet16Tracer;
use tet_trace_cpu::tet20::Tet20Tracer;
use tet_trace_cpu::tet32::Tet32Tracer;
use tet_trace_cpu::tet80::Tet80Tracer;
use tet_trace_cpu::{DuffF32, DuffF64, Ray, Start, TraceOutcome, Tracer, locate};

/// The unjittered 4³ grid with every tet face lying in one of the planes
/// `axis = value` marked constrained.
fn planes(list: &[(usize, f32)]) -> TetMesh {
    let g = kuhn_grid(&GridSpec {
        cells: [4, 4, 4],
        jitter: 0.0,
        ..Default::default()
    });
    let on = |v: [Vec3; 3]| list.iter().any(|&(a, x)| v.iter().all(|p| p[a] == x));
    constrain_faces(g, on, None)
}

fn tracers(m: &TetMesh) -> Vec<Box<dyn Tracer + '_>> {
    vec![
        Box::new(Tet20Tracer::<DuffF32>::new(m).unwrap()),
        Box::new(Tet16Tracer::<DuffF32>::new(m).unwrap()),
        Box::new(Tet32Tracer::<DuffF32>::new(m).unwrap()),
        Box::new(Tet20Tracer::<DuffF64>::new(m).unwrap()),
        Box::new(Tet80Tracer::new(m).unwrap()),
    ]
}

fn first_hit(t: &dyn Tracer, ray: &Ray) -> tet_trace_cpu::Hit {
    let start = locate(t.mesh(), ray.origin, 0).unwrap();
    *t.trace(ray, Start::Tet(start)).hit().expect("primary hit")
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() < 1e-4
}

#[test]
fn mirror_reflects_to_the_far_wall() {
    // Mirror x = 1, wall x = 4 (the boundary).
    let m = planes(&[(0, 1.0), (0, 4.0)]);
    let ray = Ray::new(Vec3::new(2.5, 2.2, 1.7), Vec3::new(-1.0, 0.31, 0.17));
    // Analytic: x = 1 at t = 1.5; reflected (+1, .31, .17) reaches x = 4 after 3.
    let p1 = Vec3::new(1.0, 2.2 + 0.31 * 1.5, 1.7 + 0.17 * 1.5);
    let p2 = p1 + Vec3::new(3.0, 0.31 * 3.0, 0.17 * 3.0);
    for t in tracers(&m) {
        let hit = first_hit(t.as_ref(), &ray);
        assert!((hit.t - 1.5).abs() < 1e-5, "{}", t.name());
        assert!(close(ray.at(hit.t), p1));
        let r = reflect(t.as_ref(), &ray, &hit);
        let h2 = *r.outcome.unwrap().hit().expect("reflected hit");
        assert!(
            close(r.ray.at(h2.t), p2),
            "{}: {:?}",
            t.name(),
            r.ray.at(h2.t)
        );
        // The reflected ray starts on the mirror but never reports it again.
        assert_ne!(h2.face, hit.face);
    }
}

#[test]
fn glass_slab_refracts_in_and_out() {
    // Slab between z = 1 and z = 2 (interior, two-sided faces).
    let m = planes(&[(2, 1.0), (2, 2.0)]);
    let d = Vec3::new(0.3, 0.2, 1.0).normalize();
    let ray = Ray::new(Vec3::new(1.3, 1.7, 0.5), d);
    // Independent Snell: horizontal component shrinks by 1/1.5.
    let h = Vec3::new(d.x, d.y, 0.0);
    let ht = h / 1.5;
    let dt = ht + Vec3::Z * (1.0 - ht.length_squared()).sqrt();
    let p1 = ray.origin + d * (0.5 / d.z);
    let p2 = p1 + dt * (1.0 / dt.z);
    for t in tracers(&m) {
        let hit = first_hit(t.as_ref(), &ray);
        assert!(close(ray.at(hit.t), p1), "{}", t.name());
        let inside = refract(t.as_ref(), &ray, &hit, 1.0 / 1.5).unwrap();
        assert!((inside.ray.direction - dt).length() < 1e-5);
        let h2 = *inside.outcome.unwrap().hit().expect("hits the far face");
        assert!(
            close(inside.ray.at(h2.t), p2),
            "{}: {:?} vs {p2:?}",
            t.name(),
            inside.ray.at(h2.t)
        );
        // Leaving the slab restores the direction, then the ray exits the mesh.
        let out = refract(t.as_ref(), &inside.ray, &h2, 1.5).unwrap();
        assert!((out.ray.direction - d).length() < 1e-5);
        assert!(
            matches!(out.outcome, Some(TraceOutcome::Miss { .. })),
            "{}",
            t.name()
        );
    }
}

#[test]
fn total_internal_reflection_is_reported() {
    let m = planes(&[(2, 1.0)]);
    let t = Tet20Tracer::<DuffF32>::new(&m).unwrap();
    let ray = Ray::new(Vec3::new(1.3, 1.7, 1.5), Vec3::new(1.0, 0.3, -0.2));
    let hit = first_hit(&t, &ray);
    assert!(refract(&t, &ray, &hit, 1.5).is_none());
}

#[test]
fn shadow_rays_stop_at_occluders_only() {
    // Floor z = 1, occluding plate z = 2 (whole plane), light between or above.
    let m = planes(&[(2, 1.0), (2, 2.0)]);
    let t = Tet20Tracer::<DuffF32>::new(&m).unwrap();
    let ray = Ray::new(Vec3::new(1.3, 1.7, 1.6), Vec3::new(0.1, 0.2, -1.0));
    let hit = first_hit(&t, &ray);
    assert!(light_visible(&t, &hit, Vec3::new(2.1, 2.3, 1.8)));
    assert!(!light_visible(&t, &hit, Vec3::new(2.1, 2.3, 3.5)));
    // A light below the floor: the floor itself blocks nothing (the ray
    // starts beyond it), the boundary is open.
    assert!(light_visible(&t, &hit, Vec3::new(2.1, 2.3, 0.5)));
}
