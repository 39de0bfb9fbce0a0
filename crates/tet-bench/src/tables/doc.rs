//! The plain data of a `tables` run ([`TablesDoc`], written as
//! `tables.json` and printed by `tables --json`): what every table
//! measured, per scene and for the whole run. Field names are a scripted
//! interface: add, never rename or remove.

use serde::Serialize;

use crate::accuracy::{CaseAccuracy, MethodAccuracy};
use crate::load::BuildSummary;
use crate::load::build_flags::BuildFlags;
use crate::methods::layouts::Info;
use crate::outofcore::MemoryReport;
use crate::timing::RenderDoc;
use crate::timing::exitface::ExitFaceTable;

/// True for the scene the papers' Torus Knots numbers belong to: the
/// procedural `torus-knots` or a scenes.json's "Torus Knots".
pub fn is_torus_knots(spec: &str) -> bool {
    spec == "torus-knots" || spec.ends_with("#Torus Knots")
}

/// The machine and settings every table states.
#[derive(Clone, Debug, Serialize)]
pub struct Setup {
    /// Logical CPUs.
    pub cpus: usize,
    /// Worker threads used.
    pub threads: usize,
    /// Image size.
    pub width: u32,
    /// Image size.
    pub height: u32,
    /// Timed frames per method at least (best is reported).
    pub frames: u32,
    /// Seconds of timed frames per method at least: a fast method is timed
    /// over more frames than `frames` until this much time is spent (at
    /// most 200 frames; each render document's `frames` says how many).
    pub min_time_s: f64,
    /// Compile-time CPU features (`target-cpu=native` shows here).
    pub target_features: Vec<&'static str>,
    /// `--quick`.
    pub quick: bool,
    /// OS and architecture.
    pub platform: String,
}

/// Everything measured on one scene.
#[derive(Clone, Debug, Serialize)]
pub struct SceneResult {
    /// Scene spec as given.
    pub spec: String,
    /// Info (counts, bytes per layout, build report).
    pub info: Option<Info>,
    /// BVH build time, s.
    pub bvh_build_s: Option<f64>,
    /// One row per method.
    pub renders: Vec<RenderDoc>,
    /// Primary, AO and shadow rays (`render --rays mixed`) of tet20,
    /// tet16, obvhs and Embree where built with it: every scene in the full
    /// run; in the quick one, none for a scene sharing an earlier scene's
    /// mesh.
    pub secondary: Vec<RenderDoc>,
    /// tet20 on the unsorted (TetGen order) mesh, for Figure 8.
    pub unsorted_tet20: Option<RenderDoc>,
    /// tet20 on the default (Hilbert-sorted) mesh, timed in alternating
    /// rounds with `unsorted_tet20`: the figure to compare it with.
    pub sorted_tet20: Option<RenderDoc>,
    /// tet20 on the mesh built with `--wide-box` (the enclosing box holds
    /// the camera, which primary rays start from), against the default tight
    /// box (rays enter through the boundary).
    pub wide_box_tet20: Option<RenderDoc>,
    /// tet20 on the default (tight-box) mesh, timed in alternating rounds
    /// with `wide_box_tet20`: the figure to compare it with.
    pub tight_box_tet20: Option<RenderDoc>,
    /// The sorted mesh's speed-up over the unsorted one in each
    /// alternating round (empty when not measured).
    #[serde(default)]
    pub sorting_round_speedups: Vec<f64>,
    /// The tight box's speed-up over the wide one in each alternating
    /// round (empty when not measured).
    #[serde(default)]
    pub tight_box_round_speedups: Vec<f64>,
    /// Accuracy against the f64 reference.
    pub accuracy: Option<CaseAccuracy>,
    /// Ray-Strips beside the BVH (Lauterbach et al. 2007, Tables 1, 3, 4, 5).
    pub ray_strips: Option<StripsRow>,
    /// GPU methods (Aman et al. 2022, Table 3), when built with `--features gpu` and
    /// an adapter is present.
    pub gpu_renders: Vec<RenderDoc>,
    /// Why there are no GPU rows, if there are none.
    pub gpu_note: Option<String>,
    /// The build trade (full mode only): the same scene built with the
    /// quality bound `-q5`, and tet20 on it.
    pub quality5: Option<QualityTrade>,
    /// Full mode: the scene built with slivers bounded
    /// (`--min-dihedral 2`) and tet20 on it.
    pub min_dihedral2: Option<QualityTrade>,
    /// Full mode: slivers bounded with at most 1 % of the scene's vertices
    /// as refinement points and no mesh optimisation
    /// (`--min-dihedral 2 --optimize 0/0 --max-steiner 1%`).
    pub min_dihedral2_capped: Option<QualityTrade>,
    /// Full mode: the default build, in parts with walls between them
    /// (`--walls auto`, `-pY` in each): the mesh of the other tables.
    pub walls: Option<QualityTrade>,
    /// Full mode: the scene built in one TetGen run (`--walls none`).
    pub one_piece: Option<QualityTrade>,
    /// Out-of-core builds under ½ and ⅓ of the in-core peak (full mode,
    /// first scene of each geometry only).
    pub out_of_core: Vec<OutOfCoreRow>,
    /// Other scenes of the run with the same geometry: the mesh was built
    /// once for all of them (box around all their cameras and lights).
    pub shares_mesh_with: Vec<String>,
    /// True when this scene's mesh came from that shared build.
    pub mesh_reused: bool,
    /// Measurements on meshes of their own (unsorted, wide box, refined
    /// builds) that failed, each `"what: why"`; their fields are null and
    /// the rest of the scene is measured.
    pub partial_errors: Vec<String>,
    /// Why the scene failed, if it did.
    pub error: Option<String>,
}

