//! Start-up of a walk: where it starts ([`Start`]), the start tet's exit
//! face (the counter-clockwise face around the origin, with its fallbacks),
//! or the entry face when the walk enters a tet through a constrained face
//! or the mesh boundary; everything before the hot loop.

use glam::Vec3;
use tet_core::predicates::orient3d;
use tet_core::{FACE_VERTICES, Link, NO_TET, TetMesh};

use super::projection::{Projection, walk_scale};
use super::reach::Reach;
use super::stop::{Resolved, resolve_constrained};
use crate::locate::star;
use crate::ray::{Failure, Ray, TraceOutcome};

/// Where a walk starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Start {
    /// In a tet containing the ray origin (closed: the origin may be on its
    /// boundary); see [`crate::locate::locate`].
    Tet(u32),
    /// Just past constrained face `face`, inside tet `tet` (one of its two
    /// sides); the origin lies on the face. Used by secondary rays: the face
    /// itself is never reported again.
    Face {
        /// Index into [`TetMesh::constrained`].
        face: u32,
        /// The side to walk into.
        tet: u32,
    },
    /// Entering `tet` through its face `face` (0..=3, opposite vertex slot
    /// `face`), ahead of the origin, as the walk would have entered it. A
    /// boundary face ([`Link::BOUNDARY`]): the ray comes from outside the
    /// mesh, where nothing lies, so the walk starts there; see
    /// [`crate::boundary_entry`], which finds it (and resolves a constrained face on
    /// the boundary itself). An inner face: the caller knows the walk finds
    /// nothing before it and that the ray's line enters `tet` through it
    /// (the iso walk's regions, [`crate::iso::regions`]); the walk then
    /// goes on exactly as the whole walk would from there.
    Entry {
        /// The tet entered.
        tet: u32,
        /// Its face on the mesh boundary (0..=3).
        face: u8,
    },
}

impl Start {
    /// The constrained face the ray starts on ([`Start::Face`]), which a
    /// tracer without tets must skip.
    pub fn on_face(&self) -> Option<u32> {
        match *self {
            Start::Face { face, .. } => Some(face),
            Start::Tet(_) | Start::Entry { .. } => None,
        }
    }
}

/// The walk state just after choosing an exit face.
pub(crate) struct State<P: Projection> {
    pub(crate) tet: u32,
    pub(crate) ids: [u32; 3],
    pub(crate) p: P::Face,
    pub(crate) link: u32,
    pub(crate) visited: u32,
}

/// Exit face of a tet containing the origin: the outward face whose
/// projection winds counter-clockwise around the origin.
fn start_in_tet<P: Projection>(mesh: &TetMesh, proj: &P, tet: u32) -> Option<State<P>> {
    let v = mesh.tets[tet as usize];
    let p = v.map(|i| proj.project(mesh.points[i as usize]));
    FACE_VERTICES
        .iter()
        .position(|&[a, b, c]| {
            proj.left(p[a], v[a], p[b], v[b])
                && proj.left(p[b], v[b], p[c], v[c])
                && proj.left(p[c], v[c], p[a], v[a])
        })
        .map(|k| {
            let [a, b, c] = FACE_VERTICES[k];
            exit_state_of(mesh, tet, k, [v[a], v[b], v[c]], [p[a], p[b], p[c]])
        })
}

/// The walk state after choosing face `k` of `tet` as the exit.
fn exit_state<P: Projection>(mesh: &TetMesh, proj: &P, tet: u32, k: usize) -> State<P> {
    let v = mesh.tets[tet as usize];
    let [a, b, c] = FACE_VERTICES[k];
    let ids = [v[a], v[b], v[c]];
    let p = ids.map(|i| proj.project(mesh.points[i as usize]));
    exit_state_of(mesh, tet, k, ids, p)
}

/// [`exit_state`] from the face's vertex ids and their projections.
fn exit_state_of<P: Projection>(
    mesh: &TetMesh,
    tet: u32,
    k: usize,
    ids: [u32; 3],
    p: [P::P; 3],
) -> State<P> {
    State {
        tet,
        ids,
        p: P::face(p),
        link: mesh.neighbors[tet as usize][k].0,
        visited: 1,
    }
}

/// Tets around an origin searched first; where that finds nothing the
/// whole star is searched (a corner of the enclosing box can touch
/// thousands of tets), up to [`STAR_LIMIT`].
const STAR_FIRST: usize = 256;

