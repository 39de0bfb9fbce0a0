//! The tracer: mesh upload, batch tracing, camera rendering and
//! per-dispatch statistics, for every [`GpuLayout`]. See the crate docs for
//! the decisions ported from the CPU kernels and where results may differ.

use std::sync::mpsc;
use std::time::Instant;

use bytemuck::{Pod, Zeroable};
use glam::{DVec3, Vec3};
use tet_core::scene::Camera;
use tet_core::{FACE_VERTICES, Link, NO_TET, TetMesh};
use tet_trace_cpu::render::PinholeCamera;
use tet_trace_cpu::walk::{duff_basis, start_exit_face, step_cap};
use tet_trace_cpu::{DuffF32, Failure, Hit, Ray, Start, TraceOutcome, Viewpoint};
use wgpu::util::DeviceExt;

use crate::layout::Split;
use crate::{GpuContext, GpuError, GpuLayout};

/// Invocations per workgroup (must equal `@workgroup_size` in the shader).
const WORKGROUP: u32 = 64;
/// Largest number of rays per dispatch (bounds host staging memory).
const MAX_RAYS_PER_DISPATCH: u64 = 1 << 22;

// Outcome codes and start modes shared with the shader.
const ST_HIT: u32 = 0;
const ST_MISS: u32 = 1;
const ST_STEP_CAP: u32 = 2;
const ST_INVALID: u32 = 3;
const ST_LOST: u32 = 4;
const START_EXIT: u32 = 0;
const START_ENTER: u32 = 1;
const START_DONE: u32 = 2;

/// Uniform parameters (layout of the shader's `Params`, 144 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct Params {
    ray_count: u32,
    first_ray: u32,
    step_cap: u32,
    camera_mode: u32,
    width: u32,
    height: u32,
    point_count: u32,
    cam_tet: u32,
    cam_ids: [u32; 4],
    cam_links: [u32; 4],
    eye: [f32; 4],
    forward: [f32; 4],
    right: [f32; 4],
    up: [f32; 4],
    lens: [f32; 4],
}
const _: () = assert!(size_of::<Params>() == 144);

/// One batch ray: origin + `t_min`, direction + `t_max`, projection basis.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct RayRec {
    o: [f32; 4],
    d: [f32; 4],
    u: [f32; 4],
    v: [f32; 4],
}

/// Where a batch ray's walk starts (computed on the host, see crate docs).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct StartRec {
    mode: u32,
    ids: [u32; 3],
    tet: u32,
    link: u32,
    visited: u32,
    next: u32,
}

/// One result record as written by the shader (40 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct HitRec {
    status: u32,
    triangle: u32,
    face: u32,
    t: f32,
    bary: [f32; 3],
    tet: u32,
    far_tet: u32,
    visited: u32,
}
const _: () = assert!(size_of::<HitRec>() == 40);

impl HitRec {
    fn outcome(&self) -> TraceOutcome {
        let failed = |failure| TraceOutcome::Failed {
            failure,
            tets_visited: self.visited,
        };
        match self.status {
            ST_HIT => TraceOutcome::Hit(Hit {
                triangle: self.triangle,
                face: self.face,
                t: self.t,
                barycentrics: self.bary,
                tet: self.tet,
                far_tet: self.far_tet,
                tets_visited: self.visited,
            }),
            ST_MISS => TraceOutcome::Miss {
                tets_visited: self.visited,
            },
            ST_STEP_CAP => failed(Failure::StepCap),
            ST_INVALID => failed(Failure::InvalidRay),
            _ => failed(Failure::Lost),
        }
    }
}

/// Bytes of the mesh arrays resident on the GPU.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GpuMemory {
    /// Layout name.
    pub layout: &'static str,
    /// Tet records (20 bytes each for Tet20).
    pub tets: u64,
    /// Points (12 bytes each).
    pub points: u64,
    /// Constrained-face records (24 bytes each).
    pub constrained: u64,
}

impl GpuMemory {
    /// Sum of all arrays.
    pub fn total(&self) -> u64 {
        self.tets + self.points + self.constrained
    }
}

