//! Memory layout of a built structure: the strip blocks of the paper's
//! Fig. 5, the high-level BVH nodes, and the pure arithmetic on them that
//! both construction and traversal use.
//!
//! # One strip block (paper §4.1, Fig. 5)
//!
//! All strips live in one `Vec<u32>`; a strip of `n` triangles is one
//! contiguous block of [`strip_words`]`(n, b)` words starting at the offset
//! its BVH leaf stores:
//!
//! | words | content |
//! |---|---|
//! | 1 | header: `n` (bits 0–7) and the strip's quantized box (bits 8–31, [`StripBox`]) |
//! | `2K` | nodes in preorder: `lo`, `hi` split coordinates (`f32` bits) |
//! | `⌈K/4⌉` | node flags, one byte per node, four per word (little end first): bits 0–1 axis, bit 2 reverse |
//! | `n + 2` | strip vertex indices into the global vertex list |
//! | `⌈n·b/32⌉` | per-triangle words of `b` bits, packed little end first: `input_triangle << 3 \| permutation` (permutation 7: swap slot) |
//!
//! with `K = max(⌊n/2⌋ − 1, 0)` ([`hierarchy_nodes`]), `n` counting swap
//! slots (see the stripifier) as triangles, and `b` the width of a
//! per-triangle word, one for the whole structure: 3 permutation bits plus
//! the bits of the largest input triangle index ([`triangle_word_bits`];
//! 20 for the bunny's 69,451 triangles). Hence the size is known from `n`
//! and `b` alone:
//!
//! `strip_words(n, b) = 1 + 2K + ⌈K/4⌉ + (n + 2) + ⌈n·b/32⌉`.
//!
//! A strip has at most [`MAX_STRIP`] triangles (the builder cuts longer
//! ones), so that `n` fits the header's low byte.
//!
//! # The strip box (beyond the paper)
//!
//! When a BVH leaf holds several strips, the paper's Algorithm 1 would
//! start every strip from the leaf's box. Instead, the header's upper 24
//! bits hold the strip's own box, quantized to 4 bits per face on a grid of
//! [`BOX_STEPS`] steps over the leaf's box (lower faces rounded down, upper
//! faces up, checked with the same `f32` operations traversal uses, so the
//! decoded box always contains the strip). A ray skips a strip whose box it
//! misses and starts Algorithm 1 from the interval of the strip's box. The
//! box costs no memory: it fills the header word beside `n` (the paper's
//! header is 16 bits; a 32-bit one keeps the block's words aligned).
//!
//! Deviation from Fig. 5: the paper interleaves each node's two floats with
//! its flag byte (9 bytes a node); here the flag bytes follow the node
//! floats so every float stays 4-byte aligned. The bytes are the same up to
//! the rounding of `⌈K/4⌉`. The header is a 32-bit word (the paper: 16 bits)
//! and the per-triangle word holds the input triangle id and vertex
//! permutation instead of the paper's 16-bit material id, in `b` bits.
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

/// Most triangles in one strip (the header stores `n` in 8 bits).
pub const MAX_STRIP: usize = 255;

/// Steps of the strip-box grid per axis: codes run from 0 to `BOX_STEPS`.
pub const BOX_STEPS: u32 = 15;

/// Triangle count `n` of a strip from its header word.
#[inline(always)]
pub(crate) const fn header_n(header: u32) -> u32 {
    header & 0xff
}

/// A strip's box relative to its leaf's box: per axis, the code of the
/// lower and the upper face on a grid of [`BOX_STEPS`] steps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StripBox {
    /// Lower-face codes (0 = the leaf's lower face).
    pub lower: [u32; 3],
    /// Upper-face codes ([`BOX_STEPS`] = the leaf's upper face).
    pub upper: [u32; 3],
}

impl StripBox {
    /// The box covering the whole leaf.
    pub const LEAF: StripBox = StripBox {
        lower: [0; 3],
        upper: [BOX_STEPS; 3],
    };

    /// The header word of a strip of `n ≤ MAX_STRIP` triangles with this box.
    pub const fn header(&self, n: u32) -> u32 {
        let mut h = n;
        let mut a = 0;
        while a < 3 {
            h |= self.lower[a] << (8 + 4 * a);
            h |= self.upper[a] << (20 + 4 * a);
            a += 1;
        }
        h
    }

    /// The codes stored in a header word.
    #[inline(always)]
    pub fn from_header(header: u32) -> StripBox {
        let nibble = |shift: u32| (header >> shift) & 0xf;
        StripBox {
            lower: [nibble(8), nibble(12), nibble(16)],
            upper: [nibble(20), nibble(24), nibble(28)],
        }
    }
}

/// The strip-box grid of one leaf: its box and the step per axis.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LeafGrid {
    lo: Vec3A,
    hi: Vec3A,
    step: Vec3A,
}

