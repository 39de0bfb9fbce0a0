//! The projected walk in lockstep (Tet20, Tet16, Tet32 with
//! [`Planar`], ScTP with [`Triple`]), written once over lanes `L`
//! ([`Lanes`]), a projection `G` ([`Projected`]) and record reads `X`
//! ([`Records`]): the packs of lanes in registers, one round of the walk,
//! the rare path and the gate's handover ([`Rounds`], for the driver
//! [`run`]). Every function is `#[inline(always)]`, so that the walk
//! compiled inside a `#[target_feature]` entry point inlines down to the
//! intrinsics; the rare paths run out of line through [`Lanes::cold`].

use std::marker::PhantomData;

use glam::Vec3;
use tet_core::Link;

use super::Geometry;
use super::driver::{Gate, Rounds, next_ungated, run};
use super::exit::{Gathered, Geo, Leaving, Records};
use super::geometry::{Planar, Projected, Triple};
use super::lanes::Lanes;
use crate::walk::after_stop::{AfterStop, after_stop};
use crate::walk::lanes::{Batch, Feed};
use crate::walk::projection::Projection;
use crate::walk::reach::GAMMA;
#[cfg(doc)]
use crate::walk::reach::Reach;
use crate::walk::start::Lane;
use crate::walk::stop::{Advance, Stopped};
use crate::walk::topology::Topology;

/// A walk's state between two tets, as the scalar walk keeps it (its
/// `Lane` less the projection, which is a function of the ray and start):
/// about to enter `next` through the face `ids`, from tet `entry_raw`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Handover {
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

/// `L::WIDTH` walks in registers, and per lane its cold part.
struct Pack<L: Lanes, G: Projected<L>, const B: bool> {
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
    /// Lanes of bounded walks ([`crate::walk::reach`]).
    bounded: L::M,
    /// Their planes past `t_max`: origin, direction, its absolute
    /// values (x, y, z each) and the threshold ([`Reach`]).
    reach: [L::F; 10],
    /// Per entry-face slot, the lanes whose vertex there lies past it.
    beyond: [L::M; 3],
}

impl<L: Lanes, G: Projected<L>, const B: bool> Pack<L, G, B> {
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
            bounded: l.mask_of_bits(0),
            reach: [l.splat_f(0.0); 10],
            beyond: [l.mask_of_bits(0); 3],
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
        if !B {
            return;
        }
        let bit = l.mask_of_bits(1 << k);
        self.bounded = l.andnot_m(bit, self.bounded);
        if let Some(r) = &lane.reach {
            self.bounded = l.or_m(self.bounded, bit);
            let values = [
                r.origin.x,
                r.origin.y,
                r.origin.z,
                r.dir.x,
                r.dir.y,
                r.dir.z,
                r.dir_abs.x,
                r.dir_abs.y,
                r.dir_abs.z,
                r.threshold,
            ];
            for (x, v) in self.reach.iter_mut().zip(values) {
                *x = l.set_f(*x, k, v);
            }
        }
        for (s, b) in self.beyond.iter_mut().enumerate() {
            let on = l.mask_of_bits(((lane.beyond >> s & 1) as u32) << k);
            *b = l.or_m(l.andnot_m(bit, *b), on);
        }
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
    /// Lanes whose exit face lies wholly past `t_max` (bounded walks).
    beyond: u32,
    raw: L::Arr<u32>,
}

