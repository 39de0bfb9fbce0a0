//! Compact tet layouts: the hot arrays the traversal kernels walk.
//!
//! Every layout is a `#[repr(C)]`, [`bytemuck::Pod`] record with a
//! compile-time size assertion, plus a container that owns the hot arrays
//! (tets, points) and the cold data (constrained-face table, attributes,
//! anchors). Every container converts losslessly from and to the canonical
//! [`TetMesh`]:
//!
//! | layout | record | bytes | paper | slot order kept |
//! |---|---|---|---|---|
//! | [`baseline32`] | [`Baseline32`] | 32 | Lagae & Dutré 2008; Aman et al. (2022) Fig. 1 | yes |
//! | [`tet32`] | [`Tet32`] | 32 | Aman et al. (2022) §3, Fig. 2 | yes |
//! | [`tet20`] | [`Tet20`] | 20 | Aman et al. (2022) §3, Fig. 3 | canonical (see below) |
//! | [`tet16`] | [`Tet16`] | 16 | Aman et al. (2022) §3, Fig. 4 | canonical (see below) |
//! | [`tet80`] | [`Tet80`] | 80 | Maria et al. (2017) §3.2 | yes |
//!
//! ## Notation of Aman et al. (2022) → code
//!
//! | paper | code |
//! |---|---|
//! | `V_j^i` (vertex `j` of tet `i`) | `TetMesh::tets[i][j]` |
//! | `N_j^i` (neighbour across vertex `j`) | `TetMesh::neighbors[i][j]` (a [`Link`]) |
//! | `VX^i = V_0 ⊕ V_1 ⊕ V_2 ⊕ V_3` (xor-sum) | [`xor_sum`], field `vx` of every xor layout |
//! | `idx_3 = idx_0 ⊕ idx_1 ⊕ idx_2 ⊕ VX^next` | [`fourth_vertex`] |
//! | "sorted order of `idx` among `idx_i`" (`order_a`, `order_b`) | [`rank_of`] |
//! | `NX_k^i = N_k ⊕ N_3` over the sorted order | field `nx` of [`Tet16`] |
//! | GETNEXTTET32 (Alg. 3) | [`Tet32::neighbor_opposite`] |
//! | GETNEXTTET20 (Alg. 5) | [`Tet20::neighbor_by_rank`] |
//! | GETNEXTTET16 (Alg. 7) | [`Tet16::neighbor`] |
//! | *source tet* (§3, §4.2) | [`Anchor`] (one per connected component) |
//!
//! ## Sorted ("rank") order
//!
//! Tet20 and Tet16 drop the vertex ids, so the neighbour links are stored in
//! the order of the **global index of the vertex opposite them**, ascending:
//! entry `r` is the link across the face opposite the vertex of rank `r`
//! among the tet's four vertex ids. A kernel that knows the four ids (three
//! carried from the previous tet plus [`fourth_vertex`]) finds the rank with
//! [`rank_of`].
//!
//! ## Canonical slot order
//!
//! A Tet20/Tet16 record stores only the *set* of its vertex ids (through the
//! xor-sum), so the slot order of the input mesh cannot be recovered. Their
//! `to_mesh` returns the mesh in **canonical slot order**
//! ([`canonical_slot_order`]): the four ids ascending, with the last two
//! swapped when that is needed for positive orientation. Since a permutation
//! keeps a positive tet positive exactly when it is even, the encoder picks the
//! swap from the permutation parity (no geometry); the decoder, which has only
//! the id set, picks it with the exact [`orient3d`](crate::predicates::orient3d)
//! predicate. Both agree on every valid mesh. Neighbour links and the
//! `face` fields of the constrained-face table are permuted along, so the
//! result is the same mesh up to that relabelling of slots.
//!
//! ## Anchors (cold)
//!
//! Tet20/Tet16 walks need the vertex ids of the tet they start in, and a
//! Tet16 decode also needs one known link of it. The paper keeps a *source
//! tet* "with complete index information" from which point location (§4.2)
//! and all walks start. Here the cold anchor table holds one fully decoded
//! tet ([`Anchor`]) per connected component of the mesh (components joined
//! through shared faces *and* through two-sided constrained faces, i.e. the
//! graph every walk and every secondary-ray restart can follow), so that
//! point location can start anywhere and the whole mesh can be decoded by a
//! breadth-first walk. Meshes from a mesher normally have one component, hence
//! one 36-byte anchor.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use thiserror::Error;

