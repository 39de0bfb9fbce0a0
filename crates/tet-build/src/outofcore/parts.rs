//! The parts of a split and their TetGen runs: [`SeamOptions`], each part's
//! PLC run through TetGen `-pY` (every seam facet must come back as exactly
//! one face, see [`super::facet_faces`]) or, as a last resort, with its
//! surface relaxed ([`SurfaceMode`]), several parts at a time, and the
//! [`SeamReport`] of a split build.

use std::collections::HashMap;
use std::time::Duration;

use glam::{DVec3, Vec3};

use super::admission::Admission;
use super::error::SeamError;
pub(super) use super::facet_faces::FacetKind;
use super::facet_faces::{TetgenFaces, constrained_faces};
use super::part_cache::{PartCache, PlcPrint};
use super::plane::{SplitPlane, key};
use crate::bbox::BoxSpec;
use crate::pipeline::rounding::{
    FeedBack, feed_back_steiner_points, orient_tets, snap_steiner_points,
};
use crate::resolve::{ResolveOptions, ResolveReport};
use crate::tetgen::{Isolation, TetgenError, TetgenInput, TetgenOptions, tetrahedralize};

/// What [`build_slabs`](super::seam::build_slabs) (and [`build_split_once`](super::seam::build_split_once)) did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SeamReport {
    /// Scene triangles (after cleaning) strictly crossing at least one plane.
    pub triangles_cut: usize,
    /// Scene triangles lying in one of the planes.
    pub triangles_in_plane: usize,
    /// Vertices of each seam triangulation (including its 4 section corners).
    pub seam_vertices: Vec<usize>,
    /// Triangles of each seam triangulation.
    pub seam_triangles: Vec<usize>,
    /// Each seam: its plane and its rectangle (lower and upper corner; the
    /// plane's coordinate is the same in both), in the order of
    /// `seam_vertices`. Used by [`super::report::seam_quality`].
    pub seams: Vec<(SplitPlane, Vec3, Vec3)>,
    /// Input points of each part's PLC (part `k` lies between planes `k − 1` and `k`).
    pub part_points: Vec<usize>,
    /// Facets of each part's PLC.
    pub part_triangles: Vec<usize>,
    /// Points of each part's PLC used by no scene facet (wall corners,
    /// trace points): the part of `part_points` the memory model counts
    /// at the wall rate.
    pub part_wall_points: Vec<usize>,
    /// Facets of each part's PLC that are seam-only or box faces.
    pub part_wall_triangles: Vec<usize>,
    /// Tets of each part.
    pub part_tets: Vec<usize>,
    /// Peak memory of each part's worker (KiB), when isolated.
    pub part_peak_kib: Vec<Option<u64>>,
    /// Predicted peak memory of each part's TetGen run from its real input
    /// ([`super::memory_model::predict_part_peak_memory`], bytes, with margin).
    pub part_predicted_bytes: Vec<u64>,
    /// Scene pieces of each part that TetGen returned split by Steiner
    /// points it could not move off the surface (kept: see
    /// [`super::facet_faces`]).
    pub part_split_pieces: Vec<usize>,
    /// What resolving the whole scene's self-intersections did, before it
    /// was split (`None` when [`SeamOptions::resolve`] is off).
    pub resolve: Option<ResolveReport>,
    /// Parts a retry took as an earlier attempt built them, their input
    /// unchanged by the planes the retry moved (0 without a retry).
    pub parts_reused: usize,
    /// How each part's TetGen run kept the surface: [`SurfaceMode::Preserved`]
    /// but for the parts built with the surface relaxed
    /// ([`SeamOptions::surface_relaxed_parts`]).
    pub part_surface: Vec<SurfaceMode>,
}

