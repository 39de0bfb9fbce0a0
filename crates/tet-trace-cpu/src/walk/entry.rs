//! The boundary entry of rays from outside the mesh: the boundary faces
//! of a convex mesh ([`BoundaryEntry`]) and the face a ray's line enters
//! through, decided with the walk's own projection. See [`crate::boundary_entry`]
//! for why and how.

use std::collections::HashMap;

use glam::{DVec3, Vec3};
use tet_core::predicates::orient3d_f32;
use tet_core::{Link, NO_TET, TetMesh};
use thiserror::Error;

use super::projection::{DuffF32, Projection, walk_scale};
use super::start::Start;
use super::stop::{Resolved, face_hit, resolve_constrained};
use crate::locate::LocateError;
use crate::ray::{Failure, Ray, TraceOutcome};

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

/// What the previous ray of a batch met, tested first for the next
/// (coherent rays share it): the boundary face it entered through, or
/// whether it missed the mesh's bounds by a clear margin (a millionth of
/// its distance to them).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EntryHint {
    /// Index of the face entered last.
    pub(crate) face: usize,
    /// The previous ray missed the bounds clearly: the next tests the
    /// bounds before setting up its projection.
    pub(crate) outside: bool,
}

/// The boundary faces of a convex mesh, for rays that start outside it.
#[derive(Clone, Debug)]
pub struct BoundaryEntry {
    faces: Vec<EntryFace>,
    /// Per face and edge `e` (`ids[e]` → `ids[e + 1]`), the kept face
    /// across it ([`NO_FACE`] where none is kept): the entry search walks
    /// across the faces instead of testing them one by one.
    across: Vec<[u32; 3]>,
    /// The viewpoint every kept face faces ([`BoundaryEntry::seen_from`]):
    /// rays from it skip the per-face orientation test.
    seen_from: Option<Vec3>,
    /// Bounds of the mesh points (the boundary lies inside them).
    lo: DVec3,
    hi: DVec3,
}

