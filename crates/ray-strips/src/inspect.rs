//! Read-only views of the built strips, for tests and diagnostics: what
//! traversal reads, decoded.

use glam::Vec3;

use crate::layout::{
    BlockLayout, LeafGrid, PERMUTATION_BITS, PERMUTATIONS, SWAP_WORD, StripData, is_leaf,
    leaf_blocks, split_counts,
};

/// One node of a strip hierarchy, decoded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StripNode {
    /// Split axis (0 = x, 1 = y, 2 = z).
    pub axis: usize,
    /// Largest coordinate of the lower child along `axis` (paper: split1).
    pub lo: f32,
    /// Smallest coordinate of the upper child along `axis` (paper: split2).
    pub hi: f32,
    /// Whether the lower child is the second part in strip order.
    pub reverse: bool,
    /// First part: first triangle and triangle count.
    pub first: (u32, u32),
    /// Second part: first triangle and triangle count.
    pub second: (u32, u32),
}

/// One strip (one high-level BVH leaf), decoded.
#[derive(Clone, Debug, PartialEq)]
pub struct StripView {
    /// Box of the BVH leaf holding the strip (shared by the strips of a
    /// leaf when `strips_per_leaf > 1`).
    pub bounds: (Vec3, Vec3),
    /// The strip's own box as traversal decodes it from the header (within
    /// `bounds`, around `vertices`).
    pub strip_bounds: (Vec3, Vec3),
    /// The `n + 2` strip vertex positions.
    pub vertices: Vec<Vec3>,
    /// Input triangle index of each strip triangle, in strip order (`None`
    /// for a swap slot, which repeats a neighbouring triangle).
    pub triangles: Vec<Option<u32>>,
    /// For each strip triangle, the strip position (0, 1 or 2 within
    /// `vertices[j..j + 3]`) of input vertex 0, 1 and 2 (`None` for a swap
    /// slot).
    pub input_order: Vec<Option<[u8; 3]>>,
    /// The hierarchy nodes in preorder.
    pub nodes: Vec<StripNode>,
    /// Size of the strip's block in bytes.
    pub block_bytes: usize,
}

/// Decodes every strip, in BVH leaf order.
pub(crate) fn strips(data: &StripData) -> Vec<StripView> {
    data.nodes
        .iter()
        .filter(|n| is_leaf(n))
        .flat_map(|leaf| {
            let (first, count) = leaf_blocks(leaf);
            (0..count).scan(first, move |offset, _| {
                let start = *offset;
                *offset += data.block_words(data.words[start]);
                Some((leaf, start))
            })
        })
        .map(|(leaf, start)| {
            let layout = BlockLayout::new(start, data.words[start]);
            let n = layout.n as usize;
            let vertices = data.words[layout.indices..layout.indices + n + 2]
                .iter()
                .map(|&v| Vec3::from(data.vertices[v as usize]))
                .collect();
            let words: Vec<u32> = (0..n).map(|j| data.triangle_word(&layout, j)).collect();
            let mut nodes = Vec::new();
            collect(data, &layout, 0, 0, layout.n, &mut nodes);
            let (lo, hi) = (Vec3::from(leaf.min()), Vec3::from(leaf.max()));
            let (slo, shi) = LeafGrid::new(leaf).strip_box(data.words[start]);
            StripView {
                bounds: (lo, hi),
                strip_bounds: (slo.into(), shi.into()),
                vertices,
                triangles: words
                    .iter()
                    .map(|&w| (w != SWAP_WORD).then_some(w >> PERMUTATION_BITS))
                    .collect(),
                input_order: words
                    .iter()
                    .map(|&w| {
                        (w != SWAP_WORD)
                            .then(|| PERMUTATIONS[(w & ((1 << PERMUTATION_BITS) - 1)) as usize])
                    })
                    .collect(),
                nodes,
                block_bytes: 4 * data.block_words(data.words[start]),
            }
        })
        .collect()
}

fn collect(
    data: &StripData,
    layout: &BlockLayout,
    i: u32,
    t0: u32,
    m: u32,
    out: &mut Vec<StripNode>,
) {
    if m <= 3 {
        return;
    }
    let (lo, hi, axis, reverse) = layout.node(&data.words, i as usize);
    let (first, second, first_pairs) = split_counts(m);
    debug_assert_eq!(out.len(), i as usize, "preorder");
    out.push(StripNode {
        axis,
        lo,
        hi,
        reverse,
        first: (t0, first),
        second: (t0 + first, second),
    });
    collect(data, layout, i + 1, t0, first, out);
    collect(data, layout, i + first_pairs, t0 + first, second, out);
}