/// Options of [`build_slabs`](super::seam::build_slabs).
#[derive(Clone, Debug, PartialEq)]
pub struct SeamOptions {
    /// Box around the scene (the whole mesh's boundary).
    pub enclosing_box: BoxSpec,
    /// TetGen switches (`-Y` is forced on, but for
    /// [`SeamOptions::surface_relaxed_parts`]).
    pub tetgen: TetgenOptions,
    /// Where TetGen runs.
    pub isolation: Isolation,
    /// Run the parts concurrently (one thread each, at most this many at a
    /// time; 0 or 1 = one after the other). Only worth it with
    /// [`Isolation::Worker`]: in-process TetGen runs are serialized.
    pub parallel_parts: usize,
    /// A limit on the resident memory of the whole process tree (this
    /// process and its workers), bytes: a part's worker starts only while
    /// this process's resident memory, the parts already running and this
    /// part's prediction (with this process's share of its result) fit
    /// it ([`super::admission`]); one part alone always starts. `None`:
    /// `parallel_parts` alone decides.
    pub tree_limit_bytes: Option<u64>,
    /// Resolve the cleaned scene's self-intersections before splitting it
    /// ([`crate::resolve`], as the in-core build does); `None` hands
    /// crossing triangles to TetGen as they are.
    pub resolve: Option<ResolveOptions>,
    /// Parts (by index) TetGen builds with the surface relaxed: first with
    /// [`SurfaceMode::SteinerOffSurface`], and where that fails with
    /// [`SurfaceMode::Unlocked`] (walls must still come back whole: see
    /// [`super::facet_faces`]). The last resort of a build for a part whose
    /// walls moved and which TetGen still fails on: at 30 M triangles, a
    /// part whose feature below TetGen's default tolerance makes `-Y` loop
    /// wherever its walls stand. Empty by default.
    pub surface_relaxed_parts: Vec<usize>,
}

/// How a part's TetGen run treats the scene surface.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SurfaceMode {
    /// `-Y`: the surface as given; scene pieces split only where TetGen
    /// cannot move a boundary Steiner point off them. Every part unless
    /// relaxed.
    #[default]
    Preserved,
    /// `-Y/2`: the same, but a Steiner point that recovering a segment
    /// needs goes into the volume, not onto the segment
    /// ([`TetgenOptions::steiner_off_surface`]).
    SteinerOffSurface,
    /// Without `-Y` and with a coplanar tolerance of at most
    /// [`RELAXED_COPLANAR_TOLERANCE`]: TetGen may split scene pieces (and
    /// walls, which the part's check then refuses) with Steiner points.
    Unlocked,
}

impl SurfaceMode {
    /// The mode's name in reports: `preserved`, `steiner-off-surface`,
    /// `unlocked`.
    pub fn name(self) -> &'static str {
        match self {
            SurfaceMode::Preserved => "preserved",
            SurfaceMode::SteinerOffSurface => "steiner-off-surface",
            SurfaceMode::Unlocked => "unlocked",
        }
    }
}

/// The coplanar tolerance (`-T`) of [`SurfaceMode::Unlocked`]: on the 30 M
/// part `-Y` looped on, TetGen without `-Y` reports a feature below its
/// default 1e-8 (code 4) and at 1e-12 builds the part in a second.
pub const RELAXED_COPLANAR_TOLERANCE: f64 = 1e-12;

impl Default for SeamOptions {
    /// The in-core build's defaults: no box spec beyond the default,
    /// default TetGen switches, in-process, one part at a time, resolving.
    fn default() -> Self {
        SeamOptions {
            enclosing_box: BoxSpec::default(),
            tetgen: TetgenOptions::default(),
            isolation: Isolation::default(),
            parallel_parts: 0,
            tree_limit_bytes: None,
            resolve: Some(ResolveOptions::default()),
            surface_relaxed_parts: Vec::new(),
        }
    }
}

impl SeamOptions {
    /// The TetGen runs to try on part `part`, in order, with their
    /// switches: `-Y` forced on, or, for one of
    /// [`SeamOptions::surface_relaxed_parts`], the relaxed modes.
    pub(super) fn tetgen_for_part(&self, part: usize) -> Vec<(SurfaceMode, TetgenOptions)> {
        let preserved = TetgenOptions {
            preserve_surface: true,
            steiner_off_surface: false,
            ..self.tetgen.clone()
        };
        if !self.surface_relaxed_parts.contains(&part) {
            return vec![(SurfaceMode::Preserved, preserved)];
        }
        let tol = preserved
            .coplanar_tolerance
            .map_or(RELAXED_COPLANAR_TOLERANCE, |t| {
                t.min(RELAXED_COPLANAR_TOLERANCE)
            });
        vec![
            (
                SurfaceMode::SteinerOffSurface,
                TetgenOptions {
                    steiner_off_surface: true,
                    ..preserved.clone()
                },
            ),
            (
                SurfaceMode::Unlocked,
                TetgenOptions {
                    preserve_surface: false,
                    coplanar_tolerance: Some(tol),
                    ..preserved
                },
            ),
        ]
    }
}

