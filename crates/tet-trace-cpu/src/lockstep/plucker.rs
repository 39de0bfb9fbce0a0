//! The Plücker walk of Maria et al. (2017, §3.4, the `tet80` and
//! `tet80-consistent` kernels of [`crate::tet80`]) in SIMD lockstep: `W`
//! rays of a batch walk side by side over the Tet80 records, one ray per
//! lane, one tet per lane per round.
//!
//! Each round every lane gathers, from the 80-byte record of the tet it
//! enters (20 words: the four vertices inline, then four faces of
//! `occlusion`, `neighbor`), the apex `V_e` (the complement vertex of its
//! entry face `e`) and the vertex `A`, decides the side of `V_e → A`, then
//! gathers the second vertex (`B` after a left turn, `C` after a right
//! one) and decides the side of that edge; the two signs pick the exit face
//! (the `EXIT` table of [`crate::tet80`]: `A`'s face when both signs agree,
//! else the face of the second edge's other vertex), whose two words are
//! gathered last. Lanes whose exit face is occlusive or on the boundary, or
//! that reached the step cap, take the scalar walk's own crossing
//! ([`PluckerWalk::leave`]); a lane whose walk ended is refilled from the
//! batch at once. Eleven gathers per step (three vertices and two face
//! words), against the scalar walk's eleven loads.
//!
//! Both side rules fit per lane ([`Side`]): the faithful product
//! `(X − V) · (d × (V − o))` is only a different formula per tet, not
//! different state, so it runs in lanes like the consistent determinant
//! of projected vertices. Every lane evaluates the scalar walk's formulas,
//! the same IEEE operations on the same operands in the same order, with
//! no fused multiply-add; a zero consistent determinant takes the scalar
//! tie rule for that lane ([`PluckerWalk::left_tie`]), and the starts are
//! the scalar walk's own ([`Begun`], made by the tracer). So every ray
//! ends with bit for bit the outcome of the scalar walk (tested in
//! `tests/lockstep_tet80.rs`).
//!
//! Gathers index the record words: the tet is clamped to the last record
//! (`4·tet ≤ 4·(tets − 1)`) and every offset within a record is below 20,
//! with the word count checked to fit an `i32` once per batch; a layout
//! whose links point past the tet array reads a clamped record (a wrong
//! walk, never an out-of-bounds read).

use glam::{Vec2, Vec3};
use tet_core::FACE_VERTICES;
use tet_core::layout::{Tet80, Tet80Face};

use super::Width;
#[cfg(target_arch = "x86_64")]
use super::avx2::Avx2;
#[cfg(target_arch = "x86_64")]
use super::avx512::Avx512;
use super::lanes::Lanes;
use super::portable::Portable;
use super::side::{Consistent, Faithful, Side};
use crate::ray::{Failure, Ray, TraceOutcome};

/// Words per Tet80 record.
const STRIDE: u32 = 20;
/// Word of face 0's `occlusion` (face `k`: `FACE + 2k`, its `neighbor`
/// next).
const FACE: u32 = 12;

/// `3·FACE_VERTICES[e][0]` (the word of `A`), by entry face `e`.
const A_WORD: [u32; 8] = {
    let mut t = [0; 8];
    let mut e = 0;
    while e < 4 {
        t[e] = 3 * FACE_VERTICES[e][0] as u32;
        e += 1;
    }
    t
};
/// `FACE + 2·FACE_VERTICES[e][0]` (the face opposite `A`), by `e`.
const A_FACE: [u32; 8] = {
    let mut t = [0; 8];
    let mut e = 0;
    while e < 4 {
        t[e] = FACE + 2 * FACE_VERTICES[e][0] as u32;
        e += 1;
    }
    t
};
/// The slot of the second edge's vertex by `2e + s`: `C` (slot
/// `FACE_VERTICES[e][1]`) for `s = 0` (right of `V_e → A`), `B` (slot
/// `FACE_VERTICES[e][2]`) for `s = 1` (the scalar walk's `SECOND`).
const fn second_slot(i: usize) -> u32 {
    FACE_VERTICES[i / 2][1 + i % 2] as u32
}
/// `3·second_slot(2e + s)` (the word of the second vertex).
const SECOND_WORD: [u32; 8] = {
    let mut t = [0; 8];
    let mut i = 0;
    while i < 8 {
        t[i] = 3 * second_slot(i);
        i += 1;
    }
    t
};
/// `FACE + 2·second_slot(2e + s)`: the exit when the two signs differ is
/// the face opposite the second vertex *not* taken, `second_slot(2e + ¬s₁)`.
const SECOND_FACE: [u32; 8] = {
    let mut t = [0; 8];
    let mut i = 0;
    while i < 8 {
        t[i] = FACE + 2 * second_slot(i);
        i += 1;
    }
    t
};

