//! Implicit points and the exact predicates on them.
//!
//! Every point a round works with is one of
//!
//! * a vertex of the current soup (explicit `f32` coordinates);
//! * `Lpi`: a mesh edge crossed by a plane, the plane being a triangle's
//!   plane or the *vertical* plane through another edge along a coordinate
//!   axis (that is how a crossing of two coplanar edges is written);
//! * `Tpi`: the meeting point of three triangle planes (where two
//!   intersection segments inside a third triangle cross).
//!
//! A point is kept as homogeneous coordinates `base + off / den`, `base` an
//! explicit vertex, `off` and `den` polynomials in the input coordinates.
//! The predicates (side of a plane, order of two points along an axis) are
//! written once over [`Ring`] and evaluated first with [`Tracked`] doubles,
//! then, only if that cannot decide, exactly with [`Expansion`]s. So every
//! combinatorial decision is exact; only the final `f32` coordinates of a
//! new point are rounded (from a value whose own error is far below an
//! `f32` ulp).
//!
//! [`Key`]s name points symbolically, so the same point met from several
//! pairs of triangles is one point.

use std::cmp::Ordering;

use glam::{DVec3, Vec3};
use robust::{Coord, Coord3D};

use super::arith::{Ring, Tracked};
use super::expansion::Expansion;

/// A mesh edge: two vertex ids, sorted.
pub(crate) type Edge = [u32; 2];

/// The edge between `a` and `b`.
pub(crate) fn edge(a: u32, b: u32) -> Edge {
    if a < b { [a, b] } else { [b, a] }
}

/// A plane through explicit vertices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Plane {
    /// The plane of a triangle (three vertex ids).
    Triangle([u32; 3]),
    /// The plane through `edge` parallel to coordinate axis `axis`; its side
    /// is the sign of `orient2d` in the projection dropping `axis`.
    Vertical {
        /// The edge.
        edge: Edge,
        /// 0, 1, 2 for x, y, z.
        axis: u8,
    },
}

/// How a point is constructed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum PointDef {
    /// A vertex of the soup.
    Vertex(u32),
    /// Where `edge` crosses `plane` (strictly inside the edge).
    Lpi {
        /// The crossed edge.
        edge: Edge,
        /// The crossing plane.
        plane: Plane,
    },
    /// Where three triangle planes meet.
    Tpi([[u32; 3]; 3]),
}

/// The symbolic name of a point; equal keys are the same point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(crate) enum Key {
    /// A soup vertex.
    Vertex(u32),
    /// An edge crossing the interior of a triangle (sorted vertex ids).
    EdgeTriangle(Edge, [u32; 3]),
    /// Two edges crossing (sorted pair).
    EdgeEdge(Edge, Edge),
    /// Three triangles' planes (sorted).
    Triple([[u32; 3]; 3]),
}

/// Sorted copy of a triangle's vertex ids.
pub(crate) fn sorted3(mut t: [u32; 3]) -> [u32; 3] {
    t.sort_unstable();
    t
}

/// `p` projected by dropping `axis` (cyclic: x→(y,z), y→(z,x), z→(x,y)).
pub(crate) fn project(p: DVec3, axis: usize) -> (f64, f64) {
    match axis {
        0 => (p.y, p.z),
        1 => (p.z, p.x),
        _ => (p.x, p.y),
    }
}

/// Exact sign of `orient2d` of three 2-D points.
pub(crate) fn orient2(a: (f64, f64), b: (f64, f64), c: (f64, f64)) -> i8 {
    let o = robust::orient2d(
        Coord { x: a.0, y: a.1 },
        Coord { x: b.0, y: b.1 },
        Coord { x: c.0, y: c.1 },
    );
    (o > 0.0) as i8 - (o < 0.0) as i8
}

/// Exact sign of `orient3d(a, b, c, d)`.
pub(crate) fn orient3(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> i8 {
    let c3 = |p: DVec3| Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    };
    let o = robust::orient3d(c3(a), c3(b), c3(c), c3(d));
    (o > 0.0) as i8 - (o < 0.0) as i8
}

/// `base + off / den`.
struct Hom<N> {
    base: [f64; 3],
    off: [N; 3],
    den: N,
}

/// `side(x) = n · (x - a)`.
struct PlaneN<N> {
    n: [N; 3],
    a: [f64; 3],
}

fn dot<N: Ring>(a: &[N; 3], b: &[N; 3]) -> N {
    a[0].mul(&b[0]).add(&a[1].mul(&b[1])).add(&a[2].mul(&b[2]))
}

