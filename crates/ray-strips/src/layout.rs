//! Memory layout of a built structure: the strip blocks of the paper's
//! Fig. 5, the high-level BVH nodes, and the pure arithmetic on them that
//! both construction and traversal use.
//!
//! # One strip block (paper §4.1, Fig. 5)
//!
//! All strips live in one `Vec<u32>`; a strip of `n` triangles is one
//! contiguous block of [`strip_words`]`(n)` words starting at the offset its
//! BVH leaf stores:
//!
//! | words | content |
//! |---|---|
//! | 1 | header: `n` |
//! | `2K` | nodes in preorder: `lo`, `hi` split coordinates (`f32` bits) |
//! | `⌈K/4⌉` | node flags, one byte per node, four per word (little end first): bits 0–1 axis, bit 2 reverse |
//! | `n + 2` | strip vertex indices into the global vertex list |
//! | `n` | per-triangle word: `input_triangle << 3 \| permutation` (permutation 7: swap slot) |
//!
//! with `K = max(⌊n/2⌋ − 1, 0)` ([`hierarchy_nodes`]), `n` counting swap
//! slots (see the stripifier) as triangles. Hence the size is
//! known from `n` alone:
//!
//! `strip_words(n) = 1 + 2K + ⌈K/4⌉ + (n + 2) + n`.
//!
//! Deviation from Fig. 5: the paper interleaves each node's two floats with
//! its flag byte (9 bytes a node); here the flag bytes follow the node
//! floats so every float stays 4-byte aligned. The bytes are the same up to
//! the rounding of `⌈K/4⌉`. The header is a 32-bit word (the paper: 16 bits)
//! and the per-triangle word holds the input triangle id and vertex
//! permutation instead of the paper's 16-bit material id.
//!
//! # The balanced split (paper §4.1)
//!
//! A node covering `m ≥ 4` triangles holds `L = ⌊m/2⌋` triangle pairs. Its
//! *first* part (earlier in strip order; the paper's "left" before the
//! reverse flag is applied) takes `⌈L/2⌉` pairs plus the odd triangle if
//! `m` is odd; the *second* part takes `⌊L/2⌋` pairs. Parts with `m ≤ 3`
//! are the implicit leaves (the paper stops at sub-strips of 2 triangles;
//! with an odd `n` one leaf holds 3). Every leaf thus holds 2 or 3
//! triangles (a strip of one triangle is a single leaf), there are `⌊n/2⌋`
//! leaves and `⌊n/2⌋ − 1` nodes, exactly the paper's count. In preorder the first child of node `i` is `i + 1` and the
//! second is `i + ⌈L/2⌉` (the first subtree has `⌈L/2⌉ − 1` nodes), so no
//! child pointers are stored.
//!
//! The two parts overlap in vertices: triangles `[a, b)` use strip vertices
//! `[a, b + 2)`, so both children contain the centre edge `(b, b + 1)`
//! (Fig. 4's red edge 4–5).
//!
//! # Which child is "left" (erratum-prone)
//!
//! `lo` is the largest coordinate along `axis` of the *lower* child and `hi`
//! the smallest coordinate of the *upper* child (the paper's split1 and
//! split2; they may cross, `lo > hi`, when the children overlap). The lower
//! child is the first part unless the reverse flag is set. During traversal
//! the lower child's box is the parent's with `max[axis] = lo`, the upper
//! child's the parent's with `min[axis] = hi`.

use glam::{Vec3, Vec3A, Vec4};

/// Node-flag bit: the second strip part is the lower child.
pub(crate) const REVERSE: u8 = 4;

/// Per-triangle word: bits above this hold the input triangle index.
pub(crate) const PERMUTATION_BITS: u32 = 3;

/// Per-triangle word of a swap slot (permutation field 7): a copy of a
/// neighbouring triangle that the strip needs to turn, never tested.
pub(crate) const SWAP_WORD: u32 = 7;

/// Largest input triangle count a per-triangle word can name.
pub const MAX_TRIANGLES: usize = 1 << (32 - PERMUTATION_BITS);

/// The six orders of three vertices: `PERMUTATIONS[p][k]` is the strip
/// position (0, 1, 2 within the strip triangle) of input vertex `k`.
pub(crate) const PERMUTATIONS: [[u8; 3]; 6] = [
    [0, 1, 2],
    [1, 2, 0],
    [2, 0, 1],
    [0, 2, 1],
    [2, 1, 0],
    [1, 0, 2],
];

/// Strip-hierarchy nodes of a strip of `n` triangles: `max(⌊n/2⌋ − 1, 0)`.
pub const fn hierarchy_nodes(n: usize) -> usize {
    (n / 2).saturating_sub(1)
}

/// Words of one strip block of `n` triangles (see the module docs):
/// `1 + 2K + ⌈K/4⌉ + (n + 2) + n` with `K = hierarchy_nodes(n)`.
pub const fn strip_words(n: usize) -> usize {
    let k = hierarchy_nodes(n);
    1 + 2 * k + k.div_ceil(4) + (n + 2) + n
}