use crate::error::MeshError;
use crate::link::{Link, LinkKind};
use crate::mesh::{Attributes, ConstrainedFace, TetMesh};
use crate::predicates::orient3d_f32;

pub mod baseline32;
pub mod tet16;
pub mod tet20;
pub mod tet32;
pub mod tet80;

pub use baseline32::{Baseline32, Baseline32Mesh};
pub use tet16::{Tet16, Tet16Mesh};
pub use tet20::{Tet20, Tet20Mesh};
pub use tet32::{Tet32, Tet32Mesh};
pub use tet80::{Tet80, Tet80Face, Tet80Mesh};

/// A mesh a layout cannot represent, or layout data that does not decode to a
/// valid mesh. Each variant names the layout and the offending element.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum LayoutError {
    /// The input mesh violates an invariant of [`TetMesh`].
    #[error("{layout}: input mesh is invalid: {source}")]
    InvalidMesh {
        /// Layout name.
        layout: &'static str,
        /// The violated invariant.
        source: MeshError,
    },
    /// More elements than the layout's fields can index.
    #[error("{layout}: {what}: {count} exceeds the layout's limit of {limit}")]
    TooMany {
        /// Layout name.
        layout: &'static str,
        /// What was counted ("tets", "points", ...).
        what: &'static str,
        /// How many there are.
        count: usize,
        /// The largest representable count.
        limit: usize,
    },
    /// Two arrays of a container disagree in length.
    #[error("{layout}: {array} has {actual} entries, expected {expected}")]
    LengthMismatch {
        /// Layout name.
        layout: &'static str,
        /// Name of the array.
        array: &'static str,
        /// Length found.
        actual: usize,
        /// Length expected.
        expected: usize,
    },
    /// The layout data is inconsistent (e.g. a tet no anchor reaches, an xor
    /// that decodes to a vertex outside the point array).
    #[error("{layout}: {element} {index}: {detail}")]
    Corrupt {
        /// Layout name.
        layout: &'static str,
        /// Kind of element ("tet", "anchor", "constrained face").
        element: &'static str,
        /// Its index.
        index: usize,
        /// What is wrong.
        detail: String,
    },
    /// The layout decoded to a mesh that fails [`TetMesh::validate`].
    #[error("{layout}: decoded mesh is invalid: {source}")]
    DecodedInvalid {
        /// Layout name.
        layout: &'static str,
        /// The violated invariant.
        source: MeshError,
    },
}

/// Validates `mesh` and maps the error to [`LayoutError::InvalidMesh`].
pub(crate) fn validate_input(layout: &'static str, mesh: &TetMesh) -> Result<(), LayoutError> {
    mesh.validate()
        .map_err(|source| LayoutError::InvalidMesh { layout, source })
}

/// Validates a decoded mesh and maps the error to [`LayoutError::DecodedInvalid`].
pub(crate) fn validate_output(layout: &'static str, mesh: &TetMesh) -> Result<(), LayoutError> {
    mesh.validate()
        .map_err(|source| LayoutError::DecodedInvalid { layout, source })
}

/// The cold parts every container keeps beside its records: points,
/// constrained-face table, triangle count, attributes.
pub(crate) type Cold<'a> = (&'a [Vec3], &'a [ConstrainedFace], u32, &'a Attributes);

/// Builds the decoded canonical mesh from per-tet ids and links (slot order)
/// and the container's cold parts, and validates it
/// ([`LayoutError::DecodedInvalid`] on failure). Shared by every `to_mesh`.
pub(crate) fn decoded_mesh(
    layout: &'static str,
    (tets, neighbors): Decoded,
    (points, constrained, triangle_count, attributes): Cold<'_>,
) -> Result<TetMesh, LayoutError> {
    let mesh = TetMesh {
        points: points.to_vec(),
        tets,
        neighbors,
        constrained: constrained.to_vec(),
        triangle_count,
        attributes: attributes.clone(),
    };
    validate_output(layout, &mesh)?;
    Ok(mesh)
}

