//! The GPU BVH baseline (rows `bvh[]`): `tet_trace_gpu::GpuBvh` over the
//! scene's triangles on the same camera rays as the walks, its hits
//! compared with the CPU Tet20 walk's.

use anyhow::Result;
use tet_core::scene::Camera;
use tet_trace_gpu::{GpuBvh, GpuContext};

use super::compare::differences;
use super::doc::{GpuBytes, Row, Seen};
use super::rays::CameraRays;
use super::runs::Measured;

/// The BVH's row on `camera`'s `rays` (one warm-up frame, then `frames`
/// timed), compared with `tet20`, the CPU Tet20 walk's outcomes.
pub fn bvh_row(
    ctx: &GpuContext,
    scene: &str,
    mesh: &tet_core::TetMesh,
    camera: &Camera,
    rays: &CameraRays,
    frames: u32,
    tet20: &[Seen],
) -> Result<Row> {
    let bvh = GpuBvh::from_mesh(ctx, mesh)?;
    let (first, warm_up) = bvh.render(camera, rays.width, rays.height, false)?;
    let gpu: Vec<Seen> = first
        .iter()
        .map(|h| {
            h.map_or(Seen::Miss, |h| Seen::Hit {
                triangle: h.triangle,
                t: h.t,
            })
        })
        .collect();
    drop(first);
    let mut runs = Vec::new();
    for _ in 0..frames {
        runs.push(bvh.render(camera, rays.width, rays.height, false)?.1);
    }
    let bytes = bvh.gpu_bytes();
    Ok(Measured {
        scene,
        method: "gpu-bvh",
        kind: "primary",
        runs: &runs,
        differences: differences(mesh, |i| rays.ray(i), &gpu, tet20),
        gpu: &gpu,
        cpu: tet20,
        reference: "tet20",
        tets_per_ray: None,
        nodes_per_ray: Some(warm_up.tets_visited as f64 / warm_up.rays.max(1) as f64),
        gpu_bytes: GpuBytes {
            bvh: bytes,
            total: bytes,
            ..GpuBytes::default()
        },
        setup_ms: bvh.build_ms(),
        paper_ms: None,
    }
    .row())
}
