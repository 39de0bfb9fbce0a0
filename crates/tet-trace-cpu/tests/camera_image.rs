//! Every ray of a camera image, traced by every batch walk, against the
//! scalar walk: the hits of Tet20, Tet16, Tet32 (SIMD lockstep at every
//! width the CPU runs: portable 4 and 8 lanes, AVX2 where present, the
//! dispatching walk, i.e. AVX-512 where present) and ScTP (its batch path:
//! AVX-512 lockstep where present, else the interleaved walk) are bit for
//! bit those of the single-ray scalar walk (same face, same `t` and
//! barycentric bits, same tets visited), for a camera inside the mesh and
//! one outside it (rays entering through the boundary).

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::scene::Camera;
use tet_trace_cpu::kernel::{Interleaved, WalkTracer};
use tet_trace_cpu::lockstep::{self, NoGate, Planar, Width};
use tet_trace_cpu::render::PinholeCamera;
use tet_trace_cpu::walk::Topology;
use tet_trace_cpu::{BatchWalk, Ray, Start, Starts, TraceOutcome, Tracer, Viewpoint};

mod common;
use common::{bits, grid};

const WIDTH: u32 = 64;
const HEIGHT: u32 = 48;

/// The primary rays of a `WIDTH × HEIGHT` image, row by row.
fn image_rays(camera: &Camera) -> Vec<Ray> {
    let cam = PinholeCamera::new(camera, WIDTH, HEIGHT, true);
    (0..HEIGHT)
        .flat_map(|j| (0..WIDTH).map(move |i| (i, j)))
        .map(|(i, j)| cam.ray(i, j))
        .collect()
}

fn unset(n: usize) -> Vec<TraceOutcome> {
    vec![
        TraceOutcome::Miss {
            tets_visited: u32::MAX
        };
        n
    ]
}

/// The batch walks of `t` (named) on `rays` from `view`.
fn batch_walks<L: Topology, P: BatchWalk>(
    t: &WalkTracer<'_, L, P>,
    view: &Viewpoint,
    rays: &[Ray],
    simd: bool,
) -> Vec<(String, Vec<TraceOutcome>)> {
    let mut walks = Vec::new();
    let mut out = unset(rays.len());
    view.trace_batch(t, rays, &mut out);
    walks.push(("batch (widest SIMD walk)".to_string(), out));
    let mut out = unset(rays.len());
    view.trace_batch(&Interleaved(t), rays, &mut out);
    walks.push(("interleaved".to_string(), out));
    if simd {
        let starts = match view {
            Viewpoint::Inside(tet) => Starts::Same(Start::Tet(*tet)),
            Viewpoint::Outside(entry) => Starts::Outside(entry),
        };
        for width in Width::ALL.into_iter().filter(|w| w.available()) {
            let mut out = unset(rays.len());
            let batch = t.batch(rays, starts, &mut out);
            let ran = lockstep::trace::<Planar, _, _>(batch, width, &mut NoGate);
            assert!(ran.is_ok(), "{width:?} did not run");
            walks.push((format!("{width:?}"), out));
        }
    }
    walks
}

/// Asserts every batch walk of `t` equals its scalar walk on every pixel;
/// returns the number of hits.
fn check<L: Topology, P: BatchWalk>(
    t: &WalkTracer<'_, L, P>,
    view: &Viewpoint,
    rays: &[Ray],
    simd: bool,
) -> usize {
    let scalar: Vec<TraceOutcome> = rays
        .iter()
        .map(|r| match view.start(t, r) {
            Ok(s) => t.trace(r, s),
            Err(done) => done,
        })
        .collect();
    for (name, got) in batch_walks(t, view, rays, simd) {
        for (i, (g, want)) in got.iter().zip(&scalar).enumerate() {
            assert_eq!(
                bits(g),
                bits(want),
                "{} {name}: pixel ({}, {}) differs: {g:?} vs scalar {want:?}",
                t.name(),
                i as u32 % WIDTH,
                i as u32 / WIDTH
            );
        }
    }
    assert!(
        scalar
            .iter()
            .all(|o| !matches!(o, TraceOutcome::Failed { .. })),
        "{}: a walk failed",
        t.name()
    );
    scalar
        .iter()
        .filter(|o| matches!(o, TraceOutcome::Hit(_)))
        .count()
}

fn check_camera(mesh: &TetMesh, camera: &Camera, outside: bool) {
    let view = Viewpoint::locate(mesh, camera.position).unwrap();
    assert_eq!(matches!(view, Viewpoint::Outside(_)), outside);
    let rays = image_rays(camera);
    let t20 = tet_trace_cpu::tet20::Tet20Tracer::<tet_trace_cpu::DuffF32>::new(mesh).unwrap();
    let t16 = tet_trace_cpu::tet16::Tet16Tracer::<tet_trace_cpu::DuffF32>::new(mesh).unwrap();
    let t32 = tet_trace_cpu::tet32::Tet32Tracer::<tet_trace_cpu::DuffF32>::new(mesh).unwrap();
    let sctp: tet_trace_cpu::sctp::SctpTracer<'_> =
        tet_trace_cpu::sctp::SctpTracer::new(mesh).unwrap();
    let hits = [
        check(&t20, &view, &rays, true),
        check(&t16, &view, &rays, true),
        check(&t32, &view, &rays, true),
        check(&sctp, &view, &rays, false),
    ];
    // The same image whatever the kernel, with hits and misses in it.
    assert!(
        hits.iter().all(|&h| h == hits[0]),
        "hits per kernel {hits:?}"
    );
    let n = rays.len();
    assert!(
        hits[0] > n / 10 && hits[0] < n,
        "{} hits of {n}: not a useful image",
        hits[0]
    );
}

#[test]
fn every_pixel_of_a_camera_image_is_bit_identical_across_batch_walks() {
    #[cfg(target_arch = "x86_64")]
    eprintln!(
        "SIMD widths at run time: portable 4 and 8 lanes, AVX2 {}, AVX-512F {}",
        std::arch::is_x86_feature_detected!("avx2"),
        std::arch::is_x86_feature_detected!("avx512f")
    );
    // 8³ jittered cells, 3 % of the faces constrained and a closed shell.
    let mesh = grid(8, 0.1, 0.03, true, 11);
    let centre = Vec3::splat(4.0);
    // Inside the mesh, between the shell and the boundary.
    let inside = Camera {
        position: Vec3::new(0.45, 0.6, 0.5),
        target: centre,
        up: Vec3::Z,
        vfov_deg: 60.0,
    };
    check_camera(&mesh, &inside, false);
    // Outside: every ray enters through the boundary (or misses the mesh).
    let outside = Camera {
        position: Vec3::new(-7.0, 2.5, 13.0),
        target: centre,
        up: Vec3::Y,
        vfov_deg: 50.0,
    };
    check_camera(&mesh, &outside, true);
}
