//! The command-line interface (a scripted interface: see the README for the
//! `--json` schema; do not change it silently).

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};

/// Ray tracing through constrained Delaunay tetrahedralizations: build,
/// inspect, render, measure accuracy and reproduce the papers' tables.
#[derive(Debug, Parser)]
#[command(name = "tet-bench", version, about, long_about = None)]
pub struct Cli {
    /// Print one JSON document on stdout and nothing else there.
    #[arg(long, global = true)]
    pub json: bool,
    /// The subcommand.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Build a tetrahedral mesh from a scene and write it to a mesh file.
    Build(BuildArgs),
    /// Counts and exact bytes per layout of a scene or mesh file.
    Info(InfoArgs),
    /// Render a scene with one traversal method and report timings.
    Render(RenderArgs),
    /// Compare every method against an f64 brute-force reference.
    Accuracy(AccuracyArgs),
    /// Run the whole reproduction and write Markdown, CSV and JSON tables.
    Tables(TablesArgs),
    /// Internal: serve one TetGen request on stdin/stdout (isolated builds).
    #[command(hide = true)]
    TetgenWorker,
}

/// How to build a mesh from a scene.
#[derive(Debug, Clone, Copy, Args)]
pub struct BuildFlags {
    /// TetGen quality bound (radius-edge ratio, `-q`); off by default (`-pY` only).
    #[arg(long)]
    pub quality: Option<f64>,
    /// Cap on Steiner points (`-S`).
    #[arg(long)]
    pub max_steiner: Option<u64>,
    /// Time limit for TetGen in seconds (the build runs in a worker process).
    #[arg(long, default_value_t = 600.0)]
    pub time_limit: f64,
    /// Do not add the enclosing box around the scene.
    #[arg(long)]
    pub no_box: bool,
    /// Make the enclosing box hold the camera and lights too (10 % margin),
    /// so that primary rays start in the camera's tet; by default it is
    /// tight around the scene (0.2 % margin) and rays from a camera outside
    /// enter through the mesh boundary.
    #[arg(long, conflicts_with = "no_box")]
    pub wide_box: bool,
    /// Skip Hilbert reordering of points and tets.
    #[arg(long)]
    pub no_sort: bool,
}

/// `build` arguments.
#[derive(Debug, Args)]
pub struct BuildArgs {
    /// Scene: a procedural name (`torus-knots`, …), an OBJ path, or `FILE.json#Name`.
    pub scene: String,
    /// Output mesh file (required unless `--predict-memory`).
    #[arg(short, long, required_unless_present = "predict_memory")]
    pub output: Option<PathBuf>,
    /// Print TetGen's predicted peak memory for this scene (the memory
    /// model of issue 8) and exit without building.
    #[arg(long)]
    pub predict_memory: bool,
    /// Keep every TetGen run's predicted peak under this size (bytes, or
    /// with a unit K, M, G: powers of 1024, e.g. 512M): over it, the scene
    /// is split into parts with exact seams, built by parallel workers and
    /// merged.
    #[arg(long, value_name = "BYTES", value_parser = crate::outofcore::parse_memory_limit)]
    pub memory_limit: Option<u64>,
    /// With `--memory-limit`: at most this many TetGen workers at once
    /// (default: all cores); their predictions together stay under the limit.
    #[arg(long, requires = "memory_limit")]
    pub threads: Option<usize>,
    /// With `--memory-limit`: how to split (default: the paper's recursive
    /// tree, parallel slabs when no tree fits).
    #[arg(long, value_enum, default_value_t, requires = "memory_limit")]
    pub planner: crate::outofcore::Planner,
    /// With `--memory-limit`: how to merge the parts. `stream` (default)
    /// writes each part to a part file as it finishes and merges the files
    /// into the output a part at a time, each part Hilbert-sorted on its
    /// own; `memory` merges the whole mesh in memory and sorts it as a whole.
    #[arg(long, value_enum, default_value_t, requires = "memory_limit")]
    pub merge: crate::outofcore::MergeMode,
    /// After writing, trace the written mesh with tet20 (640×480, best of 3
    /// frames, all cores) and report its speed (`tet20` in `--json`).
    #[arg(long)]
    pub tet20: bool,
    /// Build options.
    #[command(flatten)]
    pub build: BuildFlags,
}

/// `info` arguments.
#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Scene (built on the fly) or mesh file (`.tmesh`).
    pub scene: String,
    /// Also report the bytes left after pruning the regions that neither the
    /// camera nor a light is in (no ray can reach them).
    #[arg(long)]
    pub prune: bool,
    /// Build options (ignored for mesh files).
    #[command(flatten)]
    pub build: BuildFlags,
}

