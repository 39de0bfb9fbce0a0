//! Tet80 kernel: the Plücker traversal of Maria, Horna & Aveneau (2017,
//! §3–4).
//!
//! Layout: [`tet_core::layout::Tet80`] = four vertex positions inline + four
//! 8-byte faces (`occlusion`, `neighbor = tet << 2 | face`), 80 bytes; the
//! walk reads no point array and no vertex ids.
//!
//! Entering tet `T` through face `e` (paper: `idV` gives the entry face's
//! vertices; its complement vertex is `V_e`), the ray leaves through one of
//! the three faces containing `V_e`. The Plücker side product of the ray
//! `(d, o)` with edge `V_e → V_x` is `d · ((V_e − o) × (V_x − V_e))`; in the
//! frame of the complement vertex it is `(V_x − V_e) · m` with
//! `m = d × (V_e − o)` computed once per tet (6 mul + 3 sub for `m`, then
//! 3 sub + 3 mul + 2 add per side product). Exactly two side products decide
//! the exit face, looked up in a 4 × 4 table ([`EXIT`]) indexed by the entry
//! face and the two signs (paper: 28 operations per tet).
//!
//! # Start tet: Algorithm 2 (paper §3.3)
//!
//! For a ray whose origin lies strictly inside the start tet,
//! [`Tet80Tracer::algorithm2_exit_face`] computes one side product with
//! the edge `V₂ → V₃` shared by `F₀` and `F₁`: the ray must pass left of an
//! outward edge of its exit face, and `V₂ → V₃` is outward in `F₀` while
//! `V₃ → V₂` is outward in `F₁`, so a positive product rules out `F₁` and
//! a negative (or zero) one `F₀`. The ruled-out face then serves as a
//! *fake entry* for Algorithm 1, which picks the exit among the three faces
//! around its complement vertex. Operation count: the first side product
//! `(V₃ − V₂) · (d × (V₂ − o))` is 3 sub + (6 mul + 3 sub) + 3 sub +
//! (3 mul + 2 add) = 20 operations, then Algorithm 1's 28: **48 operations,
//! three side products**, against the engine's four-face test (four
//! projected vertices, 12 sub, then up to 12 triple products
//! `d · (qₐ × q_b)` of 14 operations each: up to 180, 96 if the six edge
//! products were shared). Paper ↔ code: `Λr ⊙ V₂V₃` = `s23`, `f` =
//! the fake entry `entry ∈ {0, 1}`, `ExitTetra(F_f, Λr)` = `exit_face`.
//!
//! Algorithm 2 tests the ray's *line*, which is only right when the origin
//! is inside the tet: an origin on a face, edge or vertex (a camera placed
//! there, a ray started on a feature) may leave at once through a face the
//! line does not exit by. So the start first checks, with exact
//! orientation tests, that the origin is strictly inside the start tet
//! ([`Tet80Tracer::strictly_inside`]) — once per batch in
//! [`Tracer::trace_batch`] when the rays share their origin (primary rays),
//! once per ray otherwise — and falls back to the engine's search over the
//! tets around the origin ([`crate::walk::start_exit_face`]) when it is not.
//!
//! Not watertight by construction: the side product of one edge is computed
//! in the frame of a different vertex in each tet around it, so two tets can
//! disagree on a ray that grazes the edge, and zero is simply "right". Maria
//! et al. report no failures in f32; the tests measure it.
//!
//! # The consistent variant (`tet80-consistent`)
//!
//! [`Tet80ConsistentTracer`] keeps the layout, the tables and the two side
//! products per tet, but computes each side product from quantities that
//! depend only on the edge's two vertices and the ray, never on the tet:
//! the side product of `P → Q` is `d · ((P − o) × (Q − o))`, which is
//! `|d|` times the 2-D determinant `det(P′, Q′)` of the two vertices
//! projected into a frame `(u, v)` normal to the ray (Duff et al.'s basis,
//! `u × v = d/|d|`). Each vertex is projected by the same expression in
//! every tet ([`DuffF32`]), so both tets around a face, and every tet
//! around an edge, see bitwise the same `P′`, `Q′` and the same
//! determinant, whose two products are subtracted in the opposite order
//! for `Q → P` (an exact negation). A zero determinant is decided by one
//! rule, a symbolic perturbation of the ray's projected origin (the tie
//! rule of [`crate::walk`]'s projections; two vertices projected onto the
//! same point are ordered by position, the layout having no vertex ids).
//! So two tets can never disagree on which side of a shared edge the ray
//! passes, and the signs are those of real points in the plane. Cost per
//! tet: three projected vertices (3 sub + 6 mul + 4 add each) and two
//! determinants, against 9 + 2 × 8 operations for the faithful form.
//!
//! What consistency does not repair by itself: the exit rule reads two of
//! the three side products around the apex and takes the third from the
//! table, which is only right when the entry face really contains the
//! ray's projected origin. Algorithm 2's fake entry breaks that when the
//! origin lies within rounding of a face of the start tet: its one side
//! product then picks a face the projected line does not leave by, and the
//! walk went round until the step cap (about one feature ray in a few
//! hundred on jittered grids). So the consistent variant does not use
//! Algorithm 2: every start runs the engine's search
//! ([`crate::walk::start_exit_face`]) with the same projected vertices and
//! tie rule as the walk, which finds the face the projected line really
//! leaves by; from there each entry face contains the projected origin by
//! construction. The faithful variant keeps Algorithm 2, as the paper.
//!
//! # Batches: the walk in SIMD lockstep
//!
//! [`Tracer::trace_batch`] and [`Tracer::trace_batch_from`] walk 16
//! (AVX-512F) or 8 (AVX2) rays side by side, one per SIMD lane: the one
//! lockstep entry with the Plücker geometry
//! ([`lockstep::trace`] with [`Plucker`], `lockstep/plucker.rs`, the same
//! driver as every other kernel's), for both side rules: the faithful
//! product in the apex's frame is a formula per tet, not state that
//! differs per tet, so it runs per lane as well as the consistent one.
//! Each lane evaluates exactly this module's formulas and tables, takes
//! this module's start (the same `begin`, through
//! [`Tet80Tracer::batch`]), its crossing of occlusive and boundary faces
//! and its tie rule, so every ray's outcome equals the scalar walk's bit
//! for bit ([`Tet80Tracer::trace_batch_scalar`], kept as the reference and
//! taken without AVX2 or with `TET_LOCKSTEP=scalar`).
//!
//! ScTP ([`crate::sctp`]) cannot be repaired the same way within its
//! operation count: its triple products are taken in the frame of the
//! entry face's projected vertices, which differ per tet by design; a
//! consistent rule per edge is exactly the Plücker form above.