/// The most tets of a star searched (a guard, far above real stars).
const STAR_LIMIT: usize = 1 << 20;

/// The start state from the tets around an origin on a face, edge or
/// vertex of `tet`: a tet whose exit face winds counter-clockwise around
/// the origin ([`start_in_tet`]), else a boundary face through the origin
/// ([`boundary_face_at`]); `None` when neither exists (rounding), where the
/// caller falls back.
fn search_star<P: Projection>(mesh: &TetMesh, proj: &P, ray: &Ray, tet: u32) -> Option<State<P>> {
    let (origin, direction) = (ray.origin, ray.direction);
    let mut searched = 1;
    for limit in [STAR_FIRST, STAR_LIMIT] {
        let around = star(mesh, origin, tet, limit);
        let found = around[searched.min(around.len())..]
            .iter()
            .find_map(|&c| start_in_tet(mesh, proj, c));
        if found.is_some() {
            return found;
        }
        // A boundary face only once the whole star is known to hold no
        // tet the line passes through.
        if around.len() < limit || limit == STAR_LIMIT {
            return boundary_face_at(mesh, origin, direction, &around)
                .map(|(c, k)| exit_state(mesh, proj, c, k));
        }
        searched = around.len();
    }
    None
}

/// A face on the mesh boundary (no tet behind it, constrained or not) that
/// contains `p` (exact) and that direction `d` does not point into the
/// mesh from (f64), among the faces of the tets `around` (each containing
/// `p`): `(tet, face)`.
///
/// Where no tet around the origin has a counter-clockwise exit face, the
/// ray's (perturbed) line passes through none of them. Inside the mesh that
/// can only be rounding, and the fallback guesses the exit; on the boundary
/// it is the ray leaving the mesh at once (a ray from a hull vertex or edge
/// pointing outward), so the walk leaves through this face: a miss, or the
/// constrained face the origin lies on at `t = 0`. Guessing an exit there
/// instead sent the walk round an edge until the step cap. A ray from the
/// boundary pointing into the mesh is not leaving, though: rounding moved
/// its line off the tets around the origin, and the tets near them
/// ([`next_to_star`]) hold it (taking the boundary face there missed a
/// hit inside).
fn boundary_face_at(mesh: &TetMesh, p: Vec3, d: Vec3, around: &[u32]) -> Option<(u32, usize)> {
    let (q, d) = (p.as_dvec3(), d.as_dvec3());
    around.iter().find_map(|&t| {
        let v = mesh.tet_points(t).map(|x| x.as_dvec3());
        (0..4)
            .find(|&k| {
                let [a, b, c] = FACE_VERTICES[k];
                mesh.across(t, k).is_none()
                    && orient3d(v[a], v[b], v[c], q) == 0.0
                    && outward_normal(&v, k).dot(d) >= 0.0
            })
            .map(|k| (t, k))
    })
}

/// When rounding left no tet around the origin with a counter-clockwise
/// exit face: a tet near them ([`next_to_star`]), else, as a last
/// resort, the face of `tet` whose smallest f64 edge function
/// `d · (qa × qb)` is largest (the face the line leaves through, up to
/// rounding). The CPU walks report `Lost` instead of guessing (their
/// tracers then take the exact walk); this is for the GPU kernels' start,
/// which has no exact walk to fall back on.
fn start_fallback<P: Projection>(mesh: &TetMesh, proj: &P, ray: &Ray, tet: u32) -> State<P> {
    next_to_star(mesh, proj, ray, tet).unwrap_or_else(|| best_exit_guess(mesh, proj, ray, tet))
}

