//! The 16-lane lockstep walk in AVX-512 intrinsics: the AVX2 walk of
//! [`super::avx2`] with 512-bit vectors and mask registers (same decisions,
//! lane by lane the same IEEE operations), two packs of 16 lanes in flight
//! per thread. Its lane reads and gathers serve the ScTP walk too
//! ([`super::sctp`]).

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
struct V16 {
    o: [__m512; 3],
    c: [[__m512; 2]; 3],
    ids: [__m512i; 3],
    xs: [__m512; 3],
    ys: [__m512; 3],
    next: __m512i,
    entry: __m512i,
    visited: __m512i,
    /// Live lanes.
    live: __mmask16,
}

impl V16 {
    fn load(pk: &Pack<16>) -> V16 {
        let f = |a: [f32; 16]| bytemuck::cast::<[f32; 16], __m512>(a);
        let u = |a: [u32; 16]| bytemuck::cast::<[u32; 16], __m512i>(a);
        let live = pk
            .live
            .iter()
            .enumerate()
            .fold(0u16, |m, (l, &b)| m | ((b as u16) << l));
        V16 {
            o: pk.o.map(f),
            c: pk.c.map(|a| a.map(f)),
            ids: pk.ids.map(u),
            xs: pk.xs.map(f),
            ys: pk.ys.map(f),
            next: u(pk.next),
            entry: u(pk.entry),
            visited: u(pk.visited),
            live,
        }
    }

    /// Loads scalar lane `lane` into lane `l` (masked broadcasts: the
    /// other lanes stay in their registers).
    #[target_feature(enable = "avx512f")]
    fn put(&mut self, l: usize, lane: &Lane<DuffF32>) {
        let k: __mmask16 = 1 << l;
        let f = |x: &mut __m512, v: f32| *x = _mm512_mask_mov_ps(*x, k, _mm512_set1_ps(v));
        let u = |x: &mut __m512i, v: u32| *x = _mm512_mask_set1_epi32(*x, k, v as i32);
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
        self.live |= k;
    }

    /// Parks lane `l` (see `Pack::park`).
    #[target_feature(enable = "avx512f")]
    fn park(&mut self, l: usize) {
        let k: __mmask16 = 1 << l;
        self.live &= !k;
        self.next = _mm512_mask_set1_epi32(self.next, k, 0);
    }
}

