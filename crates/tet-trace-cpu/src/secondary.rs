//! Secondary rays (Aman et al. 2022, §6): shadow rays to point lights,
//! reflection and refraction rays.
//!
//! A hit reports the constrained face and the tets on both of its sides
//! ([`Hit::tet`], [`Hit::far_tet`]). A secondary ray starts *on* the hit face,
//! inside the tet on the side its direction points to ([`Start::Face`]), so
//! the walk never meets that face again and needs no epsilon offset.
//! `front`/`back` follow [`tet_core::ConstrainedFace`]: the front side is the
//! one the triangle's normal (right-hand rule on `vertices`) points to.
//!
//! # Shadow rays that end at the light's tet (§6)
//!
//! The paper locates each point light once per frame and stops a shadow walk
//! "if the tetrahedron that contains the light source is reached". Here:
//!
//! * [`LightTarget::locate`] locates the light `L` exactly
//!   ([`crate::locate::locate`]) and keeps its **star**: every tet whose
//!   *closed* cell contains `L` ([`crate::locate::star`]). For `L` strictly
//!   inside a tet that is one tet; on a face two, on an edge the ring of tets
//!   around it, on a vertex every tet incident to it — across constrained
//!   faces too.
//! * The shadow ray runs from the hit point `P` (on the hit face, starting
//!   in the tet on `L`'s side, [`start_beyond`]) with direction `L − P` and
//!   `t_max = 1`. The walk ([`ShadowTracer::trace_until`]) reports
//!   **unoccluded** as soon as it *enters* a star tet, or when the first
//!   constrained face it crosses lies beyond the light (`t > 1`, computed in
//!   f64 as for every hit) or it leaves the mesh; it reports **occluded**
//!   when it crosses a constrained face at `t ≤ 1` before entering a star
//!   tet. Whichever the walk sees first decides.
//!
//! The hit face itself never occludes: the shadow ray starts on it, in the
//! tet on the light's side, whichever side the primary ray came from (a light
//! behind the surface gets no light from the Lambert term anyway).
//!
//! Why the star and not only the located tet: the ray reaches `L` in the
//! closure of whichever tet around `L` the walk happens to be in, which is
//! decided by the walk's tie rule, not by [`crate::locate::locate`]. With the
//! whole star, reaching `L` always means entering a star tet first, so the
//! decision never depends on rounding at `t ≈ 1`. Consequences, exactly:
//!
//! * **Light strictly inside a tet, or on a non-constrained face, edge or
//!   vertex**: the segment `P L` is unoccluded iff no constrained face meets
//!   it before `L` (the walk enters the star from the segment's last tets).
//! * **Light on a constrained face (or its edge / vertex)**: the star holds
//!   the tets on both sides, so the light shines on both sides of that face;
//!   the face it lies on never shadows it (the segment touches it only at
//!   `L`). Other faces still do.
//! * **Light inside a region cut off by constrained faces** (a set of tets
//!   connected through non-constrained faces, bounded by constrained faces —
//!   e.g. inside a closed object): if `L` is not on the region's boundary,
//!   the star lies inside the region, and a walk from any `P` outside it must
//!   cross a boundary face before it can enter a star tet, so the light is
//!   occluded from every point outside the region. That crossing lies at
//!   `t < 1` exactly; in f64 it could only round past 1 if `L` were within
//!   f64 rounding (~1e-15 relative) of the face's plane without being on it.
//! * **Light outside the mesh** ([`LightTarget::outside`], no star): the
//!   shadow ray ends at the light's distance (`t_max = 1`) or at the mesh
//!   boundary (the previous rule, still used by [`light_visible`]).
//!
//! The stop test costs one comparison per step for a light inside a tet
//! (a short scan for a light on an edge or vertex). It is implemented as a
//! [`Topology`] wrapper ([`StopAt`]) that reports the mesh boundary when the
//! walk asks for the exit link of a star tet, so the projected walks reuse
//! the watertight engine unchanged ([`crate::walk::trace`]); Tet80 checks
//! the tet at the top of its loop.
//!
//! # Batches
//!
//! [`ShadowTracer::trace_until_batch`] (and [`Tracer::trace_until_batch`])
//! trace many shadow rays toward one light, e.g. a render tile's. The tet
//! kernels walk them side by side in SIMD lockstep, as they walk primary
//! rays ([`crate::lockstep`]): over the layout itself (the lockstep walk
//! gathers the layout's records, not [`StopAt`]'s), with a gate that takes
//! a walk out just before it enters a star tet and writes the outcome the
//! single-ray walk reaches there (one more tet visited, a miss; the step
//! cap first, as that walk checks it). A walk that starts in a star tet
//! ends there before any walk, as above. So every outcome is the
//! single-ray walk's, bit for bit, hit records and tets visited included,
//! and the walks that reach the step cap are walked again by the exact
//! walk as single rays are. Tracers without tets (and any
//! [`ShadowTracer`] that does not override it) trace the batch ray by
//! ray; [`PerRay`] forces that, as the reference.

