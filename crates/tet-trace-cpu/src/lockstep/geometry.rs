//! What a lane of the projected walk computes of the new vertex
//! ([`Projected`]): its projection
//! and the three edge tests against the entry face, in lanes, as the
//! scalar projection does — [`Planar`] for the 2-D projection
//! [`DuffF32`] (Tet20, Tet16, Tet32), [`Triple`] for ScTP's scalar triple
//! products [`TripleF32`].

use glam::{Vec2, Vec3};

use super::lanes::Lanes;
use crate::walk::Projection;
use crate::walk::projection::{DuffF32, Face2, TripleF32};
use crate::walk::start::Lane;

/// The projection side of a lockstep walk over lanes `L`.
pub(crate) trait Projected<L: Lanes> {
    /// The scalar projection each lane evaluates.
    type Proj: Projection;
    /// The per-ray constants, in registers.
    type Ray: Copy;
    /// A projected vertex, in registers.
    type Vert: Copy;
    /// What a lane's tie rule needs besides the registers.
    type Cold: Copy + Default;

    /// Every register zero.
    fn zero(l: L) -> (Self::Ray, Self::Vert);
    /// Loads the ray and entry face of scalar lane `lane` into lane `k`;
    /// returns its cold part.
    fn put(
        l: L,
        k: usize,
        ray: &mut Self::Ray,
        face: &mut [Self::Vert; 3],
        lane: &Lane<Self::Proj>,
    ) -> Self::Cold;
    /// Projects the points `p` (`[axis]`).
    fn project(l: L, ray: &Self::Ray, p: [L::F; 3]) -> Self::Vert;
    /// The three edge values whose signs are the scalar `left` of `v` and
    /// face vertex `i` (zero: the tie rule decides).
    fn edges(l: L, ray: &Self::Ray, v: &Self::Vert, face: &[Self::Vert; 3]) -> [L::F; 3];
    /// `t` in the lanes of `m`, `f` elsewhere.
    fn select(l: L, m: L::M, t: Self::Vert, f: Self::Vert) -> Self::Vert;
    /// The scalar tie rule of lane `k`: the three edge tests as a bit mask
    /// (`Projection::left_mask` of the lane, rare path).
    fn tie_mask(
        cold: &Self::Cold,
        face: &[Self::Vert; 3],
        v: &Self::Vert,
        k: usize,
        d: u32,
        ids: [u32; 3],
    ) -> usize;
}

/// [`DuffF32`] in lanes: `p = (u·(P−o), v·(P−o))`, edge values
/// `det(p₃, pᵢ) = p₃.x·yᵢ − p₃.y·xᵢ` (Algorithm 1): the geometry of the
/// Tet20, Tet16 and Tet32 kernels' lockstep walk.
#[derive(Clone, Copy, Debug)]
pub struct Planar;

/// The Duff basis of a lane: origin `o` and the columns `c[axis] = (u, v)`
/// of that axis.
#[derive(Clone, Copy)]
pub(crate) struct PlanarRay<F> {
    o: [F; 3],
    c: [[F; 2]; 3],
}

impl<F: Copy> PlanarRay<F> {
    /// Loads the basis of `p` into lane `k`.
    #[inline(always)]
    pub(crate) fn set<L: Lanes<F = F>>(&mut self, l: L, k: usize, p: &DuffF32) {
        for (a, o) in self.o.iter_mut().enumerate() {
            *o = l.set_f(*o, k, p.o[a]);
        }
        for (c, col) in self.c.iter_mut().zip([p.cx, p.cy, p.cz]) {
            c[0] = l.set_f(c[0], k, col.x);
            c[1] = l.set_f(c[1], k, col.y);
        }
    }
}

impl<L: Lanes> Projected<L> for Planar {
    type Proj = DuffF32;
    type Ray = PlanarRay<L::F>;
    type Vert = [L::F; 2];
    type Cold = ();

    #[inline(always)]
    fn zero(l: L) -> (Self::Ray, Self::Vert) {
        let z = l.splat_f(0.0);
        let ray = PlanarRay {
            o: [z; 3],
            c: [[z; 2]; 3],
        };
        (ray, [z; 2])
    }
    #[inline(always)]
    fn put(l: L, k: usize, ray: &mut Self::Ray, face: &mut [Self::Vert; 3], lane: &Lane<DuffF32>) {
        ray.set(l, k, &lane.proj);
        for (s, v) in face.iter_mut().enumerate() {
            v[0] = l.set_f(v[0], k, lane.st.p.xs[s]);
            v[1] = l.set_f(v[1], k, lane.st.p.ys[s]);
        }
    }
    #[inline(always)]
    fn project(l: L, ray: &Self::Ray, p: [L::F; 3]) -> Self::Vert {
        let (qx, qy, qz) = (
            l.sub_f(p[0], ray.o[0]),
            l.sub_f(p[1], ray.o[1]),
            l.sub_f(p[2], ray.o[2]),
        );
        // `(c₀·qₓ + c₁·q_y) + c₂·q_z`, as `DuffF32::project`.
        let c = &ray.c;
        let x = l.add_f(
            l.add_f(l.mul_f(c[0][0], qx), l.mul_f(c[1][0], qy)),
            l.mul_f(c[2][0], qz),
        );
        let y = l.add_f(
            l.add_f(l.mul_f(c[0][1], qx), l.mul_f(c[1][1], qy)),
            l.mul_f(c[2][1], qz),
        );
        [x, y]
    }
    #[inline(always)]
    fn edges(l: L, _: &Self::Ray, v: &Self::Vert, face: &[Self::Vert; 3]) -> [L::F; 3] {
        [
            det(l, v, &face[0]),
            det(l, v, &face[1]),
            det(l, v, &face[2]),
        ]
    }
    #[inline(always)]
    fn select(l: L, m: L::M, t: Self::Vert, f: Self::Vert) -> Self::Vert {
        [l.select_f(m, t[0], f[0]), l.select_f(m, t[1], f[1])]
    }
    #[inline(always)]
    fn tie_mask(
        _: &(),
        face: &[Self::Vert; 3],
        v: &Self::Vert,
        k: usize,
        d: u32,
        ids: [u32; 3],
    ) -> usize {
        let at = |x: L::F| L::f_lanes(x).as_ref()[k];
        let f = Face2::new(face.map(|p| Vec2::new(at(p[0]), at(p[1]))));
        f.left_mask_ties(Vec2::new(at(v[0]), at(v[1])), d, &ids)
    }
}

