//! Binned surface-area-heuristic split (Goldsmith and Salmon; the paper's
//! §3.3.1 high-level hierarchy), used twice: over triangles down to chunks,
//! and over the strips of a chunk down to one strip per leaf.

use glam::Vec3;

/// Bins per axis.
const BINS: usize = 16;

/// Something with a box to put into the BVH.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Item {
    /// Box minimum.
    pub lo: Vec3,
    /// Box maximum.
    pub hi: Vec3,
    /// Index of the triangle or strip it stands for.
    pub id: u32,
}

impl Item {
    fn centroid(&self) -> Vec3 {
        0.5 * (self.lo + self.hi)
    }
}

/// The box around all items.
pub(crate) fn bounds(items: &[Item]) -> (Vec3, Vec3) {
    items.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), it| (lo.min(it.lo), hi.max(it.hi)),
    )
}

fn half_area(lo: Vec3, hi: Vec3) -> f32 {
    let d = (hi - lo).max(Vec3::ZERO);
    d.x * d.y + d.y * d.z + d.z * d.x
}

/// Reorders `items` into two non-empty groups `[..mid]` and `[mid..]` by
/// the cheapest binned SAH split over the three axes, and returns `(mid,
/// axis)`. Items whose centroids coincide are split at the count median.
/// `items` must hold at least two items.
pub(crate) fn split(items: &mut [Item]) -> (usize, usize) {
    debug_assert!(items.len() >= 2);
    let (clo, chi) = items.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), it| (lo.min(it.centroid()), hi.max(it.centroid())),
    );
    let extent = chi - clo;
    let mut best: Option<(f32, usize, usize)> = None; // cost, axis, bins left of the split
    for axis in 0..3 {
        if extent[axis] <= 0.0 {
            continue;
        }
        let scale = BINS as f32 / extent[axis];
        let bin_of =
            |it: &Item| (((it.centroid()[axis] - clo[axis]) * scale) as usize).min(BINS - 1);
        let mut count = [0usize; BINS];
        let mut blo = [Vec3::splat(f32::INFINITY); BINS];
        let mut bhi = [Vec3::splat(f32::NEG_INFINITY); BINS];
        for it in items.iter() {
            let b = bin_of(it);
            count[b] += 1;
            blo[b] = blo[b].min(it.lo);
            bhi[b] = bhi[b].max(it.hi);
        }
        // Right-to-left sweep: cost of the right side for each split.
        let mut right_cost = [0.0f32; BINS];
        let (mut lo, mut hi, mut n) = (
            Vec3::splat(f32::INFINITY),
            Vec3::splat(f32::NEG_INFINITY),
            0,
        );
        for b in (1..BINS).rev() {
            lo = lo.min(blo[b]);
            hi = hi.max(bhi[b]);
            n += count[b];
            right_cost[b] = half_area(lo, hi) * n as f32;
        }
        let (mut lo, mut hi, mut n) = (
            Vec3::splat(f32::INFINITY),
            Vec3::splat(f32::NEG_INFINITY),
            0,
        );
        for b in 1..BINS {
            lo = lo.min(blo[b - 1]);
            hi = hi.max(bhi[b - 1]);
            n += count[b - 1];
            if n == 0 || n == items.len() {
                continue;
            }
            let cost = half_area(lo, hi) * n as f32 + right_cost[b];
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, b));
            }
        }
    }
    if let Some((_, axis, b)) = best {
        let scale = BINS as f32 / extent[axis];
        let mut mid = 0;
        for i in 0..items.len() {
            let c = items[i].centroid()[axis];
            if ((((c - clo[axis]) * scale) as usize).min(BINS - 1)) < b {
                items.swap(i, mid);
                mid += 1;
            }
        }
        if mid > 0 && mid < items.len() {
            return (mid, axis);
        }
    }
    // Coincident centroids (or a degenerate binning).
    median(items)
}

/// Count-median split along the widest axis of the boxes, ordered by box
/// centre then id (deterministic).
pub(crate) fn median(items: &mut [Item]) -> (usize, usize) {
    let (lo, hi) = bounds(items);
    let axis = (hi - lo).max_position();
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |a, b| {
        a.centroid()[axis]
            .total_cmp(&b.centroid()[axis])
            .then(a.id.cmp(&b.id))
    });
    (mid, axis)
}
