//! `Tet80`: the tetrahedron of Maria et al. (2017, §3.2), used by the
//! Plücker traversal kernel. 80 bytes: four vertex positions inline plus four
//! 8-byte faces.
//!
//! | paper (`struct Tetrahedron`, `struct Face`) | field |
//! |---|---|
//! | `float3 V[4]` (vertices) | [`Tet80::v`] (slot order of the canonical mesh) |
//! | `Face F[4]`, face `i` has complement vertex `V_i` | [`Tet80::f`] (face `k` opposite slot `k`, as in [`crate::FACE_VERTICES`]) |
//! | `int brdf` (−1: non-occlusive) | [`Tet80Face::occlusion`]: constrained-face index, [`Tet80Face::NON_OCCLUSIVE`] otherwise |
//! | `int tetra` + `int face` packed in 30 + 2 bits | [`Tet80Face::neighbor`] = `tet << 2 \| face` |
//! | `idV[3]`, common to all tets (4 `unsigned char`) | [`crate::FACE_VERTICES`] (a constant, not stored) |
//!
//! Size: the paper counts 80 bytes (`3 × 4 × 4` for the positions + `4 × 8`
//! for the faces), asserted here; its GPU code padded each vertex to a
//! `float4`, giving 96 bytes. We store `[f32; 3]`, so the true size is 80.
//!
//! Unlike the xor layouts, `neighbor` also names the tet across an occlusive
//! (constrained) face, with its face index, so a multi-hit walk continues
//! without the cold table. The hot traversal needs no point array and no
//! vertex ids; to decode losslessly back to [`TetMesh`], the container keeps
//! the point array and the vertex ids as cold *reconstruction* data, counted
//! separately in [`crate::memory`].
//!
//! Limits: the 30-bit tet field holds at most [`TET80_MAX_TETS`] tets (one
//! value is reserved for [`Tet80Face::NO_NEIGHBOR`]).

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use super::{LayoutError, check_reencodes, decoded_mesh, fourth_vertex, validate_input, xor_sum};
use crate::link::{Link, LinkKind};
use crate::mesh::{Attributes, ConstrainedFace, TetMesh};

/// Layout name used in errors and memory reports.
pub const NAME: &str = "tet80";

/// Largest tet count Tet80 can index: tet indices use 30 bits and the all-ones
/// value is reserved for "no neighbour".
pub const TET80_MAX_TETS: usize = (1 << 30) - 1;

/// One face of a [`Tet80`] (8 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Pod, Zeroable)]
pub struct Tet80Face {
    /// Index into the constrained-face table when the face lies on a scene
    /// triangle (a ray crossing it hits), else [`Self::NON_OCCLUSIVE`].
    pub occlusion: u32,
    /// Neighbour across the face: `tet << 2 | face` (its face index), or
    /// [`Self::NO_NEIGHBOR`] on the mesh boundary.
    pub neighbor: u32,
}

impl Tet80Face {
    /// `occlusion` of a face that is not a scene triangle (the paper's −1).
    pub const NON_OCCLUSIVE: u32 = u32::MAX;
    /// `neighbor` of a face on the mesh boundary.
    pub const NO_NEIGHBOR: u32 = u32::MAX;

    /// Packs a neighbour tet (`< TET80_MAX_TETS`) and its face index (0..=3).
    #[inline]
    pub const fn pack(tet: u32, face: u32) -> u32 {
        (tet << 2) | (face & 3)
    }

    /// True when the face lies on a scene triangle.
    #[inline]
    pub const fn is_occlusive(self) -> bool {
        self.occlusion != Self::NON_OCCLUSIVE
    }

    /// The neighbour tet, `None` on the mesh boundary.
    #[inline]
    pub const fn neighbor_tet(self) -> Option<u32> {
        if self.neighbor == Self::NO_NEIGHBOR {
            None
        } else {
            Some(self.neighbor >> 2)
        }
    }

    /// The face index (0..=3) of this face as seen from the neighbour (the
    /// neighbour's entry face). Meaningless on the boundary.
    #[inline]
    pub const fn neighbor_face(self) -> usize {
        (self.neighbor & 3) as usize
    }
}

/// One tet: four positions and four faces (80 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Tet80 {
    /// Vertex positions in slot order, positively oriented.
    pub v: [[f32; 3]; 4],
    /// Face `k` (opposite `v[k]`).
    pub f: [Tet80Face; 4],
}

const _: () = assert!(size_of::<Tet80>() == 80);
const _: () = assert!(size_of::<Tet80Face>() == 8);

impl Tet80 {
    /// Vertex `k` as a [`Vec3`].
    #[inline]
    pub fn vertex(&self, k: usize) -> Vec3 {
        Vec3::from_array(self.v[k & 3])
    }
}

/// A mesh in the Tet80 layout: hot `tets` only; cold table and attributes,
/// plus the reconstruction data (`points`, `vertex_ids`) the traversal never reads.
#[derive(Clone, Debug, PartialEq)]
pub struct Tet80Mesh {
    /// Tet records (hot; positions inline).
    pub tets: Vec<Tet80>,
    /// Constrained-face table (cold).
    pub constrained: Vec<ConstrainedFace>,
    /// Number of scene triangles.
    pub triangle_count: u32,
    /// Optional attributes (cold).
    pub attributes: Attributes,
    /// Vertex positions (cold, reconstruction only).
    pub points: Vec<Vec3>,
    /// Vertex ids of every tet in slot order (cold, reconstruction only).
    pub vertex_ids: Vec<[u32; 4]>,
}

