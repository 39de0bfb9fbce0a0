//! ScTP (Lagae & Dutré's scalar triple products, [`TripleF32`](crate::TripleF32)) walked in
//! 16-lane AVX-512 (else 8-lane AVX2) lockstep over the 32-byte baseline
//! layout: the batch path of [`crate::sctp::SctpTracer`].
//!
//! It is the one lockstep walk of [`crate::lockstep`] with ScTP's geometry
//! and records (`geometry::Triple`, `exit::Gathered` with the `IDS` rule):
//! each round every lane gathers the four vertex ids of the tet it enters
//! (the baseline layout stores no `VX`: the new vertex is the one id that is
//! not on the entry face, `v₀ ⊕ v₁ ⊕ v₂ ⊕ v₃ ⊕ idx₀ ⊕ idx₁ ⊕ idx₂`), its point
//! (`x, y` as one 64-bit pair, then `z`), and evaluates the three triple
//! products `d · (q₃ × qᵢ)` with `q = P − o` exactly as
//! [`Projection::left_mask`](crate::walk::Projection::left_mask) of
//! [`TripleF32`](crate::TripleF32) does
//! (glam's `cross` and `dot`, operand for operand, no fused multiply-add),
//! so every lane decides bit for bit as the scalar walk and the
//! antisymmetry that makes the walk watertight (`a × b = −(b × a)`
//! componentwise) is kept. A zero product takes the scalar tie rule for
//! that lane. The exit link is found by the slot of the exiting vertex
//! among the gathered ids (Algorithm 3). Lanes whose walk needs the rare
//! path take the scalar engine's cold path, and are refilled at once, as
//! in [`crate::lockstep`].
//!
//! Why: the scalar interleaved walk spends about 146 instructions per ScTP
//! step; in lockstep the arithmetic is shared by 16 (or 8) rays: with 8
//! AVX2 lanes it traced 2.5 times the rays per CPU-second of the
//! interleaved walk on Torus Knots (`benches/walk_step.rs`). The same walk
//! runs at the portable widths through [`super::trace_lockstep_sctp`], for
//! tests.

use tet_core::TetMesh;

use super::{Width, trace_lockstep_sctp};
use crate::ray::{Ray, TraceOutcome};
use crate::walk::lanes::Starts;
use crate::walk::topology::Topology;

/// Traces the batch in lockstep when the CPU has AVX-512F (unless
/// `TET_LOCKSTEP=avx2`) or AVX2 and the layout exposes baseline records
/// ([`ExitRule::Ids`](super::ExitRule::Ids)); false (nothing traced)
/// otherwise.
pub(crate) fn trace<T: Topology>(
    mesh: &TetMesh,
    topo: &T,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
) -> bool {
    // This module exists on x86-64 only.
    (!super::avx2_only() && trace_lockstep_sctp(Width::Avx512, mesh, topo, rays, start, cap, out))
        || trace_lockstep_sctp(Width::Avx2, mesh, topo, rays, start, cap, out)
}