/// The walk's decisions are those of a line through the mesh with each
/// vertex moved by its projection's rounding (see the module docs, "Why
/// the walk ends"), and that moved mesh can leave the origin just outside
/// the tets around it (an origin on or within rounding of a face or edge,
/// the ray running in a face's plane): the moved line then starts in a tet
/// near them, across a constrained face or not. Of the tets within
/// [`NEAR_LAYERS`] faces of the origin's star that have a
/// counter-clockwise exit face (the moved line passes through them, so a
/// walk from one is a line's walk) and that the origin lies outside of by
/// no more than rounding can move it ([`NEAR`] of its distance to the
/// start tet's vertices; [`outside_by`]), the one it lies nearest
/// outside of. (The nearest centroid along the ray, the earlier rule,
/// could pick the tet across the constrained face the ray was about to
/// hit, and so skip it; face neighbours alone missed a line moved across
/// an edge the origin lies near.) Ties, as between tets around an edge or
/// vertex the origin lies on, go to the centroid nearest the origin along
/// the ray. `None` when no tet is that near.
fn next_to_star<P: Projection>(mesh: &TetMesh, proj: &P, ray: &Ray, tet: u32) -> Option<State<P>> {
    let mut seen = star(mesh, ray.origin, tet, STAR_FIRST);
    let (o, d) = (ray.origin.as_dvec3(), ray.direction.as_dvec3());
    let reach = mesh
        .tet_points(tet)
        .iter()
        .map(|p| (p.as_dvec3() - o).length())
        .fold(0.0, f64::max)
        * NEAR;
    let along = |t: u32| {
        let c = mesh.tet_points(t).map(|x| x.as_dvec3());
        ((c[0] + c[1] + c[2] + c[3]) * 0.25 - o).dot(d).abs()
    };
    let mut layer = seen.clone();
    let mut best: Option<((f64, f64), State<P>)> = None;
    for _ in 0..NEAR_LAYERS {
        let mut next = Vec::new();
        for n in layer
            .iter()
            .flat_map(|&t| (0..4).filter_map(move |k| mesh.across(t, k)))
        {
            if seen.contains(&n.tet) || next.contains(&n.tet) {
                continue;
            }
            next.push(n.tet);
            let outside = outside_by(mesh, n.tet, o);
            if outside > reach {
                continue;
            }
            if let Some(s) = start_in_tet(mesh, proj, n.tet) {
                let key = (outside, along(n.tet));
                let better = |b: &(f64, f64)| key.0.total_cmp(&b.0).then(key.1.total_cmp(&b.1));
                if best.as_ref().is_none_or(|(b, _)| better(b).is_lt()) {
                    best = Some((key, s));
                }
            }
        }
        seen.extend_from_slice(&next);
        layer = next;
    }
    best.map(|(_, s)| s)
}

/// How far outside a tet, relative to its distance from the start tet's
/// vertices, rounding can move a ray origin ([`next_to_star`]): a few
/// hundred f32 ulps, far above the few ulps the projection rounds by and
/// far below any tet a line's walk would not pass near the origin.
const NEAR: f64 = 1e-5;

/// Face layers around the origin's star that [`next_to_star`] searches
/// (its face neighbours, theirs, and theirs: enough for a line moved
/// across an edge or vertex the origin lies near).
const NEAR_LAYERS: usize = 3;

/// The normal of face `k` of the tet with vertices `v` (not normalised),
/// pointing away from the vertex opposite the face: out of the tet.
fn outward_normal(v: &[glam::DVec3; 4], k: usize) -> glam::DVec3 {
    let [a, b, c] = FACE_VERTICES[k].map(|s| v[s]);
    let n = (b - a).cross(c - a);
    if n.dot(v[k] - a) > 0.0 { -n } else { n }
}

/// How far `p` lies outside `tet`: the largest distance to the plane of a
/// face it lies beyond (0 inside), in f64.
fn outside_by(mesh: &TetMesh, tet: u32, p: glam::DVec3) -> f64 {
    let v = mesh.tet_points(tet).map(|x| x.as_dvec3());
    (0..4)
        .map(|k| {
            let n = outward_normal(&v, k);
            let len = n.length();
            if len > 0.0 {
                n.dot(p - v[FACE_VERTICES[k][0]]) / len
            } else {
                0.0
            }
        })
        .fold(0.0, f64::max)
}

/// The face of `tet` whose smallest f64 edge function `d · (qa × qb)` is
/// largest (the face the line leaves through, up to rounding).
fn best_exit_guess<P: Projection>(mesh: &TetMesh, proj: &P, ray: &Ray, tet: u32) -> State<P> {
    let v = mesh.tets[tet as usize];
    let o = ray.origin.as_dvec3();
    let d = ray.direction.as_dvec3();
    let q = v.map(|i| mesh.points[i as usize].as_dvec3() - o);
    let score = |k: usize| {
        let [a, b, c] = FACE_VERTICES[k];
        let e = |x: usize, y: usize| d.dot(q[x].cross(q[y]));
        e(a, b).min(e(b, c)).min(e(c, a))
    };
    let k = (0..4)
        .max_by(|&x, &y| score(x).total_cmp(&score(y)))
        .unwrap_or(0);
    exit_state(mesh, proj, tet, k)
}

