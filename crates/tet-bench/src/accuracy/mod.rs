//! Accuracy of every method against an f64 reference (the `accuracy`
//! command, and the robustness and speed-vs-accuracy tables of `tables`):
//! the rays built to hurt a walk ([`adversarial`]), the scene scaled,
//! translated and on slivers ([`extremes`]), which grazing rays must cross
//! the surface ([`grazing`]), the failing rays kept for study
//! ([`failed_rays`]), and the same measurement streamed over 10⁸ rays and
//! more ([`scale`]).
//!
//! The reference is exact in structure: every candidate triangle is tested
//! with the f64 ray–triangle test of `tet_trace_cpu::reference`; candidates
//! come from a BVH over triangle boxes padded by the tolerance (so the f32
//! box test cannot drop a triangle the ray passes within tolerance of).
//!
//! A ray that **leaks** slipped through a closed surface: the method
//! misses, or hits something more than `2·tol` farther along, where every
//! line within `tol` of the ray crosses the surface — the reference hit
//! lies within `tol` of edges or vertices of its triangle, and the faces
//! around them cross every nearby line (an odd number of times; see
//! [`grazing`]: a ray entering a closed surface across an edge or
//! through a vertex, not one clipping a convex edge or touching the
//! outline); or the ray may pass such a grazed part by, and the method
//! also skips the first watertight face beyond it (skipping one of an open
//! surface is a wrong triangle or a false miss). Leaks are failures, the
//! worst a renderer can make: light passes through a watertight surface.
//!
//! Otherwise a ray counts as **ambiguous** (grazing), not wrong, when the
//! reference hit point lies within `tol` of an edge of its triangle (or
//! the ray's line passes within `tol` of one: a ray nearly in the
//! triangle's plane), a
//! second triangle is hit within `tol` along the ray, the hit lies within
//! `tol` of the ray origin, or the method's own hit point lies within
//! `tol` of an edge of the triangle it reports; `tol = max(1e-5 · diagonal, 4e-7 · max |coordinate|)`
//! (the second term is a few f32 ulps of the coordinates, which dominates
//! for scenes far from the origin). A reference hit within `tol` of the ray
//! origin is never a leak: the method may rightly place it behind the origin.

use std::time::{Duration, Instant};

use anyhow::Result;
use glam::Vec3A;
use glam::{DVec3, Vec3};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::builder::build_bvh2;
use obvhs::ray::{Ray as BvhRay, RayHit};
use rayon::prelude::*;
use serde::Serialize;
use tet_core::TetMesh;
use tet_core::synthetic::SplitMix64;
use tet_trace_cpu::Viewpoint;
use tet_trace_cpu::kernel::Tracer;
use tet_trace_cpu::ray::{Failure, Hit, Ray, TraceOutcome};
use tet_trace_cpu::reference::{Aim, edge_distance, line_edge_distance, random_ray, ray_triangle};
use tet_trace_cpu::render::PinholeCamera;
use tet_trace_cpu::walk::Start;

pub mod adversarial;
pub mod extremes;
pub mod failed_rays;
pub mod grazing;
pub mod scale;

use adversarial::adversarial_rays;
use failed_rays::{FailedRay, KEPT, ReferenceHit};
use grazing::{Graze, Surface};

use crate::load::Loaded;
use crate::load::build_flags::BuildFlags;
use crate::methods::bvh::unit_scale;
use crate::methods::method::{Method, Precision};
use crate::methods::{has_f64, tracer};
use crate::output::error_chain;

/// The f64 reference hit of one ray.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RefHit {
    /// Constrained face hit.
    face: u32,
    /// Its scene triangle.
    triangle: u32,
    /// Ray parameter of the hit.
    t: f64,
    /// The tolerance in units of the ray parameter (`tol / |direction|`).
    tol_t: f64,
    /// The hit point lies within `tol` of an edge of its face.
    near_edge: bool,
    /// Every line within `tol` of the ray crosses the surface around the
    /// edges and vertices the hit point grazes ([`Graze::MustCross`]): a
    /// watertight part of the surface is crossed. Meaningful with
    /// `near_edge`.
    closed: bool,
    /// Where the ray may pass the grazed edges and vertices by
    /// ([`Graze::MayPass`], e.g. it clips a convex edge): the first face
    /// beyond them, when the ray meets it away from its edges.
    beyond: Option<Beyond>,
    /// Another face is hit within `tol` along the ray.
    second_close: bool,
    /// The hit lies within `tol` of the ray origin.
    near_origin: bool,
}

/// The first face past a grazed part of the surface that a ray may skip.
#[derive(Clone, Copy, Debug)]
struct Beyond {
    /// Its ray parameter.
    t: f64,
    /// It lies on a watertight part of the surface (every edge shared).
    closed: bool,
}

impl RefHit {
    /// Grazing by the reference alone: near an edge, a second hit within
    /// `tol`, or near the ray origin.
    pub(crate) fn ambiguous(&self) -> bool {
        self.near_edge || self.second_close || self.near_origin
    }

    /// True when `outcome` misses, or hits more than `2·tol` beyond `t`
    /// (beyond the window in which the reference looked for a second hit).
    fn passes(&self, outcome: &TraceOutcome, t: f64) -> bool {
        match outcome {
            TraceOutcome::Miss { .. } => true,
            TraceOutcome::Hit(h) => h.t as f64 > t + 2.0 * self.tol_t,
            TraceOutcome::Failed { .. } => false,
        }
    }

    /// True when `outcome` slipped through a closed surface: the one this
    /// hit grazes, where every nearby line crosses it, or the first
    /// watertight face beyond a grazed part it may skip.
    fn leaked_by(&self, outcome: &TraceOutcome) -> bool {
        if self.near_origin {
            return false;
        }
        if self.near_edge && self.closed {
            return self.passes(outcome, self.t);
        }
        self.beyond
            .is_some_and(|b| b.closed && self.passes(outcome, b.t))
    }

