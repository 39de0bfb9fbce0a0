//! ScTP (Lagae & Dutré's scalar triple products, [`TripleF32`]) walked in
//! 16-lane AVX-512 lockstep over the 32-byte baseline layout: the batch path
//! of [`crate::sctp::SctpTracer`].
//!
//! Each round every lane gathers the four vertex ids of the tet it enters
//! (the baseline layout stores no `VX`: the new vertex is the one id that is
//! not on the entry face, `v₀ ⊕ v₁ ⊕ v₂ ⊕ v₃ ⊕ idx₀ ⊕ idx₁ ⊕ idx₂`), its point
//! (`x, y` as one 64-bit pair, then `z`), and evaluates the three triple
//! products `d · (q₃ × qᵢ)` with `q = P − o` exactly as
//! [`TripleF32::left_mask`] does (glam's `cross` and `dot`, operand for
//! operand, no fused multiply-add), so every lane decides bit for bit as the
//! scalar walk and the antisymmetry that makes the walk watertight
//! (`a × b = −(b × a)` componentwise) is kept. A zero product takes the
//! scalar tie rule for that lane. The exit link is found by the slot of the
//! exiting vertex among the gathered ids (Algorithm 3). Lanes whose walk
//! needs the rare path take the scalar engine's cold path, and are refilled
//! at once, as in [`crate::lockstep`].
//!
//! Why: the scalar interleaved walk spends about 146 instructions per ScTP
//! step; in lockstep the arithmetic is shared by 16 rays.

use std::arch::x86_64::*;

use glam::Vec3;
use tet_core::{Link, TetMesh};

use super::avx512::{gather_point, gather_words, lane_u32, splat};
use super::pack::Geo;
use crate::ray::{Ray, TraceOutcome};
use crate::walk::lanes::{Feed, Starts};
use crate::walk::projection::TripleF32;
use crate::walk::start::Lane;
use crate::walk::stop::{Advance, Stopped};
use crate::walk::stopped::{AfterStop, after_stop};
use crate::walk::topology::{ExitRule, RecordWords, Topology};

/// Traces the batch in lockstep when the CPU has AVX-512F and the
/// layout exposes baseline records ([`ExitRule::Ids`]); false (nothing
/// traced) otherwise.
pub(crate) fn trace<T: Topology>(
    mesh: &TetMesh,
    topo: &T,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
) -> bool {
    if !std::arch::is_x86_feature_detected!("avx512f") {
        return false;
    }
    match topo.record_words() {
        Some(rw) if matches!(rw.rule, ExitRule::Ids { .. }) && rw.gatherable(mesh.points.len()) => {
            // SAFETY: `run` only requires AVX-512F, detected above.
            unsafe { run(mesh, rw, rays, start, cap, out) };
            true
        }
        _ => false,
    }
}

/// 16 walks in registers, and per lane the cold part of its ray.
struct Pack {
    o: [__m512; 3],
    dir: [__m512; 3],
    /// Entry face points `q = P − o`, `[vertex][axis]`.
    q: [[__m512; 3]; 3],
    ids: [__m512i; 3],
    next: __m512i,
    entry: __m512i,
    visited: __m512i,
    live: __mmask16,
    ray: [usize; 16],
    proj: [TripleF32; 16],
}

impl Pack {
    /// Loads scalar lane `lane` of ray `ray` into lane `l`.
    #[target_feature(enable = "avx512f")]
    fn put(&mut self, l: usize, ray: usize, lane: &Lane<TripleF32>) {
        let k: __mmask16 = 1 << l;
        let f = |x: &mut __m512, v: f32| *x = _mm512_mask_mov_ps(*x, k, _mm512_set1_ps(v));
        let u = |x: &mut __m512i, v: u32| *x = _mm512_mask_set1_epi32(*x, k, v as i32);
        let (o, d) = lane.proj.origin_direction();
        for a in 0..3 {
            f(&mut self.o[a], o[a]);
            f(&mut self.dir[a], d[a]);
        }
        for s in 0..3 {
            for a in 0..3 {
                f(&mut self.q[s][a], lane.st.p[s][a]);
            }
            u(&mut self.ids[s], lane.st.ids[s]);
        }
        u(&mut self.next, lane.next);
        u(&mut self.entry, lane.entry_raw);
        u(&mut self.visited, lane.st.visited);
        self.live |= k;
        self.ray[l] = ray;
        self.proj[l] = lane.proj;
    }

    /// Parks lane `l` (tet 0 keeps its loads in range).
    #[target_feature(enable = "avx512f")]
    fn park(&mut self, l: usize) {
        let k: __mmask16 = 1 << l;
        self.live &= !k;
        self.next = _mm512_mask_set1_epi32(self.next, k, 0);
    }

