//! The build pipeline: scene → clean → optional enclosing box → TetGen →
//! exact f32 rounding check → constrained faces → [`TetMesh::assemble`] →
//! [`TetMesh::validate`].
//!
//! * **Cleaning** ([`crate::clean::clean_scene`]) merges exactly equal
//!   vertices and drops degenerate and duplicate triangles; the constrained
//!   faces keep the *input* scene triangle ids (`CleanMesh::triangle_source`).
//! * **Enclosing box** ([`crate::bbox`], optional): its 12 triangles are
//!   given TetGen facet marker 0, so they become mesh boundary, never
//!   constrained faces. Scene triangle `i` (after cleaning) gets marker `i + 1`.
//! * **TetGen** runs with `-pY` (surface preserving; Aman et al. and Maria et
//!   al. build their meshes this way) in process or isolated
//!   ([`crate::tetgen::Isolation`]).
//! * **Coverage**: every scene triangle must come back as exactly one
//!   constrained face with the same three vertices (with `-Y` TetGen may not
//!   split it); anything else is [`BuildError::TriangleNotPreserved`].
//! * **Rounding**: TetGen computes Steiner points in f64, the mesh stores
//!   f32. Every tet is checked with the exact f32 orientation. If rounding
//!   flattened or inverted some, each Steiner point of those tets is first
//!   *snapped*: among the f32 values within ±2 ulps of its f64 position
//!   (nearest first) the pipeline picks one that makes every tet around it
//!   positive (exact test), keeping TetGen's connectivity — the mesh stays a
//!   valid tetrahedralization of the same domain with the same constrained
//!   faces, only no longer exactly Delaunay near that point. Where snapping
//!   cannot fix a tet, TetGen is run again with the rounded Steiner points
//!   as ordinary input points (its exact predicates then see the very
//!   coordinates we store), up to [`BuildOptions::max_rounding_rounds`]
//!   times; a failure of such a re-run (e.g. a rounded point landing on a
//!   facet) or exhausting the rounds is [`BuildError::RoundingFlattens`],
//!   naming the tets. Input points are f32 and convert to f64 exactly, so
//!   tets made of input points only are never affected.
//! * **Normals at merged vertices**: the mesh stores one normal per point,
//!   but a scene vertex merged from copies with different normals (a crease:
//!   the corners of a flat-shaded box carry three face normals) has none
//!   that is right for all its triangles, and keeping the first copy's
//!   normal would bend the shading of every other face there. Such points
//!   get a zero normal, which the tracers read as "no vertex normal": a
//!   triangle whose three corners are all creases (a box face) is shaded
//!   with its geometric normal, others interpolate only their smooth
//!   corners. Steiner points and box corners also get zero normals. Exact
//!   per-corner shading needs per-triangle corner normals in
//!   [`tet_core::mesh::Attributes`] (not there yet); the conflicts are listed
//!   in [`CleanReport::attribute_conflicts`].
//! * **Assembly** ([`Assembly`]): by default the neighbour links are TetGen's
//!   own (`-nn`: tet neighbours and the two tets of every output face), so
//!   no face keys are sorted; [`Assembly::SortFaceKeys`] runs
//!   [`TetMesh::assemble`] instead. Both give the same mesh, field by field
//!   (tested on several scenes).
//! * **Reordering** ([`Reorder::Hilbert`], optional): points and tets sorted
//!   along a Hilbert curve, exactly as [`tet_core::reorder::hilbert_reorder`]
//!   would (same permutations, tested), but in parallel and in one gather
//!   per array.
//! * **Validation** ([`Validation`]): the result always passes
//!   [`TetMesh::validate`]; the pipeline never returns a mesh that does not.
//!   By default ([`Validation::Construction`]) it checks every invariant of
//!   `validate` except the one the rounding stage has already decided
//!   exactly (every tet positively oriented on the stored f32 points, which
//!   also implies four distinct vertices), with linear-time checks instead
//!   of a global sort; [`Validation::Full`] runs [`TetMesh::validate`].

#![cfg(feature = "tetgen")]

use std::sync::Arc;
use std::time::{Duration, Instant};

use glam::{DVec3, Vec2, Vec3};
use rayon::prelude::*;
use tet_core::hilbert::Quantizer;
use tet_core::link::{Link, LinkKind, MAX_TETS};
use tet_core::mesh::{Attributes, ConstrainedFace, FACE_VERTICES, FaceSide, face_key};
use tet_core::reorder::Reordering;
use tet_core::{MeshError, TetMesh};
use thiserror::Error;

use crate::bbox::{BoxError, BoxSpec, EnclosingBox};
use crate::clean::{CleanError, CleanReport, clean_scene};
use crate::intersect::{IntersectingPair, find_self_intersections};
use crate::scene::Scene;
use crate::tetgen::worker::peak_memory_kib;
use crate::tetgen::{Isolation, TetgenError, TetgenInput, TetgenOptions, tetrahedralize};

/// Progress callback, called at the start of every stage.
pub type ProgressFn = Arc<dyn Fn(&Progress) + Send + Sync>;

/// A stage of [`build`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Cleaning the scene.
    Clean,
    /// Adding the enclosing box.
    EnclosingBox,
    /// Running TetGen (round 1, 2, … when rounding forces a re-run).
    Tetgen {
        /// 1-based round.
        round: u32,
    },
    /// Checking tets after rounding points to f32.
    Rounding,
    /// Matching TetGen's faces to scene triangles.
    ConstrainedFaces,
    /// Building neighbours and the constrained-face table.
    Assemble,
    /// Hilbert reordering ([`Reorder::Hilbert`] only).
    Reorder,
    /// Validating the mesh.
    Validate,
}

/// How [`build`] turns TetGen's tets into neighbour links and the
/// constrained-face table. Both give the same [`TetMesh`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Assembly {
    /// Read TetGen's own adjacency (`-nn`): the neighbour of each tet face
    /// and the two tets of each constrained face. Linear time, no sorting.
    #[default]
    TetgenNeighbors,
    /// [`TetMesh::assemble`]: neighbours found by sorting all face keys
    /// (the reference; ignores TetGen's adjacency).
    SortFaceKeys,
}

/// Memory order of the mesh [`build`] returns.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Reorder {
    /// TetGen's order (points: scene vertices, box corners, Steiner points).
    #[default]
    None,
    /// Points by the Hilbert key of their position, tets by that of their
    /// centroid, constrained faces by tet: the same permutations as
    /// [`tet_core::reorder::hilbert_reorder`] (Aman et al. §5), computed in
    /// parallel. The permutations are returned in [`BuildReport::reordering`].
    Hilbert,
}

/// How [`build`] checks the finished mesh. Either way, a mesh that would
/// fail [`TetMesh::validate`] is never returned.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Validation {
    /// Every invariant of [`TetMesh::validate`] except tet orientation (and
    /// the distinct-vertices check it implies), which the rounding stage has
    /// decided exactly on the final f32 coordinates of every tet (a build
    /// with a non-positive tet fails there). Linear time: links, the
    /// constrained-face table and face manifoldness (each face key in at
    /// most one linked pair or unlinked face) without a global sort.
    #[default]
    Construction,
    /// [`TetMesh::validate`], which also re-checks orientation (slower:
    /// sorts every face key, single-threaded).
    Full,
}

/// What [`build`] reports to the progress callback.
#[derive(Clone, Debug, PartialEq)]
pub struct Progress {
    /// The stage starting now.
    pub stage: Stage,
    /// Time since the build started.
    pub elapsed: Duration,
}

/// Options of [`build`].
#[derive(Clone)]
pub struct BuildOptions {
    /// TetGen switches (default `-pYc`: surface preserving, no quality refinement).
    pub tetgen: TetgenOptions,
    /// Where TetGen runs.
    pub isolation: Isolation,
    /// Enclosing box around the scene (its faces become the mesh boundary).
    pub enclosing_box: Option<BoxSpec>,
    /// How many extra TetGen runs may be spent repairing f32 rounding.
    pub max_rounding_rounds: u32,
    /// Called at the start of each stage.
    pub progress: Option<ProgressFn>,
    /// How neighbours and constrained faces are built.
    pub assembly: Assembly,
    /// Memory order of the result.
    pub reorder: Reorder,
    /// How the result is checked.
    pub validation: Validation,
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions {
            tetgen: TetgenOptions::default(),
            isolation: Isolation::InProcess,
            enclosing_box: None,
            max_rounding_rounds: 4,
            progress: None,
            assembly: Assembly::default(),
            reorder: Reorder::default(),
            validation: Validation::default(),
        }
    }
}

impl std::fmt::Debug for BuildOptions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BuildOptions")
            .field("tetgen", &self.tetgen)
            .field("isolation", &self.isolation)
            .field("enclosing_box", &self.enclosing_box)
            .field("max_rounding_rounds", &self.max_rounding_rounds)
            .field("progress", &self.progress.as_ref().map(|_| "callback"))
            .field("assembly", &self.assembly)
            .field("reorder", &self.reorder)
            .field("validation", &self.validation)
            .finish()
    }
}

