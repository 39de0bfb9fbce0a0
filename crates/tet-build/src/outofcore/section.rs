//! The seam of a plane: one planar constrained Delaunay triangulation
//! (`spade`) of the section of a box, with cut segments, in-plane scene
//! edges and vertices as constraints; both parts next to the plane get its
//! triangles as facets.

use std::collections::HashMap;

use glam::{DVec2, Vec3};
use spade::handles::FixedVertexHandle;
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

use super::error::SeamError;
use super::plane::{SplitPlane, key};

/// The seam: triangles in the plane, each with the in-plane scene triangle
/// it lies in (cleaned index), if any.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Seam {
    /// Triangles (oriented as their scene triangle where they have one).
    pub triangles: Vec<[Vec3; 3]>,
    /// Scene triangle each lies in.
    pub source: Vec<Option<u32>>,
    /// Number of distinct seam vertices.
    pub vertices: usize,
}

/// Builds the seam triangulation of the rectangle `corners` (on the plane)
/// with `segments` and `points` as constraints and the in-plane scene
/// triangles `in_plane` (vertices, cleaned index) as constraint edges and
/// face labels.
pub fn seam_triangulation(
    plane: SplitPlane,
    corners: [Vec3; 4],
    segments: &[[Vec3; 2]],
    points: &[Vec3],
    in_plane: &[([Vec3; 3], u32)],
) -> Result<Seam, SeamError> {
    let (u, v) = ((plane.axis + 1) % 3, (plane.axis + 2) % 3);
    let to2 = |p: Vec3| Point2::new(p[u] as f64, p[v] as f64);
    let to3 = |p: Point2<f64>| {
        let mut r = Vec3::ZERO;
        r[plane.axis] = plane.value;
        r[u] = p.x as f32;
        r[v] = p.y as f32;
        r
    };
    let mut cdt: ConstrainedDelaunayTriangulation<Point2<f64>> =
        ConstrainedDelaunayTriangulation::new();
    let mut handles = HashMap::new();
    let mut insert = |cdt: &mut ConstrainedDelaunayTriangulation<Point2<f64>>, p: Vec3| {
        if let Some(&h) = handles.get(&key(p)) {
            return Ok::<_, SeamError>(h);
        }
        let h = cdt.insert(to2(p)).map_err(|e| SeamError::SeamPoint {
            point: p,
            message: format!("{e:?}"),
        })?;
        handles.insert(key(p), h);
        Ok(h)
    };
    for &c in &corners {
        insert(&mut cdt, c)?;
    }
    for &p in points {
        insert(&mut cdt, p)?;
    }
    let mut edges: Vec<[Vec3; 2]> = segments.to_vec();
    for (t, _) in in_plane {
        for i in 0..3 {
            edges.push([t[i], t[(i + 1) % 3]]);
        }
    }
    for e in &edges {
        insert(&mut cdt, e[0])?;
        insert(&mut cdt, e[1])?;
    }
    for e in &edges {
        let (h0, h1) = (insert(&mut cdt, e[0])?, insert(&mut cdt, e[1])?);
        add_seam_constraint(&mut cdt, (e[0], h0), (e[1], h1))?;
    }
    let orient2 = |a: DVec2, b: DVec2, c: DVec2| {
        robust::orient2d(
            robust::Coord { x: a.x, y: a.y },
            robust::Coord { x: b.x, y: b.y },
            robust::Coord { x: c.x, y: c.y },
        )
    };
    let flat = |p: Vec3| DVec2::new(p[u] as f64, p[v] as f64);
    let mut seam = Seam {
        vertices: cdt.num_vertices(),
        ..Seam::default()
    };
    for f in cdt.inner_faces() {
        let [a, b, c] = f.vertices().map(|h| to3(h.position()));
        let mut t = [a, b, c];
        // Which in-plane scene triangle contains the centroid (strictly)?
        let g = (flat(a) + flat(b) + flat(c)) / 3.0;
        let mut source = None;
        for (s, id) in in_plane {
            let [p, q, r] = s.map(flat);
            let o = orient2(p, q, r);
            let inside = [(p, q), (q, r), (r, p)]
                .iter()
                .all(|&(x, y)| orient2(x, y, g) * o > 0.0);
            if inside {
                source = Some(*id);
                // Orient like the scene triangle.
                if orient2(flat(t[0]), flat(t[1]), flat(t[2])) * o < 0.0 {
                    t.swap(1, 2);
                }
                break;
            }
        }
        seam.triangles.push(t);
        seam.source.push(source);
    }
    Ok(seam)
}

/// Adds the segment between the already inserted seam points `a` and `b`
/// (with their CDT handles) as a constraint, unless it is degenerate or
/// already there. Two constraints that cross mean the seam cannot be
/// triangulated conformingly: an error naming the segment.
pub(super) fn add_seam_constraint(
    cdt: &mut ConstrainedDelaunayTriangulation<Point2<f64>>,
    (a, h0): (Vec3, FixedVertexHandle),
    (b, h1): (Vec3, FixedVertexHandle),
) -> Result<(), SeamError> {
    if h0 == h1 || cdt.exists_constraint(h0, h1) {
        return Ok(());
    }
    if !cdt.can_add_constraint(h0, h1) {
        return Err(SeamError::SeamConstraintsCross { from: a, to: b });
    }
    cdt.add_constraint(h0, h1);
    Ok(())
}
