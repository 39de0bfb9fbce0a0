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

/// A pyramid whose apex is a vertex of 2·n² tets (a fan over a triangulated
/// square): far more than the first ring searched around an origin, as at
/// a corner of an enclosing box. Rays from the apex leave at once (a miss)
/// or cross the pyramid to its constrained base, whatever tet `locate`
/// returns for the apex.
#[test]
fn rays_from_a_vertex_with_a_large_star() {
    let n = 14u32;
    let mut points = vec![Vec3::new(0.5, 0.5, 0.0)];
    for j in 0..=n {
        for i in 0..=n {
            points.push(Vec3::new(i as f32 / n as f32, j as f32 / n as f32, 1.0));
        }
    }
    let at = |i: u32, j: u32| 1 + i + j * (n + 1);
    let mut tets = Vec::new();
    let mut base = Vec::new();
    for j in 0..n {
        for i in 0..n {
            for t in [
                [at(i, j), at(i + 1, j), at(i + 1, j + 1)],
                [at(i, j), at(i + 1, j + 1), at(i, j + 1)],
            ] {
                // Positively oriented (checked by `validate`).
                tets.push([0, t[0], t[1], t[2]]);
                base.push((t, base.len() as u32));
            }
        }
    }
    let count = base.len() as u32;
    let mesh = TetMesh::assemble(points, tets, &base, count).unwrap();
    mesh.validate().unwrap();
    let apex = mesh.points[0];
    let tracers: Vec<Box<dyn Tracer + '_>> = vec![
        Box::new(Tet20Tracer::<tet_trace_cpu::DuffF32>::new(&mesh).unwrap()),
        Box::new(Tet16Tracer::<tet_trace_cpu::DuffF32>::new(&mesh).unwrap()),
        Box::new(Tet32Tracer::<tet_trace_cpu::DuffF32>::new(&mesh).unwrap()),
        Box::new(Tet80ConsistentTracer::consistent(&mesh).unwrap()),
    ];
    let mut rng = SplitMix64(3);
    let mut inward = 0;
    for i in 0..120 {
        // Half aimed at the base, half in random directions.
        let d = if i % 2 == 0 {
            Vec3::new(rng.next_f64() as f32, rng.next_f64() as f32, 1.0) - apex
        } else {
            random_direction(&mut rng)
        };
        let ray = Ray::new(apex, d);
        // Inside the pyramid's cone: the line through the apex reaches
        // the base square at z = 1.
        let at_base = (d.z > 0.0).then(|| apex + d * (1.0 / d.z));
        let crosses = at_base
            .is_some_and(|p| p.x > 1e-3 && p.x < 1.0 - 1e-3 && p.y > 1e-3 && p.y < 1.0 - 1e-3);
        let leaves = at_base
            .is_none_or(|p| p.x < -1e-3 || p.x > 1.0 + 1e-3 || p.y < -1e-3 || p.y > 1.0 + 1e-3);
        for start in [0, mesh.tets.len() as u32 / 2, mesh.tets.len() as u32 - 1] {
            for t in &tracers {
                let out = t.trace(&ray, Start::Tet(start));
                assert!(
                    !out.is_failure(),
                    "{} from tet {start}: {ray:?} {out:?}",
                    t.name()
                );
                if crosses {
                    let h = out
                        .hit()
                        .unwrap_or_else(|| panic!("{}: {ray:?} {out:?}", t.name()));
                    assert!((h.t - 1.0 / d.z).abs() < 1e-4 / d.z, "{}: {h:?}", t.name());
                }
                if leaves {
                    assert!(out.hit().is_none(), "{}: {ray:?} {out:?}", t.name());
                }
            }
        }
        inward += crosses as usize;
    }
    assert!(inward > 40 && inward < 110, "{inward}");
}