/// Wall-clock time of each stage.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StageTimes {
    /// Cleaning.
    pub clean: Duration,
    /// Enclosing box.
    pub enclosing_box: Duration,
    /// TetGen, all rounds, as seen by the caller (includes the worker's
    /// start-up and pipe transfer when isolated).
    pub tetgen: Duration,
    /// TetGen, all rounds, as measured around the TetGen call itself.
    pub tetgen_inside: Duration,
    /// f32 rounding checks.
    pub rounding: Duration,
    /// Matching faces to triangles (constrained-face extraction and coverage check).
    pub constrained_faces: Duration,
    /// Neighbours and constrained-face table ([`Assembly`]).
    pub assemble: Duration,
    /// Hilbert reordering ([`Reorder::Hilbert`]).
    pub reorder: Duration,
    /// Validation ([`Validation`]).
    pub validate: Duration,
    /// The whole build.
    pub total: Duration,
}

/// What [`build`] did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BuildReport {
    /// Cleaning actions.
    pub clean: CleanReport,
    /// Scene triangles after cleaning (= constrained faces).
    pub scene_triangles: usize,
    /// Box triangles added (0 or 12).
    pub boundary_triangles: usize,
    /// Points of the mesh.
    pub points: usize,
    /// Points TetGen added (all rounds) beyond the scene and box vertices.
    pub steiner_points: usize,
    /// Tets.
    pub tets: usize,
    /// Constrained faces.
    pub constrained_faces: usize,
    /// TetGen runs (1 unless rounding forced re-runs).
    pub tetgen_rounds: u32,
    /// Tets found flat or inverted after rounding, per TetGen round (before snapping).
    pub rounding_failures: Vec<usize>,
    /// Steiner points moved to a neighbouring f32 value to keep tets positive.
    pub snapped_points: usize,
    /// TetGen switch string.
    pub switches: String,
    /// Stage times.
    pub times: StageTimes,
    /// Peak resident memory (VmHWM, KiB) of this process since it started
    /// (not only this build), or of the worker when that is larger.
    pub peak_memory_kib: Option<u64>,
    /// The isolated worker's peak resident memory (KiB), when isolated.
    pub worker_peak_memory_kib: Option<u64>,
    /// The permutations applied by [`Reorder::Hilbert`] (`order[new] = old`,
    /// old = TetGen's order); `None` without reordering.
    pub reordering: Option<Reordering>,
}

/// A failed build; each variant names what failed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum BuildError {
    /// The scene has no triangles left after cleaning.
    #[error("the scene has no triangles (after cleaning: {vertices} vertices)")]
    EmptyScene {
        /// Vertices left.
        vertices: usize,
    },
    /// Cleaning rejected the scene.
    #[error("cleaning: {0}")]
    Clean(#[from] CleanError),
    /// The enclosing box could not be built.
    #[error("enclosing box: {0}")]
    Box(#[from] BoxError),
    /// TetGen failed.
    #[error("TetGen: {0}")]
    Tetgen(#[from] TetgenError),
    /// The scene's triangles intersect each other (TetGen's code 3, with the
    /// offending pairs found by the exact check of [`crate::intersect`]).
    #[error(
        "the scene self-intersects: {total} pairs of input triangles intersect, e.g. {}",
        list_pairs(pairs)
    )]
    SelfIntersections {
        /// Up to 20 pairs, by input triangle index.
        pairs: Vec<IntersectingPair>,
        /// Number of intersecting pairs.
        total: usize,
    },
    /// A scene triangle is not exactly one constrained face of the mesh.
    #[error(
        "scene triangle {triangle} (cleaned {cleaned}) is covered by {faces} constrained faces, expected exactly one with its own vertices"
    )]
    TriangleNotPreserved {
        /// Input scene triangle id.
        triangle: u32,
        /// Index after cleaning.
        cleaned: u32,
        /// Number of TetGen faces carrying its marker.
        faces: usize,
    },
    /// TetGen returned a face with a marker that names no triangle.
    #[error("TetGen face {face} has marker {marker}, which names no scene triangle")]
    UnknownMarker {
        /// Face index in TetGen's output.
        face: usize,
        /// The marker.
        marker: i32,
    },
    /// TetGen changed input points (it must keep them, in order).
    #[error("TetGen moved or dropped input point {point}")]
    InputPointChanged {
        /// Point index.
        point: usize,
    },
    /// Rounding Steiner points to f32 still flattens or inverts tets after
    /// the allowed TetGen re-runs.
    #[error(
        "{count} tets are flat or inverted after rounding to f32 (after {rounds} TetGen runs), e.g. {tets:?}"
    )]
    RoundingFlattens {
        /// Number of bad tets.
        count: usize,
        /// Up to 16 of them (indices in the last TetGen output).
        tets: Vec<u32>,
        /// TetGen runs made.
        rounds: u32,
    },
    /// Assembly or validation failed (a bug in this pipeline or TetGen).
    #[error("mesh: {0}")]
    Mesh(#[from] MeshError),
}

fn list_pairs(pairs: &[IntersectingPair]) -> String {
    pairs
        .iter()
        .map(|p| format!("{} × {} ({:?})", p.first, p.second, p.kind))
        .collect::<Vec<_>>()
        .join(", ")
}

/// TetGen reported a self-intersection: name the pairs by input index.
fn self_intersection_error(scene: &Scene) -> BuildError {
    let report = find_self_intersections(&scene.vertices, &scene.triangles);
    if report.pairs.is_empty() {
        // Only TetGen's own tolerance sees it (or it involves the box).
        return BuildError::Tetgen(TetgenError::SelfIntersection);
    }
    BuildError::SelfIntersections {
        total: report.pairs.len(),
        pairs: report.pairs.into_iter().take(20).collect(),
    }
}