use glam::Vec3;
use tet_core::{Link, NO_TET, TetMesh};

use crate::batch::BatchWalk;
use crate::kernel::{Tracer, WalkTracer};
use crate::locate::{LocateError, locate, star};
use crate::lockstep::exit::ByLane;
use crate::ray::{Hit, Ray, TraceOutcome};
use crate::shadow_batch;
use crate::walk::{Batch, DuffF32, Start, Starts, Topology, step_cap, trace_until};
pub use crate::walk::{StopAt, stops_at};

/// Unit geometric normal of a hit's face (from the source triangle winding).
pub fn face_normal(mesh: &TetMesh, face: u32) -> Vec3 {
    let v = mesh.constrained[face as usize]
        .vertices
        .map(|i| mesh.points[i as usize]);
    (v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero()
}

/// The hit point of `hit` on `ray`, interpolated from the face's vertices
/// with the barycentrics (exactly on the face's plane up to rounding).
pub fn hit_point(mesh: &TetMesh, hit: &Hit) -> Vec3 {
    let v = mesh.constrained[hit.face as usize]
        .vertices
        .map(|i| mesh.points[i as usize]);
    v[0] * hit.barycentrics[0] + v[1] * hit.barycentrics[1] + v[2] * hit.barycentrics[2]
}

/// Where a ray leaving face `face` in direction `dir` starts: the tet on the
/// side `dir` points to, or `None` when no tet is there (mesh boundary) or
/// `dir` lies in the face's plane.
pub fn start_beyond(mesh: &TetMesh, face: u32, dir: Vec3) -> Option<Start> {
    let cf = &mesh.constrained[face as usize];
    let s = dir.dot(face_normal(mesh, face));
    let side = if s > 0.0 {
        cf.front
    } else if s < 0.0 {
        cf.back
    } else {
        return None;
    };
    (side.tet != NO_TET).then_some(Start::Face {
        face,
        tet: side.tet,
    })
}

/// A secondary ray and its outcome.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Traced {
    /// The ray cast (origin on the hit face).
    pub ray: Ray,
    /// Its outcome; `None` when no tet lies on the side it leaves to (the ray
    /// leaves the mesh at once: a miss).
    pub outcome: Option<TraceOutcome>,
}

/// True when `light` is visible from the hit point of `hit` (no constrained
/// face strictly between them). The shadow ray runs from the hit face to the
/// light with `t_max = 1`; a light outside the mesh on the far side of a
/// boundary face counts as visible.
pub fn light_visible<T: Tracer + ?Sized>(tracer: &T, hit: &Hit, light: Vec3) -> bool {
    let mesh = tracer.mesh();
    let p = hit_point(mesh, hit);
    let dir = light - p;
    let Some(start) = start_beyond(mesh, hit.face, dir) else {
        // No tet on the light's side: the light is beyond the mesh boundary
        // (or exactly in the face's plane).
        return true;
    };
    let ray = Ray {
        origin: p,
        direction: dir,
        t_min: 0.0,
        t_max: 1.0,
    };
    !matches!(tracer.trace(&ray, start), TraceOutcome::Hit(_))
}

