//! The lockstep walk, written once over lanes `L` ([`Lanes`]), a
//! projection `G` ([`Geometry`]) and record reads `X` ([`Records`]): the
//! packs of lanes in registers, one round of the walk, the rare path, the
//! driver. Every function is `#[inline(always)]`, so that the walk compiled
//! inside a `#[target_feature]` entry point inlines down to the intrinsics;
//! the rare paths run out of line through [`Lanes::cold`].

use glam::Vec3;
use tet_core::{Link, TetMesh};

use super::exit::Records;
use super::geometry::Geometry;
use super::lanes::Lanes;
use crate::ray::{Ray, TraceOutcome};
use crate::walk::lanes::{Feed, Starts};
use crate::walk::projection::Projection;
use crate::walk::start::Lane;
use crate::walk::stop::{Advance, Stopped};
use crate::walk::stopped::{AfterStop, after_stop};

/// A walk's state between two tets, as the scalar walk keeps it (its
/// `Lane` less the projection, which is a function of the ray and start):
/// about to enter `next` through the face `ids`, from tet `entry_raw`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Handover {
    pub(crate) ids: [u32; 3],
    pub(crate) next: u32,
    pub(crate) entry_raw: u32,
    pub(crate) visited: u32,
}

impl Handover {
    /// The state of a scalar lane between two tets.
    #[inline(always)]
    fn of<P: Projection>(lane: &Lane<P>) -> Self {
        Handover {
            ids: lane.st.ids,
            next: lane.next,
            entry_raw: lane.entry_raw,
            visited: lane.st.visited,
        }
    }

    /// Puts this state into `lane`, a lane of the same ray and start (so
    /// the same projection). The entry face's points are projected anew: a
    /// pure function of the point, so the same bits the lockstep lane held.
    pub(crate) fn resume<P: Projection>(self, lane: &mut Lane<P>, points: &[Vec3]) {
        for (slot, &i) in self.ids.iter().enumerate() {
            let p = points.get(i as usize).copied().unwrap_or(Vec3::NAN);
            P::set_point(&mut lane.st.p, slot, lane.proj.project(p));
        }
        lane.st.ids = self.ids;
        lane.st.visited = self.visited;
        lane.next = self.next;
        lane.entry_raw = self.entry_raw;
    }
}

/// Where a gated lockstep walk stops short: before every round, a lane
/// about to enter a tet the gate names leaves the walk (its state goes to
/// [`Gate::hand_over`], its outcome is not written) and the lane is
/// refilled. The plain walk's gate ([`NoGate`]) names none and compiles
/// away.
pub(crate) trait Gate {
    /// False for [`NoGate`]: no check at all.
    const ON: bool;
    /// Whether a walk stops before entering `tet`.
    fn stops_before(&self, tet: u32) -> bool;
    /// Receives ray `ray`'s walk, stopped before entering `h.next`.
    fn hand_over(&mut self, ray: usize, h: Handover);
}

/// The plain walk: never stops short.
pub(crate) struct NoGate;

impl Gate for NoGate {
    const ON: bool = false;
    #[inline(always)]
    fn stops_before(&self, _: u32) -> bool {
        false
    }
    #[inline(always)]
    fn hand_over(&mut self, _: usize, _: Handover) {}
}

/// `L::WIDTH` walks in registers, and per lane its cold part.
struct Pack<L: Lanes, G: Geometry<L>> {
    ray: G::Ray,
    /// The entry face: projected points and ids (counter-clockwise).
    face: [G::Vert; 3],
    ids: [L::I; 3],
    /// Tet entered next.
    next: L::I,
    /// Raw link it is entered through.
    entry: L::I,
    /// Tets visited so far.
    visited: L::I,
    /// Lanes holding a walk (else parked: state frozen, loads in range,
    /// results ignored).
    live: L::M,
    /// Index of each lane's ray in the batch.
    ray_index: L::Arr<usize>,
    cold: L::Arr<G::Cold>,
}

