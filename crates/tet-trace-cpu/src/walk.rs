//! The traversal engine shared by every kernel: a ray walks from the tet
//! containing its origin, one tet per step, until it crosses a constrained
//! face or the mesh boundary.
//!
//! # The projected (2-D) walk of Aman et al. (seed 000 §4, Algorithm 1)
//!
//! A basis `(u, v)` orthogonal to the ray direction `d` (with
//! `(u × v) · d > 0`) maps every vertex `P` to the 2-D point
//! `p = (u·(P−o), v·(P−o))` (a [`Projection`]); the ray becomes the origin
//! `(0, 0)`. With the outward faces of a positive tet, the ray leaves through
//! the face whose projection winds counter-clockwise around the origin. The
//! walk keeps the three vertices of the current entry face (`idx₀..₂`, paper
//! `idx_0..2`, code `ids`) and their projections (`p₀..₂`, code `p`) in
//! counter-clockwise order. Entering a tet, it fetches the one new vertex
//! `idx₃ = idx₀ ⊕ idx₁ ⊕ idx₂ ⊕ VX` (paper `VX^i`, code [`Topology::vx`]),
//! projects it (`p₃`) and decides with two 2-D determinants `det(p₃, pᵢ)` which
//! of the three faces through `p₃` holds the origin (paper Algorithm 1,
//! code [`exit_slot`]): 4 multiplications and 2 comparisons in the paper; here
//! a third determinant makes the choice branch-free (a table lookup instead
//! of a branch that mispredicts half the time). The vertex that
//! leaves the face is replaced by `idx₃` in place, which keeps the
//! counter-clockwise order; the neighbour across the exit face comes from the
//! layout ([`Topology::exit_link`]: Algorithms 3, 5, 7).
//!
//! # Why the walk is watertight
//!
//! Every decision is the sign of `det(pₐ, p_b) = pₐ.x·p_b.y − pₐ.y·p_b.x`
//! for a *mesh edge* `(a, b)`: whether the ray passes left or right of it.
//! The walk cannot slip between two tets, loop, or skip a face as long as
//! every tet sharing an edge sees the *same* answer for it. That holds here
//! bit for bit, in f32, with no epsilon:
//!
//! 1. identical operands: `pₐ` is a pure function of the vertex position and
//!    the ray (same formula, computed whenever the vertex is fetched), so every
//!    tet around the edge sees the same two 2-D points;
//! 2. exact antisymmetry: IEEE multiplication is commutative and
//!    `fl(x − y) = −fl(y − x)`, so `det(p_b, pₐ) = −det(pₐ, p_b)` exactly
//!    (no fused multiply-add is used: Rust never contracts implicitly), i.e.
//!    seen from either orientation of the edge the answer is the same;
//! 3. one tie rule for zero (the ray touches the edge's projection, e.g. it
//!    passes through a vertex or along an edge): the origin is perturbed
//!    symbolically to `(ε, ε²)` (simulation of simplicity), so a zero
//!    determinant is decided by `sign(pₐ.y − p_b.y)`, then `sign(p_b.x − pₐ.x)`
//!    (exact comparisons), and, when both points coincide (an edge parallel to
//!    the ray), by the global vertex indices (`a < b` ⇒ left). Each step is
//!    antisymmetric, so the rule never answers differently for the same edge.
//!
//! # Interleaving and the hot loop
//!
//! [`trace_interleaved`] walks several rays on one thread, one step each per
//! round, so the out-of-order core overlaps their dependent
//! load → project → decide → load chains; each ray's result is exactly that
//! of [`trace`] (the same `advance` / `finish_step` functions). The hot step
//! (`advance`) does only the common case (enter a tet, leave into another
//! tet); reaching a constrained face or the boundary, the step cap and the
//! lane refill are out of line. Each step prefetches the next tet's record,
//! which that lane reads a round later. The 2-D f32 projections store the
//! entry face as SoA vectors ([`Face2`]) and evaluate the projection and the
//! three determinants in SIMD, lane by lane the same IEEE operations as the
//! scalar formulas (so the watertightness argument above is unchanged); the
//! tie rule runs only when a determinant is zero.
//!
//! Measured on Torus Knots (318 584 tets, 57.6 tets per ray, 80×60, one
//! thread, callgrind): Tet20 136 → 99 instructions per step, Tet16
//! 176 → 109, Tet32 124 → 87, ScTP 170 → 146 (see the crate's report for
//! the wall-time ratios against the BVH). Prefetching the new vertex's point
//! in a separate pass per round, and single-ray walks, were measured slower;
//! 4, 8 and 16 lanes were within noise of each other.
//!
//! Batches of [`DuffF32`] kernels (Tet20, Tet16, Tet32) take the SIMD
//! lockstep walk of [`crate::lockstep`] instead (one ray per SIMD lane, the
//! same operations lane by lane, identical outcomes; Tet20 43.5 instructions
//! per step, about 2× the rays per CPU-second of the interleaved walk), and
//! so do ScTP's ([`TripleF32`] on the baseline layout, with AVX-512:
//! `crate::sctp_lockstep`); the interleaved walk serves the other
//! projections and stays the reference ([`crate::kernel::Interleaved`]).
//!
//! Each kernel's operation count is in its module docs. The engine is generic
//! over the projection (f32, f64, projected origin of Eq. 4–5, or the 3-D
//! scalar triple products of [`crate::sctp`], which use the same decisions)
//! and over the layout ([`Topology`]), and monomorphised per pair.

use glam::{DVec2, DVec3, Vec2, Vec3, Vec4};
use tet_core::{FACE_VERTICES, Link, NO_TET, TetMesh};

use crate::entry::{BoundaryEntry, EntryHint};
use crate::locate::star;
use crate::ray::{DEFAULT_STEP_CAP, Failure, Hit, Ray, TraceOutcome};

