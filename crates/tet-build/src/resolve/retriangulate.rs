//! One triangle cut into pieces: a planar constrained Delaunay
//! triangulation (spade) of its points, with the subdivided boundary and
//! the split segments as constraints.
//!
//! The triangulation is made on the vertices' own (rounded) coordinates,
//! projected along the axis [`super::cutlines`] chose, so the pieces of one
//! triangle never overlap: they tile its boundary polygon in that
//! projection. A constraint that rounding made cross another is left out
//! (the re-check after the round finds what that leaves); a piece whose
//! corners are exactly collinear in 3-D is dropped (the re-check finds the
//! vertex on its neighbour's edge).
//!
//! Pieces are wound like the triangle in the projection, except a sliver
//! whose rounded corners tilt its normal against the input triangle's: it
//! is turned over, so every piece's normal agrees with its input triangle
//! (unless the two are exactly perpendicular).
//!
//! Faces inside the boundary are found by a flood fill from the convex hull
//! that stops at boundary constraints. If the boundary could not be
//! inserted as a closed polygon, faces are kept by whether their centroid
//! lies in the triangle instead.

use std::collections::HashSet;

use glam::DVec3;
use spade::handles::{FixedUndirectedEdgeHandle, FixedVertexHandle};
use spade::{ConstrainedDelaunayTriangulation, InsertionError, Point2, Triangulation};

use super::points::{Geo, Plane, PointDef, edge, orient2, project};
use crate::clean::collinear;

/// A point of the triangle being cut.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PiecePoint {
    /// Its id in the round's table (class representative), or `u32::MAX`
    /// for a corner the table does not name.
    pub id: u32,
    /// Its vertex after rounding.
    pub vertex: u32,
    /// Its construction.
    pub def: PointDef,
}

/// What one triangle is cut along.
#[derive(Clone, Debug, Default)]
pub(crate) struct PieceInput {
    /// The triangle (vertex ids).
    pub tri: [u32; 3],
    /// The input triangle it lies in (vertex ids), whose normal the
    /// pieces' normals must agree with.
    pub parent: [u32; 3],
    /// Its projection axis.
    pub axis: usize,
    /// Its distinct points (corners included).
    pub points: Vec<PiecePoint>,
    /// Its boundary, from corner 0, through every point on its edges, as
    /// indices into `points` (closed: the last connects to the first).
    pub chain: Vec<usize>,
    /// For each chain entry, the triangle edge (0: corners 0-1, 1: 1-2,
    /// 2: 2-0) the boundary runs along from there.
    pub chain_edge: Vec<u8>,
    /// Constraint edges inside (indices into `points`).
    pub constraints: Vec<[usize; 2]>,
    /// Coplanar triangles that keep the area they share with this one.
    pub partners: Vec<[u32; 3]>,
    /// A needle thinner than the snap distance: it gives no pieces.
    pub collapsed: bool,
}

/// The pieces of one triangle.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Pieces {
    /// Pieces, wound like the triangle.
    pub triangles: Vec<[u32; 3]>,
    /// Pieces dropped because a partner keeps that area.
    pub dropped: usize,
}

/// Smallest magnitude spade accepts; smaller coordinates count as zero
/// (a shift far below any `f32` spacing of the scene).
const SPADE_MIN: f64 = spade::MIN_ALLOWED_VALUE;

fn point2(p: DVec3, axis: usize) -> Point2<f64> {
    let (x, y) = project(p, axis);
    let clamp = |v: f64| if v.abs() < SPADE_MIN { 0.0 } else { v };
    Point2::new(clamp(x), clamp(y))
}

type Cdt = ConstrainedDelaunayTriangulation<Point2<f64>>;

