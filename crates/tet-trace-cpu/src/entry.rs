//! Rays from a viewpoint outside the mesh enter it through its boundary.
//!
//! The papers' meshes hold the camera: the walk of every primary ray starts
//! in the tet around it (seed 000 §4.2). When the enclosing box must hold the
//! camera, every primary ray first crosses the empty space between the
//! camera and the scene, tet by tet: on Torus Knots (camera 20 units from
//! the centre of a 14-unit grid of knots) that is 23 of the 59.5 tets a ray
//! visits, and the 22 % of rays that miss the scene's bounds entirely walk
//! 51 tets each to reach the box. A BVH rejects those rays with one box test.
//!
//! Here the mesh may stop just outside the scene (a tight enclosing box), and
//! a ray whose origin lies outside finds the boundary face its line enters
//! through ([`BoundaryEntry::start`], then [`Start::Entry`]): nothing lies
//! outside the mesh, so the walk from that face is the walk from the
//! origin. A ray whose line misses the mesh is a miss that visits no tet.
//!
//! # Exactness
//!
//! The entering face is chosen with the walk's own edge test: the kernel's
//! projection (the ray's [`DuffF32`] projection for the f32 kernels) and
//! the tie rule of [`crate::walk`], on the same vertex pairs that the walk
//! tests ([`crate::Tracer::start_outside`]). A boundary face is entered when its
//! inward-ordered projection winds counter-clockwise around the ray; every
//! boundary edge gets one answer whichever face asks, so the symbolically
//! perturbed line enters a closed convex boundary through exactly one face
//! or through none. The face must also be ahead of the origin: the origin
//! lies on or outside its plane (exact `orient3d`). [`BoundaryEntry::new`]
//! checks that the boundary is convex (every pair of boundary faces sharing
//! an edge bends outward or is flat, exact); a walk that reaches the boundary
//! reports a miss, which is right only for a convex mesh (a ray could
//! otherwise leave and re-enter it). TetGen meshes the convex hull of its
//! input (`-c`), with or without an enclosing box, so built meshes qualify.
//!
//! # Cost
//!
//! [`BoundaryEntry::seen_from`] keeps the faces whose outer side holds the
//! viewpoint (at most three sides of a box: 6 triangles); per ray, the face
//! that the previous ray of the batch entered through is tested first
//! (neighbouring pixels nearly always share it); when that fails, a slab
//! test against the mesh bounds rejects most misses before the other faces
//! are tested.

use std::collections::HashMap;

use glam::{DVec3, Vec3};
use tet_core::predicates::orient3d_f32;
use tet_core::{Link, NO_TET, TetMesh};
use thiserror::Error;

use crate::kernel::Tracer;
use crate::locate::{LocateError, locate};
use crate::ray::{Ray, TraceOutcome};
use crate::walk::{DuffF32, Projection, Resolved, Start, Starts, resolve_constrained};

/// Why rays could not be started from a viewpoint.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ViewpointError {
    /// Locating the viewpoint failed for a reason other than lying outside
    /// the mesh.
    #[error(transparent)]
    Locate(#[from] LocateError),
    /// The viewpoint lies outside the mesh and the mesh boundary is not
    /// convex, so a ray could leave and re-enter it.
    #[error(
        "the viewpoint lies outside the mesh, whose boundary is not convex at face {face} of tet {tet} (rays from outside need a convex boundary: build with an enclosing box)"
    )]
    NotConvex {
        /// A tet with a boundary face where the boundary bends inward.
        tet: u32,
        /// That face (0..=3).
        face: u8,
    },
    /// The viewpoint lies outside a mesh that has no boundary face.
    #[error("the viewpoint lies outside the mesh, which has no boundary face")]
    NoBoundary,
}

/// One boundary face: the tet behind it, which face, its vertex ids in
/// inward order (counter-clockwise, seen by a ray entering through it) and
/// its link ([`Link::BOUNDARY`], or a constrained face with no tet outside).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct EntryFace {
    tet: u32,
    face: u8,
    ids: [u32; 3],
    link: Link,
}

