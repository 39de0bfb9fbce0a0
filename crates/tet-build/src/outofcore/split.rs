//! Recursive split plan (Erkoç et al. 2021, §3 `CLIP`): while a part's
//! predicted TetGen memory exceeds the limit, cut it by an axis-aligned
//! plane through the mean of the axis of largest variance; among nearby
//! planes prefer the one that cuts the fewest triangles (the paper's future
//! work). Before that rule, a part whose detail sits in a core far smaller
//! than its box (a scene in a room or a box) has its thick empty margin cut
//! off along the core ([`peel_plane`]): planes of the mean rule would run
//! from the core through the empty space to the box, and the walls there
//! cost every ray crossing the empty space many thin tets.
//!
//! Planes are axis-aligned with an `f32` offset, so points computed on the
//! plane later (seams) have that exact coordinate on the cut axis.
//!
//! ## Classification (exact, on f32 coordinates)
//! A triangle is *below* a plane `x[axis] = value` when one of its vertices
//! has `x[axis] < value`, *above* when one has `x[axis] > value`, *cut* when
//! both, and *in the plane* when all three equal `value` (it then belongs to
//! both halves: it is part of the seam). A triangle touching the plane only
//! with a vertex or an edge belongs to its own side only.
//!
//! ## Size estimate of a part
//! The part's TetGen input is estimated as follows. Points: its distinct
//! triangle vertices, plus one seam vertex per triangle cut at any ancestor
//! plane, plus 8 box corners. Triangles: its triangles, plus 3 per cut
//! triangle (up to two pieces on one side and about two seam-triangulation
//! triangles per seam vertex, minus the original), plus 12 box triangles.
//! The prediction counts the seam-triangulation and box facets at the
//! model's (lower) wall rate ([`MemoryModel::predict_part`]).
//! Every ancestor's seam is counted whole, and deeper parts are classified
//! by the original triangles' vertices (not the clipped pieces), so the
//! estimates and cut counts below the root are upper bounds.

use glam::Vec3;

use super::memory_model::MemoryModel;
use super::plane::{NEAR_PLANE, near_plane_vertex};

pub use super::plane::{Side, SplitPlane};

/// Predicted peak of a part with `points` scene vertices, `triangles`
/// scene triangles and `seam` triangles cut by the planes bounding it
/// (each adds about one crossing point and one piece facet on the scene
/// side, and two seam-triangulation facets on the wall side), plus the 8
/// corners and 12 facets of its box (at the wall rate).
fn predict_part(options: &SplitOptions, points: usize, triangles: usize, seam: usize) -> u64 {
    options
        .model
        .predict_part(points + triangles + 2 * seam, 2 * seam + 20)
}

/// The split plan: a binary tree of parts.
#[derive(Clone, Debug, PartialEq)]
pub enum SplitTree {
    /// A part tetrahedralized by one TetGen run.
    Leaf {
        /// The part's box `(min, max)`.
        bounds: (Vec3, Vec3),
        /// Scene triangles (indices) touching the part.
        triangles: Vec<u32>,
        /// Estimated TetGen input points (see the module docs).
        points_estimate: usize,
        /// Estimated TetGen input triangles.
        triangles_estimate: usize,
        /// Predicted peak memory (bytes, with margin).
        predicted_bytes: u64,
    },
    /// A part cut in two.
    Split {
        /// The part's box.
        bounds: (Vec3, Vec3),
        /// The cut plane.
        plane: SplitPlane,
        /// Triangles of the part the plane cuts.
        triangles_cut: usize,
        /// The half with `x[axis] ≤ value`.
        below: Box<SplitTree>,
        /// The half with `x[axis] ≥ value`.
        above: Box<SplitTree>,
    },
}

impl SplitTree {
    /// Number of leaves (TetGen runs).
    pub fn parts(&self) -> usize {
        match self {
            SplitTree::Leaf { .. } => 1,
            SplitTree::Split { below, above, .. } => below.parts() + above.parts(),
        }
    }

