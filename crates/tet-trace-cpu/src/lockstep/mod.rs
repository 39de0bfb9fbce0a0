//! SIMD lockstep walk: `W` rays of one batch walk side by side, one ray per
//! SIMD lane, one tet per lane per round. This is the
//! [`Tracer::trace_batch`](crate::Tracer::trace_batch) of every projected
//! kernel with [`DuffF32`](crate::DuffF32) (Tet20, Tet16, Tet32); the scalar walks
//! ([`crate::walk::trace`], [`crate::walk::trace_interleaved`], reachable as
//! [`crate::kernel::Interleaved`]) stay as the reference.
//!
//! Each round every lane fetches `VX` of the tet it enters, decodes the new
//! vertex `idx₃ = idx₀ ⊕ idx₁ ⊕ idx₂ ⊕ VX` and fetches its point; the
//! projection of `idx₃` ([`DuffF32`](crate::DuffF32): `p = (u·(P−o), v·(P−o))`), the three
//! edge determinants `det(p₃, pᵢ)` of Algorithm 1, the exit slot
//! ([`crate::walk::EXIT_SLOT`]), the replacement of the exiting vertex and the
//! exit link (rank of the exit vertex for Tet20 — Algorithm 5 —, two ranks
//! and two xors for Tet16 — Algorithm 7 —, the slot compare for Tet32 —
//! Algorithm 3 —, see [`ExitRule`]) run across the lanes as SIMD arithmetic,
//! compares and blends: no branches and no variable-indexed stores. A lane
//! that needs a rare path (a constrained face or the boundary, the step cap,
//! a decoded vertex out of range) takes the scalar engine's cold path (the
//! same ending, crossing and refill for every width); a finished lane is
//! refilled at once from the batch, so lanes idle only at the batch's tail.
//!
//! # Dispatch
//!
//! * x86-64 with AVX-512F (detected at run time) and a layout that exposes
//!   its records as words: the same walk with 16 lanes, 512-bit vectors and
//!   mask registers (`avx512`), two packs in flight, faster than the AVX2
//!   walk. `TET_LOCKSTEP=avx2` in the environment keeps the AVX2 walk, for
//!   same-machine comparisons;
//! * x86-64 with AVX2 (detected at run time) and a layout that exposes its
//!   records as words ([`crate::walk::Topology::record_words`]): 8-lane AVX2
//!   intrinsics, all five loads of a step (`VX`, the point's x, y, z, the
//!   link) as `vpgatherdd`/`vgatherdps`, two packs of 8 lanes in flight per
//!   thread so that the core overlaps their gather chains;
//! * x86-64 with AVX2, other layouts: the portable lane loops compiled
//!   for AVX2 (8 lanes, scalar loads through [`Topology`]);
//! * otherwise: the portable lane loops with 4 lanes on the baseline target
//!   (SSE2 on x86-64), [`trace_lockstep_portable`].
//!
//! Why intrinsics and `unsafe`: the same lane loops left to the
//! auto-vectoriser (the portable path compiled for AVX2, 8 lanes) run more
//! instructions per step than the scalar interleaved walk and are no faster
//! — the scalar loads and the transposition of 8 points into SoA vectors
//! cost more than the SIMD arithmetic saves —, while the intrinsics with
//! gathers run well under half its instructions per step. The only
//! `unsafe` is the call into the `avx2` functions after the run-time
//! check and the gathers, whose indices are clamped in-register to the
//! arrays (`next ≤ tets − 1`, `idx₃ ≤ points − 1`, ranks and slots ≤ 3,
//! offsets checked once per batch by `RecordWords::gatherable`), so no
//! layout, valid or not, can make them read out of bounds. A corrupt layout
//! whose links point past the tet array makes the scalar walk panic on the
//! index; the gather path then reads a clamped record instead (a wrong walk,
//! never an out-of-bounds read); [`tet_core::layout::LayoutMesh::from_mesh`]
//! validates the mesh, so neither happens for a tracer built by `new`.
//!
//! # Identical to the scalar walk
//!
//! Every lane evaluates exactly the scalar formulas of [`DuffF32`](crate::DuffF32) and
//! `Face2::left_mask`: the same IEEE operations on the same operands in the
//! same order, `x = (uₓqₓ + u_y q_y) + u_z q_z` with `q = P − o`, and
//! `det = p₃.x·yᵢ − p₃.y·xᵢ`, with no fused multiply-add (Rust never
//! contracts, and FMA is not enabled here). A zero determinant takes the
//! scalar tie rule for that lane. So every lane visits the same tets and
//! ends with the same outcome as [`crate::walk::trace`] (bit for bit, tested
//! in `tests/lockstep.rs`), and the watertightness argument of
//! [`crate::walk`] carries over unchanged.
//!
//! # Tuning
//!
//! Two packs in flight per thread beat one and are not beaten by three or
//! four (AVX2 and AVX-512 alike); prefetching the next records, as the
//! scalar walk does, gains nothing here and is off (`avx2::PREFETCH`).
//! Rerun the instruction counts with `benches/walk_step.rs`.
//!
//! # Modules
//!
//! * `pack`: the lanes in structure-of-arrays form, shared by every width,
//!   and the gathers' view of a layout;
//! * `portable`: the lane loops (4 lanes, or 8 compiled for AVX2);
//! * `avx2`, `avx512`: the 8- and 16-lane walks in intrinsics;
//! * `sctp`: ScTP's triple products in 16-lane AVX-512 lockstep.

