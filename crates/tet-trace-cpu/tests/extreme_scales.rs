//! Scenes at the extremes of f32: the same closed shell scaled by powers
//! of two from 2⁻¹²⁰ (≈ 7.5e-37) to 2¹²⁰ (≈ 1.3e36), at the origin and
//! far from it. Scaling a scene and its rays' origins by a power of two is
//! exact, so a walk that does not depend on the scene's scale gives the
//! same outcome bit for bit: the same face, tet and step count, the same
//! barycentrics, and `t` scaled by the same power (directions are not
//! scaled). Without the per-ray projection factor the f32 walks failed on
//! a third of these rays at 1e-30.

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};
use tet_trace_cpu::tet16::Tet16Tracer;
use tet_trace_cpu::tet20::Tet20Tracer;
use tet_trace_cpu::tet32::Tet32Tracer;
use tet_trace_cpu::tet80::Tet80ConsistentTracer;
use tet_trace_cpu::walk::BoundaryEntry;
use tet_trace_cpu::{DuffF32, OriginF32, Ray, Start, Starts, TraceOutcome, Tracer, locate};

mod common;
use common::adversarial_rays;

fn shell(scale: f32, offset: Vec3) -> TetMesh {
    let m = kuhn_grid(&GridSpec {
        cells: [5; 3],
        jitter: 0.1,
        constrained_fraction: 0.1,
        shell: Some(([1; 3], [4; 3])),
        scale,
        offset,
        seed: 5,
    });
    m.validate().unwrap();
    m
}

fn tracers(mesh: &TetMesh) -> Vec<Box<dyn Tracer + '_>> {
    vec![
        Box::new(Tet20Tracer::<DuffF32>::new(mesh).unwrap()),
        Box::new(Tet16Tracer::<DuffF32>::new(mesh).unwrap()),
        Box::new(Tet32Tracer::<DuffF32>::new(mesh).unwrap()),
        Box::new(Tet20Tracer::<OriginF32>::new(mesh).unwrap()),
        Box::new(Tet80ConsistentTracer::consistent(mesh).unwrap()),
    ]
}

/// Every traced outcome: single rays and the batch walk, from the tets
/// holding the origins, and rays from outside entering through the hull.
fn outcomes(mesh: &TetMesh, rays: &[Ray], outside: &[Ray]) -> Vec<Vec<TraceOutcome>> {
    let starts: Vec<Start> = rays
        .iter()
        .map(|r| Start::Tet(locate(mesh, r.origin, 0).unwrap()))
        .collect();
    let entry = BoundaryEntry::new(mesh).unwrap();
    tracers(mesh)
        .iter()
        .map(|t| {
            let mut all: Vec<TraceOutcome> = rays
                .iter()
                .zip(&starts)
                .map(|(r, s)| t.trace(r, *s))
                .collect();
            let mut batch = vec![TraceOutcome::Miss { tets_visited: 0 }; rays.len()];
            t.trace_batch_from(rays, Starts::Each(&starts), &mut batch);
            all.extend(batch);
            let mut from_outside = vec![TraceOutcome::Miss { tets_visited: 0 }; outside.len()];
            t.trace_batch_from(outside, Starts::Outside(&entry), &mut from_outside);
            all.extend(from_outside);
            all
        })
        .collect()
}

/// `o` with `t` divided by `scale` (exact for a power of two, unless the
/// scaled `t` is subnormal in f32: then `t` is that of `like`, when within
/// the subnormals' spacing).
fn unscaled(o: &TraceOutcome, scale: f32, like: &TraceOutcome) -> TraceOutcome {
    match (*o, like) {
        (TraceOutcome::Hit(mut h), TraceOutcome::Hit(w)) if h.t.abs() < f32::MIN_POSITIVE => {
            let spacing = f32::from_bits(1) as f64 / scale as f64;
            if (h.t as f64 / scale as f64 - w.t as f64).abs() <= spacing {
                h.t = w.t;
            }
            TraceOutcome::Hit(h)
        }
        (TraceOutcome::Hit(mut h), _) => {
            h.t /= scale;
            TraceOutcome::Hit(h)
        }
        (other, _) => other,
    }
}

#[test]
fn a_power_of_two_scale_does_not_change_a_walk() {
    let cases: [(Vec3, &[i32]); 2] = [
        (Vec3::ZERO, &[-100, 100, -120, 120]),
        (Vec3::new(96.0, -64.0, 40.0), &[-60, 60]),
    ];
    for (offset, powers) in cases {
        let base = shell(1.0, offset);
        let mut rng = SplitMix64(11);
        let rays = adversarial_rays(&base, &mut rng, 300);
        let (lo, hi) = base.point_bounds();
        let outside: Vec<Ray> = (0..200)
            .map(|i| {
                let o =
                    offset + Vec3::new(-3.0 + 0.125 * (i % 7) as f32, 7.5, 9.0 - 0.0625 * i as f32);
                let f = Vec3::new(
                    rng.next_f64() as f32,
                    rng.next_f64() as f32,
                    rng.next_f64() as f32,
                );
                Ray::new(o, lo + (hi - lo) * f - o)
            })
            .collect();
        let want = outcomes(&base, &rays, &outside);
        let failures = want.iter().flatten().filter(|o| o.is_failure()).count();
        assert_eq!(failures, 0, "the unscaled shell must trace cleanly");
        for &k in powers {
            let s = 2.0f32.powi(k);
            let mesh = shell(s, offset * s);
            for (a, b) in base.points.iter().zip(&mesh.points) {
                assert_eq!(*a * s, *b, "the scaled grid is not exact at 2^{k}");
            }
            let scale_ray = |r: &Ray| Ray::new(r.origin * s, r.direction);
            let r2: Vec<Ray> = rays.iter().map(scale_ray).collect();
            let o2: Vec<Ray> = outside.iter().map(scale_ray).collect();
            let got = outcomes(&mesh, &r2, &o2);
            for (t, (g, w)) in tracers(&mesh).iter().zip(got.iter().zip(&want)) {
                for (i, (g, w)) in g.iter().zip(w).enumerate() {
                    assert_eq!(unscaled(g, s, w), *w, "{} at 2^{k}, outcome {i}", t.name());
                }
            }
        }
    }
}
