//! The exit rule as a type ([`ExitRule`]): how the lockstep walk finds, in
//! a layout's records gathered as 32-bit words ([`RecordWords`]), the new
//! vertex of the tet a lane enters and the link of the face it leaves
//! through. Each layout's kernel module defines one zero-sized rule, which
//! its record type names (`WalkRecord::Exit`, and so `Topology::Exit`):
//! `Tet20Exit` (Algorithm 5, [`crate::tet20`]), `Tet16Exit` (Algorithm 7,
//! [`crate::tet16`]), `Tet32Exit` (Algorithm 3, [`crate::tet32`]),
//! `Baseline32Exit` (ScTP's four ids, [`crate::sctp`]); [`ByLane`] for
//! layouts whose records are not gathered. [`Gathered`] makes a rule the
//! walk's record reads ([`Records`]); the other reads go lane by lane
//! through `Topology` (`PerLane`, in `projected`).

use std::marker::PhantomData;

use tet_core::TetMesh;

use super::lanes::Lanes;

/// A layout's records as 32-bit words, for the gathers of the SIMD
/// lockstep walk ([`crate::walk::Topology::record_words`]).
#[derive(Clone, Copy, Debug)]
pub struct RecordWords<'a> {
    /// All records, word by word (`stride` words per tet).
    pub words: &'a [u32],
    /// Words per record.
    pub stride: usize,
}

impl RecordWords<'_> {
    /// True when every gather index the walk can form with rule `E` fits
    /// in an `i32` and stays inside a record (`next` and the decoded
    /// vertex are clamped to the arrays, the rule's words to its
    /// [`ExitRule::SPAN`]).
    pub(crate) fn gatherable<E: ExitRule>(&self, points: usize) -> bool {
        let s = self.stride;
        E::SPAN <= s
            && s > 0
            && self.words.len().is_multiple_of(s)
            && !self.words.is_empty()
            && self.words.len() <= i32::MAX as usize
            && points > 0
            && points <= i32::MAX as usize / 3
    }
}

/// A layout's exit rule in lanes: the new vertex `idx₃` of the tet each
/// lane enters, and the raw link across the face it leaves through, read
/// from the words of its record (`Record`). One zero-sized type per
/// layout, defined beside its scalar `exit_link` in its kernel module.
pub trait ExitRule: Sized + 'static {
    /// One past the last word of a record the rule reads: the stride of
    /// the records must be at least this for the walk to gather them
    /// (checked once per batch). `usize::MAX` for [`ByLane`]: never.
    const SPAN: usize;
    /// What [`ExitRule::link`] needs of [`ExitRule::enter`] (ScTP's ids).
    type Scratch<L: Lanes>: Copy;
    /// `idx₃` of the lanes' tets (`rec`), entered through the face `ids`
    /// (unchecked: a corrupt record can give any value).
    fn enter<L: Lanes>(
        l: L,
        rec: &Record<'_, L, Self>,
        ids: &[L::I; 3],
    ) -> (L::I, Self::Scratch<L>);
    /// The raw link of the lanes' tets (`rec`) across the face opposite
    /// the exiting vertex `x.e`.
    fn link<L: Lanes>(l: L, rec: &Record<'_, L, Self>, s: Self::Scratch<L>, x: &Leaving<L>)
    -> L::I;
}

/// What a lane's exit link depends on: the tet it leaves (`next`, the one
/// it entered this round), the entry face's ids, the new vertex `d`, the
/// exiting vertex `e` and the raw link it entered through.
#[derive(Clone, Copy)]
pub struct Leaving<L: Lanes> {
    /// The tet left.
    pub next: L::I,
    /// The entry face's vertex ids.
    pub ids: [L::I; 3],
    /// The new vertex `idx₃`.
    pub d: L::I,
    /// The exiting vertex (one of `ids`).
    pub e: L::I,
    /// The raw link the tet was entered through.
    pub entry: L::I,
}

/// The records of the tets the lanes are in, as rule `E` reads them.
pub struct Record<'a, L: Lanes, E> {
    geo: &'a Geo<'a>,
    /// The first word of each lane's record.
    base: L::I,
    _rule: PhantomData<fn() -> E>,
}

impl<L: Lanes, E: ExitRule> Record<'_, L, E> {
    /// Word `K` of each lane's record (`K < E::SPAN`, checked at compile
    /// time).
    #[inline(always)]
    pub fn word<const K: u32>(&self, l: L) -> L::I {
        const { assert!((K as usize) < E::SPAN, "a word past the rule's span") };
        // SAFETY: `K < E::SPAN` in every lane.
        unsafe { self.word_at(l, l.splat_i(K)) }
    }

    /// Word `k` of each lane's record.
    ///
    /// # Safety
    ///
    /// Every lane of `k` must be below `E::SPAN`.
    #[inline(always)]
    pub unsafe fn word_at(&self, l: L, k: L::I) -> L::I {
        // SAFETY: `base = min(next, last_tet) · stride` and `k < E::SPAN ≤
        // stride` (the caller's contract, `RecordWords::gatherable`), so
        // each lane reads a word inside `words` (whose length is
        // `(last_tet + 1) · stride < 2³¹`).
        unsafe { l.gather_words(self.geo.words, l.add_i(self.base, k)) }
    }
}

