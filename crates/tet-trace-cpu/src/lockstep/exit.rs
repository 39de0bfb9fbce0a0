//! How a round reads a layout ([`Records`]): the new vertex of the tet a
//! lane enters and the link of the face it leaves through. Gathered from
//! the record words ([`Gathered`], with the exit rules of Tet20, Tet16,
//! Tet32 and ScTP, see [`ExitRule`]) or read lane by lane through
//! [`Topology`] ([`PerLane`], the portable fallback).

use tet_core::TetMesh;

use super::lanes::Lanes;
use crate::walk::topology::{ExitRule, RecordWords, Topology};

/// The record reads of a lockstep round over lanes `L`.
pub(crate) trait Records<L: Lanes> {
    /// What [`Records::link`] needs of [`Records::enter`].
    type Scratch: Copy;
    /// The new vertex `idx₃` of tet `next` (unchecked: a corrupt record can
    /// give any value), entered through the face `ids`.
    fn enter(&self, l: L, next: L::I, ids: &[L::I; 3]) -> (L::I, Self::Scratch);
    /// The raw link of tet `next` across the face opposite `e`, the exiting
    /// vertex (`d` the new vertex, `entry` the raw link entered through).
    #[allow(clippy::too_many_arguments)]
    fn link(
        &self,
        l: L,
        s: Self::Scratch,
        next: L::I,
        ids: &[L::I; 3],
        d: L::I,
        e: L::I,
        entry: L::I,
    ) -> L::I;
    /// Hints that the records of the tets `link` (some out of range) will
    /// be read next round.
    #[inline(always)]
    fn prefetch(&self, l: L, link: L::I) {
        let _ = (l, link);
    }
}

/// Reads through [`Topology::vx`] and [`Topology::exit_link`] lane by lane.
pub(crate) struct PerLane<'a, T>(pub(crate) &'a T);

impl<L: Lanes, T: Topology> Records<L> for PerLane<'_, T> {
    type Scratch = ();

    #[inline(always)]
    fn enter(&self, l: L, next: L::I, ids: &[L::I; 3]) -> (L::I, ()) {
        let mut vx = L::i_lanes(next);
        for v in vx.as_mut() {
            *v = self.0.vx(*v);
        }
        let f = l.xor_i(l.xor_i(ids[0], ids[1]), ids[2]);
        // The lanes of `vx` into a vector: `f ⊕ vx` lane by lane.
        let mut d = L::i_lanes(f);
        for (d, v) in d.as_mut().iter_mut().zip(vx.as_ref()) {
            *d ^= v;
        }
        (from_lanes(l, d), ())
    }
    #[inline(always)]
    fn link(
        &self,
        l: L,
        _: (),
        next: L::I,
        ids: &[L::I; 3],
        d: L::I,
        e: L::I,
        entry: L::I,
    ) -> L::I {
        let (next, d, e, entry) = (
            L::i_lanes(next),
            L::i_lanes(d),
            L::i_lanes(e),
            L::i_lanes(entry),
        );
        let ids = ids.map(L::i_lanes);
        let mut raw = L::arr(0u32);
        for (k, r) in raw.as_mut().iter_mut().enumerate() {
            let face = [ids[0].as_ref()[k], ids[1].as_ref()[k], ids[2].as_ref()[k]];
            let at = |x: &L::Arr<u32>| x.as_ref()[k];
            *r = self
                .0
                .exit_link(at(&next), face, at(&d), at(&e), at(&entry));
        }
        from_lanes(l, raw)
    }
    #[inline(always)]
    fn prefetch(&self, _: L, link: L::I) {
        // A prefetch never faults: parked and stopped lanes prefetch harmlessly.
        for &r in L::i_lanes(link).as_ref() {
            self.0.prefetch(r);
        }
    }
}

/// The vector of the lanes `a`.
#[inline(always)]
fn from_lanes<L: Lanes>(l: L, a: L::Arr<u32>) -> L::I {
    let mut x = l.splat_i(0);
    for (k, &v) in a.as_ref().iter().enumerate() {
        x = l.set_i(x, k, v);
    }
    x
}

/// Array bases and bounds of the gathers.
#[derive(Clone, Copy)]
pub(crate) struct Geo<'a> {
    words: &'a [u32],
    last_tet: u32,
    stride: u32,
    vx: u32,
    ids: u32,
    links: u32,
}

