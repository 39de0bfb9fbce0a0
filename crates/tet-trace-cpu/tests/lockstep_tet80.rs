//! The Plücker (Tet80) walk in SIMD lockstep against its scalar walk, for
//! both side rules (`tet80`, `tet80-consistent`): bit-identical outcomes
//! (hit face, `t` and barycentric bits, tets on both sides, tets visited,
//! failures) ray by ray, at every lane width the CPU runs (portable 4 and
//! 8 always, AVX2 and AVX-512 where detected), and through the tracers'
//! dispatching batch paths. Meshes: a hand-built octahedron of four tets
//! around one edge, jittered and unjittered Kuhn grids with random
//! constrained faces and closed shells; rays: random, aimed exactly at
//! vertices, edge midpoints and face centroids, started on vertices and
//! running along mesh edges, along the grid axes, with `t_min`/`t_max`
//! windows, invalid ones, restarts on constrained faces, camera images
//! from inside and from outside the mesh, and small step caps.

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::predicates::orient3d_f32;
use tet_core::synthetic::SplitMix64;
use tet_trace_cpu::lockstep::{self, NoGate, Plucker, Width};
use tet_trace_cpu::reference::{Aim, random_point_inside, ray_from_feature};
use tet_trace_cpu::tet80::Tet80Tracer;
use tet_trace_cpu::{Failure, Ray, Start, Starts, TraceOutcome, Tracer, Viewpoint, locate};

mod common;
use common::{adversarial_rays, batch, bits, grid};

/// A fresh output buffer that no walk's outcome equals.
fn fresh(n: usize) -> Vec<TraceOutcome> {
    vec![
        TraceOutcome::Miss {
            tets_visited: u32::MAX
        };
        n
    ]
}

/// Every batch path of `t` on `rays` from `starts` equals the scalar
/// single-ray walk bit for bit: the lockstep walk at each width (it must
/// run exactly where the CPU has the width) and the scalar batch walks
/// equal the scalar walk itself (`trace_batch_from_scalar`); the
/// dispatching `trace_batch_from` (and `trace_batch` for one start) equal
/// the tracer's single rays `want`, which differ from the walk only where
/// it lost its way (step cap or no start: the exact walk takes over, see
/// `tet_trace_cpu::lost`). Returns the widths that ran.
fn check<const C: bool>(
    t: &Tet80Tracer<'_, C>,
    rays: &[Ray],
    starts: Starts<'_>,
    want: &[TraceOutcome],
) -> Vec<Width> {
    let mut raw = fresh(rays.len());
    t.trace_batch_from_scalar(rays, starts, &mut raw);
    for (i, r) in rays.iter().enumerate() {
        let lost = matches!(
            raw[i],
            TraceOutcome::Failed {
                failure: Failure::StepCap | Failure::Lost,
                ..
            }
        );
        if !lost {
            assert_eq!(
                bits(&raw[i]),
                bits(&want[i]),
                "only lost walks change: {r:?}"
            );
        }
    }
    let mut runs: Vec<(String, Vec<TraceOutcome>, &[TraceOutcome])> = Vec::new();
    let mut ran = Vec::new();
    for width in Width::ALL {
        let mut got = fresh(rays.len());
        let batch = t.batch(rays, starts, &mut got);
        let did = lockstep::trace::<Plucker, _, _>(batch, width, &mut NoGate).is_ok();
        assert_eq!(did, width.available(), "{}: {width:?} ran {did}", t.name());
        if did {
            ran.push(width);
            runs.push((format!("lockstep {width:?}"), got, &raw));
        }
    }
    let mut got = fresh(rays.len());
    t.trace_batch_from(rays, starts, &mut got);
    runs.push(("trace_batch_from".into(), got, want));
    if let Starts::Same(s) = starts {
        let mut got = fresh(rays.len());
        t.trace_batch(rays, s, &mut got);
        runs.push(("trace_batch".into(), got, want));
        let mut got = fresh(rays.len());
        t.trace_batch_scalar(rays, s, &mut got);
        runs.push(("trace_batch_scalar".into(), got, &raw));
    }
    for (name, got, want) in &runs {
        for (i, r) in rays.iter().enumerate() {
            assert_eq!(
                bits(&got[i]),
                bits(&want[i]),
                "{} {name} differs on ray {i} {r:?} from {starts:?}: {:?} vs scalar {:?}",
                t.name(),
                got[i],
                want[i]
            );
        }
    }
    ran
}

