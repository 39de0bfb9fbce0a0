//! One scene on the GPU: the four walks of Aman et al. (2022) Table 3 on
//! the camera rays (kernel times from timestamp queries, best of the
//! timed frames), each layout's secondary rays, and the GPU BVH on the
//! same camera rays; every outcome checked against the CPU walk of the
//! same layout on the same rays.

use std::time::Instant;

use anyhow::{Context, Result};
use glam::Vec3;
use tet_trace_cpu::render::PinholeCamera;
use tet_trace_cpu::{Tracer, Viewpoint};
use tet_trace_gpu::{GpuContext, GpuLayout, GpuTracer};

use super::bvh::bvh_row;
use super::compare::{differences, seen};
use super::doc::{AdapterDoc, GpuBytes, Row, Seen};
use super::rays::{CameraRays, Secondary, bounce_rays, cpu_primary, cpu_secondary, shadow_rays};
use super::runs::Measured;
use crate::load::Loaded;
use crate::methods::method::Method;
use crate::methods::tracer;
use crate::output::error_chain;
use crate::tables::paper::paper_scene;

/// The walks of Table 3 in the paper's order of interest (Tet20 first:
/// its CPU walk gives the secondary rays and the BVH's reference), each
/// with its GPU method and the CPU method of the same layout.
const WALKS: [(GpuLayout, Method, Method); 4] = [
    (GpuLayout::Tet20, Method::GpuTet20, Method::Tet20),
    (GpuLayout::Tet16, Method::GpuTet16, Method::Tet16),
    (GpuLayout::Tet32, Method::GpuTet32, Method::Tet32),
    (GpuLayout::Tet80, Method::GpuTet80, Method::Tet80),
];

/// How much to measure.
#[derive(Clone, Copy, Debug)]
pub struct Plan {
    /// Image width of the camera rays.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Timed frames per method, after one warm-up.
    pub frames: u32,
    /// Timed passes over each secondary batch, after one warm-up.
    pub secondary_repeats: u32,
}

/// One scene's rows.
#[derive(Debug)]
pub struct SceneRows {
    /// Whether the camera lies inside the mesh.
    pub camera_inside: bool,
    /// The walks on the camera rays.
    pub table3: Vec<Row>,
    /// The BVH on the camera rays, or why not.
    pub bvh: Result<Row, String>,
    /// The secondary rays, per layout and kind.
    pub secondary: Vec<Row>,
}

/// The adapter `ctx` runs on.
pub fn adapter(ctx: &GpuContext) -> AdapterDoc {
    let info = ctx.adapter_info();
    AdapterDoc {
        name: info.name.clone(),
        backend: format!("{:?}", info.backend),
        device_type: format!("{:?}", info.device_type),
        driver: format!("{} {}", info.driver, info.driver_info)
            .trim()
            .to_string(),
        software: ctx.is_software(),
        timestamps: ctx.has_timestamps(),
    }
}