/// Algorithm 3's branch-light search: the slot `i < 3` with `ids[i] == v`
/// (the first one), else 3. Shared by the layouts that keep the ids of
/// slots 0..2 ([`Baseline32`], [`Tet32`]).
#[inline]
pub(crate) fn slot_among(ids: [u32; 3], v: u32) -> usize {
    let mut s = 3;
    for i in (0..3).rev() {
        if ids[i] == v {
            s = i;
        }
    }
    s
}

/// Fails with [`LayoutError::Corrupt`] naming the first tet `t < count` whose
/// stored record differs from its re-encoding (`same(t)` is false).
pub(crate) fn check_reencodes(
    layout: &'static str,
    count: usize,
    same: impl Fn(usize) -> bool,
) -> Result<(), LayoutError> {
    match (0..count).find(|&t| !same(t)) {
        Some(t) => Err(LayoutError::Corrupt {
            layout,
            element: "tet",
            index: t,
            detail: "record does not re-encode from the decoded mesh".into(),
        }),
        None => Ok(()),
    }
}

// ---------------------------------------------------------------------------
// Shared container of the Baseline32 / Tet32 / Tet20 / Tet16 layouts

/// A per-tet record of one of the index-based layouts ([`Baseline32`],
/// [`Tet32`], [`Tet20`], [`Tet16`]): what [`LayoutMesh`] needs to encode and
/// decode a whole mesh, so the four containers share one implementation.
pub trait LayoutRecord: Pod + PartialEq + std::fmt::Debug {
    /// Layout name used in errors and memory reports.
    const NAME: &'static str;
    /// Whether the record drops the vertex ids (Tet20, Tet16): the mesh is
    /// then stored in [canonical slot order](canonical_slot_order) with one
    /// [`Anchor`] per component and decoded by walking; otherwise the slot
    /// order of the input is kept and the anchor table stays empty.
    const ID_LESS: bool;
    /// Whether `to_mesh` also checks that every record re-encodes from the
    /// decoded mesh (Tet16, whose decode reads one link difference per tet).
    const CHECK_REENCODE: bool;

    /// Encodes one tet from its vertex ids and links in slot order (for an
    /// id-less record, the canonical slot order).
    fn encode_record(ids: [u32; 4], links: [Link; 4]) -> Self;

    /// Decodes every tet of `mesh`: vertex ids and links in slot order.
    #[allow(clippy::type_complexity)]
    fn decode_all(mesh: &LayoutMesh<Self>) -> Result<(Vec<[u32; 4]>, Vec<[Link; 4]>), LayoutError>;
}

/// A mesh in one of the index-based layouts: hot `tets` + `points`; cold
/// constrained-face table, attributes and (id-less layouts only) anchors.
/// Used through the aliases [`Baseline32Mesh`], [`Tet32Mesh`], [`Tet20Mesh`]
/// and [`Tet16Mesh`].
#[derive(Clone, Debug, PartialEq)]
pub struct LayoutMesh<R> {
    /// Vertex positions (hot).
    pub points: Vec<Vec3>,
    /// Tet records (hot).
    pub tets: Vec<R>,
    /// Constrained-face table (cold); for id-less layouts the `face` fields
    /// are in canonical slot order.
    pub constrained: Vec<ConstrainedFace>,
    /// Id-less layouts (Tet20, Tet16): one fully decoded tet per connected
    /// component (cold), the start of point location and of whole-mesh
    /// decoding. Empty for layouts that keep the vertex ids.
    pub anchors: Vec<Anchor>,
    /// Number of scene triangles.
    pub triangle_count: u32,
    /// Optional attributes (cold).
    pub attributes: Attributes,
}

