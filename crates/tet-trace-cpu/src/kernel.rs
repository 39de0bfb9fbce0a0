//! Shared plumbing of the kernel modules: the tracer type every layout
//! kernel instantiates ([`WalkTracer`], the [`Tracer`] trait re-exported
//! from [`crate::tracer`]), and the [`WalkRecord`]
//! glue that makes every index-based layout container ([`LayoutMesh`]) a
//! [`Topology`] with one constructor.

use std::marker::PhantomData;

use tet_core::TetMesh;
use tet_core::layout::{LayoutError, LayoutMesh, LayoutRecord};
use tet_core::link::Link;

use crate::batch::BatchWalk;
use crate::lockstep::Width;
use crate::lockstep::exit::{ExitRule, RecordWords};
use crate::lost::{exact_if_lost, exact_where_lost};
use crate::ray::{Ray, TraceOutcome};
pub use crate::tracer::Tracer;
pub use crate::walk::LANES;
use crate::walk::{
    Batch, BoundaryEntry, EntryHint, Projection, Start, Starts, Topology, prefetch_index, step_cap,
    trace, trace_interleaved, trace_until, trace_within,
};

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

    /// The step cap (tets visited before a walk reports failure).
    pub fn step_cap(&self) -> u32 {
        self.cap
    }

    /// [`Tracer::trace_until_batch`] with the lockstep walk at `width`
    /// (the trait method takes [`Width::Auto`]): `out[i]` is exactly
    /// [`Tracer::trace_until`] of `rays[i]` from `starts[i]` with `stop`,
    /// over the shortest of the three slices, the walks that reach the
    /// step cap walked again by the exact walk as there. The walks run in
    /// lockstep where the projection has a lockstep walk
    /// ([`BatchWalk::trace_until_batch`]) and the CPU the width, else the
    /// scalar interleaved walk; true when in lockstep.
    pub fn trace_until_batch_at(
        &self,
        rays: &[Ray],
        starts: &[Start],
        stop: &[u32],
        out: &mut [TraceOutcome],
        width: Width,
    ) -> bool
    where
        P: BatchWalk,
    {
        let n = Starts::Each(starts).batch_len(rays.len(), out.len());
        let (rays, starts, out) = (&rays[..n], &starts[..n], &mut out[..n]);
        // The step cap of `Tracer::trace_until`: the mesh's default.
        let cap = step_cap(self.mesh);
        let batch = Batch {
            mesh: self.mesh,
            topo: &self.layout,
            rays,
            starts: Starts::Each(starts),
            cap,
            out: &mut *out,
            bounded: false,
        };
        let ran = P::trace_until_batch(batch, stop, width);
        exact_where_lost(self.mesh, cap, rays, Starts::Each(starts), out);
        ran
    }

    /// The batch of `rays` from `starts` into `out` over this tracer's
    /// mesh, layout and step cap.
    pub fn batch<'a>(
        &'a self,
        rays: &'a [Ray],
        starts: Starts<'a>,
        out: &'a mut [TraceOutcome],
    ) -> Batch<'a, L> {
        Batch {
            mesh: self.mesh,
            topo: &self.layout,
            rays,
            starts,
            cap: self.cap,
            out,
            bounded: false,
        }
    }

    /// `walk` on the batch of `rays` from `starts` into `out` (over the
    /// shortest of the three), bounded or not, then the exact walk where
    /// a walk reached the step cap: what every batch entry of the
    /// projected kernels does, whichever batch walk it takes.
    fn walk_batch(
        &self,
        rays: &[Ray],
        starts: Starts<'_>,
        out: &mut [TraceOutcome],
        bounded: bool,
        walk: impl FnOnce(Batch<'_, L>),
    ) {
        let n = starts.batch_len(rays.len(), out.len());
        let (rays, out) = (&rays[..n], &mut out[..n]);
        walk(Batch {
            bounded,
            ..self.batch(rays, starts, out)
        });
        exact_where_lost(self.mesh, self.cap, rays, starts, out);
    }
}

impl<L: Topology, P: BatchWalk> Tracer for WalkTracer<'_, L, P> {
    fn name(&self) -> String {
        format!("{}/{}", self.name, P::NAME)
    }
    fn mesh(&self) -> &TetMesh {
        self.mesh
    }
    /// The walk, or where it reached the step cap (lost in a tet thinner
    /// than its rounding), the exact walk (`lost.rs`).
    #[inline]
    fn trace(&self, ray: &Ray, start: Start) -> TraceOutcome {
        let out = trace::<P, L>(self.mesh, &self.layout, ray, start, self.cap);
        exact_if_lost(self.mesh, self.cap, ray, start, out)
    }
    fn trace_batch(&self, rays: &[Ray], start: Start, out: &mut [TraceOutcome]) {
        self.trace_batch_from(rays, Starts::Same(start), out)
    }
    fn trace_batch_from(&self, rays: &[Ray], starts: Starts<'_>, out: &mut [TraceOutcome]) {
        self.walk_batch(rays, starts, out, false, P::trace_batch);
    }
    /// The bounded walk ([`trace_within`]), the exact walk where it
    /// reaches the step cap.
    fn trace_within(&self, ray: &Ray, start: Start) -> TraceOutcome {
        let out = trace_within::<P, L>(self.mesh, &self.layout, ray, start, self.cap);
        exact_if_lost(self.mesh, self.cap, ray, start, out)
    }
    /// In SIMD lockstep where the CPU has it, each walk bounded as
    /// [`Tracer::trace_within`] bounds it.
    fn trace_batch_within(&self, rays: &[Ray], starts: Starts<'_>, out: &mut [TraceOutcome]) {
        self.walk_batch(rays, starts, out, true, P::trace_batch);
    }
    fn trace_until(&self, ray: &Ray, start: Start, stop: &[u32]) -> TraceOutcome {
        let cap = step_cap(self.mesh);
        let out = trace_until::<P, L>(self.mesh, &self.layout, ray, start, stop, cap);
        exact_if_lost(self.mesh, cap, ray, start, out)
    }
    /// In SIMD lockstep where the CPU has it
    /// ([`WalkTracer::trace_until_batch_at`] at [`Width::Auto`]).
    fn trace_until_batch(
        &self,
        rays: &[Ray],
        starts: &[Start],
        stop: &[u32],
        out: &mut [TraceOutcome],
    ) {
        self.trace_until_batch_at(rays, starts, stop, out, Width::Auto);
    }
    fn start_outside(
        &self,
        entry: &BoundaryEntry,
        ray: &Ray,
        hint: &mut EntryHint,
    ) -> Result<Start, TraceOutcome> {
        entry.start_with::<P>(self.mesh, ray, hint)
    }
}

