//! The [`Tracer`] trait: one ray-traversal method over one mesh, what
//! every kernel, the exact walk and the BVH baselines implement, so that
//! the renderer and the measurements take any of them.

use tet_core::TetMesh;

use crate::ray::{Ray, TraceOutcome};
use crate::walk::{BoundaryEntry, EntryHint, Start, Starts};

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

    /// Traces many rays into `out` (same length) from `starts`: one start
    /// for all, one per ray, or each ray's entry into the mesh from outside
    /// ([`Starts::Outside`], [`crate::boundary_entry`]; the entry decided by
    /// [`Tracer::start_outside`]). Kernels may interleave walks; the results
    /// equal [`Tracer::trace`] ray by ray.
    fn trace_batch_from(&self, rays: &[Ray], starts: Starts<'_>, out: &mut [TraceOutcome]) {
        let mut hint = EntryHint::default();
        for (i, (r, o)) in rays.iter().zip(out.iter_mut()).enumerate() {
            let start = match starts {
                Starts::Same(s) => Ok(s),
                Starts::Each(s) => Ok(s[i]),
                Starts::Outside(entry) => self.start_outside(entry, r, &mut hint),
            };
            *o = match start {
                Ok(s) => self.trace(r, s),
                Err(done) => done,
            };
        }
    }

    /// [`Tracer::trace`] for a ray that only asks what lies within its
    /// `t_max` (an ambient-occlusion ray): a tet walk may end as a miss
    /// as soon as it is past `t_max` ([`crate::walk::trace_within`]). The
    /// same hit or miss as [`Tracer::trace`] (a walk that would fail
    /// past `t_max` may end as a miss instead), in fewer tets; the
    /// default is [`Tracer::trace`].
    fn trace_within(&self, ray: &Ray, start: Start) -> TraceOutcome {
        self.trace(ray, start)
    }

    /// [`Tracer::trace_batch_from`] of rays that only ask what lies within
    /// their `t_max`: the results equal [`Tracer::trace_within`] ray by
    /// ray. The default is [`Tracer::trace_batch_from`] (right for a
    /// tracer whose [`Tracer::trace_within`] is [`Tracer::trace`]).
    fn trace_batch_within(&self, rays: &[Ray], starts: Starts<'_>, out: &mut [TraceOutcome]) {
        self.trace_batch_from(rays, starts, out)
    }

    /// How a ray whose origin lies outside the mesh begins (see
    /// [`BoundaryEntry::start_with`]): the entering boundary face decided
    /// with this tracer's own edge test, so that entry and walk agree on
    /// every boundary edge. The default decides with [`crate::DuffF32`],
    /// the projection of the f32 kernels.
    fn start_outside(
        &self,
        entry: &BoundaryEntry,
        ray: &Ray,
        hint: &mut EntryHint,
    ) -> Result<Start, TraceOutcome> {
        if !self.walks_tets() {
            // Traced from its origin; `Start::Tet` is ignored.
            return Ok(Start::Tet(0));
        }
        entry.start_with::<crate::walk::DuffF32>(self.mesh(), ray, hint)
    }

    /// False for a tracer that does not walk the tets (a BVH, a brute
    /// force): it traces every ray from its origin, so a ray from outside
    /// the mesh needs no entry face ([`Tracer::start_outside`]).
    fn walks_tets(&self) -> bool {
        true
    }

    /// A shadow ray: [`Tracer::trace`], except that a tet walk reports
    /// [`TraceOutcome::Miss`] as soon as it enters a tet of `stop` (sorted;
    /// the light's tets, see [`crate::secondary::LightTarget`]), start tet
    /// included. The default ignores `stop`, which is right for tracers
    /// without tets (a BVH): the ray then runs to its `t_max`, the light's
    /// distance. The tet kernels override it so that a render's shadow rays
    /// are walked by the kernel being measured.
    fn trace_until(&self, ray: &Ray, start: Start, stop: &[u32]) -> TraceOutcome {
        let _ = stop;
        self.trace(ray, start)
    }

    /// Many shadow rays toward one light: `out[i]` is
    /// [`Tracer::trace_until`] of `rays[i]` from `starts[i]` with `stop`,
    /// over the shortest of the three slices. The default traces them one
    /// by one; the tet kernels walk them side by side (in SIMD lockstep
    /// where the CPU has it), as they walk primary rays, with the same
    /// outcomes bit for bit.
    fn trace_until_batch(
        &self,
        rays: &[Ray],
        starts: &[Start],
        stop: &[u32],
        out: &mut [TraceOutcome],
    ) {
        for ((r, s), o) in rays.iter().zip(starts).zip(out.iter_mut()) {
            *o = self.trace_until(r, *s, stop);
        }
    }
}
