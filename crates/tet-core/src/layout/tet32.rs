//! `Tet32` (seed 000 §3, Figure 2): three vertex ids, the xor-sum and four
//! links, 32 bytes.
//!
//! | paper | field / helper |
//! |---|---|
//! | `V_0^i, V_1^i, V_2^i` | [`Tet32::v`] |
//! | `VX^i = V_0 ⊕ V_1 ⊕ V_2 ⊕ V_3` | [`Tet32::vx`] |
//! | `V_3^i = V_0 ⊕ V_1 ⊕ V_2 ⊕ VX^i` | [`Tet32::v3`] |
//! | `N_0^i .. N_3^i` (`N_j` across `V_j`) | [`Tet32::n`] |
//! | GETNEXTTET32 (Algorithm 3) | [`Tet32::neighbor_opposite`] |
//!
//! In the walk the kernel never needs `v`: it carries the three ids of the
//! entry face and gets the fourth with [`super::fourth_vertex`] from `vx`;
//! `v` serves Algorithm 3's search for the exit vertex's slot. The slot order
//! of the input mesh is kept, so the round trip is exact.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use super::{LayoutError, validate_input, validate_output, xor_sum};
use crate::link::Link;
use crate::mesh::{Attributes, ConstrainedFace, TetMesh};

/// Layout name used in errors and memory reports.
pub const NAME: &str = "tet32";

/// One tet: `V_0, V_1, V_2, VX, N_0..N_3` (32 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Pod, Zeroable)]
pub struct Tet32 {
    /// Vertex ids of slots 0, 1, 2.
    pub v: [u32; 3],
    /// Xor-sum of all four vertex ids.
    pub vx: u32,
    /// Link `N_k` across the face opposite slot `k`.
    pub n: [Link; 4],
}

const _: () = assert!(size_of::<Tet32>() == 32);

impl Tet32 {
    /// Vertex id of slot 3: `V_0 ⊕ V_1 ⊕ V_2 ⊕ VX`.
    #[inline]
    pub fn v3(&self) -> u32 {
        super::fourth_vertex(self.vx, self.v)
    }

    /// All four vertex ids in slot order.
    #[inline]
    pub fn vertices(&self) -> [u32; 4] {
        [self.v[0], self.v[1], self.v[2], self.v3()]
    }

    /// Slot (0..=3) of vertex id `v`: the `i < 3` with `V_i = v`, else 3
    /// (Algorithm 3: vertex ids and links share slots).
    #[inline]
    pub fn slot_of(&self, v: u32) -> usize {
        let mut s = 3;
        for i in (0..3).rev() {
            if self.v[i] == v {
                s = i;
            }
        }
        s
    }

    /// GETNEXTTET32: the link across the face opposite vertex id `v` (which
    /// must be a vertex of this tet).
    #[inline]
    pub fn neighbor_opposite(&self, v: u32) -> Link {
        self.n[self.slot_of(v)]
    }
}

/// A mesh in the Tet32 layout: hot `tets` + `points`, cold table and attributes.
#[derive(Clone, Debug, PartialEq)]
pub struct Tet32Mesh {
    /// Vertex positions (hot).
    pub points: Vec<Vec3>,
    /// Tet records (hot).
    pub tets: Vec<Tet32>,
    /// Constrained-face table (cold).
    pub constrained: Vec<ConstrainedFace>,
    /// Number of scene triangles.
    pub triangle_count: u32,
    /// Optional attributes (cold).
    pub attributes: Attributes,
}

impl Tet32Mesh {
    /// Encodes a valid mesh (validated first).
    pub fn from_mesh(mesh: &TetMesh) -> Result<Self, LayoutError> {
        validate_input(NAME, mesh)?;
        Ok(Tet32Mesh {
            points: mesh.points.clone(),
            tets: mesh
                .tets
                .iter()
                .zip(&mesh.neighbors)
                .map(|(&v, &n)| Tet32 {
                    v: [v[0], v[1], v[2]],
                    vx: xor_sum(v),
                    n,
                })
                .collect(),
            constrained: mesh.constrained.clone(),
            triangle_count: mesh.triangle_count,
            attributes: mesh.attributes.clone(),
        })
    }

    /// Decodes back to the canonical mesh (exactly the input of `from_mesh`).
    /// The result is validated.
    pub fn to_mesh(&self) -> Result<TetMesh, LayoutError> {
        let mesh = TetMesh {
            points: self.points.clone(),
            tets: self.tets.iter().map(Tet32::vertices).collect(),
            neighbors: self.tets.iter().map(|t| t.n).collect(),
            constrained: self.constrained.clone(),
            triangle_count: self.triangle_count,
            attributes: self.attributes.clone(),
        };
        validate_output(NAME, &mesh)?;
        Ok(mesh)
    }

    /// Exact memory of this container (see [`crate::memory`]).
    pub fn memory(&self) -> crate::memory::LayoutMemory {
        crate::memory::LayoutMemory {
            name: NAME,
            tets: self.tets.len() * size_of::<Tet32>(),
            points: self.points.len() * size_of::<Vec3>(),
            constrained: self.constrained.len() * size_of::<ConstrainedFace>(),
            attributes: self.attributes.bytes(),
            anchors: 0,
            reconstruction: 0,
        }
    }
}
