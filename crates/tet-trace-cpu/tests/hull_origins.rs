//! Rays started exactly on the mesh boundary (hull vertices, hull edge
//! midpoints, hull face centroids) in random directions, many pointing out
//! of the mesh at once: every f32 and f64 walk ends without a failure and
//! agrees with the exact reference walk — a miss, or the constrained face
//! the origin lies on at `t ≈ 0`, or the exact walk's hit.

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::synthetic::SplitMix64;
use tet_trace_cpu::exact::ExactTracer;
use tet_trace_cpu::reference::random_direction;
use tet_trace_cpu::tet16::{Tet16Tracer, Tet16TracerF64};
use tet_trace_cpu::tet20::{Tet20Tracer, Tet20TracerF64};
use tet_trace_cpu::tet32::Tet32Tracer;
use tet_trace_cpu::tet80::Tet80ConsistentTracer;
use tet_trace_cpu::{Ray, Start, Starts, TraceOutcome, Tracer, locate};

mod common;
use common::grid;

/// Points on the boundary of `mesh`'s box: its vertices there, and the
/// midpoints and centroids of the boundary faces' edges and faces.
fn boundary_points(mesh: &TetMesh) -> Vec<Vec3> {
    let (lo, hi) = mesh.point_bounds();
    let on = |p: Vec3| (0..3).any(|a| p[a] == lo[a] || p[a] == hi[a]);
    let mut out: Vec<Vec3> = mesh.points.iter().copied().filter(|&p| on(p)).collect();
    for t in 0..mesh.tets.len() as u32 {
        for k in 0..4 {
            if mesh.across(t, k).is_none() {
                let f = mesh.face_vertices(t, k).map(|i| mesh.points[i as usize]);
                out.push((f[0] + f[1]) * 0.5);
                out.push((f[0] + f[1] + f[2]) / 3.0);
            }
        }
    }
    out
}

/// `out` is an acceptable answer where the exact walk says `exact`: the
/// same miss or hit, except that a hit at `t ≈ 0` (the origin lies on a
/// constrained face, or on its edge or vertex) in either makes the ray
/// ambiguous — it may count that face or start past it.
fn agrees(out: &TraceOutcome, exact: &TraceOutcome) -> bool {
    let at_origin = |o: &TraceOutcome| o.hit().is_some_and(|h| h.t < 1e-4);
    match (out, exact) {
        (TraceOutcome::Failed { .. }, _) => false,
        (a, b) if at_origin(a) || at_origin(b) => true,
        (TraceOutcome::Hit(a), TraceOutcome::Hit(b)) => {
            a.face == b.face || (a.t - b.t).abs() < 1e-4 * (1.0 + b.t)
        }
        (TraceOutcome::Miss { .. }, TraceOutcome::Miss { .. }) => true,
        _ => false,
    }
}

#[test]
fn rays_from_the_boundary_never_loop() {
    for (seed, jitter, fraction, shell) in [
        (7u64, 0.0f32, 0.3, false),
        (8, 0.1, 0.3, false),
        (9, 0.15, 0.0, true),
        (10, 0.05, 1.0, false),
    ] {
        let mesh = grid(4, jitter, fraction, shell, seed);
        let tracers: Vec<Box<dyn Tracer + '_>> = vec![
            Box::new(Tet20Tracer::<tet_trace_cpu::DuffF32>::new(&mesh).unwrap()),
            Box::new(Tet16Tracer::<tet_trace_cpu::DuffF32>::new(&mesh).unwrap()),
            Box::new(Tet32Tracer::<tet_trace_cpu::DuffF32>::new(&mesh).unwrap()),
            Box::new(Tet20TracerF64::new(&mesh).unwrap()),
            Box::new(Tet16TracerF64::new(&mesh).unwrap()),
            Box::new(Tet80ConsistentTracer::consistent(&mesh).unwrap()),
        ];
        let exact = ExactTracer::new(&mesh);
        let mut rng = SplitMix64(seed);
        let mut rays = Vec::new();
        let mut starts = Vec::new();
        for o in boundary_points(&mesh) {
            let s = Start::Tet(locate(&mesh, o, 0).unwrap());
            for _ in 0..6 {
                rays.push(Ray::new(o, random_direction(&mut rng)));
                starts.push(s);
            }
        }
        let want: Vec<TraceOutcome> = rays
            .iter()
            .zip(&starts)
            .map(|(r, s)| exact.trace(r, *s))
            .collect();
        for t in &tracers {
            let mut batch = vec![TraceOutcome::Miss { tets_visited: 0 }; rays.len()];
            t.trace_batch_from(&rays, Starts::Each(&starts), &mut batch);
            for (i, r) in rays.iter().enumerate() {
                let single = t.trace(r, starts[i]);
                assert!(
                    agrees(&single, &want[i]),
                    "{} on {r:?}: {single:?}, exact {:?}",
                    t.name(),
                    want[i]
                );
                assert!(
                    agrees(&batch[i], &want[i]),
                    "{} batch on {r:?}: {:?}, exact {:?}",
                    t.name(),
                    batch[i],
                    want[i]
                );
            }
        }
    }
}