    /// True when `outcome` skipped the first face beyond a grazed part
    /// of the surface it may skip, that face being on an open surface.
    fn skipped_beyond(&self, outcome: &TraceOutcome) -> bool {
        !self.near_origin
            && self
                .beyond
                .is_some_and(|b| !b.closed && self.passes(outcome, b.t))
    }
}

/// f64 reference over a padded-box BVH.
pub struct Reference<'m> {
    /// The mesh whose constrained faces are tested.
    mesh: &'m TetMesh,
    /// BVH over the faces' boxes, padded by the tolerance.
    bvh: Bvh2,
    /// The faces around every edge and vertex.
    surface: Surface,
    /// Grazing tolerance (world units).
    pub tol: f64,
    /// The power of two the BVH was built at ([`unit_scale`]).
    scale: f32,
}

/// `v` in obvhs's vector type.
fn a3(v: Vec3) -> Vec3A {
    Vec3A::new(v.x, v.y, v.z)
}

/// Grazing tolerance of a mesh (see the module docs).
pub fn tolerance(mesh: &TetMesh) -> f64 {
    let (lo, hi) = mesh.point_bounds();
    // In f64: the diagonal of a scene at 1e30 overflows f32, one at 1e-30
    // underflows.
    let (lo, hi) = (lo.as_dvec3(), hi.as_dvec3());
    let diag = (hi - lo).length();
    let mag = lo.abs().max(hi.abs()).max_element();
    (1e-5 * diag).max(4e-7 * mag)
}

impl<'m> Reference<'m> {
    /// Builds the reference over `mesh.constrained`.
    pub fn new(mesh: &'m TetMesh) -> Self {
        let tol = tolerance(mesh);
        // Built on the scene scaled by a power of two (see `unit_scale`).
        let scale = unit_scale(mesh);
        let pad = Vec3A::splat((tol * 2.0 * scale as f64) as f32);
        let boxes: Vec<Aabb> = mesh
            .constrained
            .iter()
            .map(|cf| {
                let p = cf.vertices.map(|v| a3(mesh.points[v as usize] * scale));
                Aabb {
                    min: p[0].min(p[1]).min(p[2]) - pad,
                    max: p[0].max(p[1]).max(p[2]) + pad,
                }
            })
            .collect();
        let bvh = build_bvh2(
            &boxes,
            BvhBuildParams::medium_build(),
            &mut Duration::default(),
        );
        Reference {
            mesh,
            bvh,
            surface: Surface::new(mesh),
            tol,
            scale,
        }
    }

    /// The reference hit of `ray`: its closest constrained face in f64, or
    /// `None` when it hits none.
    fn closest(&self, ray: &Ray) -> Option<RefHit> {
        let mesh = self.mesh;
        let dlen = ray.direction.as_dvec3().length();
        let tol_t = self.tol / dlen;
        let (t, face, second) = self.first_hit(ray, &[])?;
        let cf = &mesh.constrained[face as usize];
        let v = cf.vertices.map(|k| mesh.points[k as usize].as_dvec3());
        let p = ray.origin.as_dvec3() + ray.direction.as_dvec3() * t;
        let near_edge = self.near_edge(face, ray, p);
        let near_origin = t < tol_t;
        let graze = if near_edge && !near_origin {
            let d = ray.direction.as_dvec3();
            self.surface.graze(mesh, cf.vertices, v, p, d, self.tol)
        } else {
            Graze::Undecided
        };
        // Past a star the ray may skip, the first face beyond it, where
        // that one is hit away from its edges and from any other face.
        let beyond = match &graze {
            Graze::MayPass(star) => self.first_hit(ray, star).and_then(|(bt, bf, b2)| {
                let q = ray.origin.as_dvec3() + ray.direction.as_dvec3() * bt;
                let clear = !self.near_edge(bf, ray, q) && b2 - bt >= tol_t;
                let closed = self
                    .surface
                    .face_closed(mesh.constrained[bf as usize].vertices);
                clear.then_some(Beyond { t: bt, closed })
            }),
            _ => None,
        };
        Some(RefHit {
            face,
            triangle: cf.triangle,
            t,
            tol_t,
            near_edge,
            closed: graze == Graze::MustCross,
            beyond,
            second_close: second - t < tol_t,
            near_origin,
        })
    }

    /// The closest constrained face along `ray` in f64 that is not in
    /// `skip` (sorted), as `(t, face, t of the next face hit)`; the next
    /// face is looked for only within `2·tol` (∞ when none is there).
    fn first_hit(&self, ray: &Ray, skip: &[u32]) -> Option<(f64, u32, f64)> {
        let mesh = self.mesh;
        let dlen = ray.direction.as_dvec3().length();
        let tol_t = self.tol / dlen;
        let mut best: Option<(f64, u32)> = None;
        let mut second = f64::INFINITY;
        // obvhs wants directions of about unit length (it treats components
        // below f32::EPSILON as zero): traverse with the unit direction,
        // whose parameter is `t · dlen`.
        let unit = (ray.direction.as_dvec3() / dlen).as_vec3();
        let r = BvhRay::new(a3(ray.origin * self.scale), a3(unit), 0.0, f32::INFINITY);
        // The BVH's parameter of a point at `t` along `ray`.
        let bvh_t = dlen * self.scale as f64;
        let mut hit = RayHit::none();
        self.bvh.ray_traverse(r, &mut hit, |_, id| {
            let face = self.bvh.primitive_indices[id];
            if skip.binary_search(&face).is_ok() {
                return f32::INFINITY;
            }
            let cf = &mesh.constrained[face as usize];
            let v = cf.vertices.map(|k| mesh.points[k as usize]);
            let Some((t, _)) = ray_triangle(ray, v) else {
                return f32::INFINITY;
            };
            if t < ray.t_min as f64 || t > ray.t_max as f64 {
                return f32::INFINITY;
            }
            match best {
                Some((bt, _)) if t >= bt => second = second.min(t),
                _ => {
                    if let Some((bt, _)) = best {
                        second = bt;
                    }
                    best = Some((t, face));
                }
            }
            // Keep looking a little beyond the closest hit for the gap test.
            (((best.unwrap().0 + 2.0 * tol_t) * bvh_t) as f32) * (1.0 + 1e-6)
        });
        best.map(|(t, face)| (t, face, second))
    }

