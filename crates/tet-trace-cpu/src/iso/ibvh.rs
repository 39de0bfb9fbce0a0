//! The implicit min-max BVH (Wald et al. 2007, §5.1): a BVH over the tets whose
//! nodes bound `{x, y, z, v}` in 4-D, so that traversal culls every subtree
//! whose value range cannot hold the isovalue(s) ([`super::ibvh_trace`]).
//!
//! * Nodes are stored depth first: an inner node's left child follows it,
//!   [`Node::index`] names the right child; a leaf holds [`Node::count`] ≤
//!   [`LEAF_SIZE`] (12, the paper's choice) consecutive primitives from
//!   [`Node::index`].
//! * Builds: BIH-style ([`BuildKind::Bih`], Wächter & Keller's spatial
//!   median: split the node's centroid bounds in the middle of their
//!   longest axis, the count median when that leaves a side empty) and
//!   binned SAH ([`BuildKind::Sah`], 16 bins per axis over the centroids).
//! * The mesh's points and values are kept as 4-D points `(x, y, z, v)`.
//! * Time steps (§6): Schema I builds one IBVH per step
//!   ([`Ibvh::build_per_step`], in parallel); Schema II refits one IBVH
//!   ([`Ibvh::refit`]): subtrees in parallel (rayon), the bounds the same
//!   bits a rebuild of the same tree would give.
//!
//! Spatial bounds are padded by a relative 2⁻¹⁸ so that a ray that hits an
//! isopolygon (computed in f32) always hits the boxes around its tet.

use glam::{Vec3, Vec4};
use rayon::prelude::*;
use tet_core::TetMesh;

use super::{IsoError, check_values};

/// Most tets in a leaf (the paper's 12).
pub const LEAF_SIZE: usize = 12;

/// One node: 4-D bounds and its children or primitives.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Node {
    /// Lower bounds `(x, y, z, v)`; `x, y, z` padded (module docs).
    pub lo: Vec4,
    /// Upper bounds `(x, y, z, v)`.
    pub hi: Vec4,
    /// Inner node: the right child; leaf: the first primitive.
    pub index: u32,
    /// Leaf: its number of primitives (≥ 1); inner node: 0.
    pub count: u32,
}

impl Node {
    /// True for a leaf.
    #[inline(always)]
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
    /// Spatial lower corner.
    #[inline(always)]
    pub fn lo3(&self) -> Vec3 {
        self.lo.truncate()
    }
    /// Spatial upper corner.
    #[inline(always)]
    pub fn hi3(&self) -> Vec3 {
        self.hi.truncate()
    }
}

/// How an [`Ibvh`] is built.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BuildKind {
    /// BIH-style spatial median (fast).
    Bih,
    /// Binned surface area heuristic.
    Sah,
}

/// The implicit min-max BVH over a tet mesh and its point values.
#[derive(Clone, Debug, PartialEq)]
pub struct Ibvh {
    /// Nodes, depth first (root at 0).
    pub nodes: Vec<Node>,
    /// Primitive `j`: vertex ids of tet `prim_tet[j]` (mesh slot order).
    pub prims: Vec<[u32; 4]>,
    /// Primitive `j`'s tet index in the mesh.
    pub prim_tet: Vec<u32>,
    /// Points and values `(x, y, z, v)`.
    pub points: Vec<Vec4>,
    /// How it was built.
    pub kind: BuildKind,
}

/// Per-tet build input: bounds and centroid.
struct Prim {
    lo: Vec3,
    hi: Vec3,
    c: Vec3,
}

impl Ibvh {
    /// BIH-style build (see the module docs).
    pub fn build_bih(mesh: &TetMesh, values: &[f32]) -> Result<Ibvh, IsoError> {
        Self::build(mesh, values, BuildKind::Bih)
    }

    /// Binned SAH build.
    pub fn build_sah(mesh: &TetMesh, values: &[f32]) -> Result<Ibvh, IsoError> {
        Self::build(mesh, values, BuildKind::Sah)
    }

