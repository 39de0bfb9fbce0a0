//! Greedy stripification of one chunk (paper §4.2; the paper used the
//! Stripe library, here a small self-contained greedy stripifier).
//!
//! A strip is a vertex sequence `s₀ s₁ … s₍ₙ₊₁₎` whose triangle `j` is
//! `{s_j, s_{j+1}, s_{j+2}}`; consecutive triangles share the edge
//! `(s_{j+1}, s_{j+2})`, so a plain strip can only turn left and right in
//! alternation. Where the mesh does not allow that, the strip *swaps*: after
//! `… o p q` it continues across edge `(o, q)` instead of `(p, q)` by
//! repeating `o` (`… o p q o r`). The slot `(p, q, o)` this creates is a
//! copy of the triangle before it, marked [`SWAP`] and never tested; it
//! costs one vertex index and one per-triangle word, far less than the
//! header, two BVH nodes and two extra indices of a new strip. Swaps are
//! optional ([`crate::BuildOptions::strip_swaps`], off by default): with
//! this greedy choice the strips turn along staircases that cut the rest of
//! the chunk into slivers (on a 10 × 10 quad grid: 18 strips with swaps, 10
//! without), and on the bunny they saved no strips (8702 against 8599 at
//! chunks of 128, plus 7264 swap slots), so the bytes grew. Rotations are
//! scored by length less three per swap; requiring a plain step after each
//! swap made it worse still.
//!
//! The algorithm, in the spirit of Stripe's and of the classic SGI
//! stripifier:
//! 1. Start at an unused triangle with the fewest unused neighbours (a
//!    lazy min-heap on the current neighbour count), so dead ends and
//!    borders are consumed first instead of being left as singletons.
//! 2. For each of its three rotations, and likewise for the next
//!    [`START_CANDIDATES`]` − 1` lowest-degree starts, grow the strip
//!    forward across the edge of its last two vertices and backward across
//!    the edge of its first two, each time choosing the unused neighbour
//!    with the fewest unused neighbours; keep the longest (trying four
//!    starts instead of one gave 5 % fewer strips on the bunny).
//!
//! Non-manifold edges (three or more triangles) and duplicate triangles
//! are ordinary candidates; every triangle lands in exactly one strip.
//! Triangles must have three distinct vertex indices (the builder skips the
//! others).

use std::cmp::Reverse;
use std::collections::{BinaryHeap, VecDeque};

/// Start triangles tried per strip (each with its three rotations).
const START_CANDIDATES: usize = 4;

/// Entry of [`Strip::triangles`] for a swap slot.
pub(crate) const SWAP: u32 = u32::MAX;

/// One strip over a chunk's local triangles.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Strip {
    /// The `n + 2` vertex indices.
    pub vertices: Vec<u32>,
    /// The `n` local triangle indices, in strip order ([`SWAP`] for swap
    /// slots).
    pub triangles: Vec<u32>,
}

/// Edge-to-triangle adjacency of one chunk, as a sorted list.
struct Adjacency<'a> {
    triangles: &'a [[u32; 3]],
    /// `(edge key, triangle)` sorted by key.
    edges: Vec<(u64, u32)>,
}

fn key(p: u32, q: u32) -> u64 {
    let (a, b) = if p < q { (p, q) } else { (q, p) };
    (u64::from(a) << 32) | u64::from(b)
}

impl<'a> Adjacency<'a> {
    fn new(triangles: &'a [[u32; 3]]) -> Self {
        let mut edges = Vec::with_capacity(3 * triangles.len());
        for (t, tri) in triangles.iter().enumerate() {
            for e in 0..3 {
                edges.push((key(tri[e], tri[(e + 1) % 3]), t as u32));
            }
        }
        edges.sort_unstable();
        Self { triangles, edges }
    }

