//! SIMD lockstep walk: `W` rays of one batch walk side by side, one ray per
//! SIMD lane, one tet per lane per round. This is the
//! [`Tracer::trace_batch`](crate::Tracer::trace_batch) of every projected
//! kernel with [`DuffF32`](crate::DuffF32) (Tet20, Tet16, Tet32), of ScTP
//! (`sctp`) and of the Tet80 kernels (`plucker`, over the same lanes, see
//! Dispatch); the scalar walks
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
//! A *gated* walk (`walk::Gate`, `trace_lockstep_gated`) also stops a lane
//! short before it enters a tet the gate names, handing its state to the
//! caller, which walks on with the scalar walk: the iso walk gates on the
//! range test, so the tets on no isovalue's side are walked in lockstep
//! ([`crate::iso::IsoWalk::trace_tile`]). The plain walk's gate compiles
//! away.
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
//! * x86-64 with AVX2, other layouts: the portable lanes (`portable`) compiled
//!   for AVX2 (8 lanes, scalar loads through [`Topology`]);
//! * otherwise: the portable lanes with 4 lanes on the baseline target
//!   (SSE2 on x86-64), [`trace_lockstep_portable`].
//!
//! The Tet80 kernels ([`crate::tet80`], both side rules) walk their own
//! records in lockstep (`plucker`): AVX-512F (16 lanes) unless
//! `TET_LOCKSTEP=avx2`, else AVX2 (8 lanes), both with gathers; without
//! either, or with `TET_LOCKSTEP=scalar`, their scalar walk
//! ([`crate::tet80::Tet80Tracer::trace_batch_scalar`]).
//!
//! # One walk, generic over lanes
//!
//! The walk (`walk`) is written once, like Embree's kernels over
//! `vfloat<K>`, over three small traits: the lanes (`lanes::Lanes`: f32
//! and u32 vectors, masks, splat, add/sub/mul, compares, selects, gathers;
//! implemented by `avx512::Avx512`, 16 lanes with mask registers,
//! `avx2::Avx2`, 8 lanes with masks as vectors, and
//! `portable::Portable<W>`, arrays of `W` lanes), the projection
//! (`geometry::Geometry`: `Planar` for [`DuffF32`](crate::DuffF32),
//! `Triple` for ScTP's [`TripleF32`](crate::TripleF32)) and the record
//! reads (`exit::Records`: `Gathered` with the exit rule as a const
//! parameter, `PerLane` through [`Topology`]). Every function on the way
//! is `#[inline(always)]` and the walk is instantiated inside a
//! `#[target_feature]` entry point per instruction set, so it compiles to
//! the same straight-line intrinsics as a hand-written kernel; its rare
//! paths run out of line, compiled for the same instruction set
//! (`Lanes::cold`). Each entry point is compiled for the whole feature set
//! its CPUs have, not its vector extension alone: AVX2 with FMA, BMI1/2,
//! LZCNT and POPCNT; AVX-512 F with VL, BW, DQ and the AVX2 set (the run-time
//! check asks for all of them). With `avx512f` alone, Tet20 ran at 0.83–0.86×
//! the speed of a `-C target-cpu=native` build of the same code (Torus
//! Knots, 1920×1440, 2 threads, AMD EPYC with AVX-512); with the set, 0.96–1.0×.
//!
//! Why intrinsics and `unsafe`: the same lane loops left to the
//! auto-vectoriser (the portable lanes compiled for AVX2, 8 lanes) run more
//! instructions per step than the scalar interleaved walk and are no faster
//! — the scalar loads and the transposition of 8 points into SoA vectors
//! cost more than the SIMD arithmetic saves —, while the intrinsics with
//! gathers run well under half its instructions per step. The `unsafe` is
//! the intrinsics inside the `Avx2` and `Avx512` lanes, whose values
//! (tokens) exist only after the run-time check, the calls into the
//! `#[target_feature]` entry points, and the gathers, whose indices are
//! clamped in-register to the arrays (`next ≤ tets − 1`, `idx₃ ≤ points −
//! 1`, ranks and slots ≤ 3, offsets checked once per batch by
//! `RecordWords::gatherable`), so no layout, valid or not, can make them
//! read out of bounds. A corrupt layout whose links point past the tet
//! array makes the scalar walk panic on the index; the gather path then
//! reads a clamped record instead (a wrong walk, never an out-of-bounds
//! read); [`tet_core::layout::LayoutMesh::from_mesh`] validates the mesh,
//! so neither happens for a tracer built by `new`.
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
//! four (AVX2 and AVX-512 alike; the `PACKS` of `walk::run`); prefetching
//! the next records, as the scalar walk does, gains nothing with gathers
//! and is off there (`exit::Records::prefetch`). Rerun the instruction
//! counts with `benches/walk_step.rs`.
//!
//! # Modules
//!
//! * `lanes`: the lane trait;
//! * `avx512`, `avx2`, `portable`: its 16-, 8- and `W`-lane implementations;
//! * `geometry`: the projections in lanes (Duff's 2-D basis, ScTP's triple
//!   products);
//! * `exit`: the record reads (gathers with the exit rules, or lane by lane);
//! * `walk`: the walk itself, once;
//! * `sctp`: ScTP's batch path (16-lane AVX-512 lockstep);
//! * `plucker`, `side`: the Tet80 walk (Maria et al.'s Plücker exit rule)
//!   over the same lanes, with its two side rules in lanes (faithful and
//!   consistent).