impl<L: Lanes, G: Geometry<L>> Pack<L, G> {
    /// Every lane parked on tet 0 (exists whenever a walk started, so the
    /// loads of parked lanes stay in range).
    #[inline(always)]
    fn parked(l: L) -> Self {
        let (ray, v) = G::zero(l);
        let z = l.splat_i(0);
        Pack {
            ray,
            face: [v; 3],
            ids: [z; 3],
            next: z,
            entry: z,
            visited: z,
            live: l.mask_of_bits(0),
            ray_index: L::arr(0),
            cold: L::arr(G::Cold::default()),
        }
    }

    /// Loads scalar lane `lane` of ray `ray` into lane `k`.
    #[inline(always)]
    fn put(&mut self, l: L, k: usize, ray: usize, lane: &Lane<G::Proj>) {
        self.cold.as_mut()[k] = G::put(l, k, &mut self.ray, &mut self.face, lane);
        for (x, &v) in self.ids.iter_mut().zip(&lane.st.ids) {
            *x = l.set_i(*x, k, v);
        }
        self.next = l.set_i(self.next, k, lane.next);
        self.entry = l.set_i(self.entry, k, lane.entry_raw);
        self.visited = l.set_i(self.visited, k, lane.st.visited);
        self.live = l.or_m(self.live, l.mask_of_bits(1 << k));
        self.ray_index.as_mut()[k] = ray;
    }

    /// The entry face's vertex ids of lane `k`.
    #[inline(always)]
    fn ids_of(&self, l: L, k: usize) -> [u32; 3] {
        [
            l.get_i(self.ids[0], k),
            l.get_i(self.ids[1], k),
            l.get_i(self.ids[2], k),
        ]
    }

    /// Parks lane `k` (on tet 0).
    #[inline(always)]
    fn park(&mut self, l: L, k: usize) {
        self.live = l.andnot_m(l.mask_of_bits(1 << k), self.live);
        self.next = l.set_i(self.next, k, 0);
    }

    /// Lanes filled with the next walks of the batch that do not end in
    /// their start tet (the others are written to `out`), parked when there
    /// are fewer; and the number of live lanes.
    #[inline(always)]
    fn fill(l: L, feed: &mut Feed<'_>) -> (Self, usize) {
        let mut pk = Self::parked(l);
        let mut live = 0;
        for k in 0..L::WIDTH {
            if let Some((i, lane)) = feed.next_lane::<G::Proj>() {
                pk.put(l, k, i, &lane);
                live += 1;
            }
        }
        (pk, live)
    }
}

/// What a round leaves for the rare path, as lane bits: the lanes that
/// stopped, whose decoded vertex was out of range, that reached the step
/// cap; and the exit links.
struct Round<L: Lanes> {
    events: u32,
    lost: u32,
    capped: u32,
    raw: L::Arr<u32>,
}