/// Builds the constrained Delaunay tetrahedralization of `scene` (see the module docs).
pub fn build(scene: &Scene, options: &BuildOptions) -> Result<(TetMesh, BuildReport), BuildError> {
    let start = Instant::now();
    let mut tetgen_options = options.tetgen.clone();
    if options.assembly == Assembly::TetgenNeighbors {
        tetgen_options.face_tets = true;
    }
    let mut report = BuildReport {
        switches: tetgen_options.switches(),
        ..BuildReport::default()
    };
    let progress = |stage: Stage| {
        if let Some(p) = &options.progress {
            p(&Progress {
                stage,
                elapsed: start.elapsed(),
            });
        }
    };

    progress(Stage::Clean);
    let t = Instant::now();
    let (cleaned, cm) = clean_scene(scene)?;
    report.times.clean = t.elapsed();
    report.clean = cm.report.clone();
    if cleaned.triangles.is_empty() {
        return Err(BuildError::EmptyScene {
            vertices: cleaned.vertices.len(),
        });
    }
    let n_scene_vertices = cleaned.vertices.len();
    let n_scene_triangles = cleaned.triangles.len();
    report.scene_triangles = n_scene_triangles;

    let mut vertices = cleaned.vertices.clone();
    let mut triangles = cleaned.triangles.clone();
    if let Some(spec) = options.enclosing_box {
        progress(Stage::EnclosingBox);
        let t = Instant::now();
        let b = EnclosingBox::new(cleaned.bounds(), spec)?;
        b.append_to(&mut vertices, &mut triangles);
        report.boundary_triangles = triangles.len() - n_scene_triangles;
        report.times.enclosing_box = t.elapsed();
    }
    let markers: Vec<i32> = (0..triangles.len())
        .map(|i| {
            if i < n_scene_triangles {
                i as i32 + 1
            } else {
                0
            }
        })
        .collect();
    let mut input = TetgenInput {
        points: vertices.iter().map(|v| v.as_dvec3().to_array()).collect(),
        triangles,
        markers,
    };
    let n_fixed = input.points.len();

    // TetGen, re-run while rounding to f32 flattens tets.
    let mut round = 0u32;
    let mut last_bad: Vec<u32> = Vec::new();
    let (out, points32, tets) = loop {
        round += 1;
        progress(Stage::Tetgen { round });
        let t = Instant::now();
        let out = match tetrahedralize(&input, &tetgen_options, &options.isolation) {
            Ok(out) => out,
            // A repair round failed (typically a rounded Steiner point on a facet).
            Err(_) if round > 1 => {
                return Err(BuildError::RoundingFlattens {
                    count: last_bad.len(),
                    tets: last_bad.into_iter().take(16).collect(),
                    rounds: round,
                });
            }
            Err(TetgenError::SelfIntersection) => return Err(self_intersection_error(scene)),
            Err(e) => return Err(e.into()),
        };
        report.times.tetgen += t.elapsed();
        report.times.tetgen_inside += Duration::from_secs_f64(out.seconds);
        if let Some(w) = out.worker_peak_kib {
            report.worker_peak_memory_kib = Some(report.worker_peak_memory_kib.unwrap_or(0).max(w));
        }
        progress(Stage::Rounding);
        let t = Instant::now();
        if out.points.len() < input.points.len() {
            return Err(BuildError::InputPointChanged {
                point: out.points.len(),
            });
        }
        if let Some(i) = (0..input.points.len()).find(|&i| out.points[i] != input.points[i]) {
            return Err(BuildError::InputPointChanged { point: i });
        }
        let points32: Vec<Vec3> = out
            .points
            .iter()
            .map(|p| Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32))
            .collect();
        let mut points32 = points32;
        let (tets, mut bad) = orient_tets(&out.points, &points32, &out.tets);
        report.rounding_failures.push(bad.len());
        if !bad.is_empty() {
            let snapped;
            (snapped, bad) =
                snap_steiner_points(&out.points, &mut points32, &tets, &bad, input.points.len());
            report.snapped_points += snapped;
        }
        report.times.rounding += t.elapsed();
        if bad.is_empty() {
            break (out, points32, tets);
        }
        let steiner = &points32[input.points.len()..];
        if round > options.max_rounding_rounds || steiner.is_empty() {
            return Err(BuildError::RoundingFlattens {
                count: bad.len(),
                tets: bad.into_iter().take(16).collect(),
                rounds: round,
            });
        }
        last_bad = bad;
        // Feed the rounded Steiner points back as input points (deduplicated,
        // and without any that coincide with an existing point).
        let mut known: Vec<[u32; 3]> = input.points.iter().map(|p| key64(*p)).collect();
        known.sort_unstable();
        let mut extra: Vec<[f64; 3]> = steiner
            .iter()
            .map(|p| p.as_dvec3().to_array())
            .filter(|p| known.binary_search(&key64(*p)).is_err())
            .collect();
        extra.sort_by_key(|p| key64(*p));
        extra.dedup_by(|a, b| key64(*a) == key64(*b));
        input.points.extend(extra);
    };
    report.tetgen_rounds = round;
    report.steiner_points = points32.len() - n_fixed;

    // Constrained faces: exactly one TetGen face per scene triangle, with its vertices.
    progress(Stage::ConstrainedFaces);
    let t = Instant::now();
    let mut face_of = vec![u32::MAX; n_scene_triangles];
    let mut count = vec![0usize; n_scene_triangles];
    for (f, (&face, &m)) in out.faces.iter().zip(&out.face_markers).enumerate() {
        if m == 0 {
            continue;
        }
        if m < 0 || m as usize > n_scene_triangles {
            return Err(BuildError::UnknownMarker { face: f, marker: m });
        }
        let c = m as usize - 1;
        count[c] += 1;
        let mut a = face;
        let mut b = input.triangles[c];
        a.sort_unstable();
        b.sort_unstable();
        if a == b {
            face_of[c] = f as u32;
        }
    }
    let mut tris = Vec::with_capacity(n_scene_triangles);
    for c in 0..n_scene_triangles {
        if count[c] != 1 || face_of[c] == u32::MAX {
            return Err(BuildError::TriangleNotPreserved {
                triangle: cm.triangle_source[c],
                cleaned: c as u32,
                faces: count[c],
            });
        }
        tris.push((input.triangles[c], cm.triangle_source[c]));
    }
    report.times.constrained_faces = t.elapsed();

    progress(Stage::Assemble);
    let t = Instant::now();
    let n_points = points32.len();
    let triangle_count = scene.triangles.len() as u32;
    let fast = match (options.assembly, &out.neighbors, &out.face_tets) {
        (Assembly::TetgenNeighbors, Some(neighbors), Some(face_tets)) => assemble_from_tetgen(
            points32,
            tets,
            &TetgenAdjacency {
                tets: &out.tets,
                neighbors,
                face_tets,
            },
            &face_of,
            &tris,
            triangle_count,
        )?,
        _ => Assembled::Unavailable(points32, tets),
    };
    let mut mesh = match fast {
        Assembled::Mesh(mesh) => mesh,
        Assembled::Unavailable(points32, tets) => {
            TetMesh::assemble(points32, tets, &tris, triangle_count)?
        }
    };
    report.times.assemble = t.elapsed();
    // Attributes: scene vertices are the first points; box corners and
    // Steiner points get zero normals / uvs.
    if let (Some(n), Some(input_normals)) = (&cleaned.normals, &scene.normals) {
        let mut v = n.clone();
        v.resize(n_points, Vec3::ZERO);
        // A merged vertex whose copies carry different normals (a crease,
        // e.g. a flat-shaded box corner) has no single shading normal.
        for &(dropped, kept) in &cm.report.attribute_conflicts {
            if input_normals[dropped as usize] != input_normals[kept as usize] {
                let out = cm.vertex_map[kept as usize];
                if let Some(slot) = v.get_mut(out as usize) {
                    *slot = Vec3::ZERO;
                }
            }
        }
        mesh.attributes.normals = Some(v);
    }
    if let Some(uv) = &cleaned.uvs {
        let mut v = uv.clone();
        v.resize(n_points, Vec2::ZERO);
        mesh.attributes.uvs = Some(v);
    }
    debug_assert!(n_scene_vertices <= n_points);

    if options.reorder == Reorder::Hilbert {
        progress(Stage::Reorder);
        let t = Instant::now();
        report.reordering = Some(hilbert_reorder(&mut mesh));
        report.times.reorder = t.elapsed();
    }

    progress(Stage::Validate);
    let t = Instant::now();
    match options.validation {
        Validation::Construction => check_construction(&mesh)?,
        Validation::Full => mesh.validate()?,
    }
    report.times.validate = t.elapsed();

    report.points = mesh.points.len();
    report.tets = mesh.tets.len();
    report.constrained_faces = mesh.constrained.len();
    report.times.total = start.elapsed();
    let own = peak_memory_kib();
    report.peak_memory_kib = match (own, report.worker_peak_memory_kib) {
        (Some(a), Some(b)) => Some(a.max(b)),
        (a, b) => a.or(b),
    };
    Ok((mesh, report))
}

fn key64(p: [f64; 3]) -> [u32; 3] {
    // Points here are f32 values widened to f64: compare their f32 bits.
    [
        (p[0] as f32 + 0.0).to_bits(),
        (p[1] as f32 + 0.0).to_bits(),
        (p[2] as f32 + 0.0).to_bits(),
    ]
}

/// Orients TetGen's tets positively by their exact f64 orientation, and lists
/// the tets whose exact orientation with f32 points is not positive.
///
/// Swapping slots 0 and 1 is the only change made to a tet, so a tet differs
/// from TetGen's exactly when it was flipped ([`assemble_from_tetgen`] relies
/// on this). Runs in parallel; the result does not depend on the thread count.
fn orient_tets(p64: &[[f64; 3]], p32: &[Vec3], tets: &[[u32; 4]]) -> (Vec<[u32; 4]>, Vec<u32>) {
    let (out, flat): (Vec<[u32; 4]>, Vec<bool>) = tets
        .par_iter()
        .with_min_len(4096)
        .map(|&t| {
            let [a, b, c, d] = t.map(|v| DVec3::from_array(p64[v as usize]));
            let o = tet_core::predicates::orient3d(a, b, c, d);
            let t = if o < 0.0 { [t[1], t[0], t[2], t[3]] } else { t };
            let [a, b, c, d] = t.map(|v| p32[v as usize]);
            (
                t,
                o == 0.0 || tet_core::predicates::orient3d_f32(a, b, c, d) <= 0.0,
            )
        })
        .unzip();
    let bad = flat
        .iter()
        .enumerate()
        .filter(|&(_, &f)| f)
        .map(|(i, _)| i as u32)
        .collect();
    (out, bad)
}

