//! The GPU BVH baseline: a binary BVH over a mesh's constrained faces (the
//! scene triangles), built on the CPU by obvhs and traversed by a WGSL
//! kernel (`bvh.wgsl`), so that a benchmark can compare the GPU tet walks
//! with a GPU BVH on the same rays, in the same run, on the same device.
//!
//! * **Build.** obvhs's BVH2 (`build_bvh2_from_tris` with the `slow_build`
//!   preset: PLOC with spatial pre-splits, reinsertion, SAH leaf
//!   collapsing; the preset of the CPU BVH baseline in `tet-bench`), one
//!   primitive per constrained face. Faces of one scene triangle stay
//!   separate primitives that report its id. Scenes far from unit size
//!   are built scaled by a power of two (exact), as the CPU baseline does.
//! * **Layout.** Nodes of 32 bytes (box min, index, box max, count: an
//!   inner node has count 0 and its two children side by side at `index`,
//!   a leaf `count` triangles from `index`), boxes padded outward by
//!   `2⁻²⁰` of their largest coordinate (obvhs rounds the boxes of split
//!   triangles to nearest). Triangles of 48 bytes in leaf order (a vertex,
//!   the two edges from it, the triangle id and the face index), so a leaf
//!   reads them without an index array.
//! * **Traversal.** One invocation per ray, a stack of postponed subtrees:
//!   both children's boxes tested together (slab test, far distance
//!   rounded up as in Ize (2013)), the nearer child visited first, the farther
//!   pushed with its entry distance and skipped when popped behind the
//!   closest hit so far; Möller–Trumbore (1997) ray/triangle tests in f32.
//!   Möller–Trumbore is not watertight: a ray through a shared edge or
//!   vertex can slip between the triangles (the tet walks cannot), so the
//!   two agree except on rays that graze an edge.
//! * **Counts.** [`DispatchStats::tets_visited`] holds the boxes tested,
//!   the root's included (the CPU BVH baseline's "nodes visited").

use std::time::{Duration, Instant};

use bytemuck::{Pod, Zeroable};
use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::builder::build_bvh2_from_tris;
use obvhs::triangle::Triangle;
use tet_core::TetMesh;
use tet_core::scene::Camera;
use tet_trace_cpu::Ray;
use tet_trace_cpu::walk::walk_scale;

use crate::context::GpuContext;
use crate::dispatch::{add_gpu_ms, rays_per_dispatch, run_pass, scope_result, storage_buffer};
use crate::error::GpuError;
use crate::layout::CAMERA;
use crate::records::CameraRec;
use crate::stats::DispatchStats;

/// WGSL of the traversal (appended to `camera.wgsl`).
const BVH: &str = include_str!("bvh.wgsl");
/// Outward padding of every box, relative to its largest coordinate.
const PAD: f32 = 1.0 / (1u32 << 20) as f32;

/// One ray's closest hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhHit {
    /// Scene triangle id ([`tet_core::ConstrainedFace::triangle`]), the id
    /// the tet walks report in [`tet_trace_cpu::Hit::triangle`].
    pub triangle: u32,
    /// Ray parameter of the hit point (in units of the ray's direction).
    pub t: f32,
}

/// A BVH over a mesh's constrained faces (the scene triangles), traversed
/// on the GPU. See the crate docs, "The GPU BVH baseline".
pub struct GpuBvh<'a> {
    ctx: &'a GpuContext,
    pipeline: wgpu::ComputePipeline,
    nodes: wgpu::Buffer,
    tris: wgpu::Buffer,
    /// Bound in place of the batch rays of camera dispatches.
    dummy: wgpu::Buffer,
    /// The power of two the scene was scaled by.
    scale: f32,
    build_ms: f64,
    gpu_bytes: u64,
}

/// A node as the kernel reads it (`Node` in `bvh.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct NodeRec {
    lo: [f32; 3],
    index: u32,
    hi: [f32; 3],
    count: u32,
}
const _: () = assert!(size_of::<NodeRec>() == 32);

