//! `Tet20` (Aman et al. 2022, §3, Figure 3): the xor-sum and four links sorted by the
//! global index of the vertex opposite them, 20 bytes.
//!
//! | paper | field / helper |
//! |---|---|
//! | `VX^i` | [`Tet20::vx`] |
//! | `N_r^i`, sorted by opposite vertex id | [`Tet20::n`] (entry `r` = rank `r`) |
//! | `order_a` ("sorted order of `idx_exit` among `idx_i`") | [`super::rank_of`] |
//! | GETNEXTTET20 (Algorithm 5) | [`Tet20::neighbor_by_rank`] |
//! | *source tet* | [`LayoutMesh::anchors`] |
//!
//! A walk step (Algorithm 4): the kernel holds the ids `idx_0..2` of the
//! entry face; `idx_3 = fourth_vertex(tets[next].vx, [idx_0, idx_1, idx_2])`;
//! after choosing the exit vertex `e` among the four ids, the next link is
//! `tets[next].neighbor_opposite(e, [idx_0, idx_1, idx_2, idx_3])`.
//!
//! The record keeps only the vertex *set*, so [`LayoutMesh::to_mesh`] returns
//! the mesh in canonical slot order ([`super::canonical_slot_order`]).

use super::{LayoutError, LayoutMesh, LayoutRecord, links_by_rank, rank_of, xor_sum};
use crate::link::Link;
use bytemuck::{Pod, Zeroable};

/// Layout name used in errors and memory reports.
pub const NAME: &str = "tet20";

/// One tet: `VX` and the four links in rank order (20 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Pod, Zeroable)]
pub struct Tet20 {
    /// Xor-sum of the four vertex ids.
    pub vx: u32,
    /// `n[r]`: link across the face opposite the vertex of rank `r`
    /// (the `r`-th smallest id).
    pub n: [Link; 4],
}

const _: () = assert!(size_of::<Tet20>() == 20);

impl Tet20 {
    /// GETNEXTTET20: the link across the face opposite the vertex of rank
    /// `rank` (0..=3; masked, never panics).
    #[inline]
    pub fn neighbor_by_rank(&self, rank: usize) -> Link {
        self.n[rank & 3]
    }

    /// The link across the face opposite vertex id `v`, given the tet's four
    /// (distinct) vertex ids in any order; `v` must be one of them.
    #[inline]
    pub fn neighbor_opposite(&self, v: u32, ids: [u32; 4]) -> Link {
        self.neighbor_by_rank(rank_of(v, ids))
    }

    /// Encodes one tet from its ids and links in slot order.
    #[inline]
    pub fn encode(ids: [u32; 4], links: [Link; 4]) -> Tet20 {
        Tet20 {
            vx: xor_sum(ids),
            n: links_by_rank(ids, links),
        }
    }
}

impl LayoutRecord for Tet20 {
    const NAME: &'static str = NAME;
    const ID_LESS: bool = true;
    const CHECK_REENCODE: bool = false;

    fn encode_record(ids: [u32; 4], links: [Link; 4]) -> Self {
        Tet20::encode(ids, links)
    }

    fn decode_all(mesh: &LayoutMesh<Self>) -> Result<(Vec<[u32; 4]>, Vec<[Link; 4]>), LayoutError> {
        mesh.decode_walk(|t| t.vx, |t, _, _| t.n)
    }
}

/// A mesh in the Tet20 layout: hot `tets` + `points`; cold table, attributes
/// and anchors, in canonical slot order.
pub type Tet20Mesh = LayoutMesh<Tet20>;