/// Face index within tet `m` of the face it shares with face `face` of a tet
/// whose vertex ids are `ids` (slot of `m`'s vertex not on that face).
fn entry_face(mesh: &TetMesh, m: u32, face_ids: [u32; 3]) -> u32 {
    let mv = mesh.tets[m as usize];
    let apex = fourth_vertex(xor_sum(mv), face_ids);
    mv.iter().position(|&v| v == apex).unwrap_or(0) as u32
}

fn encode_tet(mesh: &TetMesh, t: usize) -> Tet80 {
    let ids = mesh.tets[t];
    let mut f = [Tet80Face {
        occlusion: Tet80Face::NON_OCCLUSIVE,
        neighbor: Tet80Face::NO_NEIGHBOR,
    }; 4];
    for (k, face) in f.iter_mut().enumerate() {
        let face_ids = mesh.face_vertices(t as u32, k);
        match mesh.neighbors[t][k].kind() {
            LinkKind::Boundary => {}
            LinkKind::Tet(m) => face.neighbor = Tet80Face::pack(m, entry_face(mesh, m, face_ids)),
            LinkKind::Constrained(c) => {
                face.occlusion = c;
                if let Some(side) = mesh.constrained[c as usize].other_side(t as u32)
                    && side.exists()
                {
                    face.neighbor = Tet80Face::pack(side.tet, side.face);
                }
            }
        }
    }
    Tet80 {
        v: ids.map(|i| mesh.points[i as usize].to_array()),
        f,
    }
}

/// Fails with [`LayoutError::TooMany`] when `count` tets do not fit the
/// 30-bit neighbour field.
fn check_tet_count(count: usize) -> Result<(), LayoutError> {
    if count > TET80_MAX_TETS {
        return Err(LayoutError::TooMany {
            layout: NAME,
            what: "tets",
            count,
            limit: TET80_MAX_TETS,
        });
    }
    Ok(())
}

impl Tet80Mesh {
    /// Encodes a valid mesh (validated first). Fails with
    /// [`LayoutError::TooMany`] beyond [`TET80_MAX_TETS`] tets.
    pub fn from_mesh(mesh: &TetMesh) -> Result<Self, LayoutError> {
        check_tet_count(mesh.tets.len())?;
        validate_input(NAME, mesh)?;
        Ok(Self::encode(mesh))
    }

    fn encode(mesh: &TetMesh) -> Self {
        Tet80Mesh {
            tets: (0..mesh.tets.len()).map(|t| encode_tet(mesh, t)).collect(),
            constrained: mesh.constrained.clone(),
            triangle_count: mesh.triangle_count,
            attributes: mesh.attributes.clone(),
            points: mesh.points.clone(),
            vertex_ids: mesh.tets.clone(),
        }
    }

    /// Decodes back to the canonical mesh (exactly the input of
    /// `from_mesh`). The result is validated, and every record must equal the
    /// re-encoding of the decoded mesh (inline positions, neighbour face
    /// indices and neighbours across occlusive faces included), else
    /// [`LayoutError::Corrupt`] names the tet.
    pub fn to_mesh(&self) -> Result<TetMesh, LayoutError> {
        if self.vertex_ids.len() != self.tets.len() {
            return Err(LayoutError::LengthMismatch {
                layout: NAME,
                array: "vertex_ids",
                actual: self.vertex_ids.len(),
                expected: self.tets.len(),
            });
        }
        let neighbors = self
            .tets
            .iter()
            .map(|t| {
                t.f.map(|face| {
                    if face.is_occlusive() {
                        Link(face.occlusion | Link::CONSTRAINED_BIT)
                    } else {
                        match face.neighbor_tet() {
                            Some(m) => Link(m),
                            None => Link::BOUNDARY,
                        }
                    }
                })
            })
            .collect();
        let (points, faces, attrs) = (&self.points, &self.constrained, &self.attributes);
        let cold = (&points[..], &faces[..], self.triangle_count, attrs);
        let mesh = decoded_mesh(NAME, (self.vertex_ids.clone(), neighbors), cold)?;
        // Bitwise comparison: -0.0 and NaN payloads must survive too.
        check_reencodes(NAME, self.tets.len(), |t| {
            let again = encode_tet(&mesh, t);
            bytemuck::bytes_of(&again) == bytemuck::bytes_of(&self.tets[t])
        })?;
        Ok(mesh)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tet_count_limit_is_the_30_bit_field() {
        // The largest index, packed with face 3, must differ from NO_NEIGHBOR.
        let last = (TET80_MAX_TETS - 1) as u32;
        assert_ne!(Tet80Face::pack(last, 3), Tet80Face::NO_NEIGHBOR);
        let f = Tet80Face {
            occlusion: Tet80Face::NON_OCCLUSIVE,
            neighbor: Tet80Face::pack(last, 2),
        };
        assert_eq!((f.neighbor_tet(), f.neighbor_face()), (Some(last), 2));
        assert!(check_tet_count(1 << 29).is_ok());
        assert!(check_tet_count(TET80_MAX_TETS).is_ok());
        assert_eq!(
            check_tet_count(TET80_MAX_TETS + 1),
            Err(LayoutError::TooMany {
                layout: "tet80",
                what: "tets",
                count: 1 << 30,
                limit: (1 << 30) - 1,
            })
        );
    }
}