/// One round: every live lane enters its next tet and, in the common case,
/// moves on to the exit neighbour; `Some` when some live lane needs the rare
/// path (the step cap, an out-of-range vertex, a non-tet exit link).
#[inline(always)]
fn step<L: Lanes, G: Projected<L>, X: Records<L>, const B: bool>(
    l: L,
    pk: &mut Pack<L, G, B>,
    x: &X,
    points: &[Vec3],
    cap: u32,
) -> Option<Round<L>> {
    // Loads: the new vertex `d` and its point.
    let (d, scratch) = x.enter(l, pk.next, &pk.ids);
    let dc = l.min_u(d, l.splat_i(points.len() as u32 - 1));
    let lost = l.ne_i(dc, d);
    // SAFETY: `dc ≤ points.len() − 1` per lane, and `3 · points.len()`
    // fits in an `i32` (asserted by `walk`).
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
    let leaving = Leaving {
        next: pk.next,
        ids: pk.ids,
        d,
        e,
        entry: pk.entry,
    };
    let link = x.link(l, scratch, &leaving);
    // Commit: replace the exiting vertex, count the tet, move on.
    let capped = l.ge_u(pk.visited, l.splat_i(cap));
    let go = l.andnot_m(l.or_m(capped, lost), pk.live);
    for (k, s) in [s0, s1, s2].into_iter().enumerate() {
        let sel = l.and_m(go, s);
        pk.ids[k] = l.select_i(sel, d, pk.ids[k]);
        pk.face[k] = G::select(l, sel, v, pk.face[k]);
    }
    pk.visited = l.inc(pk.visited, go);
    // Bounded walks: the new vertex's side of the plane past `t_max`
    // replaces the exiting one's; a face wholly past it ends the walk.
    let mut past = l.mask_of_bits(0);
    if B && l.any(pk.bounded) {
        let b = l.and_m(go, pk.bounded);
        let far = beyond(l, &pk.reach, p);
        for (k, s) in [s0, s1, s2].into_iter().enumerate() {
            let sel = l.and_m(b, s);
            pk.beyond[k] = l.or_m(l.and_m(sel, far), l.andnot_m(sel, pk.beyond[k]));
        }
        past = l.and_m(
            b,
            l.and_m(pk.beyond[0], l.and_m(pk.beyond[1], pk.beyond[2])),
        );
    }
    let mut moving = l.and_m(go, l.lt_u(link, l.splat_i(Link::BOUNDARY.0)));
    if B {
        moving = l.andnot_m(past, moving);
    }
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
        beyond: l.bits(past),
        raw: L::i_lanes(link),
    })
}

/// [`Reach::beyond`] on every lane: the same f32 operations in the same
/// order (`|q|` by a select, which differs from `abs` only in the sign of
/// a zero, which no comparison sees).
#[inline(always)]
fn beyond<L: Lanes>(l: L, r: &[L::F; 10], p: [L::F; 3]) -> L::M {
    let zero = l.splat_f(0.0);
    let q = [
        l.sub_f(p[0], r[0]),
        l.sub_f(p[1], r[1]),
        l.sub_f(p[2], r[2]),
    ];
    // No closures over lane operations (see `ties`).
    let abs = [
        l.select_f(l.gt_f(zero, q[0]), l.sub_f(zero, q[0]), q[0]),
        l.select_f(l.gt_f(zero, q[1]), l.sub_f(zero, q[1]), q[1]),
        l.select_f(l.gt_f(zero, q[2]), l.sub_f(zero, q[2]), q[2]),
    ];
    let s = l.add_f(
        l.add_f(l.mul_f(q[0], r[3]), l.mul_f(q[1], r[4])),
        l.mul_f(q[2], r[5]),
    );
    let err = l.add_f(
        l.add_f(l.mul_f(abs[0], r[6]), l.mul_f(abs[1], r[7])),
        l.mul_f(abs[2], r[8]),
    );
    let err = l.mul_f(err, l.splat_f(GAMMA));
    l.gt_f(l.sub_f(s, err), r[9])
}

