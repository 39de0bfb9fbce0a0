//! Scenes and mesh files: what a `SCENE|FILE` argument becomes — a mesh
//! with its camera and lights — how a scene's mesh is built
//! ([`build_flags`]), and where the camera stands ([`camera`]).
//!
//! This module resolves the argument: a mesh file is loaded, a scene is
//! loaded and built (TetGen in a worker process, killed at the time limit).

use std::path::Path;
#[cfg(feature = "tetgen")]
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use glam::Vec3;
use tet_build::resolve::ResolveReport;
use tet_build::scene::Scene;
use tet_core::TetMesh;
use tet_core::scene::{Camera, PointLight};

pub mod build_flags;
pub mod camera;

use build_flags::BuildFlags;
use camera::{ViewArgs, ViewError, apply_view, framing_camera};

/// File extension of mesh files written by `tet-bench build`.
pub const MESH_EXTENSION: &str = "tmesh";

/// A mesh ready to trace, with what is known of its scene.
pub struct Loaded {
    /// Name for reports.
    pub name: String,
    /// The mesh.
    pub mesh: TetMesh,
    /// The scene it was built from (absent for mesh files).
    pub scene: Option<Scene>,
    /// Camera (the scene's, or one framing it from outside; `--eye` and
    /// the other view flags replace parts of it).
    pub camera: Camera,
    /// Point lights (the scene's, or one at the camera).
    pub lights: Vec<PointLight>,
    /// Construction report when built here.
    pub build: Option<BuildSummary>,
}

/// What a build cost.
#[derive(Clone, Debug, serde::Serialize)]
pub struct BuildSummary {
    /// TetGen switches.
    pub switches: String,
    /// Scene triangles after cleaning.
    pub scene_triangles: usize,
    /// Steiner points added.
    pub steiner_points: usize,
    /// Seconds: cleaning.
    pub clean_s: f64,
    /// Seconds: resolving self-intersections (on a clean scene, only the
    /// exact check that finds none).
    pub resolve_s: f64,
    /// Seconds: TetGen (including worker start and transfer).
    pub tetgen_s: f64,
    /// Seconds: neighbours, constrained faces and validation.
    pub assemble_s: f64,
    /// Seconds: Hilbert reordering (0 when skipped).
    pub reorder_s: f64,
    /// Seconds: everything.
    pub total_s: f64,
    /// Peak resident memory of the TetGen worker, KiB.
    pub worker_peak_kib: Option<u64>,
    /// Cleaning: vertices merged, triangles dropped (repeated vertex, zero
    /// area, duplicate), unused vertices removed.
    pub cleaning: CleaningSummary,
    /// Resolving self-intersections: pairs found, triangles split, points
    /// added, pieces merged, rounds (all zero for a clean scene).
    pub resolve: ResolveReport,
}

/// Counts of what cleaning changed.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct CleaningSummary {
    /// Exactly-equal vertices merged.
    pub merged_vertices: usize,
    /// Triangles dropped for a repeated vertex.
    pub repeated_vertex_triangles: usize,
    /// Triangles dropped for zero area.
    pub zero_area_triangles: usize,
    /// Exact duplicate triangles dropped.
    pub duplicate_triangles: usize,
    /// Unused vertices removed.
    pub unused_vertices: usize,
}

impl Loaded {
    /// Replaces the parts of the camera given in `view` (`--eye`,
    /// `--target`, `--up`, `--fov`), checked; the lights stay where they are.
    pub fn set_view(&mut self, view: &ViewArgs) -> Result<(), ViewError> {
        self.camera = apply_view(self.camera, view)?;
        Ok(())
    }
}

