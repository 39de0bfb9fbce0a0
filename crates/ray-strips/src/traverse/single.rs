//! Single-ray traversal: the high-level BVH (depth first; both children's
//! boxes tested together, the one entered first visited first) and, in
//! each leaf, for every strip whose quantized box the ray enters
//! ([`crate::layout::LeafGrid`]), Algorithm 1 of the paper over the strip
//! hierarchy from that box's interval (paper §5.1).
//!
//! | paper (Alg. 1) | here |
//! |---|---|
//! | `left`, `right` (strip interval) | `t0`, `m` (first triangle, triangle count) |
//! | `(right − left + 1) > 2` | `m > 3` (see [`crate::layout`]: leaves hold 2 or 3 triangles; the paper's test counts vertices of 2-triangle leaves loosely) |
//! | `d_min`, `d_max` | `dmin`, `dmax` |
//! | `d_L` (near plane), `d_R` (far plane) | plane distances in [`node_children`] |
//! | `node.split1`, `node.split2` | `lo`, `hi` |
//! | `nearChild`, `farChild` with `reverse` | [`node_children`] |
//!
//! Differences from Algorithm 1: when only the far child is hit its entry
//! distance is also tightened (`max(d_R, d_min)`), and `dmax` is clamped to
//! the best hit so far whenever a node is taken up, so popped nodes behind
//! a hit are skipped. Plane and box distances get a relative slack
//! ([`crate::traverse::prepared::SLACK`]) so that rounding never culls a
//! ray aimed at a vertex or edge on a splitting plane.

use crate::layout::{
    BlockLayout, LeafGrid, MAX_STRIP, StripData, is_leaf, leaf_blocks, split_counts,
};
use crate::traverse::prepared::{Best, Prepared, down, fmax, fmin, up};
use crate::traverse::triangle::intersect_leaf;

/// Traversal stack depth of the high-level BVH (the builder caps the tree's
/// depth below this).
pub(crate) const BVH_STACK: usize = 64;
/// Traversal stack depth of a strip hierarchy: at least its depth, which
/// is below `log2` of the longest strip ([`MAX_STRIP`]); small, because
/// every ray sets its stacks up.
pub(crate) const STRIP_STACK: usize = 12;
const _: () = assert!(MAX_STRIP < 1 << STRIP_STACK);

/// The stacks of one single-ray traversal, allocated once per ray (or
/// once per packet for its single-ray fallbacks).
pub(crate) struct Stacks {
    bvh: [(u32, f32, f32); BVH_STACK],
    pub(crate) strip: [(Part, f32, f32); STRIP_STACK],
}

impl Stacks {
    /// Empty stacks.
    pub fn new() -> Self {
        let part = Part {
            node: 0,
            t0: 0,
            m: 0,
        };
        Self {
            bvh: [(0, 0.0, 0.0); BVH_STACK],
            strip: [(part, 0.0, 0.0); STRIP_STACK],
        }
    }
}

/// A strip-hierarchy node to visit: preorder index, first triangle,
/// triangle count.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Part {
    /// Preorder node index (meaningless for leaves).
    pub node: u32,
    /// First triangle of the part.
    pub t0: u32,
    /// Triangles in the part.
    pub m: u32,
}

/// Children of inner node `part` (`part.m ≥ 4`) in visiting order for rays
/// with `forward(axis)`, with the plane `lo` bounding the lower child from
/// above and `hi` bounding the upper child from below.
#[inline(always)]
pub(crate) fn node_children(
    data: &StripData,
    layout: &BlockLayout,
    part: Part,
    forward: impl Fn(usize) -> bool,
) -> (usize, f32, f32, [Part; 2]) {
    let (lo, hi, axis, reverse) = layout.node(&data.words, part.node as usize);
    let (first, second, first_pairs) = split_counts(part.m);
    let a = Part {
        node: part.node + 1,
        t0: part.t0,
        m: first,
    };
    let b = Part {
        node: part.node + first_pairs,
        t0: part.t0 + first,
        m: second,
    };
    let (lower, upper) = if reverse { (b, a) } else { (a, b) };
    let order = if forward(axis) {
        [lower, upper]
    } else {
        [upper, lower]
    };
    (axis, lo, hi, order)
}

/// The intervals of the near and far child (as ordered by
/// [`node_children`]) for one ray with current interval `[dmin, dmax]`.
#[inline(always)]
pub(crate) fn child_intervals(
    ray: &Prepared,
    axis: usize,
    lo: f32,
    hi: f32,
    dmin: f32,
    dmax: f32,
) -> [Option<(f32, f32)>; 2] {
    let d = ray.dir[axis];
    let o = ray.org[axis];
    if d == 0.0 {
        // Parallel to the planes: a child is hit iff the origin is on its side.
        let lower = (o <= lo).then_some((dmin, dmax));
        let upper = (o >= hi).then_some((dmin, dmax));
        return [lower, upper];
    }
    // Exit distance of the near child, entry distance of the far child.
    let (near_plane, far_plane) = if d > 0.0 { (lo, hi) } else { (hi, lo) };
    let t_exit = up((near_plane - o) * ray.inv[axis]);
    let t_entry = down((far_plane - o) * ray.inv[axis]);
    [
        (t_exit >= dmin).then(|| (dmin, fmin(dmax, t_exit))),
        (t_entry <= dmax).then(|| (fmax(dmin, t_entry), dmax)),
    ]
}

