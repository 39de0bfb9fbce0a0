//! Primary-ray throughput of every method on one frame (not a criterion
//! bench: prints Mrays/s, tets per ray and failures, like the papers' tables).
//!
//! Scene: a jittered Kuhn grid of `N³` cells (default 48, 663 552 tets) with
//! a closed constrained shell around its middle third plus 0.5 % random
//! constrained faces; the camera orbits outside the shell, inside the mesh.
//! Tets and points are put in Hilbert order first (`TT_ORDER=hilbert`,
//! `region` or `none`).
//! Run: `RAYON_NUM_THREADS=2 cargo bench -p tet-trace-cpu --bench
//! render_throughput` (env `TT_CELLS`, `TT_W`, `TT_H`, `TT_FRAMES`).

use glam::Vec3;
use tet_core::scene::{Camera, PointLight};
use tet_core::synthetic::{GridSpec, kuhn_grid};
use tet_trace_cpu::render::{RenderOptions, render};
use tet_trace_cpu::sctp::SctpTracer;
use tet_trace_cpu::tet16::Tet16Tracer;
use tet_trace_cpu::tet20::Tet20Tracer;
use tet_trace_cpu::tet32::Tet32Tracer;
use tet_trace_cpu::tet80::Tet80Tracer;
use tet_trace_cpu::{DuffF32, DuffF64, OriginF32, Tracer, TripleF32};

/// Process CPU time (user + system, all threads) in ms, from /proc/self/stat
/// (10 ms resolution); `None` off Linux. On a shared machine wall time
/// includes other processes' load, CPU time does not.
fn cpu_ms() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/stat").ok()?;
    let rest = &s[s.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split(' ').collect();
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks * 10.0)
}

/// Wraps a tracer so that batches are traced ray by ray (no interleaving):
/// `TT_SINGLE=1` measures what interleaving buys.
struct Single<'a>(&'a dyn Tracer);

impl Tracer for Single<'_> {
    fn name(&self) -> String {
        format!("{}/single", self.0.name())
    }
    fn mesh(&self) -> &tet_core::TetMesh {
        self.0.mesh()
    }
    fn trace(
        &self,
        ray: &tet_trace_cpu::Ray,
        start: tet_trace_cpu::Start,
    ) -> tet_trace_cpu::TraceOutcome {
        self.0.trace(ray, start)
    }
}

fn env(name: &str, default: u32) -> u32 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    let n = env("TT_CELLS", 48);
    let (w, h) = (env("TT_W", 1920), env("TT_H", 1440));
    let frames = env("TT_FRAMES", 3);
    let mut mesh = kuhn_grid(&GridSpec {
        cells: [n; 3],
        jitter: 0.12,
        constrained_fraction: 0.005,
        shell: Some(([n / 3; 3], [2 * n / 3; 3])),
        seed: 1,
        ..Default::default()
    });
    // Memory order (Aman et al. 2022, §5): TT_ORDER = hilbert (default), region, none.
    let order = std::env::var("TT_ORDER").unwrap_or_else(|_| "hilbert".into());
    match order.as_str() {
        "hilbert" => {
            tet_core::reorder::hilbert_reorder(&mut mesh).unwrap();
        }
        "region" => {
            tet_core::reorder::region_major_reorder(&mut mesh).unwrap();
        }
        _ => {}
    }
    let nf = n as f32;
    let camera = Camera {
        position: Vec3::new(0.15 * nf, 0.8 * nf, 0.9 * nf),
        target: Vec3::splat(0.5 * nf),
        up: Vec3::Y,
        vfov_deg: 45.0,
    };
    let lights = [PointLight {
        position: Vec3::new(0.9 * nf, 0.95 * nf, 0.8 * nf),
        color: Vec3::ONE,
        intensity: 1.0,
    }];
    let opts = RenderOptions {
        width: w,
        height: h,
        ..Default::default()
    };
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
    println!(
        "mesh: {} tets, {} constrained faces, order {order}; {w}x{h}; {} threads",
        mesh.tets.len(),
        mesh.constrained.len(),
        rayon::current_num_threads()
    );
    let only = std::env::var("TT_ONLY").ok();
    for t in &tracers {
        if only
            .as_ref()
            .is_some_and(|o| !t.name().contains(o.as_str()))
        {
            continue;
        }
        let mut best = f64::MAX;
        let mut stats = None;
        let single = Single(t.as_ref());
        let t: &dyn Tracer = if env("TT_SINGLE", 0) == 1 {
            &single
        } else {
            t.as_ref()
        };
        let c0 = cpu_ms();
        for _ in 0..frames {
            let f = render(t, &camera, &lights, &opts).unwrap();
            if f.stats.ms < best {
                best = f.stats.ms;
                stats = Some(f.stats);
            }
        }
        let cpu = c0
            .zip(cpu_ms())
            .map_or(f64::NAN, |(a, b)| (b - a) / frames as f64);
        let s = stats.unwrap();
        println!(
            "{:>14}: {:7.2} Mrays/s wall (best {:6.1} ms)  {:7.2} Mrays per CPU-s  {:5.1} tets/ray  hits {}  failures {}",
            t.name(),
            s.mrays_per_s(),
            s.ms,
            s.rays as f64 / (cpu * 1e3),
            s.tets_visited as f64 / s.rays as f64,
            s.hits,
            s.failures
        );
    }
}
