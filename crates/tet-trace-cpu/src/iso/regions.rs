//! Min-max per region for the iso walk: rays that cross no region whose
//! values straddle an isovalue are misses without a walk, and the others
//! may start their walk at the first such region.
//!
//! Most camera rays through a volume never meet its isosurface (about 90 %
//! on the ell32p and blunt stand-ins of Wald et al. 2007): the plain walk crosses
//! the whole volume tet by tet to learn that, where the paper's packets
//! reject them with a few box tests high in the implicit BVH. This tree
//! gives the walk the same rejection at a fraction of the IBVH's memory:
//!
//! * the tets are grouped by the IBVH's BIH build ([`super::ibvh`]) into
//!   leaves of up to [`REGION_TETS`] tets; each node keeps the 4-D bounds
//!   `{x, y, z, v}` of its tets (the IBVH's [`Node`]), about 6 bytes per
//!   tet in all (4 of them the tet order, kept to refit a new time step),
//!   and no primitives: the walk finds the crossing itself;
//! * a tile of rays (the rays of a 16 × 16 pixel tile) descends the tree
//!   once with the packets' interval test ([`super::packet`], §5.2 of the
//!   paper) and the implicit culling of the value range and clip box,
//!   collecting the live leaves the tile's frustum meets;
//! * each run of [`RUN`] consecutive rays keeps the leaves its own interval
//!   meets, nearest first, and each ray gets the first of those boxes its
//!   segment `[t_min, t_max]` enters ([`RegionHit::At`]), or none
//!   ([`RegionHit::None`]: culled). The walk may start at that point
//!   (`walk/skip.rs`).
//!
//! # Why a culled ray is a miss of the walk, and nothing lies before `t`
//!
//! A crossing lies in a tet whose values straddle the isovalue, inside a
//! leaf whose value range then holds it (the range test is the walk's:
//! [`super::IsoQuery::active`]), and at a point the walk computes on the
//! ray within rounding of that tet. Leaf boxes are padded by far more than
//! that rounding (1e-4 of the mesh's diagonal plus 4 ulps of its largest
//! coordinate), so the ray's segment meets the leaf's box, at or after
//! the first live box it enters. The clip box culls only leaves none of
//! whose points it keeps. Culling therefore only removes walks that would
//! end in a miss, and a walk started at the first live box finds the
//! whole walk's crossing (tested ray for ray).

use glam::{Vec3, Vec4};
use tet_core::TetMesh;

use super::ibvh::{BuildKind, Node, tree};
use super::ibvh_trace::node_live;
use super::marching::slab;
use super::packet::Interval;
use super::{IsoQuery, IsoStats};
use crate::ray::Ray;

/// Most tets in a region (a leaf of the tree). Smaller regions cull more
/// rays near the surface and cost more box tests per ray: 16, 32 and 64
/// rendered the four synthetic volumes within 3 % of each other (the
/// README's isosurface figures), and 64 is the smallest tree.
pub const REGION_TETS: usize = 64;

/// Rays that share one interval test per leaf inside a tile (a row of 16
/// pixels of a 16 × 16 tile).
pub const RUN: usize = 16;

/// The min-max tree over regions of tets (module docs).
#[derive(Clone, Debug)]
pub struct RegionTree {
    /// Depth first: an inner node's left child follows it; a leaf's tets
    /// are `order[index..index + count]`.
    nodes: Vec<Node>,
    /// Tet indices, grouped by leaf.
    order: Vec<u32>,
    /// Spatial padding of every box (module docs).
    pad: f32,
    /// Bounds of the mesh's points.
    lo: Vec3,
    hi: Vec3,
    /// [`RegionTree::step_length`].
    step: f32,
}

/// What the regions say of one ray of a tile.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RegionHit {
    /// Its segment meets no live region: a miss.
    None,
    /// Its segment first meets a live region at `t` (so no crossing lies
    /// before `t`), a region holding tet `near`.
    At {
        /// Where the segment enters the region's box.
        t: f32,
        /// A tet of the region.
        near: u32,
    },
    /// Not decided (an invalid ray): walk it whole.
    Walk,
}

impl RegionTree {
    /// The tree over `mesh` (vertex ids already checked) with each tet's
    /// value range `ranges[t] = [min, max]`.
    pub fn new(mesh: &TetMesh, ranges: &[[f32; 2]]) -> RegionTree {
        let (nodes, order) = tree(mesh, BuildKind::Bih, REGION_TETS);
        let (lo, hi) = mesh.point_bounds();
        let (diagonal, largest) = if mesh.points.is_empty() {
            (0.0, 0.0)
        } else {
            ((hi - lo).length(), lo.abs().max(hi.abs()).max_element())
        };
        let pad = 1e-4 * diagonal + 4.0 * f32::EPSILON * largest + f32::MIN_POSITIVE;
        let size = (hi - lo).max(Vec3::ZERO);
        let step = (size.x * size.y * size.z / mesh.tets.len().max(1) as f32).cbrt();
        let mut t = RegionTree {
            nodes,
            order,
            pad,
            lo,
            hi,
            step,
        };
        t.refit(mesh, ranges);
        t
    }