/// Closest (or, with `any`, some) hit of `ray` in the whole structure,
/// updating `best`; see [`trace_from`]. The root box is tested before the
/// stacks are set up, so a ray that misses the scene costs one box test.
pub(crate) fn trace(data: &StripData, ray: &Prepared, best: &mut Best, any: bool) -> bool {
    let Some(root) = data.nodes.first() else {
        return false;
    };
    let Some((_, exit)) = ray.box_interval(root, best.t) else {
        return false;
    };
    trace_from(data, 0, exit, ray, best, any, &mut Stacks::new())
}

/// Closest (or, with `any`, some) hit of `ray` in the subtree of BVH node
/// `root`, whose box the ray leaves at `exit`, updating `best`.
/// Returns `true` when `any` and a hit was found.
///
/// Both children of an inner node are box-tested together; the one the
/// ray enters first is visited next and the other, if hit, is pushed with
/// its entry distance, so that it is skipped on its pop once a closer hit
/// is known.
pub(crate) fn trace_from(
    data: &StripData,
    root: u32,
    mut exit: f32,
    ray: &Prepared,
    best: &mut Best,
    any: bool,
    stacks: &mut Stacks,
) -> bool {
    let Stacks { bvh: stack, strip } = stacks;
    let mut i = root as usize;
    let mut sp = 0;
    loop {
        let node = &data.nodes[i];
        if is_leaf(node) {
            let (mut offset, count) = leaf_blocks(node);
            let grid = LeafGrid::new(node);
            for _ in 0..count {
                let header = data.words[offset];
                let layout = BlockLayout::new(offset, header);
                offset += data.block_words(header);
                let (slo, shi) = grid.strip_box(header);
                let Some((tn, tf)) = ray.interval(slo, shi, fmin(exit, best.t)) else {
                    continue;
                };
                let root = Part {
                    node: 0,
                    t0: 0,
                    m: layout.n,
                };
                if strip_from(data, &layout, root, tn, tf, ray, best, any, strip) && any {
                    return true;
                }
            }
        } else {
            let (a, b) = (i + 1, node.a() as usize);
            let hit_a = ray.box_interval(&data.nodes[a], best.t);
            let hit_b = ray.box_interval(&data.nodes[b], best.t);
            match (hit_a, hit_b) {
                (Some(ia), Some(ib)) => {
                    let ((near, near_i), (far, far_i)) = if ia.0 <= ib.0 {
                        ((a, ia), (b, ib))
                    } else {
                        ((b, ib), (a, ia))
                    };
                    stack[sp] = (far as u32, far_i.0, far_i.1);
                    sp += 1;
                    (i, exit) = (near, near_i.1);
                    continue;
                }
                (Some(ia), None) => {
                    (i, exit) = (a, ia.1);
                    continue;
                }
                (None, Some(ib)) => {
                    (i, exit) = (b, ib.1);
                    continue;
                }
                (None, None) => {}
            }
        }
        loop {
            if sp == 0 {
                return false;
            }
            sp -= 1;
            let (j, tn, tf) = stack[sp];
            if tn <= best.t {
                (i, exit) = (j as usize, fmin(tf, best.t));
                break;
            }
        }
    }
}

/// Algorithm 1 from `part` with interval `[dmin, dmax]`; returns whether a
/// hit was recorded (with `any`, it stops at the first).
#[allow(clippy::too_many_arguments)]
pub(crate) fn strip_from(
    data: &StripData,
    layout: &BlockLayout,
    part: Part,
    dmin: f32,
    dmax: f32,
    ray: &Prepared,
    best: &mut Best,
    any: bool,
    stack: &mut [(Part, f32, f32); STRIP_STACK],
) -> bool {
    let mut sp = 0;
    let mut cur = (part, dmin, dmax);
    let mut hit = false;
    loop {
        let (part, dmin, dmax) = cur;
        let dmax = fmin(dmax, best.t);
        if dmin <= dmax {
            if part.m <= 3 {
                if intersect_leaf(data, layout, part.t0, part.m, ray, best) {
                    hit = true;
                    if any {
                        return true;
                    }
                }
            } else {
                let (axis, lo, hi, [near, far]) =
                    node_children(data, layout, part, |a| ray.forward(a));
                let [n, f] = child_intervals(ray, axis, lo, hi, dmin, dmax);
                match (n, f) {
                    (Some(n), Some(f)) => {
                        stack[sp] = (far, f.0, f.1);
                        sp += 1;
                        cur = (near, n.0, n.1);
                        continue;
                    }
                    (Some(n), None) => {
                        cur = (near, n.0, n.1);
                        continue;
                    }
                    (None, Some(f)) => {
                        cur = (far, f.0, f.1);
                        continue;
                    }
                    (None, None) => {}
                }
            }
        }
        if sp == 0 {
            return hit;
        }
        sp -= 1;
        cur = stack[sp];
    }
}
