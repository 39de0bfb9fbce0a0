//! The SIMD lockstep batch walk ([`tet_trace_cpu::lockstep`]) against the
//! scalar walk: bit-identical outcomes (hit face, `t` and barycentric bits,
//! tets on both sides, tets visited, failures) ray by ray, on jittered Kuhn
//! grids with random constrained faces and closed shells, for random rays and
//! rays aimed exactly at vertices, edge midpoints, face centroids and along
//! the grid axes, with `t_min`/`t_max` windows (walks through constrained
//! faces), invalid rays, restarts on constrained faces, and step caps.

use glam::Vec3;
use proptest::prelude::*;
use tet_core::TetMesh;
use tet_core::synthetic::SplitMix64;
use tet_trace_cpu::kernel::{Interleaved, WalkTracer};
use tet_trace_cpu::lockstep::{trace_lockstep_avx2, trace_lockstep_portable};
use tet_trace_cpu::reference::{Aim, random_direction, random_point_inside, ray_from_feature};
use tet_trace_cpu::walk::Topology;
use tet_trace_cpu::{DuffF32, Ray, Start, Starts, TraceOutcome, Tracer, locate};

mod common;
use common::{bits, grid};

/// A batch from one origin: random directions, directions exactly at mesh
/// vertices, edge midpoints and face centroids, axis directions, some with a
/// `t_min`/`t_max` window, and a few invalid rays.
fn batch(mesh: &TetMesh, rng: &mut SplitMix64, origin: Vec3, n: usize) -> Vec<Ray> {
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
                    d[(rng.next_u64() % 3) as usize] = if rng.next_u64().is_multiple_of(2) {
                        1.0
                    } else {
                        -1.0
                    };
                    d
                }
                _ => {
                    if rng.next_u64().is_multiple_of(4) {
                        Vec3::ZERO // invalid: reported, not traced
                    } else {
                        random_direction(rng)
                    }
                }
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

/// The lockstep batch (dispatching, and portable at 1, 3, 4 and 8 lanes)
/// equals the scalar single-ray walk and the interleaved batch bit for bit.
fn check_batch<L: Topology>(t: &WalkTracer<'_, L, DuffF32>, rays: &[Ray], start: Start) {
    let single: Vec<TraceOutcome> = rays.iter().map(|r| t.trace(r, start)).collect();
    let fresh = || {
        vec![
            TraceOutcome::Miss {
                tets_visited: u32::MAX
            };
            rays.len()
        ]
    };
    let mut inter = fresh();
    Interleaved(t).trace_batch(rays, start, &mut inter);
    let mut lock = fresh();
    t.trace_batch(rays, start, &mut lock);
    let (mesh, topo, cap) = (t.mesh(), t.layout(), t.step_cap());
    let mut a2 = fresh();
    trace_lockstep_avx2(mesh, topo, rays, Starts::Same(start), cap, &mut a2);
    let mut p1 = fresh();
    trace_lockstep_portable::<L, 1>(mesh, topo, rays, Starts::Same(start), cap, &mut p1);
    let mut p3 = fresh();
    trace_lockstep_portable::<L, 3>(mesh, topo, rays, Starts::Same(start), cap, &mut p3);
    let mut p4 = fresh();
    trace_lockstep_portable::<L, 4>(mesh, topo, rays, Starts::Same(start), cap, &mut p4);
    let mut p8 = fresh();
    trace_lockstep_portable::<L, 8>(mesh, topo, rays, Starts::Same(start), cap, &mut p8);
    for (i, r) in rays.iter().enumerate() {
        let want = bits(&single[i]);
        for (name, got) in [
            ("interleaved", &inter),
            ("lockstep", &lock),
            ("avx2", &a2),
            ("portable/1", &p1),
            ("portable/3", &p3),
            ("portable/4", &p4),
            ("portable/8", &p8),
        ] {
            assert_eq!(
                bits(&got[i]),
                want,
                "{} {name} differs on {r:?} from {start:?}: {:?} vs {:?}",
                t.name(),
                got[i],
                single[i]
            );
        }
    }
}

/// ScTP's batch path (16-lane lockstep where the CPU has AVX-512F, else the
/// interleaved walk) gives its single-ray outcomes bit for bit.
fn check_sctp_batch(t: &tet_trace_cpu::sctp::SctpTracer<'_>, rays: &[Ray], start: Start) {
    let mut got = vec![
        TraceOutcome::Miss {
            tets_visited: u32::MAX
        };
        rays.len()
    ];
    t.trace_batch(rays, start, &mut got);
    for (r, g) in rays.iter().zip(&got) {
        assert_eq!(
            bits(g),
            bits(&t.trace(r, start)),
            "sctp batch differs on {r:?} from {start:?}"
        );
    }
}