use glam::{Vec2, Vec3};
use tet_core::layout::{LayoutError, Tet80, Tet80Face, Tet80Mesh};
use tet_core::predicates::orient3d;
use tet_core::{FACE_VERTICES, NO_TET, TetMesh};

use crate::kernel::Tracer;
use crate::lockstep::plucker::{Begun, PluckerWalk};
use crate::lockstep::{self, NoGate, Plucker, Width};
use crate::lost::{exact_if_lost, exact_where_lost};
use crate::ray::{Failure, Hit, Ray, TraceOutcome};
use crate::secondary::{ShadowTracer, stops_at};
use crate::shadow_batch::{self, PluckerUntil};
use crate::walk::{
    Batch, DuffF32, EntryHint, Projection, Start, Starts, TripleF32, degenerate_crossing, face_hit,
    left_f32, start_exit_face, start_scale, step_cap,
};

/// `EXIT[e][2·s₁ + s₂]`: the exit face of a tet entered through face `e`,
/// from the sign `s₁` of the side product with edge `V_e → A` and the sign
/// `s₂` with edge `V_e → B` (when `s₁`) or `V_e → C` (otherwise), where
/// `(A, B, C)` is face `e` in counter-clockwise order as seen along the ray,
/// i.e. slots `(FACE_VERTICES[e][0], FACE_VERTICES[e][2], FACE_VERTICES[e][1])`.
pub const EXIT: [[u8; 4]; 4] = {
    let mut t = [[0u8; 4]; 4];
    let mut e = 0;
    while e < 4 {
        let [a, b, c] = FACE_VERTICES[e];
        // (A, B, C) = (a, c, b): replace A → exit opposite a, B → c, C → b.
        t[e][0] = a as u8; // right of V→A, right of V→C: replace A
        t[e][1] = c as u8; // right of V→A, left of V→C: replace B
        t[e][2] = b as u8; // left of V→A, right of V→B: replace C
        t[e][3] = a as u8; // left of V→A, left of V→B: replace A
        e += 1;
    }
    t
};