/// How a ray's vertices are mapped to the quantities whose signs steer the walk.
pub trait Projection: Copy + Send + Sync {
    /// A projected vertex.
    type P: Copy;
    /// Short name for reports.
    const NAME: &'static str;
    /// Builds the projection of a (valid) ray.
    fn setup(ray: &Ray) -> Self;
    /// Projects one mesh vertex (must be a pure function of `p` and the ray).
    fn project(&self, p: Vec3) -> Self::P;
    /// True when the ray passes to the left of the directed edge `a → b`,
    /// i.e. `det(pa, pb) > 0` with the tie rule of the module docs.
    /// Exactly antisymmetric: `left(a, b) == !left(b, a)`.
    fn left(&self, a: Self::P, ia: u32, b: Self::P, ib: u32) -> bool;

    /// The entry face's three projected points as the walk stores them
    /// (an array, or SoA vectors for the SIMD 2-D projections).
    type Face: Copy;
    /// Packs three projected points.
    fn face(p: [Self::P; 3]) -> Self::Face;
    /// Replaces point `slot` (0..=2) of a face.
    fn set_point(face: &mut Self::Face, slot: usize, p: Self::P);
    /// The three edge tests of a step as a bit mask:
    /// bit `i` = `left(pd, d, pᵢ, ids[i])` for the points `pᵢ` of `face`
    /// (the index of [`EXIT_SLOT`]). Implementations may only change how
    /// the bits are computed, never their values: the 2-D ones evaluate the
    /// three determinants at once, branch-free, and take the tie rule only
    /// when one of them is zero.
    fn left_mask(&self, pd: Self::P, d: u32, face: &Self::Face, ids: &[u32; 3]) -> usize;

    /// Traces a batch of rays from one start over `topo` (the kernels'
    /// [`Tracer::trace_batch`](crate::Tracer::trace_batch)); the outcomes
    /// equal [`trace`] ray by ray. Default: the scalar interleaved walk
    /// ([`trace_interleaved`]); [`DuffF32`] walks SIMD lanes in lockstep
    /// ([`crate::lockstep`]).
    fn trace_batch<T: Topology>(
        mesh: &TetMesh,
        topo: &T,
        rays: &[Ray],
        starts: Starts<'_>,
        cap: u32,
        out: &mut [TraceOutcome],
    ) {
        trace_interleaved::<Self, T, { crate::kernel::LANES }>(mesh, topo, rays, starts, cap, out)
    }
}

/// [`Projection::Face`] for projections that store the face as an array:
/// the three `left` calls of Algorithm 1, as written.
macro_rules! array_face {
    ($P:ty) => {
        array_face!($P, no_mask);
        #[inline(always)]
        fn left_mask(&self, pd: $P, d: u32, f: &[$P; 3], ids: &[u32; 3]) -> usize {
            self.left(pd, d, f[0], ids[0]) as usize
                | (self.left(pd, d, f[1], ids[1]) as usize) << 1
                | (self.left(pd, d, f[2], ids[2]) as usize) << 2
        }
    };
    ($P:ty, no_mask) => {
        type Face = [$P; 3];
        #[inline(always)]
        fn face(p: [$P; 3]) -> [$P; 3] {
            p
        }
        #[inline(always)]
        fn set_point(face: &mut [$P; 3], slot: usize, p: $P) {
            face[slot] = p;
        }
    };
}

/// An entry face of 2-D f32 points in SoA form: `xs = (x₀, x₁, x₂, 0)`,
/// `ys = (y₀, y₁, y₂, 0)`, so that the three determinants of a step
/// `det(pd, pᵢ) = pd.x·yᵢ − pd.y·xᵢ` are one SIMD multiply–multiply–subtract
/// (each lane computes exactly the scalar expression of `left_2d!`: same
/// operands, same operations, no fusion, hence bit-identical).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub struct Face2 {
    // Plain arrays (16-byte aligned): a replacement is one scalar store per
    // array at a variable index, without branches; the determinants load
    // them as vectors.
    pub(crate) xs: [f32; 4],
    pub(crate) ys: [f32; 4],
}

impl Face2 {
    /// Packs three points.
    #[inline(always)]
    pub fn new(p: [Vec2; 3]) -> Face2 {
        Face2 {
            xs: [p[0].x, p[1].x, p[2].x, 0.0],
            ys: [p[0].y, p[1].y, p[2].y, 0.0],
        }
    }
    /// Point `i` (0..=2).
    #[inline(always)]
    pub fn point(&self, i: usize) -> Vec2 {
        Vec2::new(self.xs[i], self.ys[i])
    }
    /// Replaces point `slot` (0..=2; larger values panic).
    #[inline(always)]
    pub fn set(&mut self, slot: usize, p: Vec2) {
        self.xs[slot] = p.x;
        self.ys[slot] = p.y;
    }
    /// Bit `i` = `left_f32(pd, d, pᵢ, ids[i])`: the fast path when no
    /// determinant is zero, the full tie rule otherwise.
    #[inline(always)]
    pub fn left_mask(&self, pd: Vec2, d: u32, ids: &[u32; 3]) -> usize {
        let (xs, ys) = (Vec4::from_array(self.xs), Vec4::from_array(self.ys));
        let det = Vec4::splat(pd.x) * ys - Vec4::splat(pd.y) * xs;
        let nonzero = det.cmpne(Vec4::ZERO).bitmask() & 7;
        if nonzero == 7 {
            (det.cmpgt(Vec4::ZERO).bitmask() & 7) as usize
        } else {
            self.left_mask_ties(pd, d, ids)
        }
    }
    #[cold]
    #[inline(never)]
    pub(crate) fn left_mask_ties(&self, pd: Vec2, d: u32, ids: &[u32; 3]) -> usize {
        left_f32(pd, d, self.point(0), ids[0]) as usize
            | (left_f32(pd, d, self.point(1), ids[1]) as usize) << 1
            | (left_f32(pd, d, self.point(2), ids[2]) as usize) << 2
    }
}

/// [`Projection::Face`] = [`Face2`] for the 2-D f32 projections.
macro_rules! simd_face {
    () => {
        type Face = $crate::walk::Face2;
        #[inline(always)]
        fn face(p: [Vec2; 3]) -> $crate::walk::Face2 {
            $crate::walk::Face2::new(p)
        }
        #[inline(always)]
        fn set_point(face: &mut $crate::walk::Face2, slot: usize, p: Vec2) {
            face.set(slot, p);
        }
        #[inline(always)]
        fn left_mask(&self, pd: Vec2, d: u32, f: &$crate::walk::Face2, ids: &[u32; 3]) -> usize {
            f.left_mask(pd, d, ids)
        }
    };
}
pub(crate) use simd_face;

