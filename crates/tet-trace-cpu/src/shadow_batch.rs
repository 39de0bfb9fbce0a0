//! Shadow rays in batches: many walks that each end on entering given
//! tets (the light's star, [`crate::secondary::LightTarget`]), walked side
//! by side like primary rays, with, ray by ray, exactly the outcome of the
//! single-ray walk ([`crate::walk::trace_until`], the Tet80 tracers' own).
//!
//! The single-ray walk stops by reading the exit link of a stop tet as
//! the mesh boundary ([`StopAt`]): a topology the SIMD lockstep walk
//! cannot gather (its links are not the layout's words). So the batch
//! walks the layout itself, in lockstep ([`crate::lockstep::trace`]), with
//! a [`Gate`] that takes a lane out of the walk *before* it enters a stop
//! tet and writes the outcome the single-ray walk reaches there: it
//! enters the tet (one more tet visited) and ends with a
//! [`TraceOutcome::Miss`], unless the step cap (or, on a corrupt layout,
//! an out-of-range vertex) stops it first, exactly as that walk's step
//! checks them ([`projected_end`], [`plucker_end`]). A stop tet is only
//! ever entered through a link the walk followed, a crossing or its first
//! tet, and the gate checks every lane before every step, so no walk
//! passes one.
//!
//! The start is the single-ray walk's too: a valid ray whose start tet is
//! a stop tet ends there (`Miss` after one tet) before any walk
//! ([`without_stopped_starts`]; the Tet80 tracers apply their own test in
//! their start). A light outside the mesh has no stop tets: those batches
//! run the plain lockstep walk, with no gate. Where the lockstep walk
//! gives a batch back (no SIMD lanes, records it cannot gather,
//! `TET_LOCKSTEP=scalar`), the projected walks run it with the scalar
//! interleaved walk over [`StopAt`] ([`interleaved`]), the single-ray
//! walk's own step, and the Tet80 tracers ray by ray.

use glam::{Vec2, Vec3};
use tet_core::TetMesh;
use tet_core::layout::{Tet80, Tet80Face};

use crate::lockstep::plucker::{Begun, PluckerWalk};
use crate::lockstep::{self, Gate, Geometry, Handover, NoGate, Plucker, Width};
use crate::ray::{Failure, Ray, TraceOutcome};
use crate::walk::until::starts_in;
use crate::walk::{
    Batch, LANES, Projection, Start, Starts, StopAt, Topology, stops_at, trace_interleaved,
};

/// The single-ray walk's outcome where it stops in its start tet.
const STOPPED_AT_START: TraceOutcome = TraceOutcome::Miss { tets_visited: 1 };

/// The gate of a batch of shadow rays: a walk stops short of every tet of
/// `stop`, and `end` gives its outcome from the state handed over.
struct StopGate<'a, F> {
    stop: &'a [u32],
    end: F,
    /// Ray index (in the batch) and outcome of every walk stopped.
    ended: Vec<(usize, TraceOutcome)>,
}

impl<H, F: Fn(H) -> TraceOutcome> Gate<H> for StopGate<'_, F> {
    const ON: bool = true;
    #[inline(always)]
    fn stops_before(&self, tet: u32) -> bool {
        stops_at(self.stop, tet)
    }
    fn only(&self) -> Option<u32> {
        match *self.stop {
            [tet] => Some(tet),
            _ => None,
        }
    }
    fn hand_over(&mut self, ray: usize, h: H) {
        self.ended.push((ray, (self.end)(h)));
    }
}

/// Walks `batch` in lockstep with geometry `G` at `width`, every walk
/// stopped on entering a tet of `stop` with the outcome `end` gives for the
/// state handed over there (with no gate at all for an empty `stop`).
/// `Err` gives the batch back untraced, as [`lockstep::trace`] does.
pub(crate) fn gated<'a, G, T>(
    batch: Batch<'a, T>,
    stop: &[u32],
    width: Width,
    end: impl Fn(G::Handover) -> TraceOutcome,
) -> Result<(), Batch<'a, T>>
where
    G: Geometry<T>,
    T: ?Sized,
{
    if stop.is_empty() {
        return lockstep::trace::<G, T, _>(batch, width, &mut NoGate);
    }
    let Batch {
        mesh,
        topo,
        rays,
        starts,
        cap,
        out,
        bounded,
    } = batch;
    let mut gate = StopGate {
        stop,
        end,
        ended: Vec::new(),
    };
    let inner = Batch {
        mesh,
        topo,
        rays,
        starts,
        cap,
        out: &mut *out,
        // The gate's handover does not carry a bound.
        bounded: false,
    };
    if lockstep::trace::<G, T, _>(inner, width, &mut gate).is_err() {
        // Nothing traced: the same batch, given back whole.
        return Err(Batch {
            mesh,
            topo,
            rays,
            starts,
            cap,
            out,
            bounded,
        });
    }
    for (i, o) in gate.ended {
        out[i] = o;
    }
    Ok(())
}

