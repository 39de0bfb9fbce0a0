//! Kernels against the f64 brute-force reference and against each other, on
//! jittered Kuhn grids with random constrained faces and closed shells.

use glam::Vec3;
use proptest::prelude::*;
use tet_core::TetMesh;
use tet_core::synthetic::SplitMix64;
use tet_trace_cpu::reference::{Aim, axis_ray, closest_hit, random_ray, ray_from_feature};
use tet_trace_cpu::sctp::SctpTracer;
use tet_trace_cpu::tet16::{Tet16Tracer, Tet16TracerF64};
use tet_trace_cpu::tet20::{Tet20Tracer, Tet20TracerF64};
use tet_trace_cpu::tet32::{Tet32Tracer, Tet32TracerF64};
use tet_trace_cpu::tet80::Tet80Tracer;
use tet_trace_cpu::{OriginF32, Ray, Start, TraceOutcome, Tracer, locate};

mod common;
use common::{assert_outcomes_match, grid, unambiguous_reference};

fn all_f32(mesh: &TetMesh) -> Vec<Box<dyn Tracer + '_>> {
    vec![
        Box::new(Tet20Tracer::<tet_trace_cpu::DuffF32>::new(mesh).unwrap()),
        Box::new(Tet16Tracer::<tet_trace_cpu::DuffF32>::new(mesh).unwrap()),
        Box::new(Tet32Tracer::<tet_trace_cpu::DuffF32>::new(mesh).unwrap()),
    ]
}

fn others(mesh: &TetMesh) -> Vec<Box<dyn Tracer + '_>> {
    vec![
        Box::new(Tet20TracerF64::new(mesh).unwrap()),
        Box::new(Tet16TracerF64::new(mesh).unwrap()),
        Box::new(Tet32TracerF64::new(mesh).unwrap()),
        Box::new(Tet20Tracer::<OriginF32>::new(mesh).unwrap()),
        Box::new(tet_trace_cpu::scaled::ScaledTracer::tet20(mesh).unwrap()),
    ]
}

/// Kernels whose edge tests are not exactly consistent (3-D products in
/// f32, whose `d · (q × q')` cancels catastrophically when the ray passes
/// near a vertex): a ray aimed at a vertex or along an edge may loop until
/// the step cap, which must then be *reported*, or end on a wrong face. They
/// are checked against the reference on random-direction rays only.
fn lenient(mesh: &TetMesh) -> Vec<Box<dyn Tracer + '_>> {
    vec![
        Box::new(SctpTracer::<tet_trace_cpu::TripleF32>::new(mesh).unwrap()),
        Box::new(Tet80Tracer::new(mesh).unwrap()),
    ]
}