/// Loads a mesh file, or loads and builds a scene.
pub fn load(spec: &str, flags: &BuildFlags, quiet: bool) -> Result<Loaded> {
    let path = Path::new(spec);
    if path.extension().is_some_and(|e| e == MESH_EXTENSION) {
        // The camera and lights stored with the mesh (`tet-bench build`
        // writes the scene's), else a camera framing the mesh from outside.
        let (mesh, stored) = tet_core::format::load_with_scene(path)?;
        let camera = stored.camera.unwrap_or_else(|| framing_camera(&mesh));
        let lights = if stored.lights.is_empty() {
            vec![light_at(camera.position)]
        } else {
            stored.lights
        };
        return Ok(Loaded {
            name: path
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default(),
            mesh,
            scene: None,
            camera,
            lights,
            build: None,
        });
    }
    let scene = Scene::load(spec).with_context(|| format!("cannot load scene `{spec}`"))?;
    from_scene(scene, flags, quiet)
}

/// Builds a loaded scene.
pub fn from_scene(scene: Scene, flags: &BuildFlags, quiet: bool) -> Result<Loaded> {
    let (mesh, build) = build_scene(&scene, flags, quiet)?;
    Ok(with_mesh(scene, mesh, Some(build)))
}

/// A scene with its already built mesh (camera and lights from the scene,
/// or a camera framing the scene from outside and a light at the camera).
pub fn with_mesh(scene: Scene, mesh: TetMesh, build: Option<BuildSummary>) -> Loaded {
    let camera = scene.camera.unwrap_or_else(|| framing_camera(&mesh));
    let lights = if scene.lights.is_empty() {
        vec![light_at(camera.position)]
    } else {
        scene.lights.clone()
    };
    Loaded {
        name: scene.name.clone(),
        mesh,
        scene: Some(scene),
        camera,
        lights,
        build,
    }
}

/// Relative margin of the tight enclosing box (of the scene's largest
/// extent): thin, so that few tets lie between the box and the scene.
#[cfg_attr(not(feature = "tetgen"), allow(dead_code))]
pub const TIGHT_BOX_MARGIN: f32 = 0.002;

/// The enclosing box. By default it holds the scene only, grown by
/// [`TIGHT_BOX_MARGIN`] of its largest extent: cameras and lights may lie
/// outside, where primary rays enter the mesh through its boundary
/// (`tet_trace_cpu::boundary_entry`) and shadow rays leave it unoccluded. With
/// `wide`, it also holds the camera, the lights and `extra` points (the
/// cameras and lights of other scenes sharing this mesh), grown by 10 %:
/// every ray then starts inside the mesh and walks the empty space
/// between the camera and the scene (the layout of the papers' meshes).
#[cfg(feature = "tetgen")]
pub fn enclosing_box(scene: &Scene, extra: &[Vec3], wide: bool) -> tet_build::bbox::BoxSpec {
    let mut pts: Vec<Vec3> = scene.vertices.clone();
    if wide {
        pts.extend(scene.camera.iter().map(|c| c.position));
        pts.extend(scene.lights.iter().map(|l| l.position));
        pts.extend_from_slice(extra);
    }
    let (min, max) = pts
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), p| {
            (a.min(*p), b.max(*p))
        });
    let relative = if wide { 0.1 } else { TIGHT_BOX_MARGIN };
    // Relative to the scene only: an absolute floor would dwarf a scene at
    // 1e-30 (its box would be 1e24 times its size).
    let margin =
        ((max - min).max_element() * relative).max(1e-3 * max.abs().max(min.abs()).max_element());
    let margin = if margin > 0.0 && margin.is_finite() {
        margin
    } else {
        1e-6
    };
    tet_build::bbox::BoxSpec::Fixed {
        min: min - Vec3::splat(margin),
        max: max + Vec3::splat(margin),
    }
}

/// Builds a scene's mesh (TetGen in a worker process), Hilbert-sorted unless `--no-sort`.
#[cfg(feature = "tetgen")]
pub fn build_scene(
    scene: &Scene,
    flags: &BuildFlags,
    quiet: bool,
) -> Result<(TetMesh, BuildSummary)> {
    build_scene_in(scene, flags, quiet, &[])
}