/// The new vertex of a layout that keeps `VX`: `idx₃ = idx₀ ⊕ idx₁ ⊕ idx₂
/// ⊕ VX` (Tet20, Tet16, Tet32).
#[inline(always)]
pub fn decode<L: Lanes>(l: L, ids: &[L::I; 3], vx: L::I) -> L::I {
    let face = l.xor_i(ids[0], ids[1]);
    l.xor_i(face, l.xor_i(ids[2], vx))
}

/// `min(rank of x among of, 3)`. Ids are < 2³¹ (`gatherable`), so signed
/// compares order them.
#[inline(always)]
pub fn rank<L: Lanes>(l: L, x: L::I, of: [L::I; 4]) -> L::I {
    let mut r = l.splat_i(0);
    for y in of {
        r = l.inc(r, l.gt_i(x, y));
    }
    l.min_u(r, l.splat_i(3))
}

/// Algorithm 3 in lanes: the slot of `e` among the ids `vid` (3 when
/// none), the link at word `LINKS + slot`.
#[inline(always)]
pub fn slot_link<L: Lanes, E: ExitRule, const LINKS: u32>(
    l: L,
    rec: &Record<'_, L, E>,
    vid: [L::I; 3],
    e: L::I,
) -> L::I {
    const { assert!(LINKS as usize + 3 < E::SPAN, "links past the rule's span") };
    let mut slot = l.splat_i(3);
    for k in (0..3).rev() {
        slot = l.select_i(l.eq_i(e, vid[k]), l.splat_i(k as u32), slot);
    }
    // SAFETY: `slot ≤ 3`, so `LINKS + slot < E::SPAN`.
    unsafe { rec.word_at(l, l.add_i(slot, l.splat_i(LINKS))) }
}

/// The exit rule of records the lockstep walk does not gather (a
/// [`Topology`](crate::walk::Topology) that is not a layout of this crate:
/// the mesh itself, a walk stopped at given tets): read lane by lane.
pub enum ByLane {}

impl ExitRule for ByLane {
    const SPAN: usize = usize::MAX;
    type Scratch<L: Lanes> = ();
    fn enter<L: Lanes>(_: L, _: &Record<'_, L, Self>, _: &[L::I; 3]) -> (L::I, ()) {
        unreachable!("no record has usize::MAX words: never gathered")
    }
    fn link<L: Lanes>(_: L, _: &Record<'_, L, Self>, _: (), _: &Leaving<L>) -> L::I {
        unreachable!("no record has usize::MAX words: never gathered")
    }
}

/// The record reads of a lockstep round over lanes `L`.
pub(crate) trait Records<L: Lanes> {
    /// What [`Records::link`] needs of [`Records::enter`].
    type Scratch: Copy;
    /// The new vertex `idx₃` of tet `next` (unchecked: a corrupt record can
    /// give any value), entered through the face `ids`.
    fn enter(&self, l: L, next: L::I, ids: &[L::I; 3]) -> (L::I, Self::Scratch);
    /// The raw link of tet `x.next` across the face opposite `x.e`.
    fn link(&self, l: L, s: Self::Scratch, x: &Leaving<L>) -> L::I;
    /// Hints that the records of the tets `link` (some out of range) will
    /// be read next round.
    #[inline(always)]
    fn prefetch(&self, l: L, link: L::I) {
        let _ = (l, link);
    }
}

/// Array bases and bounds of the gathers.
#[derive(Clone, Copy)]
pub(crate) struct Geo<'a> {
    words: &'a [u32],
    last_tet: u32,
    stride: u32,
}

impl<'a> Geo<'a> {
    /// The gathers' view of `mesh`'s records `rw` read with rule `E`, when
    /// they are [`RecordWords::gatherable`] (the gathers' bounds rest on it).
    pub(crate) fn new<E: ExitRule>(mesh: &TetMesh, rw: &RecordWords<'a>) -> Option<Geo<'a>> {
        if !rw.gatherable::<E>(mesh.points.len()) {
            return None;
        }
        Some(Geo {
            words: rw.words,
            last_tet: (rw.words.len() / rw.stride - 1) as u32,
            stride: rw.stride as u32,
        })
    }

    /// The records of tets `next` (clamped to the last).
    #[inline(always)]
    fn record<L: Lanes, E: ExitRule>(&self, l: L, next: L::I) -> Record<'_, L, E> {
        let tet = l.min_u(next, l.splat_i(self.last_tet));
        Record {
            geo: self,
            base: l.mul_i(tet, l.splat_i(self.stride)),
            _rule: PhantomData,
        }
    }
}

/// Gathers from the record words with exit rule `E`.
pub(crate) struct Gathered<'a, E>(pub(crate) Geo<'a>, pub(crate) PhantomData<fn() -> E>);

impl<E> Clone for Gathered<'_, E> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<E> Copy for Gathered<'_, E> {}

impl<L: Lanes, E: ExitRule> Records<L> for Gathered<'_, E> {
    /// The records' first words, and what the rule keeps.
    type Scratch = (L::I, E::Scratch<L>);

    #[inline(always)]
    fn enter(&self, l: L, next: L::I, ids: &[L::I; 3]) -> (L::I, Self::Scratch) {
        let rec = self.0.record::<L, E>(l, next);
        let (d, s) = E::enter(l, &rec, ids);
        (d, (rec.base, s))
    }
    #[inline(always)]
    fn link(&self, l: L, (base, s): Self::Scratch, x: &Leaving<L>) -> L::I {
        let rec = Record {
            geo: &self.0,
            base,
            _rule: PhantomData,
        };
        E::link(l, &rec, s, x)
    }
}