    /// Lanes filled with the next walks of the batch (parked when none).
    #[target_feature(enable = "avx512f")]
    fn fill(feed: &mut Feed<'_>) -> (Pack, usize) {
        let zf = _mm512_setzero_ps();
        let zi = _mm512_setzero_si512();
        let mut pk = Pack {
            o: [zf; 3],
            dir: [zf; 3],
            q: [[zf; 3]; 3],
            ids: [zi; 3],
            next: zi,
            entry: zi,
            visited: zi,
            live: 0,
            ray: [0; 16],
            proj: [TripleF32::default(); 16],
        };
        let mut live = 0;
        for l in 0..16 {
            if let Some((i, lane)) = feed.next_lane::<TripleF32>() {
                pk.put(l, i, &lane);
                live += 1;
            }
        }
        (pk, live)
    }
}

/// What the cold path needs of a round.
struct Events {
    mask: __mmask16,
    raw: [u32; 16],
    lost: __mmask16,
    capped: __mmask16,
}

/// One round (the decisions of the scalar step with [`TripleF32`]).
#[target_feature(enable = "avx512f")]
#[inline]
fn step(v: &mut Pack, g: &Geo<'_>, cap: u32) -> Option<Events> {
    let zero = _mm512_setzero_ps();
    let tet = _mm512_min_epu32(v.next, splat(g.last_tet));
    let base = _mm512_mullo_epi32(tet, splat(g.stride));
    let ids = _mm512_add_epi32(base, splat(g.ids));
    let vid: [__m512i; 4] =
        std::array::from_fn(|k| gather_words(g, _mm512_add_epi32(ids, splat(k as i32))));
    // The vertex not on the entry face.
    let d = _mm512_xor_si512(
        _mm512_xor_si512(
            _mm512_xor_si512(vid[0], vid[1]),
            _mm512_xor_si512(vid[2], vid[3]),
        ),
        _mm512_xor_si512(_mm512_xor_si512(v.ids[0], v.ids[1]), v.ids[2]),
    );
    let dc = _mm512_min_epu32(d, splat(g.last_point));
    let lost = _mm512_cmpneq_epi32_mask(dc, d);
    let i3 = _mm512_add_epi32(_mm512_add_epi32(dc, dc), dc);
    let p = gather_point(g, i3);
    // `TripleF32::project`: q₃ = P − o.
    let q3: [__m512; 3] = std::array::from_fn(|a| _mm512_sub_ps(p[a], v.o[a]));
    let mul = _mm512_mul_ps;
    let sub = _mm512_sub_ps;
    // `d · (q₃ × qₖ)` as glam computes it: `cross(q₃, qₖ)` is
    // `(q₃.y·qₖ.z − qₖ.y·q₃.z, q₃.z·qₖ.x − qₖ.z·q₃.x, q₃.x·qₖ.y − qₖ.x·q₃.y)`,
    // then `(d.x·c.x + d.y·c.y) + d.z·c.z`.
    let s: [__m512; 3] = std::array::from_fn(|k| {
        let qk = &v.q[k];
        let cx = sub(mul(q3[1], qk[2]), mul(qk[1], q3[2]));
        let cy = sub(mul(q3[2], qk[0]), mul(qk[2], q3[0]));
        let cz = sub(mul(q3[0], qk[1]), mul(qk[0], q3[1]));
        _mm512_add_ps(
            _mm512_add_ps(mul(v.dir[0], cx), mul(v.dir[1], cy)),
            mul(v.dir[2], cz),
        )
    });
    let mut left = s.map(|x| _mm512_cmp_ps_mask::<_CMP_GT_OQ>(x, zero));
    let tie = (_mm512_cmp_ps_mask::<_CMP_EQ_OQ>(s[0], zero)
        | _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(s[1], zero)
        | _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(s[2], zero))
        & v.live;
    if tie != 0 {
        left = ties(v, d, q3, tie, left);
    }
    // Exit slot (`EXIT_SLOT`) and the exiting vertex.
    let s2 = left[0] & !left[1];
    let s1 = !left[0] & left[2];
    let s0 = !(s1 | s2);
    let e = _mm512_mask_blend_epi32(
        s1,
        _mm512_mask_blend_epi32(s2, v.ids[0], v.ids[2]),
        v.ids[1],
    );
    // Algorithm 3: the link of the exiting vertex's slot (3: none of
    // the first three).
    let mut slot = splat(3);
    for (k, &vk) in vid[..3].iter().enumerate().rev() {
        slot = _mm512_mask_blend_epi32(_mm512_cmpeq_epi32_mask(e, vk), slot, splat(k as i32));
    }
    let link = gather_words(
        g,
        _mm512_add_epi32(_mm512_add_epi32(base, splat(g.links)), slot),
    );
    // Commit.
    let capped = _mm512_cmpge_epu32_mask(v.visited, splat(cap as i32));
    let go = v.live & !(capped | lost);
    for (k, sel) in [s0, s1, s2].into_iter().enumerate() {
        let sel = go & sel;
        v.ids[k] = _mm512_mask_blend_epi32(sel, v.ids[k], d);
        for (qa, &na) in v.q[k].iter_mut().zip(&q3) {
            *qa = _mm512_mask_blend_ps(sel, *qa, na);
        }
    }
    v.visited = _mm512_mask_add_epi32(v.visited, go, v.visited, splat(1));
    let is_tet = _mm512_cmplt_epu32_mask(link, splat(Link::BOUNDARY.0 as i32));
    let moving = go & is_tet;
    v.entry = _mm512_mask_blend_epi32(moving, v.entry, v.next);
    v.next = _mm512_mask_blend_epi32(moving, v.next, link);
    let mask = v.live & !moving;
    (mask != 0).then(|| Events {
        mask,
        raw: bytemuck::cast::<__m512i, [u32; 16]>(link),
        lost,
        capped,
    })
}