/// The tie rule of the module docs for 2-D points with an already computed
/// determinant.
macro_rules! left_2d {
    ($a:expr, $ia:expr, $b:expr, $ib:expr) => {{
        let (a, b) = ($a, $b);
        let det = a.x * b.y - a.y * b.x;
        if det != 0.0 {
            det > 0.0
        } else if a.y != b.y {
            a.y > b.y
        } else if a.x != b.x {
            b.x > a.x
        } else {
            $ia < $ib
        }
    }};
}

/// The tie rule of the module docs on f32 2-D points (shared by every f32
/// 2-D projection).
#[inline(always)]
pub(crate) fn left_f32(a: Vec2, ia: u32, b: Vec2, ib: u32) -> bool {
    left_2d!(a, ia, b, ib)
}

/// Duff et al.'s orthonormal basis for a unit vector `n`, ordered so that
/// `u × v` points along `n` (public so the GPU crate projects batch rays with
/// exactly the CPU's basis).
pub fn duff_basis(n: DVec3) -> (DVec3, DVec3) {
    let sign = 1.0f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    let u = DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    let v = DVec3::new(b, sign + n.y * n.y * a, -n.y);
    if u.cross(v).dot(n) >= 0.0 {
        (u, v)
    } else {
        (v, u)
    }
}

/// f32 projection `p = (u·(P−o), v·(P−o))` with Duff et al.'s basis
/// (6 multiplications, 4 additions, 3 subtractions per vertex). Both dot
/// products are evaluated at once in SIMD, column by column:
/// `(u·q, v·q) = (uₓ, vₓ)·qₓ + (u_y, v_y)·q_y + (u_z, v_z)·q_z`, which is the
/// scalar `(uₓqₓ + u_y q_y) + u_z q_z` lane by lane (bit-identical; any fixed
/// formula keeps the walk watertight, this one also matches the scalar
/// reference order).
#[derive(Clone, Copy, Debug, Default)]
pub struct DuffF32 {
    pub(crate) o: Vec3,
    pub(crate) cx: Vec4,
    pub(crate) cy: Vec4,
    pub(crate) cz: Vec4,
}

impl Projection for DuffF32 {
    type P = Vec2;
    simd_face!();
    const NAME: &'static str = "f32";
    fn setup(ray: &Ray) -> Self {
        let (u, v) = duff_basis(ray.direction.as_dvec3().normalize());
        let (u, v) = (u.as_vec3(), v.as_vec3());
        DuffF32 {
            o: ray.origin,
            cx: Vec4::new(u.x, v.x, 0.0, 0.0),
            cy: Vec4::new(u.y, v.y, 0.0, 0.0),
            cz: Vec4::new(u.z, v.z, 0.0, 0.0),
        }
    }
    #[inline(always)]
    fn project(&self, p: Vec3) -> Vec2 {
        let q = p - self.o;
        let r =
            self.cx * Vec4::splat(q.x) + self.cy * Vec4::splat(q.y) + self.cz * Vec4::splat(q.z);
        Vec2::new(r.x, r.y)
    }
    fn trace_batch<T: Topology>(
        mesh: &TetMesh,
        topo: &T,
        rays: &[Ray],
        starts: Starts<'_>,
        cap: u32,
        out: &mut [TraceOutcome],
    ) {
        crate::lockstep::trace_lockstep(mesh, topo, rays, starts, cap, out)
    }
    #[inline(always)]
    fn left(&self, a: Vec2, ia: u32, b: Vec2, ib: u32) -> bool {
        left_2d!(a, ia, b, ib)
    }
}

/// f32 projection with the projected ray origin of Eq. 4–5:
/// `p = (u·P − po.x, v·P − po.y)`, `po = (u·o, v·o)` (one subtraction per
/// coordinate instead of three, less accurate far from the world origin).
#[derive(Clone, Copy, Debug)]
pub struct OriginF32 {
    po: Vec2,
    u: Vec3,
    v: Vec3,
}

impl Projection for OriginF32 {
    type P = Vec2;
    simd_face!();
    const NAME: &'static str = "f32-po";
    fn setup(ray: &Ray) -> Self {
        let (u, v) = duff_basis(ray.direction.as_dvec3().normalize());
        let (u, v) = (u.as_vec3(), v.as_vec3());
        OriginF32 {
            po: Vec2::new(u.dot(ray.origin), v.dot(ray.origin)),
            u,
            v,
        }
    }
    #[inline(always)]
    fn project(&self, p: Vec3) -> Vec2 {
        Vec2::new(self.u.dot(p) - self.po.x, self.v.dot(p) - self.po.y)
    }
    #[inline(always)]
    fn left(&self, a: Vec2, ia: u32, b: Vec2, ib: u32) -> bool {
        left_2d!(a, ia, b, ib)
    }
}

/// f64 variant of [`DuffF32`] (points converted exactly to f64).
#[derive(Clone, Copy, Debug)]
pub struct DuffF64 {
    o: DVec3,
    u: DVec3,
    v: DVec3,
}

impl Projection for DuffF64 {
    type P = DVec2;
    array_face!(DVec2);
    const NAME: &'static str = "f64";
    fn setup(ray: &Ray) -> Self {
        let (u, v) = duff_basis(ray.direction.as_dvec3().normalize());
        DuffF64 {
            o: ray.origin.as_dvec3(),
            u,
            v,
        }
    }
    #[inline(always)]
    fn project(&self, p: Vec3) -> DVec2 {
        let q = p.as_dvec3() - self.o;
        DVec2::new(self.u.dot(q), self.v.dot(q))
    }
    #[inline(always)]
    fn left(&self, a: DVec2, ia: u32, b: DVec2, ib: u32) -> bool {
        left_2d!(a, ia, b, ib)
    }
}