fn cross<N: Ring>(a: &[N; 3], b: &[N; 3]) -> [N; 3] {
    [
        a[1].mul(&b[2]).sub(&a[2].mul(&b[1])),
        a[2].mul(&b[0]).sub(&a[0].mul(&b[2])),
        a[0].mul(&b[1]).sub(&a[1].mul(&b[0])),
    ]
}

fn diff3<N: Ring>(a: [f64; 3], b: [f64; 3]) -> [N; 3] {
    [
        N::diff(a[0], b[0]),
        N::diff(a[1], b[1]),
        N::diff(a[2], b[2]),
    ]
}

fn zero3<N: Ring>() -> [N; 3] {
    [N::from_f64(0.0), N::from_f64(0.0), N::from_f64(0.0)]
}

fn mul_sign(a: Option<i8>, b: Option<i8>) -> Option<i8> {
    Some(a? * b?)
}

/// Exact geometry over one round's vertices.
#[derive(Clone, Copy)]
pub(crate) struct Geo<'a> {
    /// The soup's vertices.
    pub verts: &'a [Vec3],
}

impl<'a> Geo<'a> {
    /// Vertex `v` as doubles.
    pub fn pos(&self, v: u32) -> DVec3 {
        self.verts[v as usize].as_dvec3()
    }

    fn arr(&self, v: u32) -> [f64; 3] {
        self.pos(v).to_array()
    }

    fn plane_n<N: Ring>(&self, plane: &Plane) -> PlaneN<N> {
        match *plane {
            Plane::Triangle([a, b, c]) => {
                let a0 = self.arr(a);
                let ab = diff3::<N>(self.arr(b), a0);
                let ac = diff3::<N>(self.arr(c), a0);
                PlaneN {
                    n: cross(&ab, &ac),
                    a: a0,
                }
            }
            Plane::Vertical { edge: [u, v], axis } => {
                let a0 = self.arr(u);
                let [dx, dy, dz] = diff3::<N>(self.arr(v), a0);
                let z = N::from_f64(0.0);
                // e_axis × d: side = orient2d(u, v, x) in the projection.
                let n = match axis {
                    0 => [z, dz.mul(&N::from_f64(-1.0)), dy],
                    1 => [dz, z, dx.mul(&N::from_f64(-1.0))],
                    _ => [dy.mul(&N::from_f64(-1.0)), dx, z],
                };
                PlaneN { n, a: a0 }
            }
        }
    }

    fn hom<N: Ring>(&self, p: &PointDef) -> Hom<N> {
        match *p {
            PointDef::Vertex(v) => Hom {
                base: self.arr(v),
                off: zero3(),
                den: N::from_f64(1.0),
            },
            PointDef::Lpi {
                edge: [p, q],
                plane,
            } => {
                let pl = self.plane_n::<N>(&plane);
                let (p, q) = (self.arr(p), self.arr(q));
                let dp = dot(&pl.n, &diff3(p, pl.a));
                let den = dot(&pl.n, &diff3(p, q));
                let [x, y, z] = diff3::<N>(q, p);
                Hom {
                    base: p,
                    off: [dp.mul(&x), dp.mul(&y), dp.mul(&z)],
                    den,
                }
            }
            PointDef::Tpi([t1, t2, t3]) => {
                let p1 = self.plane_n::<N>(&Plane::Triangle(t1));
                let p2 = self.plane_n::<N>(&Plane::Triangle(t2));
                let p3 = self.plane_n::<N>(&Plane::Triangle(t3));
                let c2 = dot(&p2.n, &diff3(p2.a, p1.a));
                let c3 = dot(&p3.n, &diff3(p3.a, p1.a));
                let n31 = cross(&p3.n, &p1.n);
                let n12 = cross(&p1.n, &p2.n);
                let den = dot(&p1.n, &cross(&p2.n, &p3.n));
                let off = [0, 1, 2].map(|k| c2.mul(&n31[k]).add(&c3.mul(&n12[k])));
                Hom {
                    base: p1.a,
                    off,
                    den,
                }
            }
        }
    }

    fn side_with<N: Ring>(&self, x: &PointDef, plane: &Plane) -> Option<i8> {
        let h = self.hom::<N>(x);
        let pl = self.plane_n::<N>(plane);
        // n · ((base - a) den + off), times sign(den).
        let d = diff3::<N>(h.base, pl.a);
        let w = [0, 1, 2].map(|k| d[k].mul(&h.den).add(&h.off[k]));
        mul_sign(dot(&pl.n, &w).sign(), h.den.sign())
    }