fn check_mesh(mesh: &TetMesh, seed: u64, origins: usize, per: usize, cap: Option<u32>) {
    let sctp = tet_trace_cpu::sctp::SctpTracer::new(mesh).unwrap();
    let sctp = match cap {
        Some(c) => sctp.with_step_cap(c),
        None => sctp,
    };
    let t20 = tet_trace_cpu::tet20::Tet20Tracer::<DuffF32>::new(mesh).unwrap();
    let t16 = tet_trace_cpu::tet16::Tet16Tracer::<DuffF32>::new(mesh).unwrap();
    let t32 = tet_trace_cpu::tet32::Tet32Tracer::<DuffF32>::new(mesh).unwrap();
    let (t20, t16, t32) = match cap {
        Some(c) => (
            t20.with_step_cap(c),
            t16.with_step_cap(c),
            t32.with_step_cap(c),
        ),
        None => (t20, t16, t32),
    };
    let mut rng = SplitMix64(seed);
    for k in 0..origins {
        let (origin, hint) = match k % 3 {
            0 => random_point_inside(mesh, &mut rng),
            // Origins exactly on a vertex or an edge midpoint.
            _ => (
                ray_from_feature(mesh, &mut rng, [Aim::Vertex, Aim::EdgeMidpoint][k % 2]).origin,
                0,
            ),
        };
        let start = Start::Tet(locate(mesh, origin, hint).unwrap());
        let rays = batch(mesh, &mut rng, origin, per);
        check_batch(&t20, &rays, start);
        check_batch(&t16, &rays, start);
        check_batch(&t32, &rays, start);
        check_sctp_batch(&sctp, &rays, start);
    }
    // Restarts just past a constrained face (secondary rays).
    for _ in 0..origins.min(mesh.constrained.len()) {
        let c = (rng.next_u64() % mesh.constrained.len() as u64) as u32;
        let cf = &mesh.constrained[c as usize];
        let v = cf.vertices.map(|i| mesh.points[i as usize]);
        let origin = (v[0] + v[1] + v[2]) / 3.0;
        for side in [cf.front, cf.back] {
            if !side.exists() {
                continue;
            }
            let start = Start::Face {
                face: c,
                tet: side.tet,
            };
            let rays = batch(mesh, &mut rng, origin, per);
            check_batch(&t20, &rays, start);
            check_batch(&t16, &rays, start);
            check_batch(&t32, &rays, start);
            check_sctp_batch(&sctp, &rays, start);
        }
    }
}

#[test]
fn lockstep_equals_scalar_on_grids() {
    check_mesh(&grid(4, 0.12, 0.08, false, 7), 1, 12, 37, None);
    check_mesh(&grid(5, 0.1, 0.0, true, 3), 2, 12, 37, None);
    // Unjittered: axis rays run along faces and edges, many exact ties.
    check_mesh(&grid(4, 0.0, 0.1, false, 9), 3, 12, 37, None);
}

#[test]
fn lockstep_equals_scalar_at_the_step_cap() {
    let mesh = grid(5, 0.1, 0.02, true, 5);
    for cap in [0, 1, 2, 3, 5, 8, 13] {
        check_mesh(&mesh, 40 + cap as u64, 4, 29, Some(cap));
    }
}

#[test]
fn empty_and_tiny_batches() {
    let mesh = grid(3, 0.1, 0.1, false, 1);
    let t = tet_trace_cpu::tet20::Tet20Tracer::<DuffF32>::new(&mesh).unwrap();
    let mut rng = SplitMix64(6);
    let origin = Vec3::splat(1.5);
    let start = Start::Tet(locate(&mesh, origin, 0).unwrap());
    for n in [0, 1, 2, 7, 8, 9, 17] {
        let rays = batch(&mesh, &mut rng, origin, n);
        check_batch(&t, &rays, start);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, .. ProptestConfig::default() })]

    #[test]
    fn lockstep_equals_scalar(
        cells in 2u32..5,
        jitter in prop_oneof![Just(0.0f32), 0.0f32..0.15],
        fraction in 0.0f64..0.3,
        shell in any::<bool>(),
        seed in any::<u64>(),
    ) {
        let mesh = grid(cells.max(if shell { 3 } else { 2 }), jitter, fraction, shell, seed);
        check_mesh(&mesh, seed ^ 0xA5A5, 4, 23, None);
    }
}