/// A leaf triangle (`Tri` in `bvh.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct TriRec {
    v0: [f32; 3],
    triangle: u32,
    e1: [f32; 3],
    face: u32,
    e2: [f32; 3],
    pad: u32,
}
const _: () = assert!(size_of::<TriRec>() == 48);

/// A batch ray (`BatchRay`): origin + `t_min`, direction + `t_max`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct BvhRayRec {
    o: [f32; 4],
    d: [f32; 4],
}

/// One result (`BvhResult`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct BvhResultRec {
    hit: u32,
    triangle: u32,
    t: f32,
    nodes: u32,
}

impl BvhResultRec {
    fn hit(&self) -> Option<BvhHit> {
        (self.hit != 0).then_some(BvhHit {
            triangle: self.triangle,
            t: self.t,
        })
    }
}

/// The uniform parameters (`BvhParams`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct BvhParams {
    ray_count: u32,
    first_ray: u32,
    camera_mode: u32,
    width: u32,
    height: u32,
    scale: f32,
    inv_scale: f32,
    pad: u32,
    camera: CameraRec,
}
const _: () = assert!(size_of::<BvhParams>() == 112);

/// The flattened BVH: nodes, leaf triangles and the stack the deepest path
/// needs.
struct Flat {
    nodes: Vec<NodeRec>,
    tris: Vec<TriRec>,
    stack: u32,
}

