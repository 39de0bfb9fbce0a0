//! `tet80-consistent`: the Tet80 walk with one side product per edge, the
//! same in every tet. Its side test is antisymmetric bit for bit; on
//! jittered grids and closed shells, with rays aimed exactly at vertices,
//! edge midpoints and face centroids, started on features and running along
//! grid axes, it never reports a failure and agrees with the f64 brute force
//! on every unambiguous ray.

use glam::Vec3;
use proptest::prelude::*;
use tet_core::TetMesh;
use tet_core::synthetic::SplitMix64;
use tet_trace_cpu::reference::closest_hit;
use tet_trace_cpu::tet80::{Tet80ConsistentTracer, left_of};
use tet_trace_cpu::{Ray, Start, TraceOutcome, Tracer, locate};

mod common;
use common::{adversarial_rays, assert_outcomes_match, grid, unambiguous_reference};

/// Traces `ray` from the tet holding its origin: never a failure, and the
/// reference's answer on unambiguous rays.
fn check(mesh: &TetMesh, tracer: &dyn Tracer, ray: &Ray) -> TraceOutcome {
    let start = locate(mesh, ray.origin, 0).unwrap();
    let out = tracer.trace(ray, Start::Tet(start));
    assert!(
        !matches!(out, TraceOutcome::Failed { .. }),
        "{} failed on {ray:?}: {out:?}",
        tracer.name()
    );
    if let Some(reference) = unambiguous_reference(mesh, ray) {
        let boxed: Vec<Box<dyn Tracer + '_>> =
            vec![Box::new(Tet80ConsistentTracer::consistent(mesh).unwrap())];
        assert_outcomes_match(&boxed, &[out], ray, reference);
    }
    out
}

#[test]
fn the_side_test_is_antisymmetric_and_right_away_from_zero() {
    let mut rng = SplitMix64(3);
    let mut f = || (rng.next_f64() as f32 - 0.5) * 8.0;
    let mut decided = 0;
    for i in 0..20_000 {
        let (p, q, o) = (
            Vec3::new(f(), f(), f()),
            Vec3::new(f(), f(), f()),
            Vec3::new(f(), f(), f()),
        );
        // Every third ray passes exactly through p, every fifth runs along
        // the edge's own line: zero products in exact arithmetic.
        let d = match i % 15 {
            0 | 3 | 6 | 9 | 12 => p - o,
            5 | 10 => q - p,
            _ => Vec3::new(f(), f(), f()),
        };
        let o = if i % 15 == 5 || i % 15 == 10 { p } else { o };
        if p == q || d == Vec3::ZERO {
            continue;
        }
        let ray = Ray::new(o, d);
        let left = left_of(p, q, &ray);
        assert_ne!(left, left_of(q, p, &ray), "{p} {q} {ray:?}");
        // Where the exact side product is clearly non-zero, the test has
        // its sign (f64 on f32 inputs, relative margin far above f32's).
        let (pd, qd, od, dd) = (p.as_dvec3(), q.as_dvec3(), o.as_dvec3(), d.as_dvec3());
        let s = dd.dot((pd - od).cross(qd - od));
        let scale = dd.length() * (pd - od).length() * (qd - od).length();
        if s.abs() > 1e-4 * scale {
            assert_eq!(left, s > 0.0, "{p} {q} {ray:?}: {s}");
            decided += 1;
        }
    }
    assert!(decided > 10_000);
}

/// Rays from inside a closed shell (aimed at vertices, edges, faces, along
/// axes) always hit it: no loop, no escape.
#[test]
fn closed_shells_are_watertight() {
    for (seed, jitter) in [(1u64, 0.0f32), (2, 0.1), (3, 0.15)] {
        let mesh = grid(5, jitter, 0.0, true, seed);
        let tracer = Tet80ConsistentTracer::consistent(&mesh).unwrap();
        let mut rng = SplitMix64(seed * 91);
        for ray in adversarial_rays(&mesh, &mut rng, 900) {
            let out = check(&mesh, &tracer, &ray);
            let inside = (0..3).all(|a| ray.origin[a] > 1.2 && ray.origin[a] < 3.8);
            if let (true, Some(r)) = (inside, closest_hit(&mesh, &ray)) {
                let hit = out.hit().expect("a ray inside a closed shell hits it");
                assert!(hit.t as f64 <= r.t + 1e-4 * (1.0 + r.t), "{ray:?}");
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, .. ProptestConfig::default() })]

    #[test]
    fn never_fails_on_feature_rays(
        cells in 2u32..5,
        jitter in 0.0f32..0.15,
        fraction in 0.0f64..0.3,
        shell in any::<bool>(),
        seed in any::<u64>(),
    ) {
        let mesh = grid(cells.max(if shell { 3 } else { 2 }), jitter, fraction, shell, seed);
        let tracer = Tet80ConsistentTracer::consistent(&mesh).unwrap();
        let mut rng = SplitMix64(seed ^ 0xabcd);
        for ray in adversarial_rays(&mesh, &mut rng, 70) {
            check(&mesh, &tracer, &ray);
        }
    }
}