#[cfg(target_arch = "x86_64")]
mod avx2;
#[cfg(target_arch = "x86_64")]
mod avx512;
mod exit;
mod geometry;
mod lanes;
pub(crate) mod plucker;
mod portable;
#[cfg(target_arch = "x86_64")]
pub(crate) mod sctp;
mod side;
mod walk;

use walk::NoGate;
pub(crate) use walk::{Gate, Handover};

use tet_core::TetMesh;

use crate::ray::{Ray, TraceOutcome};
use crate::walk::lanes::Starts;
use crate::walk::topology::Topology;
pub use crate::walk::topology::{ExitRule, RecordWords};
#[cfg(target_arch = "x86_64")]
use avx2::Avx2;
#[cfg(target_arch = "x86_64")]
use avx512::Avx512;
use exit::{Gathered, Geo, IDS, PerLane};
#[cfg(target_arch = "x86_64")]
use exit::{RANK, RANK_XOR, Records, SLOT};
#[cfg(target_arch = "x86_64")]
use geometry::Geometry;
use geometry::{Planar, Triple};
use portable::Portable;

/// Lanes of the AVX2 lockstep walk (256-bit vectors of f32 / u32).
pub const WIDE: usize = 8;
/// Lanes of the portable lockstep walk (128-bit vectors).
pub const NARROW: usize = 4;

/// A lockstep walk's lanes, for running one width on purpose (tests,
/// comparisons); [`trace_lockstep`] picks the widest the CPU runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Width {
    /// The portable lanes, 4 wide ([`NARROW`]), baseline target.
    Portable4,
    /// The portable lanes, 8 wide, baseline target.
    Portable8,
    /// AVX2 intrinsics, 8 lanes ([`WIDE`]).
    Avx2,
    /// AVX-512F intrinsics, 16 lanes.
    Avx512,
}

impl Width {
    /// Every width, narrowest first.
    pub const ALL: [Width; 4] = [
        Width::Portable4,
        Width::Portable8,
        Width::Avx2,
        Width::Avx512,
    ];

    /// True when this CPU runs the width (the portable ones always).
    pub fn available(self) -> bool {
        match self {
            Width::Portable4 | Width::Portable8 => true,
            #[cfg(target_arch = "x86_64")]
            Width::Avx2 => avx2::has_avx2_set(),
            #[cfg(target_arch = "x86_64")]
            Width::Avx512 => avx512::has_avx512_set(),
            #[cfg(not(target_arch = "x86_64"))]
            Width::Avx2 | Width::Avx512 => false,
        }
    }