/// The out-of-core builder's options for `scene` built with `flags`: the
/// enclosing box (holding `extra` points too), TetGen switches, worker
/// isolation and self-intersection resolving, as a one-piece build has
/// them; one part at a time and no limit on the process tree (callers
/// that run parts in parallel or under a limit set those).
#[cfg(feature = "tetgen")]
pub fn seam_options(
    scene: &Scene,
    flags: &BuildFlags,
    extra: &[Vec3],
) -> Result<tet_build::outofcore::seam::SeamOptions> {
    Ok(tet_build::outofcore::seam::SeamOptions {
        enclosing_box: enclosing_box(scene, extra, flags.wide_box),
        tetgen: flags.tetgen_options(scene.vertices.len()),
        isolation: worker_isolation(flags.time_limit)?,
        parallel_parts: 1,
        tree_limit_bytes: None,
        resolve: (!flags.no_resolve).then(Default::default),
        surface_relaxed_parts: Vec::new(),
    })
}

/// The TetGen worker: this executable re-run as `tet-bench tetgen-worker`,
/// killed after `time_limit` seconds.
#[cfg(feature = "tetgen")]
pub fn worker_isolation(time_limit: f64) -> Result<tet_build::tetgen::Isolation> {
    use tet_build::tetgen::{Isolation, WorkerCommand};
    Ok(Isolation::Worker(WorkerCommand {
        program: std::env::current_exe().context("cannot find this executable")?,
        args: vec!["tetgen-worker".into()],
        timeout: Some(Duration::from_secs_f64(time_limit.max(0.001))),
    }))
}

/// [`build_scene`] with `extra` points inside the enclosing box (the
/// cameras and lights of other scenes that share this mesh).
#[cfg(feature = "tetgen")]
pub fn build_scene_in(
    scene: &Scene,
    flags: &BuildFlags,
    quiet: bool,
    extra: &[Vec3],
) -> Result<(TetMesh, BuildSummary)> {
    use std::sync::Arc;
    use tet_build::pipeline::{BuildOptions, build};

    let walls = flags.walls();
    if walls != build_flags::Walls::None {
        return build_walled(scene, flags, walls, quiet, extra);
    }
    let start = Instant::now();
    let spinner = spinner(quiet);
    let pb = spinner.clone();
    let name = scene.name.clone();
    let mut options = BuildOptions {
        isolation: worker_isolation(flags.time_limit)?,
        enclosing_box: (!flags.no_box).then(|| enclosing_box(scene, extra, flags.wide_box)),
        progress: Some(Arc::new(move |p: &tet_build::pipeline::Progress| {
            pb.set_message(format!("building {name}: {:?}", p.stage));
        })),
        ..BuildOptions::default()
    };
    if flags.no_resolve {
        options.resolve = None;
    }
    options.tetgen = flags.tetgen_options(scene.vertices.len());
    if !flags.no_sort {
        // Hilbert order inside the pipeline: parallel, one gather per array.
        options.reorder = tet_build::pipeline::Reorder::Hilbert;
    }
    let (mesh, report) = build(scene, &options)
        .with_context(|| format!("cannot build a tetrahedral mesh of `{}`", scene.name))?;
    let reorder_s = report.times.reorder.as_secs_f64();
    spinner.finish_and_clear();
    let t = report.times;
    let summary = BuildSummary {
        switches: report.switches.clone(),
        scene_triangles: report.scene_triangles,
        steiner_points: report.steiner_points,
        clean_s: t.clean.as_secs_f64(),
        resolve_s: t.resolve.as_secs_f64(),
        tetgen_s: t.tetgen.as_secs_f64(),
        assemble_s: (t.constrained_faces + t.assemble + t.validate + t.rounding).as_secs_f64(),
        reorder_s,
        total_s: start.elapsed().as_secs_f64(),
        worker_peak_kib: report.worker_peak_memory_kib,
        cleaning: CleaningSummary {
            merged_vertices: report.clean.merged_vertices.len(),
            repeated_vertex_triangles: report.clean.repeated_vertex_triangles.len(),
            zero_area_triangles: report.clean.zero_area_triangles.len(),
            duplicate_triangles: report.clean.duplicate_triangles.len(),
            unused_vertices: report.clean.unused_vertices.len(),
        },
        resolve: report.resolve.clone(),
    };
    Ok((mesh, summary))
}

