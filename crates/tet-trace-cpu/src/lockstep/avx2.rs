//! The 8-lane lockstep walk in AVX2 intrinsics, with the record words, the
//! new vertices' points and the exit links fetched by gathers; two packs of
//! 8 lanes in flight per thread so that the core overlaps their gather
//! chains.

use std::arch::x86_64::*;

use glam::Vec2;
use tet_core::{Link, TetMesh};

use super::pack::{Geo, Pack, RANK, RANK_XOR, Round, fill};
use crate::ray::{Ray, TraceOutcome};
use crate::walk::lanes::{Feed, Starts};
use crate::walk::projection::{DuffF32, Face2};
use crate::walk::start::Lane;
use crate::walk::stop::{Advance, Stopped};
use crate::walk::stopped::{AfterStop, after_stop};
use crate::walk::topology::RecordWords;

/// [`Pack`] in registers (the hot fields only).
#[derive(Clone, Copy)]
struct V8 {
    o: [__m256; 3],
    c: [[__m256; 2]; 3],
    ids: [__m256i; 3],
    xs: [__m256; 3],
    ys: [__m256; 3],
    next: __m256i,
    entry: __m256i,
    visited: __m256i,
    /// All ones in live lanes.
    live: __m256i,
}

impl V8 {
    fn load(pk: &Pack<8>) -> V8 {
        let f = |a: [f32; 8]| bytemuck::cast::<[f32; 8], __m256>(a);
        let u = |a: [u32; 8]| bytemuck::cast::<[u32; 8], __m256i>(a);
        V8 {
            o: pk.o.map(f),
            c: pk.c.map(|a| a.map(f)),
            ids: pk.ids.map(u),
            xs: pk.xs.map(f),
            ys: pk.ys.map(f),
            next: u(pk.next),
            entry: u(pk.entry),
            visited: u(pk.visited),
            live: u(pk.live.map(|b| if b { u32::MAX } else { 0 })),
        }
    }

    /// Loads scalar lane `lane` into lane `l` (blends of broadcasts: the
    /// other lanes stay in their registers).
    #[target_feature(enable = "avx2")]
    fn put(&mut self, l: usize, lane: &Lane<DuffF32>) {
        let sel = lane_mask(l);
        let self_ps = _mm256_castsi256_ps(sel);
        let f = |x: &mut __m256, v: f32| *x = _mm256_blendv_ps(*x, _mm256_set1_ps(v), self_ps);
        let u =
            |x: &mut __m256i, v: u32| *x = _mm256_blendv_epi8(*x, _mm256_set1_epi32(v as i32), sel);
        let p = lane.proj;
        f(&mut self.o[0], p.o.x);
        f(&mut self.o[1], p.o.y);
        f(&mut self.o[2], p.o.z);
        for (a, col) in [p.cx, p.cy, p.cz].iter().enumerate() {
            f(&mut self.c[a][0], col.x);
            f(&mut self.c[a][1], col.y);
        }
        for s in 0..3 {
            u(&mut self.ids[s], lane.st.ids[s]);
            f(&mut self.xs[s], lane.st.p.xs[s]);
            f(&mut self.ys[s], lane.st.p.ys[s]);
        }
        u(&mut self.next, lane.next);
        u(&mut self.entry, lane.entry_raw);
        u(&mut self.visited, lane.st.visited);
        self.live = _mm256_or_si256(self.live, sel);
    }

    /// Parks lane `l` (tet 0 keeps its loads in range).
    #[target_feature(enable = "avx2")]
    fn park(&mut self, l: usize) {
        let sel = lane_mask(l);
        self.live = _mm256_andnot_si256(sel, self.live);
        self.next = _mm256_andnot_si256(sel, self.next);
    }
}

/// All ones in lane `l`, zeros elsewhere.
#[target_feature(enable = "avx2")]
#[inline]
fn lane_mask(l: usize) -> __m256i {
    _mm256_cmpeq_epi32(
        _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7),
        _mm256_set1_epi32(l as i32),
    )
}

/// Element `l` of `x`.
#[target_feature(enable = "avx2")]
#[inline]
fn lane_u32(x: __m256i, l: usize) -> u32 {
    _mm256_cvtsi256_si32(_mm256_permutevar8x32_epi32(x, _mm256_set1_epi32(l as i32))) as u32
}