/// The scalar tie rule for the lanes of `tie` (their edge tests replaced).
#[inline(always)]
fn ties<L: Lanes, G: Projected<L>, const B: bool>(
    l: L,
    pk: &Pack<L, G, B>,
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
fn events<L: Lanes, G: Projected<L>, const B: bool>(
    l: L,
    feed: &mut Feed<'_>,
    pk: &mut Pack<L, G, B>,
    r: &Round<L>,
) -> usize {
    let mut parked = 0;
    for k in (0..L::WIDTH).filter(|k| r.events >> k & 1 != 0) {
        let bit = |b: u32| b >> k & 1 != 0;
        let link = r.raw.as_ref()[k];
        let stopped = Stopped {
            adv: Advance::stopped(bit(r.capped), bit(r.lost), bit(r.beyond)),
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
fn gate_lanes<L: Lanes, G: Projected<L>, GT: Gate<Handover>, const B: bool>(
    l: L,
    feed: &mut Feed<'_>,
    pk: &mut Pack<L, G, B>,
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
        let first = |lane: &Lane<G::Proj>| lane.next;
        match next_ungated(|| feed.next_lane(), gate, first, |lane| Handover::of(&lane)) {
            Some((j, lane)) => pk.put(l, k, j, &lane),
            None => {
                pk.park(l, k);
                parked += 1;
            }
        }
    }
    parked
}

/// The projected walk of geometry `G` over the record reads `X`, for the
/// driver ([`run`]).
struct Walk<'a, G, X, const B: bool> {
    records: X,
    points: &'a [Vec3],
    cap: u32,
    _geometry: PhantomData<fn() -> G>,
}

impl<G, X: Copy, const B: bool> Clone for Walk<'_, G, X, B> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<G, X: Copy, const B: bool> Copy for Walk<'_, G, X, B> {}

impl<'a, L: Lanes, G: Projected<L>, X: Records<L>, const B: bool> Rounds<L> for Walk<'a, G, X, B> {
    type Feed = Feed<'a>;
    type Pack = Pack<L, G, B>;
    type Round = Round<L>;
    type Handover = Handover;

    #[inline(always)]
    fn fill(&self, l: L, feed: &mut Feed<'a>) -> (Pack<L, G, B>, usize) {
        Pack::fill(l, feed)
    }
    #[inline(always)]
    fn step(&self, l: L, pk: &mut Pack<L, G, B>) -> Option<Round<L>> {
        step(l, pk, &self.records, self.points, self.cap)
    }
    #[inline(always)]
    fn events(&self, l: L, feed: &mut Feed<'a>, pk: &mut Pack<L, G, B>, r: &Round<L>) -> usize {
        events(l, feed, pk, r)
    }
    #[inline(always)]
    fn entering(&self, l: L, pk: &Pack<L, G, B>) -> (L::Arr<u32>, u32) {
        (L::i_lanes(pk.next), l.bits(pk.live))
    }
    #[inline(always)]
    fn entering_is(&self, l: L, pk: &Pack<L, G, B>, tet: u32) -> u32 {
        l.bits(l.and_m(l.eq_i(pk.next, l.splat_i(tet)), pk.live))
    }
    #[inline(always)]
    fn hand_over<GT: Gate<Handover>>(
        &self,
        l: L,
        feed: &mut Feed<'a>,
        pk: &mut Pack<L, G, B>,
        gate: &mut GT,
        stop: u32,
    ) -> usize {
        gate_lanes(l, feed, pk, gate, stop)
    }
}

/// Reads through [`Topology::vx`] and [`Topology::exit_link`] lane by lane.
struct PerLane<'a, T>(&'a T);

impl<T> Clone for PerLane<'_, T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for PerLane<'_, T> {}

impl<L: Lanes, T: Topology> Records<L> for PerLane<'_, T> {
    type Scratch = ();

    #[inline(always)]
    fn enter(&self, l: L, next: L::I, ids: &[L::I; 3]) -> (L::I, ()) {
        let mut vx = L::i_lanes(next);
        for v in vx.as_mut() {
            *v = self.0.vx(*v);
        }
        let f = l.xor_i(l.xor_i(ids[0], ids[1]), ids[2]);
        // The lanes of `vx` into a vector: `f ⊕ vx` lane by lane.
        let mut d = L::i_lanes(f);
        for (d, v) in d.as_mut().iter_mut().zip(vx.as_ref()) {
            *d ^= v;
        }
        (from_lanes(l, d), ())
    }
    #[inline(always)]
    fn link(&self, l: L, _: (), x: &Leaving<L>) -> L::I {
        let (next, d, e, entry) = (
            L::i_lanes(x.next),
            L::i_lanes(x.d),
            L::i_lanes(x.e),
            L::i_lanes(x.entry),
        );
        let ids = x.ids.map(L::i_lanes);
        let mut raw = L::arr(0u32);
        for (k, r) in raw.as_mut().iter_mut().enumerate() {
            let face = [ids[0].as_ref()[k], ids[1].as_ref()[k], ids[2].as_ref()[k]];
            let at = |x: &L::Arr<u32>| x.as_ref()[k];
            *r = self
                .0
                .exit_link(at(&next), face, at(&d), at(&e), at(&entry));
        }
        from_lanes(l, raw)
    }
    #[inline(always)]
    fn prefetch(&self, _: L, link: L::I) {
        // A prefetch never faults: parked and stopped lanes prefetch harmlessly.
        for &r in L::i_lanes(link).as_ref() {
            self.0.prefetch(r);
        }
    }
}

/// The vector of the lanes `a`.
#[inline(always)]
fn from_lanes<L: Lanes>(l: L, a: L::Arr<u32>) -> L::I {
    let mut x = l.splat_i(0);
    for (k, &v) in a.as_ref().iter().enumerate() {
        x = l.set_i(x, k, v);
    }
    x
}

