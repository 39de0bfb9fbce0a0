//! Criterion bench of the exit-face search per method: random rays stabbing
//! random tets of a jittered Kuhn grid (16³ cells, 24 576 tets) with 5 % of
//! the faces constrained, each ray walked from the tet containing its origin
//! to its first constrained face. Throughput is reported per tet visited
//! (one exit-face search per tet), so methods compare per step.
//!
//! Run: `cargo bench -p tet-trace-cpu --bench exit_face`.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};
use tet_trace_cpu::reference::{Aim, random_ray};
use tet_trace_cpu::sctp::SctpTracer;
use tet_trace_cpu::tet16::Tet16Tracer;
use tet_trace_cpu::tet20::Tet20Tracer;
use tet_trace_cpu::tet32::Tet32Tracer;
use tet_trace_cpu::tet80::Tet80Tracer;
use tet_trace_cpu::{DuffF32, DuffF64, OriginF32, Start, Tracer, TripleF32};

fn bench(c: &mut Criterion) {
    let mesh = kuhn_grid(&GridSpec {
        cells: [16; 3],
        jitter: 0.12,
        constrained_fraction: 0.05,
        seed: 42,
        ..Default::default()
    });
    let mut rng = SplitMix64(7);
    let rays: Vec<_> = (0..4096)
        .map(|_| random_ray(&mesh, &mut rng, Aim::Random))
        .collect();
    let tracers: Vec<Box<dyn Tracer + '_>> = vec![
        Box::new(Tet20Tracer::<DuffF32>::new(&mesh).unwrap()),
        Box::new(Tet20Tracer::<OriginF32>::new(&mesh).unwrap()),
        Box::new(tet_trace_cpu::scaled::ScaledTracer::tet20(&mesh).unwrap()),
        Box::new(Tet20Tracer::<DuffF64>::new(&mesh).unwrap()),
        Box::new(Tet16Tracer::<DuffF32>::new(&mesh).unwrap()),
        Box::new(Tet32Tracer::<DuffF32>::new(&mesh).unwrap()),
        Box::new(SctpTracer::<TripleF32>::new(&mesh).unwrap()),
        Box::new(Tet80Tracer::new(&mesh).unwrap()),
    ];
    let mut group = c.benchmark_group("exit_face");
    for t in &tracers {
        let steps: u64 = rays
            .iter()
            .map(|(r, s)| t.trace(r, Start::Tet(*s)).tets_visited() as u64)
            .sum();
        group.throughput(Throughput::Elements(steps));
        group.bench_function(t.name(), |b| {
            b.iter(|| {
                let mut acc = 0u32;
                for (r, s) in &rays {
                    acc = acc.wrapping_add(t.trace(black_box(r), Start::Tet(*s)).tets_visited());
                }
                acc
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