/// Traversal methods.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, ValueEnum, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Lagae & Dutré scalar triple products (32-byte baseline layout).
    Sctp,
    /// Maria et al. Plücker traversal (Tet80 layout).
    Tet80,
    /// Aman et al. 2-D projected traversal on Tet32.
    Tet32,
    /// Aman et al. on Tet20.
    Tet20,
    /// Aman et al. on Tet16.
    Tet16,
    /// BVH baseline (obvhs, BVH2).
    Obvhs,
    /// Embree 3, one `rtcIntersect1` per ray (needs the `embree` feature).
    Embree,
    /// Embree 3, `rtcIntersect8` on packets of 8 rays (needs the `embree` feature).
    Embree8,
    /// f64 brute force over all triangles (reference; slow).
    Brute,
    /// Tet20 walk as a wgpu compute shader (needs the `gpu` feature).
    GpuTet20,
    /// Tet32 on the GPU.
    GpuTet32,
    /// Tet16 on the GPU.
    GpuTet16,
    /// Tet80 (Plücker) on the GPU.
    GpuTet80,
}

impl Method {
    /// Name as on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Method::Sctp => "sctp",
            Method::Tet80 => "tet80",
            Method::Tet32 => "tet32",
            Method::Tet20 => "tet20",
            Method::Tet16 => "tet16",
            Method::Obvhs => "obvhs",
            Method::Embree => "embree",
            Method::Embree8 => "embree8",
            Method::Brute => "brute",
            Method::GpuTet20 => "gpu-tet20",
            Method::GpuTet32 => "gpu-tet32",
            Method::GpuTet16 => "gpu-tet16",
            Method::GpuTet80 => "gpu-tet80",
        }
    }

    /// True for the GPU methods.
    pub fn is_gpu(self) -> bool {
        matches!(
            self,
            Method::GpuTet20 | Method::GpuTet32 | Method::GpuTet16 | Method::GpuTet80
        )
    }
}

/// `render` arguments.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// Scene or mesh file.
    pub scene: String,
    /// Traversal method.
    #[arg(long, value_enum, default_value_t = Method::Tet20)]
    pub method: Method,
    /// Image width.
    #[arg(long, default_value_t = 1920)]
    pub width: u32,
    /// Image height.
    #[arg(long, default_value_t = 1440)]
    pub height: u32,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Frames to render; best and median are reported.
    #[arg(long, default_value_t = 5)]
    pub frames: u32,
    /// Write the shaded image (PNG).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Write a heat map of tets (or nodes) visited per pixel (PNG).
    #[arg(long)]
    pub heatmap: Option<PathBuf>,
    /// Trace shadow rays to the point lights.
    #[arg(long)]
    pub shadows: bool,
    /// Build options (ignored for mesh files).
    #[command(flatten)]
    pub build: BuildFlags,
}

/// Floating-point precision of the kernels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Precision {
    /// f32 kernels.
    F32,
    /// f64 kernels.
    F64,
    /// Both.
    Both,
}

/// `accuracy` arguments.
#[derive(Debug, Args)]
pub struct AccuracyArgs {
    /// Scene or mesh file.
    pub scene: String,
    /// Methods to check (comma separated) or `all`.
    #[arg(long, default_value = "all")]
    pub methods: String,
    /// Random rays from interior points (in addition to the camera image).
    #[arg(long, default_value_t = 100_000)]
    pub rays: usize,
    /// Side of the square camera image whose primary rays are checked
    /// (Maria et al. count failures per 1024² image).
    #[arg(long, default_value_t = 1024)]
    pub image: u32,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Repeat on the scene scaled by 1e-4 and 1e4 and translated by 1e5.
    #[arg(long)]
    pub extremes: bool,
    /// Kernel precision.
    #[arg(long, value_enum, default_value_t = Precision::F32)]
    pub precision: Precision,
    /// Build options (ignored for mesh files).
    #[command(flatten)]
    pub build: BuildFlags,
}

/// `tables` arguments.
#[derive(Debug, Args)]
pub struct TablesArgs {
    /// A scenes.json whose scenes to include (default: the procedural Torus Knots scenes).
    #[arg(long)]
    pub scenes: Option<PathBuf>,
    /// Smaller images and fewer frames: finishes in minutes on 2 cores.
    #[arg(long)]
    pub quick: bool,
    /// Output directory.
    #[arg(long, default_value = "results")]
    pub out: PathBuf,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Measure this scene (repeatable; any SCENE as for `render`). Replaces
    /// the default Torus Knots scenes; added to those of `--scenes`.
    #[arg(long = "scene", value_name = "SCENE")]
    pub scene: Vec<String>,
    /// Directory of the SVG figures (default: the `--out` directory).
    #[arg(long, value_name = "DIR")]
    pub plots: Option<PathBuf>,
    /// Image width (default: 1920, or 640 with `--quick`).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height (default: 1440, or 480 with `--quick`).
    #[arg(long)]
    pub height: Option<u32>,
    /// Timed frames per method (default: 5, or 3 with `--quick`).
    #[arg(long)]
    pub frames: Option<u32>,
}
