//! Marching tetrahedra (Wald et al. 2007, §3, Fig. 3): the isopolygon of one isotet
//! and the ray–isopolygon test.
//!
//! The four vertices are classified above (`≥ v`) or below the isovalue:
//! 16 cases ([`CASES`]). One vertex apart from the other three gives a
//! triangle on the three edges from it; two against two give a quad on the
//! four edges between the pairs, in cyclic order. Each polygon vertex lies
//! on a mesh edge `(a, b)` and is computed with the edge's endpoints in id
//! order (`a < b`): `P = Pa + (Pb − Pa)·(v − va)/(vb − va)`, so the tets
//! around the edge compute the same bits.
//!
//! # Ray–isopolygon test
//!
//! The paper computes the distance to the polygon's plane and tests the hit
//! point against the polygon's edges in a 2-D coordinate plane (half-space
//! tests). Here the 2-D plane is the ray's own: the polygon's vertices are
//! projected with the walk's ray-centred projection ([`DuffF32`]), where the
//! ray is the origin, and each polygon edge is tested with the walk's exactly
//! antisymmetric 2-D edge test and its tie rule (symbolic perturbation, ties
//! on coincident points decided by the edge keys). A quad is tested as two
//! triangles sharing a diagonal. Neighbouring isopolygons share their edge
//! bit for bit and every edge gets one answer, so a ray never slips through
//! between them (crack-free). The hit parameter is the polygon's depth
//! interpolated with the 2-D barycentrics (the plane distance, computed in
//! the same frame).

use glam::{Vec2, Vec3};

use crate::ray::Ray;
use crate::walk::{DuffF32, Projection};

/// The edges (vertex slot pairs) of the isopolygon of each case (bit `i` of
/// the case = vertex `i` is above), in cyclic order; the count is 0, 3 or 4.
pub const CASES: [(u8, [[u8; 2]; 4]); 16] = cases();

const fn cases() -> [(u8, [[u8; 2]; 4]); 16] {
    let mut out = [(0u8, [[0u8; 2]; 4]); 16];
    let mut m = 1;
    while m < 15 {
        let mut above = [0u8; 4];
        let mut below = [0u8; 4];
        let (mut na, mut nb) = (0, 0);
        let mut i = 0;
        while i < 4 {
            if m & (1 << i) != 0 {
                above[na] = i as u8;
                na += 1;
            } else {
                below[nb] = i as u8;
                nb += 1;
            }
            i += 1;
        }
        out[m] = if na == 1 {
            let x = above[0];
            (3, [[x, below[0]], [x, below[1]], [x, below[2]], [0, 0]])
        } else if nb == 1 {
            let x = below[0];
            (3, [[x, above[0]], [x, above[1]], [x, above[2]], [0, 0]])
        } else {
            let (a0, a1, b0, b1) = (above[0], above[1], below[0], below[1]);
            (4, [[a0, b0], [a0, b1], [a1, b1], [a1, b0]])
        };
        m += 1;
    }
    out
}

/// The marching-tet case of vertex values `v` for isovalue `iso`.
#[inline(always)]
pub fn case_of(v: [f32; 4], iso: f32) -> usize {
    (v[0] >= iso) as usize
        | ((v[1] >= iso) as usize) << 1
        | ((v[2] >= iso) as usize) << 2
        | ((v[3] >= iso) as usize) << 3
}

/// The isopolygon of one tet for one isovalue.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IsoPolygon {
    /// Number of vertices: 3 or 4.
    pub n: u8,
    /// Vertices in cyclic order.
    pub points: [Vec3; 4],
    /// Key of each vertex's mesh edge (`min id << 32 | max id`), the tie
    /// rule's last resort for coincident projections.
    pub keys: [u64; 4],
}

impl IsoPolygon {
    /// The isopolygon of the tet with vertex ids `ids`, corners `p` and
    /// values `v`, for `iso`; `None` when the tet does not straddle `iso`.
    #[inline]
    pub fn new(ids: [u32; 4], p: [Vec3; 4], v: [f32; 4], iso: f32) -> Option<IsoPolygon> {
        let (n, edges) = CASES[case_of(v, iso)];
        if n == 0 {
            return None;
        }
        let mut points = [Vec3::ZERO; 4];
        let mut keys = [0u64; 4];
        for k in 0..n as usize {
            let [i, j] = edges[k].map(usize::from);
            let (a, b) = if ids[i] < ids[j] { (i, j) } else { (j, i) };
            let s = (iso - v[a]) / (v[b] - v[a]);
            points[k] = p[a] + (p[b] - p[a]) * s;
            keys[k] = (ids[a] as u64) << 32 | ids[b] as u64;
        }
        Some(IsoPolygon { n, points, keys })
    }

    /// The ray parameter where the ray `pre` passes through the polygon
    /// (watertight, see the module docs), or `None`.
    #[inline]
    pub fn intersect(&self, pre: &RayPre) -> Option<f32> {
        let q = [0, 1, 2, 3].map(|k| pre.proj.project(self.points[k]));
        let tri = |a: usize, b: usize, c: usize| -> Option<f32> {
            let l0 = left_key(q[a], self.keys[a], q[b], self.keys[b]);
            let l1 = left_key(q[b], self.keys[b], q[c], self.keys[c]);
            let l2 = left_key(q[c], self.keys[c], q[a], self.keys[a]);
            if l0 != l1 || l1 != l2 {
                return None;
            }
            let det = |x: Vec2, y: Vec2| x.x * y.y - x.y * y.x;
            let (wa, wb, wc) = (det(q[b], q[c]), det(q[c], q[a]), det(q[a], q[b]));
            let s = wa + wb + wc;
            if s == 0.0 || !s.is_finite() {
                return None;
            }
            let z = |k: usize| pre.depth(self.points[k]);
            Some((wa * z(a) + wb * z(b) + wc * z(c)) / s)
        };
        let t = tri(0, 1, 2);
        if self.n == 4 {
            let u = tri(0, 2, 3);
            return match (t, u) {
                (Some(x), Some(y)) => Some(x.min(y)),
                (x, y) => x.or(y),
            };
        }
        t
    }
}

