//! The geometry of cuts: an axis-aligned [`SplitPlane`], which side of it a
//! triangle lies on, exact bits of a point (`key`) and the clipping of
//! scene triangles by a plane, with crossing points rounded once to f32 and
//! lying exactly on the plane (Erkoç et al. 2021, §3.2 `CLIP`, made
//! exact).

use glam::Vec3;

/// An axis-aligned cut plane `x[axis] = value`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SplitPlane {
    /// 0 = x, 1 = y, 2 = z.
    pub axis: usize,
    /// Plane offset (f32, so seam points are exactly on it).
    pub value: f32,
}

/// Where a triangle lies relative to a plane (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// All vertices at or below, at least one strictly below.
    Below,
    /// All vertices at or above, at least one strictly above.
    Above,
    /// Vertices strictly on both sides: the plane cuts it.
    Cut,
    /// All three vertices on the plane.
    InPlane,
}

impl SplitPlane {
    /// Classifies a triangle (exact comparisons of f32 coordinates).
    pub fn classify(&self, tri: [Vec3; 3]) -> Side {
        let below = tri.iter().any(|p| p[self.axis] < self.value);
        let above = tri.iter().any(|p| p[self.axis] > self.value);
        match (below, above) {
            (true, true) => Side::Cut,
            (true, false) => Side::Below,
            (false, true) => Side::Above,
            (false, false) => Side::InPlane,
        }
    }
}

/// One scene-triangle piece: three vertices in the source winding and the
/// (cleaned) source triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Piece {
    /// Vertices.
    pub v: [Vec3; 3],
    /// Cleaned scene triangle index.
    pub source: u32,
}

/// Exact bits of a point (−0 folded into +0).
pub(super) fn key(p: Vec3) -> [u32; 3] {
    [
        (p.x + 0.0).to_bits(),
        (p.y + 0.0).to_bits(),
        (p.z + 0.0).to_bits(),
    ]
}

/// The crossing point of edge `p q` with the plane (endpoints strictly on
/// opposite sides), computed from the endpoints in canonical order.
pub fn crossing_point(p: Vec3, q: Vec3, plane: SplitPlane) -> Vec3 {
    let (p, q) = if key(p) <= key(q) { (p, q) } else { (q, p) };
    let (pd, qd) = (p.as_dvec3(), q.as_dvec3());
    let a = plane.axis;
    let t = (plane.value as f64 - pd[a]) / (qd[a] - pd[a]);
    let x = pd + t * (qd - pd);
    let mut r = Vec3::new(x.x as f32, x.y as f32, x.z as f32);
    // Rounding a value between two f32 values stays between them; clamp
    // anyway against t's own rounding.
    r = r.clamp(p.min(q), p.max(q));
    r[a] = plane.value;
    r
}

/// Exact: do three points span a proper triangle?
pub(super) fn non_degenerate(t: [Vec3; 3]) -> bool {
    let proj = |p: Vec3, i: usize, j: usize| robust::Coord {
        x: p[i] as f64,
        y: p[j] as f64,
    };
    [(0, 1), (1, 2), (2, 0)].iter().any(|&(i, j)| {
        robust::orient2d(proj(t[0], i, j), proj(t[1], i, j), proj(t[2], i, j)) != 0.0
    })
}

/// Fans a convex polygon (3 or 4 vertices, source winding) into proper
/// triangles, trying each start vertex until no piece is degenerate.
pub(super) fn fan(poly: &[Vec3]) -> Vec<[Vec3; 3]> {
    let n = poly.len();
    for s in 0..n {
        let tris: Vec<[Vec3; 3]> = (1..n - 1)
            .map(|i| [poly[s], poly[(s + i) % n], poly[(s + i + 1) % n]])
            .collect();
        if tris.iter().all(|&t| non_degenerate(t)) {
            return tris;
        }
    }
    // Some piece is degenerate whatever the start (rounding collapsed a
    // sliver): keep the proper ones.
    (1..n - 1)
        .map(|i| [poly[0], poly[i], poly[i + 1]])
        .filter(|&t| non_degenerate(t))
        .collect()
}

/// Clips a convex polygon (source winding) strictly crossing the plane
/// into its part below and its part above (both keep the winding) and the
/// two polygon points on the plane (the seam segment).
pub fn clip_polygon(poly: &[Vec3], plane: SplitPlane) -> (Vec<Vec3>, Vec<Vec3>, [Vec3; 2]) {
    let a = plane.axis;
    let side = |p: Vec3| {
        p[a].partial_cmp(&plane.value)
            .unwrap_or(std::cmp::Ordering::Equal)
    };
    let (mut lo, mut hi, mut on) = (Vec::new(), Vec::new(), Vec::new());
    let n = poly.len();
    for i in 0..n {
        let (p, q) = (poly[i], poly[(i + 1) % n]);
        let (sp, sq) = (side(p), side(q));
        if sp.is_le() {
            lo.push(p);
        }
        if sp.is_ge() {
            hi.push(p);
        }
        if sp.is_eq() {
            on.push(p);
        }
        if (sp.is_lt() && sq.is_gt()) || (sp.is_gt() && sq.is_lt()) {
            let x = crossing_point(p, q, plane);
            lo.push(x);
            hi.push(x);
            on.push(x);
        }
    }
    debug_assert_eq!(
        on.len(),
        2,
        "a convex polygon crossing a plane meets it twice"
    );
    (lo, hi, [on[0], on[1]])
}

/// Clips a triangle crossing the plane into (below pieces, above pieces,
/// the seam segment). Source winding is kept in every piece.
pub fn cut_triangle(
    tri: [Vec3; 3],
    plane: SplitPlane,
) -> (Vec<[Vec3; 3]>, Vec<[Vec3; 3]>, [Vec3; 2]) {
    let (lo, hi, seg) = clip_polygon(&tri, plane);
    (fan(&lo), fan(&hi), seg)
}

/// Vertices off a cut plane by less than this × the box's largest extent
/// make the plane unusable ([`SeamError::PlaneNearVertex`](super::error::SeamError::PlaneNearVertex)): TetGen would
/// merge crossing points with them (its duplicate tolerance is relative).
pub const NEAR_PLANE: f64 = 1e-7;

/// The first vertex strictly off the plane but within `tolerance` of it.
pub fn near_plane_vertex(vertices: &[Vec3], plane: SplitPlane, tolerance: f64) -> Option<u32> {
    vertices
        .iter()
        .position(|p| {
            let d = (p[plane.axis] as f64 - plane.value as f64).abs();
            d > 0.0 && d < tolerance
        })
        .map(|i| i as u32)
}
