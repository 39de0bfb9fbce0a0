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
//! * **Validation**: the result always passes [`TetMesh::validate`]; the
//!   pipeline never returns a mesh that does not.

#![cfg(feature = "tetgen")]

use std::sync::Arc;
use std::time::{Duration, Instant};

use glam::{DVec3, Vec2, Vec3};
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
    /// Validating the mesh.
    Validate,
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
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions {
            tetgen: TetgenOptions::default(),
            isolation: Isolation::InProcess,
            enclosing_box: None,
            max_rounding_rounds: 4,
            progress: None,
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
    /// Neighbours and constrained-face table ([`TetMesh::assemble`]).
    pub assemble: Duration,
    /// [`TetMesh::validate`].
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
    let mut report = BuildReport {
        switches: options.tetgen.switches(),
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
        let out = match tetrahedralize(&input, &options.tetgen, &options.isolation) {
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
    let mut mesh = TetMesh::assemble(points32, tets, &tris, scene.triangles.len() as u32)?;
    report.times.assemble = t.elapsed();
    // Attributes: scene vertices are the first points; box corners and
    // Steiner points get zero normals / uvs.
    if let Some(n) = &cleaned.normals {
        let mut v = n.clone();
        v.resize(n_points, Vec3::ZERO);
        mesh.attributes.normals = Some(v);
    }
    if let Some(uv) = &cleaned.uvs {
        let mut v = uv.clone();
        v.resize(n_points, Vec2::ZERO);
        mesh.attributes.uvs = Some(v);
    }
    debug_assert!(n_scene_vertices <= n_points);

    progress(Stage::Validate);
    let t = Instant::now();
    mesh.validate()?;
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
fn orient_tets(p64: &[[f64; 3]], p32: &[Vec3], tets: &[[u32; 4]]) -> (Vec<[u32; 4]>, Vec<u32>) {
    let mut out = Vec::with_capacity(tets.len());
    let mut bad = Vec::new();
    for (i, &t) in tets.iter().enumerate() {
        let [a, b, c, d] = t.map(|v| DVec3::from_array(p64[v as usize]));
        let o = tet_core::predicates::orient3d(a, b, c, d);
        let t = if o < 0.0 { [t[1], t[0], t[2], t[3]] } else { t };
        let [a, b, c, d] = t.map(|v| p32[v as usize]);
        if o == 0.0 || tet_core::predicates::orient3d_f32(a, b, c, d) <= 0.0 {
            bad.push(i as u32);
        }
        out.push(t);
    }
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

#[cfg(test)]
mod tests {
    use super::*;

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