    /// Depth (0 for a single leaf).
    pub fn depth(&self) -> usize {
        match self {
            SplitTree::Leaf { .. } => 0,
            SplitTree::Split { below, above, .. } => 1 + below.depth().max(above.depth()),
        }
    }

    /// Triangles cut, summed over all split nodes.
    pub fn triangles_cut(&self) -> usize {
        match self {
            SplitTree::Leaf { .. } => 0,
            SplitTree::Split {
                triangles_cut,
                below,
                above,
                ..
            } => triangles_cut + below.triangles_cut() + above.triangles_cut(),
        }
    }

    /// Largest predicted leaf peak (bytes).
    pub fn max_predicted_bytes(&self) -> u64 {
        match self {
            SplitTree::Leaf {
                predicted_bytes, ..
            } => *predicted_bytes,
            SplitTree::Split { below, above, .. } => {
                below.max_predicted_bytes().max(above.max_predicted_bytes())
            }
        }
    }

    /// Empties every leaf's triangle list (the rest is kept): a plan kept
    /// beside its build no longer holds 4 bytes per scene triangle.
    pub(crate) fn forget_triangles(&mut self) {
        match self {
            SplitTree::Leaf { triangles, .. } => *triangles = Vec::new(),
            SplitTree::Split { below, above, .. } => {
                below.forget_triangles();
                above.forget_triangles();
            }
        }
    }

    /// The leaves, left (below) first.
    pub fn leaves(&self) -> Vec<&SplitTree> {
        match self {
            SplitTree::Leaf { .. } => vec![self],
            SplitTree::Split { below, above, .. } => {
                let mut v = below.leaves();
                v.extend(above.leaves());
                v
            }
        }
    }
}

/// Options of [`plan_split`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SplitOptions {
    /// Memory limit per TetGen run (bytes).
    pub limit_bytes: u64,
    /// The memory model.
    pub model: MemoryModel,
    /// Deepest split allowed (a leaf at this depth may exceed the limit).
    pub max_depth: usize,
    /// Candidate planes tried on each side of the mean, `search_steps`
    /// steps of `search_step` × the part's extent on the chosen axis
    /// (0 = the paper's plane exactly; default 8 steps of 1/32, ±25 %:
    /// wide enough to find the gaps between objects of a scene's core).
    pub search_steps: u32,
    /// Step of the plane search, relative to the part's extent.
    pub search_step: f32,
    /// Force splitting down to this depth even if the part fits (for tests
    /// and for parallelism).
    pub min_depth: usize,
    /// Build even when some part's prediction stays above `limit_bytes`
    /// at `max_depth` or where no plane splits it: the limit is then a
    /// target for the parts' size, not a bound on memory (the walls of a
    /// mesh shaped for rays), and [`super::tree::build_tree_with_memory_limit`]
    /// does not refuse with `LimitTooSmall`.
    pub best_effort: bool,
    /// Parts are cut further, as far as the planes allow, until their
    /// prediction is at most this (bytes; `u64::MAX`: no target): a target
    /// for the walls of a mesh shaped for rays, never a bound, while
    /// `limit_bytes` stays the bound. A part is cut for the target only
    /// where its halves stay within the bound, and, once its seams and box
    /// alone are predicted above the target (every part below carries them
    /// whole), only while its own scene content is too. See
    /// [`SplitOptions::shaped_for_rays`].
    pub target_bytes: u64,
}

/// The part size that shapes a walled mesh for rays
/// ([`SplitOptions::shaped_for_rays`]): dense regions cut until each
/// part's predicted TetGen peak is about this, light parts and empty
/// margins left whole. An unrefined `-pY` CDT fills empty space with long
/// fans of slivers from the fine surface to the box's corners, which every
/// ray crosses; walls cut them short. Tets per ray within 10 % of `-q5`'s
/// (or fewer) on Torus Knots and Armadillo, alone and in a box, Nefertiti
/// and `fan-sphere:200000` (20, 24, 28 and 32 MiB tried; 32 left Torus
/// Knots 19 % above).
pub const RAY_PART_TARGET_BYTES: u64 = 28 << 20;