/// Walks `batch` with geometry `G` on lanes `l` (`PACKS` packs in flight),
/// stopped short by `gate`: the SIMD lanes gather the records with the
/// layout's exit rule (`Err`, nothing traced, when they cannot be
/// gathered), the portable lanes read them through [`Topology`]. `out[i]`
/// is exactly the scalar walk of `rays[i]` with `G::Proj`, except for the
/// walks `gate` stops short (their `out` is left as it was).
#[inline(always)]
fn walk<'a, L, G, T, GT, const PACKS: usize>(
    l: L,
    batch: Batch<'a, T>,
    gate: &mut GT,
) -> Result<(), Batch<'a, T>>
where
    L: Lanes,
    G: Projected<L>,
    T: Topology,
    GT: Gate<Handover>,
{
    let mesh = batch.mesh;
    let gathered = match batch.topo.record_words() {
        Some(rw) if L::GATHERS => match Geo::new::<T::Exit>(mesh, &rw) {
            Some(g) => Some(Gathered::<T::Exit>(g, PhantomData)),
            None => return Err(batch),
        },
        _ if L::GATHERS => return Err(batch),
        _ => None,
    };
    // The gathers' indices `3·i` of the points fit in an `i32` (checked
    // by `RecordWords::gatherable` for every gathered layout already).
    assert!(
        mesh.points.len() <= i32::MAX as usize / 3,
        "too many points for the lockstep walk"
    );
    let Batch {
        topo,
        rays,
        starts,
        cap,
        out,
        bounded,
        ..
    } = batch;
    // A gate's handover does not carry a bound: gated walks are whole.
    let bounded = bounded && !GT::ON;
    let mut feed = Feed::new(mesh, rays, starts, out, bounded);
    if mesh.points.is_empty() {
        // No walk starts without points (a start tet has vertices): the
        // feed stores every ray's outcome.
        while feed.next_lane::<G::Proj>().is_some() {}
        return Ok(());
    }
    let points = &mesh.points[..];
    match gathered {
        Some(records) => run_bounded_or_not::<L, G, _, GT, PACKS>(
            l, records, points, cap, bounded, &mut feed, gate,
        ),
        None => run_bounded_or_not::<L, G, _, GT, PACKS>(
            l,
            PerLane(topo),
            points,
            cap,
            bounded,
            &mut feed,
            gate,
        ),
    }
    Ok(())
}

/// [`run`] of the walk over `records`, compiled apart for bounded walks
/// ([`crate::walk::reach`]) so that the plain walk carries none of their
/// work (measured 3.7 % slower on Torus Knots' camera rays when it did).
#[inline(always)]
fn run_bounded_or_not<'a, L, G, X, GT, const PACKS: usize>(
    l: L,
    records: X,
    points: &'a [Vec3],
    cap: u32,
    bounded: bool,
    feed: &mut Feed<'a>,
    gate: &mut GT,
) where
    L: Lanes,
    G: Projected<L>,
    X: Records<L> + Copy,
    GT: Gate<Handover>,
{
    if bounded {
        let w = Walk::<G, X, true> {
            records,
            points,
            cap,
            _geometry: PhantomData,
        };
        run::<L, _, GT, PACKS>(l, w, feed, gate);
    } else {
        let w = Walk::<G, X, false> {
            records,
            points,
            cap,
            _geometry: PhantomData,
        };
        run::<L, _, GT, PACKS>(l, w, feed, gate);
    }
}

/// The projected walk with Duff's 2-D basis ([`crate::DuffF32`]): the
/// Tet20, Tet16 and Tet32 kernels.
impl<T: Topology> Geometry<T> for Planar {
    type Handover = Handover;
    #[inline(always)]
    fn walk<'a, L: Lanes, GT: Gate<Handover>, const PACKS: usize>(
        l: L,
        batch: Batch<'a, T>,
        gate: &mut GT,
    ) -> Result<(), Batch<'a, T>> {
        walk::<L, Self, T, GT, PACKS>(l, batch, gate)
    }
}

/// The projected walk with ScTP's scalar triple products
/// ([`crate::TripleF32`]).
impl<T: Topology> Geometry<T> for Triple {
    type Handover = Handover;
    #[inline(always)]
    fn walk<'a, L: Lanes, GT: Gate<Handover>, const PACKS: usize>(
        l: L,
        batch: Batch<'a, T>,
        gate: &mut GT,
    ) -> Result<(), Batch<'a, T>> {
        walk::<L, Self, T, GT, PACKS>(l, batch, gate)
    }
}
