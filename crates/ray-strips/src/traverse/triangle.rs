//! Watertight intersection of a ray with the triangles of a strip leaf
//! (paper §5.2, with Woop, Benthin and Wald's watertight test, JCGT 2013,
//! in place of the paper's Plücker edge tests).
//!
//! Each leaf vertex is moved into ray space once (translate to the origin,
//! permute so the ray runs along `kz`, shear so it becomes the `z` axis).
//! The edge function of a directed edge `P → Q` is
//! `f(P, Q) = Q.x · P.y − Q.y · P.x`; it depends only on the two vertices,
//! and `f(Q, P) = −f(P, Q)` exactly in floating point. As in the paper,
//! edges are shared along the strip: triangle `j = (s_j, s_{j+1},
//! s_{j+2})` uses the "rung" edges `s_j → s_{j+1}` and `s_{j+1} → s_{j+2}`
//! (the second is the first rung of triangle `j + 1`) and the "rail" edge
//! `s_{j+2} → s_j`. Because every triangle sharing an edge sees the same
//! value up to sign, a ray through a shared edge or vertex is inside
//! (all three functions of one sign, zeros counting as either) in at least
//! one of the triangles around it: no leaks. When a function is exactly
//! zero all three are recomputed in `f64`, where the products of `f32`
//! values are exact, as Woop et al. do.
//!
//! Swap slots (copies of a neighbour that let a strip turn) are skipped.
//!
//! A hit replaces the best one when it is closer, or equally close with a
//! smaller input triangle index, so the result does not depend on the order
//! in which triangles are tested.

use crate::layout::{BlockLayout, PERMUTATION_BITS, PERMUTATIONS, SWAP_WORD, StripData};
use crate::traverse::prepared::{Best, Prepared, fmax, fmin};

/// Largest leaf (in triangles) of a strip hierarchy.
const MAX_LEAF: usize = 3;

/// Tests triangles `[t0, t0 + m)` (`m ≤ 3`) of a strip; returns whether
/// `best` changed.
#[inline(always)]
pub(crate) fn intersect_leaf(
    data: &StripData,
    layout: &BlockLayout,
    t0: u32,
    m: u32,
    ray: &Prepared,
    best: &mut Best,
) -> bool {
    debug_assert!(m as usize <= MAX_LEAF);
    // One copy per leaf size, so that the loops unroll and the ray-space
    // vertices stay in registers.
    match m {
        2 => leaf::<2>(data, layout, t0, ray, best),
        3 => leaf::<3>(data, layout, t0, ray, best),
        _ => leaf::<1>(data, layout, t0, ray, best),
    }
}

/// [`intersect_leaf`] for `M` triangles.
#[inline(always)]
fn leaf<const M: usize>(
    data: &StripData,
    layout: &BlockLayout,
    t0: u32,
    ray: &Prepared,
    best: &mut Best,
) -> bool {
    let m = M;
    let [kx, ky, kz] = ray.k;
    let [sx, sy, sz] = ray.shear;
    let [ox, oy, oz] = [ray.org[kx], ray.org[ky], ray.org[kz]];
    let mut x = [0.0f32; MAX_LEAF + 2];
    let mut y = [0.0f32; MAX_LEAF + 2];
    let mut pz = [0.0f32; MAX_LEAF + 2];
    let first = layout.indices + t0 as usize;
    let indices = &data.words[first..first + M + 2];
    for j in 0..M + 2 {
        // The same operations as translating all three coordinates and
        // then permuting: `p[k] = v[k] − org[k]`.
        let v = &data.vertices[indices[j] as usize];
        pz[j] = v[kz] - oz;
        x[j] = (v[kx] - ox) - sx * pz[j];
        y[j] = (v[ky] - oy) - sy * pz[j];
    }
    let edge = |p: usize, q: usize| x[q] * y[p] - y[q] * x[p];
    let edge64 = |p: usize, q: usize| {
        (f64::from(x[q]) * f64::from(y[p]) - f64::from(y[q]) * f64::from(x[p])) as f32
    };
    let mut rung = [0.0f32; MAX_LEAF + 1];
    for (j, r) in rung.iter_mut().enumerate().take(m + 1) {
        *r = edge(j, j + 1);
    }
    let mut changed = false;
    for j in 0..m {
        // U, V, W: weights of A = s_j, B = s_{j+1}, C = s_{j+2}.
        let (mut u, mut v, mut w) = (rung[j + 1], edge(j + 2, j), rung[j]);
        if u == 0.0 || v == 0.0 || w == 0.0 {
            u = edge64(j + 1, j + 2);
            v = edge64(j + 2, j);
            w = edge64(j, j + 1);
        }
        // Mixed signs (some < 0 and some > 0): outside.
        if fmin(fmin(u, v), w) < 0.0 && fmax(fmax(u, v), w) > 0.0 {
            continue;
        }
        let det = u + v + w;
        if det == 0.0 {
            continue;
        }
        // Woop's scaled z, needed only here: `z = Sz · p[kz]`.
        let z = |i: usize| sz * pz[i];
        let t = (u * z(j) + v * z(j + 1) + w * z(j + 2)) / det;
        if !(t >= ray.t_min && t <= best.t) {
            continue;
        }
        let word = data.triangle_word(layout, t0 as usize + j);
        if word == SWAP_WORD || (t == best.t && word >= best.word) {
            continue;
        }
        let weights = [u / det, v / det, w / det];
        let order = PERMUTATIONS[(word & ((1 << PERMUTATION_BITS) - 1)) as usize];
        *best = Best {
            t,
            word,
            u: weights[order[1] as usize],
            v: weights[order[2] as usize],
        };
        changed = true;
    }
    changed
}