/// A walk the tracer started: the tet entered next, its entry face, the
/// tets visited so far and the consistent walk's projection factor, as
/// the scalar walk's loop begins with them.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Begun {
    /// Tet entered next.
    pub(crate) tet: u32,
    /// Its entry face (0..=3).
    pub(crate) entry: usize,
    /// Tets visited so far.
    pub(crate) visited: u32,
    /// The projection factor (consistent side rule).
    pub(crate) scale: f32,
}

/// What the lockstep walk takes from a Tet80 tracer: its records, step cap,
/// side rule and the scalar walk's rare paths, so that every lane ends as
/// the scalar walk does.
pub(crate) trait PluckerWalk: Sync {
    /// The consistent side rule (else the faithful one).
    const CONSISTENT: bool;
    /// The Tet80 records (fewer than 2³⁰).
    fn records(&self) -> &[Tet80];
    /// The step cap.
    fn cap(&self) -> u32;
    /// The scalar walk crossing face `f` of `tet` after `visited` tets:
    /// the next tet and its entry face, or the outcome.
    fn leave(
        &self,
        ray: &Ray,
        tet: u32,
        f: Tet80Face,
        visited: u32,
    ) -> Result<(u32, usize), TraceOutcome>;
    /// The consistent side test of `p → q` (projected `pp`, `pq`) when
    /// their determinant is zero: the scalar walk's tie rule.
    fn left_tie(pp: Vec2, p: Vec3, pq: Vec2, q: Vec3) -> bool;
}

/// `L::WIDTH` walks in registers.
struct Pack<L: Lanes, S: Side<L>> {
    ray: S::Ray,
    /// `tet << 2 | entry face` of the tet entered next (the Tet80 link).
    next: L::I,
    /// Tets visited so far.
    visited: L::I,
    /// Lanes holding a walk (else parked on tet 0, results ignored).
    live: L::M,
    /// Each lane's ray in the batch.
    ray_index: L::Arr<usize>,
}

/// The rays of a batch and the tracer's start of each.
struct Feed<'a, B> {
    rays: &'a [Ray],
    begin: B,
    next: usize,
    out: &'a mut [TraceOutcome],
}

impl<B: FnMut(usize) -> Result<Begun, TraceOutcome>> Feed<'_, B> {
    /// The next ray whose walk begins (the others' outcomes are stored).
    #[inline(always)]
    fn next_lane(&mut self) -> Option<(usize, Begun)> {
        while self.next < self.rays.len() {
            let i = self.next;
            self.next += 1;
            match (self.begin)(i) {
                Ok(b) => return Some((i, b)),
                Err(o) => self.out[i] = o,
            }
        }
        None
    }
}

impl<L: Lanes, S: Side<L>> Pack<L, S> {
    /// Lane `k` walking ray `i` from `b`.
    #[inline(always)]
    fn put(&mut self, l: L, k: usize, i: usize, ray: &Ray, b: Begun) {
        S::put(l, k, &mut self.ray, ray, b.scale);
        self.next = l.set_i(self.next, k, b.tet << 2 | b.entry as u32 & 3);
        self.visited = l.set_i(self.visited, k, b.visited);
        self.live = l.or_m(self.live, l.mask_of_bits(1 << k));
        self.ray_index.as_mut()[k] = i;
    }

