//! Ambient-occlusion rays: one per primary hit, the secondary-ray workload
//! of the public Tray Racing benchmark (one primary and one AO ray per
//! pixel), traced per render tile in one batch.
//!
//! An AO ray leaves the hit point on the side of the hit face the primary
//! ray came from, in a cosine-distributed direction about that side's
//! normal (the face's geometric normal, so that the ray never starts into
//! the face), and is occluded when any constrained face lies within
//! [`ao_length`] of its origin. It starts *on* the hit face, in the tet on
//! its side ([`start_beyond`]: the hit's own tet), like every secondary ray
//! ([`crate::secondary`]): the tet walks go on from there and never meet
//! the face again, the BVHs trace it from the root and skip the face's
//! input triangle. Where no tet lies on that side (the mesh's boundary: no
//! scene geometry beyond it) or the direction lies in the face's plane, no
//! ray is cast and the hit counts as open.

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::synthetic::SplitMix64;

use super::{FrameStats, RenderOptions};
use crate::kernel::Tracer;
use crate::ray::{Hit, Ray, TraceOutcome};
use crate::secondary::{face_normal, hit_point, start_beyond};
use crate::walk::{Start, Starts};

/// A direction about the unit normal `n`, cosine-distributed over its
/// hemisphere for `u1, u2` uniform in `[0, 1)` (Malley's method: a uniform
/// point of the unit disc lifted onto the hemisphere).
pub fn cosine_direction(n: Vec3, u1: f32, u2: f32) -> Vec3 {
    let (t, b) = n.any_orthonormal_pair();
    let r = u1.sqrt();
    let (s, c) = (std::f32::consts::TAU * u2).sin_cos();
    let z = (1.0 - u1).max(0.0).sqrt();
    (t * (r * c) + b * (r * s) + n * z).normalize()
}

/// Length of the AO rays: `share` of the diagonal of the scene's bounding
/// box (the constrained faces' vertices; every point of a mesh without
/// any), so that it means the same for every method and any enclosing box.
pub fn ao_length(mesh: &TetMesh, share: f32) -> f32 {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    let mut add = |p: Vec3| {
        lo = lo.min(p);
        hi = hi.max(p);
    };
    if mesh.constrained.is_empty() {
        mesh.points.iter().copied().for_each(&mut add);
    } else {
        for cf in &mesh.constrained {
            for &v in &cf.vertices {
                add(mesh.points[v as usize]);
            }
        }
    }
    if lo.x > hi.x {
        return 0.0;
    }
    // The diagonal in f64: a scene at 1e30 would overflow its square.
    (hi.as_dvec3() - lo.as_dvec3()).length() as f32 * share
}

/// The AO ray of `hit` on the primary ray `primary` (unit direction,
/// `t_max = length`) and where it starts, its direction drawn from `seed`;
/// `None` when no ray is cast (see the module docs: the hit is open).
pub fn ao_ray(
    mesh: &TetMesh,
    primary: &Ray,
    hit: &Hit,
    length: f32,
    seed: u64,
) -> Option<(Ray, Start)> {
    let n = face_normal(mesh, hit.face);
    if n == Vec3::ZERO {
        return None;
    }
    let n = if n.dot(primary.direction) > 0.0 {
        -n
    } else {
        n
    };
    let mut rng = SplitMix64(seed);
    let (u1, u2) = (rng.next_f64() as f32, rng.next_f64() as f32);
    let dir = cosine_direction(n, u1, u2);
    let start = start_beyond(mesh, hit.face, dir)?;
    Some((
        Ray {
            origin: hit_point(mesh, hit),
            direction: dir,
            t_min: 0.0,
            t_max: length,
        },
        start,
    ))
}

/// What a pixel's AO ray found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Ao {
    /// No AO: off, or no hit.
    Off,
    /// No ray needed (see [`ao_ray`]) or none of the scene within reach.
    Open,
    /// A constrained face within [`ao_length`].
    Occluded,
    /// The walk failed (the pixel counts as open).
    Failed,
}

/// A tile's AO rays, one per primary hit, traced in one batch by the
/// primary tracer ([`Tracer::trace_batch_from`] with a start per ray: the
/// tet kernels walk them side by side in SIMD lockstep, as they walk the
/// primary rays), and what each found. The buffers are reused from tile
/// to tile.
#[derive(Default)]
pub(super) struct TileAo {
    rays: Vec<Ray>,
    starts: Vec<Start>,
    /// The tile pixel of each ray.
    pixels: Vec<usize>,
    out: Vec<TraceOutcome>,
    found: Vec<Ao>,
}

impl TileAo {
    /// Casts and traces the AO rays of the tile whose primary `rays` (of
    /// image pixels `ids`) had `outcomes`; nothing without
    /// [`RenderOptions::ambient_occlusion`] or with
    /// [`RenderOptions::headlight`]. Adds the rays cast, the tets their
    /// walks visited (0 for a tracer without tets) and their failures to
    /// `stats`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn trace<T: Tracer + ?Sized>(
        &mut self,
        tracer: &T,
        mesh: &TetMesh,
        rays: &[Ray],
        outcomes: &[TraceOutcome],
        ids: &[u32],
        length: f32,
        opts: &RenderOptions,
        stats: &mut FrameStats,
    ) {
        self.found.clear();
        self.found.resize(rays.len(), Ao::Off);
        self.rays.clear();
        self.starts.clear();
        self.pixels.clear();
        if !opts.ambient_occlusion || opts.headlight {
            return;
        }
        for (k, ((ray, o), &id)) in rays.iter().zip(outcomes).zip(ids).enumerate() {
            let TraceOutcome::Hit(hit) = o else {
                continue;
            };
            match ao_ray(mesh, ray, hit, length, ao_seed(opts.seed, id)) {
                Some((r, s)) => {
                    self.rays.push(r);
                    self.starts.push(s);
                    self.pixels.push(k);
                }
                None => self.found[k] = Ao::Open,
            }
        }
        self.out.clear();
        self.out
            .resize(self.rays.len(), TraceOutcome::Miss { tets_visited: 0 });
        // An AO ray asks only what lies within its length: a tet walk
        // ends once it is past it ([`Tracer::trace_batch_within`]).
        tracer.trace_batch_within(&self.rays, Starts::Each(&self.starts), &mut self.out);
        stats.ao_rays += self.rays.len() as u64;
        for (&k, o) in self.pixels.iter().zip(&self.out) {
            stats.ao_tets_visited += o.tets_visited() as u64;
            stats.ao_failures += o.is_failure() as u64;
            self.found[k] = match o {
                TraceOutcome::Hit(_) => Ao::Occluded,
                TraceOutcome::Failed { .. } => Ao::Failed,
                TraceOutcome::Miss { .. } => Ao::Open,
            };
        }
    }

    /// What tile pixel `k`'s AO ray found.
    pub(super) fn of(&self, k: usize) -> Ao {
        self.found[k]
    }
}

/// The seed of image pixel `pixel`'s AO direction: the frame seed mixed
/// with the pixel index, apart from the area lights' jitter.
pub fn ao_seed(seed: u64, pixel: u32) -> u64 {
    super::pixel_seed(seed ^ 0xA0A0_5EED_0000_0001, pixel)
}