/// Checks one ray on every kernel; returns the number of unambiguous rays
/// checked against the reference.
fn check_ray(mesh: &TetMesh, tracers: &[Box<dyn Tracer + '_>], ray: &Ray, start: u32) -> usize {
    check_ray_with(mesh, tracers, ray, start, true)
}

fn check_ray_with(
    mesh: &TetMesh,
    tracers: &[Box<dyn Tracer + '_>],
    ray: &Ray,
    start: u32,
    strict: bool,
) -> usize {
    let outcomes: Vec<TraceOutcome> = tracers
        .iter()
        .map(|t| t.trace(ray, Start::Tet(start)))
        .collect();
    for (t, o) in tracers.iter().zip(&outcomes) {
        if let TraceOutcome::Failed {
            failure,
            tets_visited,
        } = o
        {
            assert!(!strict, "{} failed on {ray:?}: {o:?}", t.name());
            // Reported, bounded: a step-cap failure, never a hang.
            assert_eq!(*failure, tet_trace_cpu::Failure::StepCap);
            assert!(*tets_visited <= 2 * mesh.tets.len() as u32 + 1024);
        }
    }
    let Some(reference) = unambiguous_reference(mesh, ray) else {
        return 0;
    };
    assert_outcomes_match(tracers, &outcomes, ray, reference);
    1
}

/// Tet20, Tet16 and Tet32 in f32 make identical decisions: identical outcomes.
fn assert_identical(tracers: &[Box<dyn Tracer + '_>], ray: &Ray, start: Start) {
    let first = tracers[0].trace(ray, start);
    for t in &tracers[1..] {
        assert_eq!(
            t.trace(ray, start),
            first,
            "{} differs on {ray:?}",
            t.name()
        );
    }
}

fn run_rays(mesh: &TetMesh, seed: u64, n: usize) -> usize {
    let f32s = all_f32(mesh);
    let rest = others(mesh);
    let loose = lenient(mesh);
    let mut rng = SplitMix64(seed);
    let mut checked = 0;
    for i in 0..n {
        let aim = [
            Aim::Random,
            Aim::Vertex,
            Aim::EdgeMidpoint,
            Aim::FaceCentroid,
        ][i % 4];
        let (ray, hint) = random_ray(mesh, &mut rng, aim);
        let tet = locate(mesh, ray.origin, hint).unwrap();
        assert_identical(&f32s, &ray, Start::Tet(tet));
        checked += check_ray(mesh, &f32s, &ray, tet);
        checked += check_ray(mesh, &rest, &ray, tet);
        if aim == Aim::Random {
            check_ray_with(mesh, &loose, &ray, tet, false);
        } else {
            for t in &loose {
                let o = t.trace(&ray, Start::Tet(tet));
                if let TraceOutcome::Failed { failure, .. } = o {
                    assert_eq!(failure, tet_trace_cpu::Failure::StepCap, "{}", t.name());
                }
            }
        }
    }
    checked
}

/// Interleaved batches give exactly the single-ray results.
#[test]
fn batches_equal_single_rays() {
    let mesh = grid(5, 0.1, 0.05, true, 21);
    let mut rng = SplitMix64(4);
    let start = locate(&mesh, Vec3::splat(0.5), 0).unwrap();
    let origin = Vec3::splat(0.5);
    let rays: Vec<Ray> = (0..203)
        .map(|i| match i % 3 {
            0 => Ray::new(origin, tet_trace_cpu::reference::random_direction(&mut rng)),
            1 => Ray::new(
                origin,
                mesh.points[(rng.next_u64() % mesh.points.len() as u64) as usize] - origin,
            ),
            _ => Ray::new(origin, Vec3::ZERO), // invalid: reported, not traced
        })
        .collect();
    for t in all_f32(&mesh)
        .iter()
        .chain(others(&mesh).iter())
        .chain(lenient(&mesh).iter())
    {
        let mut out = vec![TraceOutcome::Miss { tets_visited: 0 }; rays.len()];
        t.trace_batch(&rays, Start::Tet(start), &mut out);
        for (r, o) in rays.iter().zip(&out) {
            assert_eq!(*o, t.trace(r, Start::Tet(start)), "{}", t.name());
        }
    }
}

#[test]
fn random_faces_agree_with_reference() {
    let mesh = grid(4, 0.12, 0.08, false, 7);
    let checked = run_rays(&mesh, 11, 400);
    assert!(checked > 400, "too few unambiguous rays: {checked}");
}

#[test]
fn shell_agrees_with_reference() {
    let mesh = grid(4, 0.1, 0.0, true, 3);
    let checked = run_rays(&mesh, 5, 300);
    assert!(checked > 400, "too few unambiguous rays: {checked}");
}

/// The watertightness claim: f32 Tet20 without epsilons, rays starting inside
/// a closed shell (at random points, at vertices, edge midpoints and face
/// centroids, aimed at vertices and along edges) always hit the shell:
/// never a loop, never an escape through a shell edge or vertex.
#[test]
fn closed_shell_is_watertight_in_f32() {
    for (seed, jitter) in [(1u64, 0.0f32), (2, 0.1), (3, 0.15)] {
        let mesh = grid(5, jitter, 0.0, true, seed);
        let tracers = all_f32(&mesh);
        let tet20 = &tracers[0];
        let mut rng = SplitMix64(seed * 77);
        let inside = |p: Vec3| (0..3).all(|a| mesh_box_inside(&mesh, p, a));
        let mut n = 0;
        while n < 600 {
            let i = n;
            let ray = match i % 6 {
                0..=3 => {
                    let aim = [
                        Aim::Random,
                        Aim::Vertex,
                        Aim::EdgeMidpoint,
                        Aim::FaceCentroid,
                    ][i % 4];
                    random_ray(&mesh, &mut rng, aim).0
                }
                4 => ray_from_feature(&mesh, &mut rng, [Aim::Vertex, Aim::EdgeMidpoint][i % 2]),
                _ => axis_ray(&mut rng, Vec3::splat(1.0), Vec3::splat(4.0)),
            };
            // Strictly inside the shell (jitter moves interior shell vertices,
            // so test against the exact reference instead of the box).
            let Some(r) = closest_hit(&mesh, &ray) else {
                continue;
            };
            if !inside(ray.origin) || r.t <= 0.0 {
                continue;
            }
            n += 1;
            let start = locate(&mesh, ray.origin, 0).unwrap();
            let out = tet20.trace(&ray, Start::Tet(start));
            match out {
                TraceOutcome::Hit(h) => {
                    // Never skips: the hit is no farther than the closest face.
                    assert!(
                        h.t as f64 <= r.t + 1e-4 * (1.0 + r.t),
                        "skipped on {ray:?}: {h:?} vs {r:?}"
                    );
                }
                _ => panic!("escaped or failed on {ray:?} (jitter {jitter}): {out:?}"),
            }
            assert_identical(&tracers, &ray, Start::Tet(start));
        }
    }
}

/// Inside the box `[1.2, cells-1.2]` on axis `a`: certainly inside the shell
/// (jitter ≤ 0.15 cell).
fn mesh_box_inside(mesh: &TetMesh, p: Vec3, a: usize) -> bool {
    let hi = mesh.points.iter().map(|q| q[a]).fold(f32::MIN, f32::max);
    p[a] > 1.2 && p[a] < hi - 1.2
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, .. ProptestConfig::default() })]

    #[test]
    fn kernels_terminate_and_agree(
        cells in 2u32..5,
        jitter in 0.0f32..0.15,
        fraction in 0.0f64..0.3,
        shell in any::<bool>(),
        seed in any::<u64>(),
    ) {
        let mesh = grid(cells.max(if shell { 3 } else { 2 }), jitter, fraction, shell, seed);
        run_rays(&mesh, seed ^ 0x5555, 40);
    }

    #[test]
    fn axis_rays_on_unjittered_grids(seed in any::<u64>(), fraction in 0.0f64..0.3) {
        let mesh = grid(4, 0.0, fraction, false, seed);
        let f32s = all_f32(&mesh);
        let rest = others(&mesh);
        let loose = lenient(&mesh);
        let mut rng = SplitMix64(seed);
        for _ in 0..40 {
            let ray = axis_ray(&mut rng, Vec3::ZERO, Vec3::splat(4.0));
            let start = locate(&mesh, ray.origin, 0).unwrap();
            assert_identical(&f32s, &ray, Start::Tet(start));
            check_ray(&mesh, &f32s, &ray, start);
            check_ray(&mesh, &rest, &ray, start);
            for t in &loose {
                // Terminates (hit, miss or a reported step-cap failure).
                let _ = t.trace(&ray, Start::Tet(start)).tets_visited();
            }
        }
    }
}