/// [`check`] for both side rules (with step cap `cap` when given), the
/// reference being [`Tracer::trace`] ray by ray from `start(i)`.
fn check_both(mesh: &TetMesh, rays: &[Ray], starts: Starts<'_>, cap: Option<u32>) -> Vec<Width> {
    fn one<const C: bool>(
        t: Tet80Tracer<'_, C>,
        rays: &[Ray],
        starts: Starts<'_>,
        cap: Option<u32>,
    ) -> Vec<Width> {
        let t = match cap {
            Some(c) => t.with_step_cap(c),
            None => t,
        };
        let mut hint = Default::default();
        let want: Vec<TraceOutcome> = rays
            .iter()
            .enumerate()
            .map(|(i, r)| {
                let s = match starts {
                    Starts::Same(s) => Ok(s),
                    Starts::Each(s) => Ok(s[i]),
                    Starts::Outside(e) => t.start_outside(e, r, &mut hint),
                };
                match s {
                    Ok(s) => t.trace(r, s),
                    Err(done) => done,
                }
            })
            .collect();
        check(&t, rays, starts, &want)
    }
    let faithful = one(Tet80Tracer::new(mesh).unwrap(), rays, starts, cap);
    let consistent = one(Tet80Tracer::consistent(mesh).unwrap(), rays, starts, cap);
    assert_eq!(faithful, consistent);
    faithful
}

/// Batches from random, vertex and edge-midpoint origins (one start for
/// all), each ray of [`adversarial_rays`] from its own tet, and restarts
/// just past constrained faces. Returns the widths that ran.
fn check_mesh(
    mesh: &TetMesh,
    seed: u64,
    origins: usize,
    per: usize,
    cap: Option<u32>,
) -> Vec<Width> {
    let mut rng = SplitMix64(seed);
    let mut ran = Vec::new();
    for k in 0..origins {
        let (origin, hint) = match k % 3 {
            0 => random_point_inside(mesh, &mut rng),
            _ => {
                let aim = [Aim::Vertex, Aim::EdgeMidpoint][k % 2];
                (ray_from_feature(mesh, &mut rng, aim).origin, 0)
            }
        };
        let start = Start::Tet(locate(mesh, origin, hint).unwrap());
        let rays = batch(mesh, &mut rng, origin, per);
        ran = check_both(mesh, &rays, Starts::Same(start), cap);
    }
    let rays = adversarial_rays(mesh, &mut rng, origins * per);
    let each: Vec<Start> = rays
        .iter()
        .map(|r| Start::Tet(locate(mesh, r.origin, 0).unwrap()))
        .collect();
    assert_eq!(check_both(mesh, &rays, Starts::Each(&each), cap), ran);
    for _ in 0..origins.min(mesh.constrained.len()) {
        let c = (rng.next_u64() % mesh.constrained.len() as u64) as u32;
        let cf = &mesh.constrained[c as usize];
        let v = cf.vertices.map(|i| mesh.points[i as usize]);
        let origin = (v[0] + v[1] + v[2]) / 3.0;
        for side in [cf.front, cf.back].into_iter().filter(|s| s.exists()) {
            let start = Start::Face {
                face: c,
                tet: side.tet,
            };
            let rays = batch(mesh, &mut rng, origin, per);
            assert_eq!(check_both(mesh, &rays, Starts::Same(start), cap), ran);
        }
    }
    ran
}