/// Snaps the Steiner points (index ≥ `first_steiner`) of the `bad` tets to
/// a nearby f32 value that makes all their tets positive (exact test).
/// Returns how many points moved and the tets still bad.
fn snap_steiner_points(
    p64: &[[f64; 3]],
    p32: &mut [Vec3],
    tets: &[[u32; 4]],
    bad: &[u32],
    first_steiner: usize,
) -> (usize, Vec<u32>) {
    use std::collections::HashMap;
    let mut around: HashMap<u32, Vec<u32>> = HashMap::new();
    for &t in bad {
        for v in tets[t as usize] {
            if v as usize >= first_steiner {
                around.entry(v).or_default();
            }
        }
    }
    if around.is_empty() {
        return (0, bad.to_vec());
    }
    for (t, tet) in tets.iter().enumerate() {
        for v in tet {
            if let Some(list) = around.get_mut(v) {
                list.push(t as u32);
            }
        }
    }
    let positive = |p32: &[Vec3], t: u32| {
        let [a, b, c, d] = tets[t as usize].map(|v| p32[v as usize]);
        tet_core::predicates::orient3d_f32(a, b, c, d) > 0.0
    };
    let steps = |x: f32| {
        let mut v = vec![x];
        let (mut up, mut down) = (x, x);
        for _ in 0..2 {
            up = up.next_up();
            down = down.next_down();
            v.push(up);
            v.push(down);
        }
        v
    };
    let mut moved = 0;
    let mut vertices: Vec<u32> = around.keys().copied().collect();
    vertices.sort_unstable();
    for _pass in 0..3 {
        let mut changed = false;
        for &v in &vertices {
            let incident = &around[&v];
            if incident.iter().all(|&t| positive(p32, t)) {
                continue;
            }
            let target = DVec3::from_array(p64[v as usize]);
            let r = p32[v as usize];
            let mut candidates = Vec::with_capacity(125);
            for x in steps(r.x) {
                for y in steps(r.y) {
                    for z in steps(r.z) {
                        candidates.push(Vec3::new(x, y, z));
                    }
                }
            }
            candidates.sort_by(|a, b| {
                a.as_dvec3()
                    .distance_squared(target)
                    .total_cmp(&b.as_dvec3().distance_squared(target))
            });
            let original = p32[v as usize];
            let mut found = false;
            for c in candidates {
                p32[v as usize] = c;
                if incident.iter().all(|&t| positive(p32, t)) {
                    found = true;
                    break;
                }
            }
            if found {
                moved += 1;
                changed = true;
            } else {
                p32[v as usize] = original;
            }
        }
        if !changed {
            break;
        }
    }
    let still: Vec<u32> = bad.iter().copied().filter(|&t| !positive(p32, t)).collect();
    // Snapping may have broken tets outside `bad` only through the moved
    // points, whose incident tets were all checked positive when moved; a
    // later move of a neighbouring point re-checks its own incident tets.
    let mut all_bad = still;
    for (&_v, incident) in &around {
        for &t in incident {
            if !positive(p32, t) && !all_bad.contains(&t) {
                all_bad.push(t);
            }
        }
    }
    all_bad.sort_unstable();
    (moved, all_bad)
}

/// What [`assemble_from_tetgen`] made.
enum Assembled {
    /// The mesh.
    Mesh(TetMesh),
    /// TetGen's adjacency cannot place some constrained face: the inputs,
    /// handed back for [`TetMesh::assemble`].
    Unavailable(Vec<Vec3>, Vec<[u32; 4]>),
}

/// TetGen's adjacency output (`-nn`), in TetGen's tet order and slot order.
struct TetgenAdjacency<'a> {
    /// TetGen's tets, before orientation.
    tets: &'a [[u32; 4]],
    /// Neighbour `k` of each tet (opposite TetGen slot `k`), `-1` = hull.
    neighbors: &'a [[i32; 4]],
    /// TetGen's `adjtetlist`: the two tets of each output face, `-1` = none
    /// (not trusted: see [`assemble_from_tetgen`]).
    face_tets: &'a [[i32; 2]],
}

/// Builds exactly the mesh [`TetMesh::assemble`] would build from
/// `(points, tets, triangles)`, but from TetGen's own adjacency instead of
/// sorting face keys: tet links are TetGen's neighbours (slots 0 and 1
/// swapped where [`orient_tets`] flipped the tet), and constrained face `c`
/// (scene triangle `triangles[c]`, TetGen face `face_of[c]`) lies on a tet
/// TetGen lists for that face (checked to have the face) and on that tet's
/// neighbour across it. [`Assembled::Unavailable`] when TetGen names no tet with some face
/// (the caller then falls back to [`TetMesh::assemble`]). Where TetGen's
/// neighbour list disagrees with its faces the result is an error, never a
/// different mesh; face manifoldness (which makes the two identical) is
/// checked by either [`Validation`].
fn assemble_from_tetgen(
    points: Vec<Vec3>,
    tets: Vec<[u32; 4]>,
    adj: &TetgenAdjacency<'_>,
    face_of: &[u32],
    triangles: &[([u32; 3], u32)],
    triangle_count: u32,
) -> Result<Assembled, MeshError> {
    let nt = tets.len();
    for (what, count) in [("tets", nt), ("constrained faces", triangles.len())] {
        if count >= MAX_TETS as usize {
            return Err(MeshError::TooMany {
                what,
                count,
                limit: MAX_TETS as usize - 1,
            });
        }
    }
    for (array, actual) in [
        ("TetGen tets", adj.tets.len()),
        ("TetGen neighbours", adj.neighbors.len()),
    ] {
        if actual != nt {
            return Err(MeshError::LengthMismatch {
                array,
                actual,
                expected: nt,
            });
        }
    }
    if face_of.len() != triangles.len() {
        return Err(MeshError::LengthMismatch {
            array: "constrained faces",
            actual: face_of.len(),
            expected: triangles.len(),
        });
    }
    let np = points.len();
    let mut neighbors: Vec<[Link; 4]> = tets
        .par_iter()
        .zip(adj.tets.par_iter().zip(adj.neighbors.par_iter()))
        .enumerate()
        .with_min_len(4096)
        .map(|(t, (tet, (raw, n)))| {
            let t = t as u32;
            for (slot, &v) in tet.iter().enumerate() {
                if v as usize >= np {
                    return Err(MeshError::VertexOutOfBounds {
                        tet: t,
                        slot: slot as u8,
                        vertex: v,
                        points: np,
                    });
                }
            }
            let mut n = *n;
            if tet != raw {
                n.swap(0, 1);
            }
            let mut links = [Link::BOUNDARY; 4];
            for (k, (&v, link)) in n.iter().zip(&mut links).enumerate() {
                *link = match v {
                    -1 => Link::BOUNDARY,
                    v if v >= 0 && (v as usize) < nt => Link::tet(v as u32),
                    v => {
                        return Err(MeshError::NeighborOutOfBounds {
                            tet: t,
                            face: k as u8,
                            neighbor: v as u32,
                            tets: nt,
                        });
                    }
                };
            }
            Ok(links)
        })
        .collect::<Result<_, _>>()?;

    // The slot of `tet` opposite the face `vertices`, if `tet` has that face.
    let opposite = |tet: [u32; 4], vertices: [u32; 3]| {
        let mut outside = (0..4).filter(|&i| !vertices.contains(&tet[i]));
        match (outside.next(), outside.next()) {
            (Some(k), None) => Some(k),
            _ => None,
        }
    };
    let mut constrained: Vec<ConstrainedFace> = Vec::with_capacity(triangles.len());
    for (c, (&(vertices, triangle), &f)) in triangles.iter().zip(face_of).enumerate() {
        let key = face_key(vertices);
        // One tet with this face: TetGen's `adjtetlist` entry, used only
        // after checking that the tet has the face (for a face on the convex
        // hull TetGen may report its internal hull tet's unset index).
        let has_face = |s: i32| {
            let t = u32::try_from(s).ok().filter(|&t| (t as usize) < nt)?;
            opposite(tets[t as usize], vertices).map(|k| (t, k))
        };
        let sides = adj.face_tets.get(f as usize).copied().unwrap_or([-1, -1]);
        let Some((t0, k0)) = has_face(sides[0]).or_else(|| has_face(sides[1])) else {
            return Ok(Assembled::Unavailable(points, tets));
        };
        // The other side is t0's neighbour across the face.
        let second = match neighbors[t0 as usize][k0].kind() {
            LinkKind::Boundary => None,
            LinkKind::Tet(n) => match opposite(tets[n as usize], vertices) {
                Some(k) => Some((n, k)),
                None => {
                    return Err(MeshError::SharedFaceMismatch {
                        tet: t0,
                        face: k0 as u8,
                        neighbor: n,
                    });
                }
            },
            LinkKind::Constrained(prev) => {
                return Err(MeshError::DuplicateTriangle {
                    first: constrained[prev as usize].triangle,
                    second: triangle,
                    vertices: key,
                });
            }
        };
        let mut cf = ConstrainedFace {
            triangle,
            vertices,
            front: FaceSide::NONE,
            back: FaceSide::NONE,
        };
        for (t, k) in std::iter::once((t0, k0)).chain(second) {
            let link = &mut neighbors[t as usize][k];
            if let Some(prev) = link.as_constrained() {
                return Err(MeshError::DuplicateTriangle {
                    first: constrained[prev as usize].triangle,
                    second: triangle,
                    vertices: key,
                });
            }
            *link = Link::constrained(c as u32);
            cf.attach_side(tets[t as usize], t, k);
        }
        constrained.push(cf);
    }
    Ok(Assembled::Mesh(TetMesh {
        points,
        tets,
        neighbors,
        constrained,
        triangle_count,
        attributes: Attributes::default(),
    }))
}

/// Sorts `(key, index)` pairs (in parallel) and returns the indices: the
/// order of [`tet_core::reorder`] (ties broken by the old index).
fn order_by_key<K: Ord + Copy + Send>(keys: Vec<K>) -> Vec<u32> {
    let mut v: Vec<(K, u32)> = keys
        .into_par_iter()
        .enumerate()
        .map(|(i, k)| (k, i as u32))
        .collect();
    v.par_sort_unstable();
    v.into_par_iter().map(|(_, i)| i).collect()
}