/// Mirror reflection of `ray` at `hit`, traced from the reflecting side.
pub fn reflect<T: Tracer + ?Sized>(tracer: &T, ray: &Ray, hit: &Hit) -> Traced {
    let mesh = tracer.mesh();
    let n = face_normal(mesh, hit.face);
    let d = ray.direction;
    let r = d - n * (2.0 * d.dot(n));
    cast(tracer, hit, r)
}

/// Refraction of `ray` at `hit` with relative index `eta = n_incident /
/// n_transmitted` (Snell's law), traced from the transmitting side; `None`
/// on total internal reflection.
pub fn refract<T: Tracer + ?Sized>(tracer: &T, ray: &Ray, hit: &Hit, eta: f32) -> Option<Traced> {
    let mesh = tracer.mesh();
    let mut n = face_normal(mesh, hit.face);
    let d = ray.direction.normalize();
    let mut cos_i = -d.dot(n);
    if cos_i < 0.0 {
        n = -n;
        cos_i = -cos_i;
    }
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    if k < 0.0 {
        return None;
    }
    let t = d * eta + n * (eta * cos_i - k.sqrt());
    Some(cast(tracer, hit, t))
}

fn cast<T: Tracer + ?Sized>(tracer: &T, hit: &Hit, dir: Vec3) -> Traced {
    let mesh = tracer.mesh();
    let ray = Ray::new(hit_point(mesh, hit), dir);
    let outcome = start_beyond(mesh, hit.face, dir).map(|s| tracer.trace(&ray, s));
    Traced { ray, outcome }
}

/// Most tets kept in a light's star (a vertex of a valid mesh has far fewer).
pub const MAX_STAR: usize = 4096;

/// A point light located in the mesh: its position and its star (every tet
/// whose closed cell contains it; empty for a light outside the mesh). See
/// the module docs for the stopping rule.
#[derive(Clone, Debug, PartialEq)]
pub struct LightTarget {
    /// The light's position.
    pub position: Vec3,
    /// Sorted star tets.
    tets: Vec<u32>,
}

impl LightTarget {
    /// Locates `position` by walking from `source` and collects its star.
    /// Errors as [`locate`] does (outside the mesh, non-finite, bad source).
    pub fn locate(mesh: &TetMesh, position: Vec3, source: u32) -> Result<Self, LocateError> {
        let t = locate(mesh, position, source)?;
        let mut tets = star(mesh, position, t, MAX_STAR);
        tets.sort_unstable();
        tets.dedup();
        Ok(LightTarget { position, tets })
    }

    /// A light with no star (outside the mesh): shadow rays end at its
    /// distance.
    pub fn outside(position: Vec3) -> Self {
        LightTarget {
            position,
            tets: Vec::new(),
        }
    }

    /// [`LightTarget::locate`], or [`LightTarget::outside`] when the light
    /// lies outside the mesh (other errors are returned).
    pub fn locate_or_outside(
        mesh: &TetMesh,
        position: Vec3,
        source: u32,
    ) -> Result<Self, LocateError> {
        match Self::locate(mesh, position, source) {
            Err(LocateError::OutsideMesh { .. }) => Ok(Self::outside(position)),
            r => r,
        }
    }

    /// The star tets (sorted; empty for a light outside the mesh).
    pub fn tets(&self) -> &[u32] {
        &self.tets
    }
}

/// The canonical mesh as a [`Topology`] (`tets` + `neighbors`, neighbour `k`
/// opposite vertex `k`): lets any tracer's shadow rays walk without a
/// layout. An out-of-range tet reads as the boundary, never a panic.
#[derive(Clone, Copy, Debug)]
pub struct MeshTopology<'m>(pub &'m TetMesh);