/// The second edge's vertex slot: `B` after a left turn, `C` after a right one.
const SECOND: [[u8; 2]; 4] = {
    let mut t = [[0u8; 2]; 4];
    let mut e = 0;
    while e < 4 {
        let [_, b, c] = FACE_VERTICES[e];
        t[e][0] = b as u8; // C
        t[e][1] = c as u8; // B
        e += 1;
    }
    t
};

/// The Plücker (Tet80) tracer: Maria et al.'s side products in the frame
/// of the entry face's complement vertex (`CONSISTENT = false`), or one
/// side product per edge, the same in every tet (`CONSISTENT = true`, see
/// the module docs).
pub struct Tet80Tracer<'m, const CONSISTENT: bool = false> {
    mesh: &'m TetMesh,
    layout: Tet80Mesh,
    cap: u32,
}

/// The Tet80 layout walked with consistent side products (`tet80-consistent`).
pub type Tet80ConsistentTracer<'m> = Tet80Tracer<'m, true>;

impl<'m> Tet80Tracer<'m, false> {
    /// Encodes `mesh` (validated) in the Tet80 layout: the faithful walk.
    pub fn new(mesh: &'m TetMesh) -> Result<Self, LayoutError> {
        Self::with_layout(mesh)
    }
}

impl<'m> Tet80Tracer<'m, true> {
    /// Encodes `mesh` (validated) in the Tet80 layout: the consistent walk.
    pub fn consistent(mesh: &'m TetMesh) -> Result<Self, LayoutError> {
        Self::with_layout(mesh)
    }
}

impl<'m, const CONSISTENT: bool> Tet80Tracer<'m, CONSISTENT> {
    fn with_layout(mesh: &'m TetMesh) -> Result<Self, LayoutError> {
        Ok(Tet80Tracer {
            mesh,
            layout: Tet80Mesh::from_mesh(mesh)?,
            cap: step_cap(mesh),
        })
    }

    /// Replaces the step cap.
    pub fn with_step_cap(mut self, cap: u32) -> Self {
        self.cap = cap;
        self
    }

    /// The layout container.
    pub fn layout(&self) -> &Tet80Mesh {
        &self.layout
    }

    /// The step cap.
    pub fn step_cap(&self) -> u32 {
        self.cap
    }

    /// The batch of `rays` from `starts` into `out` over this tracer, for
    /// the lockstep walk ([`lockstep::trace`] with [`Plucker`]): `out[i]`
    /// is then exactly the scalar walk's outcome of `rays[i]` from its
    /// start, as [`Tet80Tracer::trace_batch_from_scalar`] gives it.
    pub fn batch<'a>(
        &'a self,
        rays: &'a [Ray],
        starts: Starts<'a>,
        out: &'a mut [TraceOutcome],
    ) -> Batch<'a, Self> {
        Batch {
            mesh: self.mesh,
            topo: self,
            rays,
            starts,
            cap: self.cap,
            out,
            bounded: false,
        }
    }

    /// The walk from `tet`, entered through face `entry`. `stop(tet)` ends
    /// it as a [`TraceOutcome::Miss`] on entering `tet` (shadow rays;
    /// monomorphised away for primary rays).
    #[inline(always)]
    fn walk<S: Fn(u32) -> bool>(
        &self,
        ray: &Ray,
        mut tet: u32,
        mut entry: usize,
        mut visited: u32,
        scale: f32,
        stop: S,
    ) -> TraceOutcome {
        let tets = &self.layout.tets[..];
        let side = Side::<CONSISTENT>::new(ray, scale);
        loop {
            if visited >= self.cap {
                return TraceOutcome::Failed {
                    failure: Failure::StepCap,
                    tets_visited: visited,
                };
            }
            visited += 1;
            if stop(tet) {
                return TraceOutcome::Miss {
                    tets_visited: visited,
                };
            }
            let rec = &tets[tet as usize];
            let exit = side.exit_face(|k| rec.vertex(k), entry);
            match self.leave(ray, tet, rec.f[exit], visited) {
                Ok((n, f)) => {
                    tet = n;
                    entry = f;
                }
                Err(out) => return out,
            }
        }
    }

    /// The walk from `b` (a walk between two tets) to its end.
    #[cfg(test)]
    pub(crate) fn walk_from(&self, ray: &Ray, b: Begun) -> TraceOutcome {
        self.walk(ray, b.tet, b.entry, b.visited, b.scale, |_| false)
    }

    /// Crosses face `f` of `tet`: `Ok(next tet, its entry face)` or the outcome.
    #[inline(always)]
    fn leave(
        &self,
        ray: &Ray,
        tet: u32,
        f: Tet80Face,
        visited: u32,
    ) -> Result<(u32, usize), TraceOutcome> {
        if f.is_occlusive() {
            let cf = &self.mesh.constrained[f.occlusion as usize];
            let (t, w) = face_hit(self.mesh, ray, cf.vertices);
            if t >= ray.t_min as f64 {
                if t > ray.t_max as f64 {
                    return Err(TraceOutcome::Miss {
                        tets_visited: visited,
                    });
                }
                let barycentrics = w.map(|x| x as f32);
                if degenerate_crossing(t, &barycentrics) {
                    return Err(TraceOutcome::Failed {
                        failure: Failure::Lost,
                        tets_visited: visited,
                    });
                }
                return Err(TraceOutcome::Hit(Hit {
                    triangle: cf.triangle,
                    face: f.occlusion,
                    t: t as f32,
                    barycentrics,
                    tet,
                    far_tet: f.neighbor_tet().unwrap_or(NO_TET),
                    tets_visited: visited,
                }));
            }
        }
        match f.neighbor_tet() {
            Some(n) => Ok((n, f.neighbor_face())),
            None => Err(TraceOutcome::Miss {
                tets_visited: visited,
            }),
        }
    }
}

