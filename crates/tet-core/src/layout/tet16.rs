//! `Tet16` (seed 000 §3, Figure 4): the xor-sum and three xor-differences of
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
//! | *source tet* | [`Tet16Mesh::anchors`] |
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
//! * for the first tet of a walk, take an [`Anchor`]: its `neighbors` hold
//!   every link, e.g. the one at the slot whose vertex has rank 3.
//!
//! The record keeps only the vertex *set*, so [`Tet16Mesh::to_mesh`] returns
//! the mesh in canonical slot order ([`super::canonical_slot_order`]).

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use super::{
    Anchor, LayoutError, anchors_of, canonical_slot_order, decode_by_walk, links_by_rank,
    links_by_slot, validate_input, validate_output, xor_sum,
};
use crate::link::Link;
use crate::mesh::{Attributes, ConstrainedFace, TetMesh};

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

/// A mesh in the Tet16 layout: hot `tets` + `points`; cold table, attributes
/// and anchors.
#[derive(Clone, Debug, PartialEq)]
pub struct Tet16Mesh {
    /// Vertex positions (hot).
    pub points: Vec<Vec3>,
    /// Tet records (hot).
    pub tets: Vec<Tet16>,
    /// Constrained-face table (cold), `face` fields in canonical slot order.
    pub constrained: Vec<ConstrainedFace>,
    /// One fully decoded tet per connected component (cold): the start of
    /// point location and of whole-mesh decoding.
    pub anchors: Vec<Anchor>,
    /// Number of scene triangles.
    pub triangle_count: u32,
    /// Optional attributes (cold).
    pub attributes: Attributes,
}

impl Tet16Mesh {
    /// Encodes a valid mesh (validated first).
    pub fn from_mesh(mesh: &TetMesh) -> Result<Self, LayoutError> {
        validate_input(NAME, mesh)?;
        let canon = canonical_slot_order(mesh);
        Ok(Tet16Mesh {
            tets: canon
                .tets
                .iter()
                .zip(&canon.neighbors)
                .map(|(&v, &n)| Tet16::encode(v, n))
                .collect(),
            anchors: anchors_of(&canon),
            points: canon.points,
            constrained: canon.constrained,
            triangle_count: canon.triangle_count,
            attributes: canon.attributes,
        })
    }

    /// Decodes the whole mesh by walking out from the anchors (each tet's
    /// links decoded from the link it was entered through), returning it in
    /// canonical slot order (equal to `canonical_slot_order(input)`). The
    /// result is validated; inconsistent data gives [`LayoutError::Corrupt`].
    pub fn to_mesh(&self) -> Result<TetMesh, LayoutError> {
        let vx: Vec<u32> = self.tets.iter().map(|t| t.vx).collect();
        let (ids, links) = decode_by_walk(
            NAME,
            &vx,
            &self.points,
            &self.constrained,
            &self.anchors,
            |t, entry, rank| self.tets[t].neighbors(entry, rank),
        )?;
        let neighbors = ids
            .iter()
            .zip(&links)
            .map(|(&v, &n)| links_by_slot(v, n))
            .collect();
        let mesh = TetMesh {
            points: self.points.clone(),
            tets: ids,
            neighbors,
            constrained: self.constrained.clone(),
            triangle_count: self.triangle_count,
            attributes: self.attributes.clone(),
        };
        validate_output(NAME, &mesh)?;
        // The links were decoded from one entry per tet; re-encoding catches
        // records whose other xor-differences are inconsistent.
        let bad = (0..self.tets.len())
            .find(|&t| Tet16::encode(mesh.tets[t], mesh.neighbors[t]) != self.tets[t]);
        if let Some(t) = bad {
            return Err(LayoutError::Corrupt {
                layout: NAME,
                element: "tet",
                index: t,
                detail: "record does not re-encode from the decoded mesh".into(),
            });
        }
        Ok(mesh)
    }

    /// Exact memory of this container (see [`crate::memory`]).
    pub fn memory(&self) -> crate::memory::LayoutMemory {
        crate::memory::LayoutMemory {
            name: NAME,
            tets: self.tets.len() * size_of::<Tet16>(),
            points: self.points.len() * size_of::<Vec3>(),
            constrained: self.constrained.len() * size_of::<ConstrainedFace>(),
            attributes: self.attributes.bytes(),
            anchors: self.anchors.len() * size_of::<Anchor>(),
            reconstruction: 0,
        }
    }
}
