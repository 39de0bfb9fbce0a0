//! Accuracy of every method against an f64 reference (the `accuracy`
//! command, and the robustness and speed-vs-accuracy tables of `tables`).
//!
//! The reference is exact in structure: every candidate triangle is tested
//! with the f64 ray–triangle test of `tet_trace_cpu::reference`; candidates
//! come from a BVH over triangle boxes padded by the tolerance (so the f32
//! box test cannot drop a triangle the ray passes within tolerance of).
//!
//! A ray counts as **ambiguous** (grazing), not wrong, when the reference hit
//! point lies within `tol` of an edge of its triangle, a second triangle is
//! hit within `tol` along the ray, the hit lies within `tol` of the ray
//! origin, or the method's own hit point lies within
//! `tol` of an edge of the triangle it reports; `tol = max(1e-5 · diagonal, 4e-7 · max |coordinate|)`
//! (the second term is a few f32 ulps of the coordinates, which dominates
//! for scenes far from the origin).

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
use tet_trace_cpu::ray::{Failure, Ray, TraceOutcome};
use tet_trace_cpu::reference::{Aim, edge_distance, random_ray, ray_triangle};
use tet_trace_cpu::render::PinholeCamera;
use tet_trace_cpu::walk::Start;

use crate::cli::{BuildFlags, Method, Precision};
use crate::extremes;
use crate::load::Loaded;
use crate::methods::{has_f64, tracer};
use crate::output::error_chain;

/// The f64 reference hit of one ray.
#[derive(Clone, Copy, Debug)]
struct RefHit {
    /// Constrained face hit.
    face: u32,
    /// Its scene triangle.
    triangle: u32,
    /// Closest hit point within `tol` of an edge, or another hit within `tol`.
    ambiguous: bool,
}

/// f64 reference over a padded-box BVH.
pub struct Reference<'m> {
    /// The mesh whose constrained faces are tested.
    mesh: &'m TetMesh,
    /// BVH over the faces' boxes, padded by the tolerance.
    bvh: Bvh2,
    /// Grazing tolerance (world units).
    pub tol: f64,
}

/// `v` in obvhs's vector type.
fn a3(v: Vec3) -> Vec3A {
    Vec3A::new(v.x, v.y, v.z)
}

/// Grazing tolerance of a mesh (see the module docs).
pub fn tolerance(mesh: &TetMesh) -> f64 {
    let (lo, hi) = mesh.point_bounds();
    let diag = (hi - lo).length() as f64;
    let mag = lo.abs().max(hi.abs()).max_element() as f64;
    (1e-5 * diag).max(4e-7 * mag)
}