impl SplitOptions {
    /// The split of every build that shapes its mesh for rays: parts cut
    /// toward [`RAY_PART_TARGET_BYTES`] (a target), each predicted under
    /// `limit_bytes` (a bound; `u64::MAX` for none). `tet-bench`'s
    /// `--walls auto`, the local `--memory-limit` build and the job
    /// planner ([`super::job::plan_job`]) all cut with it, so a job's or
    /// a limited build's merged mesh takes no more tets per ray than the
    /// default walled build where its limit allows parts of that size.
    pub fn shaped_for_rays(limit_bytes: u64) -> SplitOptions {
        SplitOptions {
            limit_bytes,
            target_bytes: RAY_PART_TARGET_BYTES,
            ..SplitOptions::default()
        }
    }

    /// The split of a build under `limit_bytes` (a bound on every part's
    /// prediction): [`SplitOptions::shaped_for_rays`] when `for_rays` (the
    /// walled default), else cut for the limit alone (fewer, larger
    /// parts; as `--walls none` builds one piece).
    pub fn under_limit(limit_bytes: u64, for_rays: bool) -> SplitOptions {
        if for_rays {
            SplitOptions::shaped_for_rays(limit_bytes)
        } else {
            SplitOptions {
                limit_bytes,
                ..SplitOptions::default()
            }
        }
    }

    /// The size a part is cut down to: the bound or, when lower, the
    /// target.
    fn cut_above(&self) -> u64 {
        self.limit_bytes.min(self.target_bytes)
    }
}

impl Default for SplitOptions {
    fn default() -> Self {
        SplitOptions {
            limit_bytes: u64::MAX,
            model: MemoryModel::FITTED,
            max_depth: 16,
            search_steps: 8,
            search_step: 1.0 / 32.0,
            min_depth: 0,
            best_effort: false,
            target_bytes: u64::MAX,
        }
    }
}

/// Chooses the cut plane of a part: the axis of largest variance of the
/// part's triangle corners (each corner counted once per triangle, clamped
/// into the part's box), through their mean; then, among the planes `mean ± k·step·extent` (`k ≤ search_steps`)
/// strictly inside the box, the one cutting the fewest triangles (ties: the
/// nearest to the mean). Returns the plane and its cut count, or `None`
/// when no plane lies strictly inside the box (a degenerate part).
pub fn choose_plane(
    vertices: &[Vec3],
    triangles: &[[u32; 3]],
    part: &[u32],
    bounds: (Vec3, Vec3),
    options: &SplitOptions,
) -> Option<(SplitPlane, usize)> {
    choose_plane_avoiding(vertices, triangles, part, bounds, options, 0.0)
}

/// [`choose_plane`], skipping candidate planes that pass within
/// `tolerance` of a vertex of the part's triangles without passing through
/// it (the seams refuse those, [`NEAR_PLANE`]); when every
/// candidate is too close, the plain rule's plane is returned.
pub fn choose_plane_avoiding(
    vertices: &[Vec3],
    triangles: &[[u32; 3]],
    part: &[u32],
    bounds: (Vec3, Vec3),
    options: &SplitOptions,
    tolerance: f64,
) -> Option<(SplitPlane, usize)> {
    let (lo, hi) = bounds;
    let n = part.len() as f64 * 3.0;
    let (mut sum, mut sum2) = ([0f64; 3], [0f64; 3]);
    for &t in part {
        for &v in &triangles[t as usize] {
            let p = vertices[v as usize].clamp(lo, hi);
            for a in 0..3 {
                let x = p[a] as f64;
                sum[a] += x;
                sum2[a] += x * x;
            }
        }
    }
    // Axis of largest variance; an empty part falls back to the longest box axis.
    let (axis, mean) = if part.is_empty() {
        let e = hi - lo;
        let axis = (0..3).max_by(|&a, &b| e[a].total_cmp(&e[b])).unwrap_or(0);
        (axis, 0.5 * (lo[axis] as f64 + hi[axis] as f64))
    } else {
        let var = |a: usize| sum2[a] / n - (sum[a] / n).powi(2);
        let axis = (0..3)
            .max_by(|&a, &b| var(a).total_cmp(&var(b)))
            .unwrap_or(0);
        (axis, sum[axis] / n)
    };
    let extent = (hi[axis] - lo[axis]) as f64;
    let mut best: Option<(SplitPlane, usize, f64)> = None;
    let steps = options.search_steps as i64;
    for k in -steps..=steps {
        let target = mean + k as f64 * options.search_step as f64 * extent;
        let value = target as f32;
        if !(value > lo[axis] && value < hi[axis]) {
            continue;
        }
        let plane = SplitPlane { axis, value };
        let near = tolerance > 0.0
            && part.iter().any(|&t| {
                triangles[t as usize].iter().any(|&v| {
                    let d = (vertices[v as usize][axis] as f64 - value as f64).abs();
                    d > 0.0 && d < tolerance
                })
            });
        if near {
            continue;
        }
        let cut = part
            .iter()
            .filter(|&&t| {
                let tri = triangles[t as usize].map(|v| vertices[v as usize]);
                plane.classify(tri) == Side::Cut
            })
            .count();
        let dist = (value as f64 - mean).abs();
        let better = match best {
            None => true,
            Some((_, c, d)) => cut < c || (cut == c && dist < d),
        };
        if better {
            best = Some((plane, cut, dist));
        }
    }
    match best {
        Some((p, c, _)) => Some((p, c)),
        None if tolerance > 0.0 => {
            choose_plane_avoiding(vertices, triangles, part, bounds, options, 0.0)
        }
        None => None,
    }
}

