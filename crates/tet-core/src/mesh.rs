//! The canonical tetrahedral mesh: the one representation every layout is
//! converted from and decoded back to.

use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3};

use crate::error::MeshError;
use crate::fields::ScalarField;
use crate::link::{Link, MAX_TETS};

/// Face `k` of a tet is opposite vertex slot `k`; `FACE_VERTICES[k]` lists the
/// other three slots in the order whose right-hand normal points *out of* a
/// positively oriented tet.
pub const FACE_VERTICES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];

/// "No tet": used in [`FaceSide`] for a constrained face on the mesh boundary.
pub const NO_TET: u32 = u32::MAX;

/// One side of a constrained face: the tet and which of its faces it is.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Pod, Zeroable)]
pub struct FaceSide {
    /// Tet index, or [`NO_TET`] when the face is on the mesh boundary.
    pub tet: u32,
    /// Face index 0..4 within `tet` (0 when `tet` is [`NO_TET`]).
    pub face: u32,
}

impl FaceSide {
    /// The absent side of a constrained face on the mesh boundary.
    pub const NONE: FaceSide = FaceSide {
        tet: NO_TET,
        face: 0,
    };

    /// True when a tet is on this side.
    pub fn exists(self) -> bool {
        self.tet != NO_TET
    }
}

/// A face of the tetrahedralization lying on a scene triangle (cold data).
///
/// Secondary rays restart from it (Aman et al. §6): `front` is the tet on the
/// side the triangle's normal points to (right-hand rule on the triangle's own
/// winding, i.e. `vertices` order), `back` the tet on the other side.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Pod, Zeroable)]
pub struct ConstrainedFace {
    /// Id of the source scene triangle (an index into the scene's triangle list).
    pub triangle: u32,
    /// The face's mesh vertices in the source triangle's winding; hit
    /// barycentrics refer to this order.
    pub vertices: [u32; 3],
    /// Tet on the side the triangle's normal points to.
    pub front: FaceSide,
    /// Tet on the opposite side.
    pub back: FaceSide,
}

impl ConstrainedFace {
    /// Records tet `t` (vertices `tet`), whose face `k` is this face, as the
    /// front or the back side according to the face's winding: the
    /// triangle's normal points out of the back tet. Shared by every
    /// builder of the table so the rule exists once.
    pub fn attach_side(&mut self, tet: [u32; 4], t: u32, k: usize) {
        let s = FACE_VERTICES[k];
        let outward = [tet[s[0]], tet[s[1]], tet[s[2]]];
        let side = FaceSide {
            tet: t,
            face: k as u32,
        };
        if same_cyclic_order(self.vertices, outward) {
            self.back = side;
        } else {
            self.front = side;
        }
    }

    /// The side on which `tet` lies, if it is one of the two.
    pub fn side_of(&self, tet: u32) -> Option<FaceSide> {
        if self.front.tet == tet {
            Some(self.front)
        } else if self.back.tet == tet {
            Some(self.back)
        } else {
            None
        }
    }

    /// The side opposite to `tet` (where a ray leaving `tet` through this face continues).
    pub fn other_side(&self, tet: u32) -> Option<FaceSide> {
        if self.front.tet == tet {
            Some(self.back)
        } else if self.back.tet == tet {
            Some(self.front)
        } else {
            None
        }
    }
}

/// Optional per-vertex and per-triangle attributes. A scene pays only for what
/// it has: absent attributes take no memory and are never fetched.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Attributes {
    /// Per-point normals (length = number of points) when the scene has them.
    pub normals: Option<Vec<Vec3>>,
    /// Per-point texture coordinates (length = number of points) when the scene has them.
    pub uvs: Option<Vec<Vec2>>,
    /// Per-scene-triangle material ids (length = triangle count) when the scene has them.
    pub materials: Option<Vec<u32>>,
    /// A per-point scalar field with one or more time steps (the volume an
    /// isosurface is traced in), when the mesh has one. See
    /// [`crate::fields`].
    pub scalars: Option<ScalarField>,
}

