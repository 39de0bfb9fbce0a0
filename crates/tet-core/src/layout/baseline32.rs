//! `Baseline32`: the 32-byte tet of Lagae & Dutré (seed 000 §3, Figure 1),
//! used by the scalar-triple-product (ScTP) traversal kernel.
//!
//! | paper | field |
//! |---|---|
//! | `V_0^i .. V_3^i` | [`Baseline32::v`] (slot order of the canonical mesh) |
//! | `N_0^i .. N_3^i` (`N_j` across vertex `V_j`) | [`Baseline32::n`] |
//!
//! The slot order of the input mesh is kept, so the round trip is exact.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use super::{LayoutError, validate_input, validate_output};
use crate::link::Link;
use crate::mesh::{Attributes, ConstrainedFace, TetMesh};

/// Layout name used in errors and memory reports.
pub const NAME: &str = "baseline32";

/// One tet: four vertex ids and four links (32 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Pod, Zeroable)]
pub struct Baseline32 {
    /// Vertex ids `V_0..V_3`, positively oriented.
    pub v: [u32; 4],
    /// Link `N_k` across the face opposite `v[k]`.
    pub n: [Link; 4],
}

const _: () = assert!(size_of::<Baseline32>() == 32);

impl Baseline32 {
    /// Slot (0..=3) of vertex id `v` in this tet; 3 when `v` is not among
    /// `v[0..3]` (Algorithm 3's search, branch-light).
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

    /// Link across the face opposite vertex id `v` (which must be one of `v`).
    #[inline]
    pub fn neighbor_opposite(&self, v: u32) -> Link {
        self.n[self.slot_of(v)]
    }
}

/// A mesh in the Baseline32 layout: hot `tets` + `points`, cold table and attributes.
#[derive(Clone, Debug, PartialEq)]
pub struct Baseline32Mesh {
    /// Vertex positions (hot).
    pub points: Vec<Vec3>,
    /// Tet records (hot).
    pub tets: Vec<Baseline32>,
    /// Constrained-face table (cold).
    pub constrained: Vec<ConstrainedFace>,
    /// Number of scene triangles.
    pub triangle_count: u32,
    /// Optional attributes (cold).
    pub attributes: Attributes,
}

impl Baseline32Mesh {
    /// Encodes a valid mesh (validated first).
    pub fn from_mesh(mesh: &TetMesh) -> Result<Self, LayoutError> {
        validate_input(NAME, mesh)?;
        Ok(Self::encode(mesh))
    }

    fn encode(mesh: &TetMesh) -> Self {
        Baseline32Mesh {
            points: mesh.points.clone(),
            tets: mesh
                .tets
                .iter()
                .zip(&mesh.neighbors)
                .map(|(&v, &n)| Baseline32 { v, n })
                .collect(),
            constrained: mesh.constrained.clone(),
            triangle_count: mesh.triangle_count,
            attributes: mesh.attributes.clone(),
        }
    }

    /// Decodes back to the canonical mesh (exactly the input of `from_mesh`).
    /// The result is validated.
    pub fn to_mesh(&self) -> Result<TetMesh, LayoutError> {
        let mesh = TetMesh {
            points: self.points.clone(),
            tets: self.tets.iter().map(|t| t.v).collect(),
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
            tets: self.tets.len() * size_of::<Baseline32>(),
            points: self.points.len() * size_of::<Vec3>(),
            constrained: self.constrained.len() * size_of::<ConstrainedFace>(),
            attributes: self.attributes.bytes(),
            anchors: 0,
            reconstruction: 0,
        }
    }
}
