//! The GPU side of a tracer: the uploaded mesh and compiled kernel
//! ([`Kernel`]), one compute pass with its read-back and timing
//! ([`run_pass`], shared with the BVH kernel), and how many rays fit one
//! dispatch.

use std::sync::mpsc;

use bytemuck::Pod;
use tet_core::TetMesh;
use wgpu::util::DeviceExt;

use crate::context::GpuContext;
use crate::error::GpuError;
use crate::layout::{GpuLayout, Split};
use crate::records::{HitRec, Params};
use crate::stats::{DispatchStats, GpuMemory};

/// Invocations per workgroup (must equal `@workgroup_size` in the shader).
const WORKGROUP: u32 = 64;
/// Largest number of rays per dispatch (bounds host staging memory).
const MAX_RAYS_PER_DISPATCH: u64 = 1 << 22;

/// A mesh uploaded in one layout, with the layout's compiled kernel.
pub(crate) struct Kernel {
    pipeline: wgpu::ComputePipeline,
    points: wgpu::Buffer,
    /// Tet records, one buffer per binding (see `Split`).
    pub(crate) tets: Vec<wgpu::Buffer>,
    faces: wgpu::Buffer,
    /// Bound in place of the per-ray inputs of camera dispatches.
    pub(crate) dummy: wgpu::Buffer,
}

impl Kernel {
    /// Encodes `mesh` (validated) in `layout`, uploads it and compiles the
    /// layout's kernel; with the bytes resident. Fails with
    /// [`GpuError::TooLarge`] when an array exceeds a device limit.
    pub(crate) fn upload(
        ctx: &GpuContext,
        mesh: &TetMesh,
        layout: GpuLayout,
    ) -> Result<(Kernel, GpuMemory), GpuError> {
        let tets = layout.encode(mesh)?;
        let points: Vec<f32> = mesh.points.iter().flat_map(|p| p.to_array()).collect();
        let faces: Vec<u32> = mesh
            .constrained
            .iter()
            .flat_map(|cf| {
                [
                    cf.triangle,
                    cf.front.tet,
                    cf.back.tet,
                    cf.vertices[0],
                    cf.vertices[1],
                    cf.vertices[2],
                ]
            })
            .collect();
        let memory = GpuMemory {
            layout: layout.name(),
            tets: (tets.len() * 4) as u64,
            points: (points.len() * 4) as u64,
            constrained: (faces.len() * 4) as u64,
        };
        // The records may be split over several bindings; each part must
        // also fit `max_buffer_size`.
        let split = Split::new(
            tets.len() as u64,
            ctx.max_binding_bytes(),
            ctx.max_storage_buffers.saturating_sub(5),
        )
        .ok_or(GpuError::TooLarge {
            buffer: "tet records",
            bytes: memory.tets,
            limit: "max_storage_buffer_binding_size (times the bindings available for tets)",
            value: ctx.max_binding_bytes(),
        })?;
        ctx.check_size("points", memory.points)?;
        ctx.check_size("constrained faces", memory.constrained)?;
        if mesh.points.len() > (u32::MAX / 3) as usize {
            return Err(GpuError::TooMany {
                what: "points",
                count: mesh.points.len(),
                limit: (u32::MAX / 3) as usize,
            });
        }
        let device = &ctx.device;
        let oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let val = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let storage = |label: &str, data: &[u8]| storage_buffer(device, label, data);
        let points_buf = storage("points", bytemuck::cast_slice(&points));
        let tets_bufs: Vec<wgpu::Buffer> = (0..split.count)
            .map(|j| {
                storage(
                    layout.name(),
                    bytemuck::cast_slice(&tets[split.part(j, tets.len())]),
                )
            })
            .collect();
        let faces_buf = storage("constrained", bytemuck::cast_slice(&faces));
        let dummy = storage("dummy", &[0u8; 64]);
        let source = layout.source(split);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(layout.method()),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(layout.method()),
            layout: None,
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
        scope_result("mesh upload / pipeline creation", val, oom)?;
        let kernel = Kernel {
            pipeline,
            points: points_buf,
            tets: tets_bufs,
            faces: faces_buf,
            dummy,
        };
        Ok((kernel, memory))
    }

    /// One dispatch of `params.ray_count` rays; returns the records and the
    /// GPU time when timestamps are enabled.
    pub(crate) fn dispatch(
        &self,
        ctx: &GpuContext,
        params: &Params,
        rays: &wgpu::Buffer,
        starts: &wgpu::Buffer,
    ) -> Result<(Vec<HitRec>, Option<f64>), GpuError> {
        let mut inputs = vec![(0, &self.points), (2, &self.faces), (4, rays), (5, starts)];
        for (j, b) in self.tets.iter().enumerate() {
            inputs.push((Split::binding(j as u32), b));
        }
        run_pass(
            ctx,
            "walk",
            &self.pipeline,
            &inputs,
            (3, bytemuck::bytes_of(params)),
            6,
            params.ray_count,
        )
    }
}

