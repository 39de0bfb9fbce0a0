//! Rays from outside the mesh enter through its boundary
//! (`tet_trace_cpu::boundary_entry`): against the f64 brute force, through boundary
//! vertices and edges exactly, along boundary faces, batched, and refused on
//! a non-convex boundary.

use glam::Vec3;
use proptest::prelude::*;
use tet_core::TetMesh;
use tet_core::synthetic::SplitMix64;
use tet_trace_cpu::boundary_entry::{BoundaryEntry, Viewpoint, ViewpointError};
use tet_trace_cpu::reference::{closest_hit, grazes_an_edge, random_direction};
use tet_trace_cpu::sctp::SctpTracer;
use tet_trace_cpu::tet16::{Tet16Tracer, Tet16TracerF64};
use tet_trace_cpu::tet20::{Tet20Tracer, Tet20TracerF64};
use tet_trace_cpu::tet32::Tet32Tracer;
use tet_trace_cpu::tet80::Tet80Tracer;
use tet_trace_cpu::{DuffF32, Failure, Ray, Start, Starts, TraceOutcome, Tracer};

mod common;
use common::{EDGE_TOL, assert_outcomes_match, grid, unambiguous_reference};

/// The watertight f32 kernels (identical decisions) and the f64 ones.
fn exact(mesh: &TetMesh) -> Vec<Box<dyn Tracer + '_>> {
    vec![
        Box::new(Tet20Tracer::<DuffF32>::new(mesh).unwrap()),
        Box::new(Tet16Tracer::<DuffF32>::new(mesh).unwrap()),
        Box::new(Tet32Tracer::<DuffF32>::new(mesh).unwrap()),
        Box::new(Tet20TracerF64::new(mesh).unwrap()),
        Box::new(Tet16TracerF64::new(mesh).unwrap()),
    ]
}

/// Kernels whose 3-D f32 products are not exactly consistent (see
/// `tests/kernels.rs`): checked on clear rays, may report a step cap.
fn lenient(mesh: &TetMesh) -> Vec<Box<dyn Tracer + '_>> {
    vec![
        Box::new(SctpTracer::<tet_trace_cpu::TripleF32>::new(mesh).unwrap()),
        Box::new(Tet80Tracer::new(mesh).unwrap()),
    ]
}

/// The outcome of `ray` from a viewpoint outside the mesh.
fn trace_outside(t: &dyn Tracer, view: &Viewpoint, ray: &Ray) -> TraceOutcome {
    match view.start(t, ray) {
        Ok(s) => t.trace(ray, s),
        Err(done) => done,
    }
}