/// The outcome of the projected walk (over `topo`, `points` points, step
/// cap `cap`) handed over before it enters a stop tet: what its next step
/// (`advance` over [`StopAt`]) does there — the step cap, a new vertex out
/// of range, else one more tet and the stop tet's exit read as the
/// boundary, a miss.
pub(crate) fn projected_end<T: Topology>(
    h: Handover,
    topo: &T,
    points: usize,
    cap: u32,
) -> TraceOutcome {
    if h.visited >= cap {
        return TraceOutcome::Failed {
            failure: Failure::StepCap,
            tets_visited: h.visited,
        };
    }
    let d = h.ids[0] ^ h.ids[1] ^ h.ids[2] ^ topo.vx(h.next);
    if d as usize >= points {
        return TraceOutcome::Failed {
            failure: Failure::Lost,
            tets_visited: h.visited,
        };
    }
    TraceOutcome::Miss {
        tets_visited: h.visited + 1,
    }
}

/// The outcome of the Plücker walk (step cap `cap`) handed over before it
/// enters a stop tet: what its loop does there (the Tet80 tracers' walk) —
/// the step cap, else one more tet and a miss.
fn plucker_end(b: Begun, cap: u32) -> TraceOutcome {
    if b.visited >= cap {
        TraceOutcome::Failed {
            failure: Failure::StepCap,
            tets_visited: b.visited,
        }
    } else {
        TraceOutcome::Miss {
            tets_visited: b.visited + 1,
        }
    }
}

/// The start of ray `i` of a batch (none for rays entering from outside).
fn start_of(starts: Starts<'_>, i: usize) -> Option<Start> {
    match starts {
        Starts::Same(s) => Some(s),
        Starts::Each(s) => s.get(i).copied(),
        Starts::Outside(_) => None,
    }
}

