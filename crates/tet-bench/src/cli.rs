//! The command line (a scripted interface: see the README for the
//! `--json` schema; do not change it silently): the subcommands, their
//! arguments, and the parsers of values that exist only here (boxes,
//! counts). What the arguments name lives with the code that uses it: the
//! methods ([`crate::methods::method`]), the build flags
//! ([`crate::load::build_flags`]), the view ([`crate::load::camera`]), the
//! out-of-core options ([`crate::outofcore::options`]) and the iso methods
//! ([`crate::iso::IsoMethod`]).

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};

use crate::iso::IsoMethod;
use crate::load::build_flags::BuildFlags;
use crate::load::camera::{ViewArgs, parse_vec3};
use crate::methods::method::{Method, Precision};
use crate::outofcore::options::{
    MemPerPart, MergeMode, Planner, parse_mem_per_part, parse_memory_limit,
};
use crate::timing::ray_kinds::RayKinds;

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
    #[command(after_help = procedural_scenes_help())]
    Build(BuildArgs),
    /// Counts and exact bytes per layout of a scene or mesh file.
    #[command(after_help = procedural_scenes_help())]
    Info(InfoArgs),
    /// Render a scene with one traversal method and report timings.
    #[command(after_help = procedural_scenes_help())]
    Render(RenderArgs),
    /// Compare every method against an f64 brute-force reference.
    #[command(after_help = procedural_scenes_help())]
    Accuracy(AccuracyArgs),
    /// Run the whole reproduction and write Markdown, CSV and JSON tables.
    #[command(after_help = procedural_scenes_help())]
    Tables(TablesArgs),
    /// Trace isosurfaces of a tetrahedral volume (a VTK, TetGen or mesh
    /// file with point scalars, or a synthetic volume's name).
    Iso(IsoArgs),
    /// Convert a tet mesh between formats: our mesh file (`.tmesh`), VTK
    /// (`.vtk`, `.vtu`, `.pvd`) and TetGen (`.node`/`.ele`/`.face`/`.neigh`,
    /// named by the `.node` path); a synthetic volume's name is an input.
    Convert(ConvertArgs),
    // Jobs: a build planned into a directory (`build --plan`), run by any
    // engine part by part, then merged.
    /// Build one part of a planned job (`build SCENE --plan JOB_DIR`); the
    /// part index defaults from Slurm or Kubernetes.
    BuildPart(BuildPartArgs),
    /// Merge the finished parts of a planned job into one mesh file.
    Merge(MergeArgs),
    /// Inspect a planned job (`job status JOB_DIR`).
    Job(JobArgs),
    /// Submit a planned job to a batch system: an array of part tasks and
    /// a merge that waits for them.
    Submit(SubmitArgs),
    /// The GPU benchmark in one command (needs `--features gpu`): kernel
    /// times of the GPU walks (Aman et al. 2022, Table 3), a GPU BVH on
    /// the same rays and secondary rays, every hit checked against the CPU
    /// walk; writes `OUT_DIR/gpu.json` and `OUT_DIR/gpu.md`.
    #[command(after_help = procedural_scenes_help())]
    GpuBench(GpuBenchArgs),
    /// Internal: serve one TetGen request on stdin/stdout (isolated builds).
    #[command(hide = true)]
    TetgenWorker,
}

/// The help's list of the procedural scenes a `SCENE` argument may name,
/// one line each, printed from [`tet_build::procedural::SCENES`]: the list
/// the names are parsed against.
pub fn procedural_scenes_help() -> String {
    let scenes = tet_build::procedural::SCENES;
    let width = scenes.iter().map(|p| p.name.len()).max().unwrap_or(0);
    let mut help = String::from(
        "SCENE is an OBJ file (scenes/stanford-bunny.obj), a scene of a scenes.json \
         (scenes/scenes.json#Armadillo; the file alone lists its scenes), or a procedural \
         scene (N: a count, with an optional k or m suffix):\n",
    );
    for p in scenes {
        help.push_str(&format!("  {:width$}  {}\n", p.name, p.about));
    }
    help
}

