// Body of the `traversal` fuzz target: every CPU kernel terminates on every
// mesh and ray, with a typed outcome.
//
// From the bytes: a small valid mesh (`grid::mesh_from`), then up to eight
// rays — origins inside a tet, exactly on a vertex, an edge or a face, or
// raw f32 bits (NaN, infinities, subnormals, outside the mesh); directions
// along edges and towards vertices, axis-aligned, zero, tiny, huge, or raw
// bits — each started in the tet `locate` finds, in an arbitrary tet that
// need not contain the origin, or just past a two-sided constrained face as
// a secondary ray does. Every kernel (ScTP, Tet32 f32/f64, Tet20, Tet16,
// Tet80), with its default step cap and with a tiny fuzzed one, must:
//
// * return (never loop: the fuzzer's `-timeout` catches hangs; never panic
//   or index out of bounds);
// * visit at most its step cap of tets, and report `StepCap` only at it;
// * report `InvalidRay` for every ray with a NaN/infinite component or a
//   zero direction (`Ray::is_valid`);
// * on a hit, name an existing constrained face, its scene triangle, an
//   existing tet, `far_tet` = the tet across that face, finite barycentrics
//   and `t` within `[t_min, t_max]`;
// * give the same outcomes from `trace_batch` as ray by ray.

use glam::Vec3;
use tet_core::{NO_TET, TetMesh};
use tet_trace_cpu::ray::DEFAULT_STEP_CAP;
use tet_trace_cpu::sctp::SctpTracer;
use tet_trace_cpu::tet16::Tet16Tracer;
use tet_trace_cpu::tet20::Tet20Tracer;
use tet_trace_cpu::tet32::{Tet32Tracer, Tet32TracerF64};
use tet_trace_cpu::tet80::Tet80Tracer;
use tet_trace_cpu::walk::step_cap;
use tet_trace_cpu::{DuffF32, Failure, Ray, Start, TraceOutcome, Tracer, TripleF32, locate};

use super::grid::mesh_from;
use super::input::Bytes;

/// Runs the property on `data`; returns the number of (ray, kernel) traces.
pub fn check(data: &[u8]) -> usize {
    let mut b = Bytes::new(data);
    let mesh = mesh_from(&mut b);
    let small_cap = 1 + b.below(8);
    let rays: Vec<(Ray, Start, bool)> = (0..1 + b.below(8))
        .map(|_| ray_from(&mesh, &mut b))
        .collect();
    let default_cap = step_cap(&mesh);
    assert!(default_cap <= DEFAULT_STEP_CAP);
    let mut traced = 0;
    for cap in [default_cap, small_cap] {
        let tracers: Vec<Box<dyn Tracer + '_>> = vec![
            Box::new(
                SctpTracer::<TripleF32>::new(&mesh)
                    .expect("sctp")
                    .with_step_cap(cap),
            ),
            Box::new(
                Tet32Tracer::<DuffF32>::new(&mesh)
                    .expect("tet32")
                    .with_step_cap(cap),
            ),
            Box::new(
                Tet32TracerF64::new(&mesh)
                    .expect("tet32/f64")
                    .with_step_cap(cap),
            ),
            Box::new(
                Tet20Tracer::<DuffF32>::new(&mesh)
                    .expect("tet20")
                    .with_step_cap(cap),
            ),
            Box::new(
                Tet16Tracer::<DuffF32>::new(&mesh)
                    .expect("tet16")
                    .with_step_cap(cap),
            ),
            Box::new(Tet80Tracer::new(&mesh).expect("tet80").with_step_cap(cap)),
        ];
        for tracer in &tracers {
            for &(ray, start, exact) in &rays {
                let out = tracer.trace(&ray, start);
                check_outcome(&mesh, tracer.as_ref(), &ray, start, exact, cap, &out);
                traced += 1;
            }
            // Batches: one start for all rays, as a tile of primary rays.
            let start = rays[0].1;
            let batch: Vec<Ray> = rays.iter().map(|r| r.0).collect();
            let mut out = vec![TraceOutcome::Miss { tets_visited: 0 }; batch.len()];
            tracer.trace_batch(&batch, start, &mut out);
            for (ray, o) in batch.iter().zip(&out) {
                let single = tracer.trace(ray, start);
                assert_eq!(
                    format!("{o:?}"),
                    format!("{single:?}"),
                    "{}: trace_batch differs from trace for {ray:?} from {start:?}",
                    tracer.name()
                );
            }
        }
    }
    traced
}

