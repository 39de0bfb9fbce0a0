//! The exact walk as the fallback of a floating-point walk that lost its
//! way.
//!
//! A floating-point walk decides every step with the exact sign of its
//! rounded projection, which is the walk of a line through the mesh with
//! each vertex moved by that rounding (the walk's module docs, "Why the
//! walk ends"). Where a tet is thinner than the rounding (a near-flat
//! sliver, which TetGen's output rounded to f32 can hold), the moved mesh
//! folds over and the walk can circle until its step cap. The step cap
//! (twice the tets, plus 1024) is more than any line's walk takes, so
//! reaching it proves the walk lost. So does a start that finds no tet
//! near the origin whose projection holds the line (`Lost`). Such a ray is
//! then walked again by the exact walk of [`crate::exact`] (exact predicates, symbolic
//! perturbation), from the same start, and reports that outcome, with
//! the tets both walks visited.
//!
//! A caller that set a lower step cap ([`crate::kernel::WalkTracer::with_step_cap`],
//! to bound the work per ray) keeps the `StepCap` failure: below the
//! default cap it no longer proves a lost walk.

use tet_core::TetMesh;

use crate::exact::ExactTracer;
use crate::ray::{Ray, TraceOutcome};
use crate::tracer::Tracer;
use crate::walk::{Start, Starts, step_cap};

/// `out`, or the exact walk's outcome of `ray` from `start` where `out`
/// reached a step cap `cap` at or above the mesh's default.
pub(crate) fn exact_if_lost(
    mesh: &TetMesh,
    cap: u32,
    ray: &Ray,
    start: Start,
    out: TraceOutcome,
) -> TraceOutcome {
    if !out.lost_its_way() || cap < step_cap(mesh) {
        return out;
    }
    ExactTracer::new(mesh)
        .trace(ray, start)
        .with_tets_added(out.tets_visited())
}

/// [`exact_if_lost`] over a batch: every outcome in `out` that reached a
/// step cap `cap` at or above the mesh's default is replaced by the exact
/// walk's, from the ray's start in `starts` (entering from outside with
/// the exact walk's own entry decision).
pub(crate) fn exact_where_lost(
    mesh: &TetMesh,
    cap: u32,
    rays: &[Ray],
    starts: Starts<'_>,
    out: &mut [TraceOutcome],
) {
    if cap < step_cap(mesh) || !out.iter().any(TraceOutcome::lost_its_way) {
        return;
    }
    let exact = ExactTracer::new(mesh);
    for (i, (ray, o)) in rays.iter().zip(out.iter_mut()).enumerate() {
        if !o.lost_its_way() {
            continue;
        }
        let one = match starts {
            Starts::Same(s) => Starts::Same(s),
            Starts::Each(s) => match s.get(i) {
                Some(&s) => Starts::Same(s),
                None => continue,
            },
            Starts::Outside(entry) => Starts::Outside(entry),
        };
        let mut again = [*o];
        exact.trace_batch_from(std::slice::from_ref(ray), one, &mut again);
        *o = again[0].with_tets_added(o.tets_visited());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ray::Failure;
    use glam::Vec3;
    use tet_core::synthetic::{GridSpec, kuhn_grid};

    /// A capped walk at the default cap gives the exact walk's outcome (with
    /// both walks' tets); under a lower cap, or not capped, it stays.
    #[test]
    fn a_capped_walk_takes_the_exact_walks_outcome_at_the_default_cap() {
        let shell = Some(([1; 3], [3; 3]));
        let mesh = kuhn_grid(&GridSpec {
            cells: [4; 3],
            shell,
            ..Default::default()
        });
        let origin = Vec3::splat(0.5);
        let start = Start::Tet(crate::locate(&mesh, origin, 0).unwrap());
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
        let TraceOutcome::Hit(got) = exact_if_lost(&mesh, cap, &ray, start, capped) else {
            panic!("no hit after the fallback")
        };
        assert_eq!((got.face, got.t), (w.face, w.t));
        assert_eq!(got.tets_visited, w.tets_visited + cap);
        assert_eq!(exact_if_lost(&mesh, cap - 1, &ray, start, capped), capped);
        let miss = TraceOutcome::Miss { tets_visited: 3 };
        assert_eq!(exact_if_lost(&mesh, cap, &ray, start, miss), miss);

        let rays = [ray, ray, ray];
        let mut out = [capped, miss, capped];
        exact_where_lost(&mesh, cap, &rays, Starts::Same(start), &mut out);
        assert_eq!(out[1], miss);
        for o in [out[0], out[2]] {
            assert_eq!(o.hit().map(|h| (h.face, h.t)), Some((w.face, w.t)));
        }
    }
}