impl<const CONSISTENT: bool> Tet80Tracer<'_, CONSISTENT> {
    /// Maria et al.'s Algorithm 2 on start tet `tet` (see [`algorithm2`]).
    #[inline(always)]
    pub fn algorithm2_exit_face(&self, ray: &Ray, tet: u32) -> usize {
        let rec = &self.layout.tets[tet as usize];
        Side::<CONSISTENT>::new(ray, 1.0).algorithm2(|k| rec.vertex(k))
    }

    /// The start of a walk from `Start::Tet(t)`: the start tet and its exit
    /// face. Faithful: Algorithm 2 when the origin lies strictly inside `t`
    /// (`inside`), else the engine's search over the tets around an origin
    /// on a face, edge or vertex ([`start_exit_face`]). Consistent: always
    /// the engine's search (see the module docs).
    fn start_tet(&self, ray: &Ray, t: u32, inside: bool) -> Option<(u32, usize)> {
        if CONSISTENT {
            // The engine's search with the same projected vertices and tie
            // rule as the walk.
            start_exit_face::<DuffF32>(self.mesh, ray, t)
        } else if inside {
            Some((t, self.algorithm2_exit_face(ray, t)))
        } else {
            start_exit_face::<TripleF32>(self.mesh, ray, t)
        }
    }

    /// True when `p` lies strictly inside tet `t` (exact orientation tests):
    /// where Algorithm 2 applies.
    pub fn strictly_inside(&self, t: u32, p: Vec3) -> bool {
        strictly_inside(self.mesh, t, p)
    }

    /// [`Tracer::trace`] with a stop predicate (see [`Tet80Tracer::walk`])
    /// and the start tet's interior test already made (`inside`, for
    /// `Start::Tet` only).
    #[inline(always)]
    fn trace_with<S: Fn(u32) -> bool>(
        &self,
        ray: &Ray,
        start: Start,
        inside: Option<bool>,
        stop: S,
    ) -> TraceOutcome {
        match self.begin(ray, start, inside, &stop) {
            Ok(b) => self.walk(ray, b.tet, b.entry, b.visited, b.scale, stop),
            Err(out) => out,
        }
    }

    /// Everything before the walk's loop: the ray's checks, the start
    /// (see [`Tet80Tracer::trace_with`]) and the consistent walk's
    /// projection factor; `Err` when the walk ended before its loop.
    #[inline(always)]
    fn begin<S: Fn(u32) -> bool>(
        &self,
        ray: &Ray,
        start: Start,
        inside: Option<bool>,
        stop: &S,
    ) -> Result<Begun, TraceOutcome> {
        let lost = |tets_visited| TraceOutcome::Failed {
            failure: Failure::Lost,
            tets_visited,
        };
        if !ray.is_valid() {
            return Err(TraceOutcome::Failed {
                failure: Failure::InvalidRay,
                tets_visited: 0,
            });
        }
        // The consistent walk's projection factor, the same as its start's
        // (`start_exit_face` takes it from the same tet).
        let scale = if CONSISTENT {
            start_scale(self.mesh, ray, start)
        } else {
            1.0
        };
        let begun = |tet, entry, visited| Begun {
            tet,
            entry,
            visited,
            scale,
        };
        match start {
            Start::Tet(t) => {
                if t as usize >= self.layout.tets.len() {
                    return Err(lost(0));
                }
                if stop(t) {
                    return Err(TraceOutcome::Miss { tets_visited: 1 });
                }
                let inside =
                    !CONSISTENT && inside.unwrap_or_else(|| self.strictly_inside(t, ray.origin));
                let Some((t, k)) = self.start_tet(ray, t, inside) else {
                    return Err(lost(1));
                };
                let f = self.layout.tets[t as usize].f[k];
                self.leave(ray, t, f, 1).map(|(n, e)| begun(n, e, 1))
            }
            Start::Face { face, tet } => self
                .mesh
                .constrained
                .get(face as usize)
                .and_then(|cf| cf.side_of(tet))
                .filter(|_| (tet as usize) < self.layout.tets.len())
                .map(|s| begun(tet, s.face as usize, 0))
                .ok_or(lost(0)),
            Start::Entry { tet, face } => {
                if self.mesh.is_boundary_face(tet, face) {
                    Ok(begun(tet, face as usize, 0))
                } else {
                    Err(lost(0))
                }
            }
        }
    }

    /// The start tet's interior test shared by a batch whose rays all
    /// start in tet `t` from one origin (primary rays), made once.
    fn shared_inside(&self, rays: &[Ray], start: Start) -> Option<bool> {
        match (start, rays.first()) {
            (Start::Tet(t), Some(r0))
                if (t as usize) < self.layout.tets.len()
                    && r0.origin.is_finite()
                    && rays.iter().all(|r| r.origin == r0.origin) =>
            {
                Some(self.strictly_inside(t, r0.origin))
            }
            _ => None,
        }
    }

    /// The scalar batch walk, one ray after the other (the reference of
    /// the lockstep walk, see [`Tet80Tracer::batch`]): rays
    /// sharing one origin share the start tet's interior test.
    pub fn trace_batch_scalar(&self, rays: &[Ray], start: Start, out: &mut [TraceOutcome]) {
        let inside = self.shared_inside(rays, start);
        for (r, o) in rays.iter().zip(out.iter_mut()) {
            *o = self.trace_with(r, start, inside, |_| false);
        }
    }

    /// [`Tracer::trace_batch_from`] ray after ray with the scalar walk.
    pub fn trace_batch_from_scalar(
        &self,
        rays: &[Ray],
        starts: Starts<'_>,
        out: &mut [TraceOutcome],
    ) {
        let mut hint = EntryHint::default();
        for (i, (r, o)) in rays.iter().zip(out.iter_mut()).enumerate() {
            let start = match starts {
                Starts::Same(s) => Ok(s),
                Starts::Each(s) => match s.get(i) {
                    Some(&s) => Ok(s),
                    None => break,
                },
                Starts::Outside(entry) => self.start_outside(entry, r, &mut hint),
            };
            *o = match start {
                Ok(s) => self.trace_with(r, s, None, |_| false),
                Err(done) => done,
            };
        }
    }
}

