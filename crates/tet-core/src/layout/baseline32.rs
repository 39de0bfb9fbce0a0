//! `Baseline32`: the 32-byte tet of Lagae & Dutré (2008; Aman et al. 2022, §3, Figure 1),
//! used by the scalar-triple-product (ScTP) traversal kernel.
//!
//! | paper | field |
//! |---|---|
//! | `V_0^i .. V_3^i` | [`Baseline32::v`] (slot order of the canonical mesh) |
//! | `N_0^i .. N_3^i` (`N_j` across vertex `V_j`) | [`Baseline32::n`] |
//!
//! The slot order of the input mesh is kept, so the round trip is exact.

use super::{LayoutError, LayoutMesh, LayoutRecord};
use crate::link::Link;
use bytemuck::{Pod, Zeroable};

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
        super::slot_among([self.v[0], self.v[1], self.v[2]], v)
    }

    /// Link across the face opposite vertex id `v` (which must be one of `v`).
    #[inline]
    pub fn neighbor_opposite(&self, v: u32) -> Link {
        self.n[self.slot_of(v)]
    }
}

impl LayoutRecord for Baseline32 {
    const NAME: &'static str = NAME;
    const ID_LESS: bool = false;
    const CHECK_REENCODE: bool = false;

    fn encode_record(v: [u32; 4], n: [Link; 4]) -> Self {
        Baseline32 { v, n }
    }

    fn decode_all(mesh: &LayoutMesh<Self>) -> Result<(Vec<[u32; 4]>, Vec<[Link; 4]>), LayoutError> {
        let tets = &mesh.tets;
        Ok((
            tets.iter().map(|t| t.v).collect(),
            tets.iter().map(|t| t.n).collect(),
        ))
    }
}

/// A mesh in the Baseline32 layout: hot `tets` + `points`, cold table and
/// attributes (no anchors). The slot order is kept, so the round trip is exact.
pub type Baseline32Mesh = LayoutMesh<Baseline32>;