/// `--walls`: a scene built as parts with exact walls between them, in
/// memory, even when it would fit one TetGen run. The out-of-core
/// builder's recursive planes (Erkoç et al. 2021) cut the enclosing
/// box ([`build_flags::Walls`] says how finely), each part is tetrahedralized by its own
/// TetGen worker (as many at once as there are cores), and the parts merge
/// exactly. Why: an unrefined `-pY` CDT fills empty space with long fans
/// of slivers from the fine surface to the box's corners, which every ray
/// must cross; the walls cut those fans short (measured in the README's
/// "Walls instead of points").
///
/// The merged mesh is Hilbert-sorted as a whole unless `flags.no_sort`.
#[cfg(feature = "tetgen")]
fn build_walled(
    scene: &Scene,
    flags: &BuildFlags,
    walls: build_flags::Walls,
    quiet: bool,
    extra: &[Vec3],
) -> Result<(TetMesh, BuildSummary)> {
    if flags.no_box {
        bail!(
            "`{}`: --walls cuts the enclosing box into parts: drop --no-box",
            scene.name
        );
    }
    let start = Instant::now();
    let spinner = spinner(quiet);
    let depth = walls.depth(scene.triangles.len());
    spinner.set_message(format!("building {} in parts with walls", scene.name));
    let options = tet_build::outofcore::seam::SeamOptions {
        parallel_parts: std::thread::available_parallelism().map_or(1, |n| n.get()),
        ..seam_options(scene, flags, extra)?
    };
    // `auto`: the parts as the memory planner cuts them for a small
    // target (dense regions split, light ones and empty margins left
    // whole), or, should that build fail, every part split to `depth`.
    // `N`: every part split to `depth`.
    use tet_build::outofcore::split::SplitOptions;
    let uniform = SplitOptions {
        limit_bytes: u64::MAX,
        min_depth: depth,
        ..SplitOptions::default()
    };
    use build_flags::Walls;
    let splits = match walls {
        Walls::Auto => vec![SplitOptions::shaped_for_rays(u64::MAX), uniform],
        Walls::Parts(_) | Walls::None => vec![uniform],
    };
    let tetgen_start = Instant::now();
    let mut built = None;
    // Why a split before the one that built failed (the switches say).
    let mut note = String::new();
    for (i, split) in splits.iter().enumerate() {
        match tet_build::outofcore::tree::build_tree_with_memory_limit(scene, split, &options) {
            Ok(b) => {
                built = Some(Ok(b));
                break;
            }
            Err(e) => {
                if !quiet && i + 1 < splits.len() {
                    eprintln!(
                        "{}: walls failed: {e}; trying every part cut to depth {depth}",
                        scene.name
                    );
                }
                note = format!(" (the parts shaped for rays failed: {e})");
                built = Some(Err(e));
            }
        }
    }
    let (mut mesh, report, plan) = match built.expect("at least one split is tried") {
        Ok(b) => b,
        // `auto` promises a mesh: where no walled build succeeds, the
        // scene is built in one piece, and the switches say why.
        Err(e) if walls == Walls::Auto => {
            spinner.finish_and_clear();
            let reason = format!("walls failed: {e}");
            if !quiet {
                eprintln!("{}: {reason}; building it in one piece", scene.name);
            }
            let one_piece = BuildFlags {
                walls: Some(Walls::None),
                ..*flags
            };
            let (mesh, mut summary) = build_scene_in(scene, &one_piece, quiet, extra)?;
            summary.switches = format!("{} ({reason})", summary.switches);
            return Ok((mesh, summary));
        }
        Err(e) => {
            return Err(e)
                .with_context(|| format!("cannot build `{}` in parts with walls", scene.name));
        }
    };
    let tetgen_s = tetgen_start.elapsed().as_secs_f64();
    let reorder_start = Instant::now();
    if !flags.no_sort {
        tet_core::reorder::hilbert_reorder(&mut mesh)?;
    }
    let reorder_s = reorder_start.elapsed().as_secs_f64();
    spinner.finish_and_clear();
    // Points that are no scene vertex: the walls' and TetGen's.
    let scene_points: std::collections::HashSet<[u32; 3]> = scene
        .vertices
        .iter()
        .map(|p| (*p + Vec3::ZERO).to_array().map(f32::to_bits))
        .collect();
    let added = mesh
        .points
        .iter()
        .filter(|p| !scene_points.contains(&(**p + Vec3::ZERO).to_array().map(f32::to_bits)))
        .count();
    let summary = BuildSummary {
        switches: format!(
            "{} in {} parts{}{note}",
            options.tetgen.switches(),
            report.part_tets.len(),
            match plan.plane_moves {
                0 => String::new(),
                1 => ", walls moved once".to_string(),
                n => format!(", walls moved {n} times"),
            }
        ),
        // The input triangles the mesh holds a face of (cleaning drops
        // degenerate ones).
        scene_triangles: {
            let mut ids: Vec<u32> = mesh.constrained.iter().map(|f| f.triangle).collect();
            ids.sort_unstable();
            ids.dedup();
            ids.len()
        },
        steiner_points: added,
        // Cleaning, resolving, the cut and the merge are inside `tetgen_s`.
        clean_s: 0.0,
        resolve_s: 0.0,
        tetgen_s,
        assemble_s: 0.0,
        reorder_s,
        total_s: start.elapsed().as_secs_f64(),
        worker_peak_kib: report.part_peak_kib.iter().flatten().copied().max(),
        cleaning: CleaningSummary::default(),
        resolve: report.resolve.clone().unwrap_or_default(),
    };
    Ok((mesh, summary))
}