/// The tet around the ray origin and the face through which the ray line
/// leaves it (the `start_in_tet` search of [`trace`](crate::walk::trace), with its fallback to the
/// other tets around an origin on a face, edge or vertex).
pub fn start_exit_face<P: Projection>(mesh: &TetMesh, ray: &Ray, tet: u32) -> Option<(u32, usize)> {
    let proj = P::setup_scaled(ray, tet_scale(mesh, ray, tet));
    let s = start_in_tet(mesh, &proj, tet)
        .or_else(|| search_star(mesh, &proj, ray, tet))
        .unwrap_or_else(|| start_fallback(mesh, &proj, ray, tet));
    let f = (0..4).find(|&k| {
        mesh.neighbors[s.tet as usize][k].0 == s.link && {
            let f = mesh.face_vertices(s.tet, k);
            s.ids.iter().all(|i| f.contains(i))
        }
    })?;
    Some((s.tet, f))
}

/// One ray in flight: its projection, walk state, the tet it enters next
/// and the raw link it enters through.
pub(crate) struct Lane<P: Projection> {
    pub(crate) proj: P,
    pub(crate) st: State<P>,
    pub(crate) next: u32,
    pub(crate) entry_raw: u32,
    /// A bounded walk's plane past `t_max` ([`Lane::bounded`]), `None`
    /// for the plain walk.
    pub(crate) reach: Option<Reach>,
    /// Bit `k`: vertex `st.ids[k]` lies past the plane of `reach`.
    pub(crate) beyond: u8,
}

impl<P: Projection> Lane<P> {
    /// This lane as a bounded walk of `ray` ([`super::reach`]), which
    /// ends as a miss once its exit face lies wholly past `t_max`: `Err`
    /// (that miss) when its current face does already. A ray without a
    /// usable bound ([`Reach::of`]) walks as before.
    #[inline(always)]
    pub(crate) fn bounded(mut self, mesh: &TetMesh, ray: &Ray) -> Result<Self, TraceOutcome> {
        if let Some(r) = Reach::of(ray) {
            let at = |i: u32| mesh.points.get(i as usize).copied().unwrap_or(Vec3::NAN);
            self.beyond = r.beyond_mask(self.st.ids.map(at));
            self.reach = Some(r);
            if self.beyond == 7 {
                return Err(TraceOutcome::Miss {
                    tets_visited: self.st.visited,
                });
            }
        }
        Ok(self)
    }
}

/// Everything before the hot loop: ray checks, projection set-up, the start
/// tet's exit face (or the restart on a constrained face) and its link.
/// `Err` when the walk already ended (invalid ray, hit or miss in the start
/// tet).
pub(crate) fn begin<P: Projection>(
    mesh: &TetMesh,
    ray: &Ray,
    start: Start,
) -> Result<Lane<P>, TraceOutcome> {
    begin_scaled(mesh, ray, start, start_scale(mesh, ray, start))
}

/// [`begin`] with the projection's scale for `ray` and `start` known
/// ([`start_scale`]; rays from one origin share it).
#[inline(always)]
pub(crate) fn begin_scaled<P: Projection>(
    mesh: &TetMesh,
    ray: &Ray,
    start: Start,
    scale: f32,
) -> Result<Lane<P>, TraceOutcome> {
    if !ray.is_valid() {
        return Err(TraceOutcome::Failed {
            failure: Failure::InvalidRay,
            tets_visited: 0,
        });
    }
    begin_with(mesh, ray, P::setup_scaled(ray, scale), start)
}

/// The factor of a walk's projection ([`walk_scale`]) for `ray` starting
/// at `start`: from the start tet's vertices relative to the origin (1 for
/// a start out of range, which the walk then reports). The GPU kernels
/// scale their basis by the same factor.
pub fn start_scale(mesh: &TetMesh, ray: &Ray, start: Start) -> f32 {
    let tet = match start {
        Start::Tet(t) => t,
        Start::Face { tet, .. } | Start::Entry { tet, .. } => tet,
    };
    tet_scale(mesh, ray, tet)
}

/// [`walk_scale`] of the largest `|P − o|∞` over the vertices of `tet`.
fn tet_scale(mesh: &TetMesh, ray: &Ray, tet: u32) -> f32 {
    let Some(v) = mesh.tets.get(tet as usize) else {
        return 1.0;
    };
    let o = ray.origin.as_dvec3();
    let m = v
        .iter()
        .filter_map(|&i| mesh.points.get(i as usize))
        .map(|p| (p.as_dvec3() - o).abs().max_element())
        .fold(0.0f64, f64::max);
    walk_scale(m)
}