/// One compute pass of `n` invocations (workgroups of [`WORKGROUP`], the
/// `@workgroup_size` of every kernel, spread over a 2-D grid when they
/// exceed the per-dimension limit) of `pipeline`, with the storage buffers
/// `inputs` (binding, buffer), the uniform `params` (binding, bytes) and a
/// fresh output array of `n` records `T` at `out_binding`. Returns the
/// records and, when timestamps are enabled, the pass's GPU time (ms).
pub(crate) fn run_pass<T: Pod>(
    ctx: &GpuContext,
    label: &'static str,
    pipeline: &wgpu::ComputePipeline,
    inputs: &[(u32, &wgpu::Buffer)],
    params: (u32, &[u8]),
    out_binding: u32,
    n: u32,
) -> Result<(Vec<T>, Option<f64>), GpuError> {
    if n == 0 {
        return Ok((Vec::new(), None));
    }
    let device = &ctx.device;
    let oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let val = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let out_bytes = n as u64 * size_of::<T>() as u64;
    let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("params"),
        contents: params.1,
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let out = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("results"),
        size: out_bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("results readback"),
        size: out_bytes,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut entries: Vec<wgpu::BindGroupEntry<'_>> =
        inputs.iter().map(|&(b, buf)| entry(b, buf)).collect();
    entries.push(entry(params.0, &uniform));
    entries.push(entry(out_binding, &out));
    let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &entries,
    });
    let timing = ctx.timestamps.then(|| {
        let set = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count: 2,
        });
        let resolve = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamps"),
            size: 16,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let read = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamps readback"),
            size: 16,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        (set, resolve, read)
    });
    let mut enc =
        device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
    {
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(label),
            timestamp_writes: timing
                .as_ref()
                .map(|(set, _, _)| wgpu::ComputePassTimestampWrites {
                    query_set: set,
                    beginning_of_pass_write_index: Some(0),
                    end_of_pass_write_index: Some(1),
                }),
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &bind, &[]);
        let groups = n.div_ceil(WORKGROUP);
        let x = groups.min(ctx.max_workgroups);
        pass.dispatch_workgroups(x, groups.div_ceil(x), 1);
    }
    enc.copy_buffer_to_buffer(&out, 0, &readback, 0, out_bytes);
    if let Some((set, resolve, read)) = &timing {
        enc.resolve_query_set(set, 0..2, resolve, 0);
        enc.copy_buffer_to_buffer(resolve, 0, read, 0, 16);
    }
    ctx.queue.submit([enc.finish()]);
    let records: Vec<T> = read_buffer(device, &readback)?;
    let gpu_ms = match &timing {
        Some((_, _, read)) => {
            let ts: Vec<u64> = read_buffer(device, read)?;
            let ticks = ts[1].saturating_sub(ts[0]);
            Some(ticks as f64 * ctx.queue.get_timestamp_period() as f64 / 1e6)
        }
        None => None,
    };
    scope_result("dispatch", val, oom)?;
    Ok((records, gpu_ms))
}

/// A read-only storage buffer holding `data` (an empty array gets 32 zero
/// bytes: zero-sized bindings are invalid).
pub(crate) fn storage_buffer(device: &wgpu::Device, label: &str, data: &[u8]) -> wgpu::Buffer {
    let pad = [0u8; 32];
    let contents = if data.is_empty() { &pad[..] } else { data };
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents,
        usage: wgpu::BufferUsages::STORAGE,
    })
}

/// Rays per dispatch so that every per-ray buffer fits the limits.
pub(crate) fn rays_per_dispatch(ctx: &GpuContext, input_bytes: u64) -> Result<usize, GpuError> {
    let per_ray = (size_of::<HitRec>() as u64).max(input_bytes);
    let lim = ctx.max_binding_bytes() / per_ray;
    let wg = ctx.max_workgroups as u64;
    let n = lim
        .min(MAX_RAYS_PER_DISPATCH)
        .min(wg * wg * WORKGROUP as u64);
    if n == 0 {
        return Err(GpuError::TooLarge {
            buffer: "per-ray records",
            bytes: per_ray,
            limit: "max_storage_buffer_binding_size",
            value: ctx.max_binding_bytes(),
        });
    }
    Ok(n as usize)
}

/// Counts one dispatch and adds its GPU time (when both are timed).
pub(crate) fn add_gpu_ms(stats: &mut DispatchStats, gpu_ms: Option<f64>) {
    stats.dispatches += 1;
    if let (Some(a), Some(b)) = (stats.gpu_ms, gpu_ms) {
        stats.gpu_ms = Some(a + b);
    }
}

/// A bind-group entry of a whole buffer.
fn entry(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: buffer.as_entire_binding(),
    }
}

/// Pops the two error scopes pushed by the caller (validation innermost).
pub(crate) fn scope_result(
    during: &'static str,
    val: wgpu::ErrorScopeGuard,
    oom: wgpu::ErrorScopeGuard,
) -> Result<(), GpuError> {
    let v = pollster::block_on(val.pop());
    let o = pollster::block_on(oom.pop());
    match v.or(o) {
        Some(e) => Err(GpuError::Wgpu {
            during,
            message: e.to_string(),
        }),
        None => Ok(()),
    }
}

/// Maps a `MAP_READ` buffer after the queue finished and copies it out.
fn read_buffer<T: Pod>(device: &wgpu::Device, buf: &wgpu::Buffer) -> Result<Vec<T>, GpuError> {
    let err = |message: String| GpuError::Wgpu {
        during: "read-back",
        message,
    };
    let slice = buf.slice(..);
    let (tx, rx) = mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| err(e.to_string()))?;
    rx.recv()
        .map_err(|e| err(e.to_string()))?
        .map_err(|e| err(e.to_string()))?;
    let data = slice.get_mapped_range().map_err(|e| err(e.to_string()))?;
    let out = bytemuck::pod_collect_to_vec(&data);
    drop(data);
    buf.unmap();
    Ok(out)
}
