//! The Plücker side products of the Tet80 walk in lanes ([`Side`]): how a
//! lane decides which side of an edge `V_e → X` from the entry face's
//! complement vertex `V_e` (the apex) its ray passes, exactly as the scalar
//! `tet80` walk does — [`Faithful`] in the frame of the apex (Maria et
//! al.), [`Consistent`] from the two vertices projected into the ray's
//! 2-D frame ([`DuffF32`], `tet80-consistent`).

use glam::Vec2;

use super::geometry::{Planar, PlanarRay, Projected};
use super::lanes::Lanes;
use crate::ray::Ray;
use crate::walk::{DuffF32, Projection};

/// One side rule of the Tet80 walk over lanes `L`.
pub(crate) trait Side<L: Lanes> {
    /// True when an edge value can be zero and then needs the scalar tie
    /// rule (the consistent rule); false when zero is simply "right".
    const TIES: bool;
    /// The per-ray constants, in registers.
    type Ray: Copy;
    /// What every side product of a tet shares: computed once from the apex.
    type Apex: Copy;
    /// What the tie rule needs of the other vertex of an edge.
    type Vert: Copy;

    /// Every register zero.
    fn zero(l: L) -> Self::Ray;
    /// Loads ray `r` into lane `k`, with the consistent walk's projection
    /// factor `scale`.
    fn put(l: L, k: usize, ray: &mut Self::Ray, r: &Ray, scale: f32);
    /// The per-tet part of the side products, from the apex `v` (`[axis]`).
    fn apex(l: L, ray: &Self::Ray, v: &[L::F; 3]) -> Self::Apex;
    /// The edge apex → `x`: the lanes whose ray passes left of it, the
    /// lanes whose value is zero (only with [`Side::TIES`]), and what the
    /// tie rule needs of `x`.
    fn side(l: L, ray: &Self::Ray, apex: &Self::Apex, x: &[L::F; 3]) -> (L::M, L::M, Self::Vert);
    /// Lane `k` of the projected apex (for the tie rule).
    fn apex_2d(apex: &Self::Apex, k: usize) -> Vec2;
    /// Lane `k` of the projected `x` (for the tie rule).
    fn vert_2d(v: &Self::Vert, k: usize) -> Vec2;
}

/// Maria et al.'s side product in the frame of the apex `V`:
/// `left(V → X) = (X − V) · m > 0` with `m = d × (V − o)`, glam's `cross`
/// and `dot` operand for operand (`Side::<false>` of the scalar walk).
pub(crate) struct Faithful;

/// A lane's ray: origin and direction.
#[derive(Clone, Copy)]
pub(crate) struct FaithfulRay<F> {
    o: [F; 3],
    d: [F; 3],
}

impl<L: Lanes> Side<L> for Faithful {
    const TIES: bool = false;
    type Ray = FaithfulRay<L::F>;
    /// The apex and `m = d × (V − o)`.
    type Apex = ([L::F; 3], [L::F; 3]);
    type Vert = ();

    #[inline(always)]
    fn zero(l: L) -> Self::Ray {
        let z = l.splat_f(0.0);
        FaithfulRay {
            o: [z; 3],
            d: [z; 3],
        }
    }
    #[inline(always)]
    fn put(l: L, k: usize, ray: &mut Self::Ray, r: &Ray, _: f32) {
        for a in 0..3 {
            ray.o[a] = l.set_f(ray.o[a], k, r.origin[a]);
            ray.d[a] = l.set_f(ray.d[a], k, r.direction[a]);
        }
    }
    #[inline(always)]
    fn apex(l: L, ray: &Self::Ray, v: &[L::F; 3]) -> Self::Apex {
        let q = [
            l.sub_f(v[0], ray.o[0]),
            l.sub_f(v[1], ray.o[1]),
            l.sub_f(v[2], ray.o[2]),
        ];
        // glam's `d.cross(q)`: `(d.y·q.z − q.y·d.z, d.z·q.x − q.z·d.x,
        // d.x·q.y − q.x·d.y)`.
        let d = &ray.d;
        let m = [
            l.sub_f(l.mul_f(d[1], q[2]), l.mul_f(q[1], d[2])),
            l.sub_f(l.mul_f(d[2], q[0]), l.mul_f(q[2], d[0])),
            l.sub_f(l.mul_f(d[0], q[1]), l.mul_f(q[0], d[1])),
        ];
        (*v, m)
    }
    #[inline(always)]
    fn side(l: L, _: &Self::Ray, (v, m): &Self::Apex, x: &[L::F; 3]) -> (L::M, L::M, ()) {
        let e = [
            l.sub_f(x[0], v[0]),
            l.sub_f(x[1], v[1]),
            l.sub_f(x[2], v[2]),
        ];
        // glam's `e.dot(m)`: `(e.x·m.x + e.y·m.y) + e.z·m.z`.
        let s = l.add_f(
            l.add_f(l.mul_f(e[0], m[0]), l.mul_f(e[1], m[1])),
            l.mul_f(e[2], m[2]),
        );
        (l.gt_f(s, l.splat_f(0.0)), l.mask_of_bits(0), ())
    }
    #[inline(always)]
    fn apex_2d(_: &Self::Apex, _: usize) -> Vec2 {
        Vec2::ZERO
    }
    #[inline(always)]
    fn vert_2d(_: &(), _: usize) -> Vec2 {
        Vec2::ZERO
    }
}

/// The consistent side product: `det(V′, X′) = V′ₓ·X′_y − V′_y·X′ₓ` of the
/// two vertices projected by [`DuffF32`] (the same expression as
/// `DuffF32::project` and the `left_2d` rule's determinant), zero decided
/// by the scalar tie rule (`Side::<true>` of the scalar walk).
pub(crate) struct Consistent;

impl<L: Lanes> Side<L> for Consistent {
    const TIES: bool = true;
    type Ray = PlanarRay<L::F>;
    /// The projected apex.
    type Apex = [L::F; 2];
    /// The projected `x`.
    type Vert = [L::F; 2];

    #[inline(always)]
    fn zero(l: L) -> Self::Ray {
        <Planar as Projected<L>>::zero(l).0
    }
    #[inline(always)]
    fn put(l: L, k: usize, ray: &mut Self::Ray, r: &Ray, scale: f32) {
        ray.set(l, k, &DuffF32::setup_scaled(r, scale));
    }
    #[inline(always)]
    fn apex(l: L, ray: &Self::Ray, v: &[L::F; 3]) -> Self::Apex {
        <Planar as Projected<L>>::project(l, ray, *v)
    }
    #[inline(always)]
    fn side(l: L, ray: &Self::Ray, pa: &Self::Apex, x: &[L::F; 3]) -> (L::M, L::M, Self::Vert) {
        let px = <Planar as Projected<L>>::project(l, ray, *x);
        let det = l.sub_f(l.mul_f(pa[0], px[1]), l.mul_f(pa[1], px[0]));
        let z = l.splat_f(0.0);
        (l.gt_f(det, z), l.eq_f(det, z), px)
    }
    #[inline(always)]
    fn apex_2d(pa: &Self::Apex, k: usize) -> Vec2 {
        Vec2::new(L::f_lanes(pa[0]).as_ref()[k], L::f_lanes(pa[1]).as_ref()[k])
    }
    #[inline(always)]
    fn vert_2d(px: &Self::Vert, k: usize) -> Vec2 {
        Vec2::new(L::f_lanes(px[0]).as_ref()[k], L::f_lanes(px[1]).as_ref()[k])
    }
}
