//! The traversal engine shared by every kernel: a ray walks from the tet
//! containing its origin, one tet per step, until it crosses a constrained
//! face or the mesh boundary.
//!
//! # The projected (2-D) walk of Aman et al. (2022, §4, Algorithm 1)
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
//! 3. exact signs: the two products are rounded monotonically
//!    (`A ≤ B ⇒ fl(A) ≤ fl(B)`), so a non-zero rounded determinant already
//!    has the sign of the exact `pₐ.x·p_b.y − pₐ.y·p_b.x` of the rounded
//!    points; a zero is decided first by that exact determinant
//!    (`ExactDet`: the products in f64 for f32 points, the products'
//!    rounding errors by fused multiply-adds for f64 points), on the cold
//!    path only;
//! 4. one tie rule for an exact zero (the ray touches the edge's
//!    projection, e.g. it passes through a vertex or along an edge): the
//!    origin is perturbed symbolically to `(ε, ε²)` (simulation of
//!    simplicity), so a zero determinant is decided by `sign(pₐ.y − p_b.y)`,
//!    then `sign(p_b.x − pₐ.x)` (exact comparisons), and, when both points
//!    coincide (an edge parallel to the ray), by the global vertex indices
//!    (`a < b` ⇒ left). Each step is antisymmetric, so the rule never
//!    answers differently for the same edge.
//!
//! # Why the walk ends, even in the plane of flat faces
//!
//! Watertightness alone does not end a walk: consistent answers per edge
//! can still describe no line at all, and then the walk can circle. That
//! is what rays lying in the plane of flat constrained faces did (a CAD
//! part's cap, a city's wall, with the tets' faces around them in the same
//! plane): every vertex of the plane projects to within rounding of one 2-D
//! line through the origin, every edge of the plane has a determinant of
//! the size of its rounding error, and deciding those by rounded products
//! or by the perturbation alone gave answers no line could give (f32 walks
//! ran to the step cap).
//!
//! With rules 3 and 4, every decision is the exact sign, with the symbolic
//! perturbation, of a determinant of the *rounded* projected points. So the
//! walk is exactly the walk of a line through another mesh: each vertex `P`
//! moved to `P′ = o + pₓ·u + p_y·v + ((P − o)·d̂)·d̂`, i.e. by its
//! projection's rounding error (a few ulps of `|P − o|`) across the ray, and
//! the line `o + t·d` moved by `(ε, ε²)`. The moved line is in general
//! position with respect to the moved mesh whatever the input, and a line
//! meets a convex tet in one segment, so it crosses each moved tet at most
//! once: the walk visits each tet at most once and ends, as long as no tet
//! is inverted by moving its vertices a few ulps (a tet whose height is
//! below f32's rounding of its distance to the ray origin: a sliver at f32
//! precision, a limit the in-plane case does not add to). A ray in the
//! plane of flat faces is such a line too: the moved line passes just above
//! or just below each face of the plane, as the perturbation decides, and
//! may cross the plane where rounding moved its vertices; each such
//! crossing of a constrained face is a hit on that face (a ray lying in a
//! face meets it), never a loop; its hit record is the point of the face
//! the ray runs along ([`face_hit`]), not the crossing with the face's
//! plane, which lies anywhere or nowhere.
//!
//! The moved mesh has three more consequences:
//!
//! * the start: the moved mesh can leave an origin on or within rounding
//!   of a face or edge (the ray in a face's plane) just outside the tets
//!   around it, so when none of them has a counter-clockwise exit face,
//!   the tets within two faces of them are tried (`start::next_to_star`),
//!   the one the origin lies nearest outside of first (rounding moved the
//!   origin across the faces it lies within rounding of; the nearest
//!   centroid along the ray, the earlier rule, could start across the
//!   constrained face the ray was about to hit, and miss it), before the
//!   last-resort guess;
//! * the entry from outside: coplanar boundary faces moved by rounding make
//!   the boundary slightly non-convex, so a ray running in their plane may
//!   enter through several; the one nearest along the ray is taken
//!   ([`BoundaryEntry`]), whatever the search met first;
//! * tets thinner than the rounding (slivers between nearly coplanar
//!   faces of a plane f32 cannot hold exactly, e.g. a tilted CAD cap, or
//!   TetGen's near-flat tets once rounded to f32): a moved tet may be
//!   inverted, and there the walk may still circle. The step cap proves it
//!   (more tets than any line's walk), and the tracers then walk that ray
//!   again with the exact walk of [`crate::exact`] (`crate::lost`), so a
//!   default-capped walk never reports `StepCap` for such a ray; the GPU
//!   kernels, which have no exact walk, still report it.
//!
//! # Interleaving and the hot loop
//!
//! [`trace_interleaved`] walks several rays on one thread, one step each per
//! round, so the out-of-order core overlaps their dependent
//! load → project → decide → load chains; each ray's result is exactly that
//! of [`trace`] (the same `step::advance` / `step::finish_step`
//! functions). The hot step (`step::advance`) does only the common case
//! (enter a tet, leave into another tet); reaching a constrained face or the
//! boundary, the step cap and the lane refill are out of line. Each step
//! prefetches the next tet's record, which that lane reads a round later.
//! The 2-D f32 projections store the entry face as SoA vectors ([`Face2`])
//! and evaluate the projection and the three determinants in SIMD, lane by
//! lane the same IEEE operations as the scalar formulas (so the
//! watertightness argument above is unchanged); the tie rule runs only when
//! a determinant is zero. Prefetching the new vertex's point in a separate
//! pass per round, and single-ray walks, measured slower; 4, 8 and 16 lanes
//! perform alike.
//!
//! Batches of [`DuffF32`] kernels (Tet20, Tet16, Tet32) take the SIMD
//! lockstep walk of [`crate::lockstep`] instead (one ray per SIMD lane, the
//! same operations lane by lane, identical outcomes, fewer instructions per
//! step), and so do ScTP's ([`TripleF32`] on the baseline layout, with
//! AVX-512); [`crate::batch::BatchWalk`] makes that choice per projection.
//! The interleaved walk serves the other projections and stays the
//! reference ([`crate::kernel::Interleaved`]).
//!
//! Each kernel's operation count is in its module docs. The engine is generic
//! over the projection (f32, f64, projected origin of Eq. 4–5, or the 3-D
//! scalar triple products of [`crate::sctp`], which use the same decisions)
//! and over the layout ([`Topology`]), and monomorphised per pair.
//!
//! # Modules, bottom up
//!
//! * `projection`: the projections and the tie rule;
//! * `topology`: what the walk needs of a layout;
//! * `stop`: how a walk ends (hit, miss, failure, crossing);
//! * `start`: where a walk starts and its start-up;
//! * `step`: one step of Algorithm 1 and the single-ray walk;
//! * `until`: walks that end on entering given tets (shadow rays);
//! * `reach`: walks that end once past their ray's `t_max`
//!   (ambient-occlusion rays, [`trace_within`]);
//! * `entry`: the boundary face a ray from outside enters through;
//! * `lanes`: batches on one thread, the interleaved walk;
//! * `after_stop`: the stopped-lane cold path of the SIMD walks.

pub(crate) mod after_stop;
pub(crate) mod entry;
pub(crate) mod lanes;
pub(crate) mod projection;
pub(crate) mod reach;
pub(crate) mod start;
pub(crate) mod step;
pub(crate) mod stop;
pub(crate) mod topology;
pub(crate) mod until;

#[cfg(test)]
mod tests;

pub use entry::{BoundaryEntry, EntryHint, ViewpointError};
pub use lanes::{Batch, LANES, Starts, trace_interleaved};
pub(crate) use projection::left_2d;
pub(crate) use projection::left_f32;
pub(crate) use projection::simd_face;
pub use projection::{
    DuffF32, DuffF64, Face2, OriginF32, Projection, TripleF32, duff_basis, walk_scale,
};
pub use start::{Start, start_exit_face, start_scale};
pub use step::{EXIT_SLOT, exit_slot, step_cap, trace, trace_within};
pub(crate) use stop::degenerate_crossing;
pub use stop::face_hit;
pub use topology::{Topology, prefetch_index};
pub use until::{StopAt, stops_at, trace_until};