    /// True when the hit point `p` of `ray` on constrained face `face`
    /// lies within `tol` of an edge of the face, or the ray's line passes
    /// within `tol` of one elsewhere (a ray nearly in the face's plane
    /// grazes the face along its whole width).
    fn near_edge(&self, face: u32, ray: &Ray, p: DVec3) -> bool {
        let cf = &self.mesh.constrained[face as usize];
        let v = cf.vertices.map(|k| self.mesh.points[k as usize].as_dvec3());
        edge_distance(p, v) < self.tol
            || line_edge_distance(ray.origin.as_dvec3(), ray.direction.as_dvec3(), v) < self.tol
    }
}

/// Counts of one method on one case (JSON `cases[].methods[]`).
#[derive(Clone, Debug, Default, Serialize)]
pub struct MethodAccuracy {
    /// Method.
    pub method: String,
    /// `f32` or `f64`.
    pub precision: &'static str,
    /// Rays traced.
    pub rays: u64,
    /// Same first triangle as the reference (or both miss).
    pub agree: u64,
    /// Grazing rays (see tolerance) whose result differs: not counted as
    /// failures. Never a leak.
    pub ambiguous: u64,
    /// Missed, or hit farther along, where the reference hit grazes only
    /// closed edges (the ray slipped through a watertight surface).
    pub leaks: u64,
    /// Hit a different triangle than the reference, beyond the tolerance.
    pub wrong_triangle: u64,
    /// Missed where the reference hits, beyond the tolerance.
    pub false_misses: u64,
    /// Hit where the reference misses, beyond the tolerance.
    pub false_hits: u64,
    /// Walks stopped by the step cap.
    pub step_cap: u64,
    /// Walks that lost their way (no exit face).
    pub lost: u64,
    /// Rays rejected as invalid.
    pub invalid: u64,
    /// Hits with a NaN parameter or barycentric.
    pub nans: u64,
    /// leaks + wrong_triangle + false_misses + false_hits + step_cap + lost + invalid + nans.
    pub failures: u64,
    /// Failures per 1024² rays (the unit of Maria et al. Table 4).
    pub failures_per_1024_squared: f64,
    /// Throughput over these rays, all threads, Mrays/s: the best of
    /// repeated passes over the same rays, timed for at least
    /// [`RayPlan::min_time_s`] in all (and at least [`MIN_PASSES`] passes).
    pub mrays_per_s: f64,
    /// The first failing rays ([`failed_rays::KEPT`] at most), to
    /// reproduce them.
    pub failed_rays: Vec<FailedRay>,
}

/// One case: the scene as given, or transformed (JSON `cases[]`).
#[derive(Clone, Debug, Serialize)]
pub struct CaseAccuracy {
    /// `as-is`, `scale-1e-4`, `scale-1e4`, `scale-1e-30`, `scale-1e30`,
    /// `translate-1e5`, `kuhn-slivers`.
    pub case: String,
    /// Tets of the mesh traced.
    pub tets: usize,
    /// Grazing tolerance used.
    pub tolerance: f64,
    /// Camera rays (a square image) + random interior rays.
    pub rays: usize,
    /// Rays the reference calls ambiguous.
    pub reference_ambiguous: usize,
    /// Per method.
    pub methods: Vec<MethodAccuracy>,
    /// Why the case was skipped, if it was.
    pub skipped: Option<String>,
    /// `method/precision` left out of this case: at ×1e±30 the f32 kernels
    /// whose products of coordinates are not rescaled (sctp, tet80) would
    /// walk to their step cap on most rays (see [`extremes`]).
    pub left_out: Vec<String>,
}

/// A batch of rays with their start (`None`: a camera ray, started from
/// `view` by each tracer; see `tet_trace_cpu::boundary_entry` for a camera outside
/// the mesh).
pub struct RaySet {
    /// Each ray with its start (`None` for camera rays).
    rays: Vec<(Ray, Option<Start>)>,
    /// Where camera rays start (when there are camera rays).
    view: Option<Viewpoint>,
}

impl RaySet {
    /// Rays in the set.
    pub fn len(&self) -> usize {
        self.rays.len()
    }

    /// The reference's hit of every ray, in parallel.
    pub(crate) fn reference_hits(&self, reference: &Reference) -> Vec<Option<RefHit>> {
        self.rays
            .par_iter()
            .map(|(r, _)| reference.closest(r))
            .collect()
    }
}

/// Camera rays of a `side × side` image plus `n` rays from random interior
/// points: 70 % random directions, 10 % aimed at vertices, 10 % at edge
/// midpoints, 10 % at face centroids; then `adversarial` rays of
/// [`adversarial_rays`] (same seed).
pub fn ray_set(
    loaded: &Loaded,
    mesh: &TetMesh,
    side: u32,
    n: usize,
    adversarial: usize,
    seed: u64,
) -> Result<RaySet> {
    let mut rays = Vec::with_capacity((side * side) as usize + n);
    let mut view = None;
    if side > 0 {
        view = Some(
            Viewpoint::locate(mesh, loaded.camera.position)
                .map_err(|e| anyhow::anyhow!("camera {}: {e}", loaded.camera.position))?,
        );
        let cam = PinholeCamera::new(&loaded.camera, side, side, true);
        for j in 0..side {
            for i in 0..side {
                rays.push((cam.ray(i, j), None));
            }
        }
    }
    let mut rng = SplitMix64(seed);
    for k in 0..n {
        let aim = match k % 10 {
            7 => Aim::Vertex,
            8 => Aim::EdgeMidpoint,
            9 => Aim::FaceCentroid,
            _ => Aim::Random,
        };
        let (ray, tet) = random_ray(mesh, &mut rng, aim);
        rays.push((ray, Some(Start::Tet(tet))));
    }
    rays.extend(adversarial_rays(mesh, adversarial, seed));
    Ok(RaySet { rays, view })
}

