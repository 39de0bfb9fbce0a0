//! SIMD lockstep walk: `W` rays of one batch walk side by side, one ray per
//! SIMD lane, one tet per lane per round. This is the
//! [`Tracer::trace_batch`](crate::Tracer::trace_batch) of every projected
//! kernel with [`DuffF32`](crate::DuffF32) (Tet20, Tet16, Tet32), of ScTP
//! and of the Tet80 kernels; the scalar walks ([`crate::walk::trace`],
//! [`crate::walk::trace_interleaved`], reachable as
//! [`crate::kernel::Interleaved`], and the Tet80 tracers' own) stay as the
//! reference and serve a batch the lockstep walk gives back.
//!
//! # One request, one entry
//!
//! A batch is one request ([`Batch`]: the mesh, the topology, the rays,
//! their starts, the step cap and the outcomes), and [`trace`] the one
//! entry: it takes the batch, the [`Width`]
//! ([`Width::Auto`] picks the widest the CPU runs, and is where
//! `TET_LOCKSTEP` is read) and a gate ([`NoGate`] for none), and walks it
//! with a kernel's *geometry*, a type parameter ([`Geometry`]):
//!
//! * [`Planar`]: the projected walk with [`DuffF32`](crate::DuffF32)
//!   (Tet20, Tet16, Tet32). Each round every lane fetches `VX` of the tet
//!   it enters, decodes the new vertex `idx₃ = idx₀ ⊕ idx₁ ⊕ idx₂ ⊕ VX`
//!   and fetches its point; the projection of `idx₃` (`p = (u·(P−o),
//!   v·(P−o))`), the three edge determinants `det(p₃, pᵢ)` of Algorithm 1,
//!   the exit slot ([`crate::walk::EXIT_SLOT`]), the replacement of the
//!   exiting vertex and the exit link (the layout's [`ExitRule`]) run
//!   across the lanes as SIMD arithmetic, compares and blends: no branches
//!   and no variable-indexed stores;
//! * [`Triple`]: the same walk with ScTP's scalar triple products
//!   ([`TripleF32`](crate::TripleF32)) over the 32-byte baseline layout,
//!   whose records keep the four ids and no `VX` (its exit rule decodes
//!   `idx₃` from them); with 8 AVX2 lanes it traced 2.5 times the rays
//!   per CPU-second of the interleaved walk (Torus Knots,
//!   `benches/walk_step.rs`);
//! * [`Plucker`]: Maria et al.'s Plücker walk over the Tet80 records, both
//!   side rules (`plucker`, `side`), the topology being the Tet80 tracer.
//!
//! The three differ in their geometry only: the driver (`driver`: packs
//! of lanes stepped in turn, refills, the gate), the entry, the width and
//! the `#[target_feature]` entry points are the same. A lane that needs a
//! rare path (a constrained face or the boundary, the step cap, a decoded
//! vertex out of range) takes the scalar walk's cold path (the same
//! ending, crossing and refill for every width); a finished lane is
//! refilled at once from the batch, so lanes idle only at the batch's
//! tail.
//!
//! A *gated* walk also stops a lane short before it enters a tet the gate
//! names, handing its state to the caller, which walks on with the scalar
//! walk: the iso walk gates on the range test, so the tets on no
//! isovalue's side are walked in lockstep
//! ([`crate::iso::IsoWalk::trace_tile`]); batches of shadow rays gate on
//! the light's tets, where their walks end
//! ([`crate::secondary::ShadowTracer::trace_until_batch`]). A gate that
//! names one tet (a light strictly inside a tet) is checked in SIMD, one
//! compare per pack and round; others lane by lane. The plain walk's gate
//! ([`NoGate`]) compiles away.
//!
//! # Widths
//!
//! * [`Width::Avx512`] (x86-64 with AVX-512F, detected at run time): 16
//!   lanes, 512-bit vectors and mask registers (`avx512`), two packs in
//!   flight, faster than the AVX2 walk; what [`Width::Auto`] takes where
//!   the CPU has it, unless `TET_LOCKSTEP=avx2`;
//! * [`Width::Avx2`] (x86-64 with AVX2): 8-lane AVX2 intrinsics, all five
//!   loads of a step (`VX`, the point's x, y, z, the link) as
//!   `vpgatherdd`/`vgatherdps`, two packs of 8 lanes in flight per thread
//!   so that the core overlaps their gather chains;
//! * [`Width::Portable4`], [`Width::Portable8`]: the portable lanes
//!   (`portable`) on the baseline target, reading a projected layout's
//!   records through [`Topology`](crate::walk::Topology); for tests and
//!   machines without AVX2, where [`Width::Auto`] gives the batch back:
//!   the portable lanes are no faster than the scalar interleaved walk
//!   (see below).
//!
//! The SIMD widths gather the records of a layout that exposes them as
//! words ([`crate::walk::Topology::record_words`]) with its
//! [`ExitRule`]; a batch over other records is given back.
//!
//! # One walk, generic over lanes
//!
//! The walk is written once, like Embree's kernels over `vfloat<K>`, over
//! small traits: the lanes (`lanes::Lanes`: f32 and u32 vectors, masks,
//! splat, add/sub/mul, compares, selects, gathers; implemented by
//! `avx512::Avx512`, 16 lanes with mask registers, `avx2::Avx2`, 8 lanes
//! with masks as vectors, and `portable::Portable<W>`, arrays of `W`
//! lanes), the geometry's rounds (`driver::Rounds`, run by
//! `driver::run`), and below them the projection (`geometry::Projected`:
//! `Planar`, `Triple`), the record reads (`exit::Records`: the layout's
//! [`ExitRule`] gathered, or lane by lane through
//! [`Topology`](crate::walk::Topology)) and the Plücker side rules
//! (`side::Side`). Every function on the way is `#[inline(always)]` and
//! the walk is instantiated inside a `#[target_feature]` entry point per
//! instruction set, so it compiles to the same straight-line intrinsics as
//! a hand-written kernel; its rare paths run out of line, compiled for the
//! same instruction set (`Lanes::cold`). Each entry point is compiled for
//! the whole feature set its CPUs have, not its vector extension alone:
//! AVX2 with FMA, BMI1/2, LZCNT and POPCNT; AVX-512 F with VL, BW, DQ and
//! the AVX2 set (the run-time check asks for all of them). With `avx512f`
//! alone, Tet20 ran at 0.83–0.86× the speed of a `-C target-cpu=native`
//! build of the same code (Torus Knots, 1920×1440, 2 threads, AMD EPYC
//! with AVX-512); with the set, 0.96–1.0×.
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
//! four (AVX2 and AVX-512 alike; the `PACKS` of `driver::run`); prefetching
//! the next records, as the scalar walk does, gains nothing with gathers
//! and is off there (`exit::Records::prefetch`). Rerun the instruction
//! counts with `benches/walk_step.rs`.
//!
//! # Modules
//!
//! * `lanes`: the lane trait;
//! * `avx512`, `avx2`, `portable`: its 16-, 8- and `W`-lane implementations;
//! * `driver`: the driver and the gate, once for every geometry;
//! * `geometry`: the projections in lanes (Duff's 2-D basis, ScTP's triple
//!   products);
//! * `exit`: the exit rule as a type, and the record reads (gathered with
//!   a layout's exit rule);
//! * `projected`: the projected walk's rounds (Tet20, Tet16, Tet32, ScTP);
//! * `plucker`, `side`: the Plücker walk's rounds (Tet80) and its two side
//!   rules in lanes (faithful and consistent);
//! * `tests`: odd lane counts and gates, against the scalar walks.