/// [`tet_core::hilbert::hilbert_index`], bit for bit (tested on random
/// cells for every `bits`), without data-dependent branches: Skilling's
/// per-level "exchange or invert" steps become masks, and the final bit
/// interleave is done with magic-number bit spreading. About 4× faster, which
/// matters with one key per tet.
fn hilbert_index_fast(coords: [u32; 3], bits: u32) -> u64 {
    debug_assert!((1..=21).contains(&bits));
    let mask = (1u32 << bits) - 1;
    let [mut x0, mut x1, mut x2] = coords.map(|c| c & mask);
    let m = 1u32 << (bits - 1);
    let mut q = m;
    while q > 1 {
        let p = q - 1;
        // i = 0: invert the low bits of x0 where x0 has bit q.
        x0 ^= p & 0u32.wrapping_sub(u32::from(x0 & q != 0));
        // i = 1, 2: invert x0's low bits if bit q is set, else exchange them.
        for xi in [&mut x1, &mut x2] {
            let set = 0u32.wrapping_sub(u32::from(*xi & q != 0));
            let t = (x0 ^ *xi) & p;
            x0 ^= (p & set) | (t & !set);
            *xi ^= t & !set;
        }
        q >>= 1;
    }
    // Gray encode.
    x1 ^= x0;
    x2 ^= x1;
    let mut t = 0;
    let mut q = m;
    while q > 1 {
        t ^= (q - 1) & 0u32.wrapping_sub(u32::from(x2 & q != 0));
        q >>= 1;
    }
    x0 ^= t;
    x1 ^= t;
    x2 ^= t;
    // Interleave, most significant bit first: x0's bit j lands at 3j + 2.
    (spread3(x0) << 2) | (spread3(x1) << 1) | spread3(x2)
}

/// Moves bit `j` of a 21-bit value to bit `3 j`.
fn spread3(v: u32) -> u64 {
    let mut x = u64::from(v) & 0x1f_ffff;
    x = (x | (x << 32)) & 0x001f_0000_0000_ffff;
    x = (x | (x << 16)) & 0x001f_0000_ff00_00ff;
    x = (x | (x << 8)) & 0x100f_00f0_0f00_f00f;
    x = (x | (x << 4)) & 0x10c3_0c30_c30c_30c3;
    x = (x | (x << 2)) & 0x1249_2492_4924_9249;
    x
}

/// A signed permutation of the three axes: `y[i] = x[perm[i]]`, then every
/// bit of `y[i]` inverted where `flip[i]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct AxisMap {
    perm: [u8; 3],
    flip: [bool; 3],
}

impl AxisMap {
    const IDENTITY: AxisMap = AxisMap {
        perm: [0, 1, 2],
        flip: [false; 3],
    };

    fn apply(self, x: [u32; 3], mask: u32) -> [u32; 3] {
        std::array::from_fn(|i| x[self.perm[i] as usize] ^ if self.flip[i] { mask } else { 0 })
    }

    /// `next ∘ self`.
    fn then(self, next: AxisMap) -> AxisMap {
        AxisMap {
            perm: std::array::from_fn(|i| self.perm[next.perm[i] as usize]),
            flip: std::array::from_fn(|i| self.flip[next.perm[i] as usize] ^ next.flip[i]),
        }
    }

    fn all() -> impl Iterator<Item = AxisMap> {
        const PERMS: [[u8; 3]; 6] = [
            [0, 1, 2],
            [0, 2, 1],
            [1, 0, 2],
            [1, 2, 0],
            [2, 0, 1],
            [2, 1, 0],
        ];
        PERMS.into_iter().flat_map(|perm| {
            (0..8u8).map(move |f| AxisMap {
                perm,
                flip: [f & 4 != 0, f & 2 != 0, f & 1 != 0],
            })
        })
    }
}

/// The octant of cell `x` at bit level `j`: bit `j` of x, y, z as 3 bits.
fn octant(x: [u32; 3], j: u32) -> usize {
    ((((x[0] >> j) & 1) << 2) | (((x[1] >> j) & 1) << 1) | ((x[2] >> j) & 1)) as usize
}

/// [`tet_core::hilbert::hilbert_index`] as a finite-state machine: at each
/// level (most significant first) the state and the cell's octant give the
/// curve's 3-bit digit and the next state. The table is *derived from the
/// reference function itself*: a Hilbert curve is self-similar, so
/// `H_b(x) = D(o) · 8^(b-1) + H_(b-1)(T_o(low bits))` for the octant `o`
/// of the top bits, a digit `D(o)` and a signed axis permutation `T_o`,
/// found by probing `hilbert_index` on 4-bit cells; states are the
/// compositions of the `T_o` reachable from the identity. `None` if the
/// reference were not of that form (then [`hilbert_index_fast`] is used).
/// Equality with the reference is tested on random cells at every `bits`.
struct HilbertTable {
    /// `[state][octant] = (digit, next state)`.
    next: Vec<[(u8, u8); 8]>,
}

impl HilbertTable {
    fn derive() -> Option<HilbertTable> {
        use tet_core::hilbert::hilbert_index as h;
        let mut digit = [0u8; 8];
        let mut child = [AxisMap::IDENTITY; 8];
        for o in 0..8 {
            let top = [(o >> 2) as u32 & 1, (o >> 1) as u32 & 1, o as u32 & 1];
            let full = |r: [u32; 3]| h(std::array::from_fn(|i| (top[i] << 3) | r[i]), 4);
            let d = full([0, 0, 0]) >> 9;
            digit[o] = d as u8;
            let lows = || (0..512u32).map(|r| [r >> 6, (r >> 3) & 7, r & 7]);
            child[o] = AxisMap::all()
                .find(|t| lows().all(|r| full(r) == (d << 9) | h(t.apply(r, 7), 3)))?;
        }
        let mut states = vec![AxisMap::IDENTITY];
        let mut next = Vec::new();
        let mut i = 0;
        while i < states.len() {
            let s = states[i];
            let mut row = [(0u8, 0u8); 8];
            for (o, slot) in row.iter_mut().enumerate() {
                let so = octant(
                    s.apply([(o >> 2) as u32, (o >> 1) as u32 & 1, o as u32 & 1], 1),
                    0,
                );
                let n = s.then(child[so]);
                let k = match states.iter().position(|&x| x == n) {
                    Some(k) => k,
                    None => {
                        states.push(n);
                        states.len() - 1
                    }
                };
                *slot = (digit[so], k as u8);
            }
            next.push(row);
            i += 1;
        }
        Some(HilbertTable { next })
    }

    fn get() -> Option<&'static HilbertTable> {
        static TABLE: std::sync::OnceLock<Option<HilbertTable>> = std::sync::OnceLock::new();
        TABLE.get_or_init(HilbertTable::derive).as_ref()
    }

    fn index(&self, coords: [u32; 3], bits: u32) -> u64 {
        let mut state = 0usize;
        let mut h = 0u64;
        for j in (0..bits).rev() {
            let (d, n) = self.next[state][octant(coords, j)];
            h = (h << 3) | u64::from(d);
            state = n as usize;
        }
        h
    }
}

/// [`Quantizer::key`], through the [`HilbertTable`] when it could be derived.
fn hilbert_key(q: &Quantizer, p: Vec3) -> u64 {
    let cell = q.cell(p);
    match HilbertTable::get() {
        Some(t) => t.index(cell, q.bits),
        None => hilbert_index_fast(cell, q.bits),
    }
}

/// `new_of_old` of a permutation given as `order[new] = old` (a permutation
/// by construction here: it comes from sorting `0..n`).
fn inverse(order: &[u32]) -> Vec<u32> {
    let mut inv = vec![0u32; order.len()];
    for (new, &old) in order.iter().enumerate() {
        inv[old as usize] = new as u32;
    }
    inv
}

