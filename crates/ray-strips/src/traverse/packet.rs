//! 2×2 ray packets (paper §5.3): four rays traverse the BVH and the strip
//! hierarchies together, a node being entered when any active ray hits
//! it; when at most [`SINGLE_BELOW`] rays remain active the packet falls
//! back to single-ray traversal of the current subtree for each of them.
//!
//! The packet requires its rays to share the sign of their direction on
//! every axis (the caller checks), so every node orders its children the
//! same way for all four rays (by the split axis of the high-level BVH,
//! where single rays order by entry distance). Every triangle test is the
//! single-ray test with the same per-ray arithmetic, and culling is
//! conservative, so the closest hit (ties to the smaller input index) is
//! bit for bit the single-ray result whatever the visiting order.

use crate::layout::{BlockLayout, LeafGrid, StripData, is_leaf, leaf_blocks};
use crate::traverse::prepared::{Best, Prepared, fmin};
use crate::traverse::single::{
    BVH_STACK, Part, STRIP_STACK, Stacks, child_intervals, node_children, strip_from, trace_from,
};
use crate::traverse::triangle::intersect_leaf;

/// Rays per packet.
pub(crate) const LANES: usize = 4;

/// With this many active rays or fewer, switch to single rays.
pub(crate) const SINGLE_BELOW: u32 = 1;

/// Whether the rays of `mask` can travel as one packet: they share their
/// direction signs (as [`Prepared::forward`] sees them) on all three axes.
pub(crate) fn coherent(rays: &[Prepared; LANES], mask: u8) -> bool {
    let mut lanes = (0..LANES).filter(|l| mask & (1 << l) != 0);
    let Some(first) = lanes.next() else {
        return true;
    };
    lanes.all(|l| (0..3).all(|a| rays[l].forward(a) == rays[first].forward(a)))
}

fn lanes(mask: u8) -> impl Iterator<Item = usize> {
    (0..LANES).filter(move |l| mask & (1 << l) != 0)
}

/// The stacks of packet traversal (and of its single-ray fallbacks),
/// allocated once per batch of packets.
pub(crate) struct PacketStacks {
    bvh: [(u32, u8); BVH_STACK],
    strip: [Entry; STRIP_STACK],
    singles: Stacks,
}

impl PacketStacks {
    /// Empty stacks.
    pub fn new() -> Self {
        let part = Part {
            node: 0,
            t0: 0,
            m: 0,
        };
        Self {
            bvh: [(0, 0); BVH_STACK],
            strip: [(part, 0, [0.0; LANES], [0.0; LANES]); STRIP_STACK],
            singles: Stacks::new(),
        }
    }
}

/// Closest hits of the rays in `mask` (a coherent packet).
pub(crate) fn trace_packet(
    data: &StripData,
    rays: &[Prepared; LANES],
    mask: u8,
    best: &mut [Best; LANES],
    stacks: &mut PacketStacks,
) {
    let Some(lead) = lanes(mask).next() else {
        return;
    };
    let forward = |a: usize| rays[lead].forward(a);
    let PacketStacks {
        bvh: stack,
        strip: strip_stack,
        singles,
    } = stacks;
    stack[0] = (0, mask);
    let mut sp = 1;
    while sp > 0 {
        sp -= 1;
        let (i, mask) = stack[sp];
        let node = &data.nodes[i as usize];
        let mut active = 0u8;
        let mut dmin = [0.0f32; LANES];
        let mut dmax = [0.0f32; LANES];
        for l in lanes(mask) {
            if let Some((tn, tf)) = rays[l].box_interval(node, best[l].t) {
                active |= 1 << l;
                dmin[l] = tn;
                dmax[l] = tf;
            }
        }
        if active == 0 {
            continue;
        }
        if active.count_ones() <= SINGLE_BELOW {
            for l in lanes(active) {
                trace_from(data, i, dmax[l], &rays[l], &mut best[l], false, singles);
            }
            continue;
        }
        if is_leaf(node) {
            let (mut offset, count) = leaf_blocks(node);
            let grid = LeafGrid::new(node);
            for _ in 0..count {
                let header = data.words[offset];
                let layout = BlockLayout::new(offset, header);
                offset += data.block_words(header);
                // Each ray's interval of the strip's own box.
                let (slo, shi) = grid.strip_box(header);
                let (mut entered, mut smin, mut smax) = (0u8, dmin, dmax);
                for l in lanes(active) {
                    let t_max = fmin(dmax[l], best[l].t);
                    if let Some((tn, tf)) = rays[l].interval(slo, shi, t_max) {
                        entered |= 1 << l;
                        smin[l] = tn;
                        smax[l] = tf;
                    }
                }
                if entered == 0 {
                    continue;
                }
                strip_packet(
                    data,
                    &layout,
                    (entered, smin, smax),
                    rays,
                    best,
                    &forward,
                    (strip_stack, singles),
                );
            }
        } else {
            let (first, second) = (i + 1, node.a());
            let (near, far) = if forward(node.b() as usize) {
                (first, second)
            } else {
                (second, first)
            };
            stack[sp] = (far, active);
            stack[sp + 1] = (near, active);
            sp += 2;
        }
    }
}