/// Words of one block that belong to the hierarchy (header, node
/// coordinates, flag words); the rest is geometry.
pub const fn strip_hierarchy_words(n: usize) -> usize {
    let k = hierarchy_nodes(n);
    1 + 2 * k + k.div_ceil(4)
}

/// Sizes of the two parts of a node over `m ≥ 4` triangles, in strip
/// order, and the pair count of the first part (the preorder distance to
/// the second child).
#[inline(always)]
pub(crate) const fn split_counts(m: u32) -> (u32, u32, u32) {
    let pairs = m / 2;
    let first_pairs = pairs.div_ceil(2);
    let first = 2 * first_pairs + (m & 1);
    (first, m - first, first_pairs)
}

/// Offsets, relative to a block's start, of its sections.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BlockLayout {
    /// Triangles in the strip.
    pub n: u32,
    /// First word of the node coordinates.
    pub nodes: usize,
    /// First word of the packed flag bytes.
    pub flags: usize,
    /// First word of the vertex indices.
    pub indices: usize,
    /// First word of the per-triangle words.
    pub triangles: usize,
}

impl BlockLayout {
    /// The layout of a block of `n` triangles starting at word `start`.
    #[inline(always)]
    pub fn new(start: usize, n: u32) -> Self {
        let k = hierarchy_nodes(n as usize);
        let nodes = start + 1;
        let flags = nodes + 2 * k;
        let indices = flags + k.div_ceil(4);
        let triangles = indices + n as usize + 2;
        Self {
            n,
            nodes,
            flags,
            indices,
            triangles,
        }
    }

    /// Node `i`'s `(lo, hi, axis, reverse)`.
    #[inline(always)]
    pub fn node(&self, words: &[u32], i: usize) -> (f32, f32, usize, bool) {
        let lo = f32::from_bits(words[self.nodes + 2 * i]);
        let hi = f32::from_bits(words[self.nodes + 2 * i + 1]);
        let flag = (words[self.flags + i / 4] >> (8 * (i % 4))) as u8;
        (lo, hi, (flag & 3) as usize, flag & REVERSE != 0)
    }
}

/// Flag on [`BvhNode::b`] marking a leaf.
pub(crate) const LEAF: u32 = 1 << 31;

/// A high-level BVH node (32 bytes): two 16-byte vectors, box minimum
/// and maximum in `xyz`, and in the `w` lanes (as `f32` bits) two words
/// `a` and `b`, so that a box test loads two aligned vectors. Inner: first
/// child at `self + 1`, second child at `a`, `b` = split axis (children are
/// visited first-child first when the ray's direction along that axis is
/// `≥ 0`). Leaf: `a` = word offset of its first strip block,
/// `b = LEAF | count` for `count` consecutive blocks.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BvhNode {
    /// Box minimum and `a`.
    pub lo: Vec4,
    /// Box maximum and `b`.
    pub hi: Vec4,
}

impl BvhNode {
    /// A node over the box `[min, max]` with words `a` and `b`.
    pub fn new(min: Vec3, max: Vec3, a: u32, b: u32) -> Self {
        Self {
            lo: min.extend(f32::from_bits(a)),
            hi: max.extend(f32::from_bits(b)),
        }
    }

    /// Second child (inner) or strip block offset (leaf).
    #[inline(always)]
    pub fn a(&self) -> u32 {
        self.lo.w.to_bits()
    }

    /// Split axis (inner) or [`LEAF`]` | count`.
    #[inline(always)]
    pub fn b(&self) -> u32 {
        self.hi.w.to_bits()
    }

    /// Box minimum.
    #[inline(always)]
    pub fn min(&self) -> Vec3A {
        Vec3A::from_vec4(self.lo)
    }

    /// Box maximum.
    #[inline(always)]
    pub fn max(&self) -> Vec3A {
        Vec3A::from_vec4(self.hi)
    }
}

/// The strip blocks of a leaf node: `(offset, count)` (meaningful only
/// for leaves).
#[inline(always)]
pub(crate) fn leaf_blocks(node: &BvhNode) -> (usize, u32) {
    (node.a() as usize, node.b() & !LEAF)
}

/// Whether a BVH node is a leaf.
#[inline(always)]
pub(crate) fn is_leaf(node: &BvhNode) -> bool {
    node.b() & LEAF != 0
}

/// Everything traversal reads.
#[derive(Clone, Debug, Default)]
pub(crate) struct StripData {
    /// Global vertex list (only referenced vertices).
    pub vertices: Vec<[f32; 3]>,
    /// All strip blocks.
    pub words: Vec<u32>,
    /// High-level BVH, root at 0 (empty for an empty mesh).
    pub nodes: Vec<BvhNode>,
}