    /// Lanes filled with the next walks of the batch (parked when fewer),
    /// and the number of live lanes.
    #[inline(always)]
    fn fill<B: FnMut(usize) -> Result<Begun, TraceOutcome>>(
        l: L,
        feed: &mut Feed<'_, B>,
    ) -> (Self, usize) {
        let z = l.splat_i(0);
        let mut pk = Pack {
            ray: S::zero(l),
            next: z,
            visited: z,
            live: l.mask_of_bits(0),
            ray_index: L::arr(0),
        };
        let mut live = 0;
        for k in 0..L::WIDTH {
            if let Some((i, b)) = feed.next_lane() {
                pk.put(l, k, i, &feed.rays[i], b);
                live += 1;
            }
        }
        (pk, live)
    }
}

/// What a round leaves for the rare path: the lanes that stopped and those
/// of them at the step cap (bits), and the exit face's words.
struct Round<L: Lanes> {
    events: u32,
    capped: u32,
    occlusion: L::Arr<u32>,
    neighbor: L::Arr<u32>,
}

/// Vertex `(x, y, z)` at words `at..at + 3`.
///
/// # Safety
///
/// `at + 2 < words.len()` in every lane.
#[inline(always)]
unsafe fn vertex<L: Lanes>(l: L, words: &[u32], at: L::I) -> [L::F; 3] {
    // SAFETY: the caller's contract.
    unsafe {
        [
            l.gather_f(words, at),
            l.gather_f(words, l.add_i(at, l.splat_i(1))),
            l.gather_f(words, l.add_i(at, l.splat_i(2))),
        ]
    }
}

/// `left` with the scalar tie rule in the lanes of `tie` (rare path).
#[inline(always)]
fn ties<L: Lanes, S: Side<L>, W: PluckerWalk>(
    l: L,
    tie: L::M,
    left: L::M,
    apex: (&S::Apex, &[L::F; 3]),
    x: (&S::Vert, &[L::F; 3]),
) -> L::M {
    let (tie, mut bits) = (l.bits(tie), l.bits(left));
    let at = |v: &[L::F; 3], k: usize| Vec3::from_array(v.map(|c| L::f_lanes(c).as_ref()[k]));
    for k in (0..L::WIDTH).filter(|k| tie >> k & 1 != 0) {
        let s = W::left_tie(
            S::apex_2d(apex.0, k),
            at(apex.1, k),
            S::vert_2d(x.0, k),
            at(x.1, k),
        );
        bits = bits & !(1 << k) | (s as u32) << k;
    }
    l.mask_of_bits(bits)
}

/// One round: every live lane enters its next tet and, in the common case,
/// moves on to the exit neighbour; `Some` when some live lane stopped (the
/// step cap, an occlusive face, the boundary).
#[inline(always)]
fn step<L: Lanes, S: Side<L>, W: PluckerWalk>(
    l: L,
    pk: &mut Pack<L, S>,
    words: &[u32],
    last: u32,
    cap: u32,
) -> Option<Round<L>> {
    let e = l.and_i(pk.next, l.splat_i(3));
    let t4 = l.min_u(l.and_i(pk.next, l.splat_i(!3)), l.splat_i(last << 2));
    let base = l.mul_i(t4, l.splat_i(STRIDE / 4));
    let capped = l.ge_u(pk.visited, l.splat_i(cap));
    let go = l.andnot_m(capped, pk.live);
    // SAFETY (the three vertices): `base ≤ 20·last` and every offset is
    // at most 3·3 + 2 < 20, so each word lies in the record of tet
    // `min(tet, last)`, inside `words` (`run`'s contract).
    let apex = unsafe { vertex(l, words, l.add_i(base, l.add_i(l.add_i(e, e), e))) };
    let a = unsafe { vertex(l, words, l.add_i(base, l.permute_i(A_WORD, e))) };
    let pa = S::apex(l, &pk.ray, &apex);
    // First edge V_e → A.
    let (mut s1, tie, va) = S::side(l, &pk.ray, &pa, &a);
    if S::TIES && l.any(l.and_m(tie, go)) {
        let tie = l.and_m(tie, go);
        s1 = l.cold(|| ties::<L, S, W>(l, tie, s1, (&pa, &apex), (&va, &a)));
    }
    // Second edge: V_e → C after a right turn, V_e → B after a left one.
    let zero = l.splat_i(0);
    let e2 = l.add_i(e, e);
    let i1 = l.add_i(e2, l.inc(zero, s1));
    let x = unsafe { vertex(l, words, l.add_i(base, l.permute_i(SECOND_WORD, i1))) };
    let (mut s2, tie, vx) = S::side(l, &pk.ray, &pa, &x);
    if S::TIES && l.any(l.and_m(tie, go)) {
        let tie = l.and_m(tie, go);
        s2 = l.cold(|| ties::<L, S, W>(l, tie, s2, (&pa, &apex), (&vx, &x)));
    }
    // The exit face (`EXIT`): opposite A when both signs agree, else
    // opposite the second-edge vertex not taken.
    let differ = l.or_m(l.andnot_m(s1, s2), l.andnot_m(s2, s1));
    let i2 = l.add_i(e2, l.inc(zero, l.not_m(s1)));
    let f = l.select_i(differ, l.permute_i(SECOND_FACE, i2), l.permute_i(A_FACE, e));
    let at = l.add_i(base, f);
    // SAFETY: `base ≤ 20·last`, `f + 1 ≤ 19`, as above.
    let (occlusion, neighbor) = unsafe {
        (
            l.gather_words(words, at),
            l.gather_words(words, l.add_i(at, l.splat_i(1))),
        )
    };
    pk.visited = l.inc(pk.visited, go);
    let open = l.and_m(
        l.eq_i(occlusion, l.splat_i(Tet80Face::NON_OCCLUSIVE)),
        l.ne_i(neighbor, l.splat_i(Tet80Face::NO_NEIGHBOR)),
    );
    let moving = l.and_m(go, open);
    pk.next = l.select_i(moving, neighbor, pk.next);
    let events = l.andnot_m(moving, pk.live);
    if !l.any(events) {
        return None;
    }
    Some(Round {
        events: l.bits(events),
        capped: l.bits(capped),
        occlusion: L::i_lanes(occlusion),
        neighbor: L::i_lanes(neighbor),
    })
}