    /// Schema I (§6.1): one IBVH per time step (`steps[s]` = the values of
    /// step `s`), built in parallel.
    pub fn build_per_step(
        mesh: &TetMesh,
        steps: &[&[f32]],
        kind: BuildKind,
    ) -> Result<Vec<Ibvh>, IsoError> {
        steps
            .par_iter()
            .map(|v| Self::build(mesh, v, kind))
            .collect()
    }

    /// Builds over `mesh` with `values` (one per point).
    pub fn build(mesh: &TetMesh, values: &[f32], kind: BuildKind) -> Result<Ibvh, IsoError> {
        check_values(values, mesh.points.len())?;
        let np = mesh.points.len();
        for (t, ids) in mesh.tets.iter().enumerate() {
            if let Some(&i) = ids.iter().find(|&&i| i as usize >= np) {
                return Err(IsoError::BadVertex {
                    tet: t as u32,
                    point: i,
                    points: np,
                });
            }
        }
        let points: Vec<Vec4> = mesh
            .points
            .iter()
            .zip(values)
            .map(|(p, &v)| p.extend(v))
            .collect();
        let (nodes, order) = tree(mesh, kind, LEAF_SIZE);
        let mut bvh = Ibvh {
            nodes,
            prims: order.iter().map(|&t| mesh.tets[t as usize]).collect(),
            prim_tet: order,
            points,
            kind,
        };
        bvh.refit_nodes();
        Ok(bvh)
    }

    /// Schema II (§6.2): new values for the same points; the tree is kept,
    /// every node's bounds recomputed (subtrees in parallel).
    pub fn refit(&mut self, values: &[f32]) -> Result<(), IsoError> {
        check_values(values, self.points.len())?;
        self.points
            .par_iter_mut()
            .zip(values)
            .for_each(|(p, &v)| p.w = v);
        self.refit_nodes();
        Ok(())
    }

    /// Schema II with moving points: new positions and values (same count
    /// as the mesh's points), the tree kept.
    pub fn refit_moved(&mut self, points: &[Vec3], values: &[f32]) -> Result<(), IsoError> {
        check_values(values, self.points.len())?;
        if points.len() != self.points.len() || points.iter().any(|p| !p.is_finite()) {
            return Err(IsoError::ValueCount {
                values: points.len(),
                points: self.points.len(),
            });
        }
        self.points
            .par_iter_mut()
            .zip(points.par_iter().zip(values))
            .for_each(|(q, (p, &v))| *q = p.extend(v));
        self.refit_nodes();
        Ok(())
    }

    fn refit_nodes(&mut self) {
        if self.nodes.is_empty() {
            return;
        }
        let ctx = (&self.prims[..], &self.points[..]);
        refit_rec(&mut self.nodes, 0, ctx, 0);
    }

    /// Bytes of the structure (nodes, primitives, tet indices, 4-D points).
    pub fn bytes(&self) -> usize {
        std::mem::size_of_val(&self.nodes[..])
            + std::mem::size_of_val(&self.prims[..])
            + std::mem::size_of_val(&self.prim_tet[..])
            + std::mem::size_of_val(&self.points[..])
    }

    /// Tree depth (1 for a single leaf; 0 when empty).
    pub fn depth(&self) -> usize {
        fn rec(n: &[Node], i: usize) -> usize {
            if n[i].is_leaf() {
                1
            } else {
                1 + rec(n, i + 1).max(rec(n, n[i].index as usize))
            }
        }
        if self.nodes.is_empty() {
            0
        } else {
            rec(&self.nodes, 0)
        }
    }
}

