//! Batches of rays on one thread: the request ([`Batch`]), their starts
//! ([`Starts`]), the [`Feed`] every batch walk draws its lanes from, and
//! the scalar interleaved walk ([`trace_interleaved`]).

use glam::Vec3;
use tet_core::TetMesh;

use super::entry::{BoundaryEntry, EntryHint};
use super::projection::Projection;
use super::start::{Lane, Start, begin, begin_scaled, begin_with, start_scale};
use super::step::{advance, finish_step};
use super::stop::Advance;
use super::topology::Topology;
use crate::ray::{Failure, Ray, TraceOutcome};

/// The starts of a batch of rays: one for all (primary rays from a viewpoint
/// inside the mesh), one per ray, or each ray's entry into the mesh from
/// outside.
#[derive(Clone, Copy, Debug)]
pub enum Starts<'a> {
    /// Every ray starts from this.
    Same(Start),
    /// Ray `i` starts from element `i` (same length as the rays).
    Each(&'a [Start]),
    /// Every ray's origin lies outside the mesh: each enters through the
    /// boundary face its line crosses, decided with the walk's own
    /// projection ([`BoundaryEntry::start_with`]).
    Outside(&'a BoundaryEntry),
}

impl Starts<'_> {
    /// How many rays a batch of `rays` rays and `outs` outcomes walks with
    /// these starts: the shortest of the three ([`Starts::Same`] and
    /// [`Starts::Outside`] serve any number).
    pub fn batch_len(self, rays: usize, outs: usize) -> usize {
        let n = rays.min(outs);
        match self {
            Starts::Each(s) => n.min(s.len()),
            Starts::Same(_) | Starts::Outside(_) => n,
        }
    }
}

/// One batch of walks, as every batch walk takes it (the scalar
/// interleaved walk, [`crate::BatchWalk`], the one lockstep entry
/// [`crate::lockstep::trace`]): ray `rays[i]` walks from its start in
/// `starts` over `topo`, at most `cap` tets, into `out[i]`. The batch is
/// the shorter of `rays` and `out`; [`Starts::Each`] must have a start for
/// each of its rays.
#[derive(Debug)]
pub struct Batch<'a, T: ?Sized> {
    /// The mesh walked (points, constrained faces).
    pub mesh: &'a TetMesh,
    /// Its topology: a layout, or the tracer of a walk over its own
    /// records (Tet80).
    pub topo: &'a T,
    /// The rays.
    pub rays: &'a [Ray],
    /// Where each ray starts.
    pub starts: Starts<'a>,
    /// The step cap: tets visited before a walk reports failure.
    pub cap: u32,
    /// The outcomes, ray by ray.
    pub out: &'a mut [TraceOutcome],
    /// Bounded walks ([`super::trace_within`]): a walk ends as a miss as
    /// soon as the face it leaves through lies wholly past its ray's
    /// `t_max`. Not for gated walks (their handover does not carry it).
    pub bounded: bool,
}

/// Walks interleaved per thread by the scalar batch walk
/// ([`trace_interleaved`]) of the kernels.
pub const LANES: usize = 8;

/// A batch being traced: its rays and starts, the next ray to start, and
/// where the outcomes go. Every batch walk (the interleaved walk here, the
/// SIMD lockstep walks) draws its lanes from one and stores outcomes in it.
pub(crate) struct Feed<'a> {
    pub(crate) mesh: &'a TetMesh,
    pub(crate) rays: &'a [Ray],
    start: Starts<'a>,
    /// The next ray not started yet.
    next: usize,
    /// The boundary face the last ray from outside entered through (tested
    /// first for the next, see [`crate::boundary_entry`]).
    hint: EntryHint,
    /// The projection scale of the last ray started from [`Starts::Same`]
    /// and its origin: rays from one viewpoint share it.
    same_scale: Option<(Vec3, f32)>,
    pub(crate) out: &'a mut [TraceOutcome],
    /// Walks are bounded ([`Batch::bounded`]).
    bounded: bool,
}

impl<'a> Feed<'a> {
    /// A feed of ray `i` from `start` into `out[i]`, over the shorter of
    /// `rays` and `out`.
    #[inline(always)]
    pub(crate) fn new(
        mesh: &'a TetMesh,
        rays: &'a [Ray],
        start: Starts<'a>,
        out: &'a mut [TraceOutcome],
        bounded: bool,
    ) -> Feed<'a> {
        let n = rays.len().min(out.len());
        Feed {
            mesh,
            rays: &rays[..n],
            start,
            next: 0,
            hint: EntryHint::default(),
            same_scale: None,
            out: &mut out[..n],
            bounded,
        }
    }

    /// Starts the next queued ray that does not end before its walk (those
    /// are written to `out` directly): its index and lane.
    #[inline(always)]
    pub(crate) fn next_lane<P: Projection>(&mut self) -> Option<(usize, Lane<P>)> {
        let mesh = self.mesh;
        while self.next < self.rays.len() {
            let i = self.next;
            self.next += 1;
            let ray = &self.rays[i];
            let lane = match self.start {
                Starts::Same(s) => begin_same::<P>(mesh, ray, s, &mut self.same_scale),
                Starts::Each(s) => begin::<P>(mesh, ray, s[i]),
                Starts::Outside(entry) => begin_outside::<P>(mesh, ray, entry, &mut self.hint),
            };
            let lane = match lane {
                Ok(l) if self.bounded => l.bounded(mesh, ray),
                other => other,
            };
            match lane {
                Ok(l) => return Some((i, l)),
                Err(o) => self.out[i] = o,
            }
        }
        None
    }
}