/// The cold part of a round in registers (see the portable walk's `lane_events`):
/// only the lanes with an event are read and rewritten. Returns the
/// number of lanes parked.
#[cold]
#[inline(never)]
#[target_feature(enable = "avx512f")]
// Lane `l` indexes the round's flags, the ray slots and the registers.
#[allow(clippy::needless_range_loop)]
fn events16(
    feed: &mut Feed<'_>,
    v: &mut V16,
    ray: &mut [usize; 16],
    events: u32,
    round: &Round<16>,
) -> usize {
    let mut parked = 0;
    for l in 0..16 {
        if events >> l & 1 == 0 {
            continue;
        }
        // Only what ending or crossing needs is read from the registers;
        // a lane that crosses keeps them all but its next tet.
        let k: __mmask16 = 1 << l;
        let u = |x: __m512i| lane_u32(x, l);
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
                v.entry = _mm512_mask_set1_epi32(v.entry, k, link as i32);
                v.next = _mm512_mask_set1_epi32(v.next, k, n as i32);
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

/// Element `l` of `x` (one permute brings it to element 0).
#[target_feature(enable = "avx512f")]
#[inline]
pub(crate) fn lane_u32(x: __m512i, l: usize) -> u32 {
    let at = _mm512_set1_epi32(l as i32);
    _mm_cvtsi128_si32(_mm512_castsi512_si128(_mm512_permutexvar_epi32(at, x))) as u32
}

#[target_feature(enable = "avx512f")]
#[inline]
pub(crate) fn splat(x: i32) -> __m512i {
    _mm512_set1_epi32(x)
}

/// Gathers `words[idx]` per lane.
#[target_feature(enable = "avx512f")]
#[inline]
pub(crate) fn gather_words(g: &Geo<'_>, idx: __m512i) -> __m512i {
    // SAFETY: every caller forms `idx = min(next, last_tet) · stride + k`
    // with `0 ≤ k < stride` (checked by `RecordWords::gatherable`), so
    // each lane reads a word inside `g.words`.
    unsafe { _mm512_i32gather_epi32::<4>(idx, g.words.as_ptr() as *const i32) }
}

/// `(x, y, z)` of `points[i]` per lane, `i3 = 3·i`, `i ≤ last_point`.
#[target_feature(enable = "avx512f")]
#[inline]
pub(crate) fn gather_point(g: &Geo<'_>, i3: __m512i) -> [__m512; 3] {
    let (x, y) = gather_xy(g, i3);
    [x, y, gather_points(g, i3, 2)]
}

/// Gathers coordinate `axis` (0..=2) of `points[i]` per lane, `i ≤ last_point`.
#[target_feature(enable = "avx512f")]
#[inline]
fn gather_points(g: &Geo<'_>, i3: __m512i, axis: usize) -> __m512 {
    let base = g.points.as_ptr() as *const f32;
    // SAFETY: `i3 = 3·i` with `i ≤ last_point = points.len() − 1` per
    // lane, so word `i3 + axis` (axis ≤ 2) lies inside `points`;
    // `wrapping_add` only forms the base address.
    unsafe { _mm512_i32gather_ps::<4>(i3, base.wrapping_add(axis)) }
}

/// Gathers `(x, y)` of `points[i]` per lane (`i3 = 3·i`, `i ≤
/// last_point`) as two 8-lane gathers of 64-bit pairs, deinterleaved:
/// 16 loads instead of the 32 of two 16-lane gathers.
#[target_feature(enable = "avx512f")]
#[inline]
fn gather_xy(g: &Geo<'_>, i3: __m512i) -> (__m512, __m512) {
    let base = g.points.as_ptr() as *const i64;
    let lo = _mm512_castsi512_si256(i3);
    let hi = _mm512_extracti64x4_epi64::<1>(i3);
    // SAFETY: as `gather_points`: lane `k` reads the 8 bytes at word
    // `3·i`, the point's x and y, inside `points`.
    let (a, b) = unsafe {
        (
            _mm512_i32gather_epi64::<4>(lo, base),
            _mm512_i32gather_epi64::<4>(hi, base),
        )
    };
    let (a, b) = (_mm512_castsi512_ps(a), _mm512_castsi512_ps(b));
    let even = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
    let odd = _mm512_setr_epi32(1, 3, 5, 7, 9, 11, 13, 15, 17, 19, 21, 23, 25, 27, 29, 31);
    (
        _mm512_permutex2var_ps(a, even, b),
        _mm512_permutex2var_ps(a, odd, b),
    )
}

/// Per-lane flags of a mask.
fn flags(m: __mmask16) -> [bool; 16] {
    std::array::from_fn(|l| m >> l & 1 != 0)
}

/// One round of the walk (see the portable walk's `step`, the same decisions).
#[target_feature(enable = "avx512f")]
#[inline]
fn step<const RULE: u8>(v: &mut V16, g: &Geo<'_>, cap: u32) -> Option<(u32, Round<16>)> {
    let zero = _mm512_setzero_ps();
    let one = splat(1);
    // Loads: `VX`, the new vertex `d = idx₀ ⊕ idx₁ ⊕ idx₂ ⊕ VX`, its point.
    let tet = _mm512_min_epu32(v.next, splat(g.last_tet));
    let base = _mm512_mullo_epi32(tet, splat(g.stride));
    let vxw = gather_words(g, _mm512_add_epi32(base, splat(g.vx)));
    let d = _mm512_xor_si512(
        _mm512_xor_si512(v.ids[0], v.ids[1]),
        _mm512_xor_si512(v.ids[2], vxw),
    );
    let dc = _mm512_min_epu32(d, splat(g.last_point));
    let lost = _mm512_cmpneq_epi32_mask(dc, d);
    let i3 = _mm512_add_epi32(_mm512_add_epi32(dc, dc), dc);
    let [px3, py3, pz3] = gather_point(g, i3);
    let qx = _mm512_sub_ps(px3, v.o[0]);
    let qy = _mm512_sub_ps(py3, v.o[1]);
    let qz = _mm512_sub_ps(pz3, v.o[2]);
    // Projection: `(c₀·qₓ + c₁·q_y) + c₂·q_z`, no FMA.
    let proj = |k: usize| {
        _mm512_add_ps(
            _mm512_add_ps(_mm512_mul_ps(v.c[0][k], qx), _mm512_mul_ps(v.c[1][k], qy)),
            _mm512_mul_ps(v.c[2][k], qz),
        )
    };
    let (px, py) = (proj(0), proj(1));
    // `det(p₃, pᵢ) = p₃.x·yᵢ − p₃.y·xᵢ`.
    let det = |k: usize| _mm512_sub_ps(_mm512_mul_ps(px, v.ys[k]), _mm512_mul_ps(py, v.xs[k]));
    let dets = [det(0), det(1), det(2)];
    let mut left = dets.map(|x| _mm512_cmp_ps_mask::<_CMP_GT_OQ>(x, zero));
    let tie = (_mm512_cmp_ps_mask::<_CMP_EQ_OQ>(dets[0], zero)
        | _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(dets[1], zero)
        | _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(dets[2], zero))
        & v.live;
    if tie != 0 {
        left = ties16(v, d, px, py, tie, left);
    }
    // Exit slot and exiting vertex (`EXIT_SLOT`).
    let s2 = left[0] & !left[1];
    let s1 = !left[0] & left[2];
    let s0 = !(s1 | s2);
    let e = _mm512_mask_blend_epi32(
        s1,
        _mm512_mask_blend_epi32(s2, v.ids[0], v.ids[2]),
        v.ids[1],
    );
    // Exit link. Ids are < 2³¹ (`gatherable`), so signed compares order them.
    let rank = |x: __m512i, of: [__m512i; 4]| {
        let mut r = _mm512_setzero_si512();
        for y in of {
            r = _mm512_mask_add_epi32(r, _mm512_cmpgt_epi32_mask(x, y), r, one);
        }
        _mm512_min_epu32(r, splat(3))
    };
    let links = _mm512_add_epi32(base, splat(g.links));
    let link = match RULE {
        RANK => {
            let r = rank(e, [v.ids[0], v.ids[1], v.ids[2], d]);
            gather_words(g, _mm512_add_epi32(links, r))
        }
        RANK_XOR => {
            let rd = rank(d, [v.ids[0], v.ids[1], v.ids[2], d]);
            let re = rank(e, [v.ids[0], v.ids[1], v.ids[2], d]);
            let nx = |r: __m512i| {
                let m = _mm512_cmplt_epu32_mask(r, splat(3));
                // Lanes with rank 3 read word `base` (in range) and drop it.
                let idx = _mm512_mask_blend_epi32(m, base, _mm512_add_epi32(links, r));
                _mm512_maskz_mov_epi32(m, gather_words(g, idx))
            };
            _mm512_xor_si512(_mm512_xor_si512(v.entry, nx(rd)), nx(re))
        }
        _ => {
            let ids = _mm512_add_epi32(base, splat(g.ids));
            let vid = |k: i32| gather_words(g, _mm512_add_epi32(ids, splat(k)));
            let mut slot = splat(3);
            for k in (0..3).rev() {
                let hit = _mm512_cmpeq_epi32_mask(e, vid(k));
                slot = _mm512_mask_blend_epi32(hit, slot, splat(k));
            }
            gather_words(g, _mm512_add_epi32(links, slot))
        }
    };
    // Commit.
    let capped = _mm512_cmpge_epu32_mask(v.visited, splat(cap as i32));
    let go = v.live & !(capped | lost);
    for (k, s) in [s0, s1, s2].into_iter().enumerate() {
        let sel = go & s;
        v.ids[k] = _mm512_mask_blend_epi32(sel, v.ids[k], d);
        v.xs[k] = _mm512_mask_blend_ps(sel, v.xs[k], px);
        v.ys[k] = _mm512_mask_blend_ps(sel, v.ys[k], py);
    }
    v.visited = _mm512_mask_add_epi32(v.visited, go, v.visited, one);
    let is_tet = _mm512_cmplt_epu32_mask(link, splat(Link::BOUNDARY.0 as i32));
    let moving = go & is_tet;
    v.entry = _mm512_mask_blend_epi32(moving, v.entry, v.next);
    v.next = _mm512_mask_blend_epi32(moving, v.next, link);
    let events = v.live & !moving;
    if events == 0 {
        return None;
    }
    Some((
        events as u32,
        Round {
            raw: bytemuck::cast::<__m512i, [u32; 16]>(link),
            lost: flags(lost),
            capped: flags(capped),
        },
    ))
}

/// The scalar tie rule for the lanes with a zero determinant (`tie`).
#[target_feature(enable = "avx512f")]
#[inline(never)]
#[cold]
fn ties16(
    v: &V16,
    d: __m512i,
    px: __m512,
    py: __m512,
    tie: __mmask16,
    left: [__mmask16; 3],
) -> [__mmask16; 3] {
    let f = |a: __m512| bytemuck::cast::<__m512, [f32; 16]>(a);
    let u = |a: __m512i| bytemuck::cast::<__m512i, [u32; 16]>(a);
    let (xs, ys, ids) = (v.xs.map(f), v.ys.map(f), v.ids.map(u));
    let (d, px, py) = (u(d), f(px), f(py));
    let mut left = left;
    for l in 0..16 {
        if tie >> l & 1 == 0 {
            continue;
        }
        let pt = |k: usize| Vec2::new(xs[k][l], ys[k][l]);
        let face = Face2::new([pt(0), pt(1), pt(2)]);
        let id = [ids[0][l], ids[1][l], ids[2][l]];
        let m = face.left_mask_ties(Vec2::new(px[l], py[l]), d[l], &id);
        for (k, lk) in left.iter_mut().enumerate() {
            let bit = 1u16 << l;
            *lk = if m >> k & 1 != 0 {
                *lk | bit
            } else {
                *lk & !bit
            };
        }
    }
    left
}

/// The AVX-512 lockstep driver with exit rule `RULE`; `rw` must be
/// [`RecordWords::gatherable`] for `mesh.points`.
#[target_feature(enable = "avx512f")]
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
    // The packs live in registers; a lane's ray index is the only cold
    // state (its projection is rebuilt from the registers).
    let mut groups: [(V16, [usize; 16], usize); GROUPS] = std::array::from_fn(|_| {
        let (pk, live) = fill::<16>(&mut feed);
        (V16::load(&pk), pk.ray, live)
    });
    loop {
        let mut any = false;
        for (v, ray, live) in groups.iter_mut() {
            if *live == 0 {
                continue;
            }
            any = true;
            if let Some((events, round)) = step::<RULE>(v, &g, cap) {
                *live -= events16(&mut feed, v, ray, events, &round);
            }
        }
        if !any {
            break;
        }
    }
}

/// Packs of 16 lanes in flight per thread (see "Tuning" in [`crate::lockstep`]).
const GROUPS: usize = 2;