#[cfg(target_arch = "x86_64")]
mod avx2;
#[cfg(target_arch = "x86_64")]
mod avx512;
mod driver;
pub(crate) mod exit;
mod geometry;
pub(crate) mod lanes;
pub(crate) mod plucker;
mod portable;
mod projected;
mod side;

pub(crate) use driver::Gate;
pub use driver::NoGate;
pub use exit::{ByLane, ExitRule, RecordWords};
pub use geometry::{Planar, Triple};
pub use plucker::Plucker;
pub(crate) use projected::Handover;

pub use crate::walk::lanes::Batch;
#[cfg(target_arch = "x86_64")]
use avx2::Avx2;
#[cfg(target_arch = "x86_64")]
use avx512::Avx512;
use lanes::Lanes;
use portable::Portable;

/// A lockstep walk's lanes: [`Width::Auto`], the widest the CPU runs, or
/// one width on purpose (tests, comparisons).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Width {
    /// AVX-512 where the CPU runs it, else AVX2; none (the callers' scalar
    /// walks) without either. `TET_LOCKSTEP=avx2` in the environment keeps
    /// AVX2 on a CPU with AVX-512, `TET_LOCKSTEP=scalar` keeps every batch
    /// on its scalar walk (read once, here only; for same-machine
    /// comparisons).
    Auto,
    /// The portable lanes, 4 wide, baseline target.
    Portable4,
    /// The portable lanes, 8 wide, baseline target.
    Portable8,
    /// AVX2 intrinsics, 8 lanes.
    Avx2,
    /// AVX-512F intrinsics, 16 lanes.
    Avx512,
}

impl Width {
    /// Every fixed width, narrowest first.
    pub const ALL: [Width; 4] = [
        Width::Portable4,
        Width::Portable8,
        Width::Avx2,
        Width::Avx512,
    ];

    /// The fixed width this one walks at on this CPU: itself where the CPU
    /// runs it (the portable ones always), [`Width::Auto`]'s choice, or
    /// `None`.
    pub fn resolve(self) -> Option<Width> {
        match self {
            Width::Auto => auto(),
            w => w.available().then_some(w),
        }
    }