/// The boundary face a previous ray entered through (coherent rays share
/// it, so it is tested first).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EntryHint(pub(crate) usize);

/// The boundary faces of a convex mesh, for rays that start outside it.
#[derive(Clone, Debug)]
pub struct BoundaryEntry {
    faces: Vec<EntryFace>,
    /// The viewpoint every kept face faces ([`BoundaryEntry::seen_from`]):
    /// rays from it skip the per-face orientation test.
    seen_from: Option<Vec3>,
    /// Bounds of the mesh points (the boundary lies inside them).
    lo: DVec3,
    hi: DVec3,
}

impl BoundaryEntry {
    /// Every boundary face of `mesh`, after checking that the boundary is
    /// convex (exact; see the module docs).
    pub fn new(mesh: &TetMesh) -> Result<BoundaryEntry, ViewpointError> {
        let mut faces = Vec::new();
        for (t, links) in mesh.neighbors.iter().enumerate() {
            for (k, &link) in links.iter().enumerate() {
                let outside = match link.as_constrained() {
                    Some(c) => mesh
                        .constrained
                        .get(c as usize)
                        .and_then(|cf| cf.other_side(t as u32))
                        .is_some_and(|s| !s.exists()),
                    None => link == Link::BOUNDARY,
                };
                if outside {
                    let [a, b, c] = mesh.face_vertices(t as u32, k);
                    faces.push(EntryFace {
                        tet: t as u32,
                        face: k as u8,
                        ids: [a, c, b],
                        link,
                    });
                }
            }
        }
        if faces.is_empty() {
            return Err(ViewpointError::NoBoundary);
        }
        check_convex(mesh, &faces)?;
        let (lo, hi) = mesh.point_bounds();
        Ok(BoundaryEntry {
            faces,
            seen_from: None,
            lo: lo.as_dvec3(),
            hi: hi.as_dvec3(),
        })
    }

    /// The faces whose plane has `origin` on its outer side or on it: the
    /// only faces a ray from `origin` can enter through.
    pub fn seen_from(&self, mesh: &TetMesh, origin: Vec3) -> BoundaryEntry {
        let faces = self
            .faces
            .iter()
            .filter(|f| faces_origin(mesh, f, origin))
            .copied()
            .collect();
        BoundaryEntry {
            faces,
            seen_from: Some(origin),
            lo: self.lo,
            hi: self.hi,
        }
    }

    /// Number of boundary faces kept.
    pub fn len(&self) -> usize {
        self.faces.len()
    }

    /// True when no face is kept (a viewpoint that sees no face: inside).
    pub fn is_empty(&self) -> bool {
        self.faces.is_empty()
    }

    /// How `ray` (origin outside the mesh) begins, for a kernel that walks
    /// with the [`DuffF32`] projection (see [`BoundaryEntry::start_with`]).
    pub fn start(&self, mesh: &TetMesh, ray: &Ray) -> Result<Start, TraceOutcome> {
        self.start_with::<DuffF32>(mesh, ray, &mut EntryHint::default())
    }

    /// How `ray` (origin outside the mesh) begins: `Ok` with the start of
    /// its walk where it enters the mesh ([`Start::Entry`], or
    /// [`Start::Face`] past a constrained boundary face before `t_min`);
    /// `Err` with its outcome when it ends before any walk: a miss when its
    /// line never enters the mesh ahead of the origin, a hit on a
    /// constrained face that lies on the boundary itself.
    ///
    /// The entering face is decided with projection `P`, which must be the
    /// one the kernel walks with ([`crate::Tracer::start_outside`]), so that
    /// the entry and the walk agree on every boundary edge. `hint` holds
    /// the face found last: the next ray tests it first.
    pub fn start_with<P: Projection>(
        &self,
        mesh: &TetMesh,
        ray: &Ray,
        hint: &mut EntryHint,
    ) -> Result<Start, TraceOutcome> {
        if !ray.is_valid() {
            return Err(miss_outside(ray));
        }
        self.start_projected(mesh, ray, &P::setup(ray), hint)
    }