/// [`tet_core::reorder::hilbert_reorder`] of a valid mesh, computed in
/// parallel with one gather per array: the same permutations and the same
/// resulting mesh (tested against it).
fn hilbert_reorder(mesh: &mut TetMesh) -> Reordering {
    let q = Quantizer::from_points(&mesh.points);
    let points_ref = &mesh.points;
    let (point_order, tet_order) = rayon::join(
        || order_by_key(points_ref.par_iter().map(|&p| hilbert_key(&q, p)).collect()),
        || {
            order_by_key(
                mesh.tets
                    .par_iter()
                    .map(|t| {
                        let c: Vec3 = t.iter().map(|&v| points_ref[v as usize]).sum();
                        hilbert_key(&q, c * 0.25)
                    })
                    .collect(),
            )
        },
    );
    let (new_point, new_tet) = rayon::join(|| inverse(&point_order), || inverse(&tet_order));
    // Constrained faces by their lowest (new tet, face) side.
    let constrained_order = order_by_key(
        mesh.constrained
            .iter()
            .map(|cf| {
                [cf.front, cf.back]
                    .into_iter()
                    .filter(|s| s.exists())
                    .map(|s| (new_tet[s.tet as usize], s.face))
                    .min()
                    .unwrap_or((u32::MAX, 0))
            })
            .collect(),
    );
    let new_constrained = inverse(&constrained_order);
    let gather = |v: &[Vec3]| point_order.par_iter().map(|&o| v[o as usize]).collect();
    let points: Vec<Vec3> = gather(&mesh.points);
    if let Some(n) = mesh.attributes.normals.as_mut()
        && n.len() == point_order.len()
    {
        *n = gather(n);
    }
    if let Some(uv) = mesh.attributes.uvs.as_mut()
        && uv.len() == point_order.len()
    {
        *uv = point_order.par_iter().map(|&o| uv[o as usize]).collect();
    }
    let (tets, neighbors) = rayon::join(
        || {
            tet_order
                .par_iter()
                .map(|&o| mesh.tets[o as usize].map(|v| new_point[v as usize]))
                .collect()
        },
        || {
            tet_order
                .par_iter()
                .map(|&o| {
                    mesh.neighbors[o as usize].map(|l| match l.kind() {
                        LinkKind::Tet(n) => Link::tet(new_tet[n as usize]),
                        LinkKind::Constrained(c) => Link::constrained(new_constrained[c as usize]),
                        LinkKind::Boundary => l,
                    })
                })
                .collect()
        },
    );
    let side = |s: FaceSide| {
        if s.exists() {
            FaceSide {
                tet: new_tet[s.tet as usize],
                face: s.face,
            }
        } else {
            s
        }
    };
    let constrained = constrained_order
        .iter()
        .map(|&o| {
            let cf = mesh.constrained[o as usize];
            ConstrainedFace {
                triangle: cf.triangle,
                vertices: cf.vertices.map(|v| new_point[v as usize]),
                front: side(cf.front),
                back: side(cf.back),
            }
        })
        .collect();
    mesh.points = points;
    mesh.tets = tets;
    mesh.neighbors = neighbors;
    mesh.constrained = constrained;
    Reordering {
        points: point_order,
        tets: tet_order,
        constrained: constrained_order,
    }
}

/// [`Validation::Construction`]: every check of [`TetMesh::validate`]
/// except tet orientation (decided exactly by the rounding stage on the
/// final coordinates; a positive tet also has four distinct vertices), in
/// linear time and in parallel. The face-manifold check of `validate`
/// (sorting all `4 × tets` face keys) becomes: given symmetric links whose
/// tets share the linked face and a consistent constrained-face table (both
/// checked first), every face belongs to exactly one *class* — a linked pair
/// of tets, a two-sided constrained face, or a one-sided face — and the
/// mesh is face-manifold iff no two classes have the same vertex triple;
/// one representative per class is bucketed by its smallest vertex and only
/// the buckets are sorted.
fn check_construction(m: &TetMesh) -> Result<(), MeshError> {
    let nt = m.tets.len();
    let np = m.points.len();
    for (what, count) in [("tets", nt), ("constrained faces", m.constrained.len())] {
        if count >= MAX_TETS as usize {
            return Err(MeshError::TooMany {
                what,
                count,
                limit: MAX_TETS as usize - 1,
            });
        }
    }
    if np > u32::MAX as usize {
        return Err(MeshError::TooMany {
            what: "points",
            count: np,
            limit: u32::MAX as usize,
        });
    }
    if m.neighbors.len() != nt {
        return Err(MeshError::LengthMismatch {
            array: "neighbors",
            actual: m.neighbors.len(),
            expected: nt,
        });
    }
    if let Some(i) = m.points.par_iter().position_first(|p| !p.is_finite()) {
        return Err(MeshError::NonFinitePoint { point: i as u32 });
    }
    // Vertex ids in range (orientation: see the doc comment).
    m.tets
        .par_iter()
        .enumerate()
        .with_min_len(4096)
        .try_for_each(
            |(t, tet)| match tet.iter().position(|&v| v as usize >= np) {
                Some(slot) => Err(MeshError::VertexOutOfBounds {
                    tet: t as u32,
                    slot: slot as u8,
                    vertex: tet[slot],
                    points: np,
                }),
                None => Ok(()),
            },
        )?;
    // Each tet link t → n with t < n is checked in full (shared face, link
    // back); those pairs use disjoint link slots, so when their count is half
    // the number of tet links, every tet link is in one of them.
    let (tet_links, pairs) = (0..nt)
        .into_par_iter()
        .with_min_len(4096)
        .map(|t| check_tet_links(m, t as u32))
        .try_reduce(|| (0, 0), |a, b| Ok((a.0 + b.0, a.1 + b.1)))?;
    if tet_links != 2 * pairs {
        // Some link n → t (t < n) is not answered: find it.
        for (n, links) in m.neighbors.iter().enumerate() {
            for (j, l) in links.iter().enumerate() {
                if let Some(t) = l.as_tet()
                    && (t as usize) < n
                    && (m.tets[t as usize].contains(&m.tets[n][j])
                        || m.face_towards(t, n as u32)
                            .is_none_or(|k| m.neighbors[t as usize][k].as_tet() != Some(n as u32)))
                {
                    return Err(MeshError::NeighborNotSymmetric {
                        tet: n as u32,
                        face: j as u8,
                        neighbor: t,
                    });
                }
            }
        }
        return Err(MeshError::NeighborNotSymmetric {
            tet: 0,
            face: 0,
            neighbor: 0,
        });
    }
    check_constrained_sides(m)?;
    check_face_classes(m)?;
    let a = &m.attributes;
    for (name, len, expected) in [
        ("normals", a.normals.as_ref().map(Vec::len), np),
        ("uvs", a.uvs.as_ref().map(Vec::len), np),
        (
            "materials",
            a.materials.as_ref().map(Vec::len),
            m.triangle_count as usize,
        ),
    ] {
        if let Some(actual) = len
            && actual != expected
        {
            return Err(MeshError::AttributeLength {
                name,
                actual,
                expected,
            });
        }
    }
    Ok(())
}

/// The links of tet `t`: a tet link to `n > t` names a tet that has exactly
/// the face's three vertices and links back through the face opposite its
/// fourth; a constrained link names a table entry with `(t, face)` as one
/// side. Returns (tet links of `t`, links to a higher tet checked).
fn check_tet_links(m: &TetMesh, t: u32) -> Result<(usize, usize), MeshError> {
    let a = m.tets[t as usize];
    let (mut tet_links, mut pairs) = (0, 0);
    for (k, link) in m.neighbors[t as usize].iter().enumerate() {
        let face = k as u8;
        match link.kind() {
            LinkKind::Boundary => {}
            LinkKind::Tet(n) => {
                tet_links += 1;
                if n <= t {
                    if n == t {
                        return Err(MeshError::SharedFaceMismatch {
                            tet: t,
                            face,
                            neighbor: n,
                        });
                    }
                    // Answered by the check from n's side (see the caller).
                    continue;
                }
                pairs += 1;
                let Some(&b) = m.tets.get(n as usize) else {
                    return Err(MeshError::NeighborOutOfBounds {
                        tet: t,
                        face,
                        neighbor: n,
                        tets: m.tets.len(),
                    });
                };
                let shares = !b.contains(&a[k]) && (0..4).all(|i| i == k || b.contains(&a[i]));
                let j = (0..4).find(|&j| !a.contains(&b[j]));
                let Some(j) = j.filter(|_| shares) else {
                    return Err(MeshError::SharedFaceMismatch {
                        tet: t,
                        face,
                        neighbor: n,
                    });
                };
                if m.neighbors[n as usize][j].as_tet() != Some(t) {
                    return Err(MeshError::NeighborNotSymmetric {
                        tet: t,
                        face,
                        neighbor: n,
                    });
                }
            }
            LinkKind::Constrained(c) => m.check_constrained_link(t, k, c)?,
        }
    }
    Ok((tet_links, pairs))
}

/// The constrained-face table, entry by entry and in parallel, with
/// [`TetMesh::validate`]'s own rules ([`TetMesh::check_constrained_face`]).
fn check_constrained_sides(m: &TetMesh) -> Result<(), MeshError> {
    (0..m.constrained.len())
        .into_par_iter()
        .with_min_len(4096)
        .try_for_each(|c| m.check_constrained_face(c))
}