impl<'m> Reference<'m> {
    /// Builds the reference over `mesh.constrained`.
    pub fn new(mesh: &'m TetMesh) -> Self {
        let tol = tolerance(mesh);
        let pad = Vec3A::splat((tol * 2.0) as f32);
        let boxes: Vec<Aabb> = mesh
            .constrained
            .iter()
            .map(|cf| {
                let p = cf.vertices.map(|v| a3(mesh.points[v as usize]));
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
        Reference { mesh, bvh, tol }
    }

    /// The reference hit of `ray`: its closest constrained face in f64, or
    /// `None` when it hits none.
    fn closest(&self, ray: &Ray) -> Option<RefHit> {
        let mesh = self.mesh;
        let dlen = ray.direction.as_dvec3().length();
        let tol_t = self.tol / dlen;
        let mut best: Option<(f64, u32)> = None;
        let mut second = f64::INFINITY;
        let r = BvhRay::new(a3(ray.origin), a3(ray.direction), 0.0, f32::INFINITY);
        let mut hit = RayHit::none();
        self.bvh.ray_traverse(r, &mut hit, |_, id| {
            let face = self.bvh.primitive_indices[id];
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
            ((best.unwrap().0 + 2.0 * tol_t) as f32) * (1.0 + 1e-6)
        });
        let (t, face) = best?;
        let cf = &mesh.constrained[face as usize];
        let v = cf.vertices.map(|k| mesh.points[k as usize].as_dvec3());
        let p = ray.origin.as_dvec3() + ray.direction.as_dvec3() * t;
        let edge = edge_distance(p, v);
        Some(RefHit {
            face,
            triangle: cf.triangle,
            ambiguous: edge < self.tol || second - t < tol_t || t < tol_t,
        })
    }

    /// True when point `p` lies within `tol` of an edge of constrained face `face`.
    fn near_edge(&self, face: u32, p: DVec3) -> bool {
        let cf = &self.mesh.constrained[face as usize];
        let v = cf.vertices.map(|k| self.mesh.points[k as usize].as_dvec3());
        edge_distance(p, v) < self.tol
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
    /// Grazing rays (see tolerance) whose result differs: not counted as failures.
    pub ambiguous: u64,
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
    /// wrong_triangle + false_misses + false_hits + step_cap + lost + invalid + nans.
    pub failures: u64,
    /// Failures per 1024² rays (the unit of Maria et al. Table 4).
    pub failures_per_1024_squared: f64,
    /// Throughput of this batch (single pass over the rays, all threads), Mrays/s.
    pub mrays_per_s: f64,
}

/// One case: the scene as given, or transformed (JSON `cases[]`).
#[derive(Clone, Debug, Serialize)]
pub struct CaseAccuracy {
    /// `as-is`, `scale-1e-4`, `scale-1e4`, `translate-1e5`, `kuhn-slivers`.
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
}

/// A batch of rays with their start (`None`: a camera ray, started from
/// `view` by each tracer; see `tet_trace_cpu::entry` for a camera outside
/// the mesh).
pub struct RaySet {
    /// Each ray with its start (`None` for camera rays).
    rays: Vec<(Ray, Option<Start>)>,
    /// Where camera rays start (when there are camera rays).
    view: Option<Viewpoint>,
}

/// Camera rays of a `side × side` image plus `n` rays from random interior
/// points: 70 % random directions, 10 % aimed at vertices, 10 % at edge
/// midpoints, 10 % at face centroids.
pub fn ray_set(loaded: &Loaded, mesh: &TetMesh, side: u32, n: usize, seed: u64) -> Result<RaySet> {
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
    Ok(RaySet { rays, view })
}

/// Checks one tracer against the reference.
fn check(
    t: &dyn Tracer,
    precision: &'static str,
    reference: &Reference,
    expected: &[Option<RefHit>],
    set: &RaySet,
) -> MethodAccuracy {
    let start = Instant::now();
    let outcomes: Vec<TraceOutcome> = set
        .rays
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
        .collect();
    let secs = start.elapsed().as_secs_f64();
    let mut m = MethodAccuracy {
        method: t.name(),
        precision,
        rays: set.rays.len() as u64,
        mrays_per_s: set.rays.len() as f64 / secs.max(1e-9) / 1e6,
        ..Default::default()
    };
    for (((ray, _), o), e) in set.rays.iter().zip(&outcomes).zip(expected) {
        match (o, e) {
            (TraceOutcome::Failed { failure, .. }, _) => match failure {
                Failure::StepCap => m.step_cap += 1,
                Failure::Lost => m.lost += 1,
                Failure::InvalidRay => m.invalid += 1,
            },
            (TraceOutcome::Hit(h), _)
                if h.t.is_nan() || h.barycentrics.iter().any(|b| b.is_nan()) =>
            {
                m.nans += 1
            }
            (TraceOutcome::Hit(h), Some(r)) if h.triangle == r.triangle || h.face == r.face => {
                m.agree += 1
            }
            (TraceOutcome::Miss { .. }, None) => m.agree += 1,
            (_, Some(r)) if r.ambiguous => m.ambiguous += 1,
            // The method's own hit grazes an edge of its triangle: the
            // reference may rightly have passed just outside that triangle.
            (TraceOutcome::Hit(h), _)
                if reference.near_edge(
                    h.face,
                    ray.origin.as_dvec3() + ray.direction.as_dvec3() * h.t as f64,
                ) =>
            {
                m.ambiguous += 1
            }
            (TraceOutcome::Hit(_), None) => m.false_hits += 1,
            (TraceOutcome::Hit(_), Some(_)) => m.wrong_triangle += 1,
            (TraceOutcome::Miss { .. }, Some(_)) => m.false_misses += 1,
        }
    }
    m.failures =
        m.wrong_triangle + m.false_misses + m.false_hits + m.step_cap + m.lost + m.invalid + m.nans;
    m.failures_per_1024_squared = m.failures as f64 * (1024.0 * 1024.0) / m.rays.max(1) as f64;
    m
}

/// Runs every method on one mesh.
pub fn run_case(
    case: &str,
    loaded: &Loaded,
    methods: &[Method],
    precision: Precision,
    side: u32,
    n: usize,
    seed: u64,
) -> Result<CaseAccuracy> {
    let mesh = &loaded.mesh;
    let reference = Reference::new(mesh);
    let set = ray_set(loaded, mesh, side, n, seed)?;
    let expected: Vec<Option<RefHit>> = set
        .rays
        .par_iter()
        .map(|(r, _)| reference.closest(r))
        .collect();
    let mut out = Vec::new();
    for &m in methods {
        if matches!(precision, Precision::F32 | Precision::Both) && m != Method::Brute {
            let t = tracer(m, false, mesh)?;
            out.push(check(t.as_ref(), "f32", &reference, &expected, &set));
        }
        if matches!(precision, Precision::F64 | Precision::Both) && has_f64(m) {
            let t = tracer(m, true, mesh)?;
            out.push(check(t.as_ref(), "f64", &reference, &expected, &set));
        }
    }
    Ok(CaseAccuracy {
        case: case.into(),
        tets: mesh.tets.len(),
        tolerance: reference.tol,
        rays: set.rays.len(),
        reference_ambiguous: expected
            .iter()
            .filter(|e| e.is_some_and(|e| e.ambiguous))
            .count(),
        methods: out,
        skipped: None,
    })
}

/// The scene as given and, with `extremes` (the build flags to rebuild
/// with), the extreme cases of [`crate::extremes::cases`]; a case that
/// cannot be built is reported as skipped with its error.
#[allow(clippy::too_many_arguments)]
pub fn all_cases(
    loaded: &Loaded,
    methods: &[Method],
    precision: Precision,
    side: u32,
    n: usize,
    seed: u64,
    extremes: Option<&BuildFlags>,
    quiet: bool,
) -> Result<Vec<CaseAccuracy>> {
    let mut cases = vec![run_case(
        "as-is", loaded, methods, precision, side, n, seed,
    )?];
    if let Some(flags) = extremes {
        for (name, result) in extremes::cases(loaded, flags, quiet) {
            cases.push(match result {
                Ok(l) => run_case(&name, &l, methods, precision, side, n, seed)?,
                Err(e) => CaseAccuracy {
                    case: name,
                    tets: 0,
                    tolerance: 0.0,
                    rays: 0,
                    reference_ambiguous: 0,
                    methods: Vec::new(),
                    skipped: Some(error_chain(&e)),
                },
            });
        }
    }
    Ok(cases)
}
