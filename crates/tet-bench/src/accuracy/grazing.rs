//! Whether a ray that grazes an edge or a vertex of the scene's surface
//! must cross the surface there, or may pass it by: what separates a leak
//! (a method slipped through a watertight surface) from a grazing ray
//! (rounding may rightly decide either way) in the accuracy measurement.
//!
//! # The star and its parity
//!
//! The reference hit point `x` lies within the tolerance of some edges or
//! vertices of its face (the *grazed* features). The *star* `S` is every
//! constrained face containing a grazed vertex, or both ends of a grazed
//! edge. Every line within the tolerance of the ray's line crosses the
//! faces of `S` near `x` some number of times, and how many changes as
//! the line moves sideways only where it crosses an edge of `S` — by one
//! where that edge belongs to an odd number of faces of `S` (an *odd
//! edge*), by two (a fold) or none (a crossing moved from one face to its
//! neighbour) elsewhere. Far away the line crosses none of `S`, so seen
//! along the ray (projected onto the plane orthogonal to its direction,
//! the line a point `p`), the parity of the crossings is the parity of the
//! odd edges a half-line from `p` meets.
//!
//! * **Odd**: every nearby line crosses the surface here. A ray entering
//!   a closed surface across an edge (the two faces on either side of it)
//!   or through a vertex; a method that misses or hits something farther
//!   along leaked.
//! * **Even**: some nearby line crosses none of `S`. A ray clipping a
//!   convex edge (both faces of the edge on one side of it, as on a
//!   silhouette), or touching a vertex of the outline; a method may pass
//!   it by — but must then hit the first face beyond `S`.
//! * **Undecided**: an odd edge passes within the tolerance of the line
//!   (an open edge of the surface is grazed, or the line passes by the
//!   star's rim): grazing, never a leak.
//!
//! The test uses the f64 positions of the faces and nothing else, so it
//! does not depend on the faces' winding.

use std::collections::{HashMap, HashSet};

use glam::{DVec2, DVec3};
use tet_core::TetMesh;
use tet_trace_cpu::reference::segment_distance;

/// The faces around every edge and vertex of the constrained faces.
#[derive(Clone, Debug, Default)]
pub(crate) struct Surface {
    /// Faces per edge, the edge as its sorted vertex pair.
    edge_faces: HashMap<(u32, u32), u32>,
    /// Faces around each vertex.
    vertex_faces: HashMap<u32, Vec<u32>>,
}

/// The edge `a`–`b` as a sorted key.
fn edge_key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// What a grazing ray must do at the star of the features it grazes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum Graze {
    /// Every nearby line crosses the star: passing it by is a leak.
    MustCross,
    /// Some nearby line passes the star by (faces of the star, sorted):
    /// a method may skip them, not what lies beyond.
    MayPass(Vec<u32>),
    /// Undecided (an open edge, or the star's rim, near the line).
    Undecided,
}

impl Surface {
    /// Counts the faces around every edge and vertex of `mesh.constrained`.
    pub(crate) fn new(mesh: &TetMesh) -> Self {
        let mut edge_faces: HashMap<(u32, u32), u32> = HashMap::new();
        let mut vertex_faces: HashMap<u32, Vec<u32>> = HashMap::new();
        for (f, cf) in mesh.constrained.iter().enumerate() {
            let v = cf.vertices;
            for k in 0..3 {
                *edge_faces
                    .entry(edge_key(v[k], v[(k + 1) % 3]))
                    .or_default() += 1;
                vertex_faces.entry(v[k]).or_default().push(f as u32);
            }
        }
        Surface {
            edge_faces,
            vertex_faces,
        }
    }

    /// True when every edge of face `vertices` is shared by at least two
    /// faces: the face lies on a watertight part of the surface.
    pub(crate) fn face_closed(&self, vertices: [u32; 3]) -> bool {
        (0..3).all(|k| {
            self.edge_faces
                .get(&edge_key(vertices[k], vertices[(k + 1) % 3]))
                .is_some_and(|n| *n >= 2)
        })
    }

    /// The star of the edges and vertices of face `vertices` (positions
    /// `p`) that `x` lies within `tol` of (see the module docs), sorted.
    fn star(&self, vertices: [u32; 3], p: [DVec3; 3], x: DVec3, tol: f64) -> Vec<u32> {
        let around = |v: u32| self.vertex_faces.get(&v).into_iter().flatten().copied();
        let mut star = HashSet::new();
        for k in 0..3 {
            let j = (k + 1) % 3;
            if (x - p[k]).length() < tol {
                star.extend(around(vertices[k]));
            }
            if segment_distance(x, p[k], p[j]) < tol {
                let (a, b) = (vertices[k], vertices[j]);
                star.extend(around(a).filter(|&f| self.vertex_faces[&b].contains(&f)));
            }
        }
        let mut star: Vec<u32> = star.into_iter().collect();
        star.sort_unstable();
        star
    }

