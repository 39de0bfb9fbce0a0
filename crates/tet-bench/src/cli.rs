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

/// How to build a mesh from a scene.
#[derive(Debug, Clone, Copy, Args)]
pub struct BuildFlags {
    /// TetGen quality bound (radius-edge ratio, `-q`); off by default (`-pY` only).
    #[arg(long)]
    pub quality: Option<f64>,
    /// Refine tets whose smallest dihedral angle is below this many
    /// degrees (slivers; TetGen `-q<ratio>/<degrees>`), with or without
    /// `--quality`.
    #[arg(long, value_name = "DEGREES")]
    pub min_dihedral: Option<f64>,
    /// Cap on the Steiner points of the quality refinement (`-S`; the
    /// points TetGen adds to recover the scene's edges and faces do not
    /// count): a number, or a percentage of the scene's vertices (`1%`).
    /// With `--min-dihedral 2`, 1 % already removes the worst slivers.
    #[arg(long, value_name = "N|P%", value_parser = parse_max_steiner)]
    pub max_steiner: Option<MaxSteiner>,
    /// TetGen's mesh optimisation `LEVEL/SCHEME` (`-O`): up to 2^LEVEL − 1
    /// passes (LEVEL 0 to 9) of flips (SCHEME bit 1), smoothing (2) and
    /// vertex insertion/deletion (4). Default: TetGen's 2/7.
    #[arg(long, value_name = "LEVEL/SCHEME", value_parser = parse_optimization)]
    pub optimize: Option<tet_build::tetgen_options::Optimization>,
    /// Dihedral angle in degrees above which TetGen's optimisation works on
    /// a tet (`-o/`; TetGen's default 165).
    #[arg(long, value_name = "DEGREES")]
    pub max_dihedral: Option<f64>,
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
    /// Do not split triangles that cross, touch in their interiors or
    /// overlap: such a scene then fails with the list of intersecting
    /// pairs instead of being resolved.
    #[arg(long)]
    pub no_resolve: bool,
    /// Cut the enclosing box into parts with exact walls between them (the
    /// out-of-core builder's recursive planes), tetrahedralize the parts
    /// in parallel and merge them: the walls break up the long sliver fans
    /// of the unrefined `-pY` mesh, which every ray crosses. `auto`: dense
    /// regions cut until each part's predicted TetGen peak is about 28 MiB
    /// (light parts and empty margins left whole; where no walled build
    /// succeeds, the scene in one piece); `N`: every part cut to the same
    /// depth, N parts (rounded up to a power of two); `none`: one TetGen
    /// run for the whole scene. Default: `auto`, or `none` with
    /// `--no-box`, `--quality` or `--min-dihedral` (the papers' refined
    /// builds are one piece).
    #[arg(long, value_name = "N|auto|none", value_parser = parse_walls)]
    pub walls: Option<Walls>,
}

/// How finely `--walls` cuts the enclosing box.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Walls {
    /// Parts of about 28 MiB predicted TetGen peak
    /// (`tet_build::outofcore::split::RAY_PART_TARGET_BYTES`, the size every
    /// build shaped for rays cuts toward; if that build fails: one part per about
    /// [`Walls::TRIANGLES_PER_PART`] scene triangles, uniform depth; if
    /// that fails too: the scene in one piece, the switches saying why).
    Auto,
    /// This many parts (rounded up to a power of two).
    Parts(u32),
    /// The scene in one piece: one TetGen run, no walls.
    None,
}

#[cfg_attr(not(feature = "tetgen"), allow(dead_code))]
impl Walls {
    /// `auto`'s fallback: scene triangles per part at uniform depth (Torus
    /// Knots: 32 parts, Armadillo and Nefertiti: 64).
    pub const TRIANGLES_PER_PART: usize = 2_000;