/// 3-D scalar triple products (Lagae & Dutré): a vertex maps to `q = P − o`
/// and the ray passes left of edge `a → b` when `d · (qa × qb) > 0`
/// (= `det(pa, pb)` up to a positive factor). `a × b = −(b × a)`
/// component-wise exactly, so the product is exactly antisymmetric. Zero is
/// decided as in 2-D by perturbing the origin by `ε u + ε² v` (`u, v` the
/// Duff basis): first `sign((qa − qb) · v)`, then `sign((qb − qa) · u)`, then
/// the vertex indices (`a < b` ⇒ left), each antisymmetric.
#[derive(Clone, Copy, Debug, Default)]
pub struct TripleF32 {
    o: Vec3,
    d: Vec3,
    u: Vec3,
    v: Vec3,
}

impl TripleF32 {
    /// The ray's origin and direction (for the SIMD lockstep walk).
    pub(crate) fn origin_direction(&self) -> (Vec3, Vec3) {
        (self.o, self.d)
    }

    #[cold]
    #[inline(never)]
    pub(crate) fn left_mask_ties(&self, pd: Vec3, d: u32, f: &[Vec3; 3], ids: &[u32; 3]) -> usize {
        self.left(pd, d, f[0], ids[0]) as usize
            | (self.left(pd, d, f[1], ids[1]) as usize) << 1
            | (self.left(pd, d, f[2], ids[2]) as usize) << 2
    }
}

impl Projection for TripleF32 {
    type P = Vec3;
    array_face!(Vec3, no_mask);
    /// The three triple products first, branch-free; the tie rule of
    /// [`TripleF32::left`] only when one of them is zero (same products, so
    /// the same bits as three `left` calls).
    #[inline(always)]
    fn left_mask(&self, pd: Vec3, d: u32, f: &[Vec3; 3], ids: &[u32; 3]) -> usize {
        let s = f.map(|p| self.d.dot(pd.cross(p)));
        if (s[0] != 0.0) & (s[1] != 0.0) & (s[2] != 0.0) {
            (s[0] > 0.0) as usize | ((s[1] > 0.0) as usize) << 1 | ((s[2] > 0.0) as usize) << 2
        } else {
            self.left_mask_ties(pd, d, f, ids)
        }
    }
    const NAME: &'static str = "f32-stp";
    /// On x86-64 with AVX-512F over the baseline layout: 16 lanes in
    /// lockstep (`crate::sctp_lockstep`, identical outcomes); otherwise
    /// the scalar interleaved walk.
    fn trace_batch<T: Topology>(
        mesh: &TetMesh,
        topo: &T,
        rays: &[Ray],
        starts: Starts<'_>,
        cap: u32,
        out: &mut [TraceOutcome],
    ) {
        #[cfg(target_arch = "x86_64")]
        if crate::sctp_lockstep::trace(mesh, topo, rays, starts, cap, out) {
            return;
        }
        trace_interleaved::<Self, T, { crate::kernel::LANES }>(mesh, topo, rays, starts, cap, out)
    }
    fn setup(ray: &Ray) -> Self {
        let (u, v) = duff_basis(ray.direction.as_dvec3().normalize());
        TripleF32 {
            o: ray.origin,
            d: ray.direction,
            u: u.as_vec3(),
            v: v.as_vec3(),
        }
    }
    #[inline(always)]
    fn project(&self, p: Vec3) -> Vec3 {
        p - self.o
    }
    #[inline(always)]
    fn left(&self, a: Vec3, ia: u32, b: Vec3, ib: u32) -> bool {
        let s = self.d.dot(a.cross(b));
        if s != 0.0 {
            return s > 0.0;
        }
        let e = a - b;
        let y = e.dot(self.v);
        if y != 0.0 {
            return y > 0.0;
        }
        let x = e.dot(self.u);
        if x != 0.0 { x < 0.0 } else { ia < ib }
    }
}

/// The hot connectivity of a layout, as the walk needs it.
pub trait Topology: Sync {
    /// Xor of the four vertex indices of `tet` (paper `VX^i`).
    fn vx(&self, tet: u32) -> u32;
    /// Raw [`Link`] of `tet` across the face opposite vertex `exiting`.
    ///
    /// `face` is the entry face, `d` the fourth vertex, `exiting ∈ face`,
    /// `entry_raw` the raw link of `tet` across the entry face (the previous
    /// tet, or the constrained face crossed), which Tet16 needs.
    fn exit_link(&self, tet: u32, face: [u32; 3], d: u32, exiting: u32, entry_raw: u32) -> u32;
    /// Hints that the record of `tet` (an index that may be out of range:
    /// a prefetch never faults) will be read soon. Default: nothing.
    #[inline(always)]
    fn prefetch(&self, tet: u32) {
        let _ = tet;
    }
    /// The records as 32-bit words for the gathers of the SIMD lockstep walk
    /// ([`crate::lockstep`]); `None` (the default) makes it read them through
    /// [`Topology::vx`] and [`Topology::exit_link`] lane by lane.
    #[inline(always)]
    fn record_words(&self) -> Option<crate::lockstep::RecordWords<'_>> {
        None
    }
}

/// Prefetches the cache line holding `slice[index]` into all cache levels
/// (x86-64 `prefetcht0`; nothing elsewhere). Never reads memory
/// architecturally, so an out-of-range index is harmless: the address is
/// formed with `wrapping_add` and never dereferenced.
#[inline(always)]
pub fn prefetch_index<X>(slice: &[X], index: u32) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        let ptr = slice.as_ptr().wrapping_add(index as usize) as *const i8;
        // SAFETY: `prefetcht0` is a hint; it never faults and has no
        // architectural effect, whatever the address (SSE is part of the
        // x86-64 baseline).
        unsafe { _mm_prefetch::<_MM_HINT_T0>(ptr) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = (slice, index);
    }
}

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
    /// Entering the mesh from outside: the ray's origin lies outside the
    /// mesh and its line enters `tet` through that tet's boundary face
    /// `face` (0..=3, opposite vertex slot `face`, linked to
    /// [`Link::BOUNDARY`]), ahead of the origin. Nothing lies outside the
    /// mesh, so the walk starts there; see [`crate::entry`], which finds it
    /// (and resolves a constrained face on the boundary itself).
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