impl<'a> GpuBvh<'a> {
    /// Builds the BVH on the CPU over `mesh.constrained` (each face's three
    /// points; a hit reports the face's
    /// [`triangle`](tet_core::ConstrainedFace::triangle), the id the tet
    /// walks report; faces of one triangle are separate primitives) and
    /// uploads it. Fails with [`GpuError::EmptyScene`] without constrained
    /// faces and with [`GpuError::TooLarge`] when the nodes or triangles
    /// exceed a device limit.
    pub fn from_mesh(ctx: &'a GpuContext, mesh: &TetMesh) -> Result<GpuBvh<'a>, GpuError> {
        if mesh.constrained.is_empty() {
            return Err(GpuError::EmptyScene);
        }
        let t0 = Instant::now();
        let scale = build_scale(mesh);
        let source: Vec<Triangle> = mesh
            .constrained
            .iter()
            .map(|cf| {
                let [v0, v1, v2] = cf
                    .vertices
                    .map(|k| Vec3A::from(mesh.points[k as usize] * scale));
                Triangle { v0, v1, v2 }
            })
            .collect();
        let bvh = build_bvh2_from_tris(
            &source,
            BvhBuildParams::slow_build(),
            &mut Duration::default(),
        );
        let flat = flatten(&bvh, &source, mesh)?;
        let build_ms = t0.elapsed().as_secs_f64() * 1e3;
        let node_bytes = size_of_val(flat.nodes.as_slice()) as u64;
        let tri_bytes = size_of_val(flat.tris.as_slice()) as u64;
        ctx.check_size("BVH nodes", node_bytes)?;
        ctx.check_size("BVH triangles", tri_bytes)?;
        let device = &ctx.device;
        let oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let val = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let nodes = storage_buffer(device, "bvh nodes", bytemuck::cast_slice(&flat.nodes));
        let tris = storage_buffer(device, "bvh triangles", bytemuck::cast_slice(&flat.tris));
        let dummy = storage_buffer(device, "dummy", &[0u8; 64]);
        let source = format!("{CAMERA}\nconst STACK_SIZE: u32 = {}u;\n{BVH}", flat.stack);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("gpu-bvh"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("gpu-bvh"),
            layout: None,
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
        scope_result("BVH upload / pipeline creation", val, oom)?;
        Ok(GpuBvh {
            ctx,
            pipeline,
            nodes,
            tris,
            dummy,
            scale,
            build_ms,
            gpu_bytes: node_bytes + tri_bytes,
        })
    }

    /// CPU build time, ms: obvhs's build and the flattening into the GPU
    /// records (the upload and the kernel's compilation excluded; in a
    /// build with debug assertions obvhs also validates its tree).
    pub fn build_ms(&self) -> f64 {
        self.build_ms
    }

    /// Bytes resident on the GPU: the nodes (32 bytes each) and the leaf
    /// triangles (48 bytes per primitive reference, a face split by
    /// obvhs's spatial splits counted once per leaf that holds it); the
    /// triangles carry their ids, so there is no separate index array.
    pub fn gpu_bytes(&self) -> u64 {
        self.gpu_bytes
    }

    /// Closest hit of each ray with `t` in `[t_min, t_max]` (`None` for a
    /// miss and for an invalid ray, see [`Ray::is_valid`]). Stats as the
    /// tet walks' ([`DispatchStats`]): method `"gpu-bvh"`, GPU time from
    /// timestamp queries when available, wall time, dispatches, rays,
    /// hits; `tets_visited` counts the BVH boxes tested (root included).
    /// Large batches are split into several dispatches.
    pub fn trace_batch(
        &self,
        rays: &[Ray],
    ) -> Result<(Vec<Option<BvhHit>>, DispatchStats), GpuError> {
        let mut stats = self.new_stats();
        let t0 = Instant::now();
        let per = rays_per_dispatch(self.ctx, size_of::<BvhRayRec>() as u64)?;
        let mut out = Vec::with_capacity(rays.len());
        for chunk in rays.chunks(per) {
            let recs: Vec<BvhRayRec> = chunk.iter().map(ray_rec).collect();
            let buf = storage_buffer(&self.ctx.device, "bvh rays", bytemuck::cast_slice(&recs));
            let params = BvhParams {
                ray_count: chunk.len() as u32,
                ..self.base_params()
            };
            self.dispatch(&params, &buf, &mut out, &mut stats)?;
        }
        stats.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        Ok((out, stats))
    }

    /// The primary rays of a `width × height` image (row-major from the
    /// top), generated on the GPU by the tet walks' camera code
    /// (`camera.wgsl`, the same f32 camera record as
    /// [`GpuTracer::render`](crate::GpuTracer::render)), so the two trace
    /// bit-identical rays and their kernel times compare like for like.
    /// Fails with [`GpuError::Camera`] on an empty image or a degenerate
    /// camera.
    pub fn render(
        &self,
        camera: &Camera,
        width: u32,
        height: u32,
        pixel_centers: bool,
    ) -> Result<(Vec<Option<BvhHit>>, DispatchStats), GpuError> {
        let camera = CameraRec::new(camera, width, height, pixel_centers)?;
        let pixels = width as u64 * height as u64;
        let mut stats = self.new_stats();
        let t0 = Instant::now();
        let per = rays_per_dispatch(self.ctx, 0)? as u64;
        let mut out = Vec::with_capacity(pixels as usize);
        let mut first = 0u64;
        while first < pixels {
            let n = per.min(pixels - first);
            let params = BvhParams {
                ray_count: n as u32,
                first_ray: first as u32,
                camera_mode: 1,
                width,
                height,
                camera,
                ..self.base_params()
            };
            self.dispatch(&params, &self.dummy, &mut out, &mut stats)?;
            first += n;
        }
        stats.wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        Ok((out, stats))
    }

    /// One dispatch of `params.ray_count` rays: the hits appended to `out`,
    /// the dispatch and its counts added to `stats`.
    fn dispatch(
        &self,
        params: &BvhParams,
        rays: &wgpu::Buffer,
        out: &mut Vec<Option<BvhHit>>,
        stats: &mut DispatchStats,
    ) -> Result<(), GpuError> {
        let (recs, gpu_ms) = run_pass::<BvhResultRec>(
            self.ctx,
            "gpu-bvh",
            &self.pipeline,
            &[(0, &self.nodes), (1, &self.tris), (3, rays)],
            (2, bytemuck::bytes_of(params)),
            4,
            params.ray_count,
        )?;
        add_gpu_ms(stats, gpu_ms);
        stats.rays += recs.len() as u64;
        for r in &recs {
            stats.hits += (r.hit != 0) as u64;
            stats.tets_visited += r.nodes as u64;
        }
        out.extend(recs.iter().map(BvhResultRec::hit));
        Ok(())
    }

    fn new_stats(&self) -> DispatchStats {
        DispatchStats {
            method: "gpu-bvh".into(),
            device: self.ctx.device_name(),
            gpu_ms: self.ctx.timestamps.then_some(0.0),
            ..Default::default()
        }
    }

    fn base_params(&self) -> BvhParams {
        BvhParams {
            scale: self.scale,
            inv_scale: 1.0 / self.scale,
            ..BvhParams::zeroed()
        }
    }
}

/// The kernel's record of `ray`; an invalid ray gets an empty interval
/// (a miss that tests no box).
fn ray_rec(ray: &Ray) -> BvhRayRec {
    if ray.is_valid() {
        BvhRayRec {
            o: ray.origin.extend(ray.t_min).to_array(),
            d: ray.direction.extend(ray.t_max).to_array(),
        }
    } else {
        BvhRayRec {
            o: [0.0, 0.0, 0.0, 1.0],
            d: [1.0, 0.0, 0.0, 0.0],
        }
    }
}

/// A power of two that brings the mesh's largest coordinate near 1 when it
/// lies outside `[2⁻¹⁶, 2¹⁶]` (else 1), as `tet-bench`'s CPU BVH does:
/// obvhs's surface areas, and the kernel's f32 products of edges, over- or
/// underflow for scenes at 1e30 or 1e-30. 1 when scaling would not be
/// exact (a coordinate in the subnormals).
fn build_scale(mesh: &TetMesh) -> f32 {
    let m = mesh
        .points
        .iter()
        .map(|p| p.abs().max_element())
        .fold(0.0f32, f32::max);
    let s = walk_scale(m as f64);
    let exact = s == 1.0 || mesh.points.iter().all(|&p| (p * s) / s == p);
    if exact { s } else { 1.0 }
}

/// obvhs's BVH as the kernel's records: nodes with padded boxes, the leaf
/// triangles of `source` (the scaled faces) in leaf order with their ids,
/// and the largest number of inner nodes on a root-to-leaf path (the
/// traversal stack pushes at most one entry per inner node).
fn flatten(bvh: &Bvh2, source: &[Triangle], mesh: &TetMesh) -> Result<Flat, GpuError> {
    let too_many = |what, count| GpuError::TooMany {
        what,
        count,
        limit: u32::MAX as usize,
    };
    if bvh.nodes.len() >= u32::MAX as usize {
        return Err(too_many("BVH nodes", bvh.nodes.len()));
    }
    if bvh.primitive_indices.len() >= u32::MAX as usize {
        return Err(too_many("BVH primitives", bvh.primitive_indices.len()));
    }
    let nodes = bvh
        .nodes
        .iter()
        .map(|n| {
            let (lo, hi) = (Vec3::from(n.aabb().min), Vec3::from(n.aabb().max));
            let m = lo.abs().max(hi.abs()).max(hi - lo).max_element();
            let e = Vec3::splat(m * PAD);
            NodeRec {
                lo: (lo - e).to_array(),
                index: n.first_index,
                hi: (hi + e).to_array(),
                count: n.prim_count,
            }
        })
        .collect();
    let tris = bvh
        .primitive_indices
        .iter()
        .map(|&f| {
            let t = &source[f as usize];
            TriRec {
                v0: Vec3::from(t.v0).to_array(),
                triangle: mesh.constrained[f as usize].triangle,
                e1: Vec3::from(t.v1 - t.v0).to_array(),
                face: f,
                e2: Vec3::from(t.v2 - t.v0).to_array(),
                pad: 0,
            }
        })
        .collect();
    // Inner nodes on the deepest path (iteratively: a degenerate tree may
    // be as deep as it has primitives).
    let mut stack = 0u32;
    let mut todo = vec![(0usize, 0u32)];
    while let Some((i, inner)) = todo.pop() {
        let n = &bvh.nodes[i];
        if n.is_leaf() {
            stack = stack.max(inner);
        } else {
            let c = n.first_index as usize;
            todo.push((c, inner + 1));
            todo.push((c + 1, inner + 1));
        }
    }
    Ok(Flat {
        nodes,
        tris,
        stack: stack.max(1),
    })
}
