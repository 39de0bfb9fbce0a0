//! Exact self-intersection detection for triangle scenes.
//!
//! A constrained tetrahedralization needs its input triangles to meet only in
//! shared vertices and shared edges. This module reports every pair of
//! triangles (by input index) that meets anywhere else.
//!
//! * **Broad phase**: a uniform grid over the scene bounds; each triangle is
//!   entered into the cells its bounding box overlaps; a candidate pair is
//!   tested only in the cell holding the lower corner of the overlap of the
//!   two bounding boxes, so each pair is tested once without a hash set.
//! * **Narrow phase**, exact (`orient3d`/`orient2d` from `robust`), on
//!   closed triangles. Vertices are "shared" when their positions are
//!   exactly equal.
//!   - no shared vertex: the triangles meet iff an edge of one meets the
//!     other (closed segment–triangle tests, coplanar case in 2-D);
//!   - one shared vertex `v`, `A = (v, a1, a2)`, `B = (v, b1, b2)`: they meet
//!     beyond `v` iff segment `a1a2` meets `B` or `b1b2` meets `A` (the
//!     common part of the two triangles is star-shaped from `v`, so it
//!     reaches beyond `v` only by crossing an opposite edge);
//!   - a shared edge `uw`, `A = (u, w, a)`, `B = (u, w, b)`: if not coplanar
//!     they meet only along `uw`; if coplanar they overlap iff `a` and `b`
//!     lie on the same side of `uw`;
//!   - three shared vertices: a duplicate.
//! * Exactly degenerate (collinear) triangles are skipped and listed
//!   separately; [`crate::clean`] removes them.
//! * The cells are tested in parallel (rayon); the report is sorted, so it
//!   does not depend on the thread count.

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use robust::{Coord, Coord3D};

/// How two triangles meet.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum IntersectionKind {
    /// Not coplanar, and they meet beyond their shared vertices/edge
    /// (crossing, or touching at a point that is not a shared vertex).
    Transversal,
    /// Coplanar and overlapping beyond their shared part.
    Coplanar,
    /// Same three vertex positions.
    Duplicate,
}

/// A reported pair of triangles, `first < second` (input indices).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct IntersectingPair {
    /// Lower triangle index.
    pub first: u32,
    /// Higher triangle index.
    pub second: u32,
    /// How they meet.
    pub kind: IntersectionKind,
}

/// Result of [`find_self_intersections`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IntersectionReport {
    /// Offending pairs, sorted by `(first, second)`.
    pub pairs: Vec<IntersectingPair>,
    /// Triangles skipped because their vertices are exactly collinear.
    pub degenerate: Vec<u32>,
    /// Number of candidate pairs the broad phase passed to exact tests.
    pub candidates: u64,
}

impl IntersectionReport {
    /// True when no pair intersects.
    pub fn is_clean(&self) -> bool {
        self.pairs.is_empty()
    }
}

fn c3(p: DVec3) -> Coord3D<f64> {
    Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    }
}

