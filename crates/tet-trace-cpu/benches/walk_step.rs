//! Same-run comparison of the batch paths of the projected walk on a real
//! mesh (not a criterion bench): the scalar interleaved walk
//! ([`tet_trace_cpu::walk::trace_interleaved`]) against the SIMD lockstep walk
//! ([`tet_trace_cpu::lockstep`]), frame by frame in turn, so that the load of
//! a shared machine hits both alike; likewise ScTP's batch path against its
//! lockstep walk at 8 (AVX2) and 16 (AVX-512) lanes where the CPU runs
//! them. Prints Mrays/s of the best frame, tets per ray, and checks that
//! both paths give identical outcomes per pixel.
//!
//! Run (mesh from `tet-bench build torus-knots -o /tmp/tk.tmesh`):
//! `TT_MESH=/tmp/tk.tmesh RAYON_NUM_THREADS=2 cargo bench -p tet-trace-cpu
//! --bench walk_step` (env `TT_W`, `TT_H`, `TT_FRAMES`, `TT_ONLY` = substring
//! of the method names to run). For callgrind (instructions per step), run
//! the bench binary with `TT_W=80 TT_H=60 TT_FRAMES=1 TT_ONLY=<name>
//! RAYON_NUM_THREADS=1` under `valgrind --tool=callgrind
//! --toggle-collect='*trace_batch*'` and divide by the printed step count.
//! The camera is the one `tet-bench render` uses for a mesh file (just
//! inside the +z side of the bounding box, looking at the centre).

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::scene::{Camera, PointLight};
use tet_trace_cpu::kernel::Interleaved;
use tet_trace_cpu::lockstep::{self, NoGate, Triple, Width};
use tet_trace_cpu::render::{Frame, RenderOptions, render};
use tet_trace_cpu::sctp::SctpTracer;
use tet_trace_cpu::tet16::Tet16Tracer;
use tet_trace_cpu::tet20::Tet20Tracer;
use tet_trace_cpu::tet32::Tet32Tracer;
use tet_trace_cpu::{DuffF32, Ray, Start, Starts, TraceOutcome, Tracer, TripleF32};

/// Process CPU time (user + system, all threads) in ms from /proc/self/stat
/// (10 ms ticks); `None` off Linux. On a shared machine, CPU time is less
/// disturbed by other processes than wall time.
fn cpu_ms() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/stat").ok()?;
    let rest = &s[s.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split(' ').collect();
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks * 10.0)
}

fn env(name: &str, default: u32) -> u32 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// `tet_bench::load::framing_camera`, duplicated (no dependency cycle).
fn framing_camera(mesh: &TetMesh) -> Camera {
    let (min, max) = mesh
        .points
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), p| {
            (a.min(*p), b.max(*p))
        });
    let center = (min + max) * 0.5;
    Camera {
        position: Vec3::new(center.x, center.y, max.z - 0.02 * (max.z - min.z)),
        target: center,
        up: Vec3::Y,
        vfov_deg: 60.0,
    }
}

/// ScTP's lockstep walk at one width (the batch path of `SctpTracer` is
/// 16-lane AVX-512 where the CPU has it, else the interleaved walk).
struct SctpAt<'a, 'm>(&'a SctpTracer<'m>, Width);

