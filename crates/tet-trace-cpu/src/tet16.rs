//! Tet16 kernel (Aman et al. 2022, §3–4, Algorithms 1, 6, 7).
//!
//! Layout: [`tet_core::layout::Tet16`] = `VX` + `NX_k = N_k ⊕ N_3` for the
//! rank-ordered links (16 bytes). The link across the exit face is rebuilt
//! from the link the walk entered through (paper `prev_tet_idx`; the raw
//! constrained link when a secondary ray restarts behind a constrained
//! face): `N_b = N_a ⊕ NX_a ⊕ NX_b` with `NX_3 = 0`, where `order_a` is the
//! rank of the new vertex `idx₃` (opposite the entry face) and `order_b` the
//! rank of the exit vertex. Per step: as [`crate::tet20`] plus one more rank
//! (4 comparisons) and two xors; the record load is 16 bytes.

use tet_core::layout::{Tet16, Tet16Mesh, rank_of};

use crate::kernel::{WalkRecord, WalkTracer};
use crate::lockstep::exit::{ExitRule, Leaving, Record, decode, rank};
use crate::lockstep::lanes::Lanes;
use crate::walk::{DuffF32, DuffF64};

impl WalkRecord for Tet16 {
    const KERNEL: &'static str = "tet16";
    const PREFETCH: bool = true;
    type Exit = Tet16Exit;
    #[inline(always)]
    fn vx(&self) -> u32 {
        self.vx
    }
    #[inline(always)]
    fn exit_link(&self, f: [u32; 3], d: u32, exiting: u32, entry: u32) -> u32 {
        let nx = &self.nx;
        let ids = [f[0], f[1], f[2], d];
        // `NX_3 = 0` (Tet16::nx4) as a select: no stack array to index.
        let pick = |rank: usize| if rank < 3 { nx[rank] } else { 0 };
        entry ^ pick(rank_of(d, ids)) ^ pick(rank_of(exiting, ids))
    }
}

/// Tet16's exit rule in the lockstep walk's lanes (Algorithm 7): `VX` at
/// word 0 of the record, `NX_r` at word `1 + r` (`NX_3 = 0`), the link
/// `entry ⊕ NX(rank(idx₃)) ⊕ NX(rank(exiting))`.
#[derive(Clone, Copy, Debug)]
pub struct Tet16Exit;

impl Tet16Exit {
    /// `NX_r` of the lanes' records, 0 for rank 3: those lanes read word 0
    /// of the record (in range) and drop it.
    #[inline(always)]
    fn nx<L: Lanes>(l: L, rec: &Record<'_, L, Self>, r: L::I) -> L::I {
        let m = l.gt_i(l.splat_i(3), r);
        let k = l.select_i(m, l.add_i(l.splat_i(1), r), l.splat_i(0));
        // SAFETY: `k ≤ 1 + 2 < SPAN`, or 0.
        l.zero_unless(m, unsafe { rec.word_at(l, k) })
    }
}

impl ExitRule for Tet16Exit {
    const SPAN: usize = 4;
    type Scratch<L: Lanes> = ();
    #[inline(always)]
    fn enter<L: Lanes>(l: L, rec: &Record<'_, L, Self>, ids: &[L::I; 3]) -> (L::I, ()) {
        (decode(l, ids, rec.word::<0>(l)), ())
    }
    #[inline(always)]
    fn link<L: Lanes>(l: L, rec: &Record<'_, L, Self>, _: (), x: &Leaving<L>) -> L::I {
        // `rank(d)` among the entry face (d itself never counts).
        let of = [x.ids[0], x.ids[1], x.ids[2], x.d];
        let (rd, re) = (rank(l, x.d, of), rank(l, x.e, of));
        let (nd, ne) = (Self::nx(l, rec, rd), Self::nx(l, rec, re));
        l.xor_i(l.xor_i(x.entry, nd), ne)
    }
}

/// Tet16 tracer with projection `P`.
pub type Tet16Tracer<'m, P = DuffF32> = WalkTracer<'m, Tet16Mesh, P>;
/// Tet16 in f64.
pub type Tet16TracerF64<'m> = Tet16Tracer<'m, DuffF64>;