    /// Exact side (−1, 0, +1) of point `x` relative to `plane`.
    pub fn side(&self, x: &PointDef, plane: &Plane) -> i8 {
        self.side_with::<Tracked>(x, plane)
            .or_else(|| self.side_with::<Expansion>(x, plane))
            .unwrap_or(0)
    }

    fn cmp_with<N: Ring>(&self, a: &PointDef, b: &PointDef, axis: usize) -> Option<Ordering> {
        let (ha, hb) = (self.hom::<N>(a), self.hom::<N>(b));
        // (a - b)_k den_a den_b = (base_a - base_b) den_a den_b + off_a den_b - off_b den_a
        let d = N::diff(ha.base[axis], hb.base[axis]);
        let v = d
            .mul(&ha.den)
            .mul(&hb.den)
            .add(&ha.off[axis].mul(&hb.den))
            .sub(&hb.off[axis].mul(&ha.den));
        let s = mul_sign(mul_sign(v.sign(), ha.den.sign()), hb.den.sign())?;
        Some(s.cmp(&0))
    }

    /// Exact order of coordinate `axis` of `a` and `b`.
    pub fn cmp_axis(&self, a: &PointDef, b: &PointDef, axis: usize) -> Ordering {
        if a == b {
            return Ordering::Equal;
        }
        if let (PointDef::Vertex(u), PointDef::Vertex(v)) = (a, b) {
            return self.verts[*u as usize][axis].total_cmp(&self.verts[*v as usize][axis]);
        }
        self.cmp_with::<Tracked>(a, b, axis)
            .or_else(|| self.cmp_with::<Expansion>(a, b, axis))
            .unwrap_or(Ordering::Equal)
    }

    /// Exact lexicographic order (x, then y, then z).
    pub fn cmp_lex(&self, a: &PointDef, b: &PointDef) -> Ordering {
        (0..3)
            .map(|k| self.cmp_axis(a, b, k))
            .find(|o| o.is_ne())
            .unwrap_or(Ordering::Equal)
    }

    /// Exact equality of positions.
    pub fn same(&self, a: &PointDef, b: &PointDef) -> bool {
        self.cmp_lex(a, b).is_eq()
    }

    /// Coordinates in doubles, correct to far better than an `f32` ulp.
    pub fn approx(&self, p: &PointDef) -> DVec3 {
        if let PointDef::Vertex(v) = p {
            return self.pos(*v);
        }
        let h = self.hom::<Tracked>(p);
        let den = h.den.v;
        let coords: [f64; 3] = [0, 1, 2].map(|k| h.base[k] + h.off[k].v / den);
        let good = (0..3).all(|k| {
            let err = (h.off[k].e + h.off[k].v.abs() * h.den.relative_error()) / den.abs();
            err.is_finite() && err <= coords[k].abs() * 2f64.powi(-45)
        });
        if good && den != 0.0 {
            return DVec3::from_array(coords);
        }
        let h = self.hom::<Expansion>(p);
        let den = h.den.estimate();
        DVec3::from_array([0, 1, 2].map(|k| h.base[k] + h.off[k].estimate() / den))
    }

    /// The point rounded to `f32` (a vertex keeps its own coordinates).
    pub fn round(&self, p: &PointDef) -> Vec3 {
        match p {
            PointDef::Vertex(v) => self.verts[*v as usize],
            _ => self.approx(p).as_vec3(),
        }
    }

    /// An axis along which `a` and `b` differ (the one where they differ
    /// most, checked exactly); `None` when they are the same point.
    pub fn line_axis(&self, a: &PointDef, b: &PointDef) -> Option<usize> {
        let d = (self.approx(a) - self.approx(b)).abs();
        let mut order = [0usize, 1, 2];
        order.sort_by(|&i, &j| d[j].total_cmp(&d[i]));
        order.into_iter().find(|&k| self.cmp_axis(a, b, k).is_ne())
    }

    /// The projection axis of triangle `t`: the dominant axis of its normal
    /// among those where the projection is non-degenerate (exact), or `None`
    /// for an exactly degenerate triangle.
    pub fn triangle_axis(&self, t: [u32; 3]) -> Option<usize> {
        let [a, b, c] = t.map(|v| self.pos(v));
        let n = (b - a).cross(c - a).abs();
        let mut order = [2usize, 1, 0];
        order.sort_by(|&i, &j| n[j].total_cmp(&n[i]));
        order
            .into_iter()
            .find(|&k| orient2(project(a, k), project(b, k), project(c, k)) != 0)
    }

