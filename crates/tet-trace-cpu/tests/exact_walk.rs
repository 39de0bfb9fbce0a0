//! The exact reference walk (`exact`): on jittered grids and closed shells,
//! with rays aimed exactly at vertices, edge midpoints and face centroids,
//! started on vertices, edges and faces, running along edges and grid axes,
//! it never fails, agrees with the f64 brute force on every unambiguous
//! ray, and never leaks out of a closed shell.

use glam::Vec3;
use proptest::prelude::*;
use tet_core::TetMesh;
use tet_core::synthetic::SplitMix64;
use tet_trace_cpu::exact::{ExactTracer, left_of};
use tet_trace_cpu::reference::closest_hit;
use tet_trace_cpu::{Ray, Start, Starts, TraceOutcome, Tracer, Viewpoint, locate};

mod common;
use common::{adversarial_rays, assert_outcomes_match, bits, grid, unambiguous_reference};

/// Traces `ray` from the tet holding its origin: never a failure, and the
/// reference's answer on unambiguous rays. Returns the outcome and whether
/// it was checked against the reference.
fn check(mesh: &TetMesh, ray: &Ray) -> (TraceOutcome, bool) {
    let tracer = ExactTracer::new(mesh);
    let start = locate(mesh, ray.origin, 0).unwrap();
    let out = tracer.trace(ray, Start::Tet(start));
    assert!(!out.is_failure(), "exact failed on {ray:?}: {out:?}");
    let Some(reference) = unambiguous_reference(mesh, ray) else {
        return (out, false);
    };
    let boxed: Vec<Box<dyn Tracer + '_>> = vec![Box::new(ExactTracer::new(mesh))];
    assert_outcomes_match(&boxed, &[out], ray, reference);
    (out, true)
}

/// Runs `n` adversarial rays on `mesh`; returns how many were checked
/// against the reference.
fn run(mesh: &TetMesh, seed: u64, n: usize) -> usize {
    let mut rng = SplitMix64(seed);
    adversarial_rays(mesh, &mut rng, n)
        .iter()
        .filter(|r| check(mesh, r).1)
        .count()
}

#[test]
fn random_faces_agree_with_reference() {
    for (seed, jitter) in [(1u64, 0.0f32), (2, 0.1), (3, 0.15)] {
        let mesh = grid(4, jitter, 0.3, false, seed);
        let checked = run(&mesh, seed * 13, 450);
        assert!(checked > 150, "too few unambiguous rays: {checked}");
    }
}

/// The interleaved batch walk gives each ray's single-ray outcome, bit for
/// bit, from one start, from a start per ray and from outside the mesh.
#[test]
fn batches_equal_single_rays() {
    let mesh = grid(4, 0.1, 0.2, true, 9);
    let tracer = ExactTracer::new(&mesh);
    let mut rng = SplitMix64(9);
    let rays = adversarial_rays(&mesh, &mut rng, 200);
    let starts: Vec<Start> = rays
        .iter()
        .map(|r| Start::Tet(locate(&mesh, r.origin, 0).unwrap()))
        .collect();
    let mut out = vec![TraceOutcome::Miss { tets_visited: 0 }; rays.len()];
    tracer.trace_batch_from(&rays, Starts::Each(&starts), &mut out);
    for ((r, s), o) in rays.iter().zip(&starts).zip(&out) {
        assert_eq!(bits(o), bits(&tracer.trace(r, *s)), "{r:?}");
    }
    // One origin for all (a camera inside the mesh).
    let origin = Vec3::new(1.3, 2.2, 1.7);
    let start = Start::Tet(locate(&mesh, origin, 0).unwrap());
    let fan: Vec<Ray> = (0..100)
        .map(|_| Ray::new(origin, tet_trace_cpu::reference::random_direction(&mut rng)))
        .collect();
    let mut out = vec![TraceOutcome::Miss { tets_visited: 0 }; fan.len()];
    tracer.trace_batch(&fan, start, &mut out);
    for (r, o) in fan.iter().zip(&out) {
        assert_eq!(bits(o), bits(&tracer.trace(r, start)), "{r:?}");
    }
    // From outside the mesh: every ray enters and gets the reference's
    // answer where it is unambiguous.
    let eye = Vec3::new(-3.0, 1.9, 2.3);
    let view = Viewpoint::locate(&mesh, eye).unwrap();
    let rays: Vec<Ray> = (0..100)
        .map(|i| {
            let target = Vec3::new(2.0, 0.3 + 0.035 * i as f32, 1.0 + 0.02 * i as f32);
            Ray::new(eye, target - eye)
        })
        .collect();
    let mut out = vec![TraceOutcome::Miss { tets_visited: 0 }; rays.len()];
    view.trace_batch(&tracer, &rays, &mut out);
    let boxed: Vec<Box<dyn Tracer + '_>> = vec![Box::new(ExactTracer::new(&mesh))];
    for (r, o) in rays.iter().zip(&out) {
        assert!(!o.is_failure(), "{r:?}: {o:?}");
        if let Some(reference) = unambiguous_reference(&mesh, r) {
            assert_outcomes_match(&boxed, &[*o], r, reference);
        }
    }
}