/// `build` arguments.
#[derive(Debug, Args)]
pub struct BuildArgs {
    /// Scene: a procedural name (`torus-knots`, …; listed below), an OBJ
    /// path, or `FILE.json#Name` (`scenes/scenes.json#Armadillo`).
    pub scene: String,
    /// Output mesh file (required unless `--predict-memory` or `--plan`).
    #[arg(short, long, required_unless_present_any = ["predict_memory", "plan"])]
    pub output: Option<PathBuf>,
    /// Print TetGen's predicted peak memory for this scene (the memory
    /// model of Erkoç et al. 2021, §3.2) and exit without building.
    #[arg(long)]
    pub predict_memory: bool,
    /// Keep this process and its TetGen workers together under this size
    /// (bytes, or with a unit K, M, G: powers of 1024, e.g. 512M): this
    /// process sets a share aside for itself (`--predict-memory` says how
    /// much), and when TetGen's predicted peak does not fit the rest, the
    /// scene is split into parts with exact seams, built by parallel
    /// workers (only as many at once as fit) and merged. With `--plan`: the
    /// limit on each part's predicted TetGen peak (each part runs on its
    /// own).
    #[arg(long, value_name = "BYTES", value_parser = parse_memory_limit)]
    pub memory_limit: Option<u64>,
    /// With `--memory-limit`: at most this many TetGen workers at once
    /// (default: all cores); with this process, they stay under the limit.
    #[arg(long, requires = "memory_limit")]
    pub threads: Option<usize>,
    /// With `--memory-limit`: how to split (default: the paper's recursive
    /// tree, parallel slabs when no tree fits).
    #[arg(long, value_enum, default_value_t, requires = "memory_limit")]
    pub planner: Planner,
    /// With `--memory-limit`: how to merge the parts. `stream` (default)
    /// writes each part to a part file as it finishes and merges the files
    /// into the output a part at a time, each part Hilbert-sorted on its
    /// own; `memory` merges the whole mesh in memory and sorts it as a whole.
    #[arg(long, value_enum, default_value_t, requires = "memory_limit")]
    pub merge: MergeMode,
    /// After writing, trace the written mesh with tet20 (640×480, best of 3
    /// frames, all cores) and report its speed (`tet20` in `--json`).
    #[arg(long)]
    pub tet20: bool,
    /// Plan the build as a job in this directory instead of building:
    /// `job.json` and one input file per part; each part is then built by
    /// `build-part` (any order, any machine) and the results merged by
    /// `merge`. With `--memory-limit`, every part's predicted TetGen peak
    /// fits it.
    #[arg(long, value_name = "JOB_DIR", conflicts_with_all = ["output", "predict_memory", "tet20"])]
    pub plan: Option<PathBuf>,
    /// With `--plan`: cut into at least this many parts (the paper's tree
    /// is split down to depth ⌈log2 N⌉ at least; slabs until there are N).
    #[arg(long, requires = "plan")]
    pub parts: Option<usize>,
    /// Build options.
    #[command(flatten)]
    pub build: BuildFlags,
}

/// `build-part` arguments.
#[derive(Debug, Args)]
pub struct BuildPartArgs {
    /// The job directory (`build --plan`).
    pub job_dir: PathBuf,
    /// The part to build; default: `SLURM_ARRAY_TASK_ID` (a Slurm array
    /// task), else `JOB_COMPLETION_INDEX` (a Kubernetes Indexed Job).
    #[arg(long)]
    pub index: Option<usize>,
}

/// `merge` arguments.
#[derive(Debug, Args)]
pub struct MergeArgs {
    /// The job directory.
    pub job_dir: PathBuf,
    /// The merged mesh file (`.tmesh`).
    #[arg(short, long)]
    pub output: PathBuf,
}

/// `job` arguments.
#[derive(Debug, Args)]
pub struct JobArgs {
    /// What to do.
    #[command(subcommand)]
    pub command: JobCommand,
}

/// `job` subcommands.
#[derive(Debug, Subcommand)]
pub enum JobCommand {
    /// Each part: done, failed, stale or missing, with predicted and
    /// measured peak memory.
    Status(JobStatusArgs),
}

/// `job status` arguments.
#[derive(Debug, Args)]
pub struct JobStatusArgs {
    /// The job directory.
    pub job_dir: PathBuf,
    /// Also read every result file and check its digest (slower).
    #[arg(long)]
    pub verify: bool,
}

