//! The host-side fallback for walks that lost their way: the same rule as
//! the CPU tracers' (`tet_trace_cpu`'s private `lost` module), applied to
//! the outcomes a dispatch downloaded.
//!
//! A floating-point walk decides every step with the exact sign of its
//! rounded projection, which is the walk of a line through the mesh with
//! each vertex moved by that rounding. Where a tet is thinner than the
//! rounding (a near-flat sliver), the moved mesh folds over and the walk
//! can circle until its step cap. The default step cap
//! ([`tet_trace_cpu::walk::step_cap`]: twice the tets, plus 1024) is more
//! than any line's walk takes, so reaching it proves the walk lost; so
//! does a start that finds no tet whose projection holds the line
//! (`Lost`). The CPU tracers then walk the ray again with the exact walk
//! ([`ExactTracer`]: exact predicates, symbolic perturbation) from the same
//! start and report that outcome, with the tets of both walks counted.
//! WGSL has no exact arithmetic, so the GPU tracer does the same on the
//! host, after the outcomes are downloaded: [`exact_where_lost`].
//!
//! A caller that set a lower step cap ([`crate::GpuTracer::with_step_cap`],
//! to bound the work per ray) keeps the `StepCap` (and `Lost`) failure, as
//! on the CPU: below the default cap it no longer proves a lost walk.

use std::time::Instant;

use tet_core::TetMesh;
use tet_trace_cpu::exact::ExactTracer;
use tet_trace_cpu::walk::step_cap;
use tet_trace_cpu::{Ray, Start, Starts, TraceOutcome, Tracer};

use crate::stats::DispatchStats;

/// Replaces every outcome in `out` that lost its way ([`TraceOutcome::lost_its_way`]) under a
/// step cap `cap` at or above the mesh's default by the exact walk's
/// outcome, with the tets of both walks. `start_of(i)` gives the ray and
/// start of outcome `i` (the ray as the walk saw it, the start it walked
/// from), or `None` to leave that outcome as it is (e.g. one that was
/// already re-walked). The walks re-done are counted into
/// [`DispatchStats::host_rewalks`] and their host time into
/// [`DispatchStats::host_rewalk_ms`], kept apart from the GPU's.
pub(crate) fn exact_where_lost(
    mesh: &TetMesh,
    cap: u32,
    out: &mut [TraceOutcome],
    stats: &mut DispatchStats,
    mut start_of: impl FnMut(usize) -> Option<(Ray, Start)>,
) {
    if cap < step_cap(mesh) || !out.iter().any(TraceOutcome::lost_its_way) {
        return;
    }
    let t0 = Instant::now();
    let (mut index, mut rays, mut starts) = (Vec::new(), Vec::new(), Vec::new());
    for (i, o) in out.iter().enumerate() {
        if o.lost_its_way()
            && let Some((ray, start)) = start_of(i)
        {
            index.push(i);
            rays.push(ray);
            starts.push(start);
        }
    }
    if index.is_empty() {
        return;
    }
    // Equal to `ExactTracer::trace` ray by ray (the trait's contract).
    let mut again = vec![TraceOutcome::Miss { tets_visited: 0 }; rays.len()];
    ExactTracer::new(mesh).trace_batch_from(&rays, Starts::Each(&starts), &mut again);
    for (&i, a) in index.iter().zip(again) {
        out[i] = a.with_tets_added(out[i].tets_visited());
    }
    stats.host_rewalks += index.len() as u64;
    stats.host_rewalk_ms += t0.elapsed().as_secs_f64() * 1e3;
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use tet_core::synthetic::{GridSpec, kuhn_grid};
    use tet_trace_cpu::Failure;

    /// A lost walk (step cap or no start) at the default cap gives the
    /// exact walk's outcome with both walks' tets, and is counted; under a
    /// lower cap, not lost, or left out by `start_of`, it stays.
    #[test]
    fn a_lost_walk_takes_the_exact_walks_outcome_at_the_default_cap() {
        let shell = Some(([1; 3], [3; 3]));
        let mesh = kuhn_grid(&GridSpec {
            cells: [4; 3],
            shell,
            ..Default::default()
        });
        let origin = Vec3::splat(0.5);
        let start = Start::Tet(tet_trace_cpu::locate(&mesh, origin, 0).unwrap());
        let ray = Ray::new(origin, Vec3::splat(2.0) - origin);
        let want = ExactTracer::new(&mesh).trace(&ray, start);
        let TraceOutcome::Hit(w) = want else {
            panic!("the exact walk hits the box: {want:?}")
        };
        let cap = step_cap(&mesh);
        let capped = TraceOutcome::Failed {
            failure: Failure::StepCap,
            tets_visited: cap,
        };
        let no_start = TraceOutcome::Failed {
            failure: Failure::Lost,
            tets_visited: 1,
        };
        let miss = TraceOutcome::Miss { tets_visited: 3 };
        let fresh = || [capped, miss, no_start, capped];
        let mut stats = DispatchStats::default();
        let mut out = fresh();
        exact_where_lost(&mesh, cap, &mut out, &mut stats, |i| {
            (i != 3).then_some((ray, start))
        });
        assert_eq!(out[1], miss);
        assert_eq!(out[3], capped, "left out by start_of");
        for (o, spent) in [(out[0], cap), (out[2], 1)] {
            let TraceOutcome::Hit(h) = o else {
                panic!("no hit after the fallback: {o:?}")
            };
            assert_eq!((h.face, h.triangle, h.t), (w.face, w.triangle, w.t));
            assert_eq!(h.tets_visited, w.tets_visited + spent);
        }
        assert_eq!(stats.host_rewalks, 2);
        assert!(stats.host_rewalk_ms >= 0.0);
        assert_eq!(stats.gpu_ms, None);

        // Under a lower cap the failures stay, and nothing is re-walked.
        let mut stats = DispatchStats::default();
        let mut out = fresh();
        exact_where_lost(&mesh, cap - 1, &mut out, &mut stats, |_| Some((ray, start)));
        assert_eq!(out, fresh());
        assert_eq!(stats, DispatchStats::default());
    }
}