/// The cold part of a round in registers (as the AVX-512 walk's): a
/// stopped lane reads only what ending or crossing needs; a crossing
/// rewrites its next tet and entry link. Returns the lanes parked.
#[cold]
#[inline(never)]
#[target_feature(enable = "avx2")]
#[allow(clippy::needless_range_loop)]
fn events8(
    feed: &mut Feed<'_>,
    v: &mut V8,
    ray: &mut [usize; 8],
    events: u32,
    round: &Round<8>,
) -> usize {
    let mut parked = 0;
    for l in 0..8 {
        if events >> l & 1 == 0 {
            continue;
        }
        let u = |x: __m256i| lane_u32(x, l);
        let ids = [u(v.ids[0]), u(v.ids[1]), u(v.ids[2])];
        let (tet, visited, link) = (u(v.next), u(v.visited), round.raw[l]);
        let adv = Advance::stopped(round.capped[l], round.lost[l]);
        let stopped = Stopped {
            adv,
            ids,
            tet,
            visited,
            link,
        };
        match after_stop(feed, ray[l], stopped) {
            AfterStop::Cross(n) => {
                let sel = lane_mask(l);
                v.entry = _mm256_blendv_epi8(v.entry, _mm256_set1_epi32(link as i32), sel);
                v.next = _mm256_blendv_epi8(v.next, _mm256_set1_epi32(n as i32), sel);
            }
            AfterStop::Refill(j, lane) => {
                v.put(l, &lane);
                ray[l] = j;
            }
            AfterStop::Park => {
                v.park(l);
                parked += 1;
            }
        }
    }
    parked
}

#[target_feature(enable = "avx2")]
#[inline]
fn splat(x: i32) -> __m256i {
    _mm256_set1_epi32(x)
}

/// Gathers `words[idx]` per lane.
#[target_feature(enable = "avx2")]
#[inline]
fn gather_words(g: &Geo<'_>, idx: __m256i) -> __m256i {
    // SAFETY: every caller forms `idx = min(next, last_tet) · stride + k`
    // with `0 ≤ k < stride` (checked by `RecordWords::gatherable`), so
    // each lane reads a word inside `g.words`.
    unsafe { _mm256_i32gather_epi32::<4>(g.words.as_ptr() as *const i32, idx) }
}

/// Gathers coordinate `axis` (0..=2) of `points[i]` per lane, `i ≤ last_point`.
#[target_feature(enable = "avx2")]
#[inline]
fn gather_points(g: &Geo<'_>, i3: __m256i, axis: usize) -> __m256 {
    // `Vec3` is `#[repr(C)]` `{x, y, z}`: 3 f32 words per point.
    let base = g.points.as_ptr() as *const f32;
    // SAFETY: `i3 = 3·i` with `i ≤ last_point = points.len() − 1` per
    // lane, so word `i3 + axis` (axis ≤ 2) lies inside `points`;
    // `wrapping_add` only forms the base address.
    unsafe { _mm256_i32gather_ps::<4>(base.wrapping_add(axis), i3) }
}

/// What the cold path needs after a round with events.
struct Cold {
    events: u32,
    round: Round<8>,
}