/// One out-of-core build of a scene.
#[derive(Clone, Debug, Serialize)]
pub struct OutOfCoreRow {
    /// Fraction of the in-core peak in the limit (0.5, 0.333…): the limit
    /// is the builder's own share (`memory.own_bytes`) plus this fraction
    /// of the in-core TetGen peak.
    pub fraction: f64,
    /// The in-core build's measured TetGen peak, KiB (the limit holds a
    /// fraction of it; of the prediction when not measured).
    pub in_core_peak_kib: Option<u64>,
    /// The in-core build's total seconds.
    pub in_core_s: f64,
    /// The in-core mesh's tets.
    pub in_core_tets: usize,
    /// Limit, parts, peaks, time.
    pub memory: Option<MemoryReport>,
    /// Tets of the merged mesh.
    pub tets: usize,
    /// tet20 on the merged mesh.
    pub tet20: Option<RenderDoc>,
    /// Tet quality of the in-core mesh (Erkoç et al. 2021, Table 3).
    pub in_core_quality: Option<Quality>,
    /// Tet quality of the merged mesh.
    pub quality: Option<Quality>,
    /// Why the build failed, if it did.
    pub error: Option<String>,
}

/// Tet quality (Erkoç et al. 2021, Table 3: aspect ratio = longest edge ÷ smallest
/// height; also the radius-edge ratio).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Quality {
    /// Smallest aspect ratio.
    pub aspect_min: f64,
    /// Largest aspect ratio.
    pub aspect_max: f64,
    /// Mean aspect ratio.
    pub aspect_mean: f64,
    /// Smallest radius-edge ratio.
    pub radius_edge_min: f64,
    /// Largest radius-edge ratio.
    pub radius_edge_max: f64,
    /// Mean radius-edge ratio.
    pub radius_edge_mean: f64,
}

/// A quality-refined build and its traversal speed.
#[derive(Clone, Debug, Serialize)]
pub struct QualityTrade {
    /// Tets.
    pub tets: usize,
    /// Construction report.
    pub build: Option<BuildSummary>,
    /// tet20 on the refined mesh.
    pub tet20: RenderDoc,
}

