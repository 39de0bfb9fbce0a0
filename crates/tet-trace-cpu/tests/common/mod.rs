//! Helpers shared by the kernel test binaries (each uses some of them).
#![allow(dead_code)]

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};
use tet_trace_cpu::reference::{
    Aim, RefHit, axis_ray, closest_hit, grazes_an_edge, random_direction, random_ray,
    ray_from_feature,
};
use tet_trace_cpu::{Ray, TraceOutcome, Tracer};

/// A validated jittered Kuhn grid of `cells³` cells with a `fraction` of
/// random constrained faces, or (with `shell`) a closed shell one cell in.
pub fn grid(cells: u32, jitter: f32, fraction: f64, shell: bool, seed: u64) -> TetMesh {
    let m = kuhn_grid(&GridSpec {
        cells: [cells; 3],
        jitter,
        constrained_fraction: fraction,
        shell: shell.then_some(([1; 3], [cells - 1; 3])),
        seed,
        ..Default::default()
    });
    m.validate().unwrap();
    m
}

/// Hits closer than this to an edge of the reference triangle (in units of
/// the grid cell, i.e. ~1/1000 of a cell) may legitimately land on the
/// neighbouring triangle in f32; hits closer than this to the origin or to a
/// second hit are ambiguous too.
pub const EDGE_TOL: f64 = 1e-3;

/// The f64 brute-force hit of `ray`, or `None` when the ray is ambiguous
/// (it grazes an edge of a constrained face, its hit lies within
/// [`EDGE_TOL`] of its origin or of a second hit, or its origin lies within
/// [`EDGE_TOL`] of a constrained face, in front of it or behind):
/// `Some(reference)` when the outcomes must match it.
pub fn unambiguous_reference(mesh: &TetMesh, ray: &Ray) -> Option<Option<RefHit>> {
    let reference = closest_hit(mesh, ray);
    // An origin rounded onto a face may sit just behind it, where the
    // brute force (t < t_min) skips the face a walk may rightly report.
    let widened = Ray {
        t_min: ray.t_min - EDGE_TOL as f32,
        ..*ray
    };
    let origin_clear =
        closest_hit(mesh, &widened).is_none_or(|h| h.t > ray.t_min as f64 + EDGE_TOL);
    let clear = origin_clear
        && !grazes_an_edge(mesh, ray, EDGE_TOL)
        && reference.is_none_or(|h| h.t > EDGE_TOL && h.t_gap > EDGE_TOL);
    clear.then_some(reference)
}

/// Asserts that each tracer's outcome (failures aside, checked by the
/// caller) is the brute-force `reference`: the same face, `t` and
/// barycentrics to 1e-4, or a miss.
pub fn assert_outcomes_match(
    tracers: &[Box<dyn Tracer + '_>],
    outcomes: &[TraceOutcome],
    ray: &Ray,
    reference: Option<RefHit>,
) {
    for (t, o) in tracers.iter().zip(outcomes) {
        match (reference, o) {
            (_, TraceOutcome::Failed { .. }) => {}
            (None, TraceOutcome::Miss { .. }) => {}
            (Some(r), TraceOutcome::Hit(h)) => {
                assert_eq!(h.face, r.face, "{} on {ray:?}: {h:?} vs {r:?}", t.name());
                assert!(
                    (h.t as f64 - r.t).abs() < 1e-4 * (1.0 + r.t),
                    "{}: t {} vs {}",
                    t.name(),
                    h.t,
                    r.t
                );
                for k in 0..3 {
                    assert!(
                        (h.barycentrics[k] as f64 - r.barycentrics[k]).abs() < 1e-4,
                        "{}: barycentrics",
                        t.name()
                    );
                }
            }
            _ => panic!("{} on {ray:?}: {o:?} vs reference {reference:?}", t.name()),
        }
    }
}

/// Every bit of an outcome (f32 fields as bits, so `-0.0 ≠ 0.0`).
pub fn bits(o: &TraceOutcome) -> (u8, [u32; 9]) {
    match *o {
        TraceOutcome::Hit(h) => (
            0,
            [
                h.triangle,
                h.face,
                h.t.to_bits(),
                h.barycentrics[0].to_bits(),
                h.barycentrics[1].to_bits(),
                h.barycentrics[2].to_bits(),
                h.tet,
                h.far_tet,
                h.tets_visited,
            ],
        ),
        TraceOutcome::Miss { tets_visited } => (1, [tets_visited, 0, 0, 0, 0, 0, 0, 0, 0]),
        TraceOutcome::Failed {
            failure,
            tets_visited,
        } => (2, [tets_visited, failure as u32, 0, 0, 0, 0, 0, 0, 0]),
    }
}

/// Rays aimed at features, started on features, along mesh edges (origin
/// on a vertex, through another vertex of its tet) and along grid axes.
pub fn adversarial_rays(mesh: &TetMesh, rng: &mut SplitMix64, n: usize) -> Vec<Ray> {
    let (lo, hi) = mesh.point_bounds();
    (0..n)
        .map(|i| match i % 9 {
            0..=3 => {
                let aim = [
                    Aim::Random,
                    Aim::Vertex,
                    Aim::EdgeMidpoint,
                    Aim::FaceCentroid,
                ][i % 4];
                random_ray(mesh, rng, aim).0
            }
            4 => ray_from_feature(mesh, rng, Aim::Vertex),
            5 => ray_from_feature(mesh, rng, Aim::EdgeMidpoint),
            6 => ray_from_feature(mesh, rng, Aim::FaceCentroid),
            7 => {
                let t = (rng.next_u64() % mesh.tets.len() as u64) as u32;
                let p = mesh.tet_points(t);
                let r = rng.next_u64() as usize;
                let (a, b) = (r % 4, (r % 4 + 1 + r / 4 % 3) % 4);
                Ray::new(p[a], p[b] - p[a])
            }
            _ => axis_ray(rng, lo, hi),
        })
        .collect()
}

/// Rays from `origin`: random directions, directions exactly at mesh
/// vertices, edge midpoints and face centroids, along the axes, some with
/// a `t_min`/`t_max` window, and a few invalid ones.
pub fn batch(mesh: &TetMesh, rng: &mut SplitMix64, origin: Vec3, n: usize) -> Vec<Ray> {
    let pt =
        |rng: &mut SplitMix64| mesh.points[(rng.next_u64() % mesh.points.len() as u64) as usize];
    (0..n)
        .map(|i| {
            let dir = match i % 7 {
                0 | 1 => random_direction(rng),
                2 => pt(rng) - origin,
                3 => (pt(rng) + pt(rng)) * 0.5 - origin,
                4 => {
                    let t = mesh.tets[(rng.next_u64() % mesh.tets.len() as u64) as usize];
                    let f = t.map(|v| mesh.points[v as usize]);
                    (f[0] + f[1] + f[2]) / 3.0 - origin
                }
                5 => {
                    let mut d = Vec3::ZERO;
                    d[(rng.next_u64() % 3) as usize] = 1.0 - 2.0 * (rng.next_u64() % 2) as f32;
                    d
                }
                _ if rng.next_u64().is_multiple_of(4) => Vec3::ZERO, // invalid
                _ => random_direction(rng),
            };
            let mut r = Ray::new(origin, dir);
            match rng.next_u64() % 5 {
                0 => r.t_min = rng.range_f32(0.0, 2.0),
                1 => r.t_max = rng.range_f32(0.0, 2.0),
                _ => {}
            }
            r
        })
        .collect()
}