    /// Triangles containing edge `{p, q}`.
    fn across(&self, p: u32, q: u32) -> impl Iterator<Item = u32> + '_ {
        let k = key(p, q);
        let start = self.edges.partition_point(|e| e.0 < k);
        self.edges[start..]
            .iter()
            .take_while(move |e| e.0 == k)
            .map(|e| e.1)
    }

    /// Neighbours of `t` over its three edges (with repetition when two
    /// triangles share more than one edge).
    fn neighbours(&self, t: u32) -> impl Iterator<Item = u32> + '_ {
        let tri = self.triangles[t as usize];
        (0..3).flat_map(move |e| {
            self.across(tri[e], tri[(e + 1) % 3])
                .filter(move |&o| o != t)
        })
    }

    /// The vertex of `t` that is neither `p` nor `q`.
    fn third(&self, t: u32, p: u32, q: u32) -> u32 {
        let tri = self.triangles[t as usize];
        *tri.iter()
            .find(|&&v| v != p && v != q)
            .expect("triangle has three distinct vertices")
    }
}

/// Decomposes `triangles` (local vertex indices, three distinct per
/// triangle) into strips covering every triangle exactly once.
pub(crate) fn stripify(triangles: &[[u32; 3]], swaps: bool) -> Vec<Strip> {
    let adj = Adjacency::new(triangles);
    let n = triangles.len();
    let mut used = vec![false; n];
    let mut degree: Vec<u32> = (0..n as u32)
        .map(|t| adj.neighbours(t).count() as u32)
        .collect();
    let mut heap: BinaryHeap<Reverse<(u32, u32)>> = (0..n as u32)
        .map(|t| Reverse((degree[t as usize], t)))
        .collect();
    // Marks for the trial growths: `mark[t] == stamp` means taken.
    let mut mark = vec![0u32; n];
    let mut stamp = 0u32;
    let mut strips = Vec::new();
    while let Some(Reverse((d, first))) = heap.pop() {
        if used[first as usize] || d != degree[first as usize] {
            continue;
        }
        // Up to START_CANDIDATES current lowest-degree starts.
        let mut starts = vec![first];
        while starts.len() < START_CANDIDATES {
            let Some(Reverse((d, t))) = heap.pop() else {
                break;
            };
            if !used[t as usize] && d == degree[t as usize] && !starts.contains(&t) {
                starts.push(t);
            }
        }
        let mut best: Option<(VecDeque<u32>, VecDeque<u32>)> = None;
        for (start, rotation) in starts.iter().flat_map(|&s| (0..3).map(move |r| (s, r))) {
            stamp += 1;
            let grown = grow(
                &adj,
                start,
                rotation,
                (&used, &degree),
                &mut mark,
                stamp,
                swaps,
            );
            if best.as_ref().is_none_or(|b| score(&grown.1) > score(&b.1)) {
                best = Some(grown);
            }
        }
        let (vertices, tris) = best.expect("three rotations tried");
        for &t in &starts {
            heap.push(Reverse((degree[t as usize], t)));
        }
        for &t in tris.iter().filter(|&&t| t != SWAP) {
            used[t as usize] = true;
        }
        for &t in tris.iter().filter(|&&t| t != SWAP) {
            for o in adj.neighbours(t) {
                if !used[o as usize] {
                    degree[o as usize] -= 1;
                    heap.push(Reverse((degree[o as usize], o)));
                }
            }
        }
        strips.push(Strip {
            vertices: vertices.into(),
            triangles: tris.into(),
        });
    }
    strips
}

/// How good a grown strip is: its triangles, less two for each swap slot
/// (a strip that turns at every step cuts the rest of the chunk into
/// slivers).
fn score(tris: &VecDeque<u32>) -> isize {
    let swaps = tris.iter().filter(|&&t| t == SWAP).count() as isize;
    tris.len() as isize - 3 * swaps
}