/// Statistics of one batch or frame, with the fields of the CPU renderer's
/// `FrameStats` (so `tet-bench` can report GPU methods the same way).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DispatchStats {
    /// Method name (`"gpu-tet20"`, ...).
    pub method: String,
    /// Adapter, from [`GpuContext::device_name`].
    pub device: String,
    /// Summed GPU time of the kernel dispatches (timestamp queries), ms;
    /// `None` when the adapter has no timestamp queries.
    pub gpu_ms: Option<f64>,
    /// Wall time from the first submit to the last result on the host
    /// (includes uploads of per-ray data and read-back), ms.
    pub wall_ms: f64,
    /// Number of dispatches.
    pub dispatches: u32,
    /// Rays traced.
    pub rays: u64,
    /// Rays that hit a constrained face.
    pub hits: u64,
    /// Rays that failed (step cap, lost, invalid).
    pub failures: u64,
    /// Tets visited by all rays.
    pub tets_visited: u64,
}

impl DispatchStats {
    /// The time to report: GPU time when measured, wall time otherwise (ms).
    pub fn ms(&self) -> f64 {
        self.gpu_ms.unwrap_or(self.wall_ms)
    }

    /// Million rays per second over [`DispatchStats::ms`].
    pub fn mrays_per_s(&self) -> f64 {
        self.rays as f64 / (self.ms() * 1e3)
    }

    fn count(&mut self, outcomes: &[TraceOutcome]) {
        self.rays += outcomes.len() as u64;
        for o in outcomes {
            self.hits += o.hit().is_some() as u64;
            self.failures += o.is_failure() as u64;
            self.tets_visited += o.tets_visited() as u64;
        }
    }
}

/// A camera frame traced on the GPU.
#[derive(Clone, Debug, PartialEq)]
pub struct GpuFrame {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Outcome per pixel, row-major from the top.
    pub outcomes: Vec<TraceOutcome>,
    /// Statistics of the whole frame (re-traced rays included).
    pub stats: DispatchStats,
    /// Rays whose origin lay on the start tet's boundary so that the GPU
    /// start failed; they were re-traced through [`GpuTracer::trace_batch`].
    pub retraced: u64,
}

impl GpuFrame {
    /// The frame of `outcomes`, with the wall time since `t0` and the
    /// outcomes counted into `stats`.
    fn done(
        width: u32,
        height: u32,
        outcomes: Vec<TraceOutcome>,
        mut stats: DispatchStats,
        t0: Instant,
        retraced: u64,
    ) -> GpuFrame {
        stats.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        stats.count(&outcomes);
        GpuFrame {
            width,
            height,
            outcomes,
            stats,
            retraced,
        }
    }

    /// Hit triangle per pixel (`u32::MAX` for none), as in the CPU `Frame`.
    pub fn triangles(&self) -> Vec<u32> {
        self.outcomes
            .iter()
            .map(|o| o.hit().map_or(u32::MAX, |h| h.triangle))
            .collect()
    }
}