/// Rays from inside a closed shell (every origin, on features and within
/// rounding of the shell included) always hit it, no farther than the
/// closest shell face: no escape, no skip.
#[test]
fn closed_shells_never_leak() {
    for (seed, jitter) in [(1u64, 0.0f32), (2, 0.1), (3, 0.15)] {
        let mesh = grid(5, jitter, 0.0, true, seed);
        let mut rng = SplitMix64(seed * 91);
        let mut inside_rays = 0;
        for ray in adversarial_rays(&mesh, &mut rng, 900) {
            let (out, _) = check(&mesh, &ray);
            let inside = (0..3).all(|a| ray.origin[a] > 1.2 && ray.origin[a] < 3.8);
            if let (true, Some(r)) = (inside, closest_hit(&mesh, &ray)) {
                inside_rays += 1;
                let hit = out
                    .hit()
                    .unwrap_or_else(|| panic!("leaked: {ray:?} {out:?}"));
                assert!(hit.t as f64 <= r.t + 1e-4 * (1.0 + r.t), "{ray:?}");
            }
        }
        assert!(inside_rays > 100, "{inside_rays}");
    }
}

/// Rays from inside a closed shell aimed exactly at its vertices and at
/// points of its edges: the line passes through the shell's skeleton, the
/// walk must still stop on a shell face at `t ≈ 1`.
#[test]
fn rays_at_shell_vertices_and_edges_hit() {
    for (seed, jitter) in [(4u64, 0.0f32), (5, 0.12)] {
        let mesh = grid(5, jitter, 0.0, true, seed);
        let tracer = ExactTracer::new(&mesh);
        let mut rng = SplitMix64(seed);
        for (i, cf) in mesh.constrained.iter().enumerate() {
            let v = cf.vertices.map(|k| mesh.points[k as usize]);
            let targets = [v[0], (v[0] + v[1]) * 0.5, v[1] * 0.25 + v[2] * 0.75];
            for target in targets {
                let origin = Vec3::new(
                    rng.range_f32(1.5, 3.5),
                    rng.range_f32(1.5, 3.5),
                    rng.range_f32(1.5, 3.5),
                );
                let ray = Ray::new(origin, target - origin);
                let start = locate(&mesh, origin, 0).unwrap();
                let out = tracer.trace(&ray, Start::Tet(start));
                let hit = out
                    .hit()
                    .unwrap_or_else(|| panic!("face {i}: {ray:?} leaked: {out:?}"));
                assert!((hit.t - 1.0).abs() < 1e-4, "face {i}: {ray:?} {hit:?}");
            }
        }
    }
}

/// Rays started exactly on a hull vertex, edge or face, pointing out of
/// the mesh, in it, or along the hull: a miss or the reference's hit,
/// never a loop (`hull_origins.rs` holds the f32 walks to the same).
#[test]
fn rays_from_the_hull() {
    let mesh = grid(3, 0.0, 0.3, false, 7);
    let mut rng = SplitMix64(7);
    let origins = [
        Vec3::ZERO,
        Vec3::new(3.0, 3.0, 3.0),
        Vec3::new(0.0, 1.5, 0.0),
        Vec3::new(0.0, 1.25, 2.5),
    ];
    for o in origins {
        for _ in 0..40 {
            let d = tet_trace_cpu::reference::random_direction(&mut rng);
            let (out, _) = check(&mesh, &Ray::new(o, d));
            let leaves = (0..3).any(|a| (o[a] == 0.0 && d[a] < 0.0) || (o[a] == 3.0 && d[a] > 0.0));
            if leaves {
                // A miss, or (the perturbed origin being inside the mesh)
                // the constrained hull face the origin lies on, at t = 0.
                match out {
                    TraceOutcome::Miss { .. } => {}
                    TraceOutcome::Hit(h) => {
                        let v = mesh.constrained[h.face as usize].vertices;
                        let on = v.map(|k| mesh.points[k as usize]);
                        let w = h.barycentrics;
                        let p = on[0] * w[0] + on[1] * w[1] + on[2] * w[2];
                        assert!(h.t == 0.0 && (p - o).length() < 1e-5, "{o} {d}: {h:?}");
                    }
                    _ => unreachable!("checked"),
                }
            }
        }
        for d in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z] {
            check(&mesh, &Ray::new(o, d));
        }
    }
}