/// One part's PLC: its facets (scene pieces and wall triangles) and its
/// box faces (unmarked facets; empty for a tree, whose walls are among
/// the facets).
pub(super) struct PartFacetList {
    pub(super) facets: Vec<([Vec3; 3], FacetKind)>,
    pub(super) box_faces: Vec<[Vec3; 3]>,
}

/// Where the parts' PLCs come from: made one part at a time, so that a
/// planner or a local build holds every part's facets only while that
/// part is written or built, never all of them at once.
pub(super) trait PartFacets: Send + Sync {
    /// How many parts.
    fn len(&self) -> usize;
    /// About how many facets part `k` has (for the order parts start in).
    fn size(&self, k: usize) -> usize;
    /// Part `k`'s PLC.
    fn facets(&self, k: usize) -> Result<PartFacetList, SeamError>;
}

/// What one part's TetGen run took and gave (the per-part report fields).
#[derive(Clone, Copy, Debug)]
pub(super) struct PartStats {
    pub(super) input_points: usize,
    pub(super) input_triangles: usize,
    /// Points used by no scene facet (seam and box corners, trace points).
    pub(super) wall_points: usize,
    /// Facets that are not scene pieces (seam-only and box faces).
    pub(super) wall_triangles: usize,
    pub(super) tets: usize,
    pub(super) peak_kib: Option<u64>,
    /// Scene pieces TetGen returned split by boundary Steiner points.
    pub(super) split_pieces: usize,
    /// How TetGen kept the surface.
    pub(super) surface: SurfaceMode,
}

/// One part after TetGen: f32 points, positive tets, constrained faces.
pub(super) struct PartMesh {
    pub(super) points: Vec<Vec3>,
    pub(super) tets: Vec<[u32; 4]>,
    /// (vertices, cleaned source) in the part's point indices.
    pub(super) constrained: Vec<([u32; 3], u32)>,
    pub(super) stats: PartStats,
}

/// A part's PLC as TetGen receives it: its facets' points deduplicated by
/// their exact bits, facets marked `1..` in order, box faces unmarked.
pub(super) struct PartPlc {
    pub(super) points: Vec<Vec3>,
    pub(super) input: TetgenInput,
    /// Points used by no scene facet.
    pub(super) wall_points: usize,
    /// Facets that are not scene pieces (seam-only and box faces).
    pub(super) wall_triangles: usize,
}

impl PartPlc {
    /// The PLC of a part's `facets` and `box_faces`.
    pub(super) fn new(facets: &[([Vec3; 3], FacetKind)], box_faces: &[[Vec3; 3]]) -> PartPlc {
        let mut index: HashMap<[u32; 3], u32> = HashMap::new();
        let mut points: Vec<Vec3> = Vec::new();
        let mut id = |p: Vec3| {
            *index.entry(key(p)).or_insert_with(|| {
                points.push(p);
                points.len() as u32 - 1
            })
        };
        let mut triangles = Vec::new();
        let mut markers = Vec::new();
        for (i, (t, _)) in facets.iter().enumerate() {
            triangles.push(t.map(&mut id));
            markers.push(i as i32 + 1);
        }
        for t in box_faces {
            triangles.push(t.map(&mut id));
            markers.push(0);
        }
        let mut on_scene = vec![false; points.len()];
        for ((_, k), t) in facets.iter().zip(&triangles) {
            if matches!(k, FacetKind::Scene(_)) {
                for &v in t {
                    on_scene[v as usize] = true;
                }
            }
        }
        let wall_points = on_scene.iter().filter(|&&s| !s).count();
        let wall_triangles = facets
            .iter()
            .filter(|(_, k)| matches!(k, FacetKind::Seam))
            .count()
            + box_faces.len();
        let input = TetgenInput {
            points: points.iter().map(|p| p.as_dvec3().to_array()).collect(),
            triangles,
            markers,
        };
        PartPlc {
            points,
            input,
            wall_points,
            wall_triangles,
        }
    }