/// One packet entry of the strip traversal: the part and each ray's
/// interval.
type Entry = (Part, u8, [f32; LANES], [f32; LANES]);

/// Algorithm 1 for a packet over one strip.
#[allow(clippy::too_many_arguments)]
fn strip_packet(
    data: &StripData,
    layout: &BlockLayout,
    (mask, dmin, dmax): (u8, [f32; LANES], [f32; LANES]),
    rays: &[Prepared; LANES],
    best: &mut [Best; LANES],
    forward: &impl Fn(usize) -> bool,
    (stack, singles): (&mut [Entry; STRIP_STACK], &mut Stacks),
) {
    let root = Part {
        node: 0,
        t0: 0,
        m: layout.n,
    };
    let mut sp = 0;
    let mut cur: Entry = (root, mask, dmin, dmax);
    loop {
        let (part, mut mask, dmin, mut dmax) = cur;
        for l in lanes(mask) {
            dmax[l] = fmin(dmax[l], best[l].t);
            if dmin[l] > dmax[l] {
                mask &= !(1 << l);
            }
        }
        if mask != 0 {
            if mask.count_ones() <= SINGLE_BELOW {
                for l in lanes(mask) {
                    strip_from(
                        data,
                        layout,
                        part,
                        dmin[l],
                        dmax[l],
                        &rays[l],
                        &mut best[l],
                        false,
                        &mut singles.strip,
                    );
                }
            } else if part.m <= 3 {
                for l in lanes(mask) {
                    intersect_leaf(data, layout, part.t0, part.m, &rays[l], &mut best[l]);
                }
            } else {
                let (axis, lo, hi, [near, far]) = node_children(data, layout, part, forward);
                let mut near_entry: Entry = (near, 0, [0.0; LANES], [0.0; LANES]);
                let mut far_entry: Entry = (far, 0, [0.0; LANES], [0.0; LANES]);
                for l in lanes(mask) {
                    let [n, f] = child_intervals(&rays[l], axis, lo, hi, dmin[l], dmax[l]);
                    if let Some((a, b)) = n {
                        near_entry.1 |= 1 << l;
                        near_entry.2[l] = a;
                        near_entry.3[l] = b;
                    }
                    if let Some((a, b)) = f {
                        far_entry.1 |= 1 << l;
                        far_entry.2[l] = a;
                        far_entry.3[l] = b;
                    }
                }
                if near_entry.1 != 0 {
                    if far_entry.1 != 0 {
                        stack[sp] = far_entry;
                        sp += 1;
                    }
                    cur = near_entry;
                    continue;
                }
                if far_entry.1 != 0 {
                    cur = far_entry;
                    continue;
                }
            }
        }
        if sp == 0 {
            return;
        }
        sp -= 1;
        cur = stack[sp];
    }
}