/// Measures the scene `loaded` (of spec `spec`, whose paper figures go
/// beside the rows).
pub fn measure_scene(
    ctx: &GpuContext,
    loaded: &Loaded,
    spec: &str,
    plan: &Plan,
) -> Result<SceneRows> {
    let mesh = &loaded.mesh;
    let view = Viewpoint::locate(mesh, loaded.camera.position)
        .map_err(|e| anyhow::anyhow!("camera {}: {e}", loaded.camera.position))?;
    let rays = CameraRays {
        camera: PinholeCamera::new(&loaded.camera, plan.width, plan.height, false),
        width: plan.width,
        height: plan.height,
    };
    let light = loaded
        .lights
        .first()
        .map_or(loaded.camera.position, |l| l.position);
    let mut rows = SceneRows {
        camera_inside: matches!(view, Viewpoint::Inside(_)),
        table3: Vec::new(),
        bvh: Err("not measured".into()),
        secondary: Vec::new(),
    };
    let mut batches: Vec<Secondary> = Vec::new();
    let mut tet20: Vec<Seen> = Vec::new();
    for (layout, method, cpu_method) in WALKS {
        eprintln!("  {}: {}", loaded.name, method.name());
        let cpu = tracer(cpu_method, false, mesh)?;
        let cpu_out = cpu_primary(cpu.as_ref(), &view, &rays);
        let cpu_seen: Vec<Seen> = cpu_out.iter().map(seen).collect();
        if layout == GpuLayout::Tet20 {
            batches = secondary_batches(loaded, &cpu_out, &rays, light);
        }
        drop(cpu_out);
        let setup = Instant::now();
        let gpu = GpuTracer::new(ctx, mesh, layout)
            .with_context(|| format!("cannot upload {} in {}", loaded.name, layout.name()))?;
        let setup_ms = setup.elapsed().as_secs_f64() * 1e3;
        let first = gpu.render_view(&loaded.camera, plan.width, plan.height, false, &view)?;
        let gpu_seen: Vec<Seen> = first.outcomes.iter().map(seen).collect();
        let warm_up = first.stats;
        let mut runs = Vec::new();
        for _ in 0..plan.frames {
            let frame = gpu.render_view(&loaded.camera, plan.width, plan.height, false, &view)?;
            runs.push(frame.stats);
        }
        let mem = gpu.memory();
        let gpu_bytes = GpuBytes {
            tets: mem.tets,
            points: mem.points,
            constrained: mem.constrained,
            bvh: 0,
            total: mem.total(),
        };
        rows.table3.push(
            Measured {
                scene: &loaded.name,
                method: method.name(),
                kind: "primary",
                runs: &runs,
                differences: differences(mesh, |i| rays.ray(i), &gpu_seen, &cpu_seen),
                gpu: &gpu_seen,
                cpu: &cpu_seen,
                reference: cpu_method.name(),
                tets_per_ray: Some(warm_up.tets_visited as f64 / warm_up.rays.max(1) as f64),
                nodes_per_ray: None,
                gpu_bytes,
                setup_ms,
                paper_ms: paper_scene(spec).and_then(|p| p.gpu_ms(method)),
            }
            .row(),
        );
        for batch in &batches {
            let walk = Walk {
                scene: &loaded.name,
                method,
                cpu_method,
                gpu: &gpu,
                cpu: cpu.as_ref(),
                gpu_bytes,
                setup_ms,
            };
            if let Some(row) = walk.secondary_row(batch, plan.secondary_repeats)? {
                rows.secondary.push(row);
            }
        }
        if layout == GpuLayout::Tet20 {
            tet20 = cpu_seen;
        }
    }
    eprintln!("  {}: gpu-bvh", loaded.name);
    rows.bvh = bvh_row(
        ctx,
        &loaded.name,
        mesh,
        &loaded.camera,
        &rays,
        plan.frames,
        &tet20,
    )
    .map_err(|e| error_chain(&e));
    Ok(rows)
}

/// The secondary rays of the CPU Tet20 walk's primary outcomes: shadow
/// rays to `light` and one bounce per hit.
fn secondary_batches(
    loaded: &Loaded,
    primary: &[tet_trace_cpu::TraceOutcome],
    rays: &CameraRays,
    light: Vec3,
) -> Vec<Secondary> {
    vec![
        shadow_rays(&loaded.mesh, primary, light),
        bounce_rays(&loaded.mesh, primary, rays),
    ]
}

/// One layout's walk on the GPU and on the CPU.
struct Walk<'a> {
    /// Scene name.
    scene: &'a str,
    /// The GPU method.
    method: Method,
    /// The CPU method of the same layout.
    cpu_method: Method,
    /// The GPU tracer.
    gpu: &'a GpuTracer<'a>,
    /// The CPU tracer.
    cpu: &'a dyn Tracer,
    /// The layout's bytes on the GPU.
    gpu_bytes: GpuBytes,
    /// Its encoding and upload, ms.
    setup_ms: f64,
}

impl Walk<'_> {
    /// The row of one batch of secondary rays (`GpuTracer::trace_batch`
    /// from the CPU's rays and starts: one warm-up, `repeats` timed);
    /// `None` for an empty batch.
    fn secondary_row(&self, batch: &Secondary, repeats: u32) -> Result<Option<Row>> {
        if batch.rays.is_empty() {
            return Ok(None);
        }
        let cpu_seen: Vec<Seen> = cpu_secondary(self.cpu, batch).iter().map(seen).collect();
        let (first, warm_up) = self.gpu.trace_batch(&batch.rays, &batch.starts)?;
        let gpu_seen: Vec<Seen> = first.iter().map(seen).collect();
        drop(first);
        let mut runs = Vec::new();
        for _ in 0..repeats.max(1) {
            runs.push(self.gpu.trace_batch(&batch.rays, &batch.starts)?.1);
        }
        let mesh = self.gpu.mesh();
        Ok(Some(
            Measured {
                scene: self.scene,
                method: self.method.name(),
                kind: batch.kind,
                runs: &runs,
                differences: differences(mesh, |i| batch.rays[i], &gpu_seen, &cpu_seen),
                gpu: &gpu_seen,
                cpu: &cpu_seen,
                reference: self.cpu_method.name(),
                tets_per_ray: Some(warm_up.tets_visited as f64 / warm_up.rays.max(1) as f64),
                nodes_per_ray: None,
                gpu_bytes: self.gpu_bytes,
                setup_ms: self.setup_ms,
                paper_ms: None,
            }
            .row(),
        ))
    }
}