/// Batch systems `submit` writes scripts for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Engine {
    /// Slurm: one job array of parts, a merge job depending on it.
    Slurm,
}

/// `submit` arguments.
#[derive(Debug, Args)]
pub struct SubmitArgs {
    /// The job directory.
    pub job_dir: PathBuf,
    /// The batch system.
    #[arg(long, value_enum)]
    pub engine: Engine,
    /// The partition (queue) to submit to; default: the cluster's.
    #[arg(long)]
    pub partition: Option<String>,
    /// Memory per part task: `auto` (from the plan's largest predicted
    /// part) or a size (`2G`, `512M`).
    #[arg(long, default_value = "auto", value_parser = parse_mem_per_part)]
    pub mem_per_part: MemPerPart,
    /// The merged mesh file (default: `JOB_DIR/mesh.tmesh`).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Write the scripts only, submit nothing.
    #[arg(long)]
    pub dry_run: bool,
}

/// `info` arguments.
#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Scene (built on the fly; procedural names listed below) or mesh
    /// file (`.tmesh`).
    pub scene: String,
    /// Also report the bytes left after pruning the regions that neither the
    /// camera nor a light is in (no ray can reach them).
    #[arg(long)]
    pub prune: bool,
    /// Build options (ignored for mesh files).
    #[command(flatten)]
    pub build: BuildFlags,
}

/// `render` arguments.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// Scene (procedural names listed below; an OBJ path; `FILE.json#Name`)
    /// or mesh file (`.tmesh`).
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
    /// Trace shadow rays to the point lights (the same as `--rays shadow`,
    /// or `mixed` with `--rays ao`).
    #[arg(long)]
    pub shadows: bool,
    /// The rays of a frame: primary rays only, or per primary hit also one
    /// ambient-occlusion ray (`ao`; cosine-distributed, a tenth of the
    /// scene's diagonal long), shadow rays to the point lights (`shadow`),
    /// or both (`mixed`). Each kind's rays and speed are reported apart.
    #[arg(long, value_enum, default_value_t = RayKinds::Primary)]
    pub rays: RayKinds,
    /// View (overrides the scene's camera).
    #[command(flatten)]
    pub view: ViewArgs,
    /// Build options (ignored for mesh files).
    #[command(flatten)]
    pub build: BuildFlags,
}

/// `accuracy` arguments.
#[derive(Debug, Args)]
pub struct AccuracyArgs {
    /// Scene (procedural names listed below; an OBJ path; `FILE.json#Name`)
    /// or mesh file (`.tmesh`).
    pub scene: String,
    /// Methods to check (comma separated) or `all`.
    #[arg(long, default_value = "all")]
    pub methods: String,
    /// Random rays from interior points (in addition to the camera image).
    #[arg(long, default_value_t = 100_000)]
    pub rays: usize,
    /// Side of the square camera image whose primary rays are checked
    /// (Maria et al. 2017 count failures per 1024² image).
    #[arg(long, default_value_t = 1024)]
    pub image: u32,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Repeat on the scene scaled by 1e-4, 1e4, 1e-30 and 1e30 and translated by 1e5.
    #[arg(long)]
    pub extremes: bool,
    /// Add as many adversarial rays as `--rays`: aimed exactly at mesh
    /// vertices, at points of edges and faces (scene triangles or not),
    /// along edges, and started on faces and vertices.
    #[arg(long)]
    pub adversarial: bool,
    /// Kernel precision.
    #[arg(long, value_enum, default_value_t = Precision::F32)]
    pub precision: Precision,
    /// Time each method over the rays for at least this many seconds in
    /// all (at least 3 passes over the same rays) and report the best
    /// pass's Mrays/s.
    #[arg(long, default_value_t = 0.5)]
    pub min_time: f64,
    /// View of the camera rays (overrides the scene's camera).
    #[command(flatten)]
    pub view: ViewArgs,
    /// Build options (ignored for mesh files).
    #[command(flatten)]
    pub build: BuildFlags,
}