/// The walk's 2-D edge test with its tie rule ([`crate::walk`]'s
/// `left_2d!`), keyed by edge keys.
#[inline(always)]
fn left_key(a: Vec2, ka: u64, b: Vec2, kb: u64) -> bool {
    crate::walk::left_2d!(a, ka, b, kb)
}

/// Per-ray constants of the isopolygon test: the ray-centred projection
/// and the depth scale.
#[derive(Clone, Copy, Debug)]
pub struct RayPre {
    /// The projection (origin at the ray).
    pub proj: DuffF32,
    /// The ray.
    pub ray: Ray,
    /// `1 / |d|²`.
    pub inv_dd: f32,
    /// `1 / d` per axis (for box tests).
    pub inv_d: Vec3,
}

impl RayPre {
    /// Set-up for a valid ray.
    pub fn new(ray: &Ray) -> RayPre {
        RayPre {
            proj: DuffF32::setup(ray),
            ray: *ray,
            inv_dd: 1.0 / ray.direction.length_squared(),
            inv_d: ray.direction.recip(),
        }
    }

    /// Ray parameter of the projection of `p` on the ray.
    #[inline(always)]
    pub fn depth(&self, p: Vec3) -> f32 {
        (p - self.ray.origin).dot(self.ray.direction) * self.inv_dd
    }

    /// Entry and exit parameters of the ray's line through the box
    /// `[lo, hi]` (entry > exit: missed).
    #[inline(always)]
    pub fn slab(&self, lo: Vec3, hi: Vec3) -> (f32, f32) {
        slab(self.ray.origin, self.inv_d, lo, hi)
    }
}

/// Entry and exit parameters of the line `origin + t·d` (`inv_d = 1/d`)
/// through the box `[lo, hi]` (entry > exit: missed).
#[inline(always)]
pub(super) fn slab(origin: Vec3, inv_d: Vec3, lo: Vec3, hi: Vec3) -> (f32, f32) {
    let mut t0 = f32::NEG_INFINITY;
    let mut t1 = f32::INFINITY;
    for a in 0..3 {
        let u = (lo[a] - origin[a]) * inv_d[a];
        let v = (hi[a] - origin[a]) * inv_d[a];
        // `f32::min`/`max` ignore the NaN of `0 · ∞` (origin on a slab
        // plane of a parallel ray): that axis does not bound the ray.
        t0 = t0.max(u.min(v));
        t1 = t1.min(u.max(v));
    }
    (t0, t1)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every case's polygon runs over the edges between an above and a below
    /// vertex, each such edge once, consecutive edges sharing a vertex (a
    /// cycle around the tet); the two empty cases have none.
    #[test]
    fn cases_cut_exactly_the_straddling_edges() {
        for (m, &(n, edges)) in CASES.iter().enumerate() {
            let above = |i: u8| m & (1 << i) != 0;
            let straddling = (0..4u8)
                .flat_map(|i| (i + 1..4).map(move |j| (i, j)))
                .filter(|&(i, j)| above(i) != above(j))
                .count();
            assert_eq!(n as usize, straddling, "case {m}");
            let e = &edges[..n as usize];
            for (k, &[i, j]) in e.iter().enumerate() {
                assert_ne!(above(i), above(j), "case {m}");
                let [a, b] = e[(k + 1) % e.len()];
                assert!([a, b].contains(&i) || [a, b].contains(&j), "case {m}");
            }
        }
    }

    /// A polygon vertex on an edge gets the same bits from either end.
    #[test]
    fn edge_points_are_canonical() {
        let p = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z * 1.3];
        let v = [0.1, 0.9, 0.4, 0.7];
        let a = IsoPolygon::new([5, 9, 2, 7], p, v, 0.5).unwrap();
        // The same tet with its slots permuted.
        let b = IsoPolygon::new(
            [9, 5, 7, 2],
            [p[1], p[0], p[3], p[2]],
            [v[1], v[0], v[3], v[2]],
            0.5,
        )
        .unwrap();
        let mut pa: Vec<_> = (0..a.n as usize)
            .map(|k| (a.keys[k], a.points[k].to_array()))
            .collect();
        let mut pb: Vec<_> = (0..b.n as usize)
            .map(|k| (b.keys[k], b.points[k].to_array()))
            .collect();
        pa.sort_by_key(|x| x.0);
        pb.sort_by_key(|x| x.0);
        assert_eq!(pa, pb);
        for (_, q) in &pa {
            // On the plane of the linear field: f = 0.1 + 0.8x + 0.3y + 0.6/1.3·z.
            let q = Vec3::from_array(*q);
            let f = 0.1 + 0.8 * q.x + 0.3 * q.y + 0.6 / 1.3 * q.z;
            assert!((f - 0.5).abs() < 1e-6, "{f}");
        }
    }
}