/// The rare part of a round: each lane of `r.events` stopped; end it at the
/// step cap or cross its exit face with the scalar walk's `leave`, and when
/// its walk ended store the outcome and refill the lane (or park it).
/// Returns the number of lanes parked.
#[inline(always)]
fn events<L: Lanes, S: Side<L>, W: PluckerWalk, B: FnMut(usize) -> Result<Begun, TraceOutcome>>(
    l: L,
    w: &W,
    feed: &mut Feed<'_, B>,
    pk: &mut Pack<L, S>,
    r: &Round<L>,
) -> usize {
    let mut parked = 0;
    for k in (0..L::WIDTH).filter(|k| r.events >> k & 1 != 0) {
        let i = pk.ray_index.as_ref()[k];
        let visited = l.get_i(pk.visited, k);
        let ended = if r.capped >> k & 1 != 0 {
            TraceOutcome::Failed {
                failure: Failure::StepCap,
                tets_visited: visited,
            }
        } else {
            let face = Tet80Face {
                occlusion: r.occlusion.as_ref()[k],
                neighbor: r.neighbor.as_ref()[k],
            };
            let tet = l.get_i(pk.next, k) >> 2;
            match w.leave(&feed.rays[i], tet, face, visited) {
                Ok((n, f)) => {
                    pk.next = l.set_i(pk.next, k, n << 2 | f as u32 & 3);
                    continue;
                }
                Err(o) => o,
            }
        };
        feed.out[i] = ended;
        match feed.next_lane() {
            Some((j, b)) => pk.put(l, k, j, &feed.rays[j], b),
            None => {
                pk.live = l.andnot_m(l.mask_of_bits(1 << k), pk.live);
                pk.next = l.set_i(pk.next, k, 0);
                parked += 1;
            }
        }
    }
    parked
}