impl<const CONSISTENT: bool> Tet80Tracer<'_, CONSISTENT> {
    /// This walk's own start of each ray of a batch, with the stop test
    /// `stop` of [`Tet80Tracer::begin`]: rays sharing one origin share the
    /// start tet's interior test.
    fn starts_with<'a, S: Fn(u32) -> bool + 'a>(
        &'a self,
        rays: &'a [Ray],
        starts: Starts<'a>,
        stop: S,
    ) -> impl FnMut(usize) -> Result<Begun, TraceOutcome> + 'a {
        let inside = match starts {
            Starts::Same(s) => self.shared_inside(rays, s),
            _ => None,
        };
        let mut hint = EntryHint::default();
        move |i: usize| {
            let r = &rays[i];
            let start = match starts {
                Starts::Same(s) => s,
                Starts::Each(s) => s[i],
                Starts::Outside(entry) => self.start_outside(entry, r, &mut hint)?,
            };
            self.begin(r, start, inside, &stop)
        }
    }

    /// [`ShadowTracer::trace_until_batch`] with the lockstep walk at
    /// `width` (the trait method takes [`Width::Auto`]): `out[i]` is
    /// exactly [`ShadowTracer::trace_until`] of `rays[i]` from `starts[i]`
    /// with `stop`, over the shortest of the three slices. The walks run in
    /// lockstep where the CPU has the width (each stopped short of the stop
    /// tets, see [`lockstep`]'s gates), else one by one; true when in
    /// lockstep. Walks that reach the step cap are walked again by the
    /// exact walk, as there.
    pub fn trace_until_batch_at(
        &self,
        rays: &[Ray],
        starts: &[Start],
        stop: &[u32],
        out: &mut [TraceOutcome],
        width: Width,
    ) -> bool {
        let n = Starts::Each(starts).batch_len(rays.len(), out.len());
        let (rays, starts, out) = (&rays[..n], &starts[..n], &mut out[..n]);
        let batch = self.batch(rays, Starts::Each(starts), out);
        let ran = shadow_batch::plucker(batch, stop, width);
        if !ran {
            for ((r, s), o) in rays.iter().zip(starts).zip(out.iter_mut()) {
                *o = self.trace_with(r, *s, None, |t| stops_at(stop, t));
            }
        }
        exact_where_lost(self.mesh, self.cap, rays, Starts::Each(starts), out);
        ran
    }
}