/// A mesh uploaded in one compact layout, with its compiled kernel.
pub struct GpuTracer<'a> {
    ctx: &'a GpuContext,
    layout: GpuLayout,
    mesh: &'a TetMesh,
    pipeline: wgpu::ComputePipeline,
    points: wgpu::Buffer,
    /// Tet records, one buffer per binding (see `Split`).
    tets: Vec<wgpu::Buffer>,
    faces: wgpu::Buffer,
    dummy: wgpu::Buffer,
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
        let storage = |label: &str, data: &[u8]| {
            // Zero-sized bindings are invalid: pad empty arrays.
            let pad = [0u8; 32];
            let contents = if data.is_empty() { &pad[..] } else { data };
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::STORAGE,
            })
        };
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
        Ok(GpuTracer {
            ctx,
            layout,
            mesh,
            pipeline,
            points: points_buf,
            tets: tets_bufs,
            faces: faces_buf,
            dummy,
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
        self.tets.len()
    }

    /// Bytes of the mesh on the GPU.
    pub fn memory(&self) -> GpuMemory {
        self.memory
    }

    /// The mesh (cold data: attributes, constrained-face table).
    pub fn mesh(&self) -> &TetMesh {
        self.mesh
    }

    /// Host-side start of one batch ray: the CPU walk's exact start logic.
    fn start_record(&self, ray: &Ray, start: Start) -> StartRec {
        let done = |status| StartRec {
            mode: START_DONE,
            ids: [0; 3],
            tet: NO_TET,
            link: status,
            visited: 0,
            next: 0,
        };
        if !ray.is_valid() {
            return done(ST_INVALID);
        }
        let mesh = self.mesh;
        if self.layout == GpuLayout::Tet80 {
            return self.start_record_tet80(ray, start);
        }
        match start {
            Start::Tet(t) => {
                if t as usize >= mesh.tets.len() {
                    return done(ST_LOST);
                }
                match start_exit_face::<DuffF32>(mesh, ray, t) {
                    Some((tet, k)) => StartRec {
                        mode: START_EXIT,
                        ids: mesh.face_vertices(tet, k),
                        tet,
                        link: mesh.neighbors[tet as usize][k].0,
                        visited: 1,
                        next: 0,
                    },
                    None => done(ST_LOST),
                }
            }
            Start::Face { face, tet } => {
                let side = mesh
                    .constrained
                    .get(face as usize)
                    .and_then(|cf| cf.side_of(tet))
                    .filter(|_| (tet as usize) < mesh.tets.len());
                let Some(side) = side else {
                    return done(ST_LOST);
                };
                let v = mesh.tets[tet as usize];
                let [a, b, c] = FACE_VERTICES[(side.face & 3) as usize];
                StartRec {
                    mode: START_ENTER,
                    ids: [v[a], v[c], v[b]],
                    tet: NO_TET,
                    link: Link::constrained(face).0,
                    visited: 0,
                    next: tet,
                }
            }
            Start::Entry { tet, face } => {
                if !mesh.is_boundary_face(tet, face) {
                    return done(ST_LOST);
                }
                let v = mesh.tets[tet as usize];
                let [a, b, c] = FACE_VERTICES[(face & 3) as usize];
                StartRec {
                    mode: START_ENTER,
                    ids: [v[a], v[c], v[b]],
                    tet: NO_TET,
                    link: Link::BOUNDARY.0,
                    visited: 0,
                    next: tet,
                }
            }
        }
    }

    /// Start of a Tet80 walk, as `Tet80Tracer::trace` (Maria et al.'s
    /// Algorithm 2 from an interior origin, the triple-product search from an
    /// origin on a face, edge or vertex, then `leave` through the exit face;
    /// or entering through a face).
    fn start_record_tet80(&self, ray: &Ray, start: Start) -> StartRec {
        let mesh = self.mesh;
        let rec = |mode, tet, face, visited| StartRec {
            mode,
            ids: [face, 0, 0],
            tet,
            link: 0,
            visited,
            next: 0,
        };
        let done = |status, visited| StartRec {
            link: status,
            ..rec(START_DONE, NO_TET, 0, visited)
        };
        match start {
            Start::Tet(t) if (t as usize) < mesh.tets.len() => {
                match tet_trace_cpu::tet80::start_exit(mesh, ray, t) {
                    Some((t, k)) => rec(START_EXIT, t, k as u32, 1),
                    None => done(ST_LOST, 1),
                }
            }
            Start::Tet(_) => done(ST_LOST, 0),
            Start::Face { face, tet } => {
                match mesh
                    .constrained
                    .get(face as usize)
                    .and_then(|cf| cf.side_of(tet))
                    .filter(|_| (tet as usize) < mesh.tets.len())
                {
                    Some(s) => rec(START_ENTER, tet, s.face & 3, 0),
                    None => done(ST_LOST, 0),
                }
            }
            Start::Entry { tet, face } if mesh.is_boundary_face(tet, face) => {
                rec(START_ENTER, tet, face as u32, 0)
            }
            Start::Entry { .. } => done(ST_LOST, 0),
        }
    }

    /// Traces arbitrary rays, ray `i` from `starts[i]` (a tet containing its
    /// origin, or a constrained face for secondary rays), like the CPU
    /// `Tracer::trace`. Large batches are split into several dispatches.
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
        let per = self.rays_per_dispatch(size_of::<RayRec>() as u64)?;
        let mut out = Vec::with_capacity(rays.len());
        for (rc, sc) in rays.chunks(per).zip(starts.chunks(per)) {
            let recs: Vec<RayRec> = rc
                .iter()
                .map(|r| {
                    let (u, v) = if r.is_valid() {
                        duff_basis(r.direction.as_dvec3().normalize())
                    } else {
                        (DVec3::X, DVec3::Y)
                    };
                    let (u, v) = (u.as_vec3(), v.as_vec3());
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
                .map(|(r, &s)| self.start_record(r, s))
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
            let (hits, gpu_ms) = self.dispatch(&params, &rays_buf, &starts_buf)?;
            add_gpu_ms(&mut stats, gpu_ms);
            out.extend(hits.iter().map(HitRec::outcome));
        }
        stats.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        stats.count(&out);
        Ok((out, stats))
    }

    /// Traces the primary rays of a `width × height` image, generated on the
    /// GPU with the conventions of `scenes.json` (see
    /// `tet_trace_cpu::render::PinholeCamera`), all starting in `start_tet`
    /// (a tet containing the eye, e.g. from `tet_trace_cpu::locate`).
    pub fn render(
        &self,
        camera: &Camera,
        width: u32,
        height: u32,
        pixel_centers: bool,
        start_tet: u32,
    ) -> Result<GpuFrame, GpuError> {
        let mesh = self.mesh;
        let pixels = width as u64 * height as u64;
        if width == 0 || height == 0 || pixels > u32::MAX as u64 {
            return Err(GpuError::Camera {
                detail: format!("image size {width}x{height} is empty or too large"),
            });
        }
        if start_tet as usize >= mesh.tets.len() {
            return Err(GpuError::Camera {
                detail: format!(
                    "start tet {start_tet} is out of bounds ({} tets)",
                    mesh.tets.len()
                ),
            });
        }
        let forward = (camera.target - camera.position).normalize();
        let right = -camera.up.cross(forward).normalize();
        let up = -forward.cross(right);
        if !(camera.position.is_finite() && forward.is_finite() && right.is_finite()) {
            return Err(GpuError::Camera {
                detail: format!("degenerate camera {camera:?}"),
            });
        }
        let half_h = (camera.vfov_deg.to_radians() * 0.5).tan();
        let aspect = width as f32 / height as f32;
        let offset = if pixel_centers { 0.5 } else { 0.0 };
        let v4 = |v: Vec3| v.extend(0.0).to_array();
        let base = Params {
            camera_mode: 1,
            width,
            height,
            cam_tet: start_tet,
            cam_ids: mesh.tets[start_tet as usize],
            cam_links: mesh.neighbors[start_tet as usize].map(|l| l.0),
            eye: v4(camera.position),
            forward: v4(forward),
            right: v4(right),
            up: v4(up),
            lens: [half_h, aspect, offset, 0.0],
            ..self.base_params()
        };
        let mut stats = self.new_stats();
        let t0 = Instant::now();
        let per = self.rays_per_dispatch(0)? as u64;
        let mut outcomes = Vec::with_capacity(pixels as usize);
        let mut first = 0u64;
        while first < pixels {
            let n = per.min(pixels - first);
            let params = Params {
                ray_count: n as u32,
                first_ray: first as u32,
                ..base
            };
            let (hits, gpu_ms) = self.dispatch(&params, &self.dummy, &self.dummy)?;
            add_gpu_ms(&mut stats, gpu_ms);
            outcomes.extend(hits.iter().map(HitRec::outcome));
            first += n;
        }
        // Rays the GPU could not start (origin on the start tet's boundary):
        // re-trace them with the CPU's full start logic.
        let lost: Vec<usize> = outcomes
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
        if !lost.is_empty() {
            let cam = PinholeCamera::new(camera, width, height, pixel_centers);
            let rays: Vec<Ray> = lost
                .iter()
                .map(|&i| cam.ray(i as u32 % width, i as u32 / width))
                .collect();
            let starts = vec![Start::Tet(start_tet); rays.len()];
            let (re, s) = self.trace_batch(&rays, &starts)?;
            stats.dispatches += s.dispatches;
            if let (Some(a), Some(b)) = (stats.gpu_ms, s.gpu_ms) {
                stats.gpu_ms = Some(a + b);
            }
            for (&i, o) in lost.iter().zip(re) {
                outcomes[i] = o;
            }
        }
        Ok(GpuFrame::done(
            width,
            height,
            outcomes,
            stats,
            t0,
            lost.len() as u64,
        ))
    }

    /// [`GpuTracer::render`] from a located viewpoint: the GPU's own camera
    /// rays when the camera is inside the mesh; from outside, the rays are
    /// made on the host, each starts through the boundary face it enters by
    /// (`tet_trace_cpu::entry`, host side, like the starts of
    /// [`GpuTracer::trace_batch`]) and a ray that misses the mesh is a miss
    /// that visits no tet.
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

    /// Rays per dispatch so that every per-ray buffer fits the limits.
    fn rays_per_dispatch(&self, input_bytes: u64) -> Result<usize, GpuError> {
        let per_ray = (size_of::<HitRec>() as u64).max(input_bytes);
        let lim = self.ctx.max_binding_bytes() / per_ray;
        let wg = self.ctx.max_workgroups as u64;
        let n = lim
            .min(MAX_RAYS_PER_DISPATCH)
            .min(wg * wg * WORKGROUP as u64);
        if n == 0 {
            return Err(GpuError::TooLarge {
                buffer: "per-ray records",
                bytes: per_ray,
                limit: "max_storage_buffer_binding_size",
                value: self.ctx.max_binding_bytes(),
            });
        }
        Ok(n as usize)
    }

    /// One dispatch of `params.ray_count` rays; returns the records and the
    /// GPU time when timestamps are enabled.
    fn dispatch(
        &self,
        params: &Params,
        rays: &wgpu::Buffer,
        starts: &wgpu::Buffer,
    ) -> Result<(Vec<HitRec>, Option<f64>), GpuError> {
        let n = params.ray_count;
        if n == 0 {
            return Ok((Vec::new(), None));
        }
        let device = &self.ctx.device;
        let oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let val = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let out_bytes = n as u64 * size_of::<HitRec>() as u64;
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("params"),
            contents: bytemuck::bytes_of(params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let out = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("hits"),
            size: out_bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("hits readback"),
            size: out_bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut entries = vec![
            entry(0, &self.points),
            entry(2, &self.faces),
            entry(3, &uniform),
            entry(4, rays),
            entry(5, starts),
            entry(6, &out),
        ];
        for (j, b) in self.tets.iter().enumerate() {
            entries.push(entry(Split::binding(j as u32), b));
        }
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("walk"),
            layout: &self.pipeline.get_bind_group_layout(0),
            entries: &entries,
        });
        let timing = self.ctx.timestamps.then(|| {
            let set = device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("walk timestamps"),
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
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("walk"),
        });
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("walk"),
                timestamp_writes: timing.as_ref().map(|(set, _, _)| {
                    wgpu::ComputePassTimestampWrites {
                        query_set: set,
                        beginning_of_pass_write_index: Some(0),
                        end_of_pass_write_index: Some(1),
                    }
                }),
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind, &[]);
            let groups = n.div_ceil(WORKGROUP);
            let x = groups.min(self.ctx.max_workgroups);
            pass.dispatch_workgroups(x, groups.div_ceil(x), 1);
        }
        enc.copy_buffer_to_buffer(&out, 0, &readback, 0, out_bytes);
        if let Some((set, resolve, read)) = &timing {
            enc.resolve_query_set(set, 0..2, resolve, 0);
            enc.copy_buffer_to_buffer(resolve, 0, read, 0, 16);
        }
        self.ctx.queue.submit([enc.finish()]);
        let hits: Vec<HitRec> = read_buffer(device, &readback)?;
        let gpu_ms = match &timing {
            Some((_, _, read)) => {
                let ts: Vec<u64> = read_buffer(device, read)?;
                let ticks = ts[1].saturating_sub(ts[0]);
                Some(ticks as f64 * self.ctx.queue.get_timestamp_period() as f64 / 1e6)
            }
            None => None,
        };
        scope_result("dispatch", val, oom)?;
        Ok((hits, gpu_ms))
    }
}