/// Timed passes per measurement, at least (the best is reported).
pub const MIN_PASSES: u32 = 3;

/// The rays of a case and how long to time them.
#[derive(Clone, Copy, Debug)]
pub struct RayPlan {
    /// Camera rays: a `side`² image (0 for none).
    pub side: u32,
    /// Random rays from inside the mesh.
    pub random: usize,
    /// Seed of the random rays.
    pub seed: u64,
    /// Seconds each method's passes over the rays take at least, in all.
    pub min_time_s: f64,
    /// Rays aimed at or started on mesh features ([`adversarial_rays`]).
    pub adversarial: usize,
}

/// Traces every ray of `set` once with `t`, in parallel.
pub(crate) fn trace_all(t: &dyn Tracer, set: &RaySet) -> Vec<TraceOutcome> {
    set.rays
        .par_iter()
        .map(|(r, s)| {
            // Camera rays always come with their viewpoint.
            let start = match (s, &set.view) {
                (Some(s), _) => Ok(*s),
                (None, Some(view)) => view.start(t, r),
                (None, None) => Err(TraceOutcome::Failed {
                    failure: Failure::Lost,
                    tets_visited: 0,
                }),
            };
            match start {
                Ok(s) => t.trace(r, s),
                Err(done) => done,
            }
        })
        .collect()
}

/// Checks one tracer against the reference; its speed is the best of
/// passes repeated until `min_time_s` is spent (at least [`MIN_PASSES`]).
fn check(
    t: &dyn Tracer,
    precision: &'static str,
    reference: &Reference,
    expected: &[Option<RefHit>],
    set: &RaySet,
    min_time_s: f64,
) -> MethodAccuracy {
    let first = Instant::now();
    let outcomes = trace_all(t, set);
    let mut best = first.elapsed().as_secs_f64();
    let mut passes = 1;
    while passes < MIN_PASSES || first.elapsed().as_secs_f64() < min_time_s {
        let start = Instant::now();
        let again = trace_all(t, set);
        best = best.min(start.elapsed().as_secs_f64());
        debug_assert_eq!(again.len(), outcomes.len());
        passes += 1;
    }
    let mut m = MethodAccuracy {
        method: t.name(),
        precision,
        mrays_per_s: set.rays.len() as f64 / best.max(1e-9) / 1e6,
        ..Default::default()
    };
    m.tally(reference, set, &outcomes, expected);
    m.finish();
    m
}

impl MethodAccuracy {
    /// Judges `outcomes` (of the rays of `set`) against the reference's
    /// `expected` hits and adds them to the counters.
    pub(crate) fn tally(
        &mut self,
        reference: &Reference,
        set: &RaySet,
        outcomes: &[TraceOutcome],
        expected: &[Option<RefHit>],
    ) {
        self.rays += set.rays.len() as u64;
        for (((ray, start), o), e) in set.rays.iter().zip(outcomes).zip(expected) {
            // The method's own hit grazes an edge of its triangle, or lies
            // within the tolerance of the origin (a ray started on a surface
            // may count it or not): the reference may rightly have decided
            // otherwise.
            let own_hit_grazes = |h: &Hit| {
                let d = ray.direction.as_dvec3();
                (h.t as f64).abs() * d.length() < reference.tol
                    || reference.near_edge(h.face, ray, ray.origin.as_dvec3() + d * h.t as f64)
            };
            let verdict = classify(o, e.as_ref(), own_hit_grazes);
            self.count(verdict);
            if !matches!(verdict, Verdict::Agree | Verdict::Ambiguous)
                && self.failed_rays.len() < KEPT
            {
                let r = e.as_ref().map(|r| ReferenceHit {
                    triangle: r.triangle,
                    t: r.t,
                    near_edge: r.near_edge,
                    closed: r.closed,
                });
                let kept = FailedRay::new(format!("{verdict:?}"), ray, start.as_ref(), o, r);
                self.failed_rays.push(kept);
            }
        }
    }

    /// Sums the failures and their rate per 1024² rays from the counters.
    pub(crate) fn finish(&mut self) {
        self.failures = self.leaks
            + self.wrong_triangle
            + self.false_misses
            + self.false_hits
            + self.step_cap
            + self.lost
            + self.invalid
            + self.nans;
        self.failures_per_1024_squared =
            self.failures as f64 * (1024.0 * 1024.0) / self.rays.max(1) as f64;
    }
}

/// How one method's result on one ray compares with the reference.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Verdict {
    /// Same first triangle (or both miss).
    Agree,
    /// Different, but the ray grazes (not a failure).
    Ambiguous,
    /// Slipped through a closed surface the reference hit grazes.
    Leak,
    /// Another triangle, beyond the tolerance.
    WrongTriangle,
    /// Missed a hit the reference finds away from any edge.
    FalseMiss,
    /// Hit where the reference misses.
    FalseHit,
    /// The walk stopped at the step cap.
    StepCap,
    /// The walk lost its way.
    Lost,
    /// The ray was rejected.
    Invalid,
    /// A NaN parameter or barycentric.
    Nan,
}

