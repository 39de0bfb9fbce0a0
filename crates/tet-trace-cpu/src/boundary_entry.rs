//! Rays from a viewpoint outside the mesh enter it through its boundary.
//!
//! The papers' meshes hold the camera: the walk of every primary ray starts
//! in the tet around it (Aman et al. 2022, §4.2). When the enclosing box must hold the
//! camera, every primary ray first crosses the empty space between the
//! camera and the scene, tet by tet: with a camera well outside the scene
//! that is a large share of the tets a ray visits, and the rays that miss
//! the scene's bounds entirely walk all the way to the box. A BVH rejects
//! those rays with one box test.
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
//! projection (the ray's [`DuffF32`](crate::DuffF32) projection for the f32 kernels) and
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
//! are tested. A ray that misses the bounds by a clear margin (a millionth
//! of its distance to them, far above the rounding of the face test) makes
//! the next ray test the bounds first, before its projection is set up:
//! the rays that stream past the mesh in the margins of a frame then cost a
//! slab test each (the Armadillo seen from 2 000 units, 1920×1440, one
//! thread: 48 → 28 ns per ray, obvhs 24 ns), and a ray that does not
//! clearly miss takes the path above, so every outcome is the same as
//! without it.

use glam::Vec3;
use tet_core::TetMesh;

use crate::locate::{LocateError, locate};
use crate::ray::{Ray, TraceOutcome};
use crate::tracer::Tracer;
pub use crate::walk::{BoundaryEntry, EntryHint, ViewpointError};
use crate::walk::{Start, Starts};

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