    /// Lanes per pack.
    pub fn lanes(self) -> usize {
        match self {
            Width::Portable4 => NARROW,
            Width::Portable8 | Width::Avx2 => WIDE,
            Width::Avx512 => 16,
        }
    }
}

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
    trace_lockstep_gated(mesh, topo, rays, start, cap, out, &mut NoGate);
}

/// [`trace_lockstep`] stopped short by `gate`: a walk about to enter a tet
/// the gate names is handed to it instead (its `out` left unwritten), so
/// that a caller walks on with the scalar walk from there (the iso walk
/// does, from the first tet whose values straddle an isovalue).
#[allow(clippy::too_many_arguments)]
pub(crate) fn trace_lockstep_gated<T: Topology, GT: Gate>(
    mesh: &TetMesh,
    topo: &T,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
    gate: &mut GT,
) {
    #[cfg(target_arch = "x86_64")]
    let wide = !avx2_only();
    #[cfg(not(target_arch = "x86_64"))]
    let wide = false;
    dispatch(mesh, topo, rays, start, cap, out, wide, gate);
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
    dispatch(mesh, topo, rays, start, cap, out, false, &mut NoGate);
}

/// [`trace_lockstep`] with `W` lanes compiled for the baseline target (no
/// run-time dispatch; `0 < W ≤ 32`): the portable fallback, public so that
/// tests cover it on machines with AVX2 too.
pub fn trace_lockstep_portable<T: Topology, const W: usize>(
    mesh: &TetMesh,
    topo: &T,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
) {
    const { assert!(W > 0 && W <= 32, "1 to 32 portable lanes") };
    walk::run_plain::<Portable<W>, Planar, _, 1>(
        Portable,
        &PerLane(topo),
        mesh,
        rays,
        start,
        cap,
        out,
    );
}

/// [`trace_lockstep`] at `width` exactly: the portable widths read the
/// records through [`Topology`]; the AVX2 and AVX-512 ones gather them and
/// need [`Topology::record_words`] (a Tet20, Tet16 or Tet32 layout). False
/// (nothing traced) when the CPU lacks the width or the layout its records.
pub fn trace_lockstep_at<T: Topology>(
    width: Width,
    mesh: &TetMesh,
    topo: &T,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
) -> bool {
    match width {
        Width::Portable4 => trace_lockstep_portable::<T, NARROW>(mesh, topo, rays, start, cap, out),
        Width::Portable8 => trace_lockstep_portable::<T, WIDE>(mesh, topo, rays, start, cap, out),
        #[cfg(target_arch = "x86_64")]
        Width::Avx2 | Width::Avx512 => {
            let Some((rule, g)) = projected_records(mesh, topo) else {
                return false;
            };
            match (width, Avx2::detect(), Avx512::detect()) {
                (Width::Avx512, _, Some(t)) => {
                    gathered_avx512(t, rule, g, mesh, rays, start, cap, out, &mut NoGate)
                }
                (Width::Avx2, Some(t), _) => {
                    gathered_avx2(t, rule, g, mesh, rays, start, cap, out, &mut NoGate)
                }
                _ => return false,
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        Width::Avx2 | Width::Avx512 => return false,
    }
    true
}

/// ScTP ([`TripleF32`](crate::TripleF32)) in lockstep at `width` over the
/// 32-byte baseline layout ([`ExitRule::Ids`] records, gathered at every
/// width): `out[i]` is exactly [`crate::walk::trace`]`::<TripleF32, T>` of
/// `rays[i]`. False (nothing traced) when the CPU lacks the width or `topo`
/// is not a baseline layout. The batch path of [`crate::sctp::SctpTracer`]
/// is this walk at [`Width::Avx512`] where the CPU has it.
pub fn trace_lockstep_sctp<T: Topology>(
    width: Width,
    mesh: &TetMesh,
    topo: &T,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
) -> bool {
    let Some(g) = baseline_records(mesh, topo) else {
        return false;
    };
    let x = &Gathered::<IDS>(g);
    match width {
        Width::Portable4 => walk::run_plain::<Portable<NARROW>, Triple, _, 1>(
            Portable, x, mesh, rays, start, cap, out,
        ),
        Width::Portable8 => walk::run_plain::<Portable<WIDE>, Triple, _, 1>(
            Portable, x, mesh, rays, start, cap, out,
        ),
        #[cfg(target_arch = "x86_64")]
        Width::Avx2 => match Avx2::detect() {
            // SAFETY: the token proves the CPU has AVX2.
            Some(t) => unsafe {
                walk_avx2::<Triple, _, _>(t, x, mesh, rays, start, cap, out, &mut NoGate)
            },
            None => return false,
        },
        #[cfg(target_arch = "x86_64")]
        Width::Avx512 => match Avx512::detect() {
            // SAFETY: the token proves the CPU has AVX-512F.
            Some(t) => unsafe {
                walk_avx512::<Triple, _, _>(t, x, mesh, rays, start, cap, out, &mut NoGate)
            },
            None => return false,
        },
        #[cfg(not(target_arch = "x86_64"))]
        Width::Avx2 | Width::Avx512 => return false,
    }
    true
}

/// The gatherable records of a projected layout (Tet20, Tet16, Tet32; the
/// baseline's `Ids` rule is ScTP's) and their exit rule.
#[cfg(target_arch = "x86_64")]
fn projected_records<'a, T: Topology>(mesh: &TetMesh, topo: &'a T) -> Option<(ExitRule, Geo<'a>)> {
    let rw = topo.record_words()?;
    if matches!(rw.rule, ExitRule::Ids { .. }) {
        return None;
    }
    Some((rw.rule, Geo::new(mesh, &rw)?))
}

/// The gatherable records of the 32-byte baseline layout.
fn baseline_records<'a, T: Topology>(mesh: &TetMesh, topo: &'a T) -> Option<Geo<'a>> {
    let rw = topo.record_words()?;
    matches!(rw.rule, ExitRule::Ids { .. }).then_some(())?;
    Geo::new(mesh, &rw)
}