/// Judges one ray: `outcome` of the method, `expected` the reference hit,
/// `own_hit_grazes` whether a hit of the method lies within the tolerance
/// of an edge of the face it reports. A leak is decided before any
/// grazing excuse, so a miss across a closed edge is never ambiguous.
fn classify(
    outcome: &TraceOutcome,
    expected: Option<&RefHit>,
    own_hit_grazes: impl FnOnce(&Hit) -> bool,
) -> Verdict {
    match (outcome, expected) {
        (TraceOutcome::Failed { failure, .. }, _) => match failure {
            Failure::StepCap => Verdict::StepCap,
            Failure::Lost => Verdict::Lost,
            Failure::InvalidRay => Verdict::Invalid,
        },
        (TraceOutcome::Hit(h), _) if h.t.is_nan() || h.barycentrics.iter().any(|b| b.is_nan()) => {
            Verdict::Nan
        }
        (TraceOutcome::Hit(h), Some(r)) if h.triangle == r.triangle || h.face == r.face => {
            Verdict::Agree
        }
        (TraceOutcome::Miss { .. }, None) => Verdict::Agree,
        (o, Some(r)) if r.leaked_by(o) => Verdict::Leak,
        (TraceOutcome::Miss { .. }, Some(r)) if r.skipped_beyond(outcome) => Verdict::FalseMiss,
        (TraceOutcome::Hit(_), Some(r)) if r.skipped_beyond(outcome) => Verdict::WrongTriangle,
        (_, Some(r)) if r.ambiguous() => Verdict::Ambiguous,
        (TraceOutcome::Hit(h), _) if own_hit_grazes(h) => Verdict::Ambiguous,
        (TraceOutcome::Hit(_), None) => Verdict::FalseHit,
        (TraceOutcome::Hit(_), Some(_)) => Verdict::WrongTriangle,
        (TraceOutcome::Miss { .. }, Some(_)) => Verdict::FalseMiss,
    }
}

impl MethodAccuracy {
    /// Adds one ray's verdict to its counter.
    fn count(&mut self, v: Verdict) {
        let c = match v {
            Verdict::Agree => &mut self.agree,
            Verdict::Ambiguous => &mut self.ambiguous,
            Verdict::Leak => &mut self.leaks,
            Verdict::WrongTriangle => &mut self.wrong_triangle,
            Verdict::FalseMiss => &mut self.false_misses,
            Verdict::FalseHit => &mut self.false_hits,
            Verdict::StepCap => &mut self.step_cap,
            Verdict::Lost => &mut self.lost,
            Verdict::Invalid => &mut self.invalid,
            Verdict::Nan => &mut self.nans,
        };
        *c += 1;
    }
}

/// The kernel precisions `precision` asks of `method`, as `(f64, label)`:
/// f32 for every method but the brute force (the f64 reference itself),
/// f64 where the method has it.
pub(crate) fn variants(
    method: Method,
    precision: Precision,
) -> impl Iterator<Item = (bool, &'static str)> {
    let f32 = matches!(precision, Precision::F32 | Precision::Both) && method != Method::Brute;
    let f64 = matches!(precision, Precision::F64 | Precision::Both) && has_f64(method);
    [(f32, (false, "f32")), (f64, (true, "f64"))]
        .into_iter()
        .filter_map(|(on, v)| on.then_some(v))
}

/// Runs every method on one mesh.
pub fn run_case(
    case: &str,
    loaded: &Loaded,
    methods: &[Method],
    precision: Precision,
    plan: RayPlan,
) -> Result<CaseAccuracy> {
    let mesh = &loaded.mesh;
    let reference = Reference::new(mesh);
    let set = ray_set(
        loaded,
        mesh,
        plan.side,
        plan.random,
        plan.adversarial,
        plan.seed,
    )?;
    let expected = set.reference_hits(&reference);
    let mut out = Vec::new();
    let mut left_out = Vec::new();
    for &m in methods {
        let unscaled_f32 = matches!(m, Method::Sctp | Method::Tet80);
        let beyond_f32 = unscaled_f32 && extremes::beyond_f32_products(case);
        if beyond_f32 {
            left_out.push(format!("{}/f32", m.name()));
        }
        for (f64, label) in variants(m, precision) {
            if beyond_f32 && !f64 {
                continue;
            }
            let t = tracer(m, f64, mesh)?;
            out.push(check(
                t.as_ref(),
                label,
                &reference,
                &expected,
                &set,
                plan.min_time_s,
            ));
        }
    }
    Ok(CaseAccuracy {
        case: case.into(),
        tets: mesh.tets.len(),
        tolerance: reference.tol,
        rays: set.rays.len(),
        reference_ambiguous: expected
            .iter()
            .filter(|e| e.is_some_and(|e| e.ambiguous()))
            .count(),
        methods: out,
        skipped: None,
        left_out,
    })
}

/// The scene as given and, with `extremes` (the build flags to rebuild
/// with), the extreme cases of [`extremes::cases`]; a case that
/// cannot be built is reported as skipped with its error.
pub fn all_cases(
    loaded: &Loaded,
    methods: &[Method],
    precision: Precision,
    plan: RayPlan,
    extremes: Option<&BuildFlags>,
    quiet: bool,
) -> Result<Vec<CaseAccuracy>> {
    let mut cases = vec![run_case("as-is", loaded, methods, precision, plan)?];
    if let Some(flags) = extremes {
        for (name, result) in extremes::cases(loaded, flags, quiet) {
            cases.push(match result {
                Ok(l) => run_case(&name, &l, methods, precision, plan)?,
                Err(e) => CaseAccuracy {
                    case: name,
                    tets: 0,
                    tolerance: 0.0,
                    rays: 0,
                    reference_ambiguous: 0,
                    methods: Vec::new(),
                    skipped: Some(error_chain(&e)),
                    left_out: Vec::new(),
                },
            });
        }
    }
    Ok(cases)
}

#[cfg(test)]
mod tests {
    use super::*;
    use tet_core::synthetic::{GridSpec, constrain_faces, kuhn_grid};

