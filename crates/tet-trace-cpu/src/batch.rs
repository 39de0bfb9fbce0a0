//! Which batch walk each projection takes: the SIMD lockstep walks where
//! one exists for it ([`crate::lockstep`]), else the scalar interleaved
//! walk ([`crate::walk::trace_interleaved`]). Every batch walk gives, ray by
//! ray, exactly the outcome of [`crate::walk::trace`].

use tet_core::TetMesh;

use crate::lockstep;
use crate::ray::{Ray, TraceOutcome};
use crate::walk::{
    DuffF32, DuffF64, LANES, OriginF32, Projection, Starts, Topology, TripleF32, trace_interleaved,
};

/// A projection with a batch walk: what
/// [`Tracer::trace_batch`](crate::Tracer::trace_batch) of a
/// [`WalkTracer`](crate::WalkTracer) runs.
pub trait BatchWalk: Projection {
    /// Traces a batch of rays (ray `i` from the start `starts` gives it) over
    /// `topo`, at most `cap` tets each; the outcomes equal
    /// [`crate::walk::trace`] ray by ray. Default: the scalar interleaved
    /// walk ([`trace_interleaved`], [`LANES`] walks per thread).
    fn trace_batch<T: Topology>(
        mesh: &TetMesh,
        topo: &T,
        rays: &[Ray],
        starts: Starts<'_>,
        cap: u32,
        out: &mut [TraceOutcome],
    ) {
        trace_interleaved::<Self, T, LANES>(mesh, topo, rays, starts, cap, out)
    }
}

/// SIMD lanes in lockstep ([`lockstep::trace_lockstep`]).
impl BatchWalk for DuffF32 {
    fn trace_batch<T: Topology>(
        mesh: &TetMesh,
        topo: &T,
        rays: &[Ray],
        starts: Starts<'_>,
        cap: u32,
        out: &mut [TraceOutcome],
    ) {
        lockstep::trace_lockstep(mesh, topo, rays, starts, cap, out)
    }
}

/// On x86-64 with AVX-512F over the baseline layout: 16 lanes in lockstep
/// (identical outcomes); otherwise the scalar interleaved walk.
impl BatchWalk for TripleF32 {
    fn trace_batch<T: Topology>(
        mesh: &TetMesh,
        topo: &T,
        rays: &[Ray],
        starts: Starts<'_>,
        cap: u32,
        out: &mut [TraceOutcome],
    ) {
        #[cfg(target_arch = "x86_64")]
        if lockstep::sctp::trace(mesh, topo, rays, starts, cap, out) {
            return;
        }
        trace_interleaved::<Self, T, LANES>(mesh, topo, rays, starts, cap, out)
    }
}

/// The scalar interleaved walk.
impl BatchWalk for DuffF64 {}

/// The scalar interleaved walk.
impl BatchWalk for OriginF32 {}