/// [`begin`] of a valid ray whose projection `proj` is set up.
#[inline(always)]
pub(crate) fn begin_with<P: Projection>(
    mesh: &TetMesh,
    ray: &Ray,
    proj: P,
    start: Start,
) -> Result<Lane<P>, TraceOutcome> {
    let st: State<P> = match start {
        Start::Tet(t) => {
            if t as usize >= mesh.tets.len() {
                return Err(TraceOutcome::Failed {
                    failure: Failure::Lost,
                    tets_visited: 0,
                });
            }
            match start_in_tet(mesh, &proj, t) {
                Some(s) => s,
                None => {
                    // The origin is on the start tet's boundary and the ray
                    // leaves it at once: try the other tets around the origin.
                    // Where rounding moved the line off all of them, the
                    // tets near them; where none is near enough, the walk
                    // reports `Lost` and the tracers take the exact walk
                    // (`crate::lost`) rather than a guess.
                    match search_star(mesh, &proj, ray, t)
                        .or_else(|| next_to_star(mesh, &proj, ray, t))
                    {
                        Some(s) => s,
                        None => {
                            return Err(TraceOutcome::Failed {
                                failure: Failure::Lost,
                                tets_visited: 0,
                            });
                        }
                    }
                }
            }
        }
        Start::Face { .. } | Start::Entry { .. } => {
            // Entering `tet` through face `k`: past a constrained face, or
            // through the mesh boundary from outside.
            let through = match start {
                Start::Face { face, tet } => mesh
                    .constrained
                    .get(face as usize)
                    .and_then(|cf| cf.side_of(tet))
                    .map(|side| (tet, side.face as usize, Link::constrained(face))),
                Start::Entry { tet, face } => mesh
                    .neighbors
                    .get(tet as usize)
                    .filter(|_| face < 4)
                    .map(|links| (tet, face as usize, links[face as usize])),
                Start::Tet(_) => None,
            };
            return through
                .map(|(tet, k, behind)| enter_through(mesh, proj, tet, k, behind))
                .ok_or(TraceOutcome::Failed {
                    failure: Failure::Lost,
                    tets_visited: 0,
                });
        }
    };
    // Resolve the start tet's exit link.
    let link = Link(st.link);
    if let Some(n) = link.as_tet() {
        let entry_raw = st.tet;
        return Ok(Lane {
            proj,
            st,
            next: n,
            entry_raw,
            reach: None,
            beyond: 0,
        });
    }
    match resolve_face(mesh, ray, &st, link) {
        Resolved::Done(out) => Err(out),
        Resolved::Cross(n) => {
            let entry_raw = st.link;
            Ok(Lane {
                proj,
                st,
                next: n,
                entry_raw,
                reach: None,
                beyond: 0,
            })
        }
    }
}

/// A lane about to enter `tet` through its face `face` (slot index), whose
/// raw link on the far side is `behind` (the constrained face crossed, or
/// the boundary): the entry face in counter-clockwise (= inward) order.
#[inline(always)]
fn enter_through<P: Projection>(
    mesh: &TetMesh,
    proj: P,
    tet: u32,
    face: usize,
    behind: Link,
) -> Lane<P> {
    let v = mesh.tets[tet as usize];
    let [a, b, c] = FACE_VERTICES[face & 3];
    let ids = [v[a], v[c], v[b]];
    let st = State {
        tet: NO_TET,
        p: P::face(ids.map(|i| proj.project(mesh.points[i as usize]))),
        ids,
        link: behind.0,
        visited: 0,
    };
    Lane {
        proj,
        st,
        next: tet,
        entry_raw: behind.0,
        reach: None,
        beyond: 0,
    }
}

/// A non-tet link was reached: boundary (miss), or a constrained face (hit,
/// miss beyond `t_max`, or crossing when before `t_min`).
#[inline(never)]
fn resolve_face<P: Projection>(mesh: &TetMesh, ray: &Ray, st: &State<P>, link: Link) -> Resolved {
    match link.as_constrained() {
        Some(c) => resolve_constrained(mesh, ray, c, st.ids, st.tet, st.visited),
        None => Resolved::Done(TraceOutcome::Miss {
            tets_visited: st.visited,
        }),
    }
}