/// Traces many rays (ray `i` from `start` of ray `i`) with `K` walks interleaved on one thread:
/// each round advances every lane by one tet, so the CPU overlaps the
/// dependent load → project → decide → load chains of independent rays
/// (memory-level parallelism without SIMD). Each step prefetches the record
/// of the lane's next tet, which that lane reads a round later.
/// Results are identical to [`trace`](super::step::trace) ray by ray (same
/// `advance` and `finish_step`).
pub fn trace_interleaved<P: Projection, T: Topology, const K: usize>(batch: Batch<'_, T>) {
    let Batch {
        mesh,
        topo,
        rays,
        starts,
        cap,
        out,
        bounded,
    } = batch;
    let mut feed = Feed::new(mesh, rays, starts, out, bounded);
    let points = &mesh.points[..];
    // Lanes in flight, each with its ray index; a finished lane is replaced
    // in place by the next ray, or removed when none is left.
    let mut lanes: Vec<(usize, Lane<P>)> = Vec::with_capacity(K);
    while lanes.len() < K {
        match feed.next_lane() {
            Some(l) => lanes.push(l),
            None => break,
        }
    }
    while !lanes.is_empty() {
        let mut j = 0;
        while j < lanes.len() {
            let adv = advance(points, topo, &mut lanes[j].1, cap);
            if adv == Advance::Go || lane_event(&mut feed, &mut lanes, j, adv) {
                j += 1;
            }
        }
    }
}

/// The out-of-line part of [`trace_interleaved`]'s round: lane `j` stopped
/// with `adv`; finish its step, and when its walk ended, store the outcome
/// and refill or remove the lane. True when `lanes[j]` is (still) a live
/// lane that already took its step this round.
#[cold]
#[inline(never)]
fn lane_event<P: Projection>(
    feed: &mut Feed<'_>,
    lanes: &mut Vec<(usize, Lane<P>)>,
    j: usize,
    adv: Advance,
) -> bool {
    let (i, lane) = &mut lanes[j];
    let i = *i;
    let Some(o) = finish_step(feed.mesh, &feed.rays[i], lane, adv) else {
        return true;
    };
    feed.out[i] = o;
    match feed.next_lane() {
        Some(l) => {
            lanes[j] = l;
            true
        }
        None => {
            lanes.swap_remove(j);
            false
        }
    }
}

/// [`begin`] for rays that share a start: the projection scale, a
/// function of the start tet and the origin ([`start_scale`]), is computed
/// again only when the origin changes.
#[inline(always)]
fn begin_same<P: Projection>(
    mesh: &TetMesh,
    ray: &Ray,
    start: Start,
    last: &mut Option<(Vec3, f32)>,
) -> Result<Lane<P>, TraceOutcome> {
    let scale = match *last {
        Some((o, scale)) if o == ray.origin => scale,
        _ => {
            let scale = start_scale(mesh, ray, start);
            *last = Some((ray.origin, scale));
            scale
        }
    };
    begin_scaled(mesh, ray, start, scale)
}

/// [`begin`] for a ray from outside the mesh: its entry is decided with the
/// projection the walk then uses (set up once). The steps of
/// [`BoundaryEntry::start_with`], spelled out here: one function returning
/// the projection with the start served both, and the batch walks from
/// outside ran 3–5 % slower (Torus Knots and Armadillo, one thread).
#[inline(always)]
fn begin_outside<P: Projection>(
    mesh: &TetMesh,
    ray: &Ray,
    entry: &BoundaryEntry,
    hint: &mut EntryHint,
) -> Result<Lane<P>, TraceOutcome> {
    if !ray.is_valid() {
        return Err(TraceOutcome::Failed {
            failure: Failure::InvalidRay,
            tets_visited: 0,
        });
    }
    if entry.misses_first(ray, hint) {
        return Err(TraceOutcome::Miss { tets_visited: 0 });
    }
    let proj = P::setup_scaled(ray, entry.scale(ray));
    let start = entry.start_projected(mesh, ray, &proj, hint)?;
    begin_with(mesh, ray, proj, start)
}