/// One round of the walk (see the portable walk's `step`, the same decisions).
#[target_feature(enable = "avx2")]
#[inline]
fn step<const RULE: u8>(v: &mut V8, g: &Geo<'_>, cap: u32) -> Option<Cold> {
    let zero = _mm256_setzero_ps();
    let ones = _mm256_set1_epi32(-1);
    // Loads: `VX`, the new vertex `d = idx₀ ⊕ idx₁ ⊕ idx₂ ⊕ VX`, its point.
    let tet = _mm256_min_epu32(v.next, splat(g.last_tet));
    let base = _mm256_mullo_epi32(tet, splat(g.stride));
    let vxw = gather_words(g, _mm256_add_epi32(base, splat(g.vx)));
    let d = _mm256_xor_si256(
        _mm256_xor_si256(v.ids[0], v.ids[1]),
        _mm256_xor_si256(v.ids[2], vxw),
    );
    let dc = _mm256_min_epu32(d, splat(g.last_point));
    let lost = _mm256_xor_si256(_mm256_cmpeq_epi32(dc, d), ones);
    let i3 = _mm256_add_epi32(_mm256_add_epi32(dc, dc), dc);
    let qx = _mm256_sub_ps(gather_points(g, i3, 0), v.o[0]);
    let qy = _mm256_sub_ps(gather_points(g, i3, 1), v.o[1]);
    let qz = _mm256_sub_ps(gather_points(g, i3, 2), v.o[2]);
    // Projection: `(c₀·qₓ + c₁·q_y) + c₂·q_z`, no FMA.
    let proj = |k: usize| {
        _mm256_add_ps(
            _mm256_add_ps(_mm256_mul_ps(v.c[0][k], qx), _mm256_mul_ps(v.c[1][k], qy)),
            _mm256_mul_ps(v.c[2][k], qz),
        )
    };
    let (px, py) = (proj(0), proj(1));
    // `det(p₃, pᵢ) = p₃.x·yᵢ − p₃.y·xᵢ`.
    let det = |k: usize| _mm256_sub_ps(_mm256_mul_ps(px, v.ys[k]), _mm256_mul_ps(py, v.xs[k]));
    let dets = [det(0), det(1), det(2)];
    let mut left = dets.map(|x| _mm256_cmp_ps::<_CMP_GT_OQ>(x, zero));
    let tie = _mm256_or_ps(
        _mm256_or_ps(
            _mm256_cmp_ps::<_CMP_EQ_OQ>(dets[0], zero),
            _mm256_cmp_ps::<_CMP_EQ_OQ>(dets[1], zero),
        ),
        _mm256_cmp_ps::<_CMP_EQ_OQ>(dets[2], zero),
    );
    let tie = _mm256_and_ps(tie, _mm256_castsi256_ps(v.live));
    if _mm256_movemask_ps(tie) != 0 {
        left = ties8(v, d, px, py, tie, left);
    }
    // Exit slot and exiting vertex (`EXIT_SLOT`).
    let s2 = _mm256_castps_si256(_mm256_andnot_ps(left[1], left[0]));
    let s1 = _mm256_castps_si256(_mm256_andnot_ps(left[0], left[2]));
    let s0 = _mm256_xor_si256(_mm256_or_si256(s1, s2), ones);
    let e = _mm256_blendv_epi8(_mm256_blendv_epi8(v.ids[0], v.ids[2], s2), v.ids[1], s1);
    // Exit link. Ids are < 2³¹ (`gatherable`), so signed compares order
    // them; `a > b` is −1, so a sum of compares is minus a count.
    let rank = |x: __m256i, of: [__m256i; 4]| {
        let c = of.map(|y| _mm256_cmpgt_epi32(x, y));
        let n = _mm256_add_epi32(_mm256_add_epi32(c[0], c[1]), _mm256_add_epi32(c[2], c[3]));
        _mm256_min_epu32(_mm256_sub_epi32(_mm256_setzero_si256(), n), splat(3))
    };
    let links = _mm256_add_epi32(base, splat(g.links));
    let link = match RULE {
        RANK => {
            let r = rank(e, [v.ids[0], v.ids[1], v.ids[2], d]);
            gather_words(g, _mm256_add_epi32(links, r))
        }
        RANK_XOR => {
            // `rank(d)` among the entry face (d itself never counts).
            let rd = rank(d, [v.ids[0], v.ids[1], v.ids[2], d]);
            let re = rank(e, [v.ids[0], v.ids[1], v.ids[2], d]);
            let nx = |r: __m256i| {
                let m = _mm256_cmpgt_epi32(splat(3), r);
                let idx = _mm256_and_si256(_mm256_add_epi32(links, r), m);
                // Lanes with rank 3 read word 0 (in range) and drop it.
                _mm256_and_si256(gather_words(g, _mm256_blendv_epi8(base, idx, m)), m)
            };
            _mm256_xor_si256(_mm256_xor_si256(v.entry, nx(rd)), nx(re))
        }
        _ => {
            let ids = _mm256_add_epi32(base, splat(g.ids));
            let vid = |k: i32| gather_words(g, _mm256_add_epi32(ids, splat(k)));
            let mut slot = splat(3);
            for k in (0..3).rev() {
                let hit = _mm256_cmpeq_epi32(e, vid(k));
                slot = _mm256_blendv_epi8(slot, splat(k), hit);
            }
            gather_words(g, _mm256_add_epi32(links, slot))
        }
    };
    // Commit.
    let capped = _mm256_cmpeq_epi32(
        _mm256_min_epu32(v.visited, splat(cap as i32)),
        splat(cap as i32),
    );
    let go = _mm256_andnot_si256(_mm256_or_si256(capped, lost), v.live);
    for (k, s) in [s0, s1, s2].into_iter().enumerate() {
        let sel = _mm256_and_si256(go, s);
        let self_ps = _mm256_castsi256_ps(sel);
        v.ids[k] = _mm256_blendv_epi8(v.ids[k], d, sel);
        v.xs[k] = _mm256_blendv_ps(v.xs[k], px, self_ps);
        v.ys[k] = _mm256_blendv_ps(v.ys[k], py, self_ps);
    }
    v.visited = _mm256_sub_epi32(v.visited, go);
    let boundary = splat(Link::BOUNDARY.0 as i32);
    let is_tet = _mm256_xor_si256(
        _mm256_cmpeq_epi32(_mm256_min_epu32(link, boundary), boundary),
        ones,
    );
    let moving = _mm256_and_si256(go, is_tet);
    v.entry = _mm256_blendv_epi8(v.entry, v.next, moving);
    v.next = _mm256_blendv_epi8(v.next, link, moving);
    let raw = bytemuck::cast::<__m256i, [u32; 8]>(link);
    if PREFETCH {
        for &r in &raw {
            crate::walk::topology::prefetch_index(g.words, r.wrapping_mul(g.stride as u32));
        }
    }
    let events = _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_andnot_si256(moving, v.live)));
    if events == 0 {
        return None;
    }
    let flags = |m: __m256i| bytemuck::cast::<__m256i, [u32; 8]>(m).map(|x| x != 0);
    Some(Cold {
        events: events as u32,
        round: Round {
            raw,
            lost: flags(lost),
            capped: flags(capped),
        },
    })
}

