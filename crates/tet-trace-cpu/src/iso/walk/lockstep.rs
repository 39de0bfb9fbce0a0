//! The iso walk's empty stretch in SIMD lockstep.
//!
//! From a viewpoint outside the volume most of a ray's walk crosses tets
//! whose four values lie on one side of every isovalue: the range test
//! fails and nothing else happens there. Those steps are exactly the steps
//! of the surface walk, so they run in the lockstep walk of
//! [`crate::lockstep`] (8 or 16 rays per SIMD pack), gated by the range
//! test: a lane about to enter a tet that straddles an isovalue leaves the
//! lockstep walk, and the scalar iso walk ([`IsoWalk::step`]) goes on from
//! that tet with the same state (entry face, exit history, tets visited)
//! and the same projection (a function of the ray and its entry). Every
//! decision is the scalar walk's, so the outcome is [`IsoWalk::trace_from`]'s
//! bit for bit; rays that leave the volume inside the lockstep walk miss
//! there.

use tet_core::TetMesh;

use super::super::{IsoQuery, IsoStats};
use super::ray::Ctx;
use super::{IsoOutcome, IsoWalk, WalkState, converted};
use crate::lockstep::{self, Gate, Handover, Planar, Width};
use crate::ray::{Failure, Ray, TraceOutcome};
use crate::walk::start::begin;
use crate::walk::{Batch, DuffF32, EntryHint, Start, Starts, Topology};

/// The range test as a gate: walks stop short of the first tet whose
/// values straddle an isovalue.
struct RangeGate<'a> {
    ranges: &'a [[f32; 2]],
    /// Only its range test is used (the per-ray parts belong to any ray).
    ctx: Ctx<'a>,
    handed: Vec<(usize, Handover)>,
}

impl Gate<Handover> for RangeGate<'_> {
    const ON: bool = true;

    #[inline(always)]
    fn stops_before(&self, tet: u32) -> bool {
        // A tet out of range is the scalar walk's to report (lost).
        self.ranges
            .get(tet as usize)
            .is_none_or(|&r| self.ctx.active(r))
    }

    fn hand_over(&mut self, ray: usize, h: Handover) {
        self.handed.push((ray, h));
    }
}

impl IsoWalk<'_> {
    /// [`IsoWalk::trace_tile`] for rays from outside the volume over
    /// `topo`: the empty stretch of every walk in lockstep, the rest scalar.
    pub(super) fn tile_lockstep<T: Topology>(
        &self,
        topo: &T,
        rays: &[Ray],
        query: &IsoQuery,
        out: &mut [IsoOutcome],
        stats: &mut IsoStats,
    ) {
        let n = rays.len().min(out.len());
        if n == 0 {
            return;
        }
        if query.check().is_err() {
            out[..n].fill(IsoOutcome::Failed {
                failure: Failure::InvalidRay,
                tets_visited: 0,
            });
            return;
        }
        let mesh: &TetMesh = &self.mesh;
        // Rays that meet no live region miss without a walk; the others
        // start at their first region where that is far enough in.
        let regions = self.first_regions(&rays[..n], query, stats);
        let mut prev = None;
        // Each ray's entry face (rays that miss the volume end here).
        let mut hint = EntryHint::default();
        let (mut index, mut starts, mut walking) = (Vec::new(), Vec::new(), Vec::new());
        for (i, ray) in rays[..n].iter().enumerate() {
            let Some(start) = self.tile_start(ray, regions[i], None, &mut prev, &mut hint) else {
                out[i] = IsoOutcome::Miss { tets_visited: 0 };
                continue;
            };
            match start {
                Ok(s) => {
                    index.push(i);
                    starts.push(s);
                    walking.push(*ray);
                }
                Err(o) => out[i] = converted(o),
            }
        }
        if walking.is_empty() {
            return;
        }
        let mut gate = RangeGate {
            ranges: &self.ranges,
            ctx: Ctx::new(mesh, self.values, &walking[0], query),
            handed: Vec::new(),
        };
        let mut ends = vec![TraceOutcome::Miss { tets_visited: 0 }; walking.len()];
        let batch = Batch {
            mesh,
            topo,
            rays: &walking,
            starts: Starts::Each(&starts),
            cap: self.cap,
            out: &mut ends,
            bounded: false,
        };
        if let Err(batch) = lockstep::trace::<Planar, _, _>(batch, Width::Auto, &mut gate) {
            // No SIMD lanes, or records they cannot gather: the portable
            // lanes, which read any topology.
            let ran = lockstep::trace::<Planar, _, _>(batch, Width::Portable8, &mut gate);
            debug_assert!(ran.is_ok(), "the portable lanes read any topology");
        }
        let mut handed = vec![false; walking.len()];
        for &(j, _) in &gate.handed {
            handed[j] = true;
        }
        // Walks that ended in lockstep: they left the volume, or failed,
        // without entering a tet that straddles an isovalue.
        for (j, end) in ends.iter().enumerate().filter(|(j, _)| !handed[*j]) {
            stats.range_tests += u64::from(end.tets_visited());
            out[index[j]] = converted(*end);
        }
        for (j, h) in gate.handed {
            let o = self.resume(topo, &walking[j], starts[j], h, query, stats);
            out[index[j]] = o;
        }
    }

    /// The scalar iso walk of `ray` (from `start`) resumed where the
    /// lockstep walk handed it over, to its end.
    fn resume<T: Topology>(
        &self,
        topo: &T,
        ray: &Ray,
        start: Start,
        h: Handover,
        query: &IsoQuery,
        stats: &mut IsoStats,
    ) -> IsoOutcome {
        let mesh: &TetMesh = &self.mesh;
        // The same projection as the lockstep lane's (the same `begin`).
        let mut lane = match begin::<DuffF32>(mesh, ray, start) {
            Ok(l) => l,
            Err(o) => return converted(o),
        };
        let opened = lane.st.visited;
        h.resume(&mut lane, &mesh.points);
        let mut w = WalkState {
            lane,
            cached: None,
            ctx: Ctx::new(mesh, self.values, ray, query),
            opened,
        };
        loop {
            if let Some(o) = self.step(topo, &mut w, stats) {
                stats.range_tests += u64::from(o.tets_visited().saturating_sub(opened));
                return o;
            }
        }
    }
}