impl Topology for MeshTopology<'_> {
    type Exit = ByLane;
    #[inline(always)]
    fn vx(&self, tet: u32) -> u32 {
        self.0
            .tets
            .get(tet as usize)
            .map_or(0, |v| v[0] ^ v[1] ^ v[2] ^ v[3])
    }
    #[inline(always)]
    fn exit_link(&self, tet: u32, _face: [u32; 3], _d: u32, exiting: u32, _entry: u32) -> u32 {
        let (Some(v), Some(n)) = (
            self.0.tets.get(tet as usize),
            self.0.neighbors.get(tet as usize),
        ) else {
            return Link::BOUNDARY.0;
        };
        let k = if exiting == v[0] {
            0
        } else if exiting == v[1] {
            1
        } else if exiting == v[2] {
            2
        } else {
            3
        };
        n[k].0
    }
}

/// A tracer of shadow rays that can stop when the walk enters given tets.
pub trait ShadowTracer: Sync {
    /// The canonical mesh.
    fn mesh(&self) -> &TetMesh;
    /// Traces `ray` from `start` like [`Tracer::trace`], but reports
    /// [`TraceOutcome::Miss`] as soon as the walk enters a tet of `stop`
    /// (sorted; see [`stops_at`]), including the start tet.
    fn trace_until(&self, ray: &Ray, start: Start, stop: &[u32]) -> TraceOutcome;

    /// Many shadow rays toward one light (a tile's, in [`crate::render`]):
    /// `out[i]` is [`ShadowTracer::trace_until`] of `rays[i]` from
    /// `starts[i]` with `stop`, over the shortest of the three slices. The
    /// default traces them one by one (right for any tracer, e.g. a BVH);
    /// the tet kernels walk them side by side, in SIMD lockstep where the
    /// CPU has it, with the same outcomes bit for bit.
    fn trace_until_batch(
        &self,
        rays: &[Ray],
        starts: &[Start],
        stop: &[u32],
        out: &mut [TraceOutcome],
    ) {
        for ((r, s), o) in rays.iter().zip(starts).zip(out.iter_mut()) {
            *o = self.trace_until(r, *s, stop);
        }
    }
}

/// Any [`Tracer`] as a [`ShadowTracer`], through [`Tracer::trace_until`]
/// and [`Tracer::trace_until_batch`]: the shadow rays of a render walked
/// by its own primary tracer.
#[derive(Clone, Copy)]
pub struct OwnShadows<'a, T: ?Sized>(pub &'a T);

impl<T: Tracer + ?Sized> ShadowTracer for OwnShadows<'_, T> {
    fn mesh(&self) -> &TetMesh {
        self.0.mesh()
    }
    fn trace_until(&self, ray: &Ray, start: Start, stop: &[u32]) -> TraceOutcome {
        self.0.trace_until(ray, start, stop)
    }
    fn trace_until_batch(
        &self,
        rays: &[Ray],
        starts: &[Start],
        stop: &[u32],
        out: &mut [TraceOutcome],
    ) {
        self.0.trace_until_batch(rays, starts, stop, out)
    }
}

/// A [`ShadowTracer`] whose batches are traced one ray at a time (the
/// trait's default [`ShadowTracer::trace_until_batch`] over the wrapped
/// tracer's [`ShadowTracer::trace_until`]): the reference the batched
/// shadow walks are tested and measured against, e.g.
/// `render_scene_with(t, &PerRay(&OwnShadows(t)), ...)`.
#[derive(Clone, Copy)]
pub struct PerRay<'a, S: ?Sized>(pub &'a S);

impl<S: ShadowTracer + ?Sized> ShadowTracer for PerRay<'_, S> {
    fn mesh(&self) -> &TetMesh {
        self.0.mesh()
    }
    fn trace_until(&self, ray: &Ray, start: Start, stop: &[u32]) -> TraceOutcome {
        self.0.trace_until(ray, start, stop)
    }
}

/// Shadow rays walked on the canonical mesh with the f32 2-D projection
/// (the watertight engine of [`crate::walk`]): usable with any primary
/// tracer, including ones that are not tet walks.
#[derive(Clone, Copy, Debug)]
pub struct MeshWalker<'m> {
    mesh: &'m TetMesh,
    cap: u32,
}