    /// The memory model's prediction of TetGen's peak on this PLC
    /// ([`super::memory_model::predict_part_peak_memory`], bytes).
    pub(super) fn predicted_peak_bytes(&self) -> u64 {
        let (points, triangles) = (self.input.points.len(), self.input.triangles.len());
        super::memory_model::predict_part_peak_memory(
            points - self.wall_points,
            triangles - self.wall_triangles,
            self.wall_points,
            self.wall_triangles,
        )
    }
}

/// Runs TetGen on one part's facets and checks the result.
pub(super) fn run_part(
    part: usize,
    facets: &[([Vec3; 3], FacetKind)],
    box_faces: &[[Vec3; 3]],
    options: &SeamOptions,
) -> Result<PartMesh, SeamError> {
    run_plc(part, facets, PartPlc::new(facets, box_faces), options)
}

/// The time limit of one part's TetGen run in a build that retries (a
/// local build, or a job planned again over its failed parts):
/// [`PART_TIME_FLOOR`] plus [`PART_TIME_PER_ELEMENT`] for each point and
/// triangle of its PLC, ten to thirty times what such a part takes. A run
/// far past its size's time has met a configuration TetGen's boundary
/// recovery loops on (at 30 M triangles, a few parts of thousands); the build
/// moves that part's walls and tries again sooner than a fixed limit
/// sized for the largest part would let it.
fn part_time_limit(points: usize, triangles: usize) -> Duration {
    PART_TIME_FLOOR + PART_TIME_PER_ELEMENT * (points + triangles).min(u32::MAX as usize) as u32
}

/// `isolation` with a worker's time limit cut to [`part_time_limit`] of a
/// part of `points` and `triangles` (in process: unchanged, TetGen cannot
/// be stopped there).
pub(super) fn timed_for_part(isolation: &Isolation, points: usize, triangles: usize) -> Isolation {
    match isolation {
        Isolation::Worker(w) => {
            let limit = part_time_limit(points, triangles);
            let mut w = w.clone();
            w.timeout = Some(w.timeout.map_or(limit, |t| t.min(limit)));
            Isolation::Worker(w)
        }
        other => other.clone(),
    }
}

/// See [`part_time_limit`].
const PART_TIME_FLOOR: Duration = Duration::from_secs(10);

/// See [`part_time_limit`].
const PART_TIME_PER_ELEMENT: Duration = Duration::from_millis(2);

/// TetGen runs on one part before rounding gives up: the first, then
/// re-runs with rounded Steiner points as input points.
const MAX_PART_ROUNDS: usize = 4;

/// Runs TetGen on a part's PLC (made of `facets`) and checks the result.
///
/// Rounding TetGen's Steiner points to f32 may flatten or invert tets;
/// those points are first snapped to a neighbouring f32 value
/// ([`snap_steiner_points`]), and where that is not enough TetGen runs
/// again with the rounded Steiner points of the tets still flat as input
/// points, so that its exact predicates see the coordinates the mesh
/// stores ([`FeedBack::FlatTets`]: only those, unlike the in-core build).
/// Fed-back points lie strictly inside the part's box (TetGen keeps every
/// wall facet whole), so the walls, and the seams, do not change.
///
/// A part built with its surface relaxed tries each mode of
/// [`SeamOptions::tetgen_for_part`] in turn and keeps the first that
/// passes every check; when none does, the first mode's error is returned.
fn run_plc(
    part: usize,
    facets: &[([Vec3; 3], FacetKind)],
    mut plc: PartPlc,
    options: &SeamOptions,
) -> Result<PartMesh, SeamError> {
    let modes = options.tetgen_for_part(part);
    let mut first_error = None;
    for (i, (mode, topts)) in modes.iter().enumerate() {
        // The last mode takes the PLC, the others a copy (fed-back points
        // change it).
        let input = if i + 1 == modes.len() {
            std::mem::take(&mut plc.input)
        } else {
            plc.input.clone()
        };
        match run_plc_as(part, facets, &plc, input, *mode, topts, &options.isolation) {
            Ok(mesh) => return Ok(mesh),
            Err(e) => {
                first_error.get_or_insert(e);
            }
        }
    }
    Err(first_error.expect("at least one mode"))
}

