//! One intersecting pair of triangles: where they meet, as named points and
//! constraint segments for each of the two, decided exactly.
//!
//! * Not coplanar: `A ∩ plane(B)` and `B ∩ plane(A)` are segments (or
//!   points) on the line where the planes meet; their overlap, ordered
//!   exactly along that line, is `A ∩ B`. Each end is a vertex or an edge
//!   crossing the other plane, renamed to an edge–edge crossing or a vertex
//!   when it lies exactly on the other triangle's boundary.
//! * Coplanar (including duplicates, and pairs within the snap distance of
//!   each other's plane): in the projection of the first, every edge of one
//!   clipped to the other is a constraint of the other; edge crossings and
//!   vertices on the other's edges split those edges.

use glam::DVec3;

use super::points::{Edge, Geo, Key, Plane, PointDef, edge, orient2, orient3, project, sorted3};

/// Where a point lies in one triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Where {
    /// At one of its corners.
    Corner,
    /// Strictly inside one of its edges.
    Edge(Edge),
    /// Strictly inside the triangle.
    Interior,
}

/// The line a constraint segment lies on, within the triangle that gets it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(crate) enum Line {
    /// The line of a mesh edge lying in the triangle's plane.
    Edge(Edge),
    /// Where the triangle's plane meets this triangle's plane.
    Plane([u32; 3]),
}

/// What one pair adds: points with their place in each triangle (index 0:
/// the first triangle, 1: the second) and segments, each for one of them.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct PairResult {
    /// Named points and where they lie in the first and second triangle.
    pub points: Vec<(Key, [Where; 2])>,
    /// `(which triangle, line, from, to)`.
    pub segments: Vec<(usize, Line, Key, Key)>,
    /// The two triangles are coplanar (their overlap is kept once).
    pub coplanar: bool,
}

/// Locates the 2-D point `p` in triangle `t` (projected, `sign` its
/// orientation): `None` outside, else corner / edge (index) / interior.
fn locate_2d(p: (f64, f64), t: [(f64, f64); 3], sign: i8) -> Option<Option<usize>> {
    let o: [i8; 3] = std::array::from_fn(|i| orient2(t[i], t[(i + 1) % 3], p) * sign);
    if o.iter().any(|&s| s < 0) {
        return None;
    }
    Some(match o.iter().filter(|&&s| s == 0).count() {
        0 => None,
        _ => o.iter().position(|&s| s == 0),
    })
}

/// The place of a point in triangle `t` given the signs of the point against
/// its three edge lines (already oriented inward): `None` when outside.
fn place(t: [u32; 3], o: [i8; 3]) -> Option<(Where, Option<u32>)> {
    if o.iter().any(|&s| s < 0) {
        return None;
    }
    let zeros: Vec<usize> = (0..3).filter(|&i| o[i] == 0).collect();
    Some(match zeros.as_slice() {
        [] => (Where::Interior, None),
        [i] => (Where::Edge(edge(t[*i], t[(*i + 1) % 3])), None),
        // On two edge lines: the corner they share.
        [i, j, ..] => {
            let corner = if (i + 1) % 3 == *j { t[*j] } else { t[*i] };
            (Where::Corner, Some(corner))
        }
    })
}

/// One end of `A ∩ plane(B)`, located in both triangles.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    key: Key,
    at: [Where; 2],
}

/// Largest distance of a corner of `q` from the plane of `p`.
fn plane_gap(p: [DVec3; 3], q: [DVec3; 3]) -> f64 {
    let n = (p[1] - p[0]).cross(p[2] - p[0]);
    let len = n.length();
    if len == 0.0 {
        return f64::INFINITY;
    }
    q.iter()
        .map(|&x| (n.dot(x - p[0]) / len).abs())
        .fold(0.0, f64::max)
}

/// Intersection of a reported pair `(a, b)` (vertex ids of both). Two
/// triangles whose corners all lie within `eps` of the other's plane count
/// as coplanar: their crossing line would be decided by rounding noise,
/// and cutting along it again after every rounding need not end.
pub(crate) fn intersect_pair(geo: &Geo, a: [u32; 3], b: [u32; 3], eps: f64) -> PairResult {
    let pa = a.map(|v| geo.pos(v));
    let pb = b.map(|v| geo.pos(v));
    let coplanar = (0..3).all(|j| orient3(pa[0], pa[1], pa[2], pb[j]) == 0)
        || (plane_gap(pa, pb) <= eps && plane_gap(pb, pa) <= eps);
    if coplanar {
        coplanar_pair(geo, a, b)
    } else {
        transversal_pair(geo, a, b)
    }
}