/// A part's empty margin thicker than this fraction of its extent on an
/// axis is cut off first ([`peel_plane`]).
pub const PEEL_MARGIN: f32 = 0.25;

/// The plane that cuts a thick empty margin off a part, if it has one: a
/// scene in a large box (a room, "… in a Box") has its detail in a core
/// far smaller than the box, and the planes of the mean rule would run
/// from that core through the empty space out to the box, where every
/// wall forces long thin tets that every ray crossing the empty space
/// then walks through (measured on Torus Knots in a Box: 2.5× the tets
/// per ray of the in-core mesh there). Cut first along the core instead,
/// and the empty space keeps tets as large as in core.
///
/// The core is the box of the corners of the part's *small* triangles
/// (those spanning less than a tenth of the part's largest extent, so the
/// box's own faces do not count); a margin between the core and the part's
/// bounds thicker than [`PEEL_MARGIN`] of the extent is cut by the plane
/// 1 % of the extent outside the core, provided it cuts only large
/// triangles and passes no vertex within `tolerance`. The thickest such
/// margin wins.
pub fn peel_plane(
    vertices: &[Vec3],
    triangles: &[[u32; 3]],
    part: &[u32],
    bounds: (Vec3, Vec3),
    tolerance: f64,
) -> Option<(SplitPlane, usize)> {
    let (lo, hi) = bounds;
    let size = (hi - lo).max_element();
    // A triangle of the detail, not of the box around it.
    let small = |t: [Vec3; 3]| {
        (t[0].max(t[1]).max(t[2]) - t[0].min(t[1]).min(t[2])).max_element() < 0.1 * size
    };
    let mut best: Option<(SplitPlane, usize, f32)> = None;
    for axis in 0..3 {
        let extent = hi[axis] - lo[axis];
        if extent.is_nan() || extent <= 0.0 {
            continue;
        }
        let (mut core_lo, mut core_hi) = (f32::INFINITY, f32::NEG_INFINITY);
        for &t in part {
            let tri = triangles[t as usize].map(|v| vertices[v as usize].clamp(lo, hi));
            if small(tri) {
                let c = tri.map(|p| p[axis]);
                core_lo = core_lo.min(c[0].min(c[1]).min(c[2]));
                core_hi = core_hi.max(c[0].max(c[1]).max(c[2]));
            }
        }
        if core_lo > core_hi {
            continue;
        }
        let pad = 0.01 * extent;
        for (value, margin) in [
            (core_lo - pad, core_lo - lo[axis]),
            (core_hi + pad, hi[axis] - core_hi),
        ] {
            if margin < PEEL_MARGIN * extent || !(value > lo[axis] && value < hi[axis]) {
                continue;
            }
            let plane = SplitPlane { axis, value };
            let mut cut = 0;
            let mut clean = true;
            for &t in part {
                let tri = triangles[t as usize].map(|v| vertices[v as usize]);
                let near = near_plane_vertex(&tri, plane, tolerance).is_some();
                let side = plane.classify(tri);
                if near || side == Side::InPlane || (side == Side::Cut && small(tri)) {
                    clean = false;
                    break;
                }
                cut += usize::from(side == Side::Cut);
            }
            let relative = margin / extent;
            if clean && best.as_ref().is_none_or(|b| relative > b.2) {
                best = Some((plane, cut, relative));
            }
        }
    }
    best.map(|(p, c, _)| (p, c))
}

