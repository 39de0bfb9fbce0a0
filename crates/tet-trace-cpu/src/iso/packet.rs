//! Packet traversal of the implicit BVH (Wald et al. 2007, §5.2): packets of up to
//! [`PACKET`] rays (16 × 16) share one traversal with
//!
//! 1. implicit culling (value range, and clip box) first, once per packet;
//! 2. speculative first-active descent: when the packet's first active ray
//!    hits the node's box, descend without testing the others;
//! 3. otherwise an interval-arithmetic test (Boulos et al., Reshetov et al.:
//!    bounds of the origins and reciprocal directions over the packet)
//!    rejects a node that every ray misses before the largest far bound
//!    (`t_max`, or the nearest crossing so far) of the node's own active
//!    rays;
//! 4. otherwise first-active tracking: the rays before the first one that
//!    hits the box are inactive below this node.
//!
//! In a leaf each tet's range is tested and each isopolygon built once per
//! packet, then intersected with every active ray by the single-ray test.
//!
//! # Same answer as single rays
//!
//! Each ray keeps the nearest crossing by [`IsoHit::before`] among those it
//! tests, with the single-ray tests of [`super::ibvh_trace`]. A ray
//! deactivated at a node misses its (padded) box before its nearest crossing
//! so far, so the node holds no crossing that could win; a node the
//! interval test rejects is missed so by every ray still active in it (the
//! far bound is the maximum over the rays from the node's own first active
//! ray, kept as suffix maxima: a node pushed before a deeper node advanced
//! the first active ray keeps the earlier rays, whose crossings may lie
//! far behind the later rays'); a crossing a ray does test only competes
//! by its `(t, tet, isovalue)` key. The result is
//! bit for bit that of [`Ibvh::trace`] (tested), whatever the visiting order.
//! The paper's frustum culling of isopolygons (corner rays against the
//! polygon's edge half-spaces) is not done: the single-ray test projects per
//! ray, so there is no shared 2-D plane for the corner rays.

use glam::Vec3;

use super::ibvh::Ibvh;
use super::ibvh_trace::{may_beat, node_live};
use super::marching::{IsoPolygon, RayPre};
use super::{IsoHit, IsoQuery, IsoStats};
use crate::ray::Ray;

/// Rays per packet (16 × 16); longer slices are traced in chunks.
pub const PACKET: usize = 256;

/// Interval bounds of a packet's rays.
pub(super) struct Interval {
    o_lo: Vec3,
    o_hi: Vec3,
    inv_lo: Vec3,
    inv_hi: Vec3,
    t_lo: f32,
}

impl Interval {
    /// The bounds of the rays of `pre` that are not `done` (invalid).
    fn new(pre: &[RayPre], done: &[bool]) -> Interval {
        Self::of(
            pre.iter()
                .zip(done)
                .filter(|(_, d)| !**d)
                .map(|(p, _)| (&p.ray, p.inv_d)),
        )
    }

    /// The bounds of rays given with their reciprocal directions.
    pub(super) fn of<'a>(rays: impl IntoIterator<Item = (&'a Ray, Vec3)>) -> Interval {
        let mut iv = Interval {
            o_lo: Vec3::INFINITY,
            o_hi: Vec3::NEG_INFINITY,
            inv_lo: Vec3::INFINITY,
            inv_hi: Vec3::NEG_INFINITY,
            t_lo: f32::INFINITY,
        };
        for (ray, inv_d) in rays {
            iv.o_lo = iv.o_lo.min(ray.origin);
            iv.o_hi = iv.o_hi.max(ray.origin);
            iv.inv_lo = iv.inv_lo.min(inv_d);
            iv.inv_hi = iv.inv_hi.max(inv_d);
            iv.t_lo = iv.t_lo.min(ray.t_min);
        }
        iv
    }

    /// True when every ray of the packet certainly misses the box before
    /// `t_far` (the largest far bound of the active rays).
    pub(super) fn misses(&self, lo: Vec3, hi: Vec3, t_far: f32) -> bool {
        self.entry(lo, hi, t_far).is_none()
    }

    /// A lower bound of where the packet's rays enter the box `[lo, hi]`
    /// before `t_far`, or `None` when every ray certainly misses it.
    pub(super) fn entry(&self, lo: Vec3, hi: Vec3, t_far: f32) -> Option<f32> {
        let mut tn = self.t_lo;
        let mut tf = t_far;
        for a in 0..3 {
            let (il, ih) = (self.inv_lo[a], self.inv_hi[a]);
            // Mixed signs or a zero direction component: no bound.
            if !(il.is_finite() && ih.is_finite()) || (il <= 0.0 && ih >= 0.0) {
                continue;
            }
            let (near, far) = if il > 0.0 {
                (lo[a], hi[a])
            } else {
                (hi[a], lo[a])
            };
            let span = |plane: f32| {
                let (x, y) = (plane - self.o_hi[a], plane - self.o_lo[a]);
                let q = [x * il, x * ih, y * il, y * ih];
                (
                    q[0].min(q[1]).min(q[2].min(q[3])),
                    q[0].max(q[1]).max(q[2].max(q[3])),
                )
            };
            tn = tn.max(span(near).0);
            tf = tf.min(span(far).1);
        }
        // A NaN bound (a zero times an infinite span) culls nothing.
        if tn > tf + 1e-5 * (tn.abs() + tf.abs()) {
            None
        } else {
            Some(tn)
        }
    }
}