impl BoundaryEntry {
    /// Every boundary face of `mesh`, after checking that the boundary is
    /// convex (exact; see [`crate::boundary_entry`]).
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
        let across = across(&faces);
        check_convex(mesh, &faces, &across)?;
        let (lo, hi) = mesh.point_bounds();
        Ok(BoundaryEntry {
            across,
            faces,
            seen_from: None,
            lo: lo.as_dvec3(),
            hi: hi.as_dvec3(),
        })
    }

    /// The faces whose plane has `origin` on its outer side or on it: the
    /// only faces a ray from `origin` can enter through.
    pub fn seen_from(&self, mesh: &TetMesh, origin: Vec3) -> BoundaryEntry {
        let faces: Vec<EntryFace> = self
            .faces
            .iter()
            .filter(|f| faces_origin(mesh, f, origin))
            .copied()
            .collect();
        BoundaryEntry {
            across: across(&faces),
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
        if !ray.is_valid() || self.misses_first(ray, hint) {
            return Err(miss_outside(ray));
        }
        self.start_projected(mesh, ray, &P::setup_scaled(ray, self.scale(ray)), hint)
    }

    /// For a valid ray, before its projection is set up: true when the
    /// previous ray of the batch missed the mesh's bounds clearly and this
    /// one does too, so that it is a miss that visits no tet; the hint
    /// then keeps testing the bounds first. Rays that stream past the mesh
    /// (the margins of a frame) so skip the projection and the face test.
    #[inline(always)]
    pub(crate) fn misses_first(&self, ray: &Ray, hint: &mut EntryHint) -> bool {
        if !hint.outside {
            return false;
        }
        hint.outside = self.clearly_misses(ray);
        hint.outside
    }

    /// True when the ray misses the mesh's bounds grown by a millionth of
    /// the distance from its origin to their farthest corner (plus a
    /// relative 1e-9 of their size): far more than the
    /// rounding of the f32 face test, so no face can pass it.
    fn clearly_misses(&self, ray: &Ray) -> bool {
        slab_misses(
            ray,
            self.lo,
            self.hi,
            self.farthest(ray) * 1e-6 + self.pad(),
        )
    }

    /// The largest `|corner − origin|∞` over the corners of the bounds.
    fn farthest(&self, ray: &Ray) -> f64 {
        let o = ray.origin.as_dvec3();
        (self.lo - o).abs().max((self.hi - o).abs()).max_element()
    }

    /// The factor of the projection of a ray from outside ([`walk_scale`]):
    /// from the farthest corner of the mesh's bounds seen from its origin.
    pub(crate) fn scale(&self, ray: &Ray) -> f32 {
        walk_scale(self.farthest(ray))
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
        let project = |f: &EntryFace| f.ids.map(|i| proj.project(mesh.points[i as usize]));
        let winds = |f: &EntryFace, p: &[P::P; 3]| {
            proj.left(p[0], f.ids[0], p[1], f.ids[1])
                && proj.left(p[1], f.ids[1], p[2], f.ids[2])
                && proj.left(p[2], f.ids[2], p[0], f.ids[0])
                && (faced || faces_origin(mesh, f, ray.origin))
        };
        let n = self.faces.len();
        let first = hint.face.min(n.saturating_sub(1));
        // The previous ray's face first: coherent rays nearly always share
        // it, and then need no bounds test.
        if n > 0 {
            let p = project(&self.faces[first]);
            if winds(&self.faces[first], &p) {
                return Some(
                    self.nearest_if_flat::<P>(mesh, ray, first, &p, |f| winds(f, &project(f))),
                );
            }
        }
        if self.misses_bounds(ray) {
            hint.outside = true;
            return None;
        }
        // A walk across the faces toward the ray, from the previous face:
        // through the edge the ray's line passes outside of. At most one
        // face winds around the line (see the module docs), so the face the
        // walk finds is the one a search of every face finds; a walk that
        // reaches the edge of the kept faces or goes on too long (it may
        // circle where the faces seen along the ray are not a Delaunay
        // triangulation) leaves the search to the scan of every face.
        let mut at = first;
        for _ in 0..walk_steps(n) {
            let f = &self.faces[at];
            let p = project(f);
            let outside = (0..3).find(|&e| {
                let g = (e + 1) % 3;
                !proj.left(p[e], f.ids[e], p[g], f.ids[g])
            });
            let Some(e) = outside else {
                if winds(f, &p) {
                    hint.face = at;
                    return Some(
                        self.nearest_if_flat::<P>(mesh, ray, at, &p, |f| winds(f, &project(f))),
                    );
                }
                break;
            };
            match self.across[at][e] {
                NO_FACE => break,
                next => at = next as usize,
            }
        }
        let (k, p) = (1..n).map(|i| (first + i) % n).find_map(|k| {
            let p = project(&self.faces[k]);
            winds(&self.faces[k], &p).then_some((k, p))
        })?;
        hint.face = k;
        Some(self.nearest_if_flat::<P>(mesh, ray, k, &p, |f| winds(f, &project(f))))
    }

    /// Face `k` (projected `p`), which the ray's line enters, unless the
    /// ray runs in (or within rounding of) its plane: then the walk's
    /// decisions describe a line through a boundary that rounding made
    /// slightly non-convex (see the walk's module docs, "Why the walk
    /// ends"), the line may enter through several faces, and the one
    /// nearest along the ray (f64 [`face_hit`]; the first in order on a
    /// tie) is the entry, whatever face the search met first (so a batch
    /// and a single ray agree).
    fn nearest_if_flat<P: Projection>(
        &self,
        mesh: &TetMesh,
        ray: &Ray,
        k: usize,
        p: &[P::P; 3],
        enters: impl Fn(&EntryFace) -> bool,
    ) -> EntryFace {
        if !P::flat(p) {
            return self.faces[k];
        }
        let t = |f: &EntryFace| face_hit(mesh, ray, f.ids).0;
        self.faces
            .iter()
            .filter(|f| enters(f))
            .map(|f| (t(f), f))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map_or(self.faces[k], |(_, f)| *f)
    }

    /// True when the ray certainly misses the bounds of the mesh points:
    /// [`BoundaryEntry::clearly_misses`]. The margin (a millionth of the
    /// distance to the farthest corner) exceeds the rounding of the f32
    /// walk's own face test, which may take a ray running along a boundary
    /// plane as entering it; a tighter bound (a relative 1e-9 once) culled
    /// such rays alone but not after a ray that entered the same face,
    /// so a batch and a single ray disagreed.
    fn misses_bounds(&self, ray: &Ray) -> bool {
        self.clearly_misses(ray)
    }

    /// The size-relative part of [`BoundaryEntry::clearly_misses`]' margin.
    fn pad(&self) -> f64 {
        (self.hi - self.lo).max_element() * 1e-9 + 1e-30
    }
}