/// Ends of `own ∩ plane(other)`, each located in both (`slot` says which of
/// the pair `own` is).
fn plane_cut(geo: &Geo, own: [u32; 3], other: [u32; 3], slot: usize) -> Vec<Candidate> {
    let po = own.map(|v| geo.pos(v));
    let pt = other.map(|v| geo.pos(v));
    let s: [i8; 3] = std::array::from_fn(|i| orient3(pt[0], pt[1], pt[2], po[i]));
    let Some(axis) = geo.triangle_axis(other) else {
        return Vec::new();
    };
    let t2 = pt.map(|p| project(p, axis));
    let sign = orient2(t2[0], t2[1], t2[2]);
    let mut out = Vec::new();
    let mut push = |key: Key, own_at: Where, other_at: Where| {
        let mut at = [Where::Corner; 2];
        at[slot] = own_at;
        at[1 - slot] = other_at;
        out.push(Candidate { key, at });
    };
    for i in 0..3 {
        let v = own[i];
        if s[i] == 0 {
            if other.contains(&v) {
                push(Key::Vertex(v), Where::Corner, Where::Corner);
                continue;
            }
            let Some(loc) = locate_2d(project(po[i], axis), t2, sign) else {
                continue;
            };
            let at = match loc {
                None => Where::Interior,
                Some(j) => Where::Edge(edge(other[j], other[(j + 1) % 3])),
            };
            // Two zero sides would be a vertex at the same position: ids
            // are unique per position, so it was caught by `contains`.
            push(Key::Vertex(v), Where::Corner, at);
        }
    }
    for i in 0..3 {
        let j = (i + 1) % 3;
        if s[i] * s[j] >= 0 {
            continue;
        }
        let e = edge(own[i], own[j]);
        let def = PointDef::Lpi {
            edge: e,
            plane: Plane::Triangle(sorted3(other)),
        };
        let o: [i8; 3] = std::array::from_fn(|k| {
            let f = edge(other[k], other[(k + 1) % 3]);
            let vertical = Plane::Vertical {
                edge: f,
                axis: axis as u8,
            };
            // Orient so that inside is positive (edge f stored sorted).
            let flip = if f[0] == other[k] { 1 } else { -1 };
            geo.side(&def, &vertical) * flip * sign
        });
        match place(other, o) {
            None => {}
            Some((Where::Corner, Some(w))) => push(Key::Vertex(w), Where::Edge(e), Where::Corner),
            Some((Where::Edge(f), _)) => {
                let key = Key::EdgeEdge(e.min(f), e.max(f));
                push(key, Where::Edge(e), Where::Edge(f));
            }
            Some((at, _)) => push(Key::EdgeTriangle(e, sorted3(other)), Where::Edge(e), at),
        }
    }
    out
}

