//! `Tet32` (Aman et al. 2022, §3, Figure 2): three vertex ids, the xor-sum and four
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

use super::{LayoutError, LayoutMesh, LayoutRecord, xor_sum};
use crate::link::Link;
use bytemuck::{Pod, Zeroable};

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
        super::slot_among(self.v, v)
    }

    /// GETNEXTTET32: the link across the face opposite vertex id `v` (which
    /// must be a vertex of this tet).
    #[inline]
    pub fn neighbor_opposite(&self, v: u32) -> Link {
        self.n[self.slot_of(v)]
    }
}

impl LayoutRecord for Tet32 {
    const NAME: &'static str = NAME;
    const ID_LESS: bool = false;
    const CHECK_REENCODE: bool = false;

    fn encode_record(v: [u32; 4], n: [Link; 4]) -> Self {
        Tet32 {
            v: [v[0], v[1], v[2]],
            vx: xor_sum(v),
            n,
        }
    }

    fn decode_all(mesh: &LayoutMesh<Self>) -> Result<(Vec<[u32; 4]>, Vec<[Link; 4]>), LayoutError> {
        let tets = &mesh.tets;
        Ok((
            tets.iter().map(Tet32::vertices).collect(),
            tets.iter().map(|t| t.n).collect(),
        ))
    }
}

/// A mesh in the Tet32 layout: hot `tets` + `points`, cold table and
/// attributes (no anchors). The slot order is kept, so the round trip is exact.
pub type Tet32Mesh = LayoutMesh<Tet32>;