    /// The depth of the cut tree (`2^depth` parts, at most 4096) for a
    /// scene of `triangles` triangles.
    pub fn depth(self, triangles: usize) -> usize {
        let parts = match self {
            Walls::None => 1,
            Walls::Parts(n) => n as usize,
            Walls::Auto => {
                let x = triangles as f64 / Self::TRIANGLES_PER_PART as f64;
                x.max(1.0).log2().round().exp2() as usize
            }
        };
        parts.clamp(1, 4096).next_power_of_two().trailing_zeros() as usize
    }
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

/// Memory per part task.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MemPerPart {
    /// From the plan's predictions.
    Auto,
    /// This many bytes.
    Bytes(u64),
}

/// Parses `auto` or a memory size ([`parse_memory_limit`]).
pub fn parse_mem_per_part(s: &str) -> Result<MemPerPart, String> {
    if s.trim().eq_ignore_ascii_case("auto") {
        Ok(MemPerPart::Auto)
    } else {
        parse_memory_limit(s).map(MemPerPart::Bytes)
    }
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

/// Traversal methods.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, ValueEnum, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Scalar triple products (Lagae & Dutré 2008; 32-byte baseline layout).
    Sctp,
    /// Plücker traversal (Maria et al. 2017; Tet80 layout).
    Tet80,
    /// Tet80 with consistent side products: one per edge, the same in
    /// every tet around it (canonical edge orientation, one rule for zero).
    Tet80Consistent,
    /// 2-D projected traversal of Aman et al. (2022) on Tet32.
    Tet32,
    /// 2-D projected traversal of Aman et al. (2022) on Tet20.
    Tet20,
    /// 2-D projected traversal of Aman et al. (2022) on Tet16.
    Tet16,
    /// BVH baseline (obvhs, BVH2).
    Obvhs,
    /// Ray-Strips (Lauterbach et al. 2007): strip hierarchies under an SAH BVH,
    /// one ray at a time.
    Strips,
    /// Ray-Strips with 2×2 ray packets (groups of four consecutive rays).
    StripsPackets,
    /// Embree 3, one `rtcIntersect1` per ray (needs the `embree` feature).
    Embree,
    /// Embree 3, `rtcIntersect8` on packets of 8 rays (needs the `embree` feature).
    Embree8,
    /// f64 brute force over all triangles (reference; slow).
    Brute,
    /// The exact reference walk: exact side products with a symbolic tie
    /// rule (reference; not in the default comparisons).
    Exact,
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
            Method::Tet80Consistent => "tet80-consistent",
            Method::Tet32 => "tet32",
            Method::Tet20 => "tet20",
            Method::Tet16 => "tet16",
            Method::Obvhs => "obvhs",
            Method::Strips => "strips",
            Method::StripsPackets => "strips-packets",
            Method::Embree => "embree",
            Method::Embree8 => "embree8",
            Method::Brute => "brute",
            Method::Exact => "exact",
            Method::GpuTet20 => "gpu-tet20",
            Method::GpuTet32 => "gpu-tet32",
            Method::GpuTet16 => "gpu-tet16",
            Method::GpuTet80 => "gpu-tet80",
        }
    }

    /// The tet layout the method walks (a name of
    /// `tet_core::memory::LAYOUT_NAMES`); `None` for the methods that walk
    /// no layout (BVHs, Ray-Strips, brute force, the exact walk).
    pub fn layout(self) -> Option<&'static str> {
        match self {
            Method::Sctp => Some("baseline32"),
            Method::Tet80 | Method::Tet80Consistent | Method::GpuTet80 => Some("tet80"),
            Method::Tet32 | Method::GpuTet32 => Some("tet32"),
            Method::Tet20 | Method::GpuTet20 => Some("tet20"),
            Method::Tet16 | Method::GpuTet16 => Some("tet16"),
            Method::Obvhs
            | Method::Strips
            | Method::StripsPackets
            | Method::Embree
            | Method::Embree8
            | Method::Brute
            | Method::Exact => None,
        }
    }

    /// True for the methods that walk tets (and so report tets per ray).
    pub fn walks_tets(self) -> bool {
        self.layout().is_some() || self == Method::Exact
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
    /// Trace shadow rays to the point lights.
    #[arg(long)]
    pub shadows: bool,
    /// View (overrides the scene's camera).
    #[command(flatten)]
    pub view: ViewArgs,
    /// Build options (ignored for mesh files).
    #[command(flatten)]
    pub build: BuildFlags,
}