    /// [`BoundaryEntry::start_with`] for a valid ray whose projection is set
    /// up (the walk's own, reused).
    pub(crate) fn start_projected<P: Projection>(
        &self,
        mesh: &TetMesh,
        ray: &Ray,
        proj: &P,
        hint: &mut EntryHint,
    ) -> Result<Start, TraceOutcome> {
        let f = self
            .entered(mesh, ray, proj, hint)
            .ok_or_else(|| miss_outside(ray))?;
        let Some(c) = f.link.as_constrained() else {
            return Ok(Start::Entry {
                tet: f.tet,
                face: f.face,
            });
        };
        match resolve_constrained(mesh, ray, c, f.ids, NO_TET, 0) {
            Resolved::Done(out) => Err(out),
            Resolved::Cross(tet) => Ok(Start::Face { face: c, tet }),
        }
    }

    /// The face the ray's line enters through ahead of its origin.
    fn entered<P: Projection>(
        &self,
        mesh: &TetMesh,
        ray: &Ray,
        proj: &P,
        hint: &mut EntryHint,
    ) -> Option<EntryFace> {
        let faced = self.seen_from == Some(ray.origin);
        let enters = |f: &EntryFace| {
            let p = f.ids.map(|i| proj.project(mesh.points[i as usize]));
            proj.left(p[0], f.ids[0], p[1], f.ids[1])
                && proj.left(p[1], f.ids[1], p[2], f.ids[2])
                && proj.left(p[2], f.ids[2], p[0], f.ids[0])
                && (faced || faces_origin(mesh, f, ray.origin))
        };
        let n = self.faces.len();
        let first = hint.0.min(n.saturating_sub(1));
        // The previous ray's face first: coherent rays nearly always share
        // it, and then need no bounds test.
        if n > 0 && enters(&self.faces[first]) {
            return Some(self.faces[first]);
        }
        if self.misses_bounds(ray) {
            return None;
        }
        let k = (1..n)
            .map(|i| (first + i) % n)
            .find(|&k| enters(&self.faces[k]))?;
        hint.0 = k;
        Some(self.faces[k])
    }

    /// True when the ray certainly misses the bounds of the mesh points
    /// (slab test in f64 on bounds grown by a relative 1e-9, far more than
    /// the rounding of the test).
    fn misses_bounds(&self, ray: &Ray) -> bool {
        let o = ray.origin.as_dvec3();
        let d = ray.direction.as_dvec3();
        let pad = (self.hi - self.lo).max_element() * 1e-9 + 1e-30;
        let (lo, hi) = (self.lo - DVec3::splat(pad), self.hi + DVec3::splat(pad));
        let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
        for a in 0..3 {
            if d[a] == 0.0 {
                if o[a] < lo[a] || o[a] > hi[a] {
                    return true;
                }
                continue;
            }
            let inv = 1.0 / d[a];
            let (u, v) = ((lo[a] - o[a]) * inv, (hi[a] - o[a]) * inv);
            t0 = t0.max(u.min(v));
            t1 = t1.min(u.max(v));
        }
        t0 > t1 * (1.0 + 1e-12)
    }
}

/// True when `origin` lies on the outer side of face `f`'s plane or on it.
fn faces_origin(mesh: &TetMesh, f: &EntryFace, origin: Vec3) -> bool {
    let [a, b, c] = mesh.face_vertices(f.tet, f.face as usize);
    let p = |i: u32| mesh.points[i as usize];
    orient3d_f32(p(a), p(b), p(c), origin) >= 0.0
}