/// [`run_plc`] in one surface mode, on `input` (the PLC's TetGen input or
/// a copy).
fn run_plc_as(
    part: usize,
    facets: &[([Vec3; 3], FacetKind)],
    plc: &PartPlc,
    mut input: TetgenInput,
    surface: SurfaceMode,
    topts: &TetgenOptions,
    isolation: &Isolation,
) -> Result<PartMesh, SeamError> {
    let PartPlc {
        ref points,
        wall_points,
        wall_triangles,
        ..
    } = *plc;
    let plc_points = input.points.len();
    let plc_triangles = input.triangles.len();
    let mut last_bad = 0;
    for round in 1..=MAX_PART_ROUNDS {
        let out = match tetrahedralize(&input, topts, isolation) {
            Ok(out) => out,
            // A repair round failed (a rounded point too close to a facet).
            Err(_) if round > 1 => {
                return Err(SeamError::RoundingFlattens {
                    part,
                    count: last_bad,
                });
            }
            Err(TetgenError::SelfIntersection) => {
                return Err(self_intersection(part, facets, points, &input.triangles));
            }
            Err(source) => return Err(SeamError::Tetgen { part, source }),
        };
        if let Some(i) =
            (0..input.points.len()).find(|&i| out.points.get(i) != Some(&input.points[i]))
        {
            return Err(SeamError::InputPointChanged { part, point: i });
        }
        // Seam facets must be exactly one face with their own vertices;
        // scene pieces may be split inside the part (see `facet_faces`).
        let returned = TetgenFaces {
            points: &out.points,
            faces: &out.faces,
            markers: &out.face_markers,
        };
        let constrained = constrained_faces(part, facets, &input.triangles, plc_points, &returned)?;
        let mut p32: Vec<Vec3> = out
            .points
            .iter()
            .map(|p| Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32))
            .collect();
        let (tets, mut bad) = orient_tets(&out.points, &p32, &out.tets);
        if !bad.is_empty() {
            (_, bad) = snap_steiner_points(
                &|v| DVec3::from_array(out.points[v as usize]),
                &mut p32,
                &tets,
                &bad,
                input.points.len(),
            );
        }
        if bad.is_empty() {
            return Ok(PartMesh {
                stats: PartStats {
                    input_points: plc_points,
                    input_triangles: plc_triangles,
                    wall_points,
                    wall_triangles,
                    tets: tets.len(),
                    peak_kib: out.worker_peak_kib,
                    split_pieces: constrained.split_pieces,
                    surface,
                },
                points: p32,
                tets,
                constrained: constrained.faces,
            });
        }
        last_bad = bad.len();
        // Feed the rounded Steiner points of the tets still flat back.
        let to_tetgen = |p: Vec3| p.as_dvec3().to_array();
        let which = FeedBack::FlatTets;
        if feed_back_steiner_points(&mut input.points, &p32, which, &tets, &bad, &to_tetgen) == 0 {
            break;
        }
    }
    Err(SeamError::RoundingFlattens {
        part,
        count: last_bad,
    })
}

/// Names the first intersecting pair of a part's PLC (TetGen only says
/// that there is one).
pub(super) fn self_intersection(
    part: usize,
    facets: &[([Vec3; 3], FacetKind)],
    points: &[Vec3],
    triangles: &[[u32; 3]],
) -> SeamError {
    let r = crate::intersect::find_self_intersections(points, triangles);
    let what = |i: u32| {
        let t = triangles[i as usize].map(|v| points[v as usize]);
        let s = match facets.get(i as usize) {
            Some((_, FacetKind::Scene(s))) => Some(*s),
            _ => None,
        };
        (t, s)
    };
    match r.pairs.first() {
        Some(p) => SeamError::PartSelfIntersects {
            part,
            first: what(p.first),
            second: what(p.second),
            kind: p.kind,
            pairs: r.pairs.len(),
        },
        None => SeamError::Tetgen {
            part,
            source: TetgenError::SelfIntersection,
        },
    }
}