/// The scalar tie rule for the lanes of `tie`.
#[target_feature(enable = "avx512f")]
#[inline(never)]
#[cold]
fn ties(
    v: &Pack,
    d: __m512i,
    q3: [__m512; 3],
    tie: __mmask16,
    left: [__mmask16; 3],
) -> [__mmask16; 3] {
    let f = |x: __m512| bytemuck::cast::<__m512, [f32; 16]>(x);
    let u = |x: __m512i| bytemuck::cast::<__m512i, [u32; 16]>(x);
    let (q, ids, d, q3) = (v.q.map(|p| p.map(f)), v.ids.map(u), u(d), q3.map(f));
    let mut left = left;
    for l in 0..16 {
        if tie >> l & 1 == 0 {
            continue;
        }
        let face = [0, 1, 2].map(|k| Vec3::new(q[k][0][l], q[k][1][l], q[k][2][l]));
        let id = [ids[0][l], ids[1][l], ids[2][l]];
        let pd = Vec3::new(q3[0][l], q3[1][l], q3[2][l]);
        let m = v.proj[l].left_mask_ties(pd, d[l], &face, &id);
        let bit = 1u16 << l;
        for (k, lk) in left.iter_mut().enumerate() {
            *lk = if m >> k & 1 != 0 {
                *lk | bit
            } else {
                *lk & !bit
            };
        }
    }
    left
}

/// The cold part of a round: finish the lanes of `ev`, refill or park
/// them. Returns the number parked.
#[cold]
#[inline(never)]
#[target_feature(enable = "avx512f")]
fn events(feed: &mut Feed<'_>, v: &mut Pack, ev: &Events) -> usize {
    let mut parked = 0;
    for l in 0..16 {
        if ev.mask >> l & 1 == 0 {
            continue;
        }
        let k: __mmask16 = 1 << l;
        let u = |x: __m512i| lane_u32(x, l);
        let ids = [u(v.ids[0]), u(v.ids[1]), u(v.ids[2])];
        let (tet, visited, link, i) = (u(v.next), u(v.visited), ev.raw[l], v.ray[l]);
        let adv = Advance::stopped(ev.capped & k != 0, ev.lost & k != 0);
        let stopped = Stopped {
            adv,
            ids,
            tet,
            visited,
            link,
        };
        match after_stop(feed, i, stopped) {
            AfterStop::Cross(n) => {
                v.entry = _mm512_mask_set1_epi32(v.entry, k, link as i32);
                v.next = _mm512_mask_set1_epi32(v.next, k, n as i32);
            }
            AfterStop::Refill(j, lane) => v.put(l, j, &lane),
            AfterStop::Park => {
                v.park(l);
                parked += 1;
            }
        }
    }
    parked
}

/// The driver: two packs of 16 lanes stepped in turn.
#[target_feature(enable = "avx512f")]
fn run(
    mesh: &TetMesh,
    rw: RecordWords<'_>,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
) {
    let g = Geo::new(mesh, &rw);
    let mut feed = Feed::new(mesh, rays, start, out);
    let mut packs: [(Pack, usize); 2] = std::array::from_fn(|_| Pack::fill(&mut feed));
    loop {
        let mut any = false;
        for (v, live) in packs.iter_mut() {
            if *live == 0 {
                continue;
            }
            any = true;
            if let Some(ev) = step(v, &g, cap) {
                *live -= events(&mut feed, v, &ev);
            }
        }
        if !any {
            break;
        }
    }
}