/// The tree's shape over the tets of `mesh` (of valid vertex ids): nodes
/// depth first with zero bounds, leaves of at most `leaf` tets, and the tet
/// order the leaves index into.
pub(super) fn tree(mesh: &TetMesh, kind: BuildKind, leaf: usize) -> (Vec<Node>, Vec<u32>) {
    let prims: Vec<Prim> = mesh
        .tets
        .par_iter()
        .map(|ids| {
            let p = ids.map(|i| mesh.points[i as usize]);
            let lo = p[0].min(p[1]).min(p[2].min(p[3]));
            let hi = p[0].max(p[1]).max(p[2].max(p[3]));
            Prim {
                lo,
                hi,
                c: (lo + hi) * 0.5,
            }
        })
        .collect();
    let mut order: Vec<u32> = (0..mesh.tets.len() as u32).collect();
    let mut nodes = Vec::with_capacity(2 * mesh.tets.len() / leaf.max(1) + 1);
    if !order.is_empty() {
        build_rec(&prims, &mut order, 0, (kind, leaf.max(1)), &mut nodes);
    }
    (nodes, order)
}

/// Builds the subtree over `order` (primitives from `first`) into `nodes`.
fn build_rec(
    prims: &[Prim],
    order: &mut [u32],
    first: usize,
    (kind, leaf): (BuildKind, usize),
    nodes: &mut Vec<Node>,
) {
    let me = nodes.len();
    nodes.push(Node {
        lo: Vec4::ZERO,
        hi: Vec4::ZERO,
        index: first as u32,
        count: order.len() as u32,
    });
    if order.len() <= leaf {
        return;
    }
    let mid = match kind {
        BuildKind::Bih => split_bih(prims, order),
        BuildKind::Sah => split_sah(prims, order),
    };
    let (l, r) = order.split_at_mut(mid);
    build_rec(prims, l, first, (kind, leaf), nodes);
    let right = nodes.len();
    build_rec(prims, r, first + mid, (kind, leaf), nodes);
    nodes[me].index = right as u32;
    nodes[me].count = 0;
}

fn centroid_bounds(prims: &[Prim], order: &[u32]) -> (Vec3, Vec3) {
    order.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &i| (lo.min(prims[i as usize].c), hi.max(prims[i as usize].c)),
    )
}

/// Count median along `axis` (the fallback of both builds).
fn split_median(prims: &[Prim], order: &mut [u32], axis: usize) -> usize {
    let mid = order.len() / 2;
    order.select_nth_unstable_by(mid, |&a, &b| {
        prims[a as usize].c[axis].total_cmp(&prims[b as usize].c[axis])
    });
    mid
}

fn split_bih(prims: &[Prim], order: &mut [u32]) -> usize {
    let (lo, hi) = centroid_bounds(prims, order);
    let ext = hi - lo;
    let axis = ext.max_position();
    if ext[axis] <= 0.0 {
        return order.len() / 2;
    }
    let plane = lo[axis] + ext[axis] * 0.5;
    let mut i = 0;
    for j in 0..order.len() {
        if prims[order[j] as usize].c[axis] < plane {
            order.swap(i, j);
            i += 1;
        }
    }
    if i == 0 || i == order.len() {
        split_median(prims, order, axis)
    } else {
        i
    }
}

const BINS: usize = 16;

fn area(lo: Vec3, hi: Vec3) -> f32 {
    let e = (hi - lo).max(Vec3::ZERO);
    e.x * e.y + e.y * e.z + e.z * e.x
}