fn add_gpu_ms(stats: &mut DispatchStats, gpu_ms: Option<f64>) {
    stats.dispatches += 1;
    if let (Some(a), Some(b)) = (stats.gpu_ms, gpu_ms) {
        stats.gpu_ms = Some(a + b);
    }
}

fn entry(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: buffer.as_entire_binding(),
    }
}

/// Pops the two error scopes pushed by the caller (validation innermost).
fn scope_result(
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hit_records_map_to_cpu_outcomes() {
        let rec = |status| HitRec {
            status,
            triangle: 7,
            face: 3,
            t: 2.5,
            bary: [0.25, 0.25, 0.5],
            tet: 11,
            far_tet: NO_TET,
            visited: 9,
        };
        match rec(ST_HIT).outcome() {
            TraceOutcome::Hit(h) => {
                assert_eq!((h.triangle, h.face, h.tet, h.tets_visited), (7, 3, 11, 9));
                assert_eq!((h.t, h.barycentrics), (2.5, [0.25, 0.25, 0.5]));
                assert!(!h.has_far_side());
            }
            o => panic!("{o:?}"),
        }
        assert_eq!(
            rec(ST_MISS).outcome(),
            TraceOutcome::Miss { tets_visited: 9 }
        );
        for (st, f) in [
            (ST_STEP_CAP, Failure::StepCap),
            (ST_INVALID, Failure::InvalidRay),
            (ST_LOST, Failure::Lost),
            (99, Failure::Lost),
        ] {
            assert_eq!(
                rec(st).outcome(),
                TraceOutcome::Failed {
                    failure: f,
                    tets_visited: 9
                }
            );
        }
    }
}
