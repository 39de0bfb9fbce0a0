//! Timing the GPU methods (`gpu-tet20`, …): camera rays generated and
//! walked on the GPU (wgpu), timed with timestamp queries when the adapter
//! has them, reported as a [`RenderDoc`] like the CPU methods.

use anyhow::{Result, bail};

use crate::load::Loaded;
use crate::methods::method::Method;
use crate::timing::RenderDoc;

/// Renders `frames` GPU frames (plus a warm-up) of `method`.
#[cfg(feature = "gpu")]
pub fn time_gpu(
    loaded: &Loaded,
    method: Method,
    width: u32,
    height: u32,
    frames: u32,
) -> Result<RenderDoc> {
    use std::time::Instant;
    use tet_trace_gpu::{GpuContext, GpuLayout, GpuTracer};

    let layout = match method {
        Method::GpuTet20 => GpuLayout::Tet20,
        Method::GpuTet32 => GpuLayout::Tet32,
        Method::GpuTet16 => GpuLayout::Tet16,
        Method::GpuTet80 => GpuLayout::Tet80,
        m => bail!("{} is not a GPU method", m.name()),
    };
    let setup = Instant::now();
    let ctx = GpuContext::new()?;
    let tracer = GpuTracer::new(&ctx, &loaded.mesh, layout)?;
    let setup_s = setup.elapsed().as_secs_f64();
    let view = tet_trace_cpu::Viewpoint::locate(&loaded.mesh, loaded.camera.position)
        .map_err(|e| anyhow::anyhow!("camera {}: {e}", loaded.camera.position))?;
    let mut frame = tracer.render_view(&loaded.camera, width, height, false, &view)?;
    let mut ms = Vec::new();
    let mut best = frame.stats.clone();
    for _ in 0..frames.max(1) {
        frame = tracer.render_view(&loaded.camera, width, height, false, &view)?;
        if frame.stats.ms() < best.ms() || ms.is_empty() {
            best = frame.stats.clone();
        }
        ms.push(frame.stats.ms());
    }
    ms.sort_by(f64::total_cmp);
    let mem = tracer.memory();
    let hot_bytes = (mem.tets + mem.points) as usize;
    Ok(RenderDoc {
        scene: loaded.name.clone(),
        method,
        tracer: format!("{} on {}", best.method, best.device),
        width,
        height,
        threads: 0,
        frames: frames.max(1),
        best_ms: best.ms(),
        median_ms: ms[ms.len() / 2],
        mrays_per_s: best.mrays_per_s(),
        tets_per_ray: best.tets_visited as f64 / best.rays.max(1) as f64,
        nodes_per_ray: None,
        rays: best.rays,
        hits: best.hits,
        failures: best.failures,
        shadow_rays: 0,
        rays_kind: super::ray_kinds::RayKinds::Primary,
        by_kind: super::ray_kinds::ByKind {
            primary: super::ray_kinds::KindDoc {
                rays: best.rays,
                mrays_per_s: best.mrays_per_s(),
                tets_per_ray: None,
            },
            ..Default::default()
        },
        setup_s,
        hot_bytes,
        target_features: crate::timing::target_features(),
    })
}

/// Without the `gpu` feature.
#[cfg(not(feature = "gpu"))]
pub fn time_gpu(_: &Loaded, method: Method, _: u32, _: u32, _: u32) -> Result<RenderDoc> {
    bail!(
        "{} needs the GPU methods: rebuild with `cargo run --release -p tet-bench --features gpu -- …`",
        method.name()
    )
}