/// Grows a strip from `start` (its vertices rotated by `rotation`) in both
/// directions over triangles neither used nor marked with `stamp`.
fn grow(
    adj: &Adjacency<'_>,
    start: u32,
    rotation: usize,
    (used, degree): (&[bool], &[u32]),
    mark: &mut [u32],
    stamp: u32,
    swaps: bool,
) -> (VecDeque<u32>, VecDeque<u32>) {
    let tri = adj.triangles[start as usize];
    let mut vertices: VecDeque<u32> = (0..3).map(|k| tri[(rotation + k) % 3]).collect();
    let mut tris = VecDeque::from([start]);
    mark[start as usize] = stamp;
    let next = |p: u32, q: u32, mark: &[u32]| {
        adj.across(p, q)
            .filter(|&o| !used[o as usize] && mark[o as usize] != stamp)
            .min_by_key(|&o| (degree[o as usize], o))
    };
    loop {
        let len = vertices.len();
        let (o, p, q) = (vertices[len - 3], vertices[len - 2], vertices[len - 1]);
        if let Some(t) = next(p, q, mark) {
            mark[t as usize] = stamp;
            vertices.push_back(adj.third(t, p, q));
            tris.push_back(t);
        } else if let Some(t) = next(o, q, mark).filter(|_| swaps) {
            mark[t as usize] = stamp;
            vertices.push_back(o);
            tris.push_back(SWAP);
            vertices.push_back(adj.third(t, o, q));
            tris.push_back(t);
        } else {
            break;
        }
    }
    loop {
        let (p, q, r) = (vertices[0], vertices[1], vertices[2]);
        if let Some(t) = next(p, q, mark) {
            mark[t as usize] = stamp;
            vertices.push_front(adj.third(t, p, q));
            tris.push_front(t);
        } else if let Some(t) = next(r, p, mark).filter(|_| swaps) {
            // `r p q …` becomes `x r p q …` after the swap slot `(r, p, q)`.
            mark[t as usize] = stamp;
            vertices.push_front(r);
            tris.push_front(SWAP);
            vertices.push_front(adj.third(t, r, p));
            tris.push_front(t);
        } else {
            break;
        }
    }
    (vertices, tris)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A regular grid of `w × h` quads, two triangles each.
    fn grid(w: u32, h: u32) -> Vec<[u32; 3]> {
        let mut t = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let v = y * (w + 1) + x;
                t.push([v, v + 1, v + w + 2]);
                t.push([v, v + w + 2, v + w + 1]);
            }
        }
        t
    }

    fn check_cover(tris: &[[u32; 3]], strips: &[Strip]) {
        let mut seen = vec![0; tris.len()];
        for s in strips {
            assert_eq!(s.vertices.len(), s.triangles.len() + 2);
            let set = |j: usize| {
                let mut a = [s.vertices[j], s.vertices[j + 1], s.vertices[j + 2]];
                a.sort();
                a
            };
            for (j, &t) in s.triangles.iter().enumerate() {
                if t == SWAP {
                    let prev = j > 0 && set(j) == set(j - 1);
                    let next = j + 1 < s.triangles.len() && set(j) == set(j + 1);
                    assert!(prev || next, "swap slot {j} repeats a neighbour");
                    continue;
                }
                seen[t as usize] += 1;
                let mut b = tris[t as usize];
                b.sort();
                assert_eq!(set(j), b, "strip triangle {j} is not input triangle {t}");
            }
        }
        assert!(seen.iter().all(|&c| c == 1), "coverage {seen:?}");
    }

    #[test]
    fn a_grid_row_is_one_strip() {
        let tris = grid(10, 1);
        let strips = stripify(&tris, false);
        check_cover(&tris, &strips);
        assert_eq!(strips.len(), 1);
    }

    #[test]
    fn grids_duplicates_and_fans_are_covered_once() {
        let tris = grid(7, 5);
        check_cover(&tris, &stripify(&tris, false));
        check_cover(&tris, &stripify(&tris, true));
        // A fan around vertex 0 (a strip cannot turn around it) plus a
        // duplicate and a non-manifold fin.
        let mut fan: Vec<[u32; 3]> = (1..9).map(|i| [0, i, i + 1]).collect();
        fan.push([0, 1, 2]);
        fan.push([0, 1, 20]);
        check_cover(&fan, &stripify(&fan, false));
        check_cover(&fan, &stripify(&fan, true));
    }

    #[test]
    fn a_fan_is_one_strip_with_swaps() {
        let fan: Vec<[u32; 3]> = (1..9).map(|i| [0, i, i + 1]).collect();
        assert!(stripify(&fan, false).len() > 1);
        let strips = stripify(&fan, true);
        check_cover(&fan, &strips);
        assert_eq!(strips.len(), 1, "{strips:?}");
        assert!(strips[0].triangles.contains(&SWAP));
    }
}