impl LeafGrid {
    /// The grid over a leaf node's box (its `w` lanes, the node's words,
    /// are left out: as floats they are subnormal and slow in arithmetic).
    #[inline(always)]
    pub fn new(leaf: &BvhNode) -> Self {
        Self::over(leaf.lo.truncate(), leaf.hi.truncate())
    }

    /// The grid over the box `[lo, hi]` (the builder's, before the leaf's
    /// node exists). Each end is divided separately, so the step is finite
    /// for any finite box.
    #[inline(always)]
    pub fn over(lo: Vec3, hi: Vec3) -> Self {
        let (lo, hi) = (Vec3A::from(lo), Vec3A::from(hi));
        let steps = Vec3A::splat(BOX_STEPS as f32);
        Self {
            lo,
            hi,
            step: hi / steps - lo / steps,
        }
    }

    /// The decoded box of the strip with header word `header`: code `q`
    /// gives the lower face `lo + q·step` (exactly `lo` for 0) and the
    /// upper face `hi − (BOX_STEPS − q)·step` (exactly `hi` for
    /// `BOX_STEPS`). The builder quantizes with this same function, so
    /// the decoded box always contains the strip.
    #[inline(always)]
    pub fn strip_box(&self, header: u32) -> (Vec3A, Vec3A) {
        let q = StripBox::from_header(header);
        let lower = Vec3A::from(q.lower.map(|c| c as f32));
        let upper = Vec3A::from(q.upper.map(|c| (BOX_STEPS - c) as f32));
        (self.lo + lower * self.step, self.hi - upper * self.step)
    }
}

/// Strip-hierarchy nodes of a strip of `n` triangles: `max(⌊n/2⌋ − 1, 0)`.
pub const fn hierarchy_nodes(n: usize) -> usize {
    (n / 2).saturating_sub(1)
}

/// Words of one strip block of `n` triangles with per-triangle words of
/// `bits` bits (see the module docs): `1 + 2K + ⌈K/4⌉ + (n + 2) +
/// ⌈n·bits/32⌉` with `K = hierarchy_nodes(n)`.
pub const fn strip_words(n: usize, bits: u32) -> usize {
    let k = hierarchy_nodes(n);
    1 + 2 * k + k.div_ceil(4) + (n + 2) + (n * bits as usize).div_ceil(32)
}

/// Width of the per-triangle words of a structure over `triangles` input
/// triangles: the permutation bits plus enough bits for the largest input
/// index (at least one).
pub const fn triangle_word_bits(triangles: usize) -> u32 {
    let largest = triangles.saturating_sub(1) as u64;
    let index_bits = if largest == 0 {
        1
    } else {
        64 - largest.leading_zeros()
    };
    PERMUTATION_BITS + index_bits
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
    /// The layout of the block starting at word `start` with header word
    /// `header`.
    #[inline(always)]
    pub fn new(start: usize, header: u32) -> Self {
        let n = header_n(header);
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
    /// Width of a per-triangle word ([`triangle_word_bits`]).
    pub triangle_bits: u32,
    /// Global vertex list (only referenced vertices).
    pub vertices: Vec<[f32; 3]>,
    /// All strip blocks.
    pub words: Vec<u32>,
    /// High-level BVH, root at 0 (empty for an empty mesh).
    pub nodes: Vec<BvhNode>,
}

impl StripData {
    /// Words of the block whose header word is `header`.
    #[inline(always)]
    pub fn block_words(&self, header: u32) -> usize {
        strip_words(header_n(header) as usize, self.triangle_bits)
    }

    /// Per-triangle word of strip triangle `j` of the block at `layout`.
    #[inline(always)]
    pub fn triangle_word(&self, layout: &BlockLayout, j: usize) -> u32 {
        let bit = j * self.triangle_bits as usize;
        let at = layout.triangles + bit / 32;
        let low = u64::from(self.words[at]);
        // The word's last bits may lie in the next word (none after the
        // last block: then the word ends within this one).
        let high = self.words.get(at + 1).map_or(0, |&w| u64::from(w));
        let both = low | (high << 32);
        ((both >> (bit % 32)) & ((1u64 << self.triangle_bits) - 1)) as u32
    }
}

/// Appends `values` of `bits` bits each to `out`, packed little end first
/// (the layout [`StripData::triangle_word`] reads).
pub(crate) fn pack_words(values: &[u32], bits: u32, out: &mut [u32]) {
    debug_assert_eq!(out.len(), (values.len() * bits as usize).div_ceil(32));
    for (j, &v) in values.iter().enumerate() {
        debug_assert!(u64::from(v) < 1u64 << bits);
        let bit = j * bits as usize;
        let at = bit / 32;
        let shifted = u64::from(v) << (bit % 32);
        out[at] |= shifted as u32;
        if (shifted >> 32) != 0 {
            out[at + 1] |= (shifted >> 32) as u32;
        }
    }
}