/// `tables` arguments.
#[derive(Debug, Args)]
pub struct TablesArgs {
    /// A scenes.json whose scenes to include, e.g. `scenes/scenes.json`
    /// (default: the procedural Torus Knots scenes and Flat Parts).
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
    /// Measure this scene (repeatable; any SCENE as for `render`, the
    /// procedural ones listed below). Replaces the default Torus Knots
    /// scenes; added to those of `--scenes`.
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
    /// Timed frames per method, at least (default: 5, or 3 with `--quick`).
    #[arg(long)]
    pub frames: Option<u32>,
    /// Seconds each method is timed, at least: rendered frames (more than
    /// `--frames` where they are fast, at most 200) and passes over the
    /// accuracy rays (default: 0.5, or 0.2 with `--quick`).
    #[arg(long)]
    pub min_time: Option<f64>,
    /// Sizes of the large-model table (Torus Knots tessellated to about
    /// this many triangles; `k`/`m` suffixes; `none` for no table).
    /// Default: 1m,10m,30m, or none with `--quick`.
    #[arg(long, value_name = "LIST", value_delimiter = ',', value_parser = parse_size)]
    pub large_models: Option<Vec<u64>>,
    /// Build Tet20 of the large-model table out of core under this limit
    /// on the whole process tree (bytes, or with K, M, G), as `build
    /// --memory-limit` does. Default: in core where TetGen's predicted
    /// peak fits in half the free memory, else out of core under half the
    /// free memory.
    #[arg(long, value_name = "BYTES", value_parser = parse_memory_limit)]
    pub large_models_limit: Option<u64>,
    /// Sizes of the large out-of-core table (`fan-sphere:N` built in parts
    /// under its builder's share plus a sixteenth of its predicted in-core
    /// peak; `k`/`m` suffixes; `none` for no table). Default: 1m, or none
    /// with `--quick`.
    #[arg(long, value_name = "LIST", value_delimiter = ',', value_parser = parse_size)]
    pub large_out_of_core: Option<Vec<u64>>,
    /// Rays of the robustness table on the first scene, in batches (camera
    /// image, random and adversarial rays; `k`/`m` suffixes; `none` for the
    /// plain 1024² + 100 k rays). Default: 100m, or none with `--quick`.
    #[arg(long, value_name = "N", value_parser = parse_size)]
    pub robustness_rays: Option<u64>,
}

/// A `--large-models` entry: a count (`1m`, `300k`, `250000`) or `none` (0).
fn parse_size(text: &str) -> Result<u64, String> {
    if text.trim().eq_ignore_ascii_case("none") {
        return Ok(0);
    }
    tet_build::procedural::parse_count(text).ok_or_else(|| {
        format!("`{text}` is not a count (digits, optionally with k or m) or `none`")
    })
}

impl TablesArgs {
    /// Rays of the first scene's robustness table, when streamed (see
    /// `--robustness-rays`).
    pub fn streamed_robustness_rays(&self) -> Option<u64> {
        match self.robustness_rays {
            Some(0) => None,
            Some(n) => Some(n),
            None if self.quick => None,
            None => Some(100_000_000),
        }
    }

    /// Sizes of the large-model table (see `--large-models`).
    pub fn large_model_sizes(&self) -> Vec<u64> {
        match &self.large_models {
            Some(sizes) => sizes.iter().copied().filter(|&n| n > 0).collect(),
            None if self.quick => Vec::new(),
            None => vec![1_000_000, 10_000_000, 30_000_000],
        }
    }

    /// Sizes of the large out-of-core table (see `--large-out-of-core`).
    pub fn large_out_of_core_sizes(&self) -> Vec<u64> {
        match &self.large_out_of_core {
            Some(sizes) => sizes.iter().copied().filter(|&n| n > 0).collect(),
            None if self.quick => Vec::new(),
            None => vec![1_000_000],
        }
    }

    /// Seconds each method is timed, at least (frames and accuracy passes).
    pub fn min_time_s(&self) -> f64 {
        self.min_time.unwrap_or(if self.quick { 0.2 } else { 0.5 })
    }
}