/// A first tet for the perturbation of [`left_of`] (any tet will do).
const AROUND: [Vec3; 4] = [
    Vec3::new(1.0, 0.0, 0.0),
    Vec3::new(0.0, 1.0, 0.0),
    Vec3::new(0.0, 0.0, 1.0),
    Vec3::new(-1.0, -1.0, -1.0),
];

/// The side decision against exact integer arithmetic: on integer points
/// the side product is computed exactly in `i64`; where it is zero, the
/// two orientations of the edge still get opposite answers.
#[test]
fn side_decision_is_exact_and_antisymmetric() {
    let mut rng = SplitMix64(11);
    let mut f = || (rng.next_u64() % 7) as i64 - 3;
    let mut zeros = 0;
    for _ in 0..20_000 {
        let p = [f(), f(), f()];
        let q = [f(), f(), f()];
        let o = [f(), f(), f()];
        let d = [f(), f(), f()];
        if p == q || d == [0, 0, 0] {
            continue;
        }
        let v = |x: [i64; 3]| Vec3::new(x[0] as f32, x[1] as f32, x[2] as f32);
        let (u, w) = (
            [p[0] - o[0], p[1] - o[1], p[2] - o[2]],
            [q[0] - o[0], q[1] - o[1], q[2] - o[2]],
        );
        let c = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        let s = d[0] * c[0] + d[1] * c[1] + d[2] * c[2];
        let ray = Ray::new(v(o), v(d));
        let left = left_of(v(p), v(q), &ray, AROUND);
        assert_ne!(
            left,
            left_of(v(q), v(p), &ray, AROUND),
            "{p:?} {q:?} {ray:?}"
        );
        if s == 0 {
            zeros += 1;
        } else {
            assert_eq!(left, s > 0, "{p:?} {q:?} {ray:?}");
        }
    }
    assert!(zeros > 500, "{zeros}");
}

/// Large and tiny coordinates: the exact sign where f64 rounding loses it.
#[test]
fn side_decision_survives_cancellation() {
    // The line x = 1e7 + 1 (direction z) against an edge at x = 1e7 ± 1
    // around it, far from the origin in y: f64 keeps it, so does the sum;
    // then a line offset by one f32 ulp at 1e7 (1.0).
    let o = Vec3::new(1e7 + 1.0, 0.0, 0.0);
    let ray = Ray::new(o, Vec3::Z);
    let a = Vec3::new(1e7, 3e7, 0.0);
    let b = Vec3::new(1e7 + 2.0, 3e7, 0.0);
    // d · ((a − o) × (b − o)) = (a−o)_x (b−o)_y − (a−o)_y (b−o)_x
    // = (−1)(3e7) − (3e7)(1) < 0.
    assert!(!left_of(a, b, &ray, AROUND));
    assert!(left_of(b, a, &ray, AROUND));
    // Through both points' vertical plane exactly: zero, decided by the
    // perturbation, still antisymmetric.
    let c = Vec3::new(1e7 + 1.0, 3e7, 0.0);
    let e = Vec3::new(1e7 + 1.0, -2e-30, 5.0);
    assert_ne!(left_of(c, e, &ray, AROUND), left_of(e, c, &ray, AROUND));
}

/// A case proptest found: a ray started at a face centroid rounded to f32,
/// a hair behind the face; the walk reports the face at `t = 0`, the f64
/// brute force skips it. Either answer is right, so the ray is ambiguous.
#[test]
fn origin_rounded_onto_a_face() {
    let seed = 13311309548564230044u64;
    let mesh = grid(3, 0.10299499, 0.052738192025845156, false, seed);
    run(&mesh, seed ^ 0xa5a5, 60);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, .. ProptestConfig::default() })]

    #[test]
    fn never_fails_and_agrees(
        cells in 2u32..5,
        jitter in 0.0f32..0.15,
        fraction in 0.0f64..0.3,
        shell in any::<bool>(),
        seed in any::<u64>(),
    ) {
        let mesh = grid(cells.max(if shell { 3 } else { 2 }), jitter, fraction, shell, seed);
        run(&mesh, seed ^ 0xa5a5, 60);
    }
}