impl Attributes {
    /// Exact heap bytes of the attribute arrays present.
    pub fn bytes(&self) -> usize {
        self.normals.as_ref().map_or(0, |v| v.len() * 12)
            + self.uvs.as_ref().map_or(0, |v| v.len() * 8)
            + self.materials.as_ref().map_or(0, |v| v.len() * 4)
            + self.scalars.as_ref().map_or(0, ScalarField::bytes)
    }
}

/// The canonical tetrahedral mesh.
///
/// Invariants (checked by [`TetMesh::validate`]): every tet is positively
/// oriented; `neighbors[t][k]` is the link across face `k` of tet `t`;
/// neighbour links are symmetric and neighbours share the face's vertices;
/// each constrained face is referenced from exactly the tets on its sides.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TetMesh {
    /// Vertex positions.
    pub points: Vec<Vec3>,
    /// Four vertex indices per tet, positively oriented.
    pub tets: Vec<[u32; 4]>,
    /// Link across face `k` (opposite vertex `k`) of each tet.
    pub neighbors: Vec<[Link; 4]>,
    /// The constrained-face table (cold data), indexed by [`Link::as_constrained`].
    pub constrained: Vec<ConstrainedFace>,
    /// Number of scene triangles the `triangle` ids refer to.
    pub triangle_count: u32,
    /// Optional attributes.
    pub attributes: Attributes,
}

/// Sorted vertex triple identifying a face independently of its tet.
#[inline]
pub fn face_key(mut v: [u32; 3]) -> [u32; 3] {
    if v[0] > v[1] {
        v.swap(0, 1);
    }
    if v[1] > v[2] {
        v.swap(1, 2);
    }
    if v[0] > v[1] {
        v.swap(0, 1);
    }
    v
}

/// `(sorted face vertices, tet, face)` for every face of every tet, sorted:
/// faces shared by two tets are adjacent (neighbours by sorting, no hash map).
pub(crate) fn sorted_faces(tets: &[[u32; 4]]) -> Vec<([u32; 3], u32, u8)> {
    let mut faces = Vec::with_capacity(tets.len() * 4);
    for (t, tet) in tets.iter().enumerate() {
        for (k, s) in FACE_VERTICES.iter().enumerate() {
            faces.push((
                face_key([tet[s[0]], tet[s[1]], tet[s[2]]]),
                t as u32,
                k as u8,
            ));
        }
    }
    faces.sort_unstable();
    faces
}

/// True when `b` is a cyclic rotation of `a` (same orientation).
pub(crate) fn same_cyclic_order(a: [u32; 3], b: [u32; 3]) -> bool {
    a == b || a == [b[1], b[2], b[0]] || a == [b[2], b[0], b[1]]
}

impl TetMesh {
    /// Number of tets.
    pub fn tet_count(&self) -> usize {
        self.tets.len()
    }

    /// Vertex ids of face `face` of tet `tet`, ordered so the normal points outward.
    #[inline]
    pub fn face_vertices(&self, tet: u32, face: usize) -> [u32; 3] {
        let v = self.tets[tet as usize];
        let s = FACE_VERTICES[face];
        [v[s[0]], v[s[1]], v[s[2]]]
    }

    /// True when face `face` (0..=3) of tet `tet` exists and lies on the mesh
    /// boundary (its link is [`Link::BOUNDARY`]): where a ray from outside
    /// may enter (`Start::Entry` of the trace crates).
    #[inline]
    pub fn is_boundary_face(&self, tet: u32, face: u8) -> bool {
        self.neighbors
            .get(tet as usize)
            .and_then(|n| n.get(face as usize))
            .is_some_and(|l| *l == Link::BOUNDARY)
    }

