//! The lockstep driver, once for every geometry: packs of lanes stepped
//! in turn, each lane refilled from the batch as soon as its walk ends,
//! and lanes stopped short by a [`Gate`]. What a pack holds, one round and
//! the rare path are the geometry's ([`Rounds`]: the projected walk of
//! `projected`, the Plücker walk of `plucker`).

use super::lanes::Lanes;

/// Where a gated lockstep walk stops short: before every round, a lane
/// about to enter a tet the gate names leaves the walk (its state `H`, a
/// geometry's handover, goes to [`Gate::hand_over`]; its outcome is not
/// written) and the lane is refilled. The plain walk's gate ([`NoGate`])
/// names none and compiles away.
pub trait Gate<H> {
    /// False for [`NoGate`]: no check at all.
    const ON: bool;
    /// Whether a walk stops before entering `tet`.
    fn stops_before(&self, tet: u32) -> bool;
    /// The one tet the gate stops before, when it names only one (a
    /// shadow ray's light strictly inside a tet): the driver then compares
    /// all lanes with it at once instead of asking
    /// [`Gate::stops_before`] lane by lane (the same answers). Default:
    /// none.
    fn only(&self) -> Option<u32> {
        None
    }
    /// Receives ray `ray`'s walk, stopped before entering a tet it names.
    fn hand_over(&mut self, ray: usize, h: H);
}

/// The plain walk's gate: never stops a walk short.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoGate;

impl<H> Gate<H> for NoGate {
    const ON: bool = false;
    #[inline(always)]
    fn stops_before(&self, _: u32) -> bool {
        false
    }
    #[inline(always)]
    fn hand_over(&mut self, _: usize, _: H) {}
}

/// The next walk to load into a freed slot: the next queued walk (from
/// `next`) whose first tet (`first`) the gate does not stop before; those it
/// stops before are handed over at once (as `handover` makes them). `None`
/// when the batch has no walk left: the slot is parked.
#[inline(always)]
pub(crate) fn next_ungated<W, H, GT: Gate<H>>(
    mut next: impl FnMut() -> Option<(usize, W)>,
    gate: &mut GT,
    first: impl Fn(&W) -> u32,
    handover: impl Fn(W) -> H,
) -> Option<(usize, W)> {
    loop {
        match next() {
            Some((j, w)) if gate.stops_before(first(&w)) => gate.hand_over(j, handover(w)),
            other => return other,
        }
    }
}

/// One geometry's lockstep walk over lanes `L`: what a pack of
/// `L::WIDTH` walks holds in registers, one round of it and its rare
/// path. Every method is `#[inline(always)]` in the implementations, so
/// that [`run`], instantiated inside a `#[target_feature]` entry point,
/// inlines down to the intrinsics.
pub(crate) trait Rounds<L: Lanes> {
    /// The batch's walks not started yet, and where outcomes go.
    type Feed;
    /// `L::WIDTH` walks in registers.
    type Pack;
    /// What a round leaves for the rare path.
    type Round;
    /// What a [`Gate`] receives of a walk it stops.
    type Handover;

    /// A pack filled with the next walks of `feed` (parked lanes when
    /// fewer), and the number of live lanes.
    fn fill(&self, l: L, feed: &mut Self::Feed) -> (Self::Pack, usize);
    /// One round: every live lane enters its next tet and, in the common
    /// case, moves on; `Some` when some live lane needs the rare path.
    fn step(&self, l: L, pk: &mut Self::Pack) -> Option<Self::Round>;
    /// The rare part of round `r`: the stopped lanes end, cross or walk
    /// on, and lanes whose walk ended are refilled or parked. Returns the
    /// number of lanes parked.
    fn events(&self, l: L, feed: &mut Self::Feed, pk: &mut Self::Pack, r: &Self::Round) -> usize;
    /// The tet each lane enters next, and the live lanes as bits.
    fn entering(&self, l: L, pk: &Self::Pack) -> (L::Arr<u32>, u32);
    /// The live lanes (bits) about to enter `tet`, compared in SIMD.
    fn entering_is(&self, l: L, pk: &Self::Pack, tet: u32) -> u32;
    /// Hands the lanes of `stop` (bits) to `gate` and refills them,
    /// handing over at once the new walks whose first tet the gate names
    /// too. Returns the number of lanes parked.
    fn hand_over<GT: Gate<Self::Handover>>(
        &self,
        l: L,
        feed: &mut Self::Feed,
        pk: &mut Self::Pack,
        gate: &mut GT,
        stop: u32,
    ) -> usize;
}

/// Walks every ray of `feed` with `PACKS` packs of `L::WIDTH` lanes
/// stepped in turn (the out-of-order core overlaps their dependent load
/// chains), stopping short the walks `gate` names.
///
/// `walk` is taken by value and copied into the rare paths' closures:
/// borrowed, its address would escape to their out-of-line calls, and the
/// compiler would reload its fields (and splat them again) every round
/// instead of keeping them in registers.
#[inline(always)]
pub(crate) fn run<L, R, GT, const PACKS: usize>(l: L, walk: R, feed: &mut R::Feed, gate: &mut GT)
where
    L: Lanes,
    R: Rounds<L> + Copy,
    GT: Gate<R::Handover>,
{
    let mut packs: [(R::Pack, usize); PACKS] = std::array::from_fn(|_| walk.fill(l, feed));
    let only = if GT::ON { gate.only() } else { None };
    loop {
        let mut any = false;
        for (pk, live) in packs.iter_mut() {
            if *live == 0 {
                continue;
            }
            if GT::ON {
                let stop = match only {
                    Some(tet) => walk.entering_is(l, pk, tet),
                    None => {
                        let (next, live_bits) = walk.entering(l, pk);
                        let mut stop = 0u32;
                        for k in (0..L::WIDTH).filter(|k| live_bits >> k & 1 != 0) {
                            if gate.stops_before(next.as_ref()[k]) {
                                stop |= 1 << k;
                            }
                        }
                        stop
                    }
                };
                if stop != 0 {
                    let (f, p, g) = (&mut *feed, &mut *pk, &mut *gate);
                    *live -= l.cold(move || walk.hand_over(l, f, p, g, stop));
                    if *live == 0 {
                        continue;
                    }
                }
            }
            any = true;
            if let Some(r) = walk.step(l, pk) {
                let (f, p) = (&mut *feed, &mut *pk);
                *live -= l.cold(move || walk.events(l, f, p, &r));
            }
        }
        if !any {
            break;
        }
    }
}