/// Cuts `input.tri` (see the module docs).
pub(crate) fn retriangulate(geo: &Geo, input: &PieceInput) -> Result<Pieces, InsertionError> {
    if input.collapsed {
        return Ok(Pieces {
            triangles: Vec::new(),
            dropped: 1,
        });
    }
    let verts = geo.verts;
    let axis = input.axis;
    let mut cdt = Cdt::new();
    // Spade merges points at one position: the first one names the vertex.
    let mut point_of: Vec<usize> = Vec::new();
    let mut handles: Vec<FixedVertexHandle> = Vec::with_capacity(input.points.len());
    for (i, p) in input.points.iter().enumerate() {
        let h = cdt.insert(point2(verts[p.vertex as usize].as_dvec3(), axis))?;
        if h.index() == point_of.len() {
            point_of.push(i);
        }
        handles.push(h);
    }
    // The boundary first: it must not give way to anything inside.
    let mut barrier: HashSet<FixedUndirectedEdgeHandle> = HashSet::new();
    let mut closed = true;
    let chain = &input.chain;
    for i in 0..chain.len() {
        let (h0, h1) = (handles[chain[i]], handles[chain[(i + 1) % chain.len()]]);
        if h0 == h1 {
            continue;
        }
        let edges = cdt.try_add_constraint(h0, h1);
        if edges.is_empty() {
            closed = false;
        }
        barrier.extend(edges.iter().map(|e| e.as_undirected()));
    }
    for &[a, b] in &input.constraints {
        let (h0, h1) = (handles[a], handles[b]);
        if h0 != h1 {
            // A constraint crossing another is left out; the re-check after
            // the round finds what that leaves.
            cdt.try_add_constraint(h0, h1);
        }
    }
    let inside = if closed {
        flood_inside(&cdt, &barrier)
    } else {
        vec![false; cdt.num_all_faces()]
    };
    let corners = input
        .tri
        .map(|v| project(verts[v as usize].as_dvec3(), axis));
    let sign = orient2(corners[0], corners[1], corners[2]);
    let in_triangle =
        |p: (f64, f64)| (0..3).all(|i| orient2(corners[i], corners[(i + 1) % 3], p) * sign >= 0);
    let partner_sides: Vec<([u32; 3], i8)> = input
        .partners
        .iter()
        .map(|&t| {
            let p = t.map(|v| project(verts[v as usize].as_dvec3(), axis));
            (t, orient2(p[0], p[1], p[2]))
        })
        .collect();
    let mut pieces = Pieces::default();
    for face in cdt.inner_faces() {
        let keep = if closed {
            inside[face.fix().index()]
        } else {
            let c = face
                .vertices()
                .map(|h| DVec3::new(h.position().x, h.position().y, 0.0))
                .iter()
                .sum::<DVec3>()
                / 3.0;
            in_triangle((c.x, c.y))
        };
        if !keep {
            continue;
        }
        let pts = face
            .vertices()
            .map(|h| &input.points[point_of[h.fix().index()]]);
        let covered = partner_sides
            .iter()
            .any(|&(t, s)| pts.iter().all(|p| inside_closed(geo, &p.def, t, s, axis)));
        if covered {
            pieces.dropped += 1;
            continue;
        }
        let ids = pts.map(|p| p.vertex);
        let [a, b, c] = ids.map(|v| verts[v as usize]);
        if ids[0] == ids[1] || ids[1] == ids[2] || ids[0] == ids[2] || collinear(a, b, c) {
            continue;
        }
        // spade's faces are counter-clockwise in the projection; a sliver
        // that rounding tilted against the input triangle is turned over
        // (its normal, not its projection, decides).
        let mut piece = if sign > 0 {
            ids
        } else {
            [ids[0], ids[2], ids[1]]
        };
        if geo.normal_agreement(piece, input.parent) < 0 {
            piece.swap(1, 2);
        }
        pieces.triangles.push(piece);
    }
    if let [t] = pieces.triangles.as_slice() {
        let mut a = *t;
        let mut b = input.tri;
        a.sort_unstable();
        b.sort_unstable();
        if a == b {
            pieces.triangles[0] = input.tri;
        }
    }
    Ok(pieces)
}

/// Faces not reachable from the outside without crossing the boundary.
fn flood_inside(cdt: &Cdt, barrier: &HashSet<FixedUndirectedEdgeHandle>) -> Vec<bool> {
    let mut outside = vec![false; cdt.num_all_faces()];
    let mut stack = Vec::new();
    for face in cdt.inner_faces() {
        for e in face.adjacent_edges() {
            if e.rev().face().is_outer() && !barrier.contains(&e.fix().as_undirected()) {
                let i = face.fix().index();
                if !outside[i] {
                    outside[i] = true;
                    stack.push(face.fix());
                }
            }
        }
    }
    while let Some(f) = stack.pop() {
        for e in cdt.face(f).adjacent_edges() {
            if barrier.contains(&e.fix().as_undirected()) {
                continue;
            }
            if let Some(g) = e.rev().face().as_inner() {
                let i = g.fix().index();
                if !outside[i] {
                    outside[i] = true;
                    stack.push(g.fix());
                }
            }
        }
    }
    let mut inside: Vec<bool> = outside.iter().map(|o| !o).collect();
    inside[0] = false; // the outer face
    inside
}

/// Is the exact point `p` (in the common plane) inside the closed triangle
/// `t`, whose projection has orientation `sign`?
fn inside_closed(geo: &Geo, p: &PointDef, t: [u32; 3], sign: i8, axis: usize) -> bool {
    (0..3).all(|i| {
        let (a, b) = (t[i], t[(i + 1) % 3]);
        let e = edge(a, b);
        let flip = if e[0] == a { 1 } else { -1 };
        let plane = Plane::Vertical {
            edge: e,
            axis: axis as u8,
        };
        geo.side(p, &plane) * flip * sign >= 0
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn a_split_edge_and_an_inner_segment_make_four_pieces() {
        // Triangle 0-1-2 in z = 0 (clockwise seen from +z), point 3 on edge
        // 0-1, point 4 inside; constraint 3-4.
        let verts = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.0, 4.0, 0.0),
            Vec3::new(4.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
        ];
        let geo = Geo { verts: &verts };
        let points = (0..5)
            .map(|v| PiecePoint {
                id: v,
                vertex: v,
                def: PointDef::Vertex(v),
            })
            .collect();
        let input = PieceInput {
            tri: [0, 1, 2],
            parent: [0, 1, 2],
            axis: 2,
            points,
            chain: vec![0, 3, 1, 2],
            chain_edge: vec![0, 0, 1, 2],
            constraints: vec![[3, 4]],
            partners: Vec::new(),
            collapsed: false,
        };
        let pieces = retriangulate(&geo, &input).unwrap();
        let area = |t: &[u32; 3]| {
            let [a, b, c] = t.map(|v| verts[v as usize].as_dvec3());
            (b - a).cross(c - a).z * 0.5
        };
        // All clockwise like the triangle (negative z area), summing to it.
        assert!(pieces.triangles.iter().all(|t| area(t) < 0.0));
        let total: f64 = pieces.triangles.iter().map(area).sum();
        assert_eq!(total, area(&[0, 1, 2]));
        assert_eq!(pieces.triangles.len(), 4);
        assert!(
            pieces
                .triangles
                .iter()
                .any(|t| t.contains(&3) && t.contains(&4))
        );
    }
}