/// Prefetch the next tets' records (see "Tuning" in [`crate::lockstep`]).
const PREFETCH: bool = false;

/// The scalar tie rule for the lanes with a zero determinant (`tie`).
#[target_feature(enable = "avx2")]
#[inline(never)]
#[cold]
fn ties8(
    v: &V8,
    d: __m256i,
    px: __m256,
    py: __m256,
    tie: __m256,
    left: [__m256; 3],
) -> [__m256; 3] {
    let f = |a: __m256| bytemuck::cast::<__m256, [f32; 8]>(a);
    let u = |a: __m256i| bytemuck::cast::<__m256i, [u32; 8]>(a);
    let (xs, ys, ids) = (v.xs.map(f), v.ys.map(f), v.ids.map(u));
    let (d, px, py, tie) = (u(d), f(px), f(py), f(tie));
    let mut left = left.map(f);
    for l in 0..8 {
        if tie[l].to_bits() == 0 {
            continue;
        }
        let pt = |k: usize| Vec2::new(xs[k][l], ys[k][l]);
        let face = Face2::new([pt(0), pt(1), pt(2)]);
        let id = [ids[0][l], ids[1][l], ids[2][l]];
        let m = face.left_mask_ties(Vec2::new(px[l], py[l]), d[l], &id);
        for (k, lk) in left.iter_mut().enumerate() {
            lk[l] = f32::from_bits(if m >> k & 1 != 0 { u32::MAX } else { 0 });
        }
    }
    left.map(bytemuck::cast::<[f32; 8], __m256>)
}

/// The AVX2 lockstep driver with exit rule `RULE`; `rw` must be
/// [`RecordWords::gatherable`] for `mesh.points`.
#[target_feature(enable = "avx2")]
pub(super) fn run_gather<const RULE: u8>(
    mesh: &TetMesh,
    rw: RecordWords<'_>,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
) {
    let g = Geo::new(mesh, &rw);
    let mut feed = Feed::new(mesh, rays, start, out);
    // `GROUPS` independent packs of 8 lanes, stepped in turn: the
    // out-of-order core overlaps their dependent gather chains.
    let mut groups: [(V8, [usize; 8], usize); GROUPS] = std::array::from_fn(|_| {
        let (pk, live) = fill::<8>(&mut feed);
        (V8::load(&pk), pk.ray, live)
    });
    loop {
        let mut any = false;
        for (v, ray, live) in groups.iter_mut() {
            if *live == 0 {
                continue;
            }
            any = true;
            if let Some(c) = step::<RULE>(v, &g, cap) {
                *live -= events8(&mut feed, v, ray, c.events, &c.round);
            }
        }
        if !any {
            break;
        }
    }
}

/// Packs of 8 lanes in flight per thread (see "Tuning" in [`crate::lockstep`]).
const GROUPS: usize = 2;