/// The starts of a batch of rays: one for all (primary rays from a viewpoint
/// inside the mesh), one per ray, or each ray's entry into the mesh from
/// outside.
#[derive(Clone, Copy, Debug)]
pub enum Starts<'a> {
    /// Every ray starts from this.
    Same(Start),
    /// Ray `i` starts from element `i` (same length as the rays).
    Each(&'a [Start]),
    /// Every ray's origin lies outside the mesh: each enters through the
    /// boundary face its line crosses, decided with the walk's own
    /// projection ([`BoundaryEntry::start_with`]).
    Outside(&'a BoundaryEntry),
}

/// Which slot of the counter-clockwise entry face `(a, b, c)` the new vertex
/// `d` replaces (paper Algorithm 1): the exit face is the entry face with that
/// slot replaced by `d`.
///
/// Algorithm 1 as written: if the ray is left of `d → a`, the exit face is
/// `(a, b, d)` (slot 2) when it is right of `d → b`, else `(d, b, c)` (slot
/// 0); if it is right of `d → a`, the exit face is `(c, a, d)` (slot 1) when
/// it is left of `d → c`, else slot 0. That needs two edge tests but a
/// data-dependent branch per step that mispredicts about half the time, so
/// the three signs are computed branch-free and the same decision is looked
/// up in [`EXIT_SLOT`] (one more determinant, no misprediction). Both forms
/// give identical results (the table ignores `d → c` when left of `d → a`
/// and `d → b` otherwise), so the watertightness argument is unchanged.
#[inline(always)]
pub fn exit_slot<P: Projection>(
    proj: &P,
    p: &[P::P; 3],
    ids: &[u32; 3],
    pd: P::P,
    d: u32,
) -> usize {
    EXIT_SLOT[proj.left_mask(pd, d, &P::face(*p), ids) & 7] as usize
}

/// Algorithm 1 as a table over `left(d→a) | left(d→b) << 1 | left(d→c) << 2`.
pub const EXIT_SLOT: [u8; 8] = [0, 2, 0, 0, 1, 2, 1, 0];

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
    let state = |k: usize| {
        let [a, b, c] = FACE_VERTICES[k];
        State {
            tet,
            ids: [v[a], v[b], v[c]],
            p: P::face([p[a], p[b], p[c]]),
            link: mesh.neighbors[tet as usize][k].0,
            visited: 1,
        }
    };
    for (k, s) in FACE_VERTICES.iter().enumerate() {
        let [a, b, c] = *s;
        if proj.left(p[a], v[a], p[b], v[b])
            && proj.left(p[b], v[b], p[c], v[c])
            && proj.left(p[c], v[c], p[a], v[a])
        {
            return Some(state(k));
        }
    }
    None
}

/// Last resort when rounding left no tet around the origin with a
/// counter-clockwise exit face: the face of `tet` whose smallest f64 edge
/// function `d · (qa × qb)` is largest (the face the line leaves through, up
/// to rounding).
fn start_fallback<P: Projection>(mesh: &TetMesh, proj: &P, ray: &Ray, tet: u32) -> State<P> {
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
    let [a, b, c] = FACE_VERTICES[k];
    let ids = [v[a], v[b], v[c]];
    State {
        tet,
        ids,
        p: P::face(ids.map(|i| proj.project(mesh.points[i as usize]))),
        link: mesh.neighbors[tet as usize][k].0,
        visited: 1,
    }
}

/// The tet around the ray origin and the face through which the ray line
/// leaves it (the `start_in_tet` search of [`trace`], with its fallback to the
/// other tets around an origin on a face, edge or vertex).
pub fn start_exit_face<P: Projection>(mesh: &TetMesh, ray: &Ray, tet: u32) -> Option<(u32, usize)> {
    let proj = P::setup(ray);
    let found = |t: u32| {
        start_in_tet(mesh, &proj, t).map(|s| {
            let k = (0..4)
                .find(|&k| {
                    mesh.neighbors[t as usize][k].0 == s.link && {
                        let f = mesh.face_vertices(t, k);
                        f.contains(&s.ids[0]) && f.contains(&s.ids[1]) && f.contains(&s.ids[2])
                    }
                })
                .unwrap_or(0);
            (t, k)
        })
    };
    found(tet)
        .or_else(|| {
            star(mesh, ray.origin, tet, 256)
                .into_iter()
                .skip(1)
                .find_map(found)
        })
        .or_else(|| {
            let s = start_fallback(mesh, &proj, ray, tet);
            let k = (0..4).find(|&k| {
                mesh.neighbors[tet as usize][k].0 == s.link && {
                    let f = mesh.face_vertices(tet, k);
                    s.ids.iter().all(|i| f.contains(i))
                }
            })?;
            Some((tet, k))
        })
}

/// One ray in flight: its projection, walk state, the tet it enters next
/// and the raw link it enters through.
pub(crate) struct Lane<P: Projection> {
    pub(crate) proj: P,
    pub(crate) st: State<P>,
    pub(crate) next: u32,
    pub(crate) entry_raw: u32,
}

/// Traces `ray` from `start` with projection `P` over layout `topo`, visiting
/// at most `cap` tets. `mesh` provides the cold data (points, start tet,
/// constrained-face table) and must be the mesh `topo` was built from.
pub fn trace<P: Projection, T: Topology>(
    mesh: &TetMesh,
    topo: &T,
    ray: &Ray,
    start: Start,
    cap: u32,
) -> TraceOutcome {
    let mut lane = match begin::<P>(mesh, ray, start) {
        Ok(lane) => lane,
        Err(out) => return out,
    };
    let points = &mesh.points[..];
    loop {
        let adv = advance(points, topo, &mut lane, cap);
        if adv != Advance::Go
            && let Some(out) = finish_step(mesh, ray, &mut lane, adv)
        {
            return out;
        }
    }
}