/// Plans the recursive split of the scene triangles inside `bounds` (the
/// enclosing box of the whole build) under `options.limit_bytes`. A part
/// that no plane brings under the limit by `options.max_depth` stays a
/// leaf above it ([`SplitTree::max_predicted_bytes`] tells);
/// [`plan_split_within`] gives up at the first such part instead.
pub fn plan_split(
    vertices: &[Vec3],
    triangles: &[[u32; 3]],
    bounds: (Vec3, Vec3),
    options: &SplitOptions,
) -> SplitTree {
    Planning::new(vertices, triangles, bounds, options, false)
        .part((0..triangles.len() as u32).collect(), 0, bounds, 0)
        .expect("a plan that does not stop at the limit always ends")
}

/// [`plan_split`] when every part must fit `options.limit_bytes`: `None`
/// as soon as one part cannot (a leaf at `max_depth`, or one no plane
/// splits, still above the limit), without planning the rest. The plans it
/// returns are [`plan_split`]'s; a limit too small costs a few descents to
/// `max_depth` instead of a whole tree split down to it (a builder trying
/// several shares keeps its planning peak that of the plan it builds).
pub fn plan_split_within(
    vertices: &[Vec3],
    triangles: &[[u32; 3]],
    bounds: (Vec3, Vec3),
    options: &SplitOptions,
) -> Option<SplitTree> {
    Planning::new(vertices, triangles, bounds, options, true).part(
        (0..triangles.len() as u32).collect(),
        0,
        bounds,
        0,
    )
}

/// What every part of one [`plan_split`] shares.
struct Planning<'a> {
    vertices: &'a [Vec3],
    triangles: &'a [[u32; 3]],
    options: &'a SplitOptions,
    /// Planes within this of a vertex (not through it) are avoided.
    tolerance: f64,
    /// Give up (`None`) at the first part that stays above the limit.
    stop: bool,
}

impl<'a> Planning<'a> {
    fn new(
        vertices: &'a [Vec3],
        triangles: &'a [[u32; 3]],
        bounds: (Vec3, Vec3),
        options: &'a SplitOptions,
        stop: bool,
    ) -> Self {
        Planning {
            vertices,
            triangles,
            options,
            tolerance: NEAR_PLANE * (bounds.1 - bounds.0).max_element() as f64,
            stop,
        }
    }