    /// Recomputes every node's bounds for new tet value ranges (a new time
    /// step), the regions kept.
    pub fn refit(&mut self, mesh: &TetMesh, ranges: &[[f32; 2]]) {
        let pad = Vec4::new(self.pad, self.pad, self.pad, 0.0);
        // Children follow their parent, so one pass from the back.
        for i in (0..self.nodes.len()).rev() {
            let n = self.nodes[i];
            let (lo, hi) = if n.is_leaf() {
                let tets = &self.order[n.index as usize..(n.index + n.count) as usize];
                let (lo, hi) =
                    tets.iter()
                        .fold((Vec4::INFINITY, Vec4::NEG_INFINITY), |(lo, hi), &t| {
                            let p = mesh.tet_points(t);
                            let [vlo, vhi] = ranges[t as usize];
                            (
                                lo.min(p[0].min(p[1]).min(p[2].min(p[3])).extend(vlo)),
                                hi.max(p[0].max(p[1]).max(p[2].max(p[3])).extend(vhi)),
                            )
                        });
                (lo - pad, hi + pad)
            } else {
                let (l, r) = (&self.nodes[i + 1], &self.nodes[n.index as usize]);
                (l.lo.min(r.lo), l.hi.max(r.hi))
            };
            self.nodes[i].lo = lo;
            self.nodes[i].hi = hi;
        }
    }

    /// Bytes of the tree (nodes and the tet order).
    pub fn bytes(&self) -> usize {
        std::mem::size_of_val(&self.nodes[..]) + std::mem::size_of_val(&self.order[..])
    }

    /// What the regions say of each ray of a tile ([`RegionHit`]):
    /// `out[i]` for `rays[i]`.
    pub fn first_regions(
        &self,
        rays: &[Ray],
        query: &IsoQuery,
        out: &mut [RegionHit],
        stats: &mut IsoStats,
    ) {
        let n = rays.len().min(out.len());
        out[..n].fill(RegionHit::Walk);
        if self.nodes.is_empty() {
            return;
        }
        let rays = &rays[..n];
        let inv: Vec<Vec3> = rays.iter().map(|r| r.direction.recip()).collect();
        let valid = |range: std::ops::Range<usize>| {
            range
                .filter(|&i| rays[i].is_valid())
                .map(|i| (&rays[i], inv[i]))
        };
        let t_far = |range: std::ops::Range<usize>| {
            valid(range)
                .map(|(r, _)| r.t_max)
                .fold(f32::NEG_INFINITY, f32::max)
        };
        let far = t_far(0..n);
        if far == f32::NEG_INFINITY {
            return;
        }
        // The live leaves the tile's frustum meets.
        let tile = Interval::of(valid(0..n));
        let mut leaves: Vec<&Node> = Vec::new();
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            let nd = &self.nodes[i];
            stats.nodes_visited += 1;
            if !node_live(nd, query) {
                continue;
            }
            stats.box_tests += 1;
            if tile.misses(nd.lo3(), nd.hi3(), far) {
                stats.frustum_culls += 1;
                continue;
            }
            if nd.is_leaf() {
                leaves.push(nd);
            } else {
                stack.push(nd.index as usize);
                stack.push(i + 1);
            }
        }
        // Per run of rays, the leaves its interval meets; per ray, the
        // first of those its segment enters.
        let mut near: Vec<(f32, &Node)> = Vec::with_capacity(leaves.len());
        for start in (0..n).step_by(RUN) {
            let run = start..(start + RUN).min(n);
            let far = t_far(run.clone());
            if far == f32::NEG_INFINITY {
                continue;
            }
            let iv = Interval::of(valid(run.clone()));
            // Nearest first, so that a ray stops at the first leaf that
            // cannot come before the one it found.
            near.clear();
            stats.box_tests += leaves.len() as u64;
            near.extend(
                leaves
                    .iter()
                    .filter_map(|nd| Some((iv.entry(nd.lo3(), nd.hi3(), far)?, *nd))),
            );
            near.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
            for i in run {
                let ray = &rays[i];
                if !ray.is_valid() {
                    continue;
                }
                let mut first = RegionHit::None;
                for &(lower, nd) in &near {
                    if matches!(first, RegionHit::At { t, .. } if t <= lower) {
                        break;
                    }
                    stats.box_tests += 1;
                    let (t0, t1) = slab(ray.origin, inv[i], nd.lo3(), nd.hi3());
                    if t0 <= t1 && t1 >= ray.t_min && t0 <= ray.t_max {
                        let t = t0.max(ray.t_min);
                        if !matches!(first, RegionHit::At { t: best, .. } if best <= t) {
                            first = RegionHit::At {
                                t,
                                near: self.order[nd.index as usize],
                            };
                        }
                    }
                }
                out[i] = first;
            }
        }
    }

    /// The lower and upper corners of the mesh's points.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        (self.lo, self.hi)
    }

    /// About the length of a walk step (the edge of a cube holding one tet's
    /// share of the bounds' volume).
    pub fn step_length(&self) -> f32 {
        self.step
    }
}