/// One round: every live lane enters its next tet and, in the common case,
/// moves on to the exit neighbour; `Some` when some live lane needs the rare
/// path (the step cap, an out-of-range vertex, a non-tet exit link).
#[inline(always)]
fn step<L: Lanes, G: Geometry<L>, X: Records<L>>(
    l: L,
    pk: &mut Pack<L, G>,
    x: &X,
    points: &[Vec3],
    cap: u32,
) -> Option<Round<L>> {
    // Loads: the new vertex `d` and its point.
    let (d, scratch) = x.enter(l, pk.next, &pk.ids);
    let dc = l.min_u(d, l.splat_i(points.len() as u32 - 1));
    let lost = l.ne_i(dc, d);
    // SAFETY: `dc ≤ points.len() − 1` per lane, and `3 · points.len()`
    // fits in an `i32` (asserted by `run`).
    let p = unsafe { l.gather_point(points, dc) };
    // Projection and Algorithm 1's three edge tests; a zero edge value
    // takes the scalar tie rule for that lane.
    let v = G::project(l, &pk.ray, p);
    let dets = G::edges(l, &pk.ray, &v, &pk.face);
    let zero = l.splat_f(0.0);
    let mut left = [
        l.gt_f(dets[0], zero),
        l.gt_f(dets[1], zero),
        l.gt_f(dets[2], zero),
    ];
    let tie = l.or_m(
        l.or_m(l.eq_f(dets[0], zero), l.eq_f(dets[1], zero)),
        l.eq_f(dets[2], zero),
    );
    let tie = l.and_m(tie, pk.live);
    if l.any(tie) {
        let pk = &*pk;
        left = l.cold(move || ties(l, pk, d, &v, tie, left));
    }
    // Exit slot (`EXIT_SLOT`): 2 when left of d→a and right of d→b, 1 when
    // right of d→a and left of d→c, else 0; the exiting vertex.
    let s2 = l.andnot_m(left[1], left[0]);
    let s1 = l.andnot_m(left[0], left[2]);
    let s0 = l.not_m(l.or_m(s1, s2));
    let e = l.select_i(s1, pk.ids[1], l.select_i(s2, pk.ids[2], pk.ids[0]));
    let link = x.link(l, scratch, pk.next, &pk.ids, d, e, pk.entry);
    // Commit: replace the exiting vertex, count the tet, move on.
    let capped = l.ge_u(pk.visited, l.splat_i(cap));
    let go = l.andnot_m(l.or_m(capped, lost), pk.live);
    for (k, s) in [s0, s1, s2].into_iter().enumerate() {
        let sel = l.and_m(go, s);
        pk.ids[k] = l.select_i(sel, d, pk.ids[k]);
        pk.face[k] = G::select(l, sel, v, pk.face[k]);
    }
    pk.visited = l.inc(pk.visited, go);
    let moving = l.and_m(go, l.lt_u(link, l.splat_i(Link::BOUNDARY.0)));
    pk.entry = l.select_i(moving, pk.next, pk.entry);
    pk.next = l.select_i(moving, link, pk.next);
    x.prefetch(l, link);
    let events = l.andnot_m(moving, pk.live);
    if !l.any(events) {
        return None;
    }
    Some(Round {
        events: l.bits(events),
        lost: l.bits(lost),
        capped: l.bits(capped),
        raw: L::i_lanes(link),
    })
}

/// The scalar tie rule for the lanes of `tie` (their edge tests replaced).
#[inline(always)]
fn ties<L: Lanes, G: Geometry<L>>(
    l: L,
    pk: &Pack<L, G>,
    d: L::I,
    v: &G::Vert,
    tie: L::M,
    left: [L::M; 3],
) -> [L::M; 3] {
    // No closures over lane operations here: a closure not inlined would
    // lose the instruction set of the entry point.
    let tie = l.bits(tie);
    let mut bits = [l.bits(left[0]), l.bits(left[1]), l.bits(left[2])];
    let (d, ids) = (L::i_lanes(d), pk.ids.map(L::i_lanes));
    for k in (0..L::WIDTH).filter(|k| tie >> k & 1 != 0) {
        let id = [ids[0].as_ref()[k], ids[1].as_ref()[k], ids[2].as_ref()[k]];
        let m = G::tie_mask(&pk.cold.as_ref()[k], &pk.face, v, k, d.as_ref()[k], id);
        for (s, b) in bits.iter_mut().enumerate() {
            *b = *b & !(1 << k) | ((m >> s & 1) as u32) << k;
        }
    }
    [
        l.mask_of_bits(bits[0]),
        l.mask_of_bits(bits[1]),
        l.mask_of_bits(bits[2]),
    ]
}

/// The rare part of a round: each lane of `r.events` stopped; finish its
/// step with the scalar engine, and when its walk ended store the outcome
/// and refill the lane (or park it). Only what ending or crossing needs is
/// read from the registers. Returns the number of lanes parked.
#[inline(always)]
fn events<L: Lanes, G: Geometry<L>>(
    l: L,
    feed: &mut Feed<'_>,
    pk: &mut Pack<L, G>,
    r: &Round<L>,
) -> usize {
    let mut parked = 0;
    for k in (0..L::WIDTH).filter(|k| r.events >> k & 1 != 0) {
        let bit = |b: u32| b >> k & 1 != 0;
        let link = r.raw.as_ref()[k];
        let stopped = Stopped {
            adv: Advance::stopped(bit(r.capped), bit(r.lost)),
            ids: pk.ids_of(l, k),
            tet: l.get_i(pk.next, k),
            visited: l.get_i(pk.visited, k),
            link,
        };
        match after_stop::<G::Proj>(feed, pk.ray_index.as_ref()[k], stopped) {
            AfterStop::Cross(n) => {
                pk.entry = l.set_i(pk.entry, k, link);
                pk.next = l.set_i(pk.next, k, n);
            }
            AfterStop::Refill(j, lane) => pk.put(l, k, j, &lane),
            AfterStop::Park => {
                pk.park(l, k);
                parked += 1;
            }
        }
    }
    parked
}