/// The widest walk the CPU supports (AVX-512 only when `wide`), stopped
/// short by `gate`.
#[allow(clippy::too_many_arguments)]
fn dispatch<T: Topology, GT: Gate>(
    mesh: &TetMesh,
    topo: &T,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
    wide: bool,
    gate: &mut GT,
) {
    #[cfg(not(target_arch = "x86_64"))]
    let _ = wide;
    #[cfg(target_arch = "x86_64")]
    {
        let records = projected_records(mesh, topo);
        if wide
            && let Some(t) = Avx512::detect()
            && let Some((rule, g)) = records
        {
            gathered_avx512(t, rule, g, mesh, rays, start, cap, out, gate);
            return;
        }
        if let Some(t) = Avx2::detect() {
            match records {
                Some((rule, g)) => gathered_avx2(t, rule, g, mesh, rays, start, cap, out, gate),
                // SAFETY: the token proves the CPU has AVX2.
                None => unsafe { portable_avx2(t, topo, mesh, rays, start, cap, out, gate) },
            }
            return;
        }
    }
    portable_gated::<T, GT, NARROW>(topo, mesh, rays, start, cap, out, gate);
}

/// The width the batch paths that choose between a lockstep walk and a
/// scalar one (the Tet80 tracers, the iso walk's tiles) walk in lockstep
/// on this CPU: AVX-512F (16 lanes) unless `TET_LOCKSTEP=avx2`, else AVX2
/// (8 lanes); `None` (the scalar walk) without either, or with
/// `TET_LOCKSTEP=scalar` in the environment (read once; for same-machine
/// comparisons).
pub(crate) fn batch_width() -> Option<Width> {
    static WIDTH: std::sync::OnceLock<Option<Width>> = std::sync::OnceLock::new();
    *WIDTH.get_or_init(|| {
        let env = std::env::var("TET_LOCKSTEP").unwrap_or_default();
        if env == "scalar" {
            return None;
        }
        [Width::Avx512, Width::Avx2]
            .into_iter()
            .filter(|w| *w != Width::Avx512 || env != "avx2")
            .find(|w| w.available())
    })
}

