//! The scene's own triangles, recovered from a mesh's constrained faces.
//!
//! A constrained face is a piece of one input triangle
//! ([`ConstrainedFace::triangle`](crate::ConstrainedFace::triangle)): usually the whole triangle, but a
//! triangle that crossed another (resolved before TetGen) or a wall of a
//! walled or out-of-core build is tiled by several coplanar pieces. Methods
//! that index the scene itself (the BVH and Ray-Strips baselines) should
//! see the triangles as the user gave them, not the pieces: a BVH over the
//! pieces of a walled Torus Knots in a Box traced 20 % slower.
//!
//! The pieces of a triangle tile it, and its three corners are mesh points
//! (every scene vertex is one), so the triangle is the largest triangle
//! spanned by its pieces' vertices, oriented as its pieces are. A triangle
//! with one piece is that piece, vertex order and all.

use glam::DVec3;

use crate::TetMesh;

/// The input triangles of a mesh, by id (the scene's own order, whatever
/// order the mesh keeps its faces in), each with its pieces.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct InputTriangles {
    /// Corners of each input triangle (mesh point ids), in the pieces'
    /// winding.
    pub corners: Vec<[u32; 3]>,
    /// Each input triangle's id ([`ConstrainedFace::triangle`](crate::ConstrainedFace::triangle)).
    pub ids: Vec<u32>,
    /// Constrained faces of input triangle `i`:
    /// `pieces[starts[i]..starts[i + 1]]`.
    starts: Vec<u32>,
    pieces: Vec<u32>,
    /// The input triangle of each constrained face.
    of_face: Vec<u32>,
}

impl InputTriangles {
    /// Groups `mesh`'s constrained faces by input triangle.
    pub fn of(mesh: &TetMesh) -> InputTriangles {
        let faces = &mesh.constrained;
        let mut ids: Vec<u32> = faces.iter().map(|cf| cf.triangle).collect();
        ids.sort_unstable();
        ids.dedup();
        let of_face: Vec<u32> = faces
            .iter()
            .map(|cf| ids.binary_search(&cf.triangle).expect("listed above") as u32)
            .collect();
        let mut starts = vec![0u32; ids.len() + 1];
        for &i in &of_face {
            starts[i as usize + 1] += 1;
        }
        for i in 0..ids.len() {
            starts[i + 1] += starts[i];
        }
        let mut fill = starts.clone();
        let mut pieces = vec![0u32; faces.len()];
        for (f, &i) in of_face.iter().enumerate() {
            pieces[fill[i as usize] as usize] = f as u32;
            fill[i as usize] += 1;
        }
        let mut t = InputTriangles {
            corners: Vec::with_capacity(ids.len()),
            ids,
            starts,
            pieces,
            of_face,
        };
        t.corners = (0..t.ids.len()).map(|i| t.recover(mesh, i)).collect();
        t
    }

    /// Number of input triangles.
    pub fn len(&self) -> usize {
        self.ids.len()
    }

    /// True when the mesh has no constrained face.
    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }

    /// The constrained faces that tile input triangle `i`.
    pub fn pieces(&self, i: usize) -> &[u32] {
        &self.pieces[self.starts[i] as usize..self.starts[i + 1] as usize]
    }

    /// The input triangle constrained face `face` is a piece of.
    pub fn of_face(&self, face: u32) -> Option<u32> {
        self.of_face.get(face as usize).copied()
    }

    /// A piece of input triangle `i` that holds point `p` of its plane (a
    /// point on a seam between pieces gets one of them; a point a hair
    /// outside every piece, the nearest).
    pub fn piece_at(&self, mesh: &TetMesh, i: usize, p: DVec3) -> u32 {
        let pieces = self.pieces(i);
        if pieces.len() == 1 {
            return pieces[0];
        }
        let depth = |f: u32| {
            let v = mesh.constrained[f as usize]
                .vertices
                .map(|v| mesh.points[v as usize].as_dvec3());
            let ([b0, b1, b2], _) = plane_barycentrics(v, p);
            b0.min(b1).min(b2)
        };
        // The first piece that holds `p`, else the one it lies deepest in
        // (rounding puts a point on a seam a hair outside both pieces).
        let mut best = (pieces[0], f64::NEG_INFINITY);
        for &f in pieces {
            let d = depth(f);
            if d >= 0.0 {
                return f;
            }
            if d > best.1 {
                best = (f, d);
            }
        }
        best.0
    }

    /// Input triangle `i`'s corners: its only piece, or the largest
    /// triangle its pieces' vertices span, wound as its largest piece.
    fn recover(&self, mesh: &TetMesh, i: usize) -> [u32; 3] {
        let pieces = self.pieces(i);
        let face = |f: u32| mesh.constrained[f as usize].vertices;
        if pieces.len() == 1 {
            return face(pieces[0]);
        }
        let at = |v: u32| mesh.points[v as usize].as_dvec3();
        let normal = |t: [u32; 3]| (at(t[1]) - at(t[0])).cross(at(t[2]) - at(t[0]));
        let widest = pieces
            .iter()
            .map(|&f| face(f))
            .max_by(|a, b| normal(*a).length().total_cmp(&normal(*b).length()))
            .expect("an input triangle has a piece");
        let mut verts: Vec<u32> = pieces.iter().flat_map(|&f| face(f)).collect();
        verts.sort_unstable();
        verts.dedup();
        let mut best = (widest, normal(widest).length());
        for (a, &x) in verts.iter().enumerate() {
            for (b, &y) in verts.iter().enumerate().skip(a + 1) {
                for &z in &verts[b + 1..] {
                    let area = normal([x, y, z]).length();
                    if area > best.1 {
                        best = ([x, y, z], area);
                    }
                }
            }
        }
        let [x, y, z] = best.0;
        if normal([x, y, z]).dot(normal(widest)) < 0.0 {
            [x, z, y]
        } else {
            [x, y, z]
        }
    }
}