/// An octahedron of four tets around the edge from `(0, 0, −1)` to
/// `(0, 0, 1)`, the face in the plane `y = 0` on the `x > 0` side a scene
/// triangle: every ray from the axis runs along that edge's tets.
fn octahedron() -> TetMesh {
    let points = vec![
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(-1.0, 0.0, 0.0),
        Vec3::new(0.0, -1.0, 0.0),
    ];
    let tets: Vec<[u32; 4]> = (0..4)
        .map(|k| {
            let t = [0, 1, 2 + k, 2 + (k + 1) % 4];
            let p = t.map(|i| points[i as usize]);
            if orient3d_f32(p[0], p[1], p[2], p[3]) > 0.0 {
                t
            } else {
                [t[1], t[0], t[2], t[3]]
            }
        })
        .collect();
    let mesh = TetMesh::assemble(points, tets, &[([0, 1, 2], 0)], 1).unwrap();
    mesh.validate().unwrap();
    mesh
}

#[test]
fn lockstep_equals_scalar_on_a_hand_built_octahedron() {
    let mesh = octahedron();
    let mut rng = SplitMix64(5);
    let mut origins = vec![
        Vec3::new(0.1, 0.2, 0.05),
        Vec3::ZERO,
        Vec3::new(0.0, 0.0, 0.5),
    ];
    origins.extend(mesh.points.iter().copied());
    for origin in origins {
        let start = Start::Tet(locate(&mesh, origin, 0).unwrap());
        let mut rays = batch(&mesh, &mut rng, origin, 41);
        // Along the axis edge and towards every vertex.
        rays.extend([Vec3::Z, -Vec3::Z].map(|d| Ray::new(origin, d)));
        rays.extend(mesh.points.iter().map(|&p| Ray::new(origin, p - origin)));
        check_both(&mesh, &rays, Starts::Same(start), None);
    }
}

#[test]
fn lockstep_equals_scalar_on_grids() {
    let ran = check_mesh(&grid(4, 0.12, 0.08, false, 7), 1, 9, 37, None);
    check_mesh(&grid(5, 0.1, 0.0, true, 3), 2, 9, 37, None);
    // Unjittered: axis rays run along faces and edges, rays from vertices
    // along edges; many exact zeros for the consistent tie rule.
    check_mesh(&grid(4, 0.0, 0.1, false, 9), 3, 9, 37, None);
    check_mesh(&grid(3, 0.0, 0.2, true, 2), 4, 9, 37, None);
    eprintln!("tet80 lockstep widths run: {ran:?}");
    assert!(ran.contains(&Width::Portable4) && ran.contains(&Width::Portable8));
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        assert!(ran.contains(&Width::Avx2));
    }
}

#[test]
fn lockstep_equals_scalar_at_the_step_cap() {
    let mesh = grid(4, 0.1, 0.05, true, 5);
    for cap in [0, 1, 2, 3, 5, 8] {
        check_mesh(&mesh, 40 + cap as u64, 3, 23, Some(cap));
    }
}

#[test]
fn lockstep_equals_scalar_on_camera_images_and_tiny_batches() {
    let mesh = grid(6, 0.1, 0.04, true, 11);
    let centre = Vec3::splat(3.0);
    for (position, up) in [
        (Vec3::new(0.45, 0.6, 0.5), Vec3::Z),
        (Vec3::new(-5.0, 2.5, 10.0), Vec3::Y),
    ] {
        let camera = tet_core::scene::Camera {
            position,
            target: centre,
            up,
            vfov_deg: 55.0,
        };
        let cam = tet_trace_cpu::render::PinholeCamera::new(&camera, 32, 24, true);
        let rays: Vec<Ray> = (0..24)
            .flat_map(|j| (0..32).map(move |i| (i, j)))
            .map(|(i, j)| cam.ray(i, j))
            .collect();
        let view = Viewpoint::locate(&mesh, position).unwrap();
        let starts = match &view {
            Viewpoint::Inside(t) => Starts::Same(Start::Tet(*t)),
            Viewpoint::Outside(entry) => Starts::Outside(entry),
        };
        check_both(&mesh, &rays, starts, None);
        // Batches shorter than, equal to and just over the lanes.
        for n in [0, 1, 2, 7, 8, 9, 17, 33] {
            check_both(&mesh, &rays[..n], starts, None);
        }
    }
}
