//! The `gpu.json` document (schema `tet-gpu-bench`, version 1; fields in
//! docs/json.md): plain data, filled by the measurement and read by the
//! Markdown writer.

use serde::Serialize;

use super::scenes::MeshDoc;

/// The schema name of `gpu.json`.
pub const SCHEMA: &str = "tet-gpu-bench";
/// Its version: fields are only ever added within one version.
pub const VERSION: u32 = 1;

/// `gpu.json`.
#[derive(Debug, Serialize)]
pub struct GpuBenchDoc {
    /// [`SCHEMA`].
    pub schema: &'static str,
    /// [`VERSION`].
    pub version: u32,
    /// The adapter every row ran on.
    pub adapter: AdapterDoc,
    /// Image size, repetitions, where the meshes came from.
    pub setup: SetupDoc,
    /// One per scene of the run, measured or skipped.
    pub scenes: Vec<SceneDoc>,
    /// Aman et al. (2022) Table 3: the GPU walks on the camera rays.
    pub table3: Vec<Row>,
    /// The GPU BVH on the same camera rays.
    pub bvh: Vec<Row>,
    /// Secondary rays (shadow, one diffuse bounce) given by the CPU.
    pub secondary: Vec<Row>,
    /// Why `bvh` is empty, `null` when it is not.
    pub bvh_note: Option<String>,
    /// Seconds of the whole run.
    pub total_s: f64,
}

/// The adapter (JSON `adapter`).
#[derive(Clone, Debug, Serialize)]
pub struct AdapterDoc {
    /// Its name (`NVIDIA H200`, `llvmpipe (LLVM 15.0.6, 256 bits)`).
    pub name: String,
    /// The wgpu backend (`Vulkan`).
    pub backend: String,
    /// `DiscreteGpu`, `IntegratedGpu`, `VirtualGpu`, `Cpu` or `Other`.
    pub device_type: String,
    /// The driver's name and version as the adapter reports them.
    pub driver: String,
    /// True for a software adapter (`device_type` `Cpu`): its times are
    /// not GPU times.
    pub software: bool,
    /// Whether the kernels are timed with timestamp queries (else every
    /// row's `timing` is `wall`).
    pub timestamps: bool,
}

/// How the run measured (JSON `setup`).
#[derive(Clone, Debug, Serialize)]
pub struct SetupDoc {
    /// `--quick`.
    pub quick: bool,
    /// Image width of the camera rays.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Timed dispatches per method (after one warm-up); the best is reported.
    pub frames: u32,
    /// Timed passes over each batch of secondary rays (after one warm-up).
    pub secondary_repeats: u32,
    /// `--meshes`, `null` when not given.
    pub meshes_dir: Option<String>,
    /// The enclosing box of the meshes built here: `wide` (holds the
    /// camera and lights, the papers' layout) or `tight`.
    pub enclosing_box: &'static str,
    /// CPU threads of the CPU walks.
    pub cpu_threads: usize,
}

/// One scene (JSON `scenes[]`).
#[derive(Clone, Debug, Serialize)]
pub struct SceneDoc {
    /// Name in the rows (the paper's, where it has the scene).
    pub scene: String,
    /// The spec it was loaded from.
    pub spec: String,
    /// Its mesh, `null` when skipped.
    pub mesh: Option<MeshDoc>,
    /// Whether the camera lies inside the mesh (primary rays made and
    /// started on the GPU) or outside (made on the host, each entering
    /// through the boundary face it crosses); `null` when skipped.
    pub camera_inside: Option<bool>,
    /// Why the scene has no rows (mesh file missing and not buildable,
    /// scene files missing, a GPU error), `null` when measured.
    pub skipped: Option<String>,
    /// Seconds the scene took, its mesh's loading or building and the CPU
    /// walks included.
    pub total_s: f64,
}