/// Per-ray state of a packet.
struct Lanes<'a> {
    pre: Vec<RayPre>,
    best: &'a mut [Option<IsoHit>],
    done: Vec<bool>,
    any: bool,
    /// `far[r]`: the largest far bound (`t_max`, or the nearest crossing
    /// so far plus the cull slack) over the active rays `r..`; negative
    /// infinity when none is active. Stale while `far_stale`.
    far: Vec<f32>,
    /// Some ray's nearest crossing changed since `far` was computed.
    far_stale: bool,
}

impl Lanes<'_> {
    /// The single-ray box test, with this ray's current nearest crossing.
    #[inline(always)]
    fn hits(&self, r: usize, lo: Vec3, hi: Vec3) -> bool {
        if self.done[r] {
            return false;
        }
        let p = &self.pre[r];
        let (t0, t1) = p.slab(lo, hi);
        t0 <= t1 && t1 >= p.ray.t_min && t0 <= p.ray.t_max && may_beat(t0, self.best[r].as_ref())
    }

    /// The largest far bound over the active rays `first..`, recomputing
    /// the suffix maxima [`Lanes::far`] when a leaf changed some ray's
    /// nearest crossing since.
    ///
    /// A node on the stack is culled for its own active rays `first..`,
    /// and nodes pushed before a deeper node advanced `first` keep a
    /// smaller one: the bound of a node must be taken over the rays from
    /// its own `first`, never from the `first` of the leaf that shrank it.
    fn far_from(&mut self, first: usize) -> f32 {
        if self.far_stale {
            self.far_stale = false;
            self.update_far();
        }
        self.far[first]
    }

    /// Recomputes [`Lanes::far`] from the rays' current far bounds.
    fn update_far(&mut self) {
        let mut m = f32::NEG_INFINITY;
        for r in (0..self.pre.len()).rev() {
            if !self.done[r] {
                let t = self.pre[r].ray.t_max;
                let t = self.best[r].map_or(t, |b| {
                    t.min(b.t + super::ibvh_trace::CULL_SLACK * b.t.abs())
                });
                m = m.max(t);
            }
            self.far[r] = m;
        }
    }
}

impl Ibvh {
    /// Traces `rays` (best coherent, e.g. a 16 × 16 pixel tile) in packets of
    /// [`PACKET`]; `out[i]` is [`Ibvh::trace`] of `rays[i]`, bit for bit.
    /// Invalid rays get `None`.
    pub fn trace_packet(&self, rays: &[Ray], query: &IsoQuery, out: &mut [Option<IsoHit>]) {
        self.trace_packet_stats(rays, query, out, &mut IsoStats::default());
    }

    /// [`Ibvh::trace_packet`], counting its work into `stats`.
    pub fn trace_packet_stats(
        &self,
        rays: &[Ray],
        query: &IsoQuery,
        out: &mut [Option<IsoHit>],
        stats: &mut IsoStats,
    ) {
        for (r, o) in rays.chunks(PACKET).zip(out.chunks_mut(PACKET)) {
            self.packet(r, query, o, false, stats);
        }
    }

