//! Which batch walk each projection takes: the SIMD lockstep walks where
//! one exists for it ([`crate::lockstep`]), else the scalar interleaved
//! walk ([`crate::walk::trace_interleaved`]). Every batch walk gives, ray by
//! ray, exactly the outcome of [`crate::walk::trace`]; the batches of
//! shadow rays ([`BatchWalk::trace_until_batch`]) that of
//! [`crate::walk::trace_until`].

use crate::lockstep::{self, NoGate, Planar, Triple, Width};
use crate::shadow_batch;
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

    /// Traces `batch` as shadow rays: each ray's outcome is
    /// [`crate::walk::trace_until`]'s with `stop` (sorted; the walk ends
    /// with a miss on entering one of its tets, start tet included), from
    /// its start (rays from outside the mesh, [`Starts::Outside`](crate::walk::Starts::Outside), enter
    /// as [`crate::walk::trace`] has them enter, and stop on entering a
    /// stop tet too). In lockstep at `width` where this projection has a
    /// lockstep walk and the CPU and layout allow it, else the scalar
    /// interleaved walk. True when the walks ran in lockstep. Default: the
    /// scalar interleaved walk.
    fn trace_until_batch<T: Topology>(batch: Batch<'_, T>, stop: &[u32], width: Width) -> bool {
        let _ = width;
        shadow_batch::interleaved::<Self, T>(batch, stop);
        false
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
    fn trace_until_batch<T: Topology>(batch: Batch<'_, T>, stop: &[u32], width: Width) -> bool {
        shadow_batch::projected::<Planar, Self, T>(batch, stop, width)
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
    fn trace_until_batch<T: Topology>(batch: Batch<'_, T>, stop: &[u32], width: Width) -> bool {
        shadow_batch::projected::<Triple, Self, T>(batch, stop, width)
    }
}

/// The scalar interleaved walk.
impl BatchWalk for DuffF64 {}

/// The scalar interleaved walk.
impl BatchWalk for OriginF32 {}