/// True when the ray certainly misses the box `lo..hi` grown by `pad` on
/// every side ahead of its origin (slab test in f64).
fn slab_misses(ray: &Ray, lo: DVec3, hi: DVec3, pad: f64) -> bool {
    let o = ray.origin.as_dvec3();
    let d = ray.direction.as_dvec3();
    let (lo, hi) = (lo - DVec3::splat(pad), hi + DVec3::splat(pad));
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

/// [`BoundaryEntry::across`] of a face with no kept face across an edge.
const NO_FACE: u32 = u32::MAX;

/// For every face and edge, the face across it (running the edge the
/// other way), or [`NO_FACE`].
fn across(faces: &[EntryFace]) -> Vec<[u32; 3]> {
    let mut by_edge: HashMap<(u32, u32), u32> = HashMap::with_capacity(faces.len() * 3);
    for (i, f) in faces.iter().enumerate() {
        for e in 0..3 {
            by_edge.insert((f.ids[e], f.ids[(e + 1) % 3]), i as u32);
        }
    }
    faces
        .iter()
        .map(|f| {
            std::array::from_fn(|e| {
                let (a, b) = (f.ids[e], f.ids[(e + 1) % 3]);
                by_edge.get(&(b, a)).copied().unwrap_or(NO_FACE)
            })
        })
        .collect()
}

/// Steps the entry walk takes over `n` faces before it leaves the search
/// to the scan: a walk across the faces seen from a viewpoint crosses
/// about their square root.
fn walk_steps(n: usize) -> usize {
    4 * (n as f64).sqrt() as usize + 16
}

/// True when `origin` lies on the outer side of face `f`'s plane or on it.
fn faces_origin(mesh: &TetMesh, f: &EntryFace, origin: Vec3) -> bool {
    let [a, b, c] = mesh.face_vertices(f.tet, f.face as usize);
    let p = |i: u32| mesh.points[i as usize];
    orient3d_f32(p(a), p(b), p(c), origin) >= 0.0
}

/// Checks that every two boundary faces sharing an edge bend outward or are
/// coplanar: the far vertex of each lies on or inside the other's plane
/// (`across`: the faces' [`across`] table).
fn check_convex(
    mesh: &TetMesh,
    faces: &[EntryFace],
    across: &[[u32; 3]],
) -> Result<(), ViewpointError> {
    let p = |i: u32| mesh.points[i as usize];
    for (f, across) in faces.iter().zip(across) {
        let [a, b, c] = mesh.face_vertices(f.tet, f.face as usize);
        for (e, &g) in across.iter().enumerate() {
            let (x, y) = (f.ids[e], f.ids[(e + 1) % 3]);
            // The neighbour across the edge runs it the other way.
            if g == NO_FACE {
                return Err(ViewpointError::NotConvex {
                    tet: f.tet,
                    face: f.face,
                });
            }
            let far = faces[g as usize]
                .ids
                .into_iter()
                .find(|&v| v != x && v != y);
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

/// The outcome of a ray that never enters the mesh: a miss, or the walk's
/// failure for an invalid ray.
fn miss_outside(ray: &Ray) -> TraceOutcome {
    if ray.is_valid() {
        TraceOutcome::Miss { tets_visited: 0 }
    } else {
        TraceOutcome::Failed {
            failure: Failure::InvalidRay,
            tets_visited: 0,
        }
    }
}