    /// A method that never hits anything.
    struct AlwaysMiss<'m>(&'m TetMesh);

    impl Tracer for AlwaysMiss<'_> {
        fn name(&self) -> String {
            "always-miss".into()
        }
        fn mesh(&self) -> &TetMesh {
            self.0
        }
        fn trace(&self, _: &Ray, _: Start) -> TraceOutcome {
            TraceOutcome::Miss { tets_visited: 0 }
        }
    }

    /// A method that reports, by brute force, the farthest constrained
    /// face along the ray (`None`: it passes through every surface but the
    /// last) or the first one at `t ≥ after`.
    struct Along<'m>(&'m TetMesh, Option<f64>);

    impl Tracer for Along<'_> {
        fn name(&self) -> String {
            "along".into()
        }
        fn mesh(&self) -> &TetMesh {
            self.0
        }
        fn trace(&self, ray: &Ray, _: Start) -> TraceOutcome {
            let m = self.0;
            let crossings = (0..m.constrained.len() as u32).filter_map(|f| {
                let cf = &m.constrained[f as usize];
                let (t, b) = ray_triangle(ray, cf.vertices.map(|k| m.points[k as usize]))?;
                (t >= self.1.unwrap_or(0.0)).then_some((t, b, f))
            });
            let pick = match self.1 {
                None => crossings.max_by(|a, b| a.0.total_cmp(&b.0)),
                Some(_) => crossings.min_by(|a, b| a.0.total_cmp(&b.0)),
            };
            match pick {
                Some((t, b, f)) => TraceOutcome::Hit(Hit {
                    triangle: m.constrained[f as usize].triangle,
                    face: f,
                    t: t as f32,
                    barycentrics: b.map(|x| x as f32),
                    tet: 0,
                    far_tet: tet_core::NO_TET,
                    tets_visited: 0,
                }),
                None => TraceOutcome::Miss { tets_visited: 0 },
            }
        }
    }

    /// The closed surface of the box [1, 3]³ inside a 4³ grid, unjittered.
    fn closed_box() -> TetMesh {
        kuhn_grid(&GridSpec {
            cells: [4, 4, 4],
            jitter: 0.0,
            shell: Some(([1, 1, 1], [3, 3, 3])),
            ..Default::default()
        })
    }

    /// Every edge midpoint and every corner of every constrained face.
    fn edges_and_vertices(mesh: &TetMesh) -> Vec<Vec3> {
        let mut out = Vec::new();
        for cf in &mesh.constrained {
            let p = cf.vertices.map(|k| mesh.points[k as usize]);
            for k in 0..3 {
                out.push(p[k]);
                out.push((p[k] + p[(k + 1) % 3]) * 0.5);
            }
        }
        out
    }

    /// Rays from `origin` through each target, each with the reference
    /// hit; starts in tet 0 (the fake tracers ignore it).
    fn aimed(origin: Vec3, targets: &[Vec3]) -> RaySet {
        RaySet {
            rays: targets
                .iter()
                .map(|&p| (Ray::new(origin, p - origin), Some(Start::Tet(0))))
                .collect(),
            view: None,
        }
    }

    fn expected(reference: &Reference, set: &RaySet) -> Vec<Option<RefHit>> {
        set.rays.iter().map(|(r, _)| reference.closest(r)).collect()
    }

    #[test]
    fn a_miss_across_a_closed_edge_or_vertex_is_a_leak() {
        let mesh = closed_box();
        assert_eq!(mesh.constrained.len(), 48);
        let reference = Reference::new(&mesh);
        let grazing = edges_and_vertices(&mesh);
        let centroids: Vec<Vec3> = mesh
            .constrained
            .iter()
            .map(|cf| cf.vertices.map(|k| mesh.points[k as usize]))
            .map(|p| (p[0] + p[1] + p[2]) / 3.0)
            .collect();
        let origin = Vec3::new(2.0, 2.0, 2.0);
        let set = aimed(origin, &[grazing.clone(), centroids.clone()].concat());
        let exp = expected(&reference, &set);
        // Every grazing ray hits the box near an edge: the rays that the
        // old counting filed under "grazing" whatever the method did.
        for e in &exp[..grazing.len()] {
            let e = e.expect("a ray from inside the box hits it");
            assert!(e.near_edge && e.ambiguous(), "{e:?}");
        }
        let m = check(&AlwaysMiss(&mesh), "f32", &reference, &exp, &set, 0.0);
        assert_eq!(m.leaks, grazing.len() as u64, "{m:?}");
        assert_eq!(m.ambiguous, 0, "{m:?}");
        // A miss away from any edge stays a false miss.
        assert_eq!(m.false_misses, centroids.len() as u64, "{m:?}");
        assert_eq!(m.failures, m.rays, "{m:?}");
        assert_eq!(m.failures_per_1024_squared, 1024.0 * 1024.0);
    }

    #[test]
    fn a_farther_hit_across_a_closed_edge_is_a_leak() {
        let mesh = closed_box();
        let reference = Reference::new(&mesh);
        // From above the box, at the inner edges and vertex of its top
        // side (not its rim, where the ray would graze the box's outline):
        // the first hit is the top, the farthest the bottom or a side.
        let inside = |c: f32| c > 1.0 && c < 3.0;
        let grazing: Vec<Vec3> = edges_and_vertices(&mesh)
            .into_iter()
            .filter(|p| p.z == 3.0 && inside(p.x) && inside(p.y))
            .collect();
        assert!(!grazing.is_empty());
        let set = aimed(Vec3::new(2.1, 1.95, 3.9), &grazing);
        let exp = expected(&reference, &set);
        for e in &exp {
            let e = e.expect("the top of the box is hit");
            assert!(e.near_edge && e.ambiguous(), "{e:?}");
        }
        let m = check(&Along(&mesh, None), "f32", &reference, &exp, &set, 0.0);
        assert_eq!(m.leaks, grazing.len() as u64, "{m:?}");
        assert_eq!(m.ambiguous + m.agree + m.wrong_triangle, 0, "{m:?}");
        assert_eq!(m.failures, m.leaks);
    }

    #[test]
    fn a_miss_at_an_open_edge_or_vertex_is_grazing_not_a_leak() {
        // An open square: the plane z = 1 of a 2³ grid, 8 triangles; its
        // inner edges join two triangles, its border edges bound one.
        let grid = kuhn_grid(&GridSpec {
            cells: [2, 2, 2],
            jitter: 0.0,
            ..Default::default()
        });
        let mesh = constrain_faces(grid, |v| v.iter().all(|p| p.z == 1.0), None);
        assert_eq!(mesh.constrained.len(), 8);
        let reference = Reference::new(&mesh);
        let on_border = |p: Vec3| [p.x, p.y].iter().any(|&c| c == 0.0 || c == 2.0);
        let (border, inner): (Vec<Vec3>, Vec<Vec3>) = edges_and_vertices(&mesh)
            .into_iter()
            .partition(|&p| on_border(p));
        assert!(!border.is_empty() && !inner.is_empty());
        for (targets, leak) in [(&border, false), (&inner, true)] {
            let set = aimed(Vec3::new(0.9, 1.15, 1.8), targets);
            let exp = expected(&reference, &set);
            assert!(exp.iter().all(|e| e.is_some_and(|e| e.near_edge)));
            let m = check(&AlwaysMiss(&mesh), "f32", &reference, &exp, &set, 0.0);
            let n = targets.len() as u64;
            if leak {
                assert_eq!((m.leaks, m.ambiguous, m.failures), (n, 0, n), "{m:?}");
            } else {
                assert_eq!((m.leaks, m.ambiguous, m.failures), (0, n, 0), "{m:?}");
            }
        }
    }

    /// A closed step: the block [1, 3]×[1, 2]×[1, 2] with the block
    /// [1, 2]×[1, 2]×[2, 3] on top of its left half, in a 5×3×5 grid. Its
    /// top face at z = 2 meets the wall x = 2 of the upper block in a
    /// concave edge.
    fn closed_step() -> TetMesh {
        let grid = kuhn_grid(&GridSpec {
            cells: [5, 3, 5],
            jitter: 0.0,
            ..Default::default()
        });
        let solid = |c: Vec3| {
            let lower = c.x > 1.0 && c.x < 3.0 && c.z > 1.0 && c.z < 2.0;
            let upper = c.x > 1.0 && c.x < 2.0 && c.z > 2.0 && c.z < 3.0;
            c.y > 1.0 && c.y < 2.0 && (lower || upper)
        };
        solid_faces(grid, solid)
    }

    /// `grid` with its faces between a cell of `solid` (a test on the
    /// cell's centre) and a cell outside it constrained: the solid's
    /// closed surface.
    fn solid_faces(grid: TetMesh, solid: impl Fn(Vec3) -> bool) -> TetMesh {
        constrain_faces(
            grid,
            |v| {
                // An axis-aligned face separates a cell of the solid from
                // one outside it.
                (0..3).any(|a| {
                    let m = (v[0] + v[1] + v[2]) / 3.0;
                    let e = Vec3::AXES[a] * 0.5;
                    let cell = |p: Vec3| p.floor() + Vec3::splat(0.5);
                    v.iter().all(|p| p[a] == v[0][a]) && solid(cell(m - e)) != solid(cell(m + e))
                })
            },
            None,
        )
    }

    #[test]
    fn a_ray_clipping_a_convex_edge_before_a_wall_is_grazing() {
        // The ray meets the top face of the step's lower block within
        // tol/4 of its convex edge x = 3 and leaves through the side face
        // at once: it clips the corner. The line behind it meets the wall
        // x = 2, a face around a vertex of the hit triangle, which a test
        // of the whole line took for a crossing (a leak).
        let mesh = closed_step();
        let reference = Reference::new(&mesh);
        let delta = (reference.tol / 4.0) as f32;
        let p = Vec3::new(3.0 - delta, 1.37, 2.0);
        let clip = Vec3::new(1.0, 0.0, -0.5);
        // Control: entering the block steeply at the same point crosses
        // the surface there.
        let enter = Vec3::new(-0.2, 0.0, -1.0);
        let set = RaySet {
            rays: [clip, enter]
                .iter()
                .map(|&d| (Ray::new(p - d * 0.5, d), Some(Start::Tet(0))))
                .collect(),
            view: None,
        };
        let exp = expected(&reference, &set);
        let [Some(c), Some(e)] = [exp[0], exp[1]] else {
            panic!("both rays hit the step: {exp:?}");
        };
        assert!(c.near_edge && !c.closed, "{c:?}");
        assert!(e.near_edge && e.closed, "{e:?}");
        let m = check(&AlwaysMiss(&mesh), "f32", &reference, &exp, &set, 0.0);
        assert_eq!((m.leaks, m.ambiguous, m.failures), (1, 1, 1), "{m:?}");
    }

    /// Two closed blocks side by side: [1, 2] and [3, 4] in x, both
    /// [1, 2]×[1, 2] in y and z, in a 5×3×3 grid.
    fn two_blocks() -> TetMesh {
        let grid = kuhn_grid(&GridSpec {
            cells: [5, 3, 3],
            jitter: 0.0,
            ..Default::default()
        });
        let solid = |c: Vec3| {
            let x = (c.x > 1.0 && c.x < 2.0) || (c.x > 3.0 && c.x < 4.0);
            x && c.y > 1.0 && c.y < 2.0 && c.z > 1.0 && c.z < 2.0
        };
        solid_faces(grid, solid)
    }

    #[test]
    fn a_ray_clipping_a_convex_edge_may_skip_it_but_not_the_face_beyond() {
        // The ray meets the top of the left block within tol/4 of its
        // convex edge x = 2 and leaves through its side at once (the two
        // faces of the edge lie on one side of it: some nearby line passes
        // both by), then crosses the right block's wall x = 3 at z = 1.5,
        // far from any edge. Skipping the clipped corner is grazing;
        // skipping the wall too slips through a closed surface.
        let mesh = two_blocks();
        let reference = Reference::new(&mesh);
        let delta = (reference.tol / 4.0) as f32;
        let d = Vec3::new(1.0, 0.0, -0.5);
        let x = Vec3::new(2.0 - delta, 1.37, 2.0);
        let set = RaySet {
            rays: vec![(Ray::new(x - d * 0.5, d), Some(Start::Tet(0)))],
            view: None,
        };
        let exp = expected(&reference, &set);
        let e = exp[0].expect("the ray hits the left block");
        assert!(e.near_edge && !e.closed, "{e:?}");
        let b = e.beyond.expect("the right block's wall lies beyond");
        assert!(b.closed && (b.t - 1.5).abs() < 1e-4, "{b:?}");
        // Past the corner, at the wall: grazing.
        let past = Along(&mesh, Some(e.t + 10.0 * e.tol_t));
        let m = check(&past, "f32", &reference, &exp, &set, 0.0);
        assert_eq!((m.ambiguous, m.failures), (1, 0), "{m:?}");
        // Through the wall too, or nothing at all: leaks.
        for method in [&Along(&mesh, None) as &dyn Tracer, &AlwaysMiss(&mesh)] {
            let m = check(method, "f32", &reference, &exp, &set, 0.0);
            assert_eq!((m.leaks, m.failures), (1, 1), "{m:?}");
        }
    }

    #[test]
    fn a_ray_nearly_in_a_face_plane_is_grazing() {
        // The ray runs 1.3e-6 rad below the plane of the box's top face
        // and crosses it 0.3 from every edge: its hit point is far from
        // the edges, but its line passes within `tol` of them.
        let mesh = closed_box();
        let reference = Reference::new(&mesh);
        let rise = 2f32.powi(-19);
        let origin = Vec3::new(0.5, 1.37, 3.0 + rise);
        let ray = Ray::new(origin, Vec3::new(1.0, 0.0, -rise / 1.8));
        let hit = reference.closest(&ray).expect("the ray hits the top face");
        let cf = &mesh.constrained[hit.face as usize];
        let v = cf.vertices.map(|k| mesh.points[k as usize].as_dvec3());
        let x = ray.origin.as_dvec3() + ray.direction.as_dvec3() * hit.t;
        assert!((x.z - 3.0).abs() < 1e-9 && (x.x - 2.3).abs() < 1e-6, "{x}");
        assert!(edge_distance(x, v) > 100.0 * reference.tol);
        assert!(hit.near_edge && hit.ambiguous(), "{hit:?}");
        let set = RaySet {
            rays: vec![(ray, Some(Start::Tet(0)))],
            view: None,
        };
        let m = check(
            &AlwaysMiss(&mesh),
            "f32",
            &reference,
            &[Some(hit)],
            &set,
            0.0,
        );
        assert_eq!((m.ambiguous, m.failures), (1, 0), "{m:?}");
    }

    #[test]
    fn a_miss_along_the_outline_of_a_closed_surface_is_grazing() {
        // Rays from outside that touch an edge and a corner of the box and
        // go on outside it: both faces of the edge lie on one side of them.
        let mesh = closed_box();
        let reference = Reference::new(&mesh);
        let edge = Vec3::new(1.0, 1.0, 2.5);
        let corner = Vec3::new(1.0, 1.0, 1.0);
        let set = RaySet {
            rays: vec![
                (
                    Ray::new(Vec3::new(0.0, 1.5, 2.5), edge - Vec3::new(0.0, 1.5, 2.5)),
                    Some(Start::Tet(0)),
                ),
                (
                    Ray::new(Vec3::new(0.0, 2.0, 2.0), corner - Vec3::new(0.0, 2.0, 2.0)),
                    Some(Start::Tet(0)),
                ),
            ],
            view: None,
        };
        let exp = expected(&reference, &set);
        assert!(
            exp.iter().all(|e| e.is_some_and(|e| e.near_edge)),
            "{exp:?}"
        );
        let m = check(&AlwaysMiss(&mesh), "f32", &reference, &exp, &set, 0.0);
        assert_eq!((m.leaks, m.ambiguous, m.failures), (0, 2, 0), "{m:?}");
        // The same points entered across the edge and the corner leak.
        let set = aimed(Vec3::new(0.0, 0.5, 2.5), &[edge]);
        let set = RaySet {
            rays: [set.rays, aimed(Vec3::new(0.0, 0.2, 0.1), &[corner]).rays].concat(),
            view: None,
        };
        let exp = expected(&reference, &set);
        let m = check(&AlwaysMiss(&mesh), "f32", &reference, &exp, &set, 0.0);
        assert_eq!((m.leaks, m.ambiguous, m.failures), (2, 0, 2), "{m:?}");
    }

    /// The exact walk against the reference on every adversarial ray of
    /// jittered grids with a closed shell and random scene triangles: no
    /// failure of any kind, only agreement or a ray the reference itself
    /// calls ambiguous.
    #[test]
    fn the_exact_walk_passes_every_adversarial_ray() {
        for (seed, jitter) in [(1u64, 0.0f32), (2, 0.12)] {
            let grid = kuhn_grid(&GridSpec {
                cells: [5, 5, 5],
                jitter,
                shell: Some(([1, 1, 1], [4, 4, 4])),
                constrained_fraction: 0.05,
                seed,
                ..Default::default()
            });
            grid.validate().unwrap();
            let reference = Reference::new(&grid);
            let set = RaySet {
                rays: adversarial_rays(&grid, 1200, seed),
                view: None,
            };
            assert!(set.rays.len() > 1100, "{}", set.rays.len());
            let exp = expected(&reference, &set);
            let t = tracer(Method::Exact, false, &grid).unwrap();
            let m = check(t.as_ref(), "f32", &reference, &exp, &set, 0.0);
            assert_eq!(m.failures, 0, "{m:?}");
            assert_eq!(m.agree + m.ambiguous, m.rays, "{m:?}");
            assert!(m.agree > m.rays / 2, "{m:?}");
        }
    }

    #[test]
    fn the_walk_does_not_leak_through_the_closed_box() {
        let mesh = closed_box();
        let reference = Reference::new(&mesh);
        let origin = Vec3::new(2.1, 1.95, 2.05);
        let mut set = aimed(origin, &edges_and_vertices(&mesh));
        set.view = Some(Viewpoint::locate(&mesh, origin).unwrap());
        for r in &mut set.rays {
            r.1 = None;
        }
        let exp = expected(&reference, &set);
        for method in [Method::Tet20, Method::Tet32, Method::Sctp] {
            let t = tracer(method, false, &mesh).unwrap();
            let m = check(t.as_ref(), "f32", &reference, &exp, &set, 0.0);
            assert_eq!((m.leaks, m.failures), (0, 0), "{m:?}");
            assert_eq!(m.agree + m.ambiguous, m.rays, "{m:?}");
        }
    }
}