/// `gpu-bench` arguments.
#[derive(Debug, Args)]
pub struct GpuBenchArgs {
    /// Where `gpu.json` and `gpu.md` go (`meshes.json` with
    /// `--prepare-meshes`); created when missing.
    pub out_dir: PathBuf,
    /// Small images (160×120), 3 timed dispatches, one secondary pass: a
    /// test of the command (CI, lavapipe), not of speed.
    #[arg(long)]
    pub quick: bool,
    /// Directory of prebuilt meshes, one `NAME.tmesh` per scene (NAME: the
    /// scene spec after its `#`, an OBJ's file stem or the procedural
    /// name, lower case, other characters as `-`: `torus-knots`,
    /// `torus-knots-box`, `armadillo`, `neptune`, `mix`). A scene without
    /// its file is built when TetGen is compiled in, else skipped.
    #[arg(long, value_name = "DIR")]
    pub meshes: Option<PathBuf>,
    /// Build every scene's mesh into `--meshes DIR` (no GPU needed), report
    /// each file's size and the total against `--budget-mb`, and stop.
    #[arg(long, requires = "meshes", conflicts_with = "adapter_only")]
    pub prepare_meshes: bool,
    /// With `--prepare-meshes`: megabytes the meshes may take on the way
    /// to a GPU machine (the whole carried set, binary and loader
    /// packages with it, stays under 60 MB: give what is left for them).
    #[arg(
        long,
        value_name = "MB",
        default_value_t = 60.0,
        requires = "prepare_meshes"
    )]
    pub budget_mb: f64,
    /// Print the adapter wgpu finds (name, backend, device type, driver)
    /// and stop; fails on a software adapter (lavapipe, llvmpipe) unless
    /// `--allow-software`.
    #[arg(long)]
    pub adapter_only: bool,
    /// With `--adapter-only`: accept a software adapter.
    #[arg(long, requires = "adapter_only")]
    pub allow_software: bool,
    /// The scenes.json of the real scenes (Armadillo, Neptune, Mix).
    #[arg(long, value_name = "FILE", default_value = "scenes/scenes.json")]
    pub scenes: PathBuf,
    /// Measure this scene instead of the five of Table 3 (repeatable; any
    /// SCENE as for `render`, or a `.tmesh` file).
    #[arg(long = "scene", value_name = "SCENE")]
    pub scene: Vec<String>,
    /// Image width (default: 1920, or 160 with `--quick`).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height (default: 1440, or 120 with `--quick`).
    #[arg(long)]
    pub height: Option<u32>,
    /// Timed dispatches of each method, after one warm-up; the best is
    /// reported (default: 20, or 3 with `--quick`).
    #[arg(long)]
    pub frames: Option<u32>,
    /// Build missing meshes in the default tight box (cameras outside the
    /// mesh, rays entering through its boundary) instead of the papers'
    /// wide box that holds the camera and lights.
    #[arg(long)]
    pub tight_box: bool,
}

/// `iso` arguments.
#[derive(Debug, Args)]
pub struct IsoArgs {
    /// Volume: a `.vtk`/`.vtu`/`.pvd`, TetGen `.node` or mesh file with a
    /// scalar field, or a synthetic name (ell32p, feok, bucky, blunt,
    /// buckycube, fusion, linear, marschner-lobb).
    pub volume: String,
    /// Isovalue (repeat for up to 4 at once; default: the synthetic
    /// volume's own, else the middle of the field's range).
    #[arg(long = "isovalue", allow_negative_numbers = true)]
    pub isovalues: Vec<f32>,
    /// Method.
    #[arg(long, value_enum, default_value_t = IsoMethod::WalkTet20)]
    pub method: IsoMethod,
    /// Time step of the field (0-based).
    #[arg(long, default_value_t = 0)]
    pub time_step: usize,
    /// Walks: let every ray walk until it leaves the volume, without the
    /// min-max regions that cull rays meeting no straddling region (for
    /// comparisons; the hits are the same).
    #[arg(long)]
    pub no_regions: bool,
    /// `buckycube` only: `N` bucky balls per axis, N³ in all (Wald et al. 2007,
    /// Table 3; 1 to 8, default 2).
    #[arg(long, value_name = "N")]
    pub replications: Option<u32>,
    /// Image width.
    #[arg(long, default_value_t = 1024)]
    pub width: u32,
    /// Image height.
    #[arg(long, default_value_t = 1024)]
    pub height: u32,
    /// Timed frames (after one warm-up frame).
    #[arg(long, default_value_t = 3)]
    pub frames: u32,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Write the image (PNG).
    #[arg(short = 'o', long)]
    pub output: Option<PathBuf>,
    /// Trace a shadow ray from every hit to the light (`--light` or
    /// `--light-dir`; default: a point light at the eye); clipped-away
    /// surface casts no shadow.
    #[arg(long)]
    pub shadows: bool,
    /// Point light `X,Y,Z` of the shadow rays.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true, conflicts_with = "light_dir")]
    pub light: Option<glam::Vec3>,
    /// Directional light: the direction `X,Y,Z` its light travels in.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub light_dir: Option<glam::Vec3>,
    /// Clip box `X0,Y0,Z0,X1,Y1,Z1` (two opposite corners): only crossings
    /// inside it count, or, with `--clip-mode cut`, crossings strictly
    /// inside it are cut away.
    #[arg(long, value_name = "X0,Y0,Z0,X1,Y1,Z1", value_parser = parse_box, allow_hyphen_values = true)]
    pub clip: Option<(glam::Vec3, glam::Vec3)>,
    /// What the clip box keeps.
    #[arg(long, value_enum, default_value_t = IsoClipMode::Keep)]
    pub clip_mode: IsoClipMode,
    /// View (replaces parts of the default camera, which frames the
    /// volume's bounds from an oblique direction).
    #[command(flatten)]
    pub view: ViewArgs,
}