    /// What the line through `x` along `d` must do at the star of the
    /// features of face `vertices` (positions `p`) it grazes within `tol`.
    pub(crate) fn graze(
        &self,
        mesh: &TetMesh,
        vertices: [u32; 3],
        p: [DVec3; 3],
        x: DVec3,
        d: DVec3,
        tol: f64,
    ) -> Graze {
        let star = self.star(vertices, p, x, tol);
        if star.is_empty() {
            // The line passes near an edge, not the hit point: a ray nearly
            // in the face's plane.
            return Graze::Undecided;
        }
        let mut count: HashMap<(u32, u32), u32> = HashMap::new();
        for &f in &star {
            let v = mesh.constrained[f as usize].vertices;
            for k in 0..3 {
                *count.entry(edge_key(v[k], v[(k + 1) % 3])).or_default() += 1;
            }
        }
        // The odd edges, projected along `d` with the line at the origin.
        let (u, w) = d.normalize().any_orthonormal_pair();
        let flat = |i: u32| {
            let q = mesh.points[i as usize].as_dvec3() - x;
            DVec2::new(q.dot(u), q.dot(w))
        };
        let odd: Vec<[DVec2; 2]> = count
            .iter()
            .filter(|(_, n)| *n % 2 == 1)
            .map(|(&(a, b), _)| [flat(a), flat(b)])
            .collect();
        if odd.iter().any(|&[a, b]| point_segment_2d(a, b) < tol) {
            return Graze::Undecided;
        }
        if odd_crossings(&odd) {
            Graze::MustCross
        } else {
            Graze::MayPass(star)
        }
    }
}

/// Distance from the origin to segment `a`–`b`.
fn point_segment_2d(a: DVec2, b: DVec2) -> f64 {
    let e = b - a;
    let s = if e.length_squared() > 0.0 {
        (-a.dot(e) / e.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + e * s).length()
}

/// True when a half-line from the origin meets an odd number of the
/// segments `odd` (none of which passes through the origin). The half-line
/// bisects the widest angle between the segments' endpoints, so that it
/// passes no endpoint closely.
fn odd_crossings(odd: &[[DVec2; 2]]) -> bool {
    let mut angles: Vec<f64> = odd.iter().flatten().map(|p| p.y.atan2(p.x)).collect();
    if angles.is_empty() {
        return false;
    }
    angles.sort_by(f64::total_cmp);
    // The gap from the last angle round to the first, then the others.
    let last = angles[angles.len() - 1];
    let mut gap = angles[0] + std::f64::consts::TAU - last;
    let mut at = last + 0.5 * gap;
    for k in 1..angles.len() {
        let g = angles[k] - angles[k - 1];
        if g > gap {
            gap = g;
            at = angles[k - 1] + 0.5 * g;
        }
    }
    // Rotate the half-line onto the +x axis.
    let (s, c) = (-at).sin_cos();
    let turn = |p: DVec2| DVec2::new(p.x * c - p.y * s, p.x * s + p.y * c);
    let crossings = odd
        .iter()
        .map(|&[a, b]| (turn(a), turn(b)))
        .filter(|(a, b)| {
            (a.y >= 0.0) != (b.y >= 0.0) && a.x + (b.x - a.x) * (-a.y / (b.y - a.y)) > 0.0
        })
        .count();
    crossings % 2 == 1
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seg(a: [f64; 2], b: [f64; 2]) -> [DVec2; 2] {
        [DVec2::from(a), DVec2::from(b)]
    }

    #[test]
    fn a_polygon_around_the_origin_is_odd_one_beside_it_even() {
        // The link of a vertex: a square around the origin.
        let square = |o: [f64; 2]| {
            let c = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
            (0..4)
                .map(|k| {
                    let (a, b) = (c[k], c[(k + 1) % 4]);
                    seg([a[0] + o[0], a[1] + o[1]], [b[0] + o[0], b[1] + o[1]])
                })
                .collect::<Vec<_>>()
        };
        assert!(odd_crossings(&square([0.0, 0.0])));
        assert!(odd_crossings(&square([0.3, -0.6])));
        assert!(!odd_crossings(&square([3.0, 0.0])));
        assert!(!odd_crossings(&square([-0.5, 2.5])));
        // Two nested squares: every line crosses both sheets.
        let mut two = square([0.0, 0.0]);
        two.extend(square([0.0, 0.0]).iter().map(|s| s.map(|p| p * 2.0)));
        assert!(!odd_crossings(&two));
    }

    #[test]
    fn the_quad_around_an_edge_is_odd_when_its_faces_lie_on_both_sides() {
        // Edge A = (0, -1), B = (0, 1) through the origin; C1 on the left,
        // C2 on the right (a crossing) or both on the left (a ridge).
        let quad = |c1: [f64; 2], c2: [f64; 2]| {
            vec![
                seg([0.0, -1.0], c1),
                seg(c1, [0.0, 1.0]),
                seg([0.0, 1.0], c2),
                seg(c2, [0.0, -1.0]),
            ]
        };
        assert!(odd_crossings(&quad([-1.0, 0.2], [1.0, -0.3])));
        assert!(!odd_crossings(&quad([-1.0, 0.2], [-2.0, -0.3])));
    }
}