/// Exact orientation sign of `d` relative to plane `abc` (−1, 0, +1; the
/// sign convention only needs to be consistent within this module).
///
/// Shewchuk's first, static-bound stage is inlined here (most calls end
/// there); the rest of his adaptive predicate runs only when the rounded
/// determinant is within its error bound.
#[inline]
fn orient(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> i8 {
    // Shewchuk's `o3derrboundA`, with his ε = 2⁻⁵³.
    const EPS: f64 = f64::EPSILON / 2.0;
    const BOUND: f64 = (7.0 + 56.0 * EPS) * EPS;
    let (ad, bd, cd) = (a - d, b - d, c - d);
    let (bc, ca, ab) = (
        bd.y * cd.z - bd.z * cd.y,
        cd.y * ad.z - cd.z * ad.y,
        ad.y * bd.z - ad.z * bd.y,
    );
    let det = ad.x * bc + bd.x * ca + cd.x * ab;
    let permanent = ((bd.y * cd.z).abs() + (bd.z * cd.y).abs()) * ad.x.abs()
        + ((cd.y * ad.z).abs() + (cd.z * ad.y).abs()) * bd.x.abs()
        + ((ad.y * bd.z).abs() + (ad.z * bd.y).abs()) * cd.x.abs();
    let bound = BOUND * permanent;
    if det > bound {
        return 1;
    }
    if -det > bound {
        return -1;
    }
    let o = robust::orient3d(c3(a), c3(b), c3(c), c3(d));
    (o > 0.0) as i8 - (o < 0.0) as i8
}

type P2 = (f64, f64);

fn orient2(a: P2, b: P2, c: P2) -> i8 {
    let o = robust::orient2d(
        Coord { x: a.0, y: a.1 },
        Coord { x: b.0, y: b.1 },
        Coord { x: c.0, y: c.1 },
    );
    (o > 0.0) as i8 - (o < 0.0) as i8
}

/// Drop the coordinate `axis` (0 = x, 1 = y, 2 = z).
fn project(p: DVec3, axis: usize) -> P2 {
    match axis {
        0 => (p.y, p.z),
        1 => (p.z, p.x),
        _ => (p.x, p.y),
    }
}

/// A projection axis along which triangle `t` stays non-degenerate.
fn projection_axis(t: &[DVec3; 3]) -> Option<usize> {
    (0..3)
        .rev()
        .find(|&ax| orient2(project(t[0], ax), project(t[1], ax), project(t[2], ax)) != 0)
}

/// Exact 3-D collinearity of three points.
fn degenerate(t: &[DVec3; 3]) -> bool {
    projection_axis(t).is_none()
}

fn on_segment_2d(p: P2, a: P2, b: P2) -> bool {
    // p collinear with ab assumed.
    p.0 >= a.0.min(b.0) && p.0 <= a.0.max(b.0) && p.1 >= a.1.min(b.1) && p.1 <= a.1.max(b.1)
}

/// Closed 2-D segment–segment intersection.
fn segments_meet_2d(p: P2, q: P2, a: P2, b: P2) -> bool {
    let o1 = orient2(p, q, a);
    let o2 = orient2(p, q, b);
    let o3 = orient2(a, b, p);
    let o4 = orient2(a, b, q);
    if o1 * o2 < 0 && o3 * o4 < 0 {
        return true;
    }
    (o1 == 0 && on_segment_2d(a, p, q))
        || (o2 == 0 && on_segment_2d(b, p, q))
        || (o3 == 0 && on_segment_2d(p, a, b))
        || (o4 == 0 && on_segment_2d(q, a, b))
}

/// Closed 2-D point-in-triangle (triangle non-degenerate).
fn point_in_triangle_2d(p: P2, a: P2, b: P2, c: P2) -> bool {
    let s = orient2(a, b, c);
    orient2(a, b, p) * s >= 0 && orient2(b, c, p) * s >= 0 && orient2(c, a, p) * s >= 0
}

/// Closed segment `pq` against closed non-degenerate triangle `t`, exact.
fn segment_meets_triangle(p: DVec3, q: DVec3, t: &[DVec3; 3], axis: usize) -> bool {
    let [a, b, c] = *t;
    let op = orient(a, b, c, p);
    let oq = orient(a, b, c, q);
    if op * oq > 0 {
        return false;
    }
    if op == 0 && oq == 0 {
        // Coplanar: 2-D test in a projection where the triangle is non-degenerate.
        let (p2, q2) = (project(p, axis), project(q, axis));
        let (a2, b2, c2) = (project(a, axis), project(b, axis), project(c, axis));
        return point_in_triangle_2d(p2, a2, b2, c2)
            || point_in_triangle_2d(q2, a2, b2, c2)
            || segments_meet_2d(p2, q2, a2, b2)
            || segments_meet_2d(p2, q2, b2, c2)
            || segments_meet_2d(p2, q2, c2, a2);
    }
    // The line pq crosses the plane at one point inside [p, q]; it lies in
    // the closed triangle iff the line does not pass strictly outside any edge.
    let s1 = orient(p, q, a, b);
    let s2 = orient(p, q, b, c);
    let s3 = orient(p, q, c, a);
    !((s1 > 0 || s2 > 0 || s3 > 0) && (s1 < 0 || s2 < 0 || s3 < 0))
}

/// Do closed triangles `a` and `b` (no shared vertex) meet?
fn triangles_meet(a: &[DVec3; 3], ax: usize, b: &[DVec3; 3], bx: usize) -> bool {
    // Quick plane separation tests.
    let sb: [i8; 3] = std::array::from_fn(|i| orient(a[0], a[1], a[2], b[i]));
    if (sb[0] > 0 && sb[1] > 0 && sb[2] > 0) || (sb[0] < 0 && sb[1] < 0 && sb[2] < 0) {
        return false;
    }
    let sa: [i8; 3] = std::array::from_fn(|i| orient(b[0], b[1], b[2], a[i]));
    if (sa[0] > 0 && sa[1] > 0 && sa[2] > 0) || (sa[0] < 0 && sa[1] < 0 && sa[2] < 0) {
        return false;
    }
    (0..3).any(|i| segment_meets_triangle(a[i], a[(i + 1) % 3], b, bx))
        || (0..3).any(|i| segment_meets_triangle(b[i], b[(i + 1) % 3], a, ax))
}

fn coplanar(a: &[DVec3; 3], b: &[DVec3; 3]) -> bool {
    (0..3).all(|i| orient(a[0], a[1], a[2], b[i]) == 0)
}

/// Exact test of one pair: `None` when they meet only in shared vertices or
/// a shared edge (or not at all). Both triangles must be non-degenerate.
pub fn classify_pair(a: [Vec3; 3], b: [Vec3; 3]) -> Option<IntersectionKind> {
    let a = a.map(|p| p.as_dvec3());
    let b = b.map(|p| p.as_dvec3());
    let (ax, bx) = (projection_axis(&a)?, projection_axis(&b)?);
    classify(&a, ax, &b, bx)
}

fn classify(a: &[DVec3; 3], ax: usize, b: &[DVec3; 3], bx: usize) -> Option<IntersectionKind> {
    // Shared corners: (slot in a, slot in b).
    let mut shared = [(0usize, 0usize); 3];
    let mut n = 0;
    for (i, pa) in a.iter().enumerate() {
        for (j, pb) in b.iter().enumerate() {
            if pa == pb {
                if n < 3 {
                    shared[n] = (i, j);
                }
                n += 1;
            }
        }
    }
    let kind = || {
        if coplanar(a, b) {
            IntersectionKind::Coplanar
        } else {
            IntersectionKind::Transversal
        }
    };
    match n {
        0 => triangles_meet(a, ax, b, bx).then(kind),
        1 => {
            let (i, j) = shared[0];
            let (a1, a2) = (a[(i + 1) % 3], a[(i + 2) % 3]);
            let (b1, b2) = (b[(j + 1) % 3], b[(j + 2) % 3]);
            (segment_meets_triangle(a1, a2, b, bx) || segment_meets_triangle(b1, b2, a, ax))
                .then(kind)
        }
        2 => {
            let (i0, j0) = shared[0];
            let (i1, _) = shared[1];
            let ia = 3 - i0 - i1;
            let jb = (0..3)
                .find(|&j| a[i0] != b[j] && a[i1] != b[j])
                .unwrap_or(j0);
            let (u, w, pa, pb) = (a[i0], a[i1], a[ia], b[jb]);
            if orient(u, w, pa, pb) != 0 {
                return None; // planes meet only along the shared edge
            }
            let (u2, w2) = (project(u, ax), project(w, ax));
            let sa = orient2(u2, w2, project(pa, ax));
            let sb = orient2(u2, w2, project(pb, ax));
            (sa * sb > 0).then_some(IntersectionKind::Coplanar)
        }
        _ => Some(IntersectionKind::Duplicate),
    }
}

/// A triangle in one cell of the broad phase's grid.
#[derive(Clone, Copy)]
struct Entry {
    triangle: u32,
    /// Its box.
    lo: [f32; 3],
    hi: [f32; 3],
    /// Its lowest cell.
    cell: [u32; 3],
}

/// Entries of the broad phase's grid held at once: at most this many
/// (about 40 MiB of entries) or a sixteenth of all, whichever is more (so
/// that the triangles are gone through at most about 16 times), or one z
/// layer where a layer alone holds more.
const SLAB_ENTRIES: u64 = 1 << 20;

/// Consecutive runs `[z0, z1)` of z layers, each with at most
/// [`SLAB_ENTRIES`] entries or a sixteenth of the total (a layer above it
/// alone), from the entries per layer.
fn grid_slabs(layers: &[u64], slab_entries: u64) -> Vec<(usize, usize)> {
    let budget = slab_entries.max(layers.iter().sum::<u64>().div_ceil(16));
    let mut slabs = Vec::new();
    let (mut start, mut sum) = (0, 0u64);
    for (z, &n) in layers.iter().enumerate() {
        if z > start && sum + n > budget {
            slabs.push((start, z));
            (start, sum) = (z, 0);
        }
        sum += n;
    }
    slabs.push((start, layers.len()));
    slabs
}

/// Find all pairs of triangles that meet beyond shared vertices/edges.
///
/// Indices out of range or non-finite coordinates make the affected
/// triangles count as degenerate (run [`crate::clean::clean`] first for
/// typed errors).
pub fn find_self_intersections(vertices: &[Vec3], triangles: &[[u32; 3]]) -> IntersectionReport {
    find_self_intersections_in_slabs(vertices, triangles, SLAB_ENTRIES)
}

/// [`find_self_intersections`] with the grid's slabs holding at most
/// `slab_entries` entries (or a sixteenth of all).
fn find_self_intersections_in_slabs(
    vertices: &[Vec3],
    triangles: &[[u32; 3]],
    slab_entries: u64,
) -> IntersectionReport {
    let mut report = IntersectionReport::default();
    let n = triangles.len();
    // Per triangle one byte and one index: the f64 corners and boxes are
    // made again where they are needed (f32 to f64 is exact), so that a
    // scene of millions of triangles is checked in little more memory
    // than the grid's entries.
    let mut axes: Vec<u8> = Vec::with_capacity(n);
    let mut live: Vec<u32> = Vec::with_capacity(n);
    for (t, tri) in triangles.iter().enumerate() {
        let ok = tri
            .iter()
            .all(|&v| (v as usize) < vertices.len() && vertices[v as usize].is_finite());
        let axis = if ok {
            projection_axis(&tri.map(|v| vertices[v as usize].as_dvec3()))
        } else {
            None
        };
        match axis {
            Some(ax) => {
                axes.push(ax as u8);
                live.push(t as u32);
            }
            None => {
                axes.push(u8::MAX);
                report.degenerate.push(t as u32);
            }
        }
    }
    if live.len() < 2 {
        return report;
    }
    // Only for live triangles (their indices are in range).
    let corners = |t: usize| triangles[t].map(|v| vertices[v as usize].as_dvec3());
    let bb = |t: usize| {
        let [a, b, c] = corners(t);
        (a.min(b).min(c), a.max(b).max(c))
    };
    let (mut lo, mut hi) = bb(live[0] as usize);
    let mut mean_extent = 0.0;
    for &t in &live {
        let (l, h) = bb(t as usize);
        lo = lo.min(l);
        hi = hi.max(h);
        mean_extent += (h - l).max_element();
    }
    mean_extent /= live.len() as f64;
    let extent = (hi - lo).max(DVec3::splat(1e-30));
    // Cell size: about twice the mean triangle size, capped at ~4 cells per triangle.
    let mut cell = (2.0 * mean_extent).max(extent.max_element() * 1e-6);
    let max_cells = (4 * live.len()).max(64) as f64;
    while (extent / cell).ceil().element_product() > max_cells {
        cell *= 1.25;
    }
    // Large triangles cover many cells; coarsen until the (cell, triangle)
    // entry count stays linear in the input.
    let max_entries = 32 * live.len() + (1 << 16);
    let (nx, ny, nz, cell) = loop {
        let dims = (extent / cell).ceil().max(DVec3::ONE);
        let (nx, ny, nz) = (dims.x as usize, dims.y as usize, dims.z as usize);
        let index = |v: f64, n: usize| ((v.max(0.0) as usize).min(n - 1)) as u64;
        let mut total = 0u64;
        for &t in &live {
            let (l, h) = bb(t as usize);
            let (cl, ch) = (((l - lo) / cell).floor(), ((h - lo) / cell).floor());
            total += (index(ch.x, nx) - index(cl.x, nx) + 1)
                * (index(ch.y, ny) - index(cl.y, ny) + 1)
                * (index(ch.z, nz) - index(cl.z, nz) + 1);
        }
        if total <= max_entries as u64 || nx * ny * nz == 1 {
            break (nx, ny, nz, cell);
        }
        cell *= 2.0;
    };
    let cell_of = |p: DVec3| -> [usize; 3] {
        let c = ((p - lo) / cell).floor();
        [
            (c.x.max(0.0) as usize).min(nx - 1),
            (c.y.max(0.0) as usize).min(ny - 1),
            (c.z.max(0.0) as usize).min(nz - 1),
        ]
    };
    // Each entry carries its triangle's box (exact: the corners are f32)
    // and lowest cell, so that a cell's pairs are tested from contiguous
    // memory.
    let entry_of = |t: u32| {
        let (l, h) = bb(t as usize);
        let (cl, ch) = (cell_of(l), cell_of(h));
        let entry = Entry {
            triangle: t,
            lo: l.as_vec3().to_array(),
            hi: h.as_vec3().to_array(),
            cell: cl.map(|i| i as u32),
        };
        (entry, cl, ch)
    };
    // The grid is filled and tested a slab of z layers at a time
    // ([`grid_slabs`]): a cell's list is whole within its slab and a pair
    // is tested only in one cell, so the result is the same as one pass
    // over the whole grid, in a fraction of its memory (the whole grid's
    // entries took 80 to 110 bytes per triangle, the planner's peak on
    // scenes of millions of triangles).
    let mut layers = vec![0u64; nz];
    for &t in &live {
        let (_, cl, ch) = entry_of(t);
        let columns = ((ch[0] - cl[0] + 1) * (ch[1] - cl[1] + 1)) as u64;
        for n in &mut layers[cl[2]..=ch[2]] {
            *n += columns;
        }
    }
    let (mut candidates, mut pairs) = (0u64, Vec::new());
    for (z0, z1) in grid_slabs(&layers, slab_entries) {
        // Counting sort of the slab's (cell, triangle) entries.
        let ncells = nx * ny * (z1 - z0);
        let mut counts = vec![0u32; ncells + 1];
        // Calls `f` with every cell of the slab that triangle `t` covers.
        let cells = |t: u32, f: &mut dyn FnMut(usize, &Entry)| {
            let (entry, cl, ch) = entry_of(t);
            for z in cl[2].max(z0)..=ch[2].min(z1 - 1) {
                for y in cl[1]..=ch[1] {
                    for x in cl[0]..=ch[0] {
                        f(((z - z0) * ny + y) * nx + x, &entry);
                    }
                }
            }
        };
        for &t in &live {
            cells(t, &mut |c, _| counts[c + 1] += 1);
        }
        for i in 0..ncells {
            counts[i + 1] += counts[i];
        }
        let mut fill = counts.clone();
        let total = counts[ncells] as usize;
        let mut entries = vec![
            Entry {
                triangle: 0,
                lo: [0.0; 3],
                hi: [0.0; 3],
                cell: [0; 3],
            };
            total
        ];
        for &t in &live {
            cells(t, &mut |c, entry| {
                entries[fill[c] as usize] = *entry;
                fill[c] += 1;
            });
        }
        drop(fill);
        // Every cell's pairs, in parallel (cells are independent).
        let (c, p) = (0..ncells)
            .into_par_iter()
            .fold(
                || (0u64, Vec::new()),
                |(mut candidates, mut pairs), c| {
                    let cell_xyz = [c % nx, c / nx % ny, z0 + c / (nx * ny)].map(|i| i as u32);
                    let list = &entries[counts[c] as usize..counts[c + 1] as usize];
                    for (i, s) in list.iter().enumerate() {
                        for t in &list[i + 1..] {
                            if (0..3).any(|k| s.lo[k] > t.hi[k] || t.lo[k] > s.hi[k]) {
                                continue;
                            }
                            // Test the pair only in the cell of the overlap's
                            // lower corner (`cell_of` is monotonic, so that is
                            // the larger of the two lowest cells per axis).
                            if (0..3).any(|k| s.cell[k].max(t.cell[k]) != cell_xyz[k]) {
                                continue;
                            }
                            candidates += 1;
                            let (s, t) = (s.triangle, t.triangle);
                            let (a, b) = (s.min(t) as usize, s.max(t) as usize);
                            if let Some(kind) = classify(
                                &corners(a),
                                axes[a] as usize,
                                &corners(b),
                                axes[b] as usize,
                            ) {
                                pairs.push(IntersectingPair {
                                    first: a as u32,
                                    second: b as u32,
                                    kind,
                                });
                            }
                        }
                    }
                    (candidates, pairs)
                },
            )
            .reduce(
                || (0u64, Vec::new()),
                |(ca, mut pa), (cb, pb)| {
                    pa.extend(pb);
                    (ca + cb, pa)
                },
            );
        candidates += c;
        pairs.extend(p);
    }
    report.candidates = candidates;
    report.pairs = pairs;
    report.pairs.sort_unstable_by_key(|p| (p.first, p.second));
    report
}

/// Brute-force O(n²) reference of [`find_self_intersections`] (for tests).
pub fn find_self_intersections_brute_force(
    vertices: &[Vec3],
    triangles: &[[u32; 3]],
) -> Vec<IntersectingPair> {
    let pts: Vec<[DVec3; 3]> = triangles
        .iter()
        .map(|t| t.map(|v| vertices[v as usize].as_dvec3()))
        .collect();
    let mut out = Vec::new();
    for i in 0..pts.len() {
        if degenerate(&pts[i]) {
            continue;
        }
        for j in i + 1..pts.len() {
            if degenerate(&pts[j]) {
                continue;
            }
            let (ai, aj) = (projection_axis(&pts[i]), projection_axis(&pts[j]));
            if let (Some(ai), Some(aj)) = (ai, aj)
                && let Some(kind) = classify(&pts[i], ai, &pts[j], aj)
            {
                out.push(IntersectingPair {
                    first: i as u32,
                    second: j as u32,
                    kind,
                });
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Uniform numbers in [0, 1) from a xorshift generator seeded `state`.
    fn uniform(mut state: u64) -> impl FnMut() -> f64 {
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// The slabs cover the layers in order, each within the budget (a
    /// sixteenth of all entries at least) or a single layer.
    #[test]
    fn grid_slabs_partition_the_layers_within_the_budget() {
        let layers: Vec<u64> = (0..200u64)
            .map(|z| (z * 7919) % 97 + (z % 13 == 0) as u64 * 500)
            .collect();
        for min in [1u64, 50, 300, 1 << 20] {
            let slabs = grid_slabs(&layers, min);
            let budget = min.max(layers.iter().sum::<u64>().div_ceil(16));
            assert_eq!(slabs.first().unwrap().0, 0);
            assert_eq!(slabs.last().unwrap().1, layers.len());
            for w in slabs.windows(2) {
                assert_eq!(w[0].1, w[1].0);
            }
            for &(a, b) in &slabs {
                let sum: u64 = layers[a..b].iter().sum();
                assert!(
                    b > a && (sum <= budget || b == a + 1),
                    "{a}..{b}: {sum} > {budget}"
                );
            }
            if min == 1 {
                assert!(slabs.len() >= 16, "{} slabs", slabs.len());
            }
        }
    }

    /// The grid a slab at a time (as small as one z layer, as on a scene
    /// of millions of triangles) finds the pairs and candidates the whole
    /// grid finds, and the pairs a look at every pair finds: random
    /// triangles of many sizes in a box, with shared vertices, crossing
    /// each other and the layers.
    #[test]
    fn slabs_of_the_grid_find_what_the_whole_grid_finds() {
        let mut rnd = uniform(0x9E37_79B9_7F4A_7C15);
        for round in 0..20 {
            let n = 30 + round * 10;
            let vertices: Vec<Vec3> = (0..n)
                .map(|_| Vec3::new(rnd() as f32, rnd() as f32, (rnd() * 4.0) as f32))
                .collect();
            let triangles: Vec<[u32; 3]> = (0..n)
                .map(|_| {
                    let a = (rnd() * n as f64) as u32 % n as u32;
                    // Mostly small triangles (near neighbours in index order
                    // are not near in space, so pick by distance).
                    let mut near: Vec<u32> = (0..n as u32).filter(|&b| b != a).collect();
                    near.sort_by(|&x, &y| {
                        let d = |v: u32| vertices[v as usize].distance(vertices[a as usize]);
                        d(x).total_cmp(&d(y))
                    });
                    let k = if rnd() < 0.8 { 6 } else { n - 1 };
                    let b = near[(rnd() * k as f64) as usize % k];
                    let c = near[(rnd() * k as f64) as usize % k];
                    [a, b, c]
                })
                .collect();
            let whole = find_self_intersections_in_slabs(&vertices, &triangles, u64::MAX);
            let slabs = find_self_intersections_in_slabs(&vertices, &triangles, 1);
            assert_eq!(slabs.pairs, whole.pairs, "round {round}");
            assert_eq!(slabs.candidates, whole.candidates, "round {round}");
            assert_eq!(slabs.degenerate, whole.degenerate, "round {round}");
            let mut brute = find_self_intersections_brute_force(&vertices, &triangles);
            brute.sort_unstable_by_key(|p| (p.first, p.second));
            assert_eq!(whole.pairs, brute, "round {round}");
        }
    }

    /// The inlined filter gives robust's exact sign on random points and on
    /// points on, or a few ulps off, a plane (where the filter must defer).
    #[test]
    fn filtered_orientation_matches_the_exact_predicate() {
        let mut uniform = uniform(0x2545_F491_4F6C_DD1D);
        let mut rnd = || uniform() - 0.5;
        let mut deferred = 0;
        for i in 0..20_000 {
            let mut p: [DVec3; 4] =
                std::array::from_fn(|_| DVec3::new(rnd(), rnd(), rnd()) * 10f64.powi((i % 7) - 3));
            if i % 4 == 2 {
                // Exactly coplanar (a plane z = const), one point possibly
                // an ulp off it.
                let z = p[0].z as f32;
                for v in &mut p {
                    v.z = f64::from(z);
                }
                let nudge = (i % 3) as f32 - 1.0;
                p[3].z = f64::from(z + nudge * f32::EPSILON * z.abs());
            } else if i % 2 == 1 {
                // d on the plane of a, b, c (up to rounding), then nudged
                // by a few ulps, as f32 coordinates are.
                let (s, t) = (rnd(), rnd());
                let q = p[0] + s * (p[1] - p[0]) + t * (p[2] - p[0]);
                let nudge = (i % 5) as f32 - 2.0;
                p[3] = q.as_vec3().as_dvec3();
                p[3].z = f64::from((p[3].z as f32) + nudge * f32::EPSILON * (p[3].z as f32).abs());
                for v in &mut p {
                    *v = v.as_vec3().as_dvec3();
                }
            }
            let exact = robust::orient3d(c3(p[0]), c3(p[1]), c3(p[2]), c3(p[3]));
            let expected = (exact > 0.0) as i8 - (exact < 0.0) as i8;
            assert_eq!(orient(p[0], p[1], p[2], p[3]), expected, "{p:?}");
            deferred += usize::from(expected == 0);
        }
        assert!(deferred > 0, "no point exactly on a plane was tested");
    }
}