    /// The plan of one part (`None`: it or a part below stays above the
    /// limit and `self.stop`).
    fn part(
        &self,
        part: Vec<u32>,
        seam_vertices: usize,
        bounds: (Vec3, Vec3),
        depth: usize,
    ) -> Option<SplitTree> {
        let (vertices, triangles, options) = (self.vertices, self.triangles, self.options);
        let mut used: Vec<u32> = part.iter().flat_map(|&t| triangles[t as usize]).collect();
        used.sort_unstable();
        used.dedup();
        let points_estimate = used.len() + seam_vertices + 8;
        let triangles_estimate = part.len() + 3 * seam_vertices + 12;
        let predicted_bytes = predict_part(options, used.len(), part.len(), seam_vertices);
        drop(used);
        // Where the part's seams and box alone are predicted above the
        // target, every part below carries them whole and never reaches
        // it: the part is cut for the target only while its own scene
        // content is predicted above it, so that the cuts spread the
        // content and stop when only the seams are left (cut on regardless,
        // such parts went down to `max_depth`: `fan-sphere:1m`, whose pole
        // fans the planes near a pole cut, made 39,250 parts, now 816).
        let floor = predict_part(options, 0, 0, seam_vertices);
        let reachable = floor <= options.target_bytes
            || predicted_bytes.saturating_sub(floor) > options.target_bytes;
        let over = if reachable {
            options.cut_above()
        } else {
            options.limit_bytes
        };
        let wants_split =
            depth < options.min_depth || (predicted_bytes > over && depth < options.max_depth);
        // A part within the bound but above the target is cut only where
        // its halves stay within the bound (every ancestor's seam counts
        // whole in a deeper part's estimate, so a half can be predicted
        // above its parent): the target shapes the walls, it never turns a
        // plan that fits into one that does not.
        let within = predicted_bytes <= options.limit_bytes;
        let for_target_only = depth >= options.min_depth && within;
        let leaf = |part: Vec<u32>| {
            (within || !self.stop).then_some(SplitTree::Leaf {
                bounds,
                triangles: part,
                points_estimate,
                triangles_estimate,
                predicted_bytes,
            })
        };
        if !wants_split {
            return leaf(part);
        }
        let Some((plane, cut)) = peel_plane(vertices, triangles, &part, bounds, self.tolerance)
            .or_else(|| {
                choose_plane_avoiding(vertices, triangles, &part, bounds, options, self.tolerance)
            })
        else {
            return leaf(part);
        };
        let (mut below, mut above) = (Vec::new(), Vec::new());
        for &t in &part {
            let tri = triangles[t as usize].map(|v| vertices[v as usize]);
            match plane.classify(tri) {
                Side::Below => below.push(t),
                Side::Above => above.push(t),
                Side::Cut | Side::InPlane => {
                    below.push(t);
                    above.push(t);
                }
            }
        }
        let (lo, hi) = bounds;
        let mut mid_hi = hi;
        mid_hi[plane.axis] = plane.value;
        let mut mid_lo = lo;
        mid_lo[plane.axis] = plane.value;
        let seam = seam_vertices + cut;
        let halves = self
            .part(below, seam, (lo, mid_hi), depth + 1)
            .and_then(|b| Some((b, self.part(above, seam, (mid_lo, hi), depth + 1)?)));
        let split = halves.map(|(below, above)| SplitTree::Split {
            bounds,
            plane,
            triangles_cut: cut,
            below: Box::new(below),
            above: Box::new(above),
        });
        match split {
            Some(s) if for_target_only && s.max_predicted_bytes() > options.limit_bytes => {
                leaf(part)
            }
            Some(s) => Some(s),
            None if for_target_only => leaf(part),
            None => None,
        }
    }
}

/// A slab plan: parallel planes `x[axis] = values[i]` and each slab's
/// estimated TetGen input and predicted peak.
#[derive(Clone, Debug, PartialEq)]
pub struct SlabPlan {
    /// Cut axis (the axis of largest variance of the triangle corners).
    pub axis: usize,
    /// Plane offsets, strictly increasing.
    pub values: Vec<f32>,
    /// Triangles each plane cuts.
    pub triangles_cut: Vec<usize>,
    /// Predicted peak (bytes, with margin) of each slab.
    pub predicted_bytes: Vec<u64>,
}

