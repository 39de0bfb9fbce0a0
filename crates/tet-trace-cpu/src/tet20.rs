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
use crate::walk::{DuffF32, DuffF64, ExitRule};

impl WalkRecord for Tet20 {
    const KERNEL: &'static str = "tet20";
    const PREFETCH: bool = true;
    const WORDS: Option<(usize, ExitRule)> = Some((0, ExitRule::Rank { links: 1 }));
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

/// Tet20 tracer with projection `P`.
pub type Tet20Tracer<'m, P = DuffF32> = WalkTracer<'m, Tet20Mesh, P>;
/// Tet20 in f64.
pub type Tet20TracerF64<'m> = Tet20Tracer<'m, DuffF64>;
