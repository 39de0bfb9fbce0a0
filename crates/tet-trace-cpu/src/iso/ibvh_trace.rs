//! Single-ray traversal of the implicit BVH (Wald et al. 2007, §5.2): a node is
//! culled when its value range holds no isovalue of the query (implicit
//! culling, tested first: it is the cheapest), when the clip box excludes
//! it, or when the ray misses its box before the nearest crossing found so
//! far; the nearer child is visited first. In a leaf, each tet's own value
//! range is tested, and for each isovalue it straddles its isopolygon is
//! built ([`IsoPolygon::new`]) and intersected.
//!
//! The answer is the nearest accepted crossing by [`IsoHit::before`] (ties
//! broken by tet and isovalue index), whatever order leaves are visited in:
//! the packet traversal ([`super::packet`]) gives the same bits.

use glam::Vec3;

use super::ibvh::{Ibvh, Node};
use super::marching::{IsoPolygon, RayPre};
use super::{IsoHit, IsoQuery, IsoStats, gradient};
use crate::ray::Ray;

/// Relative slack of the occlusion cull: a box entered up to this much
/// beyond the nearest crossing is still visited (rounding of the box
/// test), so every method sees the same candidate crossings.
pub(crate) const CULL_SLACK: f32 = 1e-5;

/// True when a box entered at `t_enter` may still hold a crossing no
/// farther than `best`.
#[inline(always)]
pub(crate) fn may_beat(t_enter: f32, best: Option<&IsoHit>) -> bool {
    best.is_none_or(|b| t_enter <= b.t + CULL_SLACK * b.t.abs())
}

impl Ibvh {
    /// The nearest crossing of `ray` with the isovalues of `query`.
    pub fn trace(&self, ray: &Ray, query: &IsoQuery) -> Option<IsoHit> {
        self.trace_stats(ray, query, &mut IsoStats::default())
    }

    /// [`Ibvh::trace`], counting its work into `stats`.
    pub fn trace_stats(&self, ray: &Ray, query: &IsoQuery, stats: &mut IsoStats) -> Option<IsoHit> {
        self.traverse(ray, query, false, stats)
    }

    /// Shadow ray (any hit): true when some crossing lies in `[t_min,
    /// t_max]` (the traversal stops at the first one found).
    pub fn occluded(&self, ray: &Ray, query: &IsoQuery) -> bool {
        self.traverse(ray, query, true, &mut IsoStats::default())
            .is_some()
    }

    fn traverse(
        &self,
        ray: &Ray,
        query: &IsoQuery,
        any: bool,
        stats: &mut IsoStats,
    ) -> Option<IsoHit> {
        if self.nodes.is_empty() || !ray.is_valid() || query.check().is_err() {
            return None;
        }
        let pre = RayPre::new(ray);
        let mut best: Option<IsoHit> = None;
        let mut stack = [0u32; 64];
        let mut sp = 0;
        let mut node = 0usize;
        loop {
            stats.nodes_visited += 1;
            let n = &self.nodes[node];
            let live = node_live(n, query) && {
                stats.box_tests += 1;
                let (t0, t1) = pre.slab(n.lo3(), n.hi3());
                t0 <= t1 && t1 >= ray.t_min && t0 <= ray.t_max && may_beat(t0, best.as_ref())
            };
            if live {
                if n.is_leaf() {
                    for j in n.index..n.index + n.count {
                        self.leaf_prim(j as usize, &pre, query, &mut best, stats);
                        if any && best.is_some() {
                            return best;
                        }
                    }
                } else {
                    // Nearer child first.
                    let (l, r) = (node + 1, n.index as usize);
                    let cl = self.nodes[l].lo3() + self.nodes[l].hi3();
                    let cr = self.nodes[r].lo3() + self.nodes[r].hi3();
                    let (near, far) = if (cr - cl).dot(ray.direction) >= 0.0 {
                        (l, r)
                    } else {
                        (r, l)
                    };
                    if sp < stack.len() {
                        stack[sp] = far as u32;
                        sp += 1;
                        node = near;
                        continue;
                    }
                    // A stack overflow (depth > 64) cannot happen for
                    // trees of fewer than 2⁶⁴ leaves built here, but stay
                    // correct: visit the far child through recursion.
                    self.subtree(far, &pre, query, &mut best, stats);
                    node = near;
                    continue;
                }
            }
            if sp == 0 {
                return best;
            }
            sp -= 1;
            node = stack[sp] as usize;
        }
    }