/// `det(p₃, pᵢ) = p₃.x·yᵢ − p₃.y·xᵢ`. (No closures over lane operations
/// in the walk: a closure not inlined would lose the entry point's
/// instruction set.)
#[inline(always)]
fn det<L: Lanes>(l: L, v: &[L::F; 2], f: &[L::F; 2]) -> L::F {
    l.sub_f(l.mul_f(v[0], f[1]), l.mul_f(v[1], f[0]))
}

/// `d · (q₃ × qₖ)` with glam's `cross` and `dot`: `cross(q₃, qₖ)` is
/// `(q₃.y·qₖ.z − qₖ.y·q₃.z, q₃.z·qₖ.x − qₖ.z·q₃.x, q₃.x·qₖ.y − qₖ.x·q₃.y)`,
/// then `(d.x·c.x + d.y·c.y) + d.z·c.z`.
#[inline(always)]
fn triple<L: Lanes>(l: L, d: &[L::F; 3], q3: &[L::F; 3], qk: &[L::F; 3]) -> L::F {
    let cx = l.sub_f(l.mul_f(q3[1], qk[2]), l.mul_f(qk[1], q3[2]));
    let cy = l.sub_f(l.mul_f(q3[2], qk[0]), l.mul_f(qk[2], q3[0]));
    let cz = l.sub_f(l.mul_f(q3[0], qk[1]), l.mul_f(qk[0], q3[1]));
    l.add_f(
        l.add_f(l.mul_f(d[0], cx), l.mul_f(d[1], cy)),
        l.mul_f(d[2], cz),
    )
}

/// [`TripleF32`] in lanes: `q = P − o`, edge values `d · (q₃ × qᵢ)` as
/// glam's `cross` and `dot` compute them, operand for operand, so the
/// antisymmetry that makes the walk watertight (`a × b = −(b × a)`
/// componentwise) is kept: the geometry of ScTP's lockstep walk.
#[derive(Clone, Copy, Debug)]
pub struct Triple;

/// A lane's ray: origin and direction.
#[derive(Clone, Copy)]
pub(crate) struct TripleRay<F> {
    o: [F; 3],
    dir: [F; 3],
}

impl<L: Lanes> Projected<L> for Triple {
    type Proj = TripleF32;
    type Ray = TripleRay<L::F>;
    type Vert = [L::F; 3];
    type Cold = TripleF32;

    #[inline(always)]
    fn zero(l: L) -> (Self::Ray, Self::Vert) {
        let z = l.splat_f(0.0);
        (
            TripleRay {
                o: [z; 3],
                dir: [z; 3],
            },
            [z; 3],
        )
    }
    #[inline(always)]
    fn put(
        l: L,
        k: usize,
        ray: &mut Self::Ray,
        face: &mut [Self::Vert; 3],
        lane: &Lane<TripleF32>,
    ) -> TripleF32 {
        let (o, d) = lane.proj.origin_direction();
        for a in 0..3 {
            ray.o[a] = l.set_f(ray.o[a], k, o[a]);
            ray.dir[a] = l.set_f(ray.dir[a], k, d[a]);
        }
        for (q, p) in face.iter_mut().zip(&lane.st.p) {
            for a in 0..3 {
                q[a] = l.set_f(q[a], k, p[a]);
            }
        }
        lane.proj
    }
    #[inline(always)]
    fn project(l: L, ray: &Self::Ray, p: [L::F; 3]) -> Self::Vert {
        [
            l.sub_f(p[0], ray.o[0]),
            l.sub_f(p[1], ray.o[1]),
            l.sub_f(p[2], ray.o[2]),
        ]
    }
    #[inline(always)]
    fn edges(l: L, ray: &Self::Ray, q3: &Self::Vert, face: &[Self::Vert; 3]) -> [L::F; 3] {
        [
            triple(l, &ray.dir, q3, &face[0]),
            triple(l, &ray.dir, q3, &face[1]),
            triple(l, &ray.dir, q3, &face[2]),
        ]
    }
    #[inline(always)]
    fn select(l: L, m: L::M, t: Self::Vert, f: Self::Vert) -> Self::Vert {
        [
            l.select_f(m, t[0], f[0]),
            l.select_f(m, t[1], f[1]),
            l.select_f(m, t[2], f[2]),
        ]
    }
    #[inline(always)]
    fn tie_mask(
        proj: &TripleF32,
        face: &[Self::Vert; 3],
        v: &Self::Vert,
        k: usize,
        d: u32,
        ids: [u32; 3],
    ) -> usize {
        let at = |x: &[L::F; 3]| Vec3::from_array(x.map(|c| L::f_lanes(c).as_ref()[k]));
        proj.left_mask_ties(at(v), d, &face.map(|q| at(&q)), &ids)
    }
}
