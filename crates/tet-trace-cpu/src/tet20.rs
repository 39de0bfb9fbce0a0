//! Tet20 kernel (Aman et al. 2022, §3–4, Algorithms 1, 4, 5).
//!
//! Layout: [`tet_core::layout::Tet20`] = `VX` + four links in the order of the
//! rank of their opposite vertex id (20 bytes). Per step (operation count of
//! the paper): one 4-byte load of `VX^next`, 3 xors for `idx₃`, one 12-byte
//! point load, the projection (f32: 3 subtractions, 6 multiplications, 4
//! additions), the exit face by Algorithm 1 (the paper's two 2-D
//! determinants, 4 multiplications and 2 comparisons, are evaluated here as
//! three branch-free determinants plus an 8-entry table, see
//! [`crate::walk::exit_slot`]), the
//! rank `order_a` of the exit vertex among the four ids (4 comparisons) and
//! one 4-byte link load `N_{order_a}` (Algorithm 5).
//!
//! | paper | code |
//! |---|---|
//! | `idx_0..2`, `p_0..2` | walk state `ids`, `p` |
//! | `VX^next` | [`Topology::vx`](crate::walk::Topology::vx) |
//! | `order_a`, GETNEXTTET20 | [`tet_core::layout::rank_of`], [`Tet20::neighbor_by_rank`] |

use tet_core::layout::{Tet20, Tet20Mesh, rank_of};

use crate::kernel::{WalkRecord, WalkTracer};
use crate::lockstep::exit::{ExitRule, Leaving, Record, decode, rank};
use crate::lockstep::lanes::Lanes;
use crate::walk::{DuffF32, DuffF64};

impl WalkRecord for Tet20 {
    const KERNEL: &'static str = "tet20";
    const PREFETCH: bool = true;
    type Exit = Tet20Exit;
    #[inline(always)]
    fn vx(&self) -> u32 {
        self.vx
    }
    #[inline(always)]
    fn exit_link(&self, f: [u32; 3], d: u32, exiting: u32, _entry: u32) -> u32 {
        self.neighbor_by_rank(rank_of(exiting, [f[0], f[1], f[2], d]))
            .0
    }
}

/// Tet20's exit rule in the lockstep walk's lanes (Algorithm 5): `VX` at
/// word 0 of the record, the link at word `1 + rank(exiting)`.
#[derive(Clone, Copy, Debug)]
pub struct Tet20Exit;

impl ExitRule for Tet20Exit {
    const SPAN: usize = 5;
    type Scratch<L: Lanes> = ();
    #[inline(always)]
    fn enter<L: Lanes>(l: L, rec: &Record<'_, L, Self>, ids: &[L::I; 3]) -> (L::I, ()) {
        (decode(l, ids, rec.word::<0>(l)), ())
    }
    #[inline(always)]
    fn link<L: Lanes>(l: L, rec: &Record<'_, L, Self>, _: (), x: &Leaving<L>) -> L::I {
        let r = rank(l, x.e, [x.ids[0], x.ids[1], x.ids[2], x.d]);
        // SAFETY: `r ≤ 3`, so `1 + r < SPAN`.
        unsafe { rec.word_at(l, l.add_i(l.splat_i(1), r)) }
    }
}

/// Tet20 tracer with projection `P`.
pub type Tet20Tracer<'m, P = DuffF32> = WalkTracer<'m, Tet20Mesh, P>;
/// Tet20 in f64.
pub type Tet20TracerF64<'m> = Tet20Tracer<'m, DuffF64>;
