//! Measurements (not tests; `#[ignore]`): run with
//! `cargo test --release -p tet-trace-cpu --test measure_secondary -- --ignored --nocapture`.
//!
//! * shadow rays stopping at the light's tet vs at the light's distance:
//!   tets visited and time per shadow ray, canonical walker and Tet20 layout;
//! * Tet80 start: Algorithm 2 vs the engine's four-face start test.

use std::time::Instant;

use glam::Vec3;
use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};
use tet_trace_cpu::reference::{Aim, random_direction, random_point_inside, random_ray};
use tet_trace_cpu::secondary::{LightTarget, MeshWalker, ShadowTracer, trace_shadow};
use tet_trace_cpu::tet20::Tet20Tracer;
use tet_trace_cpu::tet80::Tet80Tracer;
use tet_trace_cpu::walk::start_exit_face;
use tet_trace_cpu::{DuffF32, Hit, Ray, Start, Tracer, TripleF32};

fn shadow_cost(name: &str, s: &dyn ShadowTracer, hits: &[Hit], light: &LightTarget) {
    let t0 = Instant::now();
    let (mut tets, mut rays, mut lit) = (0u64, 0u64, 0u64);
    for h in hits {
        if let Some(o) = trace_shadow(s, h, light) {
            tets += o.tets_visited() as u64;
            rays += 1;
            lit += o.hit().is_none() as u64;
        }
    }
    let ns = t0.elapsed().as_secs_f64() * 1e9 / rays.max(1) as f64;
    println!(
        "{name:32} {rays} rays, {:.1} tets/ray, {:.1} % lit, {ns:.0} ns/ray",
        tets as f64 / rays.max(1) as f64,
        100.0 * lit as f64 / rays.max(1) as f64
    );
}

#[test]
#[ignore = "measurement, not a check: prints timings; run in release with --nocapture"]
fn measure_shadow_rays_and_tet80_start() {
    let m = kuhn_grid(&GridSpec {
        cells: [30, 30, 30],
        jitter: 0.12,
        constrained_fraction: 0.01,
        seed: 4,
        ..Default::default()
    });
    println!(
        "mesh: {} tets, {} constrained faces",
        m.tets.len(),
        m.constrained.len()
    );
    let t20 = Tet20Tracer::<DuffF32>::new(&m).unwrap();
    let walker = MeshWalker::new(&m);
    let mut rng = SplitMix64(1);
    let mut hits = Vec::new();
    while hits.len() < 200_000 {
        let (ray, s) = random_ray(&m, &mut rng, Aim::Random);
        if let Some(h) = t20.trace(&ray, Start::Tet(s)).hit() {
            hits.push(*h);
        }
    }
    let light = LightTarget::locate(&m, Vec3::new(14.3, 15.6, 13.2), 0).unwrap();
    let far = LightTarget::outside(light.position);
    for _ in 0..2 {
        shadow_cost("mesh walker, stop at light tet", &walker, &hits, &light);
        shadow_cost("mesh walker, distance only", &walker, &hits, &far);
        shadow_cost("tet20 layout, stop at light tet", &t20, &hits, &light);
        shadow_cost("tet20 layout, distance only", &t20, &hits, &far);
    }

    let t80 = Tet80Tracer::new(&m).unwrap();
    let starts: Vec<(Ray, u32)> = (0..1_000_000)
        .map(|_| {
            let (o, t) = random_point_inside(&m, &mut rng);
            (Ray::new(o, random_direction(&mut rng)), t)
        })
        .collect();
    for _ in 0..2 {
        let t0 = Instant::now();
        let mut acc = 0usize;
        for (r, t) in &starts {
            acc += t80.algorithm2_exit_face(r, *t);
        }
        let a2 = t0.elapsed().as_secs_f64() * 1e9 / starts.len() as f64;
        let t0 = Instant::now();
        for (r, t) in &starts {
            acc += start_exit_face::<TripleF32>(&m, r, *t).map_or(0, |x| x.1);
        }
        let ff = t0.elapsed().as_secs_f64() * 1e9 / starts.len() as f64;
        println!("tet80 start: algorithm 2 {a2:.1} ns, four-face test {ff:.1} ns ({acc})");
    }
}
