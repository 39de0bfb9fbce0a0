//! The SIMD lockstep batch walk ([`tet_trace_cpu::lockstep`]) against the
//! scalar walk: bit-identical outcomes (hit face, `t` and barycentric bits,
//! tets on both sides, tets visited, failures) ray by ray, on jittered Kuhn
//! grids with random constrained faces and closed shells, for random rays and
//! rays aimed exactly at vertices, edge midpoints, face centroids and along
//! the grid axes, with `t_min`/`t_max` windows (walks through constrained
//! faces), invalid rays, restarts on constrained faces, and step caps; and
//! every lane width the CPU runs (portable 4 and 8, AVX2, AVX-512), one by
//! one, for the projected walks and ScTP's, on camera images and on those
//! adversarial rays.

use glam::Vec3;
use proptest::prelude::*;
use tet_core::TetMesh;
use tet_core::scene::Camera;
use tet_core::synthetic::SplitMix64;
use tet_trace_cpu::kernel::{Interleaved, WalkTracer};
use tet_trace_cpu::lockstep::{self, NoGate, Planar, Triple, Width};
use tet_trace_cpu::reference::{Aim, random_point_inside, ray_from_feature};
use tet_trace_cpu::render::PinholeCamera;
use tet_trace_cpu::walk::{Topology, start_scale};
use tet_trace_cpu::{
    DuffF32, Failure, Ray, Start, Starts, TraceOutcome, Tracer, Viewpoint, locate,
};

mod common;
use common::{batch, bits, grid};

