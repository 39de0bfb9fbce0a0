//! The tracer: a mesh on the GPU in one [`GpuLayout`], batch tracing
//! ([`GpuTracer::trace_batch`]) and camera rendering ([`GpuTracer::render`],
//! [`GpuTracer::render_view`]). See the crate docs for the decisions ported
//! from the CPU kernels and where results may differ.

use std::time::Instant;

use bytemuck::Zeroable;
use glam::DVec3;
use tet_core::TetMesh;
use tet_core::scene::Camera;
use tet_trace_cpu::render::PinholeCamera;
use tet_trace_cpu::walk::{duff_basis, start_scale, step_cap};
use tet_trace_cpu::{Failure, Ray, Start, TraceOutcome, Viewpoint};
use wgpu::util::DeviceExt;

use crate::context::GpuContext;
use crate::dispatch::{Kernel, add_gpu_ms, rays_per_dispatch};
use crate::error::GpuError;
use crate::layout::GpuLayout;
use crate::lost::exact_where_lost;
use crate::records::{CameraRec, HitRec, Params, RayRec, StartRec};
use crate::starts::start_record;
use crate::stats::{DispatchStats, GpuFrame, GpuMemory};

/// A mesh uploaded in one compact layout, with its compiled kernel.
pub struct GpuTracer<'a> {
    ctx: &'a GpuContext,
    layout: GpuLayout,
    mesh: &'a TetMesh,
    kernel: Kernel,
    memory: GpuMemory,
    cap: u32,
}

impl<'a> GpuTracer<'a> {
    /// Encodes `mesh` (validated) in `layout` and uploads it. Fails with
    /// [`GpuError::TooLarge`] when an array exceeds a device limit.
    pub fn new(
        ctx: &'a GpuContext,
        mesh: &'a TetMesh,
        layout: GpuLayout,
    ) -> Result<Self, GpuError> {
        let (kernel, memory) = Kernel::upload(ctx, mesh, layout)?;
        Ok(GpuTracer {
            ctx,
            layout,
            mesh,
            kernel,
            memory,
            cap: step_cap(mesh),
        })
    }

    /// Replaces the step cap (tets visited before a walk reports
    /// [`Failure::StepCap`]); the default is the CPU's
    /// `tet_trace_cpu::walk::step_cap`.
    pub fn with_step_cap(mut self, cap: u32) -> Self {
        self.cap = cap;
        self
    }

    /// The step cap in use.
    pub fn step_cap(&self) -> u32 {
        self.cap
    }

    /// The layout walked.
    pub fn layout(&self) -> GpuLayout {
        self.layout
    }

    /// Number of storage bindings the tet records are split over (1 when
    /// they fit one binding).
    pub fn tet_bindings(&self) -> usize {
        self.kernel.tets.len()
    }

    /// Bytes of the mesh on the GPU.
    pub fn memory(&self) -> GpuMemory {
        self.memory
    }

    /// The mesh (cold data: attributes, constrained-face table).
    pub fn mesh(&self) -> &TetMesh {
        self.mesh
    }