/// The barycentric weights of point `p` (of the triangle's plane, or
/// projected on it) with respect to the triangle `v`, signed (negative
/// outside an edge), and the triangle's normal `(v1 − v0) × (v2 − v0)`.
/// In f64: a scene at 1e30 has normals whose squared length overflows f32.
pub fn plane_barycentrics(v: [DVec3; 3], p: DVec3) -> ([f64; 3], DVec3) {
    let n = (v[1] - v[0]).cross(v[2] - v[0]);
    let area = n.length_squared().max(f64::MIN_POSITIVE);
    // Signed areas of the sub-triangles opposite vertices 1 and 2.
    let b1 = (p - v[0]).cross(v[2] - v[0]).dot(n) / area;
    let b2 = (v[1] - v[0]).cross(p - v[0]).dot(n) / area;
    ([1.0 - b1 - b2, b1, b2], n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ConstrainedFace, FaceSide};
    use glam::Vec3;

    fn face(triangle: u32, vertices: [u32; 3]) -> ConstrainedFace {
        ConstrainedFace {
            triangle,
            vertices,
            front: FaceSide::NONE,
            back: FaceSide::NONE,
        }
    }

    /// A triangle cut into three pieces (by a wall through a corner and
    /// the opposite edge, then across one part), between two whole ones,
    /// is recovered with its corners and winding; the whole ones are
    /// their faces unchanged; each point finds the piece holding it.
    #[test]
    fn pieces_merge_back_into_their_triangle() {
        // Triangle 7: corners 0 (0,0,0), 1 (4,0,0), 2 (0,4,0), wound 0-1-2
        // (normal +z). Point 3 (2,2,0) on edge 1-2, point 4 (1,1,0) on the
        // cut 0-3, point 5 (2,0,0) on edge 0-1.
        let points = vec![
            Vec3::ZERO,
            Vec3::new(4.0, 0.0, 0.0),
            Vec3::new(0.0, 4.0, 0.0),
            Vec3::new(2.0, 2.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 5.0),
            Vec3::new(1.0, 0.0, 5.0),
            Vec3::new(0.0, 1.0, 5.0),
        ];
        let constrained = vec![
            face(3, [6, 8, 7]),
            face(7, [0, 3, 2]),
            face(7, [5, 3, 4]),
            face(9, [6, 7, 8]),
            face(7, [0, 5, 4]),
            face(7, [5, 1, 3]),
        ];
        let mesh = TetMesh {
            points,
            constrained,
            ..TetMesh::default()
        };
        let t = InputTriangles::of(&mesh);
        assert_eq!(t.len(), 3);
        assert_eq!(t.ids, vec![3, 7, 9]);
        assert_eq!(t.corners[0], [6, 8, 7]);
        assert_eq!(t.corners[2], [6, 7, 8]);
        // The same cyclic order as 0-1-2.
        let c = t.corners[1];
        let rot = [[0, 1, 2], [1, 2, 0], [2, 0, 1]];
        assert!(rot.contains(&c), "{c:?}");
        assert_eq!(t.pieces(1), &[1, 2, 4, 5]);
        assert_eq!(t.of_face(4), Some(1));
        assert_eq!(t.of_face(6), None);
        let at = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        assert_eq!(t.piece_at(&mesh, 1, at(0.5, 2.0)), 1);
        assert_eq!(t.piece_at(&mesh, 1, at(3.0, 0.5)), 5);
        assert_eq!(t.piece_at(&mesh, 1, at(1.2, 0.3)), 4);
        assert_eq!(t.piece_at(&mesh, 0, at(9.0, 9.0)), 0);
    }
}