impl<R: LayoutRecord> LayoutMesh<R> {
    /// Encodes a valid mesh (validated first). Id-less layouts store it in
    /// canonical slot order and build the anchor table.
    pub fn from_mesh(mesh: &TetMesh) -> Result<Self, LayoutError> {
        validate_input(R::NAME, mesh)?;
        let canon;
        let (source, anchors) = if R::ID_LESS {
            canon = canonical_slot_order(mesh);
            (&canon, anchors_of(&canon))
        } else {
            (mesh, Vec::new())
        };
        Ok(LayoutMesh {
            points: source.points.clone(),
            tets: source
                .tets
                .iter()
                .zip(&source.neighbors)
                .map(|(&v, &n)| R::encode_record(v, n))
                .collect(),
            constrained: source.constrained.clone(),
            anchors,
            triangle_count: source.triangle_count,
            attributes: source.attributes.clone(),
        })
    }

    /// Decodes back to the canonical mesh: exactly the input of `from_mesh`
    /// for layouts that keep the vertex ids, `canonical_slot_order(input)`
    /// for id-less ones (decoded by walking out from the anchors). The result
    /// is validated; inconsistent data gives [`LayoutError::Corrupt`].
    pub fn to_mesh(&self) -> Result<TetMesh, LayoutError> {
        let cold = (
            &self.points[..],
            &self.constrained[..],
            self.triangle_count,
            &self.attributes,
        );
        let mesh = decoded_mesh(R::NAME, R::decode_all(self)?, cold)?;
        if R::CHECK_REENCODE {
            check_reencodes(R::NAME, self.tets.len(), |t| {
                R::encode_record(mesh.tets[t], mesh.neighbors[t]) == self.tets[t]
            })?;
        }
        Ok(mesh)
    }

    /// Walk decoding of an id-less layout: `vx(r)` is a record's xor-sum and
    /// `links(r, entry, entry_rank)` its rank-ordered links given one known
    /// link (see [`decode_by_walk`]). Returns ids and links in slot order.
    pub(crate) fn decode_walk(
        &self,
        vx: impl Fn(&R) -> u32,
        links: impl Fn(&R, Link, usize) -> [Link; 4],
    ) -> Result<Decoded, LayoutError> {
        let vx: Vec<u32> = self.tets.iter().map(vx).collect();
        let (ids, by_rank) = decode_by_walk(
            R::NAME,
            &vx,
            &self.points,
            &self.constrained,
            &self.anchors,
            |t, entry, rank| links(&self.tets[t], entry, rank),
        )?;
        let neighbors = ids
            .iter()
            .zip(&by_rank)
            .map(|(&v, &n)| links_by_slot(v, n))
            .collect();
        Ok((ids, neighbors))
    }
}

// ---------------------------------------------------------------------------
// Hot-loop decode helpers.
// ---------------------------------------------------------------------------

/// `VX = V0 ⊕ V1 ⊕ V2 ⊕ V3`: the xor-sum of a tet's four vertex ids.
#[inline]
pub const fn xor_sum(v: [u32; 4]) -> u32 {
    v[0] ^ v[1] ^ v[2] ^ v[3]
}

/// The vertex of a tet that is not on `face`: `VX ⊕ a ⊕ b ⊕ c`.
///
/// This is the paper's `idx_3 = idx_0 ⊕ idx_1 ⊕ idx_2 ⊕ VX^next`: after
/// crossing a face, the kernel knows the three shared ids and fetches only
/// the new tet's `vx` to learn its fourth vertex. Works for any `u32` ids
/// (xor is its own inverse), the order of `face` does not matter.
#[inline]
pub const fn fourth_vertex(vx: u32, face: [u32; 3]) -> u32 {
    vx ^ face[0] ^ face[1] ^ face[2]
}

/// Rank of `v` among the four **distinct** ids `ids`: the number of ids
/// smaller than `v` (0..=3 when `v` is one of them).
///
/// This is the paper's "sorted order of `idx` among `idx_i`" (`order_a`,
/// `order_b` of Algorithms 4 and 6), computed branch-free with four
/// comparisons. The order of `ids` does not matter.
#[inline]
pub const fn rank_of(v: u32, ids: [u32; 4]) -> usize {
    (ids[0] < v) as usize + (ids[1] < v) as usize + (ids[2] < v) as usize + (ids[3] < v) as usize
}

