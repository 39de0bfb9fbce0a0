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
use crate::walk::{DuffF32, DuffF64, ExitRule};

impl WalkRecord for Tet16 {
    const KERNEL: &'static str = "tet16";
    const PREFETCH: bool = true;
    const WORDS: Option<(usize, ExitRule)> = Some((0, ExitRule::RankXor { links: 1 }));
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

/// Tet16 tracer with projection `P`.
pub type Tet16Tracer<'m, P = DuffF32> = WalkTracer<'m, Tet16Mesh, P>;
/// Tet16 in f64.
pub type Tet16TracerF64<'m> = Tet16Tracer<'m, DuffF64>;