/// Checks one ray from outside on every tracer against the brute force;
/// `strict`: no tracer may fail. Returns 1 when the ray was unambiguous.
fn check(mesh: &TetMesh, tracers: &[Box<dyn Tracer + '_>], ray: &Ray, strict: bool) -> usize {
    let view = Viewpoint::Outside(
        BoundaryEntry::new(mesh)
            .unwrap()
            .seen_from(mesh, ray.origin),
    );
    let all = Viewpoint::Outside(BoundaryEntry::new(mesh).unwrap());
    let outcomes: Vec<TraceOutcome> = tracers
        .iter()
        .map(|t| trace_outside(t.as_ref(), &view, ray))
        .collect();
    for (t, o) in tracers.iter().zip(&outcomes) {
        // The faces the origin sees hold the entry: the same start as from
        // every boundary face.
        assert_eq!(
            *o,
            trace_outside(t.as_ref(), &all, ray),
            "{} on {ray:?}",
            t.name()
        );
        if let TraceOutcome::Failed { failure, .. } = o {
            assert!(!strict, "{} failed on {ray:?}: {o:?}", t.name());
            assert_eq!(*failure, Failure::StepCap, "{}", t.name());
        }
    }
    let Some(reference) = unambiguous_reference(mesh, ray) else {
        return 0;
    };
    assert_outcomes_match(tracers, &outcomes, ray, reference);
    1
}

/// A point of the surface of the box `[0, n]³` on lattice coordinates
/// (`half`: also half-integers, the midpoints of boundary edges), with the
/// inward normal of one face it lies on.
fn surface_point(rng: &mut SplitMix64, n: u32, half: bool) -> (Vec3, Vec3) {
    let axis = (rng.next_u64() % 3) as usize;
    let high = rng.next_u64() % 2 == 1;
    let steps = if half { 2 * n + 1 } else { n + 1 };
    let mut p = Vec3::ZERO;
    for a in 0..3 {
        let k = (rng.next_u64() % steps as u64) as f32;
        p[a] = if half { k * 0.5 } else { k };
    }
    p[axis] = if high { n as f32 } else { 0.0 };
    let mut inward = Vec3::ZERO;
    inward[axis] = if high { -1.0 } else { 1.0 };
    (p, inward)
}

/// A ray from outside aimed exactly at `target`: the origin is `target`
/// minus a small integer vector pointing inward, so `target − origin` is
/// exact and the ray passes through the target bit for bit.
fn aimed(rng: &mut SplitMix64, target: Vec3, inward: Vec3) -> Ray {
    let mut d = Vec3::new(
        (rng.next_u64() % 5) as f32 - 2.0,
        (rng.next_u64() % 5) as f32 - 2.0,
        (rng.next_u64() % 5) as f32 - 2.0,
    );
    // Make the component along the inward normal point inward.
    let a = inward.abs().max_position();
    d[a] = inward[a] * (1.0 + (rng.next_u64() % 3) as f32);
    Ray::new(target - d, d)
}

/// Rays from outside aimed exactly at boundary vertices, boundary edge
/// midpoints and random boundary points of a grid holding a closed shell:
/// every one enters (ties on boundary edges and vertices resolve to exactly
/// one boundary face) and hits the shell like the brute force.
#[test]
fn rays_through_boundary_vertices_and_edges_enter() {
    for (seed, jitter) in [(1u64, 0.0f32), (2, 0.12)] {
        let n = 4;
        let mesh = grid(n, jitter, 0.0, true, seed);
        let tracers = exact(&mesh);
        let mut rng = SplitMix64(seed * 31);
        let mut clear = 0;
        for i in 0..400 {
            let (target, inward) = surface_point(&mut rng, n, i % 2 == 1);
            let ray = aimed(&mut rng, target, inward);
            clear += check(&mesh, &tracers, &ray, true);
            // The f32 kernels decide identically.
            let view = Viewpoint::locate(&mesh, ray.origin).unwrap();
            let first = trace_outside(tracers[0].as_ref(), &view, &ray);
            for t in &tracers[1..3] {
                assert_eq!(
                    trace_outside(t.as_ref(), &view, &ray),
                    first,
                    "{}",
                    t.name()
                );
            }
            // A line through a boundary vertex or edge that clearly reaches
            // the shell enters.
            if closest_hit(&mesh, &ray).is_some() && !grazes_an_edge(&mesh, &ray, EDGE_TOL) {
                assert!(first.hit().is_some(), "{ray:?}: {first:?}");
            }
        }
        assert!(clear > 200, "too few unambiguous rays: {clear}");
    }
}

/// Rays from far outside in random directions (many miss the mesh, some
/// graze it) and rays running inside a boundary face's plane: misses
/// without a walk, hits like the brute force, never a failure of the
/// watertight kernels.
#[test]
fn random_outside_rays_agree_with_reference() {
    let mesh = grid(4, 0.12, 0.08, false, 5);
    let strict = exact(&mesh);
    let loose = lenient(&mesh);
    let mut rng = SplitMix64(9);
    let (mut clear, mut missed) = (0, 0);
    for i in 0..500 {
        let ray = if i % 5 == 4 {
            // In the plane y = 0 (a boundary face), along x or z.
            let z = (rng.next_u64() % 9) as f32 * 0.5;
            if i % 2 == 0 {
                Ray::new(Vec3::new(-2.0, 0.0, z), Vec3::X)
            } else {
                Ray::new(Vec3::new(z, 0.0, 7.0), -Vec3::Z)
            }
        } else {
            let o = Vec3::splat(2.0) + random_direction(&mut rng) * 6.0;
            let towards = Vec3::new(
                rng.range_f32(-1.0, 5.0),
                rng.range_f32(-1.0, 5.0),
                rng.range_f32(-1.0, 5.0),
            );
            Ray::new(o, towards - o)
        };
        clear += check(&mesh, &strict, &ray, true);
        check(&mesh, &loose, &ray, false);
        let view = Viewpoint::locate(&mesh, ray.origin).unwrap();
        if let Err(TraceOutcome::Miss { tets_visited: 0 }) = view.start(strict[0].as_ref(), &ray)
            && !grazes_an_edge(&mesh, &ray, EDGE_TOL)
        {
            missed += 1;
            assert!(closest_hit(&mesh, &ray).is_none(), "{ray:?}");
        }
    }
    assert!(clear > 300, "too few unambiguous rays: {clear}");
    assert!(missed > 20, "too few rays missed the mesh: {missed}");
}

/// A boundary of many small faces (a 12-cell grid: 1,728 boundary faces),
/// where the entry search walks across the faces from the one it starts
/// at (face 0, or the previous ray's) instead of testing each: every ray
/// from outside starts and ends as the brute force says, single rays and
/// a coherent batch alike.
#[test]
fn rays_find_their_entry_across_many_boundary_faces() {
    let mesh = grid(12, 0.12, 0.02, false, 6);
    let strict = exact(&mesh);
    let mut rng = SplitMix64(10);
    let mut clear = 0;
    let c = Vec3::splat(6.0);
    for _ in 0..120 {
        let o = c + random_direction(&mut rng) * 20.0;
        let towards = c + random_direction(&mut rng) * rng.range_f32(0.0, 8.0);
        clear += check(&mesh, &strict, &Ray::new(o, towards - o), true);
    }
    assert!(clear > 80, "too few unambiguous rays: {clear}");
    // A fan of rays from one viewpoint, batched (each starts its search
    // at the previous ray's face), against the same rays one by one.
    let eye = Vec3::new(-9.0, 17.0, 25.0);
    let rays: Vec<Ray> = (0..400)
        .map(|i| {
            let (u, v) = ((i % 20) as f32 * 0.7 - 1.0, (i / 20) as f32 * 0.7 - 1.0);
            Ray::new(eye, Vec3::new(u, v, 6.0) - eye)
        })
        .collect();
    let view = Viewpoint::locate(&mesh, eye).unwrap();
    for t in &strict {
        let mut batch = vec![TraceOutcome::Miss { tets_visited: 0 }; rays.len()];
        view.trace_batch(t.as_ref(), &rays, &mut batch);
        for (ray, b) in rays.iter().zip(&batch) {
            assert_eq!(
                *b,
                trace_outside(t.as_ref(), &view, ray),
                "{} {ray:?}",
                t.name()
            );
        }
    }
}

/// Constrained faces on the boundary itself (the grid marks boundary faces
/// too): a ray entering through one hits it first, with no tet visited and
/// the outside (`NO_TET`) as its near side; with `t_min` beyond it, the ray
/// crosses it and walks on.
#[test]
fn constrained_boundary_faces_are_hit_on_entry() {
    let mesh = grid(3, 0.0, 1.0, false, 4);
    let tracers = exact(&mesh);
    let mut rng = SplitMix64(12);
    let mut hits = 0;
    for _ in 0..200 {
        let (mut target, inward) = surface_point(&mut rng, 3, false);
        // Inside a boundary square, off its diagonals.
        for a in 0..3 {
            if inward[a] == 0.0 {
                target[a] = target[a].min(2.0) + [0.3, 0.4, 0.2][a];
            }
        }
        let ray = aimed(&mut rng, target, inward);
        check(&mesh, &tracers, &ray, true);
        let view = Viewpoint::locate(&mesh, ray.origin).unwrap();
        if let Err(TraceOutcome::Hit(h)) = view.start(tracers[0].as_ref(), &ray) {
            hits += 1;
            assert_eq!(h.tets_visited, 0);
            assert_eq!(h.tet, tet_core::NO_TET);
            let r = closest_hit(&mesh, &ray).unwrap();
            assert_eq!(h.face, r.face);
            // Past it: the walk continues inside.
            let mut beyond = ray;
            beyond.t_min = h.t + 1e-3;
            if grazes_an_edge(&mesh, &beyond, EDGE_TOL) {
                continue;
            }
            for t in &tracers {
                let o = trace_outside(t.as_ref(), &view, &beyond);
                let want = closest_hit(&mesh, &beyond).map(|r| r.face);
                assert_eq!(o.hit().map(|h| h.face), want, "{} {beyond:?}", t.name());
            }
        }
    }
    assert!(hits > 100, "{hits}");
}

/// The batch path (SIMD lockstep with a start per ray) gives exactly the
/// single-ray outcomes, for starts of all three kinds mixed in one batch.
#[test]
fn batches_from_outside_equal_single_rays() {
    let mesh = grid(5, 0.1, 0.05, true, 21);
    let origin = Vec3::new(-3.0, 7.5, 9.0);
    let view = Viewpoint::locate(&mesh, origin).unwrap();
    assert!(matches!(view, Viewpoint::Outside(ref e) if !e.is_empty()));
    let mut rng = SplitMix64(4);
    let rays: Vec<Ray> = (0..301)
        .map(|i| match i % 4 {
            0 => Ray::new(origin, random_direction(&mut rng)),
            1 | 2 => Ray::new(
                origin,
                mesh.points[(rng.next_u64() % mesh.points.len() as u64) as usize] - origin,
            ),
            _ => Ray::new(origin, Vec3::ZERO),
        })
        .collect();
    for t in exact(&mesh).iter().chain(lenient(&mesh).iter()) {
        let mut out = vec![
            TraceOutcome::Miss {
                tets_visited: u32::MAX
            };
            rays.len()
        ];
        view.trace_batch(t.as_ref(), &rays, &mut out);
        for (r, o) in rays.iter().zip(&out) {
            assert_eq!(*o, trace_outside(t.as_ref(), &view, r), "{}", t.name());
        }
        // Mixed starts: interior tets, constrained faces, boundary entries.
        let mut starts = Vec::new();
        let mut mixed = Vec::new();
        for (k, r) in rays.iter().enumerate() {
            if let Ok(s) = view.start(t.as_ref(), r) {
                mixed.push(*r);
                starts.push(s);
            }
            if k % 3 == 0 {
                let p = Vec3::splat(2.5);
                let tet = tet_trace_cpu::locate(&mesh, p, 0).unwrap();
                mixed.push(Ray::new(p, random_direction(&mut rng)));
                starts.push(Start::Tet(tet));
            }
        }
        let mut got = vec![TraceOutcome::Miss { tets_visited: 0 }; mixed.len()];
        t.trace_batch_from(&mixed, Starts::Each(&starts), &mut got);
        for ((r, s), o) in mixed.iter().zip(&starts).zip(&got) {
            assert_eq!(*o, t.trace(r, *s), "{} from {s:?}", t.name());
        }
    }
}

/// Rays that stream past the mesh let the next ray test the bounds before
/// anything else (`BoundaryEntry::clearly_misses`): a batch whose rays
/// alternate between clear misses and rays aimed at the boundary's corners
/// and edge midpoints, pushed outward by 0 to 10⁻³ of their distance, gives
/// exactly the single-ray outcomes, and the rays aimed within rounding of
/// the boundary still enter. Near the world origin and far from it.
#[test]
fn rays_streaming_past_the_mesh_equal_single_rays() {
    for offset in [Vec3::ZERO, Vec3::new(3.0e4, -2.0e4, 1.0e4)] {
        let mut mesh = grid(4, 0.1, 0.05, true, 8);
        for p in &mut mesh.points {
            *p += offset;
        }
        let origin = offset + Vec3::new(-3.0, 7.5, 9.0);
        let view = Viewpoint::locate(&mesh, origin).unwrap();
        let (lo, hi) = mesh.point_bounds();
        let centre = (lo + hi) * 0.5;
        let mut targets = Vec::new();
        for x in [lo.x, centre.x, hi.x] {
            for y in [lo.y, centre.y, hi.y] {
                for z in [lo.z, centre.z, hi.z] {
                    let p = Vec3::new(x, y, z);
                    // Corners and edge midpoints: two or three coordinates on the bounds.
                    let on = (0..3).filter(|&a| p[a] != centre[a]).count();
                    if on >= 2 {
                        targets.push(p);
                    }
                }
            }
        }
        let away = Ray::new(origin, origin - centre);
        let mut rays = Vec::new();
        for p in &targets {
            for push in [0.0f32, 1e-9, 1e-8, 1e-7, 1e-6, 3e-6, 1e-5, 1e-3] {
                let out = (*p - centre).normalize() * (*p - origin).length() * push;
                rays.push(away);
                rays.push(Ray::new(origin, *p + out - origin));
            }
        }
        for t in exact(&mesh) {
            let mut out = vec![
                TraceOutcome::Miss {
                    tets_visited: u32::MAX
                };
                rays.len()
            ];
            view.trace_batch(t.as_ref(), &rays, &mut out);
            let mut entered_near = 0;
            for (k, (r, o)) in rays.iter().zip(&out).enumerate() {
                assert_eq!(
                    *o,
                    trace_outside(t.as_ref(), &view, r),
                    "{} on {r:?}",
                    t.name()
                );
                // Aimed exactly at a visible boundary point (push 0).
                if k % 16 == 1 && o.tets_visited() > 0 {
                    entered_near += 1;
                }
            }
            assert!(entered_near >= 4, "{}: {entered_near}", t.name());
        }
    }
}

/// A boundary with a pit (the top middle cell of a 3³ grid removed) is
/// refused with the face where it bends inward; a viewpoint inside is
/// located as before.
#[test]
fn non_convex_boundary_is_refused() {
    let full = grid(3, 0.0, 0.0, false, 1);
    let centre = |t: &[u32; 4]| {
        t.iter()
            .map(|&v| full.points[v as usize])
            .fold(Vec3::ZERO, |a, p| a + p)
            / 4.0
    };
    let tets: Vec<[u32; 4]> = full
        .tets
        .iter()
        .filter(|t| {
            let c = centre(t);
            !(c.x > 1.0 && c.x < 2.0 && c.y > 1.0 && c.y < 2.0 && c.z > 2.0)
        })
        .copied()
        .collect();
    assert_eq!(tets.len(), full.tets.len() - 6);
    let pit = TetMesh::assemble(full.points.clone(), tets, &[], 0).unwrap();
    pit.validate().unwrap();
    match BoundaryEntry::new(&pit) {
        Err(ViewpointError::NotConvex { tet, face }) => {
            assert!(pit.is_boundary_face(tet, face));
        }
        other => panic!("expected NotConvex, got {other:?}"),
    }
    assert!(matches!(
        Viewpoint::locate(&pit, Vec3::new(0.5, 5.0, 0.5)),
        Err(ViewpointError::NotConvex { .. })
    ));
    assert!(matches!(
        Viewpoint::locate(&pit, Vec3::splat(0.5)),
        Ok(Viewpoint::Inside(_))
    ));
    assert!(BoundaryEntry::new(&full).is_ok());
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, .. ProptestConfig::default() })]

    /// Jittered grids with random constrained faces, viewpoints anywhere
    /// outside: the watertight kernels never fail and agree with the brute
    /// force on unambiguous rays.
    #[test]
    fn outside_viewpoints_on_random_grids(
        cells in 2u32..5,
        jitter in 0.0f32..0.15,
        fraction in 0.0f64..0.3,
        seed in any::<u64>(),
    ) {
        let mesh = grid(cells, jitter, fraction, false, seed);
        let tracers = exact(&mesh);
        let mut rng = SplitMix64(seed ^ 0xabc);
        let c = Vec3::splat(cells as f32 * 0.5);
        for i in 0..30 {
            let o = c + random_direction(&mut rng) * cells as f32 * 1.5;
            let ray = if i % 2 == 0 {
                let p = mesh.points[(rng.next_u64() % mesh.points.len() as u64) as usize];
                Ray::new(o, p - o)
            } else {
                Ray::new(o, c + random_direction(&mut rng) * cells as f32 * 0.6 - o)
            };
            check(&mesh, &tracers, &ray, true);
        }
    }
}