/// The four ids in ascending order (a five-comparator sorting network).
#[inline]
pub const fn sort4(mut v: [u32; 4]) -> [u32; 4] {
    const fn cswap(v: &mut [u32; 4], i: usize, j: usize) {
        if v[i] > v[j] {
            let t = v[i];
            v[i] = v[j];
            v[j] = t;
        }
    }
    cswap(&mut v, 0, 1);
    cswap(&mut v, 2, 3);
    cswap(&mut v, 0, 2);
    cswap(&mut v, 1, 3);
    cswap(&mut v, 1, 2);
    v
}

/// The three ids of `sorted` other than the one of rank `rank` (in ascending
/// order): the vertices of the face opposite that vertex.
#[inline]
pub const fn face_without_rank(sorted: [u32; 4], rank: usize) -> [u32; 3] {
    match rank {
        0 => [sorted[1], sorted[2], sorted[3]],
        1 => [sorted[0], sorted[2], sorted[3]],
        2 => [sorted[0], sorted[1], sorted[3]],
        _ => [sorted[0], sorted[1], sorted[2]],
    }
}

/// The permutation `perm` putting `v` in canonical slot order
/// (`canonical[j] = v[perm[j]]`), from the permutation parity alone: `v`
/// sorted ascending, last two swapped when the sort is an odd permutation.
/// For distinct ids of a positively oriented tet the result is positively
/// oriented too.
pub fn canonical_permutation(v: [u32; 4]) -> [usize; 4] {
    let mut perm = [0usize, 1, 2, 3];
    perm.sort_unstable_by_key(|&i| v[i]);
    // Parity of the permutation = parity of its inversion count.
    let mut inversions = 0;
    for i in 0..4 {
        for j in i + 1..4 {
            inversions += (perm[i] > perm[j]) as u32;
        }
    }
    if inversions % 2 == 1 {
        perm.swap(2, 3);
    }
    perm
}

/// Canonical slot order of a tet from its id set and the geometry: the ids
/// ascending, last two swapped when the exact orientation of the ascending
/// order is negative. `None` when an id is out of bounds or the four points
/// are coplanar (no valid tet has that id set).
pub fn canonical_tet_from_ids(ids: [u32; 4], points: &[Vec3]) -> Option<[u32; 4]> {
    let s = sort4(ids);
    let p = [
        *points.get(s[0] as usize)?,
        *points.get(s[1] as usize)?,
        *points.get(s[2] as usize)?,
        *points.get(s[3] as usize)?,
    ];
    let o = orient3d_f32(p[0], p[1], p[2], p[3]);
    if o > 0.0 {
        Some(s)
    } else if o < 0.0 {
        Some([s[0], s[1], s[3], s[2]])
    } else {
        None
    }
}

/// `mesh` with every tet's slots permuted into canonical order (see the
/// module docs): vertex ids, neighbour links and the `face` fields of the
/// constrained-face table move together, so the result describes the same
/// tetrahedralization. This is what [`Tet20Mesh::to_mesh`] and
/// [`Tet16Mesh::to_mesh`] return. Idempotent; table entries naming tets out
/// of range are left untouched (validation reports them).
pub fn canonical_slot_order(mesh: &TetMesh) -> TetMesh {
    let perms: Vec<[usize; 4]> = mesh
        .tets
        .iter()
        .map(|&t| canonical_permutation(t))
        .collect();
    let mut out = mesh.clone();
    for (t, perm) in perms.iter().enumerate() {
        let v = mesh.tets[t];
        out.tets[t] = perm.map(|i| v[i]);
        if let Some(n) = mesh.neighbors.get(t) {
            out.neighbors[t] = perm.map(|i| n[i]);
        }
    }
    for cf in &mut out.constrained {
        for side in [&mut cf.front, &mut cf.back] {
            if let Some(perm) = perms.get(side.tet as usize)
                && let Some(j) = perm.iter().position(|&i| i as u32 == side.face)
            {
                side.face = j as u32;
            }
        }
    }
    out
}