/// The rays of `batch` that the single-ray walk ends in their start tet
/// (valid, starting in a tet of `stop`) get that outcome; `walk` traces
/// the others (the whole batch when there are none, the usual case, else
/// a copy of the rest). Returns what `walk` returns.
fn without_stopped_starts<T: ?Sized>(
    batch: Batch<'_, T>,
    stop: &[u32],
    walk: impl FnOnce(Batch<'_, T>) -> bool,
) -> bool {
    let Batch {
        mesh,
        topo,
        rays,
        starts,
        cap,
        out,
        bounded,
    } = batch;
    let n = starts.batch_len(rays.len(), out.len());
    let (rays, out) = (&rays[..n], &mut out[..n]);
    let stopped =
        |i: usize| rays[i].is_valid() && start_of(starts, i).is_some_and(|s| starts_in(s, stop));
    if stop.is_empty() || !(0..n).any(stopped) {
        return walk(Batch {
            mesh,
            topo,
            rays,
            starts,
            cap,
            out,
            bounded,
        });
    }
    let mut keep = Vec::with_capacity(n);
    for (i, o) in out.iter_mut().enumerate() {
        if stopped(i) {
            *o = STOPPED_AT_START;
        } else {
            keep.push(i);
        }
    }
    let sub_rays: Vec<Ray> = keep.iter().map(|&i| rays[i]).collect();
    // Every kept ray has a start: `Outside` stops none, so it is never here.
    let sub_starts: Vec<Start> = keep.iter().filter_map(|&i| start_of(starts, i)).collect();
    let mut sub_out: Vec<TraceOutcome> = keep.iter().map(|&i| out[i]).collect();
    let ran = walk(Batch {
        mesh,
        topo,
        rays: &sub_rays,
        starts: Starts::Each(&sub_starts),
        cap,
        out: &mut sub_out,
        bounded,
    });
    for (&i, o) in keep.iter().zip(sub_out) {
        out[i] = o;
    }
    ran
}

/// The scalar interleaved walk over [`StopAt`] (the single-ray walk's
/// step, [`LANES`] walks per thread): `batch`'s walks, each ending on
/// entering a tet of `stop`, in the single-ray walk's outcome.
pub(crate) fn interleaved<P: Projection, T: Topology>(batch: Batch<'_, T>, stop: &[u32]) {
    without_stopped_starts(batch, stop, |b| {
        walk_interleaved::<P, T>(b, stop);
        false
    });
}

/// [`interleaved`] after the starts are sorted out.
fn walk_interleaved<P: Projection, T: Topology>(batch: Batch<'_, T>, stop: &[u32]) {
    let topo = StopAt {
        inner: batch.topo,
        stop,
    };
    trace_interleaved::<P, _, LANES>(Batch {
        mesh: batch.mesh,
        topo: &topo,
        rays: batch.rays,
        starts: batch.starts,
        cap: batch.cap,
        out: batch.out,
        bounded: batch.bounded,
    });
}

/// `batch`'s shadow walks (each ending on entering a tet of `stop`) with
/// the projected lockstep geometry `G` at `width`, or, where the lockstep
/// walk gives the batch back, the scalar interleaved walk with `P`
/// (`G`'s projection). Each outcome is [`crate::walk::trace_until`]'s.
/// True when the walks ran in lockstep.
pub(crate) fn projected<G, P, T>(batch: Batch<'_, T>, stop: &[u32], width: Width) -> bool
where
    G: Geometry<T, Handover = Handover>,
    P: Projection,
    T: Topology,
{
    without_stopped_starts(batch, stop, |b| {
        let (mesh, topo, cap): (&TetMesh, &T, u32) = (b.mesh, b.topo, b.cap);
        let points = mesh.points.len();
        let end = |h: Handover| projected_end(h, topo, points, cap);
        match gated::<G, T>(b, stop, width, end) {
            Ok(()) => true,
            Err(b) => {
                walk_interleaved::<P, T>(b, stop);
                false
            }
        }
    })
}

/// A Plücker walk (the Tet80 tracers) whose starts can apply the stop
/// test of its single-ray shadow walk.
pub(crate) trait PluckerUntil: PluckerWalk {
    /// [`PluckerWalk::starts`], each walk ending at its start where the
    /// single-ray shadow walk ends there (a start tet among `stop`).
    fn starts_until<'a>(
        &'a self,
        rays: &'a [Ray],
        starts: Starts<'a>,
        stop: &'a [u32],
    ) -> impl FnMut(usize) -> Result<Begun, TraceOutcome> + 'a;
}

/// A Plücker walk whose starts stop at the tets of `stop` (the lockstep
/// gate stops the walks after their start).
struct Until<'a, W> {
    walk: &'a W,
    stop: &'a [u32],
}

impl<W: PluckerUntil> PluckerWalk for Until<'_, W> {
    const CONSISTENT: bool = W::CONSISTENT;
    fn records(&self) -> &[Tet80] {
        self.walk.records()
    }
    fn starts<'a>(
        &'a self,
        rays: &'a [Ray],
        starts: Starts<'a>,
    ) -> impl FnMut(usize) -> Result<Begun, TraceOutcome> + 'a {
        self.walk.starts_until(rays, starts, self.stop)
    }
    fn leave(
        &self,
        ray: &Ray,
        tet: u32,
        f: Tet80Face,
        visited: u32,
    ) -> Result<(u32, usize), TraceOutcome> {
        self.walk.leave(ray, tet, f, visited)
    }
    fn left_tie(pp: Vec2, p: Vec3, pq: Vec2, q: Vec3) -> bool {
        W::left_tie(pp, p, pq, q)
    }
}

/// `batch`'s shadow walks over a Plücker walk (each ending on entering a
/// tet of `stop`, as the single-ray walk does) in lockstep at `width`;
/// false, nothing traced, where the lockstep walk gives the batch back.
pub(crate) fn plucker<W: PluckerUntil>(batch: Batch<'_, W>, stop: &[u32], width: Width) -> bool {
    let Batch {
        mesh,
        topo,
        rays,
        starts,
        cap,
        out,
        bounded,
    } = batch;
    let until = Until { walk: topo, stop };
    let batch = Batch {
        mesh,
        topo: &until,
        rays,
        starts,
        cap,
        out,
        bounded,
    };
    gated::<Plucker, _>(batch, stop, width, |b| plucker_end(b, cap)).is_ok()
}