/// Plans parallel cut planes so that every slab's predicted TetGen peak
/// fits `options.limit_bytes`: `k` planes at the `k + 1`-quantiles of the
/// triangle corners along the axis of largest variance, each moved (within
/// `±search_steps · search_step ·` extent) to the candidate cutting the
/// fewest triangles and lying no closer than [`NEAR_PLANE`] ×
/// the box extent to a vertex off it (when that crowds planes into one gap
/// and the slabs do not fit, the plain quantiles are tried too); `k` grows
/// (0, 1, 2, 3, 4, 6, 9, …) until all slabs fit. Slab
/// sizes are estimated as in [`plan_split`] (module docs). `None` when no
/// plan with at most `2^min(max_depth, 10) − 1` planes fits.
pub fn plan_slabs(
    vertices: &[Vec3],
    triangles: &[[u32; 3]],
    bounds: (Vec3, Vec3),
    options: &SplitOptions,
) -> Option<SlabPlan> {
    let (lo, hi) = bounds;
    let part: Vec<u32> = (0..triangles.len() as u32).collect();
    let axis = choose_plane(
        vertices,
        triangles,
        &part,
        bounds,
        &SplitOptions {
            search_steps: 0,
            ..*options
        },
    )
    .map_or(0, |(p, _)| p.axis);
    let mut coords: Vec<f32> = triangles
        .iter()
        .flatten()
        .map(|&v| vertices[v as usize][axis].clamp(lo[axis], hi[axis]))
        .collect();
    coords.sort_by(f32::total_cmp);
    let extent = (hi[axis] - lo[axis]) as f64;
    let tolerance = NEAR_PLANE * (hi - lo).max_element() as f64;
    let max_planes = (1usize << options.max_depth.min(10)) - 1;
    let cuts = |value: f32| {
        let plane = SplitPlane { axis, value };
        triangles
            .iter()
            .filter(|t| plane.classify(t.map(|v| vertices[v as usize])) == Side::Cut)
            .count()
    };
    // k = 0, 1, 2, 3, 4, 6, 9, 13, … (×1.5) planes.
    let mut k = 0usize;
    while k <= max_planes {
        // The fewest-cuts search may crowd planes into one gap; retry
        // with the plain quantiles when it does not fit.
        let variants = if options.search_steps == 0 { 1 } else { 2 };
        for search in [options.search_steps, 0].into_iter().take(variants) {
            let mut values: Vec<f32> = Vec::new();
            let mut triangles_cut = Vec::new();
            for i in 1..=k {
                let q = coords[(i * coords.len() / (k + 1)).min(coords.len() - 1)] as f64;
                let mut best: Option<(f32, usize, f64)> = None;
                let steps = search as i64;
                for s in -steps..=steps {
                    let value = (q + s as f64 * options.search_step as f64 * extent) as f32;
                    let previous = values.last().copied().unwrap_or(lo[axis]);
                    if !(value > previous && value < hi[axis]) {
                        continue;
                    }
                    let plane = SplitPlane { axis, value };
                    if near_plane_vertex(vertices, plane, tolerance).is_some() {
                        continue;
                    }
                    let c = cuts(value);
                    let d = (value as f64 - q).abs();
                    if best.is_none_or(|(_, bc, bd)| c < bc || (c == bc && d < bd)) {
                        best = Some((value, c, d));
                    }
                }
                if let Some((v, c, _)) = best {
                    values.push(v);
                    triangles_cut.push(c);
                }
            }
            // Estimate each slab.
            let mut predicted = Vec::with_capacity(values.len() + 1);
            for s in 0..=values.len() {
                let below = if s > 0 {
                    values[s - 1]
                } else {
                    f32::NEG_INFINITY
                };
                let above = values.get(s).copied().unwrap_or(f32::INFINITY);
                let mut used = Vec::new();
                let mut tris = 0usize;
                for t in triangles {
                    let p = t.map(|v| vertices[v as usize][axis]);
                    let inside = p.iter().any(|&x| x > below && x < above)
                        || (p.iter().any(|&x| x <= below) && p.iter().any(|&x| x >= above))
                        || p.iter().all(|&x| x == below || x == above);
                    if inside {
                        tris += 1;
                        used.extend_from_slice(t);
                    }
                }
                used.sort_unstable();
                used.dedup();
                let seam: usize = [s.checked_sub(1), (s < values.len()).then_some(s)]
                    .into_iter()
                    .flatten()
                    .map(|j| triangles_cut[j])
                    .sum();
                predicted.push(predict_part(options, used.len(), tris, seam));
            }
            if predicted.iter().all(|&p| p <= options.limit_bytes) {
                return Some(SlabPlan {
                    axis,
                    values,
                    triangles_cut,
                    predicted_bytes: predicted,
                });
            }
        }
        k = (k + 1).max(k * 3 / 2);
    }
    None
}