    /// Traces arbitrary rays, ray `i` from `starts[i]` (a tet containing its
    /// origin, or a constrained face for secondary rays), like the CPU
    /// `Tracer::trace`. Large batches are split into several dispatches.
    /// A walk that lost its way (the default step cap, or no start) is
    /// walked again on the host by the exact walk from `starts[i]`, as the
    /// CPU tracers do (crate docs, "Walks that lost their way"), counted in
    /// [`DispatchStats::host_rewalks`].
    pub fn trace_batch(
        &self,
        rays: &[Ray],
        starts: &[Start],
    ) -> Result<(Vec<TraceOutcome>, DispatchStats), GpuError> {
        if rays.len() != starts.len() {
            return Err(GpuError::LengthMismatch {
                rays: rays.len(),
                starts: starts.len(),
            });
        }
        let mut stats = self.new_stats();
        let t0 = Instant::now();
        let per = rays_per_dispatch(self.ctx, size_of::<RayRec>() as u64)?;
        let mut out = Vec::with_capacity(rays.len());
        for (rc, sc) in rays.chunks(per).zip(starts.chunks(per)) {
            let recs: Vec<RayRec> = rc
                .iter()
                .zip(sc)
                .map(|(r, &s)| {
                    let (u, v) = if r.is_valid() {
                        duff_basis(r.direction.as_dvec3().normalize())
                    } else {
                        (DVec3::X, DVec3::Y)
                    };
                    // The CPU walk's factor (exact; 1 at ordinary scales).
                    let k = start_scale(self.mesh, r, s);
                    let (u, v) = (u.as_vec3() * k, v.as_vec3() * k);
                    RayRec {
                        o: r.origin.extend(r.t_min).to_array(),
                        d: r.direction.extend(r.t_max).to_array(),
                        u: u.extend(0.0).to_array(),
                        v: v.extend(0.0).to_array(),
                    }
                })
                .collect();
            let st: Vec<StartRec> = rc
                .iter()
                .zip(sc)
                .map(|(r, &s)| start_record(self.mesh, self.layout, r, s))
                .collect();
            let device = &self.ctx.device;
            let rays_buf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("rays"),
                contents: bytemuck::cast_slice(&recs),
                usage: wgpu::BufferUsages::STORAGE,
            });
            let starts_buf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("starts"),
                contents: bytemuck::cast_slice(&st),
                usage: wgpu::BufferUsages::STORAGE,
            });
            let params = Params {
                ray_count: rc.len() as u32,
                ..self.base_params()
            };
            let (hits, gpu_ms) = self
                .kernel
                .dispatch(self.ctx, &params, &rays_buf, &starts_buf)?;
            add_gpu_ms(&mut stats, gpu_ms);
            out.extend(hits.iter().map(HitRec::outcome));
        }
        stats.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        // Walks that lost their way: the exact walk from the same start,
        // on the host (see the crate docs, "Walks that lost their way").
        exact_where_lost(self.mesh, self.cap, &mut out, &mut stats, |i| {
            Some((rays[i], starts[i]))
        });
        stats.count(&out);
        Ok((out, stats))
    }

    /// Traces the primary rays of a `width × height` image, generated on the
    /// GPU with the conventions of `scenes.json` (see
    /// `tet_trace_cpu::render::PinholeCamera`), all starting in `start_tet`
    /// (a tet containing the eye, e.g. from `tet_trace_cpu::locate`).
    /// Rays the GPU cannot start there (eye on the tet's boundary) are
    /// re-traced through [`GpuTracer::trace_batch`] ([`GpuFrame::retraced`]);
    /// a walk that lost its way (the default step cap) is walked again on
    /// the host by the exact walk from `start_tet`, on the host's camera ray
    /// (crate docs, "Walks that lost their way").
    pub fn render(
        &self,
        camera: &Camera,
        width: u32,
        height: u32,
        pixel_centers: bool,
        start_tet: u32,
    ) -> Result<GpuFrame, GpuError> {
        let mesh = self.mesh;
        let camera_rec = CameraRec::new(camera, width, height, pixel_centers)?;
        let pixels = width as u64 * height as u64;
        if start_tet as usize >= mesh.tets.len() {
            return Err(GpuError::Camera {
                detail: format!(
                    "start tet {start_tet} is out of bounds ({} tets)",
                    mesh.tets.len()
                ),
            });
        }
        let base = Params {
            camera_mode: 1,
            width,
            height,
            cam_tet: start_tet,
            cam_ids: mesh.tets[start_tet as usize],
            cam_links: mesh.neighbors[start_tet as usize].map(|l| l.0),
            camera: camera_rec,
            ..self.base_params()
        };
        let mut stats = self.new_stats();
        let t0 = Instant::now();
        let per = rays_per_dispatch(self.ctx, 0)? as u64;
        let mut outcomes = Vec::with_capacity(pixels as usize);
        let mut first = 0u64;
        while first < pixels {
            let n = per.min(pixels - first);
            let params = Params {
                ray_count: n as u32,
                first_ray: first as u32,
                ..base
            };
            let (hits, gpu_ms) =
                self.kernel
                    .dispatch(self.ctx, &params, &self.kernel.dummy, &self.kernel.dummy)?;
            add_gpu_ms(&mut stats, gpu_ms);
            outcomes.extend(hits.iter().map(HitRec::outcome));
            first += n;
        }
        // Rays the GPU could not start (origin on the start tet's boundary):
        // re-traced below with the CPU's full start logic.
        let unstarted: Vec<usize> = outcomes
            .iter()
            .enumerate()
            .filter(|(_, o)| {
                matches!(
                    o,
                    TraceOutcome::Failed {
                        failure: Failure::Lost,
                        tets_visited: 0
                    }
                )
            })
            .map(|(i, _)| i)
            .collect();
        let cam = PinholeCamera::new(camera, width, height, pixel_centers);
        let ray_of = |i: usize| cam.ray(i as u32 % width, i as u32 / width);
        // The other walks that lost their way: the exact walk from the
        // start tet, of the host's camera ray (the ray of the CPU renderer;
        // the GPU's may differ in the last bit, see the crate docs).
        exact_where_lost(mesh, self.cap, &mut outcomes, &mut stats, |i| {
            unstarted
                .binary_search(&i)
                .is_err()
                .then(|| (ray_of(i), Start::Tet(start_tet)))
        });
        if !unstarted.is_empty() {
            let rays: Vec<Ray> = unstarted.iter().map(|&i| ray_of(i)).collect();
            let starts = vec![Start::Tet(start_tet); rays.len()];
            // With its own host re-walks of walks that lost their way.
            let (re, s) = self.trace_batch(&rays, &starts)?;
            stats.absorb(&s);
            for (&i, o) in unstarted.iter().zip(re) {
                outcomes[i] = o;
            }
        }
        Ok(GpuFrame::done(
            width,
            height,
            outcomes,
            stats,
            t0,
            unstarted.len() as u64,
        ))
    }

    /// [`GpuTracer::render`] from a located viewpoint: the GPU's own camera
    /// rays when the camera is inside the mesh; from outside, the rays are
    /// made on the host, each starts through the boundary face it enters by
    /// (`tet_trace_cpu::boundary_entry`, host side, like the starts of
    /// [`GpuTracer::trace_batch`]) and a ray that misses the mesh is a miss
    /// that visits no tet. Walks that lost their way are walked again on
    /// the host by the exact walk, from the same start (see
    /// [`GpuTracer::render`], [`GpuTracer::trace_batch`]).
    pub fn render_view(
        &self,
        camera: &Camera,
        width: u32,
        height: u32,
        pixel_centers: bool,
        view: &Viewpoint,
    ) -> Result<GpuFrame, GpuError> {
        let entry = match view {
            Viewpoint::Inside(t) => return self.render(camera, width, height, pixel_centers, *t),
            Viewpoint::Outside(entry) => entry,
        };
        let pixels = width as u64 * height as u64;
        if width == 0 || height == 0 || pixels > u32::MAX as u64 {
            return Err(GpuError::Camera {
                detail: format!("image size {width}x{height} is empty or too large"),
            });
        }
        let t0 = Instant::now();
        let cam = PinholeCamera::new(camera, width, height, pixel_centers);
        let mut outcomes = vec![TraceOutcome::Miss { tets_visited: 0 }; pixels as usize];
        let (mut rays, mut starts, mut index) = (Vec::new(), Vec::new(), Vec::new());
        for (i, o) in outcomes.iter_mut().enumerate() {
            let ray = cam.ray(i as u32 % width, i as u32 / width);
            match entry.start(self.mesh, &ray) {
                Ok(s) => {
                    rays.push(ray);
                    starts.push(s);
                    index.push(i);
                }
                Err(done) => *o = done,
            }
        }
        let (traced, s) = self.trace_batch(&rays, &starts)?;
        for (i, o) in index.into_iter().zip(traced) {
            outcomes[i] = o;
        }
        // Counted again over every pixel.
        let stats = DispatchStats {
            rays: 0,
            hits: 0,
            failures: 0,
            tets_visited: 0,
            ..s
        };
        Ok(GpuFrame::done(width, height, outcomes, stats, t0, 0))
    }

    fn new_stats(&self) -> DispatchStats {
        DispatchStats {
            method: self.layout.method().into(),
            device: self.ctx.device_name(),
            gpu_ms: self.ctx.timestamps.then_some(0.0),
            ..Default::default()
        }
    }

    fn base_params(&self) -> Params {
        Params {
            step_cap: self.cap,
            point_count: self.mesh.points.len() as u32,
            ..Params::zeroed()
        }
    }
}