#[cfg(target_arch = "x86_64")]
mod avx2;
#[cfg(target_arch = "x86_64")]
mod avx512;
mod pack;
mod portable;
#[cfg(target_arch = "x86_64")]
pub(crate) mod sctp;

use tet_core::TetMesh;

use crate::ray::{Ray, TraceOutcome};
use crate::walk::lanes::Starts;
use crate::walk::topology::Topology;
pub use crate::walk::topology::{ExitRule, RecordWords};
pub use pack::{NARROW, WIDE};
#[cfg(target_arch = "x86_64")]
use pack::{RANK, RANK_XOR, SLOT};

/// Traces `rays` from `start` (at most `cap` tets each) with [`DuffF32`](crate::DuffF32)
/// lanes in lockstep; `out[i]` is exactly
/// [`crate::walk::trace`]`::<DuffF32, T>` of `rays[i]`. `out.len()` must
/// equal `rays.len()` (the shorter length is used otherwise).
pub fn trace_lockstep<T: Topology>(
    mesh: &TetMesh,
    topo: &T,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
) {
    #[cfg(target_arch = "x86_64")]
    let wide = !avx2_only();
    #[cfg(not(target_arch = "x86_64"))]
    let wide = false;
    dispatch(mesh, topo, rays, start, cap, out, wide);
}

/// [`trace_lockstep`] without the AVX-512 walk (the AVX2 walk where the CPU
/// has AVX2, else the portable one): public so that tests cover the AVX2
/// walk on machines with AVX-512 too.
pub fn trace_lockstep_avx2<T: Topology>(
    mesh: &TetMesh,
    topo: &T,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
) {
    dispatch(mesh, topo, rays, start, cap, out, false);
}

/// The widest walk the CPU supports (AVX-512 only when `wide`).
fn dispatch<T: Topology>(
    mesh: &TetMesh,
    topo: &T,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
    wide: bool,
) {
    #[cfg(not(target_arch = "x86_64"))]
    let _ = wide;
    // Records the gathers of the projected walks can read (the baseline's
    // `Ids` rule is ScTP's, `sctp`).
    #[cfg(target_arch = "x86_64")]
    let words = topo
        .record_words()
        .filter(|rw| rw.gatherable(mesh.points.len()) && !matches!(rw.rule, ExitRule::Ids { .. }));
    #[cfg(target_arch = "x86_64")]
    if wide
        && std::arch::is_x86_feature_detected!("avx512f")
        && let Some(rw) = words
    {
        // SAFETY (all three): the `avx512f` functions only require the
        // CPU to support AVX-512F, which was detected just above.
        match rw.rule {
            ExitRule::Rank { .. } => unsafe {
                avx512::run_gather::<RANK>(mesh, rw, rays, start, cap, out)
            },
            ExitRule::RankXor { .. } => unsafe {
                avx512::run_gather::<RANK_XOR>(mesh, rw, rays, start, cap, out)
            },
            ExitRule::Slot { .. } | ExitRule::Ids { .. } => unsafe {
                avx512::run_gather::<SLOT>(mesh, rw, rays, start, cap, out)
            },
        }
        return;
    }
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        match words {
            Some(rw) => {
                // SAFETY (all three): the `avx2` functions only require the
                // CPU to support AVX2, which was detected just above.
                match rw.rule {
                    ExitRule::Rank { .. } => unsafe {
                        avx2::run_gather::<RANK>(mesh, rw, rays, start, cap, out)
                    },
                    ExitRule::RankXor { .. } => unsafe {
                        avx2::run_gather::<RANK_XOR>(mesh, rw, rays, start, cap, out)
                    },
                    ExitRule::Slot { .. } | ExitRule::Ids { .. } => unsafe {
                        avx2::run_gather::<SLOT>(mesh, rw, rays, start, cap, out)
                    },
                }
            }
            // SAFETY: as above.
            _ => unsafe { portable::trace_avx2(mesh, topo, rays, start, cap, out) },
        }
        return;
    }
    portable::run::<T, NARROW>(mesh, topo, rays, start, cap, out);
}

/// True when `TET_LOCKSTEP=avx2` asks the lockstep walk to keep to 8-lane
/// AVX2 on a CPU with AVX-512 (read once; for same-machine comparisons).
#[cfg(target_arch = "x86_64")]
fn avx2_only() -> bool {
    static AVX2_ONLY: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *AVX2_ONLY.get_or_init(|| std::env::var("TET_LOCKSTEP").is_ok_and(|v| v == "avx2"))
}

/// [`trace_lockstep`] with `W` lanes compiled for the baseline target (no
/// run-time dispatch): the portable fallback, public so that tests cover it
/// on machines with AVX2 too.
pub fn trace_lockstep_portable<T: Topology, const W: usize>(
    mesh: &TetMesh,
    topo: &T,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
) {
    portable::run::<T, W>(mesh, topo, rays, start, cap, out);
}