/// The `tables` document (also written as `tables.json`).
#[derive(Clone, Debug, Serialize)]
pub struct TablesDoc {
    /// Machine and settings.
    pub setup: Setup,
    /// Per scene.
    pub scenes: Vec<SceneResult>,
    /// Exit-face search (Maria et al. 2017, Table 5), single thread.
    pub exit_face: Option<ExitFaceTable>,
    /// Speed against accuracy per method and precision on the first scene,
    /// as given and at the extremes (scaled, translated, slivers).
    pub speed_accuracy: Option<SpeedAccuracy>,
    /// Isosurfaces of tet volumes (Wald et al. 2007, Tables 1, 2, 4), per synthetic
    /// volume.
    pub isosurfaces: Vec<IsoRow>,
    /// Isosurfaces as the model grows: the bucky cube replicated n³ times
    /// (Wald et al. 2007, Table 3).
    pub iso_scaling: Vec<IsoScaleRow>,
    /// Why there is no out-of-core table, if there is none.
    pub out_of_core_note: Option<String>,
    /// Large models (Lauterbach et al. 2007, §6): Ray-Strips, the BVH and Tet20 as the
    /// Torus Knots' tessellation grows, one row per size.
    pub large_models: Vec<LargeModelRow>,
    /// Why there is no large-model table, if there is none.
    pub large_models_note: Option<String>,
    /// Out-of-core builds of large closed meshes (`fan-sphere:N`) under a
    /// small fraction of their in-core peak, one row per size.
    pub large_out_of_core: Vec<LargeOutOfCoreRow>,
    /// Why there is no large out-of-core table, if there is none.
    pub large_out_of_core_note: Option<String>,
    /// SVG figures written (paths).
    pub figures: Vec<String>,
    /// Wall time of the whole run, s.
    pub total_s: f64,
}

/// How every scene of the tables is built: self-intersections resolved,
/// TetGen `-pY` in a box cut into parts with walls between them
/// (`--walls auto`, the default), Hilbert order, the default time limit.
pub const TABLE_FLAGS: BuildFlags = BuildFlags {
    quality: None,
    min_dihedral: None,
    max_steiner: None,
    optimize: None,
    max_dihedral: None,
    time_limit: 600.0,
    no_box: false,
    wide_box: false,
    no_sort: false,
    no_resolve: false,
    walls: None,
};

/// Speed against accuracy (Maria et al. 2017, Table 4 beside render speed): every CPU method in f32 and,
/// where it has one, f64, on the first scene as given and on its extreme
/// cases ([`crate::accuracy::extremes`]).
#[derive(Clone, Debug, Serialize)]
pub struct SpeedAccuracy {
    /// The scene's spec.
    pub scene: String,
    /// `as-is`, then the extreme cases (JSON as `accuracy`'s `cases[]`).
    pub cases: Vec<CaseAccuracy>,
    /// Why it is missing, when the scene could not be loaded.
    pub error: Option<String>,
}

/// What Ray-Strips measured on one scene (JSON `scenes[].ray_strips`).
#[derive(Clone, Debug, Serialize)]
pub struct StripsRow {
    /// Triangles stored.
    pub triangles: usize,
    /// Strips.
    pub strips: usize,
    /// Triangles per strip, mean.
    pub mean_strip_triangles: f64,
    /// Chunks of the SAH stage.
    pub chunks: usize,
    /// Ray-Strips build, s.
    pub build_s: f64,
    /// obvhs BVH build over the same triangles, s.
    pub bvh_build_s: f64,
    /// Ray-Strips geometry bytes (vertices, strip indices, triangle words).
    pub geometry_bytes: usize,
    /// Strip hierarchies, bytes.
    pub hierarchy_bytes: usize,
    /// BVH over the strips, bytes.
    pub top_level_bytes: usize,
    /// Everything, bytes.
    pub total_bytes: usize,
    /// The obvhs BVH's nodes, bytes.
    pub bvh_hierarchy_bytes: usize,
    /// The obvhs BVH's precomputed triangles and face ids, bytes.
    pub bvh_geometry_bytes: usize,
    /// `strips-packets` render of the same view.
    pub packets: RenderDoc,
}