fn split_sah(prims: &[Prim], order: &mut [u32]) -> usize {
    let (clo, chi) = centroid_bounds(prims, order);
    let ext = chi - clo;
    let mut best = (f32::INFINITY, 0usize, 0usize);
    for axis in 0..3 {
        if ext[axis] <= 0.0 {
            continue;
        }
        let scale = BINS as f32 / ext[axis];
        let bin_of = |c: f32| (((c - clo[axis]) * scale) as usize).min(BINS - 1);
        let empty = (
            Vec3::splat(f32::INFINITY),
            Vec3::splat(f32::NEG_INFINITY),
            0usize,
        );
        let mut bins = [empty; BINS];
        for &i in order.iter() {
            let p = &prims[i as usize];
            let b = &mut bins[bin_of(p.c[axis])];
            b.0 = b.0.min(p.lo);
            b.1 = b.1.max(p.hi);
            b.2 += 1;
        }
        // Right-to-left sweep: cost of the right side of each plane.
        let mut right = [(0.0f32, 0usize); BINS];
        let mut acc = empty;
        for k in (1..BINS).rev() {
            acc = (
                acc.0.min(bins[k].0),
                acc.1.max(bins[k].1),
                acc.2 + bins[k].2,
            );
            right[k] = (area(acc.0, acc.1), acc.2);
        }
        let mut acc = empty;
        for k in 0..BINS - 1 {
            acc = (
                acc.0.min(bins[k].0),
                acc.1.max(bins[k].1),
                acc.2 + bins[k].2,
            );
            let (ra, rn) = right[k + 1];
            if acc.2 == 0 || rn == 0 {
                continue;
            }
            let cost = area(acc.0, acc.1) * acc.2 as f32 + ra * rn as f32;
            if cost < best.0 {
                best = (cost, axis, k);
            }
        }
    }
    if !best.0.is_finite() {
        return split_median(prims, order, ext.max_position());
    }
    let (_, axis, k) = best;
    let scale = BINS as f32 / ext[axis];
    let bin_of = |c: f32| (((c - clo[axis]) * scale) as usize).min(BINS - 1);
    let mut i = 0;
    for j in 0..order.len() {
        if bin_of(prims[order[j] as usize].c[axis]) <= k {
            order.swap(i, j);
            i += 1;
        }
    }
    if i == 0 || i == order.len() {
        split_median(prims, order, axis)
    } else {
        i
    }
}

type RefitCtx<'a> = (&'a [[u32; 4]], &'a [Vec4]);

/// Pads spatial bounds by a relative 2⁻¹⁸ (see the module docs).
fn padded(lo: Vec4, hi: Vec4) -> (Vec4, Vec4) {
    let mag = lo.abs().max(hi.abs()) * (1.0 / 262_144.0) + Vec4::splat(1e-30);
    let pad = Vec4::new(mag.x, mag.y, mag.z, 0.0);
    (lo - pad, hi + pad)
}

/// Recomputes the bounds of the subtree rooted at `nodes[0]` (whose global
/// index is `base`); returns them unpadded.
fn refit_rec(nodes: &mut [Node], base: usize, ctx: RefitCtx, depth: u32) -> (Vec4, Vec4) {
    let (head, rest) = nodes.split_first_mut().expect("a subtree has a root");
    let (lo, hi) = if head.is_leaf() {
        let (prims, points) = ctx;
        let range = head.index as usize..(head.index + head.count) as usize;
        prims[range].iter().fold(
            (Vec4::splat(f32::INFINITY), Vec4::splat(f32::NEG_INFINITY)),
            |(lo, hi), ids| {
                let p = ids.map(|i| points[i as usize]);
                (
                    lo.min(p[0].min(p[1]).min(p[2].min(p[3]))),
                    hi.max(p[0].max(p[1]).max(p[2].max(p[3]))),
                )
            },
        )
    } else {
        let right = head.index as usize - base;
        let (l, r) = rest.split_at_mut(right - 1);
        let ((llo, lhi), (rlo, rhi)) = if depth < 10 {
            rayon::join(
                || refit_rec(l, base + 1, ctx, depth + 1),
                || refit_rec(r, base + right, ctx, depth + 1),
            )
        } else {
            (
                refit_rec(l, base + 1, ctx, depth + 1),
                refit_rec(r, base + right, ctx, depth + 1),
            )
        };
        (llo.min(rlo), lhi.max(rhi))
    };
    let (plo, phi) = padded(lo, hi);
    head.lo = plo;
    head.hi = phi;
    (lo, hi)
}