/// Checks that every two boundary faces sharing an edge bend outward or are
/// coplanar: the far vertex of each lies on or inside the other's plane.
fn check_convex(mesh: &TetMesh, faces: &[EntryFace]) -> Result<(), ViewpointError> {
    let mut by_edge: HashMap<(u32, u32), usize> = HashMap::with_capacity(faces.len() * 3);
    for (i, f) in faces.iter().enumerate() {
        for e in 0..3 {
            let (a, b) = (f.ids[e], f.ids[(e + 1) % 3]);
            by_edge.insert((a, b), i);
        }
    }
    let p = |i: u32| mesh.points[i as usize];
    for f in faces {
        let [a, b, c] = mesh.face_vertices(f.tet, f.face as usize);
        for e in 0..3 {
            let (x, y) = (f.ids[e], f.ids[(e + 1) % 3]);
            // The neighbour across the edge runs it the other way.
            let Some(&g) = by_edge.get(&(y, x)) else {
                return Err(ViewpointError::NotConvex {
                    tet: f.tet,
                    face: f.face,
                });
            };
            let far = faces[g].ids.into_iter().find(|&v| v != x && v != y);
            let bends_in = far.is_some_and(|v| orient3d_f32(p(a), p(b), p(c), p(v)) > 0.0);
            if bends_in {
                return Err(ViewpointError::NotConvex {
                    tet: f.tet,
                    face: f.face,
                });
            }
        }
    }
    Ok(())
}

/// Where the rays from one viewpoint (a camera) start: in the tet around
/// it, or, from outside the mesh, through the boundary face each enters by.
#[derive(Clone, Debug)]
pub enum Viewpoint {
    /// The viewpoint lies in this tet (closed).
    Inside(u32),
    /// The viewpoint lies outside the mesh; the faces it sees.
    Outside(BoundaryEntry),
}

impl Viewpoint {
    /// Locates `position` in `mesh` ([`locate`], walking from tet 0); when
    /// it lies outside, collects the boundary faces it sees.
    pub fn locate(mesh: &TetMesh, position: Vec3) -> Result<Viewpoint, ViewpointError> {
        match locate(mesh, position, 0) {
            Ok(t) => Ok(Viewpoint::Inside(t)),
            Err(LocateError::OutsideMesh { .. }) => Ok(Viewpoint::Outside(
                BoundaryEntry::new(mesh)?.seen_from(mesh, position),
            )),
            Err(e) => Err(e.into()),
        }
    }

    /// The start of `ray` (whose origin is the viewpoint) for `tracer`, or
    /// its outcome when it ends before any walk (see
    /// [`BoundaryEntry::start_with`]).
    pub fn start<T: Tracer + ?Sized>(&self, tracer: &T, ray: &Ray) -> Result<Start, TraceOutcome> {
        match self {
            Viewpoint::Inside(t) => Ok(Start::Tet(*t)),
            Viewpoint::Outside(entry) => {
                tracer.start_outside(entry, ray, &mut EntryHint::default())
            }
        }
    }

    /// Traces `rays` (all from the viewpoint) into `out` (same length) with
    /// `tracer`'s batch path; rays that miss the mesh are
    /// [`TraceOutcome::Miss`] with no tet visited.
    pub fn trace_batch<T: Tracer + ?Sized>(
        &self,
        tracer: &T,
        rays: &[Ray],
        out: &mut [TraceOutcome],
    ) {
        match self {
            Viewpoint::Inside(t) => tracer.trace_batch(rays, Start::Tet(*t), out),
            Viewpoint::Outside(entry) => tracer.trace_batch_from(rays, Starts::Outside(entry), out),
        }
    }
}

/// The outcome of a ray that never enters the mesh: a miss, or the walk's
/// failure for an invalid ray.
pub(crate) fn miss_outside(ray: &Ray) -> TraceOutcome {
    if ray.is_valid() {
        TraceOutcome::Miss { tets_visited: 0 }
    } else {
        TraceOutcome::Failed {
            failure: crate::ray::Failure::InvalidRay,
            tets_visited: 0,
        }
    }
}