/// Runs TetGen on every part, at most `options.parallel_parts` at a time
/// (and, under `options.tree_limit_bytes`, only as many as fit it):
/// that many threads take the next part from a queue as soon as their
/// previous one finishes (largest input first, so a big part does not
/// start last), which keeps both threads busy when parts differ in size.
/// Each part is handed to `finish` on its thread as soon as its TetGen
/// run returns. Results are in part order; the first error (in part order)
/// is returned. With a `cache` (a build that retries), a part whose PLC is
/// one the cache kept is taken from it instead of run; a part that fails
/// in a way a retry may cure ([`SeamError::part_to_retry`]) does not stop
/// the others, so that one attempt finds every such part (returned as
/// [`SeamError::PartsFailed`] when there are several); each part's TetGen
/// run has [`part_time_limit`] (under the isolation's own limit); and
/// when any part fails, the parts finished are kept in the cache for the
/// next attempt ([`PartCache`]).
pub(super) fn run_parts<T: Send>(
    parts: &dyn PartFacets,
    options: &SeamOptions,
    finish: &(dyn Fn(usize, PartMesh) -> Result<T, SeamError> + Sync),
    cache: Option<&PartCache<T>>,
) -> Result<Vec<T>, SeamError> {
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    let count = parts.len();
    let width = options.parallel_parts.max(1).min(count.max(1));
    let mut order: Vec<usize> = (0..count).collect();
    order.sort_by_key(|&k| std::cmp::Reverse(parts.size(k)));
    type Finished<T> = Result<(Option<PlcPrint>, T), SeamError>;
    let results: Vec<Mutex<Option<Finished<T>>>> = (0..count).map(|_| Mutex::new(None)).collect();
    let next = AtomicUsize::new(0);
    let failed = AtomicBool::new(false);
    let admission = Admission::new(options.tree_limit_bytes);
    let work = || {
        loop {
            let i = next.fetch_add(1, Ordering::Relaxed);
            if i >= order.len() || failed.load(Ordering::Relaxed) {
                break;
            }
            let k = order[i];
            let r = parts.facets(k).and_then(|list| {
                let print = cache.map(|_| PlcPrint::of(&list.facets, &list.box_faces));
                if let (Some(c), Some(p)) = (cache, print)
                    && let Some(kept) = c.take(k, p)
                {
                    return Ok((print, kept));
                }
                let plc = PartPlc::new(&list.facets, &list.box_faces);
                // Held until the part is handed on: this process's share
                // of the result counts as long as the worker's.
                let _ticket = admission.enter(plc.predicted_peak_bytes());
                let timed;
                let part_options = match cache {
                    Some(_) => {
                        timed = SeamOptions {
                            isolation: timed_for_part(
                                &options.isolation,
                                plc.input.points.len(),
                                plc.input.triangles.len(),
                            ),
                            ..options.clone()
                        };
                        &timed
                    }
                    None => options,
                };
                let part =
                    run_plc(k, &list.facets, plc, part_options).and_then(|m| finish(k, m))?;
                Ok((print, part))
            });
            if let Err(e) = &r
                && (cache.is_none() || e.part_to_retry().is_none())
            {
                failed.store(true, Ordering::Relaxed);
            }
            *results[k].lock().unwrap_or_else(|e| e.into_inner()) = Some(r);
        }
    };
    if width == 1 {
        work();
    } else {
        std::thread::scope(|scope| {
            let handles: Vec<_> = (0..width).map(|_| scope.spawn(work)).collect();
            for h in handles {
                h.join().unwrap_or_else(|e| std::panic::resume_unwind(e));
            }
        });
    }
    let mut out = Vec::with_capacity(count);
    // A failure a retry cannot cure comes first: retrying would meet it again.
    let (mut fatal, mut curable) = (None, Vec::new());
    for (k, r) in results.into_iter().enumerate() {
        match r.into_inner().unwrap_or_else(|e| e.into_inner()) {
            Some(Ok(m)) => out.push((k, m)),
            Some(Err(e)) if e.part_to_retry().is_some() => curable.push(e),
            Some(Err(e)) => {
                fatal.get_or_insert(e);
            }
            None => {}
        }
    }
    let first_error = fatal.or_else(|| SeamError::parts_failed(curable));
    match first_error {
        Some(e) => {
            if let Some(c) = cache {
                for (k, (print, part)) in out {
                    if let Some(p) = print {
                        c.keep(k, p, part);
                    }
                }
            }
            Err(e)
        }
        None => Ok(out.into_iter().map(|(_, (_, part))| part).collect()),
    }
}