/// The view: each flag given replaces that part of the scene's camera (or
/// of the default camera, which frames the whole scene from outside on
/// its +z side). Checked before anything is traced: finite coordinates,
/// an eye away from the target, an up direction not along the line of
/// sight, and a field of view strictly between 0 and 180 degrees.
#[derive(Debug, Clone, Copy, Default, Args)]
pub struct ViewArgs {
    /// Camera position `X,Y,Z`, replacing the scene's camera position (without
    /// a scene camera: outside the scene on its +z side, framing it).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub eye: Option<glam::Vec3>,
    /// Point `X,Y,Z` the camera looks at (default: the scene camera's target,
    /// or the centre of the scene).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub target: Option<glam::Vec3>,
    /// Up direction `X,Y,Z` of the image, across the line of sight (default:
    /// the scene camera's, or +y).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub up: Option<glam::Vec3>,
    /// Vertical field of view in degrees, between 0 and 180 (default: the
    /// scene camera's, or 60).
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    pub fov: Option<f32>,
}

/// Parses `X,Y,Z` (three finite numbers separated by commas).
pub fn parse_vec3(s: &str) -> Result<glam::Vec3, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [x, y, z] = parts.as_slice() else {
        return Err(format!(
            "`{s}` is not a point: give three numbers separated by commas, e.g. 0,1.5,-4"
        ));
    };
    let mut v = [0.0f32; 3];
    for (out, text) in v.iter_mut().zip([x, y, z]) {
        *out = text
            .parse::<f32>()
            .map_err(|_| format!("`{text}` in `{s}` is not a number"))?;
        if !out.is_finite() {
            return Err(format!("`{text}` in `{s}` is not finite"));
        }
    }
    Ok(glam::Vec3::from_array(v))
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
    /// Timed frames per method (default: 5, or 3 with `--quick`).
    #[arg(long)]
    pub frames: Option<u32>,
    /// Seconds each method is timed over the accuracy rays, at least, in
    /// repeated passes (default: 0.5, or 0.2 with `--quick`).
    #[arg(long)]
    pub min_time: Option<f64>,
    /// Sizes of the large-model table (Torus Knots tessellated to about
    /// this many triangles; `k`/`m` suffixes; `none` for no table).
    /// Default: 1m,10m,30m, or none with `--quick`.
    #[arg(long, value_name = "LIST", value_delimiter = ',', value_parser = parse_size)]
    pub large_models: Option<Vec<u64>>,
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

    /// Seconds each method is timed over the accuracy rays, at least.
    pub fn min_time_s(&self) -> f64 {
        self.min_time.unwrap_or(if self.quick { 0.2 } else { 0.5 })
    }
}

/// How `build --memory-limit` splits a scene whose prediction exceeds the
/// limit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum Planner {
    /// The paper's recursive tree, parallel slabs when no tree fits.
    #[default]
    Auto,
    /// Only the paper's recursive tree (perpendicular planes).
    Tree,
    /// Only parallel slabs on the axis of largest variance.
    Slabs,
}

/// How the parts of an out-of-core build are merged.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum MergeMode {
    /// Part files merged into the mesh file a part at a time (each part
    /// Hilbert-sorted on its own): the merge holds one part and the seams.
    #[default]
    Stream,
    /// The whole mesh merged in memory and Hilbert-sorted as a whole.
    Memory,
}