/// Traces many rays (ray `i` from `starts.of(i)`) with `K` walks interleaved on one thread:
/// each round advances every lane by one tet, so the CPU overlaps the
/// dependent load → project → decide → load chains of independent rays
/// (memory-level parallelism without SIMD). Each step prefetches the record
/// of the lane's next tet, which that lane reads a round later.
/// Results are identical to [`trace`] ray by ray (same `advance` and
/// `finish_step`). `out.len()` must equal `rays.len()`.
pub fn trace_interleaved<P: Projection, T: Topology, const K: usize>(
    mesh: &TetMesh,
    topo: &T,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
) {
    let n = rays.len().min(out.len());
    let (rays, out) = (&rays[..n], &mut out[..n]);
    let points = &mesh.points[..];
    let mut queued = Queue::default();
    // Lanes in flight, each with its ray index; a finished lane is replaced
    // in place by the next ray, or removed when none is left.
    let mut lanes: Vec<(usize, Lane<P>)> = Vec::with_capacity(K);
    while lanes.len() < K {
        match next_lane(mesh, rays, start, &mut queued, out) {
            Some(l) => lanes.push(l),
            None => break,
        }
    }
    while !lanes.is_empty() {
        let mut j = 0;
        while j < lanes.len() {
            let adv = advance(points, topo, &mut lanes[j].1, cap);
            if adv == Advance::Go
                || lane_event(mesh, rays, start, &mut queued, out, &mut lanes, j, adv)
            {
                j += 1;
            }
        }
    }
}

/// The out-of-line part of [`trace_interleaved`]'s round: lane `j` stopped
/// with `adv`; finish its step, and when its walk ended, store the outcome
/// and refill or remove the lane. True when `lanes[j]` is (still) a live
/// lane that already took its step this round.
#[cold]
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn lane_event<P: Projection>(
    mesh: &TetMesh,
    rays: &[Ray],
    start: Starts<'_>,
    queued: &mut Queue,
    out: &mut [TraceOutcome],
    lanes: &mut Vec<(usize, Lane<P>)>,
    j: usize,
    adv: Advance,
) -> bool {
    let (i, lane) = &mut lanes[j];
    let i = *i;
    let Some(o) = finish_step(mesh, &rays[i], lane, adv) else {
        return true;
    };
    out[i] = o;
    match next_lane(mesh, rays, start, queued, out) {
        Some(l) => {
            lanes[j] = l;
            true
        }
        None => {
            lanes.swap_remove(j);
            false
        }
    }
}

/// The rays of a batch not started yet: the next one, and the boundary
/// face the last ray from outside entered through (tested first for the
/// next, see [`crate::entry`]).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Queue {
    next: usize,
    hint: EntryHint,
}

/// Starts the next queued ray that does not end before its walk (those are
/// written to `out` directly).
#[inline(always)]
pub(crate) fn next_lane<P: Projection>(
    mesh: &TetMesh,
    rays: &[Ray],
    start: Starts<'_>,
    queue: &mut Queue,
    out: &mut [TraceOutcome],
) -> Option<(usize, Lane<P>)> {
    while queue.next < rays.len() {
        let i = queue.next;
        queue.next += 1;
        let ray = &rays[i];
        let lane = match start {
            Starts::Same(s) => begin::<P>(mesh, ray, s),
            Starts::Each(s) => begin::<P>(mesh, ray, s[i]),
            Starts::Outside(entry) => begin_outside::<P>(mesh, ray, entry, &mut queue.hint),
        };
        match lane {
            Ok(l) => return Some((i, l)),
            Err(o) => out[i] = o,
        }
    }
    None
}

/// [`begin`] for a ray from outside the mesh: its entry is decided with the
/// projection the walk then uses (set up once).
#[inline(always)]
fn begin_outside<P: Projection>(
    mesh: &TetMesh,
    ray: &Ray,
    entry: &BoundaryEntry,
    hint: &mut EntryHint,
) -> Result<Lane<P>, TraceOutcome> {
    if !ray.is_valid() {
        return Err(TraceOutcome::Failed {
            failure: Failure::InvalidRay,
            tets_visited: 0,
        });
    }
    let proj = P::setup(ray);
    let start = entry.start_projected(mesh, ray, &proj, hint)?;
    begin_with(mesh, ray, proj, start)
}

/// Everything before the hot loop: ray checks, projection set-up, the start
/// tet's exit face (or the restart on a constrained face) and its link.
/// `Err` when the walk already ended (invalid ray, hit or miss in the start
/// tet).
fn begin<P: Projection>(mesh: &TetMesh, ray: &Ray, start: Start) -> Result<Lane<P>, TraceOutcome> {
    if !ray.is_valid() {
        return Err(TraceOutcome::Failed {
            failure: Failure::InvalidRay,
            tets_visited: 0,
        });
    }
    begin_with(mesh, ray, P::setup(ray), start)
}

/// [`begin`] of a valid ray whose projection `proj` is set up.
#[inline(always)]
fn begin_with<P: Projection>(
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
                    let found = star(mesh, ray.origin, t, 256)
                        .into_iter()
                        .skip(1)
                        .find_map(|c| start_in_tet(mesh, &proj, c));
                    found.unwrap_or_else(|| start_fallback(mesh, &proj, ray, t))
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
                Start::Entry { tet, face } => {
                    mesh.is_boundary_face(tet, face)
                        .then_some((tet, face as usize, Link::BOUNDARY))
                }
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
    }
}