/// Shadow rays' starts: the stop test of the single-ray start.
impl<const CONSISTENT: bool> PluckerUntil for Tet80Tracer<'_, CONSISTENT> {
    fn starts_until<'a>(
        &'a self,
        rays: &'a [Ray],
        starts: Starts<'a>,
        stop: &'a [u32],
    ) -> impl FnMut(usize) -> Result<Begun, TraceOutcome> + 'a {
        self.starts_with(rays, starts, move |t| stops_at(stop, t))
    }
}

impl<const CONSISTENT: bool> PluckerWalk for Tet80Tracer<'_, CONSISTENT> {
    const CONSISTENT: bool = CONSISTENT;
    fn records(&self) -> &[Tet80] {
        &self.layout.tets
    }
    /// This walk's own start of each ray: rays sharing one origin share the
    /// start tet's interior test.
    fn starts<'a>(
        &'a self,
        rays: &'a [Ray],
        starts: Starts<'a>,
    ) -> impl FnMut(usize) -> Result<Begun, TraceOutcome> + 'a {
        self.starts_with(rays, starts, |_| false)
    }
    fn leave(
        &self,
        ray: &Ray,
        tet: u32,
        f: Tet80Face,
        visited: u32,
    ) -> Result<(u32, usize), TraceOutcome> {
        Tet80Tracer::leave(self, ray, tet, f, visited)
    }
    fn left_tie(pp: Vec2, p: Vec3, pq: Vec2, q: Vec3) -> bool {
        left_projected(pp, p, pq, q)
    }
}

/// How a walk decides which side of an edge the ray passes: in the frame
/// of the entry face's complement vertex (faithful, `CONSISTENT = false`)
/// or from each vertex's projection into the ray's frame (consistent; see
/// the module docs).
#[derive(Clone, Copy)]
struct Side<const CONSISTENT: bool> {
    o: Vec3,
    d: Vec3,
    /// The ray's 2-D frame (consistent only; unused otherwise).
    projection: Option<DuffF32>,
}

impl<const CONSISTENT: bool> Side<CONSISTENT> {
    #[inline(always)]
    fn new(ray: &Ray, scale: f32) -> Self {
        Side {
            o: ray.origin,
            d: ray.direction,
            projection: CONSISTENT.then(|| DuffF32::setup_scaled(ray, scale)),
        }
    }