/// Without TetGen, scenes cannot be built.
#[cfg(not(feature = "tetgen"))]
pub fn build_scene(scene: &Scene, f: &BuildFlags, q: bool) -> Result<(TetMesh, BuildSummary)> {
    build_scene_in(scene, f, q, &[])
}

/// Without TetGen, scenes cannot be built.
#[cfg(not(feature = "tetgen"))]
pub fn build_scene_in(
    scene: &Scene,
    _: &BuildFlags,
    _: bool,
    _: &[Vec3],
) -> Result<(TetMesh, BuildSummary)> {
    bail!(
        "`{}` is a scene, but this tet-bench was built without the `tetgen` feature: \
         pass a .{MESH_EXTENSION} mesh file instead",
        scene.name
    )
}

/// A white point light of intensity 1 at `position`.
fn light_at(position: Vec3) -> PointLight {
    PointLight {
        position,
        color: Vec3::ONE,
        intensity: 1.0,
    }
}

/// A progress spinner on stderr (hidden when `quiet`).
pub fn spinner(quiet: bool) -> indicatif::ProgressBar {
    if quiet {
        indicatif::ProgressBar::hidden()
    } else {
        let pb = indicatif::ProgressBar::new_spinner();
        pb.enable_steady_tick(std::time::Duration::from_millis(120));
        pb
    }
}

/// Fails with a helpful message when the mesh is empty.
pub fn require_tets(loaded: &Loaded) -> Result<()> {
    if loaded.mesh.tets.is_empty() {
        bail!("`{}` has no tetrahedra", loaded.name);
    }
    Ok(())
}