pub(crate) enum Resolved {
    Done(TraceOutcome),
    Cross(u32),
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

/// The ray reached constrained face `c` (vertices `ids`) from tet `tet`
/// (`NO_TET`: from outside the mesh) after `visited` tets: a hit, a miss
/// beyond `t_max`, or a crossing into the far side when before `t_min`.
pub(crate) fn resolve_constrained(
    mesh: &TetMesh,
    ray: &Ray,
    c: u32,
    ids: [u32; 3],
    tet: u32,
    visited: u32,
) -> Resolved {
    let cf = &mesh.constrained[c as usize];
    let (t, w) = face_hit(mesh, ray, ids);
    if t < ray.t_min as f64 {
        return match cf.other_side(tet) {
            Some(s) if s.exists() => Resolved::Cross(s.tet),
            _ => Resolved::Done(TraceOutcome::Miss {
                tets_visited: visited,
            }),
        };
    }
    if t > ray.t_max as f64 {
        return Resolved::Done(TraceOutcome::Miss {
            tets_visited: visited,
        });
    }
    let mut bary = [0f32; 3];
    for (k, &vk) in cf.vertices.iter().enumerate() {
        let j = ids.iter().position(|&x| x == vk).unwrap_or(k);
        bary[k] = w[j] as f32;
    }
    if degenerate_crossing(t, &bary) {
        return Resolved::Done(TraceOutcome::Failed {
            failure: Failure::Lost,
            tets_visited: visited,
        });
    }
    let far = cf.other_side(tet).map_or(NO_TET, |s| s.tet);
    Resolved::Done(TraceOutcome::Hit(Hit {
        triangle: cf.triangle,
        face: c,
        t: t as f32,
        barycentrics: bary,
        tet,
        far_tet: far,
        tets_visited: visited,
    }))
}

/// True when a crossing's hit record would hold infinities: the ray runs
/// (numerically) inside the face's plane, e.g. a direction mixing subnormal
/// and ordinary components. Kernels report such a walk as
/// [`Failure::Lost`] instead of returning a meaningless hit.
pub(crate) fn degenerate_crossing(t: f64, bary: &[f32; 3]) -> bool {
    !(t as f32).is_finite() || bary.iter().any(|b| !b.is_finite())
}

/// Ray parameter and barycentrics (w.r.t. `ids`) of the line's crossing with
/// triangle `ids`, in f64 (computed once per ray, at the hit).
pub fn face_hit(mesh: &TetMesh, ray: &Ray, ids: [u32; 3]) -> (f64, [f64; 3]) {
    let o = ray.origin.as_dvec3();
    let d = ray.direction.as_dvec3();
    let q = ids.map(|i| mesh.points[i as usize].as_dvec3() - o);
    let w = [
        d.dot(q[1].cross(q[2])),
        d.dot(q[2].cross(q[0])),
        d.dot(q[0].cross(q[1])),
    ];
    let sum = w[0] + w[1] + w[2];
    let w = if sum != 0.0 && sum.is_finite() {
        w.map(|x| x / sum)
    } else {
        [1.0 / 3.0; 3]
    };
    let hit = q[0] * w[0] + q[1] * w[1] + q[2] * w[2];
    (hit.dot(d) / d.length_squared(), w)
}

/// What one [`advance`] did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Advance {
    /// Entered a tet and moved to its exit neighbour: keep walking.
    Go,
    /// The step cap was reached before the step (state unchanged).
    Cap,
    /// The new vertex id was out of range (state unchanged; impossible on a
    /// valid layout, reported instead of panicking).
    Lost,
    /// Entered a tet whose exit link is not a tet (constrained face or
    /// boundary): `finish_step` resolves it.
    Face,
}

/// The hot loop body: enter `lane.next` through the face `lane.st.ids`
/// (raw back-link `lane.entry_raw`), choose the exit face, follow its link
/// when it is a tet. Everything rarer (a constrained face or the boundary,
/// the step cap) is left to the out-of-line `finish_step`.
#[inline(always)]
pub(crate) fn advance<P: Projection, T: Topology>(
    points: &[Vec3],
    topo: &T,
    lane: &mut Lane<P>,
    cap: u32,
) -> Advance {
    let st = &mut lane.st;
    if st.visited >= cap {
        return Advance::Cap;
    }
    let next = lane.next;
    let d = st.ids[0] ^ st.ids[1] ^ st.ids[2] ^ topo.vx(next);
    let Some(&pd3) = points.get(d as usize) else {
        return Advance::Lost;
    };
    let pd = lane.proj.project(pd3);
    // `EXIT_SLOT` holds 0..=2, so `min(·, 2)` is the identity; it only lets
    // the compiler drop the bounds checks of the indexings below.
    let slot = usize::min(
        EXIT_SLOT[lane.proj.left_mask(pd, d, &st.p, &st.ids) & 7] as usize,
        2,
    );
    let exiting = st.ids[slot];
    let raw = topo.exit_link(next, st.ids, d, exiting, lane.entry_raw);
    // The lane state lives in memory (several lanes are in flight), so a
    // variable-indexed store is one instruction per array.
    st.ids[slot] = d;
    P::set_point(&mut st.p, slot, pd);
    st.visited += 1;
    if raw < Link::BOUNDARY.0 {
        topo.prefetch(raw);
        lane.entry_raw = next;
        lane.next = raw;
        Advance::Go
    } else {
        // `tet` and `link` are read only when resolving a face.
        st.tet = next;
        st.link = raw;
        Advance::Face
    }
}

/// What a SIMD slot does after its lane stopped in a round.
pub(crate) enum AfterStop<P: Projection> {
    /// The ray crossed a constrained face before `t_min` and walks on:
    /// its next tet, entered through the raw link it stopped at.
    Cross(u32),
    /// Its walk ended (outcome stored): load this ray and lane instead.
    Refill(usize, Lane<P>),
    /// Its walk ended and the batch has no ray left: park the slot.
    Park,
}

/// The cold path of the SIMD walks: ray `i` stopped with `adv` (see
/// [`Advance::stopped`]) in tet `tet` entered through face `ids`, after
/// `visited` tets, at exit link `link` (the fields [`stop`] needs, read from
/// the walk's registers). Stores its outcome when its walk ended and starts
/// the next queued ray.
#[allow(clippy::too_many_arguments)]
pub(crate) fn after_stop<P: Projection>(
    mesh: &TetMesh,
    rays: &[Ray],
    start: Starts<'_>,
    queued: &mut Queue,
    out: &mut [TraceOutcome],
    i: usize,
    adv: Advance,
    ids: [u32; 3],
    tet: u32,
    visited: u32,
    link: u32,
) -> AfterStop<P> {
    match stop(mesh, &rays[i], adv, ids, tet, visited, link) {
        Resolved::Cross(n) => AfterStop::Cross(n),
        Resolved::Done(o) => {
            out[i] = o;
            match next_lane::<P>(mesh, rays, start, queued, out) {
                Some((j, lane)) => AfterStop::Refill(j, lane),
                None => AfterStop::Park,
            }
        }
    }
}