/// Links of a tet permuted from slot order into rank order: entry `r` is the
/// link across the face opposite the vertex of rank `r`.
#[inline]
pub fn links_by_rank(ids: [u32; 4], links: [Link; 4]) -> [Link; 4] {
    let mut out = [Link::BOUNDARY; 4];
    for s in 0..4 {
        out[rank_of(ids[s], ids) & 3] = links[s];
    }
    out
}

/// Links of a tet permuted from rank order back into the slot order of `ids`.
#[inline]
pub fn links_by_slot(ids: [u32; 4], by_rank: [Link; 4]) -> [Link; 4] {
    ids.map(|v| by_rank[rank_of(v, ids) & 3])
}

// ---------------------------------------------------------------------------
// Anchors.
// ---------------------------------------------------------------------------

/// A fully decoded tet stored in the cold anchor table of Tet20/Tet16 (the
/// paper's *source tet*): one per connected component. Walks and point
/// location start here; whole-mesh decoding walks outward from here.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Pod, Zeroable)]
pub struct Anchor {
    /// Index of the tet.
    pub tet: u32,
    /// Its vertex ids in canonical slot order.
    pub vertices: [u32; 4],
    /// Its links in the same slot order (link `k` opposite `vertices[k]`).
    pub neighbors: [Link; 4],
}

const _: () = assert!(size_of::<Anchor>() == 36);

impl Anchor {
    /// The anchor's links in rank order (entry `r` opposite the vertex of
    /// rank `r`), as stored by Tet20 and decoded by Tet16.
    #[inline]
    pub fn links_by_rank(&self) -> [Link; 4] {
        links_by_rank(self.vertices, self.neighbors)
    }

    /// A known `(link, rank)` pair to start Tet16 decoding in the anchor
    /// tet: its link at rank 3.
    #[inline]
    pub fn tet16_entry(&self) -> (Link, usize) {
        (self.links_by_rank()[3], 3)
    }
}

/// The smallest tet index of every connected component of `mesh`, ascending.
///
/// Tets are connected through shared faces and through constrained faces that
/// have a tet on both sides (secondary rays cross those via the table). Links
/// or table entries out of range are ignored.
pub fn component_roots(mesh: &TetMesh) -> Vec<u32> {
    let n = mesh.tets.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn find(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            let p = parent[x as usize];
            parent[x as usize] = parent[p as usize];
            x = p;
        }
        x
    }
    // Union by smaller index, so every root is its component's minimum.
    let union = |parent: &mut Vec<u32>, a: u32, b: u32| {
        let (ra, rb) = (find(parent, a), find(parent, b));
        if ra < rb {
            parent[rb as usize] = ra;
        } else if rb < ra {
            parent[ra as usize] = rb;
        }
    };
    for (t, links) in mesh.neighbors.iter().enumerate().take(n) {
        for l in links {
            if let LinkKind::Tet(m) = l.kind()
                && (m as usize) < n
            {
                union(&mut parent, t as u32, m);
            }
        }
    }
    for cf in &mesh.constrained {
        if (cf.front.tet as usize) < n && (cf.back.tet as usize) < n {
            union(&mut parent, cf.front.tet, cf.back.tet);
        }
    }
    (0..n as u32)
        .filter(|&t| find(&mut parent, t) == t)
        .collect()
}

/// Builds the anchor table of a mesh already in canonical slot order.
pub(crate) fn anchors_of(canonical: &TetMesh) -> Vec<Anchor> {
    component_roots(canonical)
        .into_iter()
        .map(|t| Anchor {
            tet: t,
            vertices: canonical.tets[t as usize],
            neighbors: canonical.neighbors[t as usize],
        })
        .collect()
}

/// Per-tet canonical vertex ids and rank-ordered links, as decoded by
/// [`decode_by_walk`].
pub(crate) type Decoded = (Vec<[u32; 4]>, Vec<[Link; 4]>);