    /// The bounds `(min, max)` of the points (infinite and inverted when
    /// there are none). Every tet lies inside them.
    pub fn point_bounds(&self) -> (Vec3, Vec3) {
        self.points
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), p| {
                (a.min(*p), b.max(*p))
            })
    }

    /// Positions of the four vertices of `tet`.
    #[inline]
    pub fn tet_points(&self, tet: u32) -> [Vec3; 4] {
        self.tets[tet as usize].map(|v| self.points[v as usize])
    }

    /// Which face of `tet` is shared with tet `other` (by vertex sets), if any.
    pub fn face_towards(&self, tet: u32, other: u32) -> Option<usize> {
        let a = self.tets[tet as usize];
        let b = self.tets[other as usize];
        // Exactly one vertex of `tet` must be missing from `other`.
        let mut missing = None;
        for (i, v) in a.iter().enumerate() {
            if !b.contains(v) {
                if missing.is_some() {
                    return None;
                }
                missing = Some(i);
            }
        }
        missing
    }

    /// The tet across face `face` of `tet`, crossing constrained faces too
    /// (via the constrained-face table), with the face index on that side.
    pub fn across(&self, tet: u32, face: usize) -> Option<FaceSide> {
        let link = self.neighbors[tet as usize][face];
        if let Some(n) = link.as_tet() {
            let j = self.face_towards(n, tet)?;
            Some(FaceSide {
                tet: n,
                face: j as u32,
            })
        } else if let Some(c) = link.as_constrained() {
            let cf = self.constrained.get(c as usize)?;
            cf.other_side(tet).filter(|s| s.exists())
        } else {
            None
        }
    }

    /// Builds the neighbour links and the constrained-face table from a tet
    /// soup and the scene triangles (`(vertices, triangle id)`, vertices as mesh
    /// point ids in the triangle's winding order).
    ///
    /// Neighbours are found by sorting face keys (no hash map). Every triangle
    /// must be a face of the mesh; two triangles on one face are an error.
    /// `triangle_count` is one more than the largest triangle id (or more).
    pub fn assemble(
        points: Vec<Vec3>,
        tets: Vec<[u32; 4]>,
        triangles: &[([u32; 3], u32)],
        triangle_count: u32,
    ) -> Result<TetMesh, MeshError> {
        if tets.len() >= MAX_TETS as usize {
            return Err(MeshError::TooMany {
                what: "tets",
                count: tets.len(),
                limit: MAX_TETS as usize - 1,
            });
        }
        if triangles.len() >= MAX_TETS as usize {
            return Err(MeshError::TooMany {
                what: "constrained faces",
                count: triangles.len(),
                limit: MAX_TETS as usize - 1,
            });
        }
        for (t, tet) in tets.iter().enumerate() {
            for (slot, &v) in tet.iter().enumerate() {
                if v as usize >= points.len() {
                    return Err(MeshError::VertexOutOfBounds {
                        tet: t as u32,
                        slot: slot as u8,
                        vertex: v,
                        points: points.len(),
                    });
                }
            }
        }
        let faces = sorted_faces(&tets);
        let mut neighbors = vec![[Link::BOUNDARY; 4]; tets.len()];
        for run in faces.chunk_by(|a, b| a.0 == b.0) {
            match run {
                [_] => {}
                [(_, ta, fa), (_, tb, fb)] => {
                    neighbors[*ta as usize][*fa as usize] = Link::tet(*tb);
                    neighbors[*tb as usize][*fb as usize] = Link::tet(*ta);
                }
                _ => {
                    let (key, t, f) = run[0];
                    return Err(MeshError::FaceNotManifold {
                        tet: t,
                        face: f,
                        vertices: key,
                        detail: "shared by more than two tets",
                    });
                }
            }
        }

        let mut constrained = Vec::with_capacity(triangles.len());
        for &(vertices, triangle) in triangles {
            let key = face_key(vertices);
            let start = faces.partition_point(|f| f.0 < key);
            let end = faces.partition_point(|f| f.0 <= key);
            if start == end {
                return Err(MeshError::TriangleNotInMesh { triangle, vertices });
            }
            let index = constrained.len() as u32;
            let mut cf = ConstrainedFace {
                triangle,
                vertices,
                front: FaceSide::NONE,
                back: FaceSide::NONE,
            };
            for &(_, t, f) in &faces[start..end] {
                let link = &mut neighbors[t as usize][f as usize];
                if let Some(prev) = link.as_constrained() {
                    let first: &ConstrainedFace = &constrained[prev as usize];
                    return Err(MeshError::DuplicateTriangle {
                        first: first.triangle,
                        second: triangle,
                        vertices: key,
                    });
                }
                *link = Link::constrained(index);
                cf.attach_side(tets[t as usize], t, f as usize);
            }
            constrained.push(cf);
        }
        Ok(TetMesh {
            points,
            tets,
            neighbors,
            constrained,
            triangle_count,
            attributes: Attributes::default(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two tets sharing face (0,1,2): apex 3 above z = 0, apex 4 below.
    fn bipyramid() -> (Vec<Vec3>, Vec<[u32; 4]>) {
        let points = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.2, 0.2, 1.0),
            Vec3::new(0.2, 0.2, -1.0),
        ];
        // orient(0,1,2,3) > 0 ; orient(1,0,2,4) > 0.
        (points, vec![[0, 1, 2, 3], [1, 0, 2, 4]])
    }

    #[test]
    fn assemble_links_shared_face_and_boundary() {
        let (p, t) = bipyramid();
        let m = TetMesh::assemble(p, t, &[], 0).unwrap();
        m.validate().unwrap();
        assert_eq!(m.neighbors[0][3], Link::tet(1));
        assert_eq!(m.neighbors[1][3], Link::tet(0));
        for k in 0..3 {
            assert!(m.neighbors[0][k].is_boundary());
            assert!(m.neighbors[1][k].is_boundary());
        }
    }

    #[test]
    fn constrained_face_sides_follow_triangle_winding() {
        let (p, t) = bipyramid();
        // Triangle (0,1,2) has normal +z: tet 0 (apex at z = 1) is in front.
        let m = TetMesh::assemble(p.clone(), t.clone(), &[([0, 1, 2], 7)], 8).unwrap();
        m.validate().unwrap();
        let cf = m.constrained[0];
        assert_eq!(cf.triangle, 7);
        assert_eq!(cf.front, FaceSide { tet: 0, face: 3 });
        assert_eq!(cf.back, FaceSide { tet: 1, face: 3 });
        assert_eq!(m.neighbors[0][3], Link::constrained(0));
        assert_eq!(m.neighbors[1][3], Link::constrained(0));
        assert_eq!(m.across(0, 3), Some(FaceSide { tet: 1, face: 3 }));
        // Reversed winding swaps the sides.
        let m = TetMesh::assemble(p, t, &[([0, 2, 1], 0)], 1).unwrap();
        assert_eq!(m.constrained[0].front.tet, 1);
        assert_eq!(m.constrained[0].back.tet, 0);
    }

    #[test]
    fn boundary_triangle_has_one_side() {
        let (p, t) = bipyramid();
        let m = TetMesh::assemble(p, t, &[([0, 1, 3], 0)], 1).unwrap();
        m.validate().unwrap();
        let cf = m.constrained[0];
        assert!(cf.front.exists() != cf.back.exists());
    }

    #[test]
    fn assemble_rejects_unknown_and_duplicate_triangles() {
        let (p, t) = bipyramid();
        assert!(matches!(
            TetMesh::assemble(p.clone(), t.clone(), &[([0, 3, 4], 0)], 1),
            Err(MeshError::TriangleNotInMesh { triangle: 0, .. })
        ));
        assert!(matches!(
            TetMesh::assemble(p, t, &[([0, 1, 2], 0), ([2, 1, 0], 1)], 2),
            Err(MeshError::DuplicateTriangle {
                first: 0,
                second: 1,
                ..
            })
        ));
    }
}