impl<'a> Geo<'a> {
    /// The gathers' view of `mesh`'s records `rw`, when they are
    /// [`RecordWords::gatherable`] (the gathers' bounds rest on it).
    pub(crate) fn new(mesh: &TetMesh, rw: &RecordWords<'a>) -> Option<Geo<'a>> {
        if !rw.gatherable(mesh.points.len()) {
            return None;
        }
        let (ids, links) = match rw.rule {
            ExitRule::Rank { links } | ExitRule::RankXor { links } => (0, links),
            ExitRule::Slot { ids, links } | ExitRule::Ids { ids, links } => (ids, links),
        };
        Some(Geo {
            words: rw.words,
            last_tet: (rw.words.len() / rw.stride - 1) as u32,
            stride: rw.stride as u32,
            vx: rw.vx as u32,
            ids: ids as u32,
            links: links as u32,
        })
    }

    /// Word `k` of the records of tets `min(next, last_tet)` (`base`, see
    /// [`Geo::base`]).
    #[inline(always)]
    fn word<L: Lanes>(&self, l: L, base: L::I, k: L::I) -> L::I {
        // SAFETY: `base = min(next, last_tet) · stride` and every caller's
        // `k < stride` (its offset plus a rank or slot ≤ 3, within the
        // record by `RecordWords::gatherable`), so each lane reads a word
        // inside `words` (whose length is `(last_tet + 1) · stride < 2³¹`).
        unsafe { l.gather_words(self.words, l.add_i(base, k)) }
    }

    /// Tet16's `NX_r` (word `links + r`), 0 for rank 3: those lanes read
    /// word 0 of the record (in range) and drop it.
    #[inline(always)]
    fn nx<L: Lanes>(&self, l: L, base: L::I, r: L::I) -> L::I {
        let m = l.gt_i(l.splat_i(3), r);
        let k = l.select_i(m, l.add_i(l.splat_i(self.links), r), l.splat_i(0));
        l.zero_unless(m, self.word(l, base, k))
    }

    /// The first word of the records of tets `next` (clamped to the last).
    #[inline(always)]
    fn base<L: Lanes>(&self, l: L, next: L::I) -> L::I {
        let tet = l.min_u(next, l.splat_i(self.last_tet));
        l.mul_i(tet, l.splat_i(self.stride))
    }
}

/// The gathered exit rules, the `RULE` of [`Gathered`].
pub(crate) const RANK: u8 = 0;
/// See [`RANK`].
pub(crate) const RANK_XOR: u8 = 1;
/// See [`RANK`].
pub(crate) const SLOT: u8 = 2;
/// See [`RANK`].
pub(crate) const IDS: u8 = 3;

/// Gathers from the record words with exit rule `RULE`: [`RANK`] (Tet20,
/// Algorithm 5), [`RANK_XOR`] (Tet16, Algorithm 7), [`SLOT`] (Tet32,
/// Algorithm 3), all three decoding `idx₃ = idx₀ ⊕ idx₁ ⊕ idx₂ ⊕ VX`; or
/// [`IDS`] (ScTP's baseline records, no `VX`: the new vertex is
/// `v₀ ⊕ v₁ ⊕ v₂ ⊕ v₃ ⊕ idx₀ ⊕ idx₁ ⊕ idx₂`, the link found by the slot of
/// the exiting vertex among the gathered ids).
pub(crate) struct Gathered<'a, const RULE: u8>(pub(crate) Geo<'a>);

/// `min(rank of x among of, 3)`. Ids are < 2³¹ (`gatherable`), so signed
/// compares order them.
#[inline(always)]
fn rank<L: Lanes>(l: L, x: L::I, of: [L::I; 4]) -> L::I {
    let mut r = l.splat_i(0);
    for y in of {
        r = l.inc(r, l.gt_i(x, y));
    }
    l.min_u(r, l.splat_i(3))
}

/// The slot of `e` among `vid` (3 when none), the link at `links + slot`.
#[inline(always)]
fn slot_link<L: Lanes>(l: L, g: &Geo<'_>, base: L::I, vid: [L::I; 3], e: L::I) -> L::I {
    let mut slot = l.splat_i(3);
    for k in (0..3).rev() {
        slot = l.select_i(l.eq_i(e, vid[k]), l.splat_i(k as u32), slot);
    }
    g.word(l, base, l.add_i(slot, l.splat_i(g.links)))
}

impl<L: Lanes, const RULE: u8> Records<L> for Gathered<'_, RULE> {
    /// The records' first words, and (for [`IDS`]) the first three ids.
    type Scratch = (L::I, [L::I; 3]);

    #[inline(always)]
    fn enter(&self, l: L, next: L::I, ids: &[L::I; 3]) -> (L::I, Self::Scratch) {
        let g = &self.0;
        let base = g.base(l, next);
        let face = l.xor_i(ids[0], ids[1]);
        if RULE == IDS {
            let v = [
                g.word(l, base, l.splat_i(g.ids)),
                g.word(l, base, l.splat_i(g.ids + 1)),
                g.word(l, base, l.splat_i(g.ids + 2)),
                g.word(l, base, l.splat_i(g.ids + 3)),
            ];
            let d = l.xor_i(
                l.xor_i(l.xor_i(v[0], v[1]), l.xor_i(v[2], v[3])),
                l.xor_i(face, ids[2]),
            );
            (d, (base, [v[0], v[1], v[2]]))
        } else {
            let vx = g.word(l, base, l.splat_i(g.vx));
            let d = l.xor_i(face, l.xor_i(ids[2], vx));
            (d, (base, [base; 3]))
        }
    }
    #[inline(always)]
    fn link(
        &self,
        l: L,
        (base, vid): Self::Scratch,
        _: L::I,
        ids: &[L::I; 3],
        d: L::I,
        e: L::I,
        entry: L::I,
    ) -> L::I {
        let g = &self.0;
        let links = l.splat_i(g.links);
        // (No closures over lane operations: see `walk`.)
        match RULE {
            RANK => {
                let r = rank(l, e, [ids[0], ids[1], ids[2], d]);
                g.word(l, base, l.add_i(links, r))
            }
            RANK_XOR => {
                // `rank(d)` among the entry face (d itself never counts).
                let rd = rank(l, d, [ids[0], ids[1], ids[2], d]);
                let re = rank(l, e, [ids[0], ids[1], ids[2], d]);
                let (nd, ne) = (g.nx(l, base, rd), g.nx(l, base, re));
                l.xor_i(l.xor_i(entry, nd), ne)
            }
            SLOT => {
                let vid = [
                    g.word(l, base, l.splat_i(g.ids)),
                    g.word(l, base, l.splat_i(g.ids + 1)),
                    g.word(l, base, l.splat_i(g.ids + 2)),
                ];
                slot_link(l, g, base, vid, e)
            }
            _ => slot_link(l, g, base, vid, e),
        }
    }
}