impl<'m> MeshWalker<'m> {
    /// A walker over `mesh` (which must be valid) with the default step cap.
    pub fn new(mesh: &'m TetMesh) -> Self {
        MeshWalker {
            mesh,
            cap: step_cap(mesh),
        }
    }
}

impl ShadowTracer for MeshWalker<'_> {
    fn mesh(&self) -> &TetMesh {
        self.mesh
    }
    fn trace_until(&self, ray: &Ray, start: Start, stop: &[u32]) -> TraceOutcome {
        let topo = MeshTopology(self.mesh);
        trace_until::<DuffF32, _>(self.mesh, &topo, ray, start, stop, self.cap)
    }
    /// The scalar interleaved walk, the single-ray walk's step (the SIMD
    /// lanes cannot gather the canonical mesh's records).
    fn trace_until_batch(
        &self,
        rays: &[Ray],
        starts: &[Start],
        stop: &[u32],
        out: &mut [TraceOutcome],
    ) {
        let n = Starts::Each(starts).batch_len(rays.len(), out.len());
        let topo = MeshTopology(self.mesh);
        let batch = Batch {
            mesh: self.mesh,
            topo: &topo,
            rays: &rays[..n],
            starts: Starts::Each(&starts[..n]),
            cap: self.cap,
            out: &mut out[..n],
            bounded: false,
        };
        shadow_batch::interleaved::<DuffF32, _>(batch, stop);
    }
}

/// Every projected-walk kernel walks its shadow rays on its own layout,
/// as [`Tracer::trace_until`] (and its batches as
/// [`Tracer::trace_until_batch`]): where a walk reaches the step cap, the
/// exact walk.
impl<L: Topology, P: BatchWalk> ShadowTracer for WalkTracer<'_, L, P> {
    fn mesh(&self) -> &TetMesh {
        self.mesh
    }
    fn trace_until(&self, ray: &Ray, start: Start, stop: &[u32]) -> TraceOutcome {
        Tracer::trace_until(self, ray, start, stop)
    }
    fn trace_until_batch(
        &self,
        rays: &[Ray],
        starts: &[Start],
        stop: &[u32],
        out: &mut [TraceOutcome],
    ) {
        Tracer::trace_until_batch(self, rays, starts, stop, out)
    }
}

/// The shadow ray from the hit point of `hit` to `light` (`t_max = 1`) and
/// where it starts; `None` when no tet lies on the light's side of the hit
/// face (the light is beyond the mesh boundary or in the face's plane).
pub fn shadow_ray(mesh: &TetMesh, hit: &Hit, light: Vec3) -> Option<(Ray, Start)> {
    let p = hit_point(mesh, hit);
    let dir = light - p;
    let start = start_beyond(mesh, hit.face, dir)?;
    Some((
        Ray {
            origin: p,
            direction: dir,
            t_min: 0.0,
            t_max: 1.0,
        },
        start,
    ))
}

/// Traces the shadow ray from `hit` to `light` with the rule of the module
/// docs: [`TraceOutcome::Miss`] = unoccluded, [`TraceOutcome::Hit`] = the
/// occluder, [`TraceOutcome::Failed`] = the walk failed. `None` when no ray
/// is cast (see [`shadow_ray`]; counts as unoccluded).
pub fn trace_shadow<S: ShadowTracer + ?Sized>(
    shadow: &S,
    hit: &Hit,
    light: &LightTarget,
) -> Option<TraceOutcome> {
    let (ray, start) = shadow_ray(shadow.mesh(), hit, light.position)?;
    Some(shadow.trace_until(&ray, start, &light.tets))
}

/// True when `light` lights the hit point of `hit` under the rule of the
/// module docs (a failed walk counts as lit).
pub fn visible_from<S: ShadowTracer + ?Sized>(shadow: &S, hit: &Hit, light: &LightTarget) -> bool {
    !matches!(trace_shadow(shadow, hit, light), Some(TraceOutcome::Hit(_)))
}
