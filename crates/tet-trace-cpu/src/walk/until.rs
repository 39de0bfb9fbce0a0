//! Walks that end on entering given tets (shadow rays toward a light
//! inside the mesh): the walk reads the exit link of such a tet as the mesh
//! boundary, so it reports a miss there.

use tet_core::{Link, TetMesh};

use super::projection::Projection;
use super::start::Start;
use super::step::trace;
use super::topology::Topology;
use crate::lockstep::exit::ByLane;
use crate::ray::{Ray, TraceOutcome};

/// True when `tet` is in the sorted set `stop` (a linear scan for the usual
/// one or two tets, binary search beyond).
#[inline(always)]
pub fn stops_at(stop: &[u32], tet: u32) -> bool {
    if stop.len() <= 8 {
        stop.contains(&tet)
    } else {
        stop.binary_search(&tet).is_ok()
    }
}

/// A [`Topology`] that ends the walk when it enters a tet of `stop`: the exit
/// link of such a tet reads as the mesh boundary, so the walk reports a
/// [`TraceOutcome::Miss`] there (for a shadow ray: unoccluded). Everything
/// else is forwarded to `inner` unchanged (same decisions, same
/// watertightness).
#[derive(Clone, Copy, Debug)]
pub struct StopAt<'a, T> {
    /// The layout walked.
    pub inner: &'a T,
    /// Sorted tets at which the walk stops.
    pub stop: &'a [u32],
}

impl<T: Topology> Topology for StopAt<'_, T> {
    /// Not gathered: the stop tets' links read as the boundary.
    type Exit = ByLane;
    #[inline(always)]
    fn vx(&self, tet: u32) -> u32 {
        self.inner.vx(tet)
    }
    #[inline(always)]
    fn exit_link(&self, tet: u32, face: [u32; 3], d: u32, exiting: u32, entry_raw: u32) -> u32 {
        if stops_at(self.stop, tet) {
            Link::BOUNDARY.0
        } else {
            self.inner.exit_link(tet, face, d, exiting, entry_raw)
        }
    }
    #[inline(always)]
    fn prefetch(&self, tet: u32) {
        self.inner.prefetch(tet)
    }
}

/// True when a walk starting at `start` already starts in a stop tet.
pub(crate) fn starts_in(start: Start, stop: &[u32]) -> bool {
    match start {
        Start::Tet(t) => stops_at(stop, t),
        Start::Face { tet, .. } | Start::Entry { tet, .. } => stops_at(stop, tet),
    }
}

fn stopped_at_start() -> TraceOutcome {
    TraceOutcome::Miss { tets_visited: 1 }
}

/// [`trace`] of `ray` from `start` over `topo`, except that the walk reports
/// [`TraceOutcome::Miss`] as soon as it enters a tet of `stop` (sorted; see
/// [`stops_at`]), start tet included.
pub fn trace_until<P: Projection, T: Topology>(
    mesh: &TetMesh,
    topo: &T,
    ray: &Ray,
    start: Start,
    stop: &[u32],
    cap: u32,
) -> TraceOutcome {
    if ray.is_valid() && starts_in(start, stop) {
        return stopped_at_start();
    }
    let topo = StopAt { inner: topo, stop };
    trace::<P, _>(mesh, &topo, ray, start, cap)
}
