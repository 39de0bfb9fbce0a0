//! What the walk needs of a layout: its hot connectivity ([`Topology`]),
//! and, for the SIMD lockstep walks, where its records keep `VX` and the
//! links ([`RecordWords`]).

/// The hot connectivity of a layout, as the walk needs it.
pub trait Topology: Sync {
    /// Xor of the four vertex indices of `tet` (paper `VX^i`).
    fn vx(&self, tet: u32) -> u32;
    /// Raw [`Link`](tet_core::Link) of `tet` across the face opposite vertex `exiting`.
    ///
    /// `face` is the entry face, `d` the fourth vertex, `exiting ∈ face`,
    /// `entry_raw` the raw link of `tet` across the entry face (the previous
    /// tet, or the constrained face crossed), which Tet16 needs.
    fn exit_link(&self, tet: u32, face: [u32; 3], d: u32, exiting: u32, entry_raw: u32) -> u32;
    /// Hints that the record of `tet` (an index that may be out of range:
    /// a prefetch never faults) will be read soon. Default: nothing.
    #[inline(always)]
    fn prefetch(&self, tet: u32) {
        let _ = tet;
    }
    /// The records as 32-bit words for the gathers of the SIMD lockstep walk
    /// ([`crate::lockstep`]); `None` (the default) makes it read them through
    /// [`Topology::vx`] and [`Topology::exit_link`] lane by lane.
    #[inline(always)]
    fn record_words(&self) -> Option<RecordWords<'_>> {
        None
    }
}

/// Prefetches the cache line holding `slice[index]` into all cache levels
/// (x86-64 `prefetcht0`; nothing elsewhere). Never reads memory
/// architecturally, so an out-of-range index is harmless: the address is
/// formed with `wrapping_add` and never dereferenced.
#[inline(always)]
pub fn prefetch_index<X>(slice: &[X], index: u32) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        let ptr = slice.as_ptr().wrapping_add(index as usize) as *const i8;
        // SAFETY: `prefetcht0` is a hint; it never faults and has no
        // architectural effect, whatever the address (SSE is part of the
        // x86-64 baseline).
        unsafe { _mm_prefetch::<_MM_HINT_T0>(ptr) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = (slice, index);
    }
}

/// How the lockstep walk finds a tet's exit link among its record's 32-bit
/// words (offsets in words within a record).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExitRule {
    /// Tet20 (Algorithm 5): the link at word `links + rank(exiting)`.
    Rank {
        /// Word of the rank-0 link.
        links: usize,
    },
    /// Tet16 (Algorithm 7): `entry ⊕ NX(rank(idx₃)) ⊕ NX(rank(exiting))`
    /// with `NX_r` at word `links + r` and `NX_3 = 0`.
    RankXor {
        /// Word of `NX_0`.
        links: usize,
    },
    /// Tet32 (Algorithm 3): the slot `k` of the exiting vertex among the ids
    /// at words `ids..ids + 3` (3 when none of them), link at `links + k`.
    Slot {
        /// Word of the slot-0 vertex id.
        ids: usize,
        /// Word of the slot-0 link.
        links: usize,
    },
    /// The 32-byte baseline (ScTP): no `VX` word; the new vertex is the one
    /// of the four ids at words `ids..ids + 4` not on the entry face, the
    /// link that of the exiting vertex's slot among the first three (3:
    /// none), at `links + slot`. Walked by ScTP's lockstep walk (`crate::lockstep`, `IDS` rule) only.
    Ids {
        /// Word of the slot-0 vertex id.
        ids: usize,
        /// Word of the slot-0 link.
        links: usize,
    },
}

/// A layout's records as 32-bit words, for the gathers of the AVX2 lockstep
/// walk ([`crate::walk::Topology::record_words`]).
#[derive(Clone, Copy, Debug)]
pub struct RecordWords<'a> {
    /// All records, word by word (`stride` words per tet).
    pub words: &'a [u32],
    /// Words per record.
    pub stride: usize,
    /// Word of `VX` within a record.
    pub vx: usize,
    /// Where the exit link is.
    pub rule: ExitRule,
}

impl RecordWords<'_> {
    /// True when every gather index the walk can form fits in an `i32` and
    /// stays inside a record (`next` and the decoded vertex are clamped to
    /// the arrays, ranks and slots to 0..=3).
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    pub(crate) fn gatherable(&self, points: usize) -> bool {
        let s = self.stride;
        let inside = match self.rule {
            ExitRule::Rank { links } => links + 3 < s,
            ExitRule::RankXor { links } => links + 2 < s,
            ExitRule::Slot { ids, links } => ids + 2 < s && links + 3 < s,
            ExitRule::Ids { ids, links } => ids + 3 < s && links + 3 < s,
        };
        inside
            && self.vx < s
            && s > 0
            && self.words.len().is_multiple_of(s)
            && !self.words.is_empty()
            && self.words.len() <= i32::MAX as usize
            && points > 0
            && points <= i32::MAX as usize / 3
    }
}