/// Face manifoldness from class representatives (see [`check_construction`];
/// links and the constrained table must have been checked).
fn check_face_classes(m: &TetMesh) -> Result<(), MeshError> {
    // The representative face of each class: a linked pair from its lower
    // tet, a constrained face from its front side (back when one-sided),
    // every other face (mesh boundary) itself.
    let represents = |t: usize, k: usize| -> bool {
        match m.neighbors[t][k].kind() {
            LinkKind::Tet(n) => (t as u32) < n,
            LinkKind::Boundary => true,
            LinkKind::Constrained(c) => {
                let cf = &m.constrained[c as usize];
                let first = if cf.front.exists() { cf.front } else { cf.back };
                first.tet == t as u32 && first.face == k as u32
            }
        }
    };
    let reps: Vec<[u32; 3]> = m
        .tets
        .par_iter()
        .enumerate()
        .with_min_len(4096)
        .flat_map_iter(|(t, tet)| {
            (0..4).filter(move |&k| represents(t, k)).map(move |k| {
                let s = FACE_VERTICES[k];
                face_key([tet[s[0]], tet[s[1]], tet[s[2]]])
            })
        })
        .collect();
    // Bucket by smallest vertex (counting sort), keeping the other two.
    let np = m.points.len();
    let mut start = vec![0u32; np + 1];
    for key in &reps {
        start[key[0] as usize + 1] += 1;
    }
    for v in 0..np {
        start[v + 1] += start[v];
    }
    let mut next = start.clone();
    let mut rest = vec![0u64; reps.len()];
    for key in &reps {
        let slot = &mut next[key[0] as usize];
        rest[*slot as usize] = (u64::from(key[1]) << 32) | u64::from(key[2]);
        *slot += 1;
    }
    // Sort each bucket; chunks of whole buckets go to different threads.
    let mut buckets: Vec<(u32, &mut [u64])> = Vec::with_capacity(np);
    let mut tail: &mut [u64] = &mut rest;
    for v in 0..np {
        let len = (start[v + 1] - start[v]) as usize;
        let (head, t) = tail.split_at_mut(len);
        tail = t;
        if len > 1 {
            buckets.push((v as u32, head));
        }
    }
    let duplicate = buckets
        .par_iter_mut()
        .with_min_len(1024)
        .find_map_any(|(v, b)| {
            b.sort_unstable();
            b.windows(2)
                .find(|w| w[0] == w[1])
                .map(|w| [*v, (w[0] >> 32) as u32, w[0] as u32])
        });
    let Some(key) = duplicate else {
        return Ok(());
    };
    // Name one tet with that face (rare path: a linear scan).
    let (t, k) = (0..m.tets.len())
        .flat_map(|t| (0..4).map(move |k| (t, k)))
        .find(|&(t, k)| face_key(m.face_vertices(t as u32, k)) == key)
        .unwrap_or((0, 0));
    Err(MeshError::FaceNotManifold {
        tet: t as u32,
        face: k as u8,
        vertices: key,
        detail: "shared by tets that are not linked across it",
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};

    fn grid(seed: u64) -> TetMesh {
        let mut m = kuhn_grid(&GridSpec {
            cells: [4, 3, 3],
            constrained_fraction: 0.3,
            shell: Some(([1, 1, 1], [3, 2, 2])),
            seed,
            ..GridSpec::default()
        });
        let n = m.points.len();
        m.attributes.normals = Some((0..n).map(|i| Vec3::new(i as f32, 1.0, 0.0)).collect());
        m.attributes.uvs = Some((0..n).map(|i| Vec2::new(0.0, i as f32)).collect());
        m
    }

    #[test]
    fn construction_check_agrees_with_validate_on_corrupted_meshes() {
        // Every corruption that keeps tets positive (links, table, extra
        // tets, attributes): the construction check must reject exactly
        // when TetMesh::validate does.
        let mut rng = SplitMix64(11);
        let (mut rejected, mut accepted) = (0, 0);
        for case in 0..600u64 {
            let mut m = grid(case % 7);
            assert!(m.validate().is_ok() && check_construction(&m).is_ok());
            let nt = m.tets.len() as u64;
            let nc = m.constrained.len() as u64;
            let t = (rng.next_u64() % nt) as usize;
            let k = (rng.next_u64() % 4) as usize;
            match case % 8 {
                0 => m.neighbors[t][k] = Link::BOUNDARY,
                1 => m.neighbors[t][k] = Link::tet((rng.next_u64() % nt) as u32),
                2 => m.neighbors[t][k] = Link::constrained((rng.next_u64() % (nc + 2)) as u32),
                3 => {
                    // A side of a constrained face moved or dropped.
                    let c = (rng.next_u64() % nc) as usize;
                    let side = FaceSide {
                        tet: (rng.next_u64() % nt) as u32,
                        face: (rng.next_u64() % 4) as u32,
                    };
                    match rng.next_u64() % 3 {
                        0 => m.constrained[c].front = side,
                        1 => m.constrained[c].back = FaceSide::NONE,
                        _ => {
                            let cf = &mut m.constrained[c];
                            std::mem::swap(&mut cf.front, &mut cf.back);
                        }
                    }
                }
                4 => {
                    // A second copy of tet t, unlinked: every face key repeats.
                    m.tets.push(m.tets[t]);
                    m.neighbors.push([Link::BOUNDARY; 4]);
                }
                5 => {
                    // Two links swapped inside one tet.
                    let j = (k + 1 + (rng.next_u64() % 3) as usize) % 4;
                    m.neighbors[t].swap(k, j);
                }
                6 => {
                    let c = (rng.next_u64() % nc) as usize;
                    match rng.next_u64() % 3 {
                        0 => m.constrained[c].triangle = m.triangle_count,
                        1 => m.constrained[c].vertices.swap(0, 1),
                        _ => m
                            .attributes
                            .uvs
                            .as_mut()
                            .unwrap()
                            .pop()
                            .map(|_| ())
                            .unwrap(),
                    }
                }
                _ => {
                    // Two linked neighbours both made boundary: the face
                    // then belongs to two unlinked tets.
                    if let Some(n) = m.neighbors[t][k].as_tet() {
                        let j = m.face_towards(n, t as u32).unwrap();
                        m.neighbors[t][k] = Link::BOUNDARY;
                        m.neighbors[n as usize][j] = Link::BOUNDARY;
                    }
                }
            }
            let full = m.validate();
            let fast = check_construction(&m);
            assert_eq!(
                fast.is_ok(),
                full.is_ok(),
                "case {case}: construction check {fast:?} vs validate {full:?}"
            );
            if case % 8 == 4 {
                // Only the face-class check can see an unlinked duplicate.
                assert!(
                    matches!(fast, Err(MeshError::FaceNotManifold { .. })),
                    "{fast:?}"
                );
            }
            if full.is_ok() {
                accepted += 1;
            } else {
                rejected += 1;
            }
        }
        // Most corruptions are caught; a few are no-ops (e.g. a link set to
        // what it was) and must then be accepted by both.
        assert!(
            rejected > 450 && accepted > 0,
            "{rejected} rejected, {accepted} accepted"
        );
    }

    #[test]
    fn parallel_hilbert_reorder_equals_tet_core() {
        for seed in 0..4 {
            let mut a = grid(seed);
            // Scramble TetGen-like orders first so the sort has work to do.
            let mut rng = SplitMix64(seed);
            let mut order: Vec<u32> = (0..a.tets.len() as u32).collect();
            for i in (1..order.len()).rev() {
                order.swap(i, (rng.next_u64() % (i as u64 + 1)) as usize);
            }
            tet_core::reorder::apply_tet_permutation(&mut a, &order).unwrap();
            let mut b = a.clone();
            let ra = tet_core::reorder::hilbert_reorder(&mut a).unwrap();
            let rb = hilbert_reorder(&mut b);
            assert_eq!(ra, rb);
            assert_eq!(a, b);
            b.validate().unwrap();
        }
    }

    #[test]
    fn tetgen_adjacency_tolerates_garbage_face_tets_and_falls_back() {
        // Two tets sharing face (0,1,2); TetGen's raw order has tet 1
        // negatively oriented (slots 0/1 swapped by orient_tets).
        let points = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::new(0.2, 0.2, 1.0),
            Vec3::new(0.2, 0.2, -1.0),
        ];
        let raw = vec![[0, 1, 2, 3], [0, 1, 2, 4]];
        let p64: Vec<[f64; 3]> = points.iter().map(|p| p.as_dvec3().to_array()).collect();
        let (tets, bad) = orient_tets(&p64, &points, &raw);
        assert!(bad.is_empty());
        assert_eq!(tets[1], [1, 0, 2, 4]);
        // TetGen's neighbour k is opposite its own slot k.
        let neighbors = vec![[-1, -1, -1, 1], [-1, -1, -1, 0]];
        // Triangle 0 = the shared face, triangle 1 = a hull face of tet 0.
        let tris = vec![([0, 1, 2], 5), ([0, 3, 1], 6)];
        let reference = TetMesh::assemble(points.clone(), tets.clone(), &tris, 7).unwrap();
        for face_tets in [
            vec![[1, 0], [0, -1]],
            vec![[-146_509_888, 1], [i32::MAX, 0]],
            vec![[0, 77], [-1, 0]],
        ] {
            let adj = TetgenAdjacency {
                tets: &raw,
                neighbors: &neighbors,
                face_tets: &face_tets,
            };
            match assemble_from_tetgen(points.clone(), tets.clone(), &adj, &[0, 1], &tris, 7) {
                Ok(Assembled::Mesh(m)) => {
                    assert_eq!(m, reference, "{face_tets:?}");
                    check_construction(&m).unwrap();
                }
                _ => panic!("{face_tets:?}"),
            }
        }
        // No listed tet has face 1: hand the inputs back for the fallback.
        let face_tets = vec![[0, 1], [1, -1]];
        let adj = TetgenAdjacency {
            tets: &raw,
            neighbors: &neighbors,
            face_tets: &face_tets,
        };
        match assemble_from_tetgen(points.clone(), tets.clone(), &adj, &[0, 1], &tris, 7) {
            Ok(Assembled::Unavailable(p, t)) => assert!(p == points && t == tets),
            _ => panic!("expected a fallback"),
        }
        // A neighbour list that disagrees with the faces is an error.
        let wrong = vec![[-1, -1, -1, -1], [-1, -1, -1, 0]];
        let face_tets = vec![[0, 1], [0, -1]];
        let adj = TetgenAdjacency {
            tets: &raw,
            neighbors: &wrong,
            face_tets: &face_tets,
        };
        let m = match assemble_from_tetgen(points.clone(), tets.clone(), &adj, &[0, 1], &tris, 7) {
            Ok(Assembled::Mesh(m)) => m,
            _ => panic!(),
        };
        assert!(check_construction(&m).is_err() && m.validate().is_err());
    }

    /// Post-TetGen stage costs on "Torus Knots in a Box", best of 10 (run in
    /// release: `cargo test --release -p tet-build --lib -- --ignored
    /// --nocapture stage_timing`).
    #[test]
    #[ignore]
    fn stage_timing() {
        let reps: usize = std::env::var("TET_STAGE_REPS")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(10);
        let best = |f: &mut dyn FnMut() -> Duration| (0..reps).map(|_| f()).min().unwrap();
        // TET_STAGE_OBJ=path.obj times that scene (convex hull) instead.
        let scene = match std::env::var("TET_STAGE_OBJ") {
            Ok(path) => crate::scene::Scene::load_obj(std::path::Path::new(&path)).unwrap(),
            Err(_) => crate::procedural::by_name("torus-knots-box").unwrap(),
        };
        let (mesh, _) = build(&scene, &BuildOptions::default()).unwrap();
        println!("{}: {} tets", scene.name, mesh.tets.len());
        println!("rayon threads: {}", rayon::current_num_threads());
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        let t = best(&mut || {
            let mut m = mesh.clone();
            let s = Instant::now();
            hilbert_reorder(&mut m);
            s.elapsed()
        });
        let r = best(&mut || {
            let mut m = mesh.clone();
            let s = Instant::now();
            tet_core::reorder::hilbert_reorder(&mut m).unwrap();
            s.elapsed()
        });
        println!(
            "hilbert reorder: parallel {:.1} ms, tet_core {:.1} ms",
            ms(t),
            ms(r)
        );
        let q = Quantizer::from_points(&mesh.points);
        let keys = best(&mut || {
            let s = Instant::now();
            let k: Vec<u64> = mesh
                .tets
                .iter()
                .map(|t| {
                    let c: Vec3 = t.iter().map(|&v| mesh.points[v as usize]).sum();
                    hilbert_key(&q, c * 0.25)
                })
                .collect();
            std::hint::black_box(k);
            s.elapsed()
        });
        let keys_seq = best(&mut || {
            let s = Instant::now();
            let k = tet_core::reorder::tet_keys(&mesh, &q);
            std::hint::black_box(k);
            s.elapsed()
        });
        let k = tet_core::reorder::tet_keys(&mesh, &q);
        let sort = best(&mut || {
            let k = k.clone();
            let s = Instant::now();
            std::hint::black_box(order_by_key(k));
            s.elapsed()
        });
        println!(
            "tet keys sequential: fast {:.1} ms, tet_core {:.1} ms; parallel sort {:.1} ms",
            ms(keys),
            ms(keys_seq),
            ms(sort)
        );
        let cells: Vec<[u32; 3]> = mesh
            .tets
            .iter()
            .map(|t| {
                let c: Vec3 = t.iter().map(|&v| mesh.points[v as usize]).sum();
                q.cell(c * 0.25)
            })
            .collect();
        let (mut fast, mut core, mut machine) = (Duration::MAX, Duration::MAX, Duration::MAX);
        for _ in 0..reps * 3 {
            let s = Instant::now();
            std::hint::black_box(
                cells
                    .iter()
                    .map(|&c| hilbert_index_fast(c, 21))
                    .fold(0u64, |a, b| a ^ b),
            );
            fast = fast.min(s.elapsed());
            let s = Instant::now();
            std::hint::black_box(
                cells
                    .iter()
                    .map(|&c| tet_core::hilbert::hilbert_index(c, 21))
                    .fold(0u64, |a, b| a ^ b),
            );
            core = core.min(s.elapsed());
            let table = HilbertTable::get().unwrap();
            let s = Instant::now();
            std::hint::black_box(
                cells
                    .iter()
                    .map(|&c| table.index(c, 21))
                    .fold(0u64, |a, b| a ^ b),
            );
            machine = machine.min(s.elapsed());
        }
        println!(
            "hilbert index only, {} cells: branch-free {:.1} ms, state machine {:.1} ms, tet_core {:.1} ms",
            cells.len(),
            ms(fast),
            ms(machine),
            ms(core)
        );
        let c = best(&mut || {
            let s = Instant::now();
            check_construction(&mesh).unwrap();
            s.elapsed()
        });
        let links = best(&mut || {
            let s = Instant::now();
            (0..mesh.tets.len())
                .into_par_iter()
                .with_min_len(4096)
                .try_for_each(|t| check_tet_links(&mesh, t as u32).map(|_| ()))
                .unwrap();
            s.elapsed()
        });
        let classes = best(&mut || {
            let s = Instant::now();
            check_face_classes(&mesh).unwrap();
            s.elapsed()
        });
        let v = best(&mut || {
            let s = Instant::now();
            mesh.validate().unwrap();
            s.elapsed()
        });
        println!(
            "construction check {:.1} ms (links {:.1}, face classes {:.1}), validate {:.1} ms",
            ms(c),
            ms(links),
            ms(classes),
            ms(v)
        );
    }

    #[test]
    fn fast_hilbert_index_equals_tet_core() {
        let mut rng = SplitMix64(3);
        for bits in 1..=21u32 {
            for _ in 0..3000 {
                let c = [
                    rng.next_u64() as u32,
                    rng.next_u64() as u32,
                    rng.next_u64() as u32,
                ];
                assert_eq!(
                    hilbert_index_fast(c, bits),
                    tet_core::hilbert::hilbert_index(c, bits),
                    "{c:?} at {bits} bits"
                );
            }
        }
        // Extremes of the lattice.
        for c in [
            [0, 0, 0],
            [u32::MAX; 3],
            [0x1f_ffff, 0, 0x1f_ffff],
            [1, 2, 4],
        ] {
            assert_eq!(
                hilbert_index_fast(c, 21),
                tet_core::hilbert::hilbert_index(c, 21)
            );
        }
    }

    #[test]
    fn hilbert_state_machine_equals_tet_core() {
        let table = HilbertTable::get().expect("the reference curve is self-similar");
        assert!(table.next.len() <= 48);
        let mut rng = SplitMix64(5);
        for bits in 1..=21u32 {
            let mask = (1u32 << bits) - 1;
            for _ in 0..3000 {
                let c = [
                    rng.next_u64() as u32,
                    rng.next_u64() as u32,
                    rng.next_u64() as u32,
                ]
                .map(|v| v & mask);
                assert_eq!(
                    table.index(c, bits),
                    tet_core::hilbert::hilbert_index(c, bits),
                    "{c:?} at {bits} bits"
                );
            }
        }
        // Exhaustively on a 16³ lattice.
        for x in 0..16u32 {
            for y in 0..16u32 {
                for z in 0..16u32 {
                    assert_eq!(
                        table.index([x, y, z], 4),
                        tet_core::hilbert::hilbert_index([x, y, z], 4)
                    );
                }
            }
        }
    }

    #[test]
    fn snapping_moves_a_flattened_steiner_point_off_the_plane() {
        // Tet (0,1,2,3) with Steiner point 3 at height 1e-50: positive in
        // f64, flat once rounded to f32 (1e-50 → 0). Snapping must move it
        // to a positive f32 height (the next f32 above 0), keeping the tet.
        let p64 = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.25, 0.25, 1e-50],
        ];
        let mut p32: Vec<Vec3> = p64
            .iter()
            .map(|p| Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32))
            .collect();
        let (tets, bad) = orient_tets(&p64, &p32, &[[0, 1, 2, 3]]);
        assert_eq!(bad, vec![0]);
        let (moved, still) = snap_steiner_points(&p64, &mut p32, &tets, &bad, 3);
        assert_eq!((moved, still), (1, vec![]));
        assert!(p32[3].z > 0.0 && p32[3].z <= 3.0 * f32::from_bits(1));
        assert_eq!(p32[3].x, 0.25);
        // Input points (index < first_steiner) are never moved.
        let mut q32: Vec<Vec3> = p64
            .iter()
            .map(|p| Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32))
            .collect();
        let (moved, still) = snap_steiner_points(&p64, &mut q32, &tets, &bad, 4);
        assert_eq!((moved, still), (0, vec![0]));
    }
}