/// One measured method on one batch of rays (JSON `table3[]`, `bvh[]`,
/// `secondary[]`).
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// Scene name.
    pub scene: String,
    /// `gpu-tet20`, `gpu-tet16`, `gpu-tet32`, `gpu-tet80` or `gpu-bvh`.
    pub method: String,
    /// `primary` (camera rays), `shadow` or `bounce`.
    pub kind: &'static str,
    /// Rays per dispatch.
    pub rays: u64,
    /// Kernel time of the fastest timed dispatch, ms (all the kernel
    /// dispatches of one frame or batch together).
    pub kernel_ms: f64,
    /// Median kernel time, ms.
    pub median_ms: f64,
    /// `rays` over `kernel_ms`, millions per second.
    pub mrays_per_s: f64,
    /// The same in billions per second (Grays/s).
    pub grays_per_s: f64,
    /// `timestamp` (GPU timestamp queries around the dispatches) or
    /// `wall` (no timestamp queries: submit to results on the host).
    pub timing: &'static str,
    /// Timed dispatches (frames or batches) the best is taken of.
    pub dispatches: u32,
    /// Wall time of the fastest dispatch on the host, ms: the kernel, the
    /// upload of per-ray data, the read-back and the host's share (ray
    /// starts).
    pub wall_ms: f64,
    /// `wall_ms − kernel_ms`: upload, download and host work outside the
    /// kernel, ms (0 with `wall` timing).
    pub outside_kernel_ms: f64,
    /// Rays whose GPU walk lost its way and that the host walked again
    /// exactly (not in `kernel_ms`).
    pub host_rewalks: u64,
    /// Rays that hit a scene triangle.
    pub hits: u64,
    /// Hits of the CPU walk on the same rays (`reference` names it).
    pub cpu_hits: u64,
    /// The CPU walk compared with: the same layout's (`tet20` for the BVH).
    pub reference: String,
    /// Rays whose outcome differs from the CPU walk's, with why.
    pub differences: Differences,
    /// Rays whose walk failed (step cap, lost, invalid ray).
    pub failures: u64,
    /// Tets visited per ray (`null` for the BVH).
    pub tets_per_ray: Option<f64>,
    /// BVH boxes tested per ray, the root's included (`null` for the walks).
    pub nodes_per_ray: Option<f64>,
    /// Bytes on the GPU of the structure traced.
    pub gpu_bytes: GpuBytes,
    /// Milliseconds to encode and upload the layout, or to build the BVH.
    pub setup_ms: f64,
    /// Aman et al. (2022) Table 3's kernel ms for this scene and layout
    /// (GTX 1060, their meshes), `null` where the paper has none.
    pub paper_ms: Option<f64>,
    /// `kernel_ms ÷ paper_ms` (below 1: faster than the paper's figure).
    pub ratio_to_paper: Option<f64>,
}

/// Bytes on the GPU (JSON `gpu_bytes`).
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct GpuBytes {
    /// Tet records (0 for the BVH).
    pub tets: u64,
    /// Points (0 for the BVH).
    pub points: u64,
    /// Constrained-face records (0 for the BVH).
    pub constrained: u64,
    /// The BVH's nodes and triangles (0 for the walks).
    pub bvh: u64,
    /// All of them.
    pub total: u64,
}

/// Rays whose outcome differs from the CPU walk's (JSON `differences`):
/// another triangle, or a hit against a miss. Each falls in one class.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Differences {
    /// All of them.
    pub rays: u64,
    /// A hit on either side lies near an edge of its triangle (within
    /// 10⁻⁵ of the ray's scale): a ray grazing an edge, which the GPU may
    /// decide the other way (its camera rays may differ from the CPU's in
    /// the last bit; drivers may fuse the projection's sums).
    pub near_edge: u64,
    /// The walk failed on one side only.
    pub failed: u64,
    /// Neither: a difference this run cannot explain.
    pub unexplained: u64,
    /// Up to five of them, the unexplained first.
    pub examples: Vec<Example>,
}

/// One differing ray (JSON `differences.examples[]`).
#[derive(Clone, Debug, Serialize)]
pub struct Example {
    /// The ray's index (a camera ray's: `y · width + x`).
    pub ray: usize,
    /// The class: `near-edge`, `failed` or `unexplained`.
    pub class: &'static str,
    /// What the GPU found.
    pub gpu: Seen,
    /// What the CPU walk found.
    pub cpu: Seen,
}

/// What a ray found (JSON `gpu`, `cpu` of an example).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "outcome", rename_all = "kebab-case")]
pub enum Seen {
    /// A scene triangle at ray parameter `t`.
    Hit {
        /// Scene triangle id.
        triangle: u32,
        /// Ray parameter.
        t: f32,
    },
    /// Nothing (or nothing before the ray's `t_max`).
    Miss,
    /// The walk failed.
    Failed,
}