    /// The axis along which the vertical plane through `f` crosses the line
    /// of `e` (two edges meeting in one point): the dominant component of
    /// their directions' cross product, checked exactly.
    pub fn cross_axis(&self, e: Edge, f: Edge) -> usize {
        let de = self.pos(e[1]) - self.pos(e[0]);
        let df = self.pos(f[1]) - self.pos(f[0]);
        let n = de.cross(df).abs();
        let mut order = [2usize, 1, 0];
        order.sort_by(|&i, &j| n[j].total_cmp(&n[i]));
        // The vertical plane through `f` along `k` must not contain `e`.
        let nonzero = |k: usize| {
            let (p, q) = (project(self.pos(e[0]), k), project(self.pos(e[1]), k));
            let (r, s) = (project(self.pos(f[0]), k), project(self.pos(f[1]), k));
            orient2(r, s, p) != 0 || orient2(r, s, q) != 0
        };
        order.into_iter().find(|&k| nonzero(k)).unwrap_or(order[0])
    }

    fn agreement_with<N: Ring>(&self, t: [u32; 3], u: [u32; 3]) -> Option<i8> {
        let normal = |t: [u32; 3]| {
            let a = self.arr(t[0]);
            cross(
                &diff3::<N>(self.arr(t[1]), a),
                &diff3::<N>(self.arr(t[2]), a),
            )
        };
        dot(&normal(t), &normal(u)).sign()
    }

    /// Exact sign of the dot product of the normals of triangles `t` and
    /// `u` (vertex ids).
    pub fn normal_agreement(&self, t: [u32; 3], u: [u32; 3]) -> i8 {
        self.agreement_with::<Tracked>(t, u)
            .or_else(|| self.agreement_with::<Expansion>(t, u))
            .unwrap_or(0)
    }

