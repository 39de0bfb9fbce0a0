//! `Tet20` (seed 000 §3, Figure 3): the xor-sum and four links sorted by the
//! global index of the vertex opposite them, 20 bytes.
//!
//! | paper | field / helper |
//! |---|---|
//! | `VX^i` | [`Tet20::vx`] |
//! | `N_r^i`, sorted by opposite vertex id | [`Tet20::n`] (entry `r` = rank `r`) |
//! | `order_a` ("sorted order of `idx_exit` among `idx_i`") | [`super::rank_of`] |
//! | GETNEXTTET20 (Algorithm 5) | [`Tet20::neighbor_by_rank`] |
//! | *source tet* | [`Tet20Mesh::anchors`] |
//!
//! A walk step (Algorithm 4): the kernel holds the ids `idx_0..2` of the
//! entry face; `idx_3 = fourth_vertex(tets[next].vx, [idx_0, idx_1, idx_2])`;
//! after choosing the exit vertex `e` among the four ids, the next link is
//! `tets[next].neighbor_opposite(e, [idx_0, idx_1, idx_2, idx_3])`.
//!
//! The record keeps only the vertex *set*, so [`Tet20Mesh::to_mesh`] returns
//! the mesh in canonical slot order ([`super::canonical_slot_order`]).

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use super::{
    Anchor, LayoutError, anchors_of, canonical_slot_order, decode_by_walk, links_by_rank,
    links_by_slot, rank_of, validate_input, validate_output, xor_sum,
};
use crate::link::Link;
use crate::mesh::{Attributes, ConstrainedFace, TetMesh};

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

/// A mesh in the Tet20 layout: hot `tets` + `points`; cold table, attributes
/// and anchors.
#[derive(Clone, Debug, PartialEq)]
pub struct Tet20Mesh {
    /// Vertex positions (hot).
    pub points: Vec<Vec3>,
    /// Tet records (hot).
    pub tets: Vec<Tet20>,
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

impl Tet20Mesh {
    /// Encodes a valid mesh (validated first).
    pub fn from_mesh(mesh: &TetMesh) -> Result<Self, LayoutError> {
        validate_input(NAME, mesh)?;
        let canon = canonical_slot_order(mesh);
        Ok(Tet20Mesh {
            tets: canon
                .tets
                .iter()
                .zip(&canon.neighbors)
                .map(|(&v, &n)| Tet20::encode(v, n))
                .collect(),
            anchors: anchors_of(&canon),
            points: canon.points,
            constrained: canon.constrained,
            triangle_count: canon.triangle_count,
            attributes: canon.attributes,
        })
    }

    /// Decodes the whole mesh by walking out from the anchors, returning it in
    /// canonical slot order (equal to `canonical_slot_order(input)`). The
    /// result is validated; inconsistent data gives [`LayoutError::Corrupt`].
    pub fn to_mesh(&self) -> Result<TetMesh, LayoutError> {
        let vx: Vec<u32> = self.tets.iter().map(|t| t.vx).collect();
        let (ids, _) = decode_by_walk(
            NAME,
            &vx,
            &self.points,
            &self.constrained,
            &self.anchors,
            |t, _, _| self.tets[t].n,
        )?;
        let neighbors = ids
            .iter()
            .zip(&self.tets)
            .map(|(&v, t)| links_by_slot(v, t.n))
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
        Ok(mesh)
    }

    /// Exact memory of this container (see [`crate::memory`]).
    pub fn memory(&self) -> crate::memory::LayoutMemory {
        crate::memory::LayoutMemory {
            name: NAME,
            tets: self.tets.len() * size_of::<Tet20>(),
            points: self.points.len() * size_of::<Vec3>(),
            constrained: self.constrained.len() * size_of::<ConstrainedFace>(),
            attributes: self.attributes.bytes(),
            anchors: self.anchors.len() * size_of::<Anchor>(),
            reconstruction: 0,
        }
    }
}
