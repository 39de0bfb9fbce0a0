//! What the walk needs of a layout: its hot connectivity ([`Topology`]),
//! and, for the SIMD lockstep walks, its records as words and their exit
//! rule ([`crate::lockstep::ExitRule`]).

use crate::lockstep::exit::{ExitRule, RecordWords};

/// The hot connectivity of a layout, as the walk needs it.
pub trait Topology: Sync {
    /// How the SIMD lockstep walk finds the new vertex and the exit link in
    /// the [`Topology::record_words`]: the layout's rule (its record
    /// type's `WalkRecord::Exit`), or [`crate::lockstep::ByLane`] for
    /// records it reads through [`Topology::vx`] and
    /// [`Topology::exit_link`] lane by lane.
    type Exit: ExitRule;
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
    /// ([`crate::lockstep`]), read with [`Topology::Exit`]; `None` (the
    /// default): not gathered.
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