fn transversal_pair(geo: &Geo, a: [u32; 3], b: [u32; 3]) -> PairResult {
    let mut result = PairResult::default();
    let ca = plane_cut(geo, a, b, 0);
    let cb = plane_cut(geo, b, a, 1);
    // `A ∩ plane(B)` lies on the line; candidates outside the other triangle
    // were dropped, so each list holds the ends of the part inside both
    // planes and inside its own triangle, clipped to the other where the
    // other's boundary crosses. Merge both lists along the line.
    let mut all: Vec<Candidate> = ca.iter().chain(&cb).copied().collect();
    if all.is_empty() {
        return result;
    }
    let defs: Vec<PointDef> = all.iter().map(|c| geo.def_of(&c.key)).collect();
    // An axis along which the line is not flat.
    let mut axis = None;
    'outer: for i in 0..defs.len() {
        for j in i + 1..defs.len() {
            if let Some(k) = geo.line_axis(&defs[i], &defs[j]) {
                axis = Some(k);
                break 'outer;
            }
        }
    }
    let mut order: Vec<usize> = (0..all.len()).collect();
    if let Some(k) = axis {
        order.sort_by(|&i, &j| geo.cmp_axis(&defs[i], &defs[j], k));
    }
    // Each list is the part of its own triangle inside the other plane; it
    // is reduced here to the points inside both triangles: a candidate of
    // `A` was kept only when it lies in closed `B`, and vice versa. The ends
    // of `A ∩ B` are the extreme kept candidates.
    all = order.iter().map(|&i| all[i]).collect();
    let defs: Vec<PointDef> = order.iter().map(|&i| defs[i]).collect();
    let first = all[0];
    let last = all[all.len() - 1];
    let same = geo.same(&defs[0], &defs[defs.len() - 1]);
    result.points.push((first.key, first.at));
    if same {
        return result;
    }
    result.points.push((last.key, last.at));
    let pa = a.map(|v| geo.pos(v));
    let pb = b.map(|v| geo.pos(v));
    let zeros = |own: [glam::DVec3; 3], other: [glam::DVec3; 3], ids: [u32; 3]| {
        let s: [i8; 3] = std::array::from_fn(|i| orient3(other[0], other[1], other[2], own[i]));
        let z: Vec<usize> = (0..3).filter(|&i| s[i] == 0).collect();
        (z.len() == 2).then(|| edge(ids[z[0]], ids[z[1]]))
    };
    let a_edge = zeros(pa, pb, a);
    let b_edge = zeros(pb, pa, b);
    let line_for = |own_edge: Option<Edge>, other_edge: Option<Edge>, other: [u32; 3]| match (
        own_edge, other_edge,
    ) {
        (Some(_), _) => None,
        (None, Some(f)) => Some(Line::Edge(f)),
        (None, None) => Some(Line::Plane(other)),
    };
    if let Some(line) = line_for(a_edge, b_edge, b) {
        result.segments.push((0, line, first.key, last.key));
    }
    if let Some(line) = line_for(b_edge, a_edge, a) {
        result.segments.push((1, line, first.key, last.key));
    }
    result
}