fn check_outcome(
    mesh: &TetMesh,
    tracer: &dyn Tracer,
    ray: &Ray,
    start: Start,
    exact: bool,
    cap: u32,
    out: &TraceOutcome,
) {
    let name = tracer.name();
    let ctx = || format!("{name}: {ray:?} from {start:?}, cap {cap}: {out:?}");
    assert!(
        out.tets_visited() <= cap,
        "visited more than the cap: {}",
        ctx()
    );
    if !ray.is_valid() {
        assert!(
            matches!(
                out,
                TraceOutcome::Failed {
                    failure: Failure::InvalidRay,
                    ..
                }
            ),
            "invalid ray not reported: {}",
            ctx()
        );
        return;
    }
    match *out {
        TraceOutcome::Failed {
            failure: Failure::StepCap,
            tets_visited,
        } => assert_eq!(tets_visited, cap, "step cap reported early: {}", ctx()),
        TraceOutcome::Failed {
            failure: Failure::InvalidRay,
            ..
        } => panic!("valid ray reported invalid: {}", ctx()),
        TraceOutcome::Failed { .. } | TraceOutcome::Miss { .. } => {}
        TraceOutcome::Hit(h) => {
            let cf = mesh
                .constrained
                .get(h.face as usize)
                .unwrap_or_else(|| panic!("hit names no constrained face: {}", ctx()));
            assert_eq!(h.triangle, cf.triangle, "wrong triangle id: {}", ctx());
            assert!(
                (h.tet as usize) < mesh.tets.len(),
                "hit tet out of bounds: {}",
                ctx()
            );
            let side = cf
                .side_of(h.tet)
                .unwrap_or_else(|| panic!("hit tet is not on the hit face: {}", ctx()));
            let far = cf.other_side(h.tet).expect("two sides");
            assert_eq!(h.far_tet, far.tet, "wrong far tet: {}", ctx());
            assert!(h.far_tet == NO_TET || (h.far_tet as usize) < mesh.tets.len());
            let _ = side;
            assert!(h.tets_visited >= 1, "hit visiting no tet: {}", ctx());
            if !exact {
                return;
            }
            assert!(
                h.barycentrics.iter().all(|w| w.is_finite()),
                "non-finite barycentrics: {}",
                ctx()
            );
            assert!(
                h.t >= ray.t_min && h.t <= ray.t_max,
                "t out of range: {}",
                ctx()
            );
        }
    }
}

/// Interesting f32 values for ray components.
const SPECIAL: [f32; 12] = [
    0.0,
    -0.0,
    1.0,
    -1.0,
    1e-30,
    -1e-38,
    1e30,
    f32::MIN_POSITIVE,
    f32::MAX,
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::NAN,
];

fn component(b: &mut Bytes) -> f32 {
    match b.u8() % 4 {
        0 => b.pick(&SPECIAL),
        1 => b.f32_bits(),
        _ => (f32::from(b.u8()) - 128.0) / 32.0,
    }
}

/// One ray, its start, and whether the start satisfies `Start`'s precondition.
pub fn ray_from(mesh: &TetMesh, b: &mut Bytes) -> (Ray, Start, bool) {
    let tet = b.below(mesh.tets.len() as u32);
    let p = mesh.tet_points(tet);
    let vertex = |b: &mut Bytes| p[b.below(4) as usize];
    let origin = match b.u8() % 6 {
        0 => {
            // Inside: a convex combination with byte weights.
            let w = [b.u8(), b.u8(), b.u8(), b.u8()].map(|x| f32::from(x) + 1.0);
            let s: f32 = w.iter().sum();
            (p[0] * w[0] + p[1] * w[1] + p[2] * w[2] + p[3] * w[3]) / s
        }
        1 => vertex(b),
        2 => (vertex(b) + vertex(b)) * 0.5,
        3 => (vertex(b) + vertex(b) + vertex(b)) / 3.0,
        4 => Vec3::new(component(b), component(b), component(b)),
        _ => vertex(b) + Vec3::new(component(b), component(b), component(b)) * 1e-3,
    };
    let direction = match b.u8() % 5 {
        // Along an edge of the start tet / towards one of its vertices.
        0 => vertex(b) - vertex(b),
        1 => vertex(b) - origin,
        2 => {
            let mut d = Vec3::ZERO;
            d[b.below(3) as usize] = if b.u8() & 1 == 0 { 1.0 } else { -1.0 };
            d
        }
        _ => Vec3::new(component(b), component(b), component(b)),
    };
    let mut ray = Ray::new(origin, direction);
    match b.u8() % 8 {
        0 => ray.t_min = component(b),
        1 => ray.t_max = component(b),
        _ => {}
    }
    // `exact`: the start satisfies `Start`'s precondition (the origin is in
    // the start tet, or on the start face), so the hit record must be sound;
    // otherwise only termination and bounds are required.
    let (start, exact) = match b.u8() % 4 {
        // An arbitrary tet (it need not contain the origin).
        0 => (Start::Tet(tet), false),
        1 => {
            // Just past a two-sided constrained face, as secondary rays
            // start, with the origin moved onto that face.
            let two_sided: Vec<u32> = (0..mesh.constrained.len() as u32)
                .filter(|&c| {
                    let c = &mesh.constrained[c as usize];
                    c.front.exists() && c.back.exists()
                })
                .collect();
            match two_sided.get(b.below(two_sided.len().max(1) as u32) as usize) {
                Some(&face) => {
                    let cf = mesh.constrained[face as usize];
                    let side = if b.u8() & 1 == 0 { cf.front } else { cf.back };
                    let w = [b.u8(), b.u8(), b.u8()].map(|x| f32::from(x) + 1.0);
                    let v = cf.vertices.map(|v| mesh.points[v as usize]);
                    ray.origin = (v[0] * w[0] + v[1] * w[1] + v[2] * w[2]) / (w[0] + w[1] + w[2]);
                    (
                        Start::Face {
                            face,
                            tet: side.tet,
                        },
                        true,
                    )
                }
                None => (Start::Tet(tet), false),
            }
        }
        _ => match locate(mesh, ray.origin, tet) {
            Ok(t) => (Start::Tet(t), true),
            Err(_) => (Start::Tet(tet), false),
        },
    };
    (ray, start, exact)
}