/// Hands over the lanes of `stop` (their next tet is the gate's) and
/// refills them, handing over at once the new walks whose first tet is the
/// gate's too. Returns the number of lanes parked.
#[inline(always)]
fn gate_lanes<L: Lanes, G: Geometry<L>, GT: Gate>(
    l: L,
    feed: &mut Feed<'_>,
    pk: &mut Pack<L, G>,
    gate: &mut GT,
    stop: u32,
) -> usize {
    let mut parked = 0;
    for k in (0..L::WIDTH).filter(|k| stop >> k & 1 != 0) {
        let h = Handover {
            ids: pk.ids_of(l, k),
            next: l.get_i(pk.next, k),
            entry_raw: l.get_i(pk.entry, k),
            visited: l.get_i(pk.visited, k),
        };
        gate.hand_over(pk.ray_index.as_ref()[k], h);
        loop {
            match feed.next_lane::<G::Proj>() {
                Some((j, lane)) if gate.stops_before(lane.next) => {
                    gate.hand_over(j, Handover::of(&lane));
                }
                Some((j, lane)) => {
                    pk.put(l, k, j, &lane);
                    break;
                }
                None => {
                    pk.park(l, k);
                    parked += 1;
                    break;
                }
            }
        }
    }
    parked
}

/// Traces `rays` from `start` (at most `cap` tets each) with `PACKS` packs
/// of `L::WIDTH` lanes stepped in turn (the out-of-order core overlaps
/// their dependent load chains); `out[i]` is exactly the scalar walk of
/// `rays[i]` with `G::Proj`, except for the walks `gate` stops short
/// (their `out` is left as it was). The points must number at most
/// `i32::MAX / 3`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn run<L: Lanes, G: Geometry<L>, X: Records<L>, GT: Gate, const PACKS: usize>(
    l: L,
    records: &X,
    mesh: &TetMesh,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
    gate: &mut GT,
) {
    // The gathers' indices `3·i` of the points fit in an `i32` (checked
    // by `RecordWords::gatherable` for every gathered layout already).
    assert!(
        mesh.points.len() <= i32::MAX as usize / 3,
        "too many points for the lockstep walk"
    );
    let mut feed = Feed::new(mesh, rays, start, out);
    let mut packs: [(Pack<L, G>, usize); PACKS] = std::array::from_fn(|_| Pack::fill(l, &mut feed));
    // A walk started only if the mesh has points and tets (its start tet
    // and vertices exist), so the loads of `step` have something to clamp to.
    if mesh.points.is_empty() {
        return;
    }
    let points = &mesh.points[..];
    loop {
        let mut any = false;
        for (pk, live) in packs.iter_mut() {
            if *live == 0 {
                continue;
            }
            if GT::ON {
                let next = L::i_lanes(pk.next);
                let live_bits = l.bits(pk.live);
                let mut stop = 0u32;
                for k in (0..L::WIDTH).filter(|k| live_bits >> k & 1 != 0) {
                    if gate.stops_before(next.as_ref()[k]) {
                        stop |= 1 << k;
                    }
                }
                if stop != 0 {
                    *live -= l.cold(|| gate_lanes(l, &mut feed, pk, gate, stop));
                    if *live == 0 {
                        continue;
                    }
                }
            }
            any = true;
            if let Some(r) = step(l, pk, records, points, cap) {
                *live -= l.cold(|| events(l, &mut feed, pk, &r));
            }
        }
        if !any {
            break;
        }
    }
}

/// [`run`] without a gate: every walk to its end.
#[inline(always)]
pub(crate) fn run_plain<L: Lanes, G: Geometry<L>, X: Records<L>, const PACKS: usize>(
    l: L,
    records: &X,
    mesh: &TetMesh,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
) {
    run::<L, G, X, NoGate, PACKS>(l, records, mesh, rays, start, cap, out, &mut NoGate);
}
