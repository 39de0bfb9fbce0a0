//! Which batch walk each projection takes: the SIMD lockstep walks where
//! one exists for it ([`crate::lockstep`]), else the scalar interleaved
//! walk ([`crate::walk::trace_interleaved`]). Every batch walk gives, ray by
//! ray, exactly the outcome of [`crate::walk::trace`].

use crate::lockstep::{self, NoGate, Planar, Triple, Width};
use crate::walk::{
    Batch, DuffF32, DuffF64, LANES, OriginF32, Projection, Topology, TripleF32, trace_interleaved,
};

/// A projection with a batch walk: what
/// [`Tracer::trace_batch`](crate::Tracer::trace_batch) of a
/// [`WalkTracer`](crate::WalkTracer) runs.
pub trait BatchWalk: Projection {
    /// Traces `batch`; the outcomes equal [`crate::walk::trace`] ray by
    /// ray. Default: the scalar interleaved walk ([`trace_interleaved`],
    /// [`LANES`] walks per thread).
    fn trace_batch<T: Topology>(batch: Batch<'_, T>) {
        trace_interleaved::<Self, T, LANES>(batch)
    }
}

/// SIMD lanes in lockstep ([`lockstep::trace`] with [`Planar`]) where the
/// CPU runs them, else the scalar interleaved walk.
impl BatchWalk for DuffF32 {
    fn trace_batch<T: Topology>(batch: Batch<'_, T>) {
        if let Err(batch) = lockstep::trace::<Planar, _, _>(batch, Width::Auto, &mut NoGate) {
            trace_interleaved::<Self, T, LANES>(batch)
        }
    }
}

/// ScTP's SIMD lanes in lockstep ([`lockstep::trace`] with [`Triple`])
/// where the CPU runs them, else the scalar interleaved walk.
impl BatchWalk for TripleF32 {
    fn trace_batch<T: Topology>(batch: Batch<'_, T>) {
        if let Err(batch) = lockstep::trace::<Triple, _, _>(batch, Width::Auto, &mut NoGate) {
            trace_interleaved::<Self, T, LANES>(batch)
        }
    }
}

/// The scalar interleaved walk.
impl BatchWalk for DuffF64 {}

/// The scalar interleaved walk.
impl BatchWalk for OriginF32 {}