/// Parses a memory size: a byte count, or a number with a unit `K`, `M`,
/// `G`, `T` (also `KB`/`KiB`, …, any case), all powers of 1024: `512M`,
/// `1.5G`, `2097152`.
pub fn parse_memory_limit(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let unit = unit.trim().to_ascii_lowercase();
    let scale: f64 = match unit.as_str() {
        "" | "b" => 1.0,
        "k" | "kb" | "kib" => 1024.0,
        "m" | "mb" | "mib" => 1024.0 * 1024.0,
        "g" | "gb" | "gib" => 1024.0 * 1024.0 * 1024.0,
        "t" | "tb" | "tib" => 1024.0 * 1024.0 * 1024.0 * 1024.0,
        _ => {
            return Err(format!(
                "unknown unit `{unit}` in `{s}`: give bytes or a number with K, M, G or T (powers of 1024), e.g. 512M or 1.5G"
            ));
        }
    };
    let value: f64 = num.parse().map_err(|_| {
        format!("`{s}` is not a memory size: give bytes or a number with K, M, G or T, e.g. 512M or 1.5G")
    })?;
    let bytes = value * scale;
    if !(bytes >= 1.0 && bytes < u64::MAX as f64) {
        return Err(format!(
            "memory limit `{s}` must be at least one byte and finite"
        ));
    }
    Ok(bytes.round() as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `--walls`: counts and `auto`, the tree depth they give, and what
    /// is refused.
    #[test]
    fn walls_parse_as_part_counts_or_auto() {
        assert_eq!(parse_walls("auto"), Ok(Walls::Auto));
        assert_eq!(parse_walls(" 8 "), Ok(Walls::Parts(8)));
        assert_eq!(parse_walls("None"), Ok(Walls::None));
        assert_eq!(Walls::None.depth(100_000), 0);
        for bad in ["0", "4097", "-2", "x", ""] {
            assert!(parse_walls(bad).is_err(), "{bad}");
        }
        // Rounded up to a power of two.
        assert_eq!(Walls::Parts(1).depth(10), 0);
        assert_eq!(Walls::Parts(5).depth(10), 3);
        assert_eq!(Walls::Parts(4096).depth(10), 12);
        // One part per about 2,000 triangles, to the nearest power of two.
        assert_eq!(Walls::Auto.depth(500), 0);
        assert_eq!(Walls::Auto.depth(77_760), 5);
        assert_eq!(Walls::Auto.depth(100_000), 6);
        assert_eq!(Walls::Auto.depth(u32::MAX as usize), 12);
    }

    #[test]
    fn steiner_caps_parse_as_counts_or_shares_of_the_vertices() {
        assert_eq!(parse_max_steiner("500"), Ok(MaxSteiner::Count(500)));
        assert_eq!(parse_max_steiner("1%"), Ok(MaxSteiner::Percent(1.0)));
        assert_eq!(parse_max_steiner("0.5 %"), Ok(MaxSteiner::Percent(0.5)));
        for bad in [
            "", "%", "-1", "0%", "-2%", "1e9999%", "nan%", "x", "5 points",
        ] {
            assert!(parse_max_steiner(bad).is_err(), "{bad}");
        }
        // 1 % of 38,888 vertices is 388.88: rounded up.
        assert_eq!(MaxSteiner::Percent(1.0).resolve(38_888), 389);
        assert_eq!(MaxSteiner::Percent(1.0).resolve(0), 0);
        assert_eq!(MaxSteiner::Count(7).resolve(1_000_000), 7);
    }

    #[test]
    fn memory_sizes_parse_with_binary_units() {
        assert_eq!(parse_memory_limit("2097152"), Ok(2_097_152));
        assert_eq!(parse_memory_limit("512M"), Ok(512 << 20));
        assert_eq!(parse_memory_limit("512mb"), Ok(512 << 20));
        assert_eq!(parse_memory_limit("1.5G"), Ok(3 << 29));
        assert_eq!(parse_memory_limit("64 KiB"), Ok(64 << 10));
        for bad in ["", "M", "12X", "-5M", "1.2.3G", "0", "0.1"] {
            let e = parse_memory_limit(bad).unwrap_err();
            assert!(e.contains(bad.trim()), "{bad}: {e}");
        }
    }

    #[test]
    fn points_parse_as_three_finite_numbers() {
        assert_eq!(
            parse_vec3("1,-2.5, 3e2"),
            Ok(glam::Vec3::new(1.0, -2.5, 300.0))
        );
        for bad in ["", "1,2", "1,2,3,4", "1,x,3", "1,inf,3", "NaN,0,0", "1;2;3"] {
            assert!(parse_vec3(bad).is_err(), "{bad}");
        }
    }
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

#[cfg(test)]
mod iso_args_tests {
    use clap::Parser;
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

    /// The walls a build uses: `auto` by default, none where there is no
    /// box or a quality bound is asked for, and what `--walls` says.
    #[test]
    fn builds_are_walled_by_default_but_not_refined_or_boxless_ones() {
        let walls = |extra: &[&str]| {
            let mut argv = vec!["tet-bench", "build", "torus-knot", "-o", "x.tmesh"];
            argv.extend_from_slice(extra);
            let Command::Build(a) = Cli::try_parse_from(argv).unwrap().command else {
                panic!("not build")
            };
            (a.build.walls(), a.build.resolved().walls)
        };
        assert_eq!(walls(&[]), (Walls::Auto, Some(Walls::Auto)));
        assert_eq!(walls(&["--no-box"]).0, Walls::None);
        assert_eq!(walls(&["--quality", "5"]).0, Walls::None);
        assert_eq!(walls(&["--min-dihedral", "2"]).0, Walls::None);
        assert_eq!(walls(&["--max-steiner", "1%"]).0, Walls::Auto);
        assert_eq!(walls(&["--walls", "none"]).0, Walls::None);
        assert_eq!(
            walls(&["--walls", "8", "--quality", "5"]).0,
            Walls::Parts(8)
        );
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

/// Isosurface methods (`--method`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, ValueEnum, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum IsoMethod {
    /// The paper's implicit min-max BVH, BIH-style build, single rays.
    Ibvh,
    /// The same with the SAH build.
    IbvhSah,
    /// The BIH-built IBVH traced by 16×16 packets.
    IbvhPackets,
    /// The iso walk over Tet20 (no BVH over the tets).
    WalkTet20,
    /// The iso walk over Tet16.
    WalkTet16,
    /// The iso walk over Tet32.
    WalkTet32,
}

impl IsoMethod {
    /// Every method, in table order.
    pub const ALL: [IsoMethod; 6] = [
        IsoMethod::Ibvh,
        IsoMethod::IbvhSah,
        IsoMethod::IbvhPackets,
        IsoMethod::WalkTet20,
        IsoMethod::WalkTet16,
        IsoMethod::WalkTet32,
    ];

    /// Name as on the command line.
    pub fn name(self) -> &'static str {
        match self {
            IsoMethod::Ibvh => "ibvh",
            IsoMethod::IbvhSah => "ibvh-sah",
            IsoMethod::IbvhPackets => "ibvh-packets",
            IsoMethod::WalkTet20 => "walk-tet20",
            IsoMethod::WalkTet16 => "walk-tet16",
            IsoMethod::WalkTet32 => "walk-tet32",
        }
    }
}

impl BuildFlags {
    /// The walls these flags build with: `--walls` as given, else `auto`
    /// for the unrefined build in a box and `none` where there is no box
    /// to cut or a quality bound is asked for (the papers' refined builds
    /// are one piece).
    pub fn walls(&self) -> Walls {
        self.walls.unwrap_or(
            if self.no_box || self.quality.is_some() || self.min_dihedral.is_some() {
                Walls::None
            } else {
                Walls::Auto
            },
        )
    }

    /// These flags with the walls they build with spelled out: builds that
    /// come out the same compare equal.
    pub fn resolved(&self) -> BuildFlags {
        BuildFlags {
            walls: Some(self.walls()),
            ..*self
        }
    }

    /// The TetGen options these flags ask for: every TetGen flag given
    /// replaces its default, the rest keep [`tet_build::tetgen_options::TetgenOptions::default`]. The
    /// one mapping for in-core, out-of-core and job builds.
    /// `--max-steiner P%` is resolved against the scene's
    /// `scene_vertices` (rounded up; the out-of-core parts each get the
    /// resulting cap).
    #[cfg_attr(not(feature = "tetgen"), allow(dead_code))]
    pub fn tetgen_options(
        &self,
        scene_vertices: usize,
    ) -> tet_build::tetgen_options::TetgenOptions {
        let d = tet_build::tetgen_options::TetgenOptions::default();
        tet_build::tetgen_options::TetgenOptions {
            quality: self.quality,
            max_steiner: self.max_steiner.map(|m| m.resolve(scene_vertices)),
            min_dihedral: self.min_dihedral.or(d.min_dihedral),
            optimization: self.optimize.or(d.optimization),
            max_dihedral: self.max_dihedral.or(d.max_dihedral),
            ..d
        }
    }
}

/// `--max-steiner`: a number of Steiner points, or a share of the scene's
/// vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaxSteiner {
    /// At most this many.
    Count(u64),
    /// At most this percentage of the scene's vertices (rounded up).
    Percent(f64),
}

impl MaxSteiner {
    /// The cap for a scene of `vertices` vertices.
    pub fn resolve(self, vertices: usize) -> u64 {
        match self {
            MaxSteiner::Count(n) => n,
            MaxSteiner::Percent(p) => (vertices as f64 * p / 100.0).ceil() as u64,
        }
    }
}

/// Parses `--walls N` (1 to 4096 parts), `--walls auto` or `--walls none`.
fn parse_walls(s: &str) -> Result<Walls, String> {
    if s.trim().eq_ignore_ascii_case("auto") {
        return Ok(Walls::Auto);
    }
    if s.trim().eq_ignore_ascii_case("none") {
        return Ok(Walls::None);
    }
    s.trim()
        .parse::<u32>()
        .ok()
        .filter(|n| (1..=4096).contains(n))
        .map(Walls::Parts)
        .ok_or_else(|| {
            format!("`{s}` is neither a count of parts from 1 to 4096 nor `auto` or `none`")
        })
}

/// Parses `--max-steiner N` or `--max-steiner P%` (P in (0, 1000]).
fn parse_max_steiner(s: &str) -> Result<MaxSteiner, String> {
    match s.strip_suffix('%') {
        Some(p) => p
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|p| *p > 0.0 && *p <= 1000.0)
            .map(MaxSteiner::Percent)
            .ok_or_else(|| format!("`{s}` is not a percentage above 0 and at most 1000")),
        None => s
            .parse::<u64>()
            .map(MaxSteiner::Count)
            .map_err(|_| format!("`{s}` is neither a count of points nor a percentage (`1%`)")),
    }
}

/// Parses `--optimize LEVEL/SCHEME` (`7/7`; a bare `LEVEL` keeps scheme 7).
fn parse_optimization(s: &str) -> Result<tet_build::tetgen_options::Optimization, String> {
    let (level, scheme) = s.split_once('/').unwrap_or((s, "7"));
    let digit = |x: &str, max: u8, what: &str| {
        x.parse::<u8>()
            .ok()
            .filter(|v| *v <= max)
            .ok_or_else(|| format!("{what} `{x}` is not a number from 0 to {max}"))
    };
    Ok(tet_build::tetgen_options::Optimization {
        level: digit(level, 9, "level")?,
        scheme: digit(scheme, 7, "scheme")?,
    })
}
