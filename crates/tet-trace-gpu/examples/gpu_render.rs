//! Primary-ray throughput of the GPU kernels on a procedural scene.
//!
//! ```text
//! cargo run -p tet-trace-gpu --example gpu_render -- [cells] [width] [height] [repeats]
//! ```
//!
//! Builds a jittered Kuhn grid of `cells³` cubes (6 tets each) with a closed
//! shell of constrained faces around the middle third, puts the camera in a
//! corner looking at the centre, renders `width × height` primary rays
//! `repeats` times per layout and prints one line per layout (GPU time from
//! timestamp queries when available, wall time otherwise; apart from them,
//! the rays whose walk lost its way and was walked again on the host, with
//! their host time). Defaults: 40 cells, 640×480, 3 repeats.

use std::time::Instant;

use glam::Vec3;
use tet_core::scene::Camera;
use tet_core::synthetic::{GridSpec, kuhn_grid};
use tet_trace_gpu::{GpuContext, GpuLayout, GpuTracer};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<u32> = std::env::args()
        .skip(1)
        .map(|a| a.parse())
        .collect::<Result<_, _>>()?;
    let arg = |i: usize, d: u32| args.get(i).copied().unwrap_or(d);
    let (n, w, h, repeats) = (arg(0, 40), arg(1, 640), arg(2, 480), arg(3, 3).max(1));
    let t0 = Instant::now();
    let lo = n / 3;
    let mesh = kuhn_grid(&GridSpec {
        cells: [n, n, n],
        jitter: 0.1,
        shell: Some(([lo, lo, lo], [n - lo, n - lo, n - lo])),
        seed: 1,
        ..Default::default()
    });
    println!(
        "mesh: {} tets, {} points, {} constrained faces ({:.1} s)",
        mesh.tets.len(),
        mesh.points.len(),
        mesh.constrained.len(),
        t0.elapsed().as_secs_f64()
    );
    let camera = Camera {
        position: Vec3::splat(0.37 * lo as f32),
        target: Vec3::splat(n as f32 * 0.5),
        up: Vec3::Y,
        vfov_deg: 45.0,
    };
    let start = tet_trace_cpu::locate(&mesh, camera.position, 0)?;
    let ctx = GpuContext::new()?;
    println!(
        "adapter: {} (timestamps: {})",
        ctx.device_name(),
        ctx.has_timestamps()
    );
    for layout in GpuLayout::ALL {
        let gpu = GpuTracer::new(&ctx, &mesh, layout)?;
        gpu.render(&camera, w, h, false, start)?; // warm-up
        let mut best: Option<tet_trace_gpu::DispatchStats> = None;
        for _ in 0..repeats {
            let f = gpu.render(&camera, w, h, false, start)?;
            if best.as_ref().is_none_or(|b| f.stats.ms() < b.ms()) {
                best = Some(f.stats);
            }
        }
        let s = best.expect("repeats >= 1");
        println!(
            "{:10} {}x{}: gpu {:>9} ms, wall {:8.2} ms, {:8.2} Mrays/s, hits {}, \
             failures {}, tets/ray {:.1}, re-walked on the host {} ({:.2} ms), GPU memory {} B",
            s.method,
            w,
            h,
            s.gpu_ms.map_or("n/a".into(), |m| format!("{m:.2}")),
            s.wall_ms,
            s.mrays_per_s(),
            s.hits,
            s.failures,
            s.tets_visited as f64 / s.rays as f64,
            s.host_rewalks,
            s.host_rewalk_ms,
            gpu.memory().total()
        );
    }
    Ok(())
}