/// True when `TET_LOCKSTEP=avx2` asks the lockstep walk to keep to 8-lane
/// AVX2 on a CPU with AVX-512 (read once; for same-machine comparisons).
#[cfg(target_arch = "x86_64")]
fn avx2_only() -> bool {
    static AVX2_ONLY: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *AVX2_ONLY.get_or_init(|| std::env::var("TET_LOCKSTEP").is_ok_and(|v| v == "avx2"))
}

/// Runs `$walk::<Planar, _>` with the gathered records of exit rule `$rule`.
#[cfg(target_arch = "x86_64")]
macro_rules! by_rule {
    ($walk:ident, $t:expr, $rule:expr, $g:expr, $($arg:expr),*) => {
        // SAFETY (all three): the token `$t` proves the CPU has the
        // entry point's instruction set.
        match $rule {
            ExitRule::Rank { .. } => unsafe {
                $walk::<Planar, _, _>($t, &Gathered::<RANK>($g), $($arg),*)
            },
            ExitRule::RankXor { .. } => unsafe {
                $walk::<Planar, _, _>($t, &Gathered::<RANK_XOR>($g), $($arg),*)
            },
            ExitRule::Slot { .. } | ExitRule::Ids { .. } => unsafe {
                $walk::<Planar, _, _>($t, &Gathered::<SLOT>($g), $($arg),*)
            },
        }
    };
}

/// The projected walk with AVX-512 lanes and gathered records of `rule`.
#[cfg(target_arch = "x86_64")]
#[allow(clippy::too_many_arguments)]
fn gathered_avx512<GT: Gate>(
    t: Avx512,
    rule: ExitRule,
    g: Geo<'_>,
    mesh: &TetMesh,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
    gate: &mut GT,
) {
    by_rule!(walk_avx512, t, rule, g, mesh, rays, start, cap, out, gate)
}

/// The projected walk with AVX2 lanes and gathered records of `rule`.
#[cfg(target_arch = "x86_64")]
#[allow(clippy::too_many_arguments)]
fn gathered_avx2<GT: Gate>(
    t: Avx2,
    rule: ExitRule,
    g: Geo<'_>,
    mesh: &TetMesh,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
    gate: &mut GT,
) {
    by_rule!(walk_avx2, t, rule, g, mesh, rays, start, cap, out, gate)
}

/// The walk with 16 AVX-512 lanes, two packs in flight, compiled for
/// AVX-512F (everything inlines into it).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq,avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
#[allow(clippy::too_many_arguments)]
fn walk_avx512<G: Geometry<Avx512>, X: Records<Avx512>, GT: Gate>(
    t: Avx512,
    x: &X,
    mesh: &TetMesh,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
    gate: &mut GT,
) {
    walk::run::<Avx512, G, X, GT, 2>(t, x, mesh, rays, start, cap, out, gate);
}

/// The walk with 8 AVX2 lanes, two packs in flight, compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
#[allow(clippy::too_many_arguments)]
fn walk_avx2<G: Geometry<Avx2>, X: Records<Avx2>, GT: Gate>(
    t: Avx2,
    x: &X,
    mesh: &TetMesh,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
    gate: &mut GT,
) {
    walk::run::<Avx2, G, X, GT, 2>(t, x, mesh, rays, start, cap, out, gate);
}

/// The portable lanes, 8 wide, compiled for AVX2, reading the records
/// through [`Topology`] (layouts without gatherable records).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
#[allow(clippy::too_many_arguments)]
fn portable_avx2<T: Topology, GT: Gate>(
    _: Avx2,
    topo: &T,
    mesh: &TetMesh,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
    gate: &mut GT,
) {
    portable_gated::<T, GT, WIDE>(topo, mesh, rays, start, cap, out, gate);
}

/// The projected walk with `W` portable lanes reading the records through
/// [`Topology`], stopped short by `gate`.
#[inline(always)]
fn portable_gated<T: Topology, GT: Gate, const W: usize>(
    topo: &T,
    mesh: &TetMesh,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
    gate: &mut GT,
) {
    let records = &PerLane(topo);
    walk::run::<Portable<W>, Planar, _, _, 1>(Portable, records, mesh, rays, start, cap, out, gate);
}
