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
//! The walk runs on the driver of every lockstep geometry
//! ([`super::driver::run`], as [`Plucker`] through [`super::trace`]), not a
//! copy of it: its rounds ([`Rounds`]) are this file's pack, step and rare
//! path. Measured against its own driver in the same run, alternating the
//! two builds (Torus Knots, 1920×1440, 2 threads, 5 frames, best of each,
//! 2-core AMD EPYC with AVX-512 shared with other builds, November 2026):
//! tet80-consistent 467 → 459 ms and 895 → 875 ms (two runs of 5 rounds;
//! median paired ratio 0.997, spread 0.81–1.12), tet80 397 → 401 ms and
//! 708 → 748 ms (median paired ratio 1.006, spread 0.94–1.64); 1 thread at
//! 960×720: 239 → 241 and 212 → 207 ms. No loss beyond that noise, and the
//! compiled step is the same: the same 11 gathers and, from the first to
//! the last, the same instructions but one.
//!
//! Gathers index the record words: the tet is clamped to the last record
//! (`4·tet ≤ 4·(tets − 1)`) and every offset within a record is below 20,
//! with the word count checked to fit an `i32` once per batch; a layout
//! whose links point past the tet array reads a clamped record (a wrong
//! walk, never an out-of-bounds read).

use std::marker::PhantomData;

use glam::{Vec2, Vec3};
use tet_core::FACE_VERTICES;
use tet_core::layout::{Tet80, Tet80Face};

use super::Geometry;
use super::driver::{Gate, Rounds, next_ungated, run};
use super::lanes::Lanes;
use super::side::{Consistent, Faithful, Side};
use crate::ray::{Failure, Ray, TraceOutcome};
use crate::walk::lanes::{Batch, Starts};

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

/// A walk between two tets: the tet entered next, its entry face, the
/// tets visited so far and the consistent walk's projection factor, as
/// the scalar walk's loop begins with them (made by the tracer's start;
/// what a [`Gate`] receives of a walk it stops).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Begun {
    /// Tet entered next.
    pub(crate) tet: u32,
    /// Its entry face (0..=3).
    pub(crate) entry: usize,
    /// Tets visited so far.
    pub(crate) visited: u32,
    /// The projection factor (consistent side rule).
    pub(crate) scale: f32,
}

/// What the lockstep walk takes from a Tet80 tracer (the topology of its
/// batches): its records, side rule, starts and the scalar walk's rare
/// paths, so that every lane ends as the scalar walk does.
pub trait PluckerWalk: Sync {
    /// The consistent side rule (else the faithful one).
    const CONSISTENT: bool;
    /// The Tet80 records (fewer than 2³⁰).
    fn records(&self) -> &[Tet80];
    /// The starts of the walks of `rays` from `starts`: ray `i`'s, or its
    /// outcome when its walk ends before it starts.
    fn starts<'a>(
        &'a self,
        rays: &'a [Ray],
        starts: Starts<'a>,
    ) -> impl FnMut(usize) -> Result<Begun, TraceOutcome> + 'a;
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
    /// Each lane's projection factor (for a handover).
    scale: L::Arr<f32>,
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
        self.scale.as_mut()[k] = b.scale;
    }

    /// Parks lane `k` (on tet 0).
    #[inline(always)]
    fn park(&mut self, l: L, k: usize) {
        self.live = l.andnot_m(l.mask_of_bits(1 << k), self.live);
        self.next = l.set_i(self.next, k, 0);
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
            scale: L::arr(0.0),
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
                pk.park(l, k);
                parked += 1;
            }
        }
    }
    parked
}

/// Hands over the lanes of `stop` (their next tet is the gate's) and
/// refills them, handing over at once the new walks whose first tet is the
/// gate's too. Returns the number of lanes parked.
#[inline(always)]
fn gate_lanes<L, S, B, GT>(
    l: L,
    feed: &mut Feed<'_, B>,
    pk: &mut Pack<L, S>,
    gate: &mut GT,
    stop: u32,
) -> usize
where
    L: Lanes,
    S: Side<L>,
    B: FnMut(usize) -> Result<Begun, TraceOutcome>,
    GT: Gate<Begun>,
{
    let mut parked = 0;
    for k in (0..L::WIDTH).filter(|k| stop >> k & 1 != 0) {
        let next = l.get_i(pk.next, k);
        let h = Begun {
            tet: next >> 2,
            entry: (next & 3) as usize,
            visited: l.get_i(pk.visited, k),
            scale: pk.scale.as_ref()[k],
        };
        gate.hand_over(pk.ray_index.as_ref()[k], h);
        match next_ungated(|| feed.next_lane(), gate, |b| b.tet, |b| b) {
            Some((j, b)) => pk.put(l, k, j, &feed.rays[j], b),
            None => {
                pk.park(l, k);
                parked += 1;
            }
        }
    }
    parked
}