impl Tracer for SctpAt<'_, '_> {
    fn name(&self) -> String {
        format!("sctp/{:?}", self.1)
    }
    fn mesh(&self) -> &TetMesh {
        self.0.mesh()
    }
    fn trace(&self, ray: &Ray, start: Start) -> TraceOutcome {
        self.0.trace(ray, start)
    }
    fn trace_batch(&self, rays: &[Ray], start: Start, out: &mut [TraceOutcome]) {
        self.trace_batch_from(rays, Starts::Same(start), out);
    }
    fn trace_batch_from(&self, rays: &[Ray], starts: Starts<'_>, out: &mut [TraceOutcome]) {
        let batch = self.0.batch(rays, starts, out);
        let ran = lockstep::trace::<Triple, _, _>(batch, self.1, &mut NoGate);
        assert!(ran.is_ok(), "{:?} lockstep not available", self.1);
    }
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    let Ok(path) = std::env::var("TT_MESH") else {
        println!("walk_step: set TT_MESH to a .tmesh file (tet-bench build ... -o FILE)");
        return;
    };
    let mesh = tet_core::format::load(&path).expect("readable mesh");
    let (w, h) = (env("TT_W", 1920), env("TT_H", 1440));
    let frames = env("TT_FRAMES", 5);
    let camera = framing_camera(&mesh);
    let lights = [PointLight {
        position: camera.position,
        color: Vec3::ONE,
        intensity: 1.0,
    }];
    let opts = RenderOptions {
        width: w,
        height: h,
        ..Default::default()
    };
    let t20 = Tet20Tracer::<DuffF32>::new(&mesh).unwrap();
    let t16 = Tet16Tracer::<DuffF32>::new(&mesh).unwrap();
    let t32 = Tet32Tracer::<DuffF32>::new(&mesh).unwrap();
    let sctp = SctpTracer::<TripleF32>::new(&mesh).unwrap();
    let (i20, i16, i32) = (Interleaved(&t20), Interleaved(&t16), Interleaved(&t32));
    let (s8, s16) = (SctpAt(&sctp, Width::Avx2), SctpAt(&sctp, Width::Avx512));
    let mut all: Vec<(&str, &dyn Tracer)> = vec![
        ("tet20-interleaved", &i20),
        ("tet20-lockstep", &t20),
        ("tet16-interleaved", &i16),
        ("tet16-lockstep", &t16),
        ("tet32-interleaved", &i32),
        ("tet32-lockstep", &t32),
        ("sctp-batch", &sctp),
    ];
    // ScTP's lockstep walk at the SIMD widths this CPU runs.
    if Width::Avx2.available() {
        all.push(("sctp-lockstep8", &s8));
    }
    if Width::Avx512.available() {
        all.push(("sctp-lockstep16", &s16));
    }
    let only = std::env::var("TT_ONLY").ok();
    let run: Vec<(&str, &dyn Tracer)> = all
        .into_iter()
        .filter(|(n, _)| only.as_ref().is_none_or(|o| n.contains(o.as_str())))
        .collect();
    println!(
        "mesh {path}: {} tets; {w}x{h}; {} threads; {frames} frames each, in turn",
        mesh.tets.len(),
        rayon::current_num_threads()
    );
    let mut best: Vec<Option<Frame>> = run.iter().map(|_| None).collect();
    let mut cpu = vec![0.0f64; run.len()];
    for _ in 0..frames {
        for (k, (_, t)) in run.iter().enumerate() {
            let c0 = cpu_ms();
            let f = render(*t, &camera, &lights, &opts).unwrap();
            cpu[k] += c0.zip(cpu_ms()).map_or(f64::NAN, |(a, b)| b - a);
            if best[k].as_ref().is_none_or(|b| f.stats.ms < b.stats.ms) {
                best[k] = Some(f);
            }
        }
    }
    let base_ms = best[0].as_ref().map_or(f64::NAN, |f| f.stats.ms);
    for (((name, _), f), cpu) in run.iter().zip(&best).zip(&cpu) {
        let f = f.as_ref().unwrap();
        let s = f.stats;
        let per_cpu_s = s.rays as f64 * frames as f64 / (cpu * 1e3);
        println!(
            "{name:>18}: {:7.2} Mrays/s (best {:7.1} ms, {:5.3}x of first)  {per_cpu_s:5.2} Mrays per CPU-s  {:5.1} tets/ray  steps {}  hits {}  failures {}",
            s.mrays_per_s(),
            s.ms,
            base_ms / s.ms,
            s.tets_visited as f64 / s.rays as f64,
            s.tets_visited,
            s.hits,
            s.failures
        );
    }
    // Interleaved and lockstep paths of one layout: identical per pixel.
    for pair in run.windows(2).zip(best.windows(2)) {
        let ([(a, _), (b, _)], [Some(fa), Some(fb)]) = pair else {
            continue;
        };
        if a.split('-').next() == b.split('-').next() {
            let same = fa.tets == fb.tets && fa.triangle == fb.triangle;
            println!("{a} vs {b}: identical tets and triangles per pixel: {same}");
        }
    }
}