/// What an `iso` clip box keeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum IsoClipMode {
    /// Crossings inside the box.
    Keep,
    /// Crossings outside the box (the box is cut away).
    Cut,
}

/// Parses `X0,Y0,Z0,X1,Y1,Z1` (six finite numbers) into the box's lower and
/// upper corners.
pub fn parse_box(s: &str) -> Result<(glam::Vec3, glam::Vec3), String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 6 {
        return Err(format!(
            "`{s}` is not a box: give six numbers X0,Y0,Z0,X1,Y1,Z1 separated by commas"
        ));
    }
    let a = parse_vec3(&parts[..3].join(","))?;
    let b = parse_vec3(&parts[3..].join(","))?;
    Ok((a.min(b), a.max(b)))
}

/// `convert` arguments.
#[derive(Debug, Args)]
pub struct ConvertArgs {
    /// Input: a mesh file, VTK file, TetGen `.node` file or synthetic
    /// volume name.
    pub input: String,
    /// Output, by extension: `.tmesh` (any other extension too), `.vtk`,
    /// `.vtu`, `.pvd`, or `.node` (TetGen files beside it).
    pub output: PathBuf,
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    #[test]
    fn boxes_parse_as_six_numbers_in_either_corner_order() {
        assert_eq!(
            parse_box("1,-2,3,0,4,-5"),
            Ok((Vec3::new(0.0, -2.0, -5.0), Vec3::new(1.0, 4.0, 3.0)))
        );
        for bad in [
            "",
            "1,2,3",
            "1,2,3,4,5",
            "1,2,3,4,5,6,7",
            "1,2,3,4,x,6",
            "1,2,3,inf,5,6",
        ] {
            assert!(parse_box(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn iso_flags_parse() {
        let cli = Cli::try_parse_from([
            "tet-bench",
            "iso",
            "ell32p",
            "--clip",
            "0,0,0,1,2,3",
            "--clip-mode",
            "cut",
            "--shadows",
            "--light-dir",
            "0,-1,0",
            "--eye",
            "5,5,5",
            "--fov",
            "30",
        ])
        .unwrap();
        let Command::Iso(a) = cli.command else {
            panic!("not iso")
        };
        assert_eq!(a.clip, Some((Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0))));
        assert_eq!(a.clip_mode, IsoClipMode::Cut);
        assert!(a.shadows);
        assert_eq!(a.light_dir, Some(Vec3::new(0.0, -1.0, 0.0)));
        assert_eq!(a.view.eye, Some(Vec3::splat(5.0)));
        assert_eq!(a.view.fov, Some(30.0));
        // A point light and a directional one exclude each other.
        assert!(
            Cli::try_parse_from([
                "tet-bench",
                "iso",
                "ell32p",
                "--shadows",
                "--light",
                "1,2,3",
                "--light-dir",
                "0,1,0",
            ])
            .is_err()
        );
    }
}