/// A [`WalkTracer`] whose batches take the scalar interleaved walk
/// ([`trace_interleaved`], `LANES` walks per thread) whatever the
/// projection: the reference the SIMD lockstep batches of
/// [`crate::lockstep`] are tested and measured against.
pub struct Interleaved<'a, 'm, L, P>(pub &'a WalkTracer<'m, L, P>);

impl<L: Topology, P: BatchWalk> Tracer for Interleaved<'_, '_, L, P> {
    fn name(&self) -> String {
        format!("{}/interleaved", self.0.name())
    }
    fn mesh(&self) -> &TetMesh {
        self.0.mesh
    }
    fn trace(&self, ray: &Ray, start: Start) -> TraceOutcome {
        self.0.trace(ray, start)
    }
    fn trace_batch(&self, rays: &[Ray], start: Start, out: &mut [TraceOutcome]) {
        let walk = trace_interleaved::<P, L, LANES>;
        self.0
            .walk_batch(rays, Starts::Same(start), out, false, walk);
    }
    fn trace_within(&self, ray: &Ray, start: Start) -> TraceOutcome {
        self.0.trace_within(ray, start)
    }
    fn trace_batch_within(&self, rays: &[Ray], starts: Starts<'_>, out: &mut [TraceOutcome]) {
        let walk = trace_interleaved::<P, L, LANES>;
        self.0.walk_batch(rays, starts, out, true, walk);
    }
}

/// The per-record part of a projected-walk kernel over an index-based layout
/// ([`tet_core::layout::Baseline32`], `Tet32`, `Tet20`, `Tet16`): with it,
/// [`LayoutMesh`] of that record is a [`Topology`] and
/// [`WalkTracer::new`] encodes and wraps it.
pub trait WalkRecord: LayoutRecord + Sync {
    /// Kernel name for reports (`"sctp"`, `"tet20"`, ...).
    const KERNEL: &'static str;
    /// Whether [`Topology::prefetch`] prefetches the record (else a no-op).
    const PREFETCH: bool;
    /// Xor of the four vertex ids (paper `VX^i`), see [`Topology::vx`].
    fn vx(&self) -> u32;
    /// Raw link across the face opposite vertex `exiting`, see
    /// [`Topology::exit_link`].
    fn exit_link(&self, face: [u32; 3], d: u32, exiting: u32, entry_raw: u32) -> u32;
    /// The same exit link in lanes, read from the record's 32-bit words by
    /// the SIMD lockstep walk: the layout's zero-sized rule, defined beside
    /// this impl ([`crate::lockstep::ByLane`]: the lockstep walk calls
    /// [`WalkRecord::exit_link`] lane by lane).
    type Exit: ExitRule;
}

impl<R: WalkRecord> Topology for LayoutMesh<R> {
    type Exit = R::Exit;
    #[inline(always)]
    fn vx(&self, tet: u32) -> u32 {
        self.tets[tet as usize].vx()
    }
    #[inline(always)]
    fn exit_link(&self, tet: u32, face: [u32; 3], d: u32, exiting: u32, entry_raw: u32) -> u32 {
        self.tets[tet as usize].exit_link(face, d, exiting, entry_raw)
    }
    #[inline(always)]
    fn prefetch(&self, tet: u32) {
        if R::PREFETCH {
            prefetch_index(&self.tets, tet);
        }
    }
    #[inline(always)]
    fn record_words(&self) -> Option<RecordWords<'_>> {
        Some(RecordWords {
            words: bytemuck::cast_slice(&self.tets),
            stride: size_of::<R>() / 4,
        })
    }
}

impl<'m, R: WalkRecord, P: Projection> WalkTracer<'m, LayoutMesh<R>, P> {
    /// Encodes `mesh` (validated) in the layout of record `R`.
    pub fn new(mesh: &'m TetMesh) -> Result<Self, LayoutError> {
        Ok(Self::with_layout(
            mesh,
            LayoutMesh::from_mesh(mesh)?,
            R::KERNEL,
        ))
    }
}

/// Algorithm 3 (GETNEXTTET32) for records that keep the ids of slots 0..2:
/// the raw link `n[k]` of the slot `k` holding `exiting`, slot 3 when it is
/// none of `v`. Written as a select chain rather than a variable-indexed
/// stack array.
#[inline(always)]
pub(crate) fn slot_exit_link(v: [u32; 3], n: [Link; 4], exiting: u32) -> u32 {
    if exiting == v[0] {
        n[0].0
    } else if exiting == v[1] {
        n[1].0
    } else if exiting == v[2] {
        n[2].0
    } else {
        n[3].0
    }
}