/// The rare outcomes of [`advance`]: `Some` when the walk ended, `None` when
/// it crossed a constrained face before `t_min` and goes on.
#[cold]
#[inline(never)]
pub(crate) fn finish_step<P: Projection>(
    mesh: &TetMesh,
    ray: &Ray,
    lane: &mut Lane<P>,
    adv: Advance,
) -> Option<TraceOutcome> {
    if adv == Advance::Go {
        return None;
    }
    let st = &lane.st;
    match stop(mesh, ray, adv, st.ids, st.tet, st.visited, st.link) {
        Resolved::Done(out) => Some(out),
        Resolved::Cross(n) => {
            lane.entry_raw = st.link;
            lane.next = n;
            None
        }
    }
}

/// Where a walk that stopped with `adv` (not [`Advance::Go`]) goes, from
/// the few fields this needs: the entry face `ids` of tet `tet` just
/// entered, the tets `visited` and the exit link `link`. The SIMD walks call
/// it with fields read from their registers.
pub(crate) fn stop(
    mesh: &TetMesh,
    ray: &Ray,
    adv: Advance,
    ids: [u32; 3],
    tet: u32,
    visited: u32,
    link: u32,
) -> Resolved {
    let failed = |failure| {
        Resolved::Done(TraceOutcome::Failed {
            failure,
            tets_visited: visited,
        })
    };
    match adv {
        Advance::Cap => failed(Failure::StepCap),
        Advance::Lost => failed(Failure::Lost),
        Advance::Go | Advance::Face => match Link(link).as_constrained() {
            Some(c) => resolve_constrained(mesh, ray, c, ids, tet, visited),
            None => Resolved::Done(TraceOutcome::Miss {
                tets_visited: visited,
            }),
        },
    }
}

impl Advance {
    /// The stop of a SIMD lane that did not move on in a round, checked in
    /// the order of [`advance`]: the step cap, then a new vertex out of
    /// range, else a non-tet exit link.
    pub(crate) fn stopped(capped: bool, lost: bool) -> Advance {
        if capped {
            Advance::Cap
        } else if lost {
            Advance::Lost
        } else {
            Advance::Face
        }
    }
}

/// Default step cap for a mesh: `2 × tets + 1024`, at most
/// [`DEFAULT_STEP_CAP`] (a straight walk never visits a tet twice).
pub fn step_cap(mesh: &TetMesh) -> u32 {
    (2 * mesh.tets.len() as u64 + 1024).min(DEFAULT_STEP_CAP as u64) as u32
}

#[cfg(test)]
mod tests {
    use super::*;
    use tet_core::synthetic::SplitMix64;

    fn rnd(rng: &mut SplitMix64) -> f32 {
        // Wide dynamic range, with exact repeats and zeros.
        match rng.next_u64() % 8 {
            0 => 0.0,
            1 => 1.0,
            _ => rng.range_f32(-1.0, 1.0) * 2f32.powi((rng.next_u64() % 20) as i32 - 10),
        }
    }

    #[test]
    fn edge_test_is_exactly_antisymmetric_with_ties() {
        let mut rng = SplitMix64(3);
        let ray = Ray::new(Vec3::new(0.1, 0.2, 0.3), Vec3::new(0.3, -0.5, 0.8));
        let p32 = DuffF32::setup(&ray);
        let p64 = DuffF64::setup(&ray);
        let pt = TripleF32::setup(&ray);
        for i in 0..20000u32 {
            let a = Vec2::new(rnd(&mut rng), rnd(&mut rng));
            let b = if i % 3 == 0 {
                a * 2.0
            } else {
                Vec2::new(rnd(&mut rng), rnd(&mut rng))
            };
            assert_ne!(p32.left(a, 1, b, 2), p32.left(b, 2, a, 1), "{a:?} {b:?}");
            let (ad, bd) = (a.as_dvec2(), b.as_dvec2());
            assert_ne!(p64.left(ad, 1, bd, 2), p64.left(bd, 2, ad, 1));
            let a3 = Vec3::new(a.x, a.y, rnd(&mut rng));
            let b3 = if i % 5 == 0 {
                a3
            } else {
                Vec3::new(b.x, b.y, rnd(&mut rng))
            };
            assert_ne!(pt.left(a3, 7, b3, 9), pt.left(b3, 9, a3, 7));
        }
    }

    #[test]
    fn tie_rule_matches_a_perturbed_origin() {
        // det = 0 with a.y > b.y: the origin moved by (ε, ε²) is left of a→b.
        let p = DuffF32::setup(&Ray::new(Vec3::ZERO, Vec3::Z));
        let (a, b) = (Vec2::new(0.0, 1.0), Vec2::new(0.0, -1.0));
        let eps = 1e-3f64;
        let exact = (b.x as f64 - a.x as f64) * (eps * eps - a.y as f64)
            - (b.y as f64 - a.y as f64) * (eps - a.x as f64);
        assert_eq!(p.left(a, 5, b, 6), exact > 0.0);
    }

    #[test]
    fn exit_table_is_algorithm_1() {
        for (i, &slot) in EXIT_SLOT.iter().enumerate() {
            let (sa, sb, sc) = (i & 1 != 0, i & 2 != 0, i & 4 != 0);
            let alg1 = if sa {
                if sb { 0 } else { 2 }
            } else if sc {
                1
            } else {
                0
            };
            assert_eq!(slot as usize, alg1, "case {i}");
        }
    }

    #[test]
    fn basis_is_right_handed_around_the_direction() {
        let mut rng = SplitMix64(8);
        for _ in 0..1000 {
            let d = crate::reference::random_direction(&mut rng)
                .as_dvec3()
                .normalize();
            let (u, v) = duff_basis(d);
            assert!((u.cross(v) - d).length() < 1e-9);
            assert!(u.dot(d).abs() < 1e-12 && v.dot(d).abs() < 1e-12);
        }
        for d in [DVec3::Z, -DVec3::Z, DVec3::X, -DVec3::Y] {
            let (u, v) = duff_basis(d);
            assert!((u.cross(v) - d).length() < 1e-12);
        }
    }
}