fn coplanar_pair(geo: &Geo, a: [u32; 3], b: [u32; 3]) -> PairResult {
    let mut result = PairResult {
        coplanar: true,
        ..PairResult::default()
    };
    let Some(axis) = geo.triangle_axis(a) else {
        return result;
    };
    let tris = [a, b];
    let p2 = tris.map(|t| t.map(|v| project(geo.pos(v), axis)));
    let sign = p2.map(|t| orient2(t[0], t[1], t[2]));
    // Vertices of each inside (or on the boundary of) the other.
    let mut located: [[Option<Where>; 3]; 2] = [[None; 3]; 2];
    for s in 0..2 {
        let o = 1 - s;
        for i in 0..3 {
            let v = tris[s][i];
            located[s][i] = if tris[o].contains(&v) {
                Some(Where::Corner)
            } else {
                locate_2d(p2[s][i], p2[o], sign[o]).map(|loc| match loc {
                    None => Where::Interior,
                    Some(j) => Where::Edge(edge(tris[o][j], tris[o][(j + 1) % 3])),
                })
            };
            if let Some(at) = located[s][i] {
                let mut pair_at = [Where::Corner; 2];
                pair_at[o] = at;
                result.points.push((Key::Vertex(v), pair_at));
            }
        }
    }
    // Proper crossings of an edge of `a` with an edge of `b`.
    let mut crossings: Vec<(usize, usize, Key)> = Vec::new();
    for i in 0..3 {
        let (e0, e1) = (p2[0][i], p2[0][(i + 1) % 3]);
        for j in 0..3 {
            let (f0, f1) = (p2[1][j], p2[1][(j + 1) % 3]);
            let (o1, o2) = (orient2(e0, e1, f0), orient2(e0, e1, f1));
            let (o3, o4) = (orient2(f0, f1, e0), orient2(f0, f1, e1));
            if o1 * o2 < 0 && o3 * o4 < 0 {
                let e = edge(a[i], a[(i + 1) % 3]);
                let f = edge(b[j], b[(j + 1) % 3]);
                let key = Key::EdgeEdge(e.min(f), e.max(f));
                result.points.push((key, [Where::Edge(e), Where::Edge(f)]));
                crossings.push((i, j, key));
            }
        }
    }
    // Each edge of one, clipped to the other, constrains the other.
    for s in 0..2 {
        let o = 1 - s;
        for j in 0..3 {
            let (f0, f1) = (p2[s][j], p2[s][(j + 1) % 3]);
            let along_boundary = (0..3).any(|i| {
                let (e0, e1) = (p2[o][i], p2[o][(i + 1) % 3]);
                orient2(e0, e1, f0) == 0 && orient2(e0, e1, f1) == 0
            });
            if along_boundary {
                continue;
            }
            let f = edge(tris[s][j], tris[s][(j + 1) % 3]);
            let mut on: Vec<Key> = Vec::new();
            for end in [j, (j + 1) % 3] {
                if located[s][end].is_some() {
                    on.push(Key::Vertex(tris[s][end]));
                }
            }
            for (i, at) in located[o].iter().enumerate() {
                if *at == Some(Where::Edge(f)) {
                    on.push(Key::Vertex(tris[o][i]));
                }
            }
            for &(i, jj, key) in &crossings {
                if (s == 0 && i == j) || (s == 1 && jj == j) {
                    on.push(key);
                }
            }
            on.sort_unstable();
            on.dedup();
            if on.len() < 2 {
                continue;
            }
            let defs: Vec<PointDef> = on.iter().map(|k| geo.def_of(k)).collect();
            let ends = [PointDef::Vertex(f[0]), PointDef::Vertex(f[1])];
            let Some(k) = geo.line_axis(&ends[0], &ends[1]) else {
                continue;
            };
            let mut order: Vec<usize> = (0..on.len()).collect();
            order.sort_by(|&x, &y| geo.cmp_axis(&defs[x], &defs[y], k));
            let (lo, hi) = (order[0], order[order.len() - 1]);
            if geo.same(&defs[lo], &defs[hi]) {
                continue;
            }
            result.segments.push((o, Line::Edge(f), on[lo], on[hi]));
        }
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn run(verts: &[Vec3], a: [u32; 3], b: [u32; 3]) -> PairResult {
        intersect_pair(&Geo { verts }, a, b, 0.0)
    }

    #[test]
    fn crossing_x_gives_one_segment_per_triangle() {
        // A in z = 0; B in x = 0.5 crossing A's interior from y = 0.2 to 0.4.
        let v = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(0.5, 0.2, -1.0),
            Vec3::new(0.5, 0.4, 1.0),
            Vec3::new(0.5, 0.3, 1.0),
        ];
        let r = run(&v, [0, 1, 2], [3, 4, 5]);
        assert!(!r.coplanar);
        assert_eq!(r.points.len(), 2);
        // Both ends are B's edges crossing A's interior.
        for (key, at) in &r.points {
            assert!(matches!(key, Key::EdgeTriangle(_, [0, 1, 2])), "{key:?}");
            assert_eq!(at[0], Where::Interior);
            assert!(matches!(at[1], Where::Edge(_)));
        }
        assert_eq!(r.segments.len(), 2);
        assert!(matches!(r.segments[0], (0, Line::Plane([3, 4, 5]), _, _)));
        assert!(matches!(r.segments[1], (1, Line::Plane([0, 1, 2]), _, _)));
    }

    #[test]
    fn edge_through_a_vertex_becomes_that_vertex() {
        // B's edge 3-4 passes exactly through A's corner 1 = (2,0,0).
        let v = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(2.0, -1.0, -1.0),
            Vec3::new(2.0, 1.0, 1.0),
            Vec3::new(0.5, 0.5, 1.0),
        ];
        let r = run(&v, [0, 1, 2], [3, 4, 5]);
        let keys: Vec<Key> = r.points.iter().map(|p| p.0).collect();
        assert!(keys.contains(&Key::Vertex(1)), "{keys:?}");
        let at = r.points.iter().find(|p| p.0 == Key::Vertex(1)).unwrap().1;
        assert_eq!(at, [Where::Corner, Where::Edge([3, 4])]);
    }

    #[test]
    fn coplanar_overlap_clips_edges_both_ways() {
        // Two right triangles in z = 0 overlapping in a small triangle.
        let v = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(4.0, 0.0, 0.0),
            Vec3::new(0.0, 4.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(5.0, 1.0, 0.0),
            Vec3::new(1.0, 5.0, 0.0),
        ];
        let r = run(&v, [0, 1, 2], [3, 4, 5]);
        assert!(r.coplanar);
        // Vertex 3 inside A; two edge crossings (B's edges 3-4 and 3-5
        // cross A's hypotenuse 1-2).
        let crossings = r
            .points
            .iter()
            .filter(|p| matches!(p.0, Key::EdgeEdge(..)))
            .count();
        assert_eq!(crossings, 2);
        let seg_a = r.segments.iter().filter(|s| s.0 == 0).count();
        let seg_b = r.segments.iter().filter(|s| s.0 == 1).count();
        assert_eq!((seg_a, seg_b), (2, 1));
    }
}
