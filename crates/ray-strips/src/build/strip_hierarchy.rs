//! Writes one strip block: header, balanced strip hierarchy (paper §4.1,
//! Fig. 4) and the strip itself, in the layout of [`crate::layout`].
//!
//! Each node stores, on the axis of least overlap between its two parts,
//! the lower part's maximum (`lo`) and the upper part's minimum (`hi`), and
//! whether the lower part is the second one in strip order (reverse flag).

use glam::Vec3;

use crate::layout::{
    BOX_STEPS, BlockLayout, LeafGrid, MAX_STRIP, REVERSE, StripBox, pack_words, split_counts,
    strip_words,
};

/// Appends the block of one strip to `out` and returns its box.
/// `strip_vertices` has `n + 2` global vertex indices and `triangle_words`
/// the `n` per-triangle words (packed to `bits` bits each); `leaf` is the box of the BVH leaf that will
/// hold the strip (it must contain the strip).
pub(crate) fn write_block(
    positions: &[[f32; 3]],
    strip_vertices: &[u32],
    triangle_words: &[u32],
    bits: u32,
    leaf: (Vec3, Vec3),
    out: &mut Vec<u32>,
) -> (Vec3, Vec3) {
    let n = triangle_words.len();
    debug_assert!(n <= MAX_STRIP);
    debug_assert_eq!(strip_vertices.len(), n + 2);
    let start = out.len();
    out.resize(start + strip_words(n, bits), 0);
    let layout = BlockLayout::new(start, n as u32);
    out[layout.indices..layout.indices + n + 2].copy_from_slice(strip_vertices);
    pack_words(triangle_words, bits, &mut out[layout.triangles..]);
    let writer = Writer {
        positions,
        strip_vertices,
        layout,
    };
    let bounds = writer.node(out, 0, 0, n as u32);
    out[start] = quantize(leaf, bounds).header(n as u32);
    bounds
}

/// The codes of the smallest grid box around `strip` within `leaf`: on
/// each axis the largest lower code and the smallest upper code whose
/// faces, decoded by traversal's own [`LeafGrid::strip_box`], still
/// enclose the strip.
fn quantize(leaf: (Vec3, Vec3), strip: (Vec3, Vec3)) -> StripBox {
    let grid = LeafGrid::over(leaf.0, leaf.1);
    // The lower and upper faces of code `c`, on every axis at once.
    let faces: [_; BOX_STEPS as usize + 1] = std::array::from_fn(|c| {
        let c = c as u32;
        let codes = StripBox {
            lower: [c; 3],
            upper: [c; 3],
        };
        grid.strip_box(codes.header(0))
    });
    let mut q = StripBox::LEAF;
    for a in 0..3 {
        q.lower[a] = (0..=BOX_STEPS)
            .rev()
            .find(|&c| faces[c as usize].0[a] <= strip.0[a])
            .unwrap_or(0);
        q.upper[a] = (0..=BOX_STEPS)
            .find(|&c| faces[c as usize].1[a] >= strip.1[a])
            .unwrap_or(BOX_STEPS);
    }
    q
}

struct Writer<'a> {
    positions: &'a [[f32; 3]],
    strip_vertices: &'a [u32],
    layout: BlockLayout,
}

impl Writer<'_> {
    /// Writes the subtree over triangles `[t0, t0 + m)` rooted at preorder
    /// node `i` and returns the box of those triangles.
    fn node(&self, out: &mut [u32], i: usize, t0: u32, m: u32) -> (Vec3, Vec3) {
        if m <= 3 {
            let vs = &self.strip_vertices[t0 as usize..(t0 + m + 2) as usize];
            return vs.iter().fold(
                (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                |(lo, hi), &v| {
                    let p = Vec3::from(self.positions[v as usize]);
                    (lo.min(p), hi.max(p))
                },
            );
        }
        let (first, second, first_pairs) = split_counts(m);
        let a = self.node(out, i + 1, t0, first);
        let b = self.node(out, i + first_pairs as usize, t0 + first, second);
        // Axis and order of least overlap (lo − hi; negative is a gap).
        let mut best = (f32::INFINITY, 0usize, false);
        for axis in 0..3 {
            let straight = a.1[axis] - b.0[axis];
            let reverse = b.1[axis] - a.0[axis];
            if straight < best.0 {
                best = (straight, axis, false);
            }
            if reverse < best.0 {
                best = (reverse, axis, true);
            }
        }
        let (_, axis, reverse) = best;
        let (lower, upper) = if reverse { (b, a) } else { (a, b) };
        out[self.layout.nodes + 2 * i] = lower.1[axis].to_bits();
        out[self.layout.nodes + 2 * i + 1] = upper.0[axis].to_bits();
        let flag = axis as u32 | if reverse { u32::from(REVERSE) } else { 0 };
        out[self.layout.flags + i / 4] |= flag << (8 * (i % 4));
        (a.0.min(b.0), a.1.max(b.1))
    }
}