    /// Recursive fallback for very deep trees.
    fn subtree(
        &self,
        node: usize,
        pre: &RayPre,
        query: &IsoQuery,
        best: &mut Option<IsoHit>,
        stats: &mut IsoStats,
    ) {
        let n = &self.nodes[node];
        stats.nodes_visited += 1;
        if !node_live(n, query) {
            return;
        }
        let (t0, t1) = pre.slab(n.lo3(), n.hi3());
        if !(t0 <= t1 && t1 >= pre.ray.t_min && t0 <= pre.ray.t_max && may_beat(t0, best.as_ref()))
        {
            return;
        }
        if n.is_leaf() {
            for j in n.index..n.index + n.count {
                self.leaf_prim(j as usize, pre, query, best, stats);
            }
        } else {
            self.subtree(node + 1, pre, query, best, stats);
            self.subtree(n.index as usize, pre, query, best, stats);
        }
    }

    /// Primitive `j`'s vertex ids, positions and values when some isovalue
    /// of `query` lies in its value range (one range test counted), for
    /// the single-ray and the packet leaf alike.
    #[inline]
    pub(crate) fn straddling_prim(
        &self,
        j: usize,
        query: &IsoQuery,
        stats: &mut IsoStats,
    ) -> Option<([u32; 4], [Vec3; 4], [f32; 4])> {
        let ids = self.prims[j];
        let p4 = ids.map(|i| self.points[i as usize]);
        let v = p4.map(|p| p.w);
        stats.range_tests += 1;
        let (lo, hi) = (
            v[0].min(v[1]).min(v[2].min(v[3])),
            v[0].max(v[1]).max(v[2].max(v[3])),
        );
        query
            .active(lo, hi)
            .then(|| (ids, p4.map(|q| q.truncate()), v))
    }

    /// Tests primitive `j` against one ray, keeping the best crossing.
    #[inline]
    pub(crate) fn leaf_prim(
        &self,
        j: usize,
        pre: &RayPre,
        query: &IsoQuery,
        best: &mut Option<IsoHit>,
        stats: &mut IsoStats,
    ) {
        let Some((ids, p, v)) = self.straddling_prim(j, query, stats) else {
            return;
        };
        for (k, &iso) in query.isovalues.iter().enumerate() {
            let Some(poly) = IsoPolygon::new(ids, p, v, iso) else {
                continue;
            };
            stats.isopolygons += 1;
            stats.isopolygon_tests += 1;
            self.offer(j, k, &poly, p, v, pre, query, best);
        }
    }

    /// Intersects one isopolygon of primitive `j` (isovalue `k`) with a ray
    /// and keeps the crossing when it beats `best`.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub(crate) fn offer(
        &self,
        j: usize,
        k: usize,
        poly: &IsoPolygon,
        p: [glam::Vec3; 4],
        v: [f32; 4],
        pre: &RayPre,
        query: &IsoQuery,
        best: &mut Option<IsoHit>,
    ) {
        let Some(t) = poly.intersect(pre) else {
            return;
        };
        if !(t >= pre.ray.t_min && t <= pre.ray.t_max && query.keeps(pre.ray.at(t))) {
            return;
        }
        let tet = self.prim_tet[j];
        let cand = (t, tet, k as u8);
        if best.is_some_and(|b| cand >= (b.t, b.tet, b.isovalue_index)) {
            return;
        }
        *best = Some(IsoHit {
            t,
            tet,
            isovalue_index: k as u8,
            normal: gradient(p, v),
        });
    }
}

/// Implicit culling and clip-box culling of a node.
#[inline(always)]
pub(crate) fn node_live(n: &Node, query: &IsoQuery) -> bool {
    query.active(n.lo.w, n.hi.w) && query.clip.is_none_or(|c| !c.culls_box(n.lo3(), n.hi3()))
}