    /// Shadow packet (any hit): `out[i]` is [`Ibvh::occluded`] of `rays[i]`.
    pub fn occluded_packet(&self, rays: &[Ray], query: &IsoQuery, out: &mut [bool]) {
        let mut hits = vec![None; PACKET.min(rays.len())];
        for (r, o) in rays.chunks(PACKET).zip(out.chunks_mut(PACKET)) {
            let h = &mut hits[..r.len()];
            h.fill(None);
            self.packet(r, query, h, true, &mut IsoStats::default());
            for (x, y) in o.iter_mut().zip(h.iter()) {
                *x = y.is_some();
            }
        }
    }

    fn packet(
        &self,
        rays: &[Ray],
        query: &IsoQuery,
        out: &mut [Option<IsoHit>],
        any: bool,
        stats: &mut IsoStats,
    ) {
        let n = rays.len().min(out.len());
        out[..n].fill(None);
        if self.nodes.is_empty() || query.check().is_err() {
            return;
        }
        // Invalid rays are never active.
        let done: Vec<bool> = rays[..n].iter().map(|r| !r.is_valid()).collect();
        let pre: Vec<RayPre> = rays[..n].iter().map(RayPre::new).collect();
        let Some(start) = done.iter().position(|&d| !d) else {
            return;
        };
        let iv = Interval::new(&pre, &done);
        let mut lanes = Lanes {
            pre,
            best: &mut out[..n],
            done,
            any,
            far: vec![f32::NEG_INFINITY; n],
            far_stale: true,
        };
        let mut stack: Vec<(u32, u32)> = Vec::with_capacity(64);
        stack.push((0, start as u32));
        while let Some((node, first)) = stack.pop() {
            let (node, mut first) = (node as usize, first as usize);
            stats.nodes_visited += 1;
            let nd = &self.nodes[node];
            if !node_live(nd, query) {
                continue;
            }
            let (lo, hi) = (nd.lo3(), nd.hi3());
            stats.box_tests += 1;
            if !lanes.hits(first, lo, hi) {
                // The bound of this node's own active rays `first..`.
                if iv.misses(lo, hi, lanes.far_from(first)) {
                    stats.frustum_culls += 1;
                    continue;
                }
                let found = (first + 1..n).find(|&r| {
                    stats.box_tests += 1;
                    lanes.hits(r, lo, hi)
                });
                match found {
                    Some(r) => first = r,
                    None => continue,
                }
            }
            if nd.is_leaf() {
                if self.packet_leaf(
                    nd.index as usize,
                    nd.count as usize,
                    first,
                    query,
                    &mut lanes,
                    stats,
                ) {
                    lanes.far_stale = true;
                }
                continue;
            }
            let (l, r) = (node + 1, nd.index as usize);
            let cl = self.nodes[l].lo3() + self.nodes[l].hi3();
            let cr = self.nodes[r].lo3() + self.nodes[r].hi3();
            let d = lanes.pre[first].ray.direction;
            let (near, far) = if (cr - cl).dot(d) >= 0.0 {
                (l, r)
            } else {
                (r, l)
            };
            stack.push((far as u32, first as u32));
            stack.push((near as u32, first as u32));
        }
    }

    /// One leaf for rays `first..`; true when some ray's best changed.
    fn packet_leaf(
        &self,
        from: usize,
        count: usize,
        first: usize,
        query: &IsoQuery,
        lanes: &mut Lanes,
        stats: &mut IsoStats,
    ) -> bool {
        let mut changed = false;
        for j in from..from + count {
            let Some((ids, p, v)) = self.straddling_prim(j, query, stats) else {
                continue;
            };
            for (k, &iso) in query.isovalues.iter().enumerate() {
                let Some(poly) = IsoPolygon::new(ids, p, v, iso) else {
                    continue;
                };
                stats.isopolygons += 1;
                for r in first..lanes.pre.len() {
                    if lanes.done[r] {
                        continue;
                    }
                    stats.isopolygon_tests += 1;
                    let before = lanes.best[r];
                    self.offer(j, k, &poly, p, v, &lanes.pre[r], query, &mut lanes.best[r]);
                    if lanes.best[r] != before {
                        changed = true;
                        if lanes.any {
                            lanes.done[r] = true;
                        }
                    }
                }
            }
        }
        changed
    }
}