    /// True when this CPU runs the width (the portable ones always;
    /// [`Width::Auto`] when it resolves to one).
    pub fn available(self) -> bool {
        match self {
            Width::Auto => auto().is_some(),
            Width::Portable4 | Width::Portable8 => true,
            #[cfg(target_arch = "x86_64")]
            Width::Avx2 => avx2::has_avx2_set(),
            #[cfg(target_arch = "x86_64")]
            Width::Avx512 => avx512::has_avx512_set(),
            #[cfg(not(target_arch = "x86_64"))]
            Width::Avx2 | Width::Avx512 => false,
        }
    }

    /// Lanes per pack (0 for a [`Width::Auto`] that resolves to none).
    pub fn lanes(self) -> usize {
        match self.resolve().unwrap_or(self) {
            Width::Auto => 0,
            Width::Portable4 => 4,
            Width::Portable8 | Width::Avx2 => 8,
            Width::Avx512 => 16,
        }
    }
}

/// [`Width::Auto`] on this CPU: the one reader of `TET_LOCKSTEP`.
fn auto() -> Option<Width> {
    static AUTO: std::sync::OnceLock<Option<Width>> = std::sync::OnceLock::new();
    *AUTO.get_or_init(|| {
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

/// A kernel's geometry in lockstep: what a lane computes per tet and
/// reads of the records of topology `T`, run by the one driver —
/// [`Planar`] (Tet20, Tet16, Tet32) and [`Triple`] (ScTP) over a
/// [`Topology`](crate::walk::Topology), [`Plucker`] (Tet80, both side
/// rules) over its tracer. [`trace`] walks a batch with one.
pub trait Geometry<T: ?Sized> {
    /// What a gate receives of a walk it stops.
    type Handover;
    /// Walks `batch` on lanes `l` with `PACKS` packs in flight, stopped
    /// short by `gate`; `Err` (nothing traced) when its records cannot be
    /// read at these lanes.
    fn walk<'a, L: Lanes, GT: Gate<Self::Handover>, const PACKS: usize>(
        l: L,
        batch: Batch<'a, T>,
        gate: &mut GT,
    ) -> Result<(), Batch<'a, T>>;
}

/// Traces `batch` in lockstep with geometry `G` at `width`: `out[i]` is
/// exactly the scalar walk's outcome of `rays[i]` from its start, except
/// for the walks `gate` stops short ([`NoGate`]: none), whose `out` is
/// left as it was. `Err` gives the batch back untraced when the CPU lacks
/// the width ([`Width::Auto`]: when it resolves to none) or the SIMD
/// lanes cannot gather the layout's records, for the caller's scalar walk.
pub fn trace<'a, G, T, GT>(
    batch: Batch<'a, T>,
    width: Width,
    gate: &mut GT,
) -> Result<(), Batch<'a, T>>
where
    G: Geometry<T>,
    T: ?Sized,
    GT: Gate<G::Handover>,
{
    match width.resolve() {
        Some(Width::Portable4) => G::walk::<Portable<4>, GT, 1>(Portable, batch, gate),
        Some(Width::Portable8) => G::walk::<Portable<8>, GT, 1>(Portable, batch, gate),
        #[cfg(target_arch = "x86_64")]
        Some(Width::Avx2) => match Avx2::detect() {
            // SAFETY: the token proves the CPU has the AVX2 set.
            Some(t) => unsafe { walk_avx2::<G, T, GT>(t, batch, gate) },
            None => Err(batch),
        },
        #[cfg(target_arch = "x86_64")]
        Some(Width::Avx512) => match Avx512::detect() {
            // SAFETY: the token proves the CPU has the AVX-512 set.
            Some(t) => unsafe { walk_avx512::<G, T, GT>(t, batch, gate) },
            None => Err(batch),
        },
        _ => Err(batch),
    }
}

/// The walk with 8 AVX2 lanes, two packs in flight, compiled for AVX2
/// (everything inlines into it).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
fn walk_avx2<'a, G, T, GT>(t: Avx2, batch: Batch<'a, T>, gate: &mut GT) -> Result<(), Batch<'a, T>>
where
    G: Geometry<T>,
    T: ?Sized,
    GT: Gate<G::Handover>,
{
    G::walk::<Avx2, GT, 2>(t, batch, gate)
}

/// The walk with 16 AVX-512 lanes, two packs in flight, compiled for
/// AVX-512F (everything inlines into it).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq,avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
fn walk_avx512<'a, G, T, GT>(
    t: Avx512,
    batch: Batch<'a, T>,
    gate: &mut GT,
) -> Result<(), Batch<'a, T>>
where
    G: Geometry<T>,
    T: ?Sized,
    GT: Gate<G::Handover>,
{
    G::walk::<Avx512, GT, 2>(t, batch, gate)
}

#[cfg(test)]
mod tests;