/// The lockstep batch (dispatching, and at every width the CPU runs)
/// equals the scalar single-ray walk and the interleaved batch bit for bit
/// (1, 3 and 5 portable lanes: the unit tests of `lockstep`).
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
    // The walks themselves, before the tracer's exact walk takes over the
    // rays that reach the step cap (`TraceOutcome` of a lost walk).
    let (mesh, topo, cap) = (t.mesh(), t.layout(), t.step_cap());
    let raw: Vec<TraceOutcome> = rays
        .iter()
        .map(|r| tet_trace_cpu::walk::trace::<DuffF32, L>(mesh, topo, r, start, cap))
        .collect();
    let mut inter = fresh();
    Interleaved(t).trace_batch(rays, start, &mut inter);
    let mut lock = fresh();
    t.trace_batch(rays, start, &mut lock);
    let mut runs = vec![("interleaved".to_string(), inter, &single)];
    runs.push(("lockstep".to_string(), lock, &single));
    for width in Width::ALL {
        let mut got = fresh();
        let batch = t.batch(rays, Starts::Same(start), &mut got);
        let ran = lockstep::trace::<Planar, _, _>(batch, width, &mut NoGate).is_ok();
        assert_eq!(ran, width.available(), "{width:?} ran {ran}");
        if ran {
            runs.push((format!("{width:?}"), got, &raw));
        }
    }
    for (i, r) in rays.iter().enumerate() {
        let lost = matches!(
            raw[i],
            TraceOutcome::Failed {
                failure: Failure::StepCap,
                ..
            }
        );
        if !lost {
            assert_eq!(bits(&single[i]), bits(&raw[i]), "only lost walks change");
        }
        for (name, got, want) in &runs {
            assert_eq!(
                bits(&got[i]),
                bits(&want[i]),
                "{} {name} differs on {r:?} from {start:?}: {:?} vs {:?}",
                t.name(),
                got[i],
                want[i]
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

/// Rays from several origins inside one start tet, interleaved in one
/// batch (`Starts::Same`): the batch reuses a projection scale only while
/// the origin stays the same, so each ray walks as if alone. Also on the
/// grid scaled by 2²⁰, where the scale is not 1 and differs between
/// origins near a vertex and at the centroid of one tet.
#[test]
fn one_start_tet_many_origins() {
    for scale in [1.0f32, (1u32 << 20) as f32] {
        let mut mesh = grid(4, 0.1, 0.1, false, 11);
        for p in &mut mesh.points {
            *p *= scale;
        }
        let t = tet_trace_cpu::tet20::Tet20Tracer::<DuffF32>::new(&mesh).unwrap();
        let mut rng = SplitMix64(12);
        let mut checked = 0;
        let mut mixed_scales = 0;
        for tet in (0..mesh.tets.len() as u32).step_by(17) {
            let v = mesh.tets[tet as usize].map(|i| mesh.points[i as usize]);
            // Interior points of the tet; those that rounding puts in
            // another tet are skipped.
            let weights = [
                [0.25f32; 4],
                [0.94, 0.02, 0.02, 0.02],
                [0.02, 0.02, 0.94, 0.02],
                [0.1, 0.3, 0.3, 0.3],
            ];
            let origins: Vec<Vec3> = weights
                .iter()
                .map(|w| v[0] * w[0] + v[1] * w[1] + v[2] * w[2] + v[3] * w[3])
                .filter(|&o| locate(&mesh, o, tet) == Ok(tet))
                .collect();
            if origins.len() < 2 {
                continue;
            }
            let rays: Vec<Ray> = (0..40)
                .flat_map(|i| batch(&mesh, &mut rng, origins[i % origins.len()], 1))
                .collect();
            let scales: Vec<u32> = rays
                .iter()
                .map(|r| start_scale(&mesh, r, Start::Tet(tet)).to_bits())
                .collect();
            mixed_scales += scales.iter().any(|&x| x != scales[0]) as usize;
            check_batch(&t, &rays, Start::Tet(tet));
            checked += 1;
        }
        assert!(checked > 10, "{checked} tets checked at scale {scale}");
        if scale > 1.0 {
            assert!(mixed_scales > 3, "{mixed_scales} batches mix scales");
        }
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

/// The walks of one kernel at every width: `trace(width, starts, out)`
/// runs the lockstep walk at `width` (false: not run); every width the CPU
/// has must run, and give the scalar outcome `scalar[i]` on ray `i`.
/// Returns the widths that ran.
fn check_widths(
    name: &str,
    rays: &[Ray],
    scalar: &[TraceOutcome],
    trace: impl Fn(Width, &mut [TraceOutcome]) -> bool,
) -> Vec<Width> {
    let mut ran = Vec::new();
    for width in Width::ALL {
        let mut got = vec![
            TraceOutcome::Miss {
                tets_visited: u32::MAX
            };
            rays.len()
        ];
        let did = trace(width, &mut got);
        assert_eq!(
            did,
            width.available(),
            "{name}: {width:?} ran {did}, available {}",
            width.available()
        );
        if !did {
            continue;
        }
        ran.push(width);
        for (i, r) in rays.iter().enumerate() {
            assert_eq!(
                bits(&got[i]),
                bits(&scalar[i]),
                "{name} {width:?} differs on ray {i} {r:?}: {:?} vs scalar {:?}",
                got[i],
                scalar[i]
            );
        }
    }
    ran
}

/// Tet20, Tet16, Tet32 and ScTP at every width on `rays` from `view`
/// against their scalar walks (`cap`: the step cap, default when `None`).
/// Returns the widths that ran, per kernel.
fn check_all_widths(
    mesh: &TetMesh,
    view: &Viewpoint,
    rays: &[Ray],
    cap: Option<u32>,
) -> Vec<(String, Vec<Width>)> {
    fn scalar<T: Tracer>(t: &T, view: &Viewpoint, rays: &[Ray]) -> Vec<TraceOutcome> {
        rays.iter()
            .map(|r| match view.start(t, r) {
                Ok(s) => t.trace(r, s),
                Err(done) => done,
            })
            .collect()
    }
    fn projected<L: Topology>(
        t: &WalkTracer<'_, L, DuffF32>,
        view: &Viewpoint,
        rays: &[Ray],
    ) -> (String, Vec<Width>) {
        let want = scalar(t, view, rays);
        let ran = check_widths(&t.name(), rays, &want, |w, out| {
            let batch = t.batch(rays, starts(view), out);
            lockstep::trace::<Planar, _, _>(batch, w, &mut NoGate).is_ok()
        });
        (t.name(), ran)
    }
    let t20 = tet_trace_cpu::tet20::Tet20Tracer::<DuffF32>::new(mesh).unwrap();
    let t16 = tet_trace_cpu::tet16::Tet16Tracer::<DuffF32>::new(mesh).unwrap();
    let t32 = tet_trace_cpu::tet32::Tet32Tracer::<DuffF32>::new(mesh).unwrap();
    let sctp: tet_trace_cpu::sctp::SctpTracer<'_> =
        tet_trace_cpu::sctp::SctpTracer::new(mesh).unwrap();
    let (t20, t16, t32, sctp) = match cap {
        Some(c) => (
            t20.with_step_cap(c),
            t16.with_step_cap(c),
            t32.with_step_cap(c),
            sctp.with_step_cap(c),
        ),
        None => (t20, t16, t32, sctp),
    };
    let mut ran = vec![
        projected(&t20, view, rays),
        projected(&t16, view, rays),
        projected(&t32, view, rays),
    ];
    let want = scalar(&sctp, view, rays);
    let widths = check_widths("ScTP", rays, &want, |w, out| {
        let batch = sctp.batch(rays, starts(view), out);
        lockstep::trace::<Triple, _, _>(batch, w, &mut NoGate).is_ok()
    });
    ran.push(("ScTP".to_string(), widths));
    ran
}

/// The batch starts of `view`.
fn starts(view: &Viewpoint) -> Starts<'_> {
    match view {
        Viewpoint::Inside(tet) => Starts::Same(Start::Tet(*tet)),
        Viewpoint::Outside(entry) => Starts::Outside(entry),
    }
}

/// The primary rays of a `w × h` image.
fn image_rays(camera: &Camera, w: u32, h: u32) -> Vec<Ray> {
    let cam = PinholeCamera::new(camera, w, h, true);
    (0..h)
        .flat_map(|j| (0..w).map(move |i| (i, j)))
        .map(|(i, j)| cam.ray(i, j))
        .collect()
}

#[test]
fn every_width_equals_scalar_on_camera_images_and_adversarial_rays() {
    let mut report = Vec::new();
    // 8³ jittered cells, 3 % of the faces constrained, a closed shell; a
    // camera inside the mesh and one outside (rays entering through the
    // boundary).
    let mesh = grid(8, 0.1, 0.03, true, 11);
    let centre = Vec3::splat(4.0);
    for (position, up) in [
        (Vec3::new(0.45, 0.6, 0.5), Vec3::Z),
        (Vec3::new(-7.0, 2.5, 13.0), Vec3::Y),
    ] {
        let camera = Camera {
            position,
            target: centre,
            up,
            vfov_deg: 55.0,
        };
        let view = Viewpoint::locate(&mesh, position).unwrap();
        let rays = image_rays(&camera, 48, 36);
        report.extend(check_all_widths(&mesh, &view, &rays, None));
    }
    // Adversarial rays (at vertices, edge midpoints, face centroids, along
    // the axes, windows, invalid) from inside, on an unjittered grid (many
    // exact ties), with and without a small step cap.
    let mut rng = SplitMix64(77);
    for (mesh, cap) in [
        (grid(4, 0.0, 0.1, false, 9), None),
        (grid(5, 0.1, 0.05, true, 4), None),
        (grid(5, 0.1, 0.05, true, 4), Some(4)),
    ] {
        for k in 0..6 {
            let origin = match k % 3 {
                0 => random_point_inside(&mesh, &mut rng).0,
                _ => {
                    let aim = [Aim::Vertex, Aim::EdgeMidpoint][k % 2];
                    ray_from_feature(&mesh, &mut rng, aim).origin
                }
            };
            let view = Viewpoint::Inside(locate(&mesh, origin, 0).unwrap());
            let rays = batch(&mesh, &mut rng, origin, 61);
            report.extend(check_all_widths(&mesh, &view, &rays, cap));
        }
    }
    // Say which widths ran (the AVX-512 ones only where the CPU has it).
    let mut kernels: Vec<(String, Vec<Width>)> = Vec::new();
    for (name, widths) in report {
        match kernels.iter_mut().find(|(n, _)| *n == name) {
            Some((_, w)) => assert_eq!(*w, widths, "{name}: widths differ between cases"),
            None => kernels.push((name, widths)),
        }
    }
    for (name, widths) in &kernels {
        eprintln!("lockstep widths run for {name}: {widths:?}");
        assert!(widths.contains(&Width::Portable4) && widths.contains(&Width::Portable8));
    }
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx512f") {
        assert!(kernels.iter().all(|(_, w)| w.contains(&Width::Avx512)));
    } else {
        eprintln!("lockstep: this CPU has no AVX-512F; the 16-lane walks did not run");
    }
}