    /// Algorithm 1 in the tet whose slot-`k` vertex is `v(k)`, entered
    /// through face `entry`: two side products of edges from the entry
    /// face's complement vertex `V_e`.
    #[inline(always)]
    fn exit_face(&self, v: impl Fn(usize) -> Vec3, entry: usize) -> usize {
        let apex = v(entry);
        let a = FACE_VERTICES[entry][0];
        let (s1, s2) = match &self.projection {
            Some(p) if CONSISTENT => {
                let pa = p.project(apex);
                let s1 = left_projected(pa, apex, p.project(v(a)), v(a));
                let second = v(SECOND[entry][s1 as usize] as usize);
                (s1, left_projected(pa, apex, p.project(second), second))
            }
            _ => {
                let m = self.d.cross(apex - self.o);
                let s1 = (v(a) - apex).dot(m) > 0.0;
                let second = SECOND[entry][s1 as usize] as usize;
                (s1, (v(second) - apex).dot(m) > 0.0)
            }
        };
        EXIT[entry][2 * s1 as usize + s2 as usize] as usize
    }

    /// Algorithm 2 (see [`algorithm2`]) with this side rule.
    #[inline(always)]
    fn algorithm2(&self, v: impl Fn(usize) -> Vec3) -> usize {
        let v2 = v(2);
        // left(V₂ → V₃) = d · ((V₂ − o) × (V₃ − V₂)) = (V₃ − V₂) · (d × (V₂ − o)).
        let left23 = match &self.projection {
            Some(p) if CONSISTENT => left_projected(p.project(v2), v2, p.project(v(3)), v(3)),
            _ => (v(3) - v2).dot(self.d.cross(v2 - self.o)) > 0.0,
        };
        // Exiting through F₀ = (V₁, V₂, V₃) needs the ray left of V₂ → V₃,
        // through F₁ = (V₀, V₃, V₂) left of V₃ → V₂: left of V₂ → V₃ rules
        // out F₁.
        let entry = if left23 { 1 } else { 0 };
        self.exit_face(v, entry)
    }
}

/// True when `p` comes before `q` in the lexicographic order of positions
/// (x, then y, then z): the last tie-break of the consistent side test.
#[inline(always)]
fn lex_less(p: Vec3, q: Vec3) -> bool {
    (p.x, p.y, p.z) < (q.x, q.y, q.z)
}

/// The consistent side test on projected vertices `pp`, `pq` (of the 3-D
/// positions `p`, `q`): the ray passes left of `p → q`. Exactly
/// antisymmetric, with the projections' tie rule.
#[inline(always)]
fn left_projected(pp: Vec2, p: Vec3, pq: Vec2, q: Vec3) -> bool {
    let (ip, iq) = if lex_less(p, q) { (0, 1) } else { (1, 0) };
    left_f32(pp, ip, pq, iq)
}

/// The consistent side test of `tet80-consistent` for one ray: does the ray
/// `o + t·d` pass left of the directed edge `p → q`, i.e. is the Plücker
/// side product `d · ((p − o) × (q − o))` positive, evaluated as the 2-D
/// determinant of `p` and `q` projected into the ray's frame, with one rule
/// for zero. `left_of(p, q, ray) == !left_of(q, p, ray)` for distinct
/// points, and the answer depends only on the edge and the ray.
pub fn left_of(p: Vec3, q: Vec3, ray: &Ray) -> bool {
    let proj = DuffF32::setup(ray);
    left_projected(proj.project(p), p, proj.project(q), q)
}

/// Maria et al.'s Algorithm 2: the exit face of a start tet (slot-`k`
/// vertex `v(k)`) for a ray `o + t·d` whose origin lies strictly inside it.
/// One side product with edge `V₂ → V₃` (shared by `F₀` and `F₁`) rules out
/// one of those two faces as the exit; Algorithm 1 then runs as if the ray
/// had entered through the ruled-out face (the *fake entry*), which leaves
/// exactly the three faces around its complement vertex. Three side
/// products in all.
#[inline(always)]
pub fn algorithm2(v: impl Fn(usize) -> Vec3, o: Vec3, d: Vec3) -> usize {
    Side::<false> {
        o,
        d,
        projection: None,
    }
    .algorithm2(v)
}

/// True when `p` lies strictly inside tet `t` of `mesh` (exact orientation
/// tests): where [`algorithm2`] applies.
pub fn strictly_inside(mesh: &TetMesh, t: u32, p: Vec3) -> bool {
    let v = mesh.tet_points(t).map(|x| x.as_dvec3());
    let q = p.as_dvec3();
    FACE_VERTICES
        .iter()
        .all(|s| orient3d(v[s[0]], v[s[1]], v[s[2]], q) < 0.0)
}