/// Shared breadth-first decoder of the id-less layouts (Tet20, Tet16).
///
/// Starting from the anchors, walks every shared face and every two-sided
/// constrained face; `vx[t]` is the xor-sum of tet `t`. `links_of(t, entry,
/// entry_rank, ids_sorted)` returns the rank-ordered links of tet `t` given the
/// link through which it was entered (as seen from `t`) and that face's rank;
/// for an anchor it is called with the anchor's own link at rank 3.
/// Returns per-tet canonical vertex ids and rank-ordered links.
pub(crate) fn decode_by_walk(
    layout: &'static str,
    vx: &[u32],
    points: &[Vec3],
    constrained: &[crate::ConstrainedFace],
    anchors: &[Anchor],
    mut links_of: impl FnMut(usize, Link, usize) -> [Link; 4],
) -> Result<Decoded, LayoutError> {
    let n = vx.len();
    let mut ids = vec![[0u32; 4]; n];
    let mut links = vec![[Link::BOUNDARY; 4]; n];
    let mut seen = vec![false; n];
    let mut queue: Vec<u32> = Vec::new();
    let corrupt = |element: &'static str, index: usize, detail: String| LayoutError::Corrupt {
        layout,
        element,
        index,
        detail,
    };
    for (a, anchor) in anchors.iter().enumerate() {
        let t = anchor.tet as usize;
        if t >= n {
            return Err(corrupt(
                "anchor",
                a,
                format!("tet {t} is out of bounds ({n} tets)"),
            ));
        }
        if xor_sum(anchor.vertices) != vx[t] {
            return Err(corrupt(
                "anchor",
                a,
                format!("vertices disagree with tet {t}'s xor-sum"),
            ));
        }
        if seen[t] {
            return Err(corrupt("anchor", a, format!("tet {t} is anchored twice")));
        }
        let canon = canonical_tet_from_ids(anchor.vertices, points)
            .filter(|c| *c == anchor.vertices)
            .ok_or_else(|| corrupt("anchor", a, "vertices are not in canonical order".into()))?;
        let by_rank = links_by_rank(canon, anchor.neighbors);
        let decoded = links_of(t, by_rank[3], 3);
        if decoded != by_rank {
            return Err(corrupt(
                "anchor",
                a,
                format!("links disagree with tet {t}'s record"),
            ));
        }
        ids[t] = canon;
        links[t] = decoded;
        seen[t] = true;
        queue.push(t as u32);
    }
    let mut head = 0;
    while head < queue.len() {
        let t = queue[head];
        head += 1;
        let sorted = sort4(ids[t as usize]);
        for r in 0..4 {
            let link = links[t as usize][r];
            let next = match link.kind() {
                LinkKind::Boundary => continue,
                LinkKind::Tet(m) => m,
                LinkKind::Constrained(c) => {
                    let cf = constrained.get(c as usize).ok_or_else(|| {
                        corrupt(
                            "tet",
                            t as usize,
                            format!("constrained face {c} is out of bounds"),
                        )
                    })?;
                    match cf.other_side(t) {
                        Some(s) if s.exists() => s.tet,
                        Some(_) => continue,
                        None => {
                            return Err(corrupt(
                                "constrained face",
                                c as usize,
                                format!("does not list tet {t} as a side"),
                            ));
                        }
                    }
                }
            };
            let m = next as usize;
            if m >= n {
                return Err(corrupt(
                    "tet",
                    t as usize,
                    format!("neighbour {m} is out of bounds"),
                ));
            }
            if seen[m] {
                continue;
            }
            let face = face_without_rank(sorted, r);
            let v = fourth_vertex(vx[m], face);
            let canon = canonical_tet_from_ids([face[0], face[1], face[2], v], points)
                .filter(|_| !face.contains(&v))
                .ok_or_else(|| {
                    corrupt(
                        "tet",
                        m,
                        format!("xor-sum decodes to invalid fourth vertex {v}"),
                    )
                })?;
            // The entry link as seen from m: the previous tet, or the same
            // constrained-face link.
            let entry = if link.is_constrained() {
                link
            } else {
                Link::tet(t)
            };
            let entry_rank = rank_of(v, canon);
            ids[m] = canon;
            links[m] = links_of(m, entry, entry_rank);
            seen[m] = true;
            queue.push(next);
        }
    }
    if let Some(t) = seen.iter().position(|s| !s) {
        return Err(corrupt("tet", t, "not reachable from any anchor".into()));
    }
    Ok((ids, links))
}