/// The Plücker walk of side rule `S` over `w`'s records (`words`, a whole
/// number of them, at most `i32::MAX` words), for the driver ([`run`]).
struct Walk<'a, S, W, B> {
    w: &'a W,
    words: &'a [u32],
    /// The last record.
    last: u32,
    cap: u32,
    _walk: PhantomData<fn() -> (S, B)>,
}

impl<S, W, B> Clone for Walk<'_, S, W, B> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<S, W, B> Copy for Walk<'_, S, W, B> {}

impl<'a, L, S, W, B> Rounds<L> for Walk<'a, S, W, B>
where
    L: Lanes,
    S: Side<L>,
    W: PluckerWalk,
    B: FnMut(usize) -> Result<Begun, TraceOutcome>,
{
    type Feed = Feed<'a, B>;
    type Pack = Pack<L, S>;
    type Round = Round<L>;
    type Handover = Begun;

    #[inline(always)]
    fn fill(&self, l: L, feed: &mut Feed<'a, B>) -> (Pack<L, S>, usize) {
        Pack::fill(l, feed)
    }
    #[inline(always)]
    fn step(&self, l: L, pk: &mut Pack<L, S>) -> Option<Round<L>> {
        step::<L, S, W>(l, pk, self.words, self.last, self.cap)
    }
    #[inline(always)]
    fn events(&self, l: L, feed: &mut Feed<'a, B>, pk: &mut Pack<L, S>, r: &Round<L>) -> usize {
        events(l, self.w, feed, pk, r)
    }
    #[inline(always)]
    fn entering(&self, l: L, pk: &Pack<L, S>) -> (L::Arr<u32>, u32) {
        let mut tets = L::i_lanes(pk.next);
        for t in tets.as_mut() {
            *t >>= 2;
        }
        (tets, l.bits(pk.live))
    }
    #[inline(always)]
    fn entering_is(&self, l: L, pk: &Pack<L, S>, tet: u32) -> u32 {
        if tet >= 1 << 30 {
            // No record has that index (`tet << 2` would wrap).
            return 0;
        }
        let t4 = l.and_i(pk.next, l.splat_i(!3));
        l.bits(l.and_m(l.eq_i(t4, l.splat_i(tet << 2)), pk.live))
    }
    #[inline(always)]
    fn hand_over<GT: Gate<Begun>>(
        &self,
        l: L,
        feed: &mut Feed<'a, B>,
        pk: &mut Pack<L, S>,
        gate: &mut GT,
        stop: u32,
    ) -> usize {
        gate_lanes(l, feed, pk, gate, stop)
    }
}

/// The Plücker walk of Maria et al. (the Tet80 kernels): its geometry is
/// the tracer's side rule over the Tet80 records, its topology the tracer
/// (`PluckerWalk`).
#[derive(Clone, Copy, Debug)]
pub struct Plucker;

impl<W: PluckerWalk> Geometry<W> for Plucker {
    type Handover = Begun;
    /// `Err` (nothing traced) when the records are empty or too many to
    /// gather.
    #[inline(always)]
    fn walk<'a, L: Lanes, GT: Gate<Begun>, const PACKS: usize>(
        l: L,
        batch: Batch<'a, W>,
        gate: &mut GT,
    ) -> Result<(), Batch<'a, W>> {
        let w = batch.topo;
        let words: &[u32] = bytemuck::cast_slice(w.records());
        if words.is_empty() || words.len() > i32::MAX as usize {
            return Err(batch);
        }
        let n = batch.rays.len().min(batch.out.len());
        let mut feed = Feed {
            rays: &batch.rays[..n],
            begin: w.starts(&batch.rays[..n], batch.starts),
            next: 0,
            out: &mut batch.out[..n],
        };
        let last = (words.len() / STRIDE as usize).saturating_sub(1) as u32;
        if W::CONSISTENT {
            let walk = Walk::<Consistent, W, _> {
                w,
                words,
                last,
                cap: batch.cap,
                _walk: PhantomData,
            };
            run::<L, _, GT, PACKS>(l, walk, &mut feed, gate);
        } else {
            let walk = Walk::<Faithful, W, _> {
                w,
                words,
                last,
                cap: batch.cap,
                _walk: PhantomData,
            };
            run::<L, _, GT, PACKS>(l, walk, &mut feed, gate);
        }
        Ok(())
    }
}