/// The isosurface methods on one synthetic volume (JSON `isosurfaces[]`).
#[derive(Clone, Debug, Serialize)]
pub struct IsoRow {
    /// Synthetic volume name.
    pub volume: String,
    /// One `iso` document per method.
    pub docs: Vec<crate::iso::IsoDoc>,
    /// Why the volume failed, if it did.
    pub error: Option<String>,
}

/// One size of the isosurface scaling table (JSON `iso_scaling[]`).
#[derive(Clone, Debug, Serialize)]
pub struct IsoScaleRow {
    /// Balls per axis (`buckycube --replications N`).
    pub replications: u32,
    /// Balls in all (`replications³`).
    pub balls: u32,
    /// One `iso` document per method (`ibvh-packets`, `walk-tet20`).
    pub docs: Vec<crate::iso::IsoDoc>,
    /// Why the size failed, if it did.
    pub error: Option<String>,
}

/// One size of the large-model table (JSON `large_models[]`).
#[derive(Clone, Debug, Serialize)]
pub struct LargeModelRow {
    /// Scene spec (`dense-knots:N`).
    pub scene: String,
    /// Scene triangles.
    pub triangles: usize,
    /// Ray-Strips, obvhs and, where it was built, tet20.
    pub structures: Vec<LargeStructure>,
    /// Why a structure is missing (e.g. TetGen's predicted peak).
    pub note: Option<String>,
    /// Why the whole size failed or was skipped.
    pub error: Option<String>,
}

/// One size of the large out-of-core table (JSON `large_out_of_core[]`).
#[derive(Clone, Debug, Serialize)]
pub struct LargeOutOfCoreRow {
    /// Scene spec (`fan-sphere:N`).
    pub scene: String,
    /// Scene triangles.
    pub triangles: usize,
    /// The memory model's prediction of an in-core TetGen run's peak, bytes.
    pub predicted_in_core_bytes: u64,
    /// The limit on the whole process tree: the builder's own share plus
    /// a sixteenth of `predicted_in_core_bytes`, bytes.
    pub limit_bytes: u64,
    /// The build's memory report (parts, peaks, time).
    pub memory: Option<MemoryReport>,
    /// Tets of the merged mesh.
    pub tets: usize,
    /// tet20 on the merged mesh.
    pub tet20: Option<RenderDoc>,
    /// tet20 (f32) against the f64 reference on the merged mesh: its
    /// camera image (256²) and 20,000 random rays.
    pub accuracy: Option<MethodAccuracy>,
    /// Why the size failed, if it did.
    pub error: Option<String>,
}

/// One structure on one large model (JSON `large_models[].structures[]`).
#[derive(Clone, Debug, Serialize)]
pub struct LargeStructure {
    /// `strips`, `obvhs` or `tet20` (the render method's name).
    pub structure: String,
    /// Bytes of the structure including the vertices.
    pub bytes: usize,
    /// `bytes` per scene triangle.
    pub bytes_per_triangle: f64,
    /// Build seconds (tet20: the whole pipeline, TetGen included; out of
    /// core, the build process's wall time, writing and reading back the
    /// mesh file included).
    pub build_s: f64,
    /// The timed render.
    pub render: RenderDoc,
    /// Tet20 built out of core: the build's memory report (the limit,
    /// parts, part and process-tree peaks, merge; `memory` of `build
    /// --json`); `null` in core and for the triangle structures.
    pub memory: Option<crate::outofcore::MemoryReport>,
}
