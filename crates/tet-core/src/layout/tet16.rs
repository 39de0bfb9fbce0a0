//! `Tet16` (Aman et al. 2022, §3, Figure 4): the xor-sum and three xor-differences of
//! the rank-ordered links, 16 bytes.
//!
//! | paper | field / helper |
//! |---|---|
//! | `VX^i` | [`Tet16::vx`] |
//! | `NX_k^i = N_k ⊕ N_3` (`k = 0..2`, ranks as in Tet20) | [`Tet16::nx`] |
//! | `order_a` (rank of `idx_3`, the vertex opposite the entry face) | `entry_rank` |
//! | `order_b` (rank of the exit vertex) | `want_rank` |
//! | `prev_tet_idx` | `entry`: the link of the entry face *as seen from this tet* |
//! | GETNEXTTET16 (Algorithm 7) | [`Tet16::neighbor`] |
//! | *source tet* | [`LayoutMesh::anchors`] |
//!
//! Links are xor-ed as raw `u32` words, so the constrained flag and the
//! boundary value survive decoding unchanged. With `NX_3 := 0`,
//! `N_b = N_a ⊕ NX_a ⊕ NX_b` for any two ranks `a`, `b`.
//!
//! The entry link is:
//! * `Link::tet(prev)` after crossing an ordinary face from tet `prev`;
//! * the flagged `Link::constrained(c)` when a secondary ray restarts in the
//!   tet on the other side of constrained face `c` (the tet on either side of
//!   a constrained face stores the same link for it);
//! * for the first tet of a walk, take an [`Anchor`](super::Anchor): its `neighbors` hold
//!   every link, e.g. the one at the slot whose vertex has rank 3.
//!
//! The record keeps only the vertex *set*, so [`LayoutMesh::to_mesh`] returns
//! the mesh in canonical slot order ([`super::canonical_slot_order`]).

use super::{LayoutError, LayoutMesh, LayoutRecord, links_by_rank, xor_sum};
use crate::link::Link;
use bytemuck::{Pod, Zeroable};

/// Layout name used in errors and memory reports.
pub const NAME: &str = "tet16";

/// One tet: `VX, NX_0, NX_1, NX_2` (16 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Pod, Zeroable)]
pub struct Tet16 {
    /// Xor-sum of the four vertex ids.
    pub vx: u32,
    /// `nx[k] = N_k ⊕ N_3` (raw link words), links in rank order.
    pub nx: [u32; 3],
}

const _: () = assert!(size_of::<Tet16>() == 16);

impl Tet16 {
    /// `[NX_0, NX_1, NX_2, 0]`: the xor-differences with `NX_3 = 0`, so every
    /// rank indexes without a branch.
    #[inline]
    pub fn nx4(&self) -> [u32; 4] {
        [self.nx[0], self.nx[1], self.nx[2], 0]
    }

    /// GETNEXTTET16: the link at rank `want_rank`, given the link `entry`
    /// at rank `entry_rank` (both 0..=3, masked). Two xors, no branch.
    #[inline]
    pub fn neighbor(&self, entry: Link, entry_rank: usize, want_rank: usize) -> Link {
        let nx = self.nx4();
        Link(entry.0 ^ nx[entry_rank & 3] ^ nx[want_rank & 3])
    }

    /// All four links in rank order, given one known link and its rank.
    #[inline]
    pub fn neighbors(&self, entry: Link, entry_rank: usize) -> [Link; 4] {
        let nx = self.nx4();
        let n3 = entry.0 ^ nx[entry_rank & 3];
        [
            Link(n3 ^ nx[0]),
            Link(n3 ^ nx[1]),
            Link(n3 ^ nx[2]),
            Link(n3),
        ]
    }

    /// Encodes one tet from its ids and links in slot order.
    #[inline]
    pub fn encode(ids: [u32; 4], links: [Link; 4]) -> Tet16 {
        let n = links_by_rank(ids, links);
        Tet16 {
            vx: xor_sum(ids),
            nx: [n[0].0 ^ n[3].0, n[1].0 ^ n[3].0, n[2].0 ^ n[3].0],
        }
    }
}

impl LayoutRecord for Tet16 {
    const NAME: &'static str = NAME;
    const ID_LESS: bool = true;
    // The links are decoded from one entry per tet; re-encoding catches
    // records whose other xor-differences are inconsistent.
    const CHECK_REENCODE: bool = true;

    fn encode_record(ids: [u32; 4], links: [Link; 4]) -> Self {
        Tet16::encode(ids, links)
    }

    fn decode_all(mesh: &LayoutMesh<Self>) -> Result<(Vec<[u32; 4]>, Vec<[Link; 4]>), LayoutError> {
        mesh.decode_walk(|t| t.vx, |t, entry, rank| t.neighbors(entry, rank))
    }
}

/// A mesh in the Tet16 layout: hot `tets` + `points`; cold table, attributes
/// and anchors, in canonical slot order.
pub type Tet16Mesh = LayoutMesh<Tet16>;
