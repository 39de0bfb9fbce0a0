//! ScTP kernel: scalar triple products on the 32-byte baseline layout
//! (Lagae & Dutré 2008, as summarised in Aman et al. (2022) §2 and Maria et al. (2017) §2).
//!
//! Layout: [`tet_core::layout::Baseline32`] = four vertex ids + four links.
//! The ray passes left of edge `a → b` when `d · ((Pa − o) × (Pb − o)) > 0`
//! (a scalar triple product, [`TripleF32`]); Lagae & Dutré need 3–6 of them
//! per tet without the entry face. Using the entry face (whose three edge
//! signs are known from the previous tet), the exit face needs two
//! (Algorithm 1 of Aman et al. (2022) on the triple-product signs, the same decision
//! procedure as the 2-D walk; the engine evaluates a third one to stay
//! branch-free, see [`crate::walk::exit_slot`]): per step one 12-byte point
//! load, 3 subtractions, three triple products (each 6 mul + 3 sub for the
//! cross product, 3 mul + 2 add for the dot), and the link of the exit
//! vertex's slot. The original neptun ScTP
//! ignored the entry face; this one does not. Zero is decided by an
//! antisymmetric tie rule ([`TripleF32`]), so every edge gets one answer in
//! every tet; but `d · (q × q')` cancels catastrophically when the ray passes
//! near a vertex (both `q` are nearly parallel to `d`), so the f32 answers
//! are not realisable by any line there: rays aimed at vertices can end on a
//! wrong face or loop to the step cap (reported as a failure). The 2-D
//! projection removes the `d` component before multiplying and does not
//! suffer from this (see the robustness census in `tests/robustness.rs`).
//!
//! Batches (a tile of primary rays) walk 16 rays in AVX-512 lockstep where
//! the CPU has AVX-512F ([`crate::lockstep`], the same decisions bit for
//! bit), several times faster than the scalar interleaved walk that serves
//! them elsewhere.

use tet_core::layout::{Baseline32, Baseline32Mesh};

use crate::kernel::{WalkRecord, WalkTracer, slot_exit_link};
use crate::lockstep::exit::{ExitRule, Leaving, Record, slot_link};
use crate::lockstep::lanes::Lanes;
use crate::walk::TripleF32;

impl WalkRecord for Baseline32 {
    const KERNEL: &'static str = "sctp";
    const PREFETCH: bool = false;
    type Exit = Baseline32Exit;
    #[inline(always)]
    fn vx(&self) -> u32 {
        let v = self.v;
        v[0] ^ v[1] ^ v[2] ^ v[3]
    }
    #[inline(always)]
    fn exit_link(&self, _f: [u32; 3], _d: u32, exiting: u32, _entry: u32) -> u32 {
        slot_exit_link([self.v[0], self.v[1], self.v[2]], self.n, exiting)
    }
}

/// The 32-byte baseline's exit rule in the lockstep walk's lanes: the
/// four ids at words 0–3 of the record (no `VX`: the new vertex is the one
/// not on the entry face, `v₀ ⊕ v₁ ⊕ v₂ ⊕ v₃ ⊕ idx₀ ⊕ idx₁ ⊕ idx₂`), the
/// link at word `4 + k` for the slot `k` of the exiting vertex among the
/// first three (3 when none of them, Algorithm 3).
#[derive(Clone, Copy, Debug)]
pub struct Baseline32Exit;

impl ExitRule for Baseline32Exit {
    const SPAN: usize = 8;
    /// The ids of slots 0–2.
    type Scratch<L: Lanes> = [L::I; 3];
    #[inline(always)]
    fn enter<L: Lanes>(l: L, rec: &Record<'_, L, Self>, ids: &[L::I; 3]) -> (L::I, [L::I; 3]) {
        let face = l.xor_i(ids[0], ids[1]);
        let v = [
            rec.word::<0>(l),
            rec.word::<1>(l),
            rec.word::<2>(l),
            rec.word::<3>(l),
        ];
        let d = l.xor_i(
            l.xor_i(l.xor_i(v[0], v[1]), l.xor_i(v[2], v[3])),
            l.xor_i(face, ids[2]),
        );
        (d, [v[0], v[1], v[2]])
    }
    #[inline(always)]
    fn link<L: Lanes>(l: L, rec: &Record<'_, L, Self>, vid: [L::I; 3], x: &Leaving<L>) -> L::I {
        slot_link::<L, Self, 4>(l, rec, vid, x.e)
    }
}

/// ScTP tracer (default: f32 triple products).
pub type SctpTracer<'m, P = TripleF32> = WalkTracer<'m, Baseline32Mesh, P>;