    /// The construction of the point named `key`, the same whichever pair
    /// of triangles met it.
    pub fn def_of(&self, key: &Key) -> PointDef {
        match *key {
            Key::Vertex(v) => PointDef::Vertex(v),
            Key::EdgeTriangle(e, t) => PointDef::Lpi {
                edge: e,
                plane: Plane::Triangle(t),
            },
            Key::EdgeEdge(e, f) => PointDef::Lpi {
                edge: e,
                plane: Plane::Vertical {
                    edge: f,
                    axis: self.cross_axis(e, f) as u8,
                },
            },
            Key::Triple(t) => PointDef::Tpi(t),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f32, y: f32, z: f32) -> Vec3 {
        Vec3::new(x, y, z)
    }

    #[test]
    fn an_edge_crossing_a_plane_lands_exactly() {
        // Edge 0-1 along z through the plane z = 0.25 of triangle 2-3-4.
        let verts = [
            v(0.5, 0.5, -1.0),
            v(0.5, 0.5, 1.0),
            v(0.0, 0.0, 0.25),
            v(2.0, 0.0, 0.25),
            v(0.0, 2.0, 0.25),
        ];
        let geo = Geo { verts: &verts };
        let x = geo.def_of(&Key::EdgeTriangle([0, 1], [2, 3, 4]));
        assert_eq!(geo.round(&x), v(0.5, 0.5, 0.25));
        assert_eq!(geo.side(&x, &Plane::Triangle([2, 3, 4])), 0);
        // The plane's normal (counter-clockwise corners) points up.
        assert_eq!(
            geo.side(&PointDef::Vertex(0), &Plane::Triangle([2, 3, 4])),
            -1
        );
        assert_eq!(
            geo.side(&PointDef::Vertex(1), &Plane::Triangle([2, 3, 4])),
            1
        );
    }

    #[test]
    fn three_planes_meet_where_a_fourth_passes() {
        // Planes x = 1, y = 2, z = 3 (as triangles) meet at (1, 2, 3); the
        // plane x + y + z = 6 passes through it, x + y + z = 6.5 does not.
        let verts = [
            v(1.0, 0.0, 0.0),
            v(1.0, 1.0, 0.0),
            v(1.0, 0.0, 1.0),
            v(0.0, 2.0, 0.0),
            v(0.0, 2.0, 1.0),
            v(1.0, 2.0, 0.0),
            v(0.0, 0.0, 3.0),
            v(1.0, 0.0, 3.0),
            v(0.0, 1.0, 3.0),
            v(6.0, 0.0, 0.0),
            v(0.0, 6.0, 0.0),
            v(0.0, 0.0, 6.0),
            v(6.5, 0.0, 0.0),
            v(0.0, 6.5, 0.0),
            v(0.0, 0.0, 6.5),
        ];
        let geo = Geo { verts: &verts };
        let x = PointDef::Tpi([[0, 1, 2], [3, 4, 5], [6, 7, 8]]);
        assert_eq!(geo.round(&x), v(1.0, 2.0, 3.0));
        assert_eq!(geo.side(&x, &Plane::Triangle([9, 10, 11])), 0);
        assert_ne!(geo.side(&x, &Plane::Triangle([12, 13, 14])), 0);
        // The same point as a vertex compares equal on every axis.
        let verts2: Vec<Vec3> = verts.iter().copied().chain([v(1.0, 2.0, 3.0)]).collect();
        let geo2 = Geo { verts: &verts2 };
        assert!(geo2.same(&x, &PointDef::Vertex(15)));
    }

    #[test]
    fn points_far_below_f32_spacing_are_ordered_exactly() {
        // The plane z = 0 and a plane tilted by 2^-41 cross the edge x = 1,
        // y = 0 at z = 0 and z = 2^-41: far below an f32 step, yet ordered
        // exactly, and a point equals itself however its plane is written.
        let d = 2f32.powi(-20);
        let verts = [
            v(1.0, 0.0, -1.0),
            v(1.0, 0.0, 1.0),
            v(0.0, 0.0, 0.0),
            v(0.0, 1.0, 0.0),
            v(2.0, 0.0, d * d),
            v(0.0, 0.0, 0.0),
        ];
        let geo = Geo { verts: &verts };
        // Plane z = 0 (triangle 2-3 and (2,0,0)) versus a plane tilted so
        // that it crosses x = 1 at z = 2^-40 / 2.
        let low = PointDef::Lpi {
            edge: [0, 1],
            plane: Plane::Triangle([2, 3, 4]),
        };
        let flat = [v(0.0, 0.0, 0.0), v(0.0, 1.0, 0.0), v(2.0, 0.0, 0.0)];
        let verts_flat: Vec<Vec3> = verts.iter().copied().chain(flat).collect();
        let geo_flat = Geo { verts: &verts_flat };
        let zero = PointDef::Lpi {
            edge: [0, 1],
            plane: Plane::Triangle([6, 7, 8]),
        };
        assert_eq!(geo_flat.cmp_axis(&zero, &low, 2), Ordering::Less);
        assert_eq!(geo_flat.cmp_axis(&low, &zero, 2), Ordering::Greater);
        assert_eq!(geo.cmp_axis(&low, &low, 2), Ordering::Equal);
        assert!(geo_flat.same(
            &zero,
            &PointDef::Lpi {
                edge: [0, 1],
                plane: Plane::Triangle([6, 8, 7])
            }
        ));
    }

    #[test]
    fn the_filter_agrees_with_exact_arithmetic_when_it_decides() {
        // Pseudo-random f32 configurations, many nearly degenerate.
        let mut seed = 7u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 40) as f32 / (1u64 << 24) as f32 - 0.5) * 4.0
        };
        let mut decided = 0;
        for _ in 0..2000 {
            let mut verts: Vec<Vec3> = (0..9).map(|_| v(next(), next(), next())).collect();
            // Make vertex 8 lie almost on the plane of 5-6-7.
            let (a, b, c) = (verts[5], verts[6], verts[7]);
            verts[8] = a + (b - a) * 0.25 + (c - a) * 0.5;
            let geo = Geo { verts: &verts };
            let x = PointDef::Lpi {
                edge: [0, 1],
                plane: Plane::Triangle([2, 3, 4]),
            };
            let pl = Plane::Triangle([5, 6, 7]);
            let exact = geo.side_with::<Expansion>(&x, &pl).unwrap();
            if let Some(s) = geo.side_with::<Tracked>(&x, &pl) {
                assert_eq!(s, exact);
                decided += 1;
            }
            let y = PointDef::Vertex(8);
            let exact = geo.side_with::<Expansion>(&y, &pl).unwrap();
            if let Some(s) = geo.side_with::<Tracked>(&y, &pl) {
                assert_eq!(s, exact);
            }
            for k in 0..3 {
                let e = geo.cmp_with::<Expansion>(&x, &y, k).unwrap();
                if let Some(t) = geo.cmp_with::<Tracked>(&x, &y, k) {
                    assert_eq!(t, e);
                }
            }
        }
        // The filter decides the generic cases.
        assert!(decided > 1500, "{decided}");
    }
}