/// Traces `rays` (ray `i` started by `begin(i)`) with `PACKS` packs of
/// `L::WIDTH` lanes stepped in turn; `out[i]` is exactly the scalar walk's
/// outcome. `words` are `w`'s records as words: a whole number of records,
/// at most `i32::MAX` words.
#[inline(always)]
fn run<L, S, W, B, const PACKS: usize>(
    l: L,
    w: &W,
    words: &[u32],
    rays: &[Ray],
    begin: B,
    out: &mut [TraceOutcome],
) where
    L: Lanes,
    S: Side<L>,
    W: PluckerWalk,
    B: FnMut(usize) -> Result<Begun, TraceOutcome>,
{
    let n = rays.len().min(out.len());
    let mut feed = Feed {
        rays: &rays[..n],
        begin,
        next: 0,
        out: &mut out[..n],
    };
    let last = (words.len() / STRIDE as usize).saturating_sub(1) as u32;
    let cap = w.cap();
    let mut packs: [(Pack<L, S>, usize); PACKS] = std::array::from_fn(|_| Pack::fill(l, &mut feed));
    loop {
        let mut any = false;
        for (pk, live) in packs.iter_mut() {
            if *live == 0 {
                continue;
            }
            any = true;
            if let Some(r) = step::<L, S, W>(l, pk, words, last, cap) {
                *live -= l.cold(|| events(l, w, &mut feed, pk, &r));
            }
        }
        if !any {
            break;
        }
    }
}

/// [`run`] with the side rule of `W`.
#[inline(always)]
fn run_side<L, W, B, const PACKS: usize>(
    l: L,
    w: &W,
    words: &[u32],
    rays: &[Ray],
    begin: B,
    out: &mut [TraceOutcome],
) where
    L: Lanes,
    W: PluckerWalk,
    B: FnMut(usize) -> Result<Begun, TraceOutcome>,
{
    if W::CONSISTENT {
        run::<L, Consistent, W, B, PACKS>(l, w, words, rays, begin, out)
    } else {
        run::<L, Faithful, W, B, PACKS>(l, w, words, rays, begin, out)
    }
}

/// Traces `rays` with `w`'s Plücker walk in lockstep at `width` (ray `i`
/// started by `begin(i)`, which also stores the outcome of a walk that
/// ends before it starts); `out[i]` is exactly the scalar walk's outcome.
/// False (nothing traced) when the CPU lacks the width or the records are
/// empty or too many to gather.
pub(crate) fn trace<W, B>(
    width: Width,
    w: &W,
    rays: &[Ray],
    begin: B,
    out: &mut [TraceOutcome],
) -> bool
where
    W: PluckerWalk,
    B: FnMut(usize) -> Result<Begun, TraceOutcome>,
{
    let words: &[u32] = bytemuck::cast_slice(w.records());
    if words.is_empty() || words.len() > i32::MAX as usize {
        return false;
    }
    match width {
        Width::Portable4 => run_side::<Portable<4>, W, B, 1>(Portable, w, words, rays, begin, out),
        Width::Portable8 => run_side::<Portable<8>, W, B, 1>(Portable, w, words, rays, begin, out),
        #[cfg(target_arch = "x86_64")]
        Width::Avx2 => match Avx2::detect() {
            // SAFETY: the token proves the CPU has AVX2.
            Some(t) => unsafe { walk_avx2(t, w, words, rays, begin, out) },
            None => return false,
        },
        #[cfg(target_arch = "x86_64")]
        Width::Avx512 => match Avx512::detect() {
            // SAFETY: the token proves the CPU has AVX-512F.
            Some(t) => unsafe { walk_avx512(t, w, words, rays, begin, out) },
            None => return false,
        },
        #[cfg(not(target_arch = "x86_64"))]
        Width::Avx2 | Width::Avx512 => return false,
    }
    true
}

/// The walk with 8 AVX2 lanes, two packs in flight, compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
fn walk_avx2<W, B>(t: Avx2, w: &W, words: &[u32], rays: &[Ray], begin: B, out: &mut [TraceOutcome])
where
    W: PluckerWalk,
    B: FnMut(usize) -> Result<Begun, TraceOutcome>,
{
    run_side::<Avx2, W, B, 2>(t, w, words, rays, begin, out)
}

/// The walk with 16 AVX-512 lanes, two packs in flight, compiled for
/// AVX-512F.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq,avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
fn walk_avx512<W, B>(
    t: Avx512,
    w: &W,
    words: &[u32],
    rays: &[Ray],
    begin: B,
    out: &mut [TraceOutcome],
) where
    W: PluckerWalk,
    B: FnMut(usize) -> Result<Begun, TraceOutcome>,
{
    run_side::<Avx512, W, B, 2>(t, w, words, rays, begin, out)
}