/// The Tet80 walk's start from `Start::Tet(t)` (`t` in range): the start
/// tet and its exit face, exactly as [`Tet80Tracer`] computes it —
/// [`algorithm2`] when the origin lies strictly inside `t`, else the
/// engine's search around an origin on a face, edge or vertex. Shared with
/// the GPU kernel's host-side start so that both walk the same tets.
pub fn start_exit(mesh: &TetMesh, ray: &Ray, t: u32) -> Option<(u32, usize)> {
    if strictly_inside(mesh, t, ray.origin) {
        let p = mesh.tet_points(t);
        Some((t, algorithm2(|k| p[k], ray.origin, ray.direction)))
    } else {
        start_exit_face::<TripleF32>(mesh, ray, t)
    }
}

impl<const CONSISTENT: bool> Tracer for Tet80Tracer<'_, CONSISTENT> {
    fn name(&self) -> String {
        if CONSISTENT {
            "tet80-consistent/f32".into()
        } else {
            "tet80/f32".into()
        }
    }
    fn mesh(&self) -> &TetMesh {
        self.mesh
    }
    /// The walk, or where it reached the step cap, the exact walk
    /// (`lost.rs`); likewise the batches.
    fn trace(&self, ray: &Ray, start: Start) -> TraceOutcome {
        let out = self.trace_with(ray, start, None, |_| false);
        exact_if_lost(self.mesh, self.cap, ray, start, out)
    }
    fn trace_until(&self, ray: &Ray, start: Start, stop: &[u32]) -> TraceOutcome {
        ShadowTracer::trace_until(self, ray, start, stop)
    }
    fn trace_until_batch(
        &self,
        rays: &[Ray],
        starts: &[Start],
        stop: &[u32],
        out: &mut [TraceOutcome],
    ) {
        ShadowTracer::trace_until_batch(self, rays, starts, stop, out)
    }
    /// In SIMD lockstep ([`lockstep::trace`] at [`Width::Auto`]): 16 lanes
    /// with AVX-512F (unless `TET_LOCKSTEP=avx2`), else 8 with AVX2; else,
    /// or with `TET_LOCKSTEP=scalar`, the scalar walk
    /// ([`Tet80Tracer::trace_batch_scalar`]). The outcomes are the same.
    fn trace_batch(&self, rays: &[Ray], start: Start, out: &mut [TraceOutcome]) {
        let starts = Starts::Same(start);
        let batch = self.batch(rays, starts, out);
        if lockstep::trace::<Plucker, _, _>(batch, Width::Auto, &mut NoGate).is_err() {
            self.trace_batch_scalar(rays, start, out);
        }
        exact_where_lost(self.mesh, self.cap, rays, starts, out);
    }
    /// As [`Tracer::trace_batch`]: in lockstep where the CPU has AVX2 or
    /// AVX-512F, else ray after ray.
    fn trace_batch_from(&self, rays: &[Ray], starts: Starts<'_>, out: &mut [TraceOutcome]) {
        let n = starts.batch_len(rays.len(), out.len());
        let (rays, out) = (&rays[..n], &mut out[..n]);
        let batch = self.batch(rays, starts, out);
        if lockstep::trace::<Plucker, _, _>(batch, Width::Auto, &mut NoGate).is_err() {
            self.trace_batch_from_scalar(rays, starts, out);
        }
        exact_where_lost(self.mesh, self.cap, rays, starts, out);
    }
}

impl<const CONSISTENT: bool> ShadowTracer for Tet80Tracer<'_, CONSISTENT> {
    fn mesh(&self) -> &TetMesh {
        self.mesh
    }
    fn trace_until(&self, ray: &Ray, start: Start, stop: &[u32]) -> TraceOutcome {
        let out = self.trace_with(ray, start, None, |t| stops_at(stop, t));
        exact_if_lost(self.mesh, self.cap, ray, start, out)
    }
    /// In SIMD lockstep where the CPU has AVX2 or AVX-512F
    /// ([`Tet80Tracer::trace_until_batch_at`] at [`Width::Auto`]).
    fn trace_until_batch(
        &self,
        rays: &[Ray],
        starts: &[Start],
        stop: &[u32],
        out: &mut [TraceOutcome],
    ) {
        self.trace_until_batch_at(rays, starts, stop, out, Width::Auto);
    }
}
