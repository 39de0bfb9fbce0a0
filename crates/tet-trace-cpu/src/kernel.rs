//! Shared plumbing of the kernel modules: the [`Tracer`] trait and the
//! tracer type every layout kernel instantiates.

use std::marker::PhantomData;

use tet_core::TetMesh;

use crate::ray::{Ray, TraceOutcome};
use crate::walk::{Projection, Start, Topology, step_cap, trace, trace_interleaved};

/// A ray-traversal method over one mesh.
pub trait Tracer: Sync {
    /// Method name for reports (`"tet20/f32"`, ...).
    fn name(&self) -> String;
    /// The canonical mesh (cold data: points, constrained faces, attributes).
    fn mesh(&self) -> &TetMesh;
    /// Traces one ray from `start` (see [`Start`]).
    fn trace(&self, ray: &Ray, start: Start) -> TraceOutcome;

    /// Traces many rays from one start into `out` (same length), e.g. the
    /// primary rays of a tile. Kernels may interleave walks; the results
    /// equal [`Tracer::trace`] ray by ray.
    fn trace_batch(&self, rays: &[Ray], start: Start, out: &mut [TraceOutcome]) {
        for (r, o) in rays.iter().zip(out.iter_mut()) {
            *o = self.trace(r, start);
        }
    }
}

/// Walks interleaved per thread by [`WalkTracer::trace_batch`].
pub const LANES: usize = 8;

/// A projected-walk kernel: layout `L` (a [`Topology`]) walked with
/// projection `P`. The kernel modules ([`crate::tet20`], ...) name the
/// useful instantiations.
pub struct WalkTracer<'m, L, P> {
    pub(crate) mesh: &'m TetMesh,
    pub(crate) layout: L,
    pub(crate) cap: u32,
    pub(crate) name: &'static str,
    pub(crate) _p: PhantomData<P>,
}

impl<'m, L: Topology, P: Projection> WalkTracer<'m, L, P> {
    pub(crate) fn with_layout(mesh: &'m TetMesh, layout: L, name: &'static str) -> Self {
        WalkTracer {
            mesh,
            layout,
            cap: step_cap(mesh),
            name,
            _p: PhantomData,
        }
    }

    /// Replaces the step cap (tets visited before a walk reports failure).
    pub fn with_step_cap(mut self, cap: u32) -> Self {
        self.cap = cap;
        self
    }

    /// The layout container.
    pub fn layout(&self) -> &L {
        &self.layout
    }
}

impl<L: Topology, P: Projection> Tracer for WalkTracer<'_, L, P> {
    fn name(&self) -> String {
        format!("{}/{}", self.name, P::NAME)
    }
    fn mesh(&self) -> &TetMesh {
        self.mesh
    }
    #[inline]
    fn trace(&self, ray: &Ray, start: Start) -> TraceOutcome {
        trace::<P, L>(self.mesh, &self.layout, ray, start, self.cap)
    }
    fn trace_batch(&self, rays: &[Ray], start: Start, out: &mut [TraceOutcome]) {
        trace_interleaved::<P, L, LANES>(self.mesh, &self.layout, rays, start, self.cap, out)
    }
}
