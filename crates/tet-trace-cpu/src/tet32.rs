//! Tet32 kernel (Aman et al. 2022, §3–4, Algorithms 1, 2, 3).
//!
//! Layout: [`tet_core::layout::Tet32`] = `V_0, V_1, V_2, VX, N_0..N_3`
//! (32 bytes). The new vertex comes from the xor field like Tet20; the exit
//! link is `N_k` for the slot `k` holding the exit vertex (Algorithm 3: three
//! id comparisons, written as a select chain rather than a variable-indexed
//! stack array, the compiler artefact that slowed the original). Per step:
//! 32-byte record, projection and Algorithm 1 as in [`crate::tet20`].

use tet_core::layout::{Tet32, Tet32Mesh};

use crate::kernel::{WalkRecord, WalkTracer, slot_exit_link};
use crate::lockstep::exit::{ExitRule, Leaving, Record, decode, slot_link};
use crate::lockstep::lanes::Lanes;
use crate::walk::{DuffF32, DuffF64};

impl WalkRecord for Tet32 {
    const KERNEL: &'static str = "tet32";
    const PREFETCH: bool = true;
    type Exit = Tet32Exit;
    #[inline(always)]
    fn vx(&self) -> u32 {
        self.vx
    }
    #[inline(always)]
    fn exit_link(&self, _f: [u32; 3], _d: u32, exiting: u32, _entry: u32) -> u32 {
        slot_exit_link(self.v, self.n, exiting)
    }
}

/// Tet32's exit rule in the lockstep walk's lanes (Algorithm 3): the ids
/// `V_0..V_2` at words 0–2 of the record, `VX` at word 3, the link at word
/// `4 + k` for the slot `k` of the exiting vertex (3 when none of them).
#[derive(Clone, Copy, Debug)]
pub struct Tet32Exit;

impl ExitRule for Tet32Exit {
    const SPAN: usize = 8;
    type Scratch<L: Lanes> = ();
    #[inline(always)]
    fn enter<L: Lanes>(l: L, rec: &Record<'_, L, Self>, ids: &[L::I; 3]) -> (L::I, ()) {
        (decode(l, ids, rec.word::<3>(l)), ())
    }
    #[inline(always)]
    fn link<L: Lanes>(l: L, rec: &Record<'_, L, Self>, _: (), x: &Leaving<L>) -> L::I {
        let vid = [rec.word::<0>(l), rec.word::<1>(l), rec.word::<2>(l)];
        slot_link::<L, Self, 4>(l, rec, vid, x.e)
    }
}

/// Tet32 tracer with projection `P`.
pub type Tet32Tracer<'m, P = DuffF32> = WalkTracer<'m, Tet32Mesh, P>;
/// Tet32 in f64.
pub type Tet32TracerF64<'m> = Tet32Tracer<'m, DuffF64>;
