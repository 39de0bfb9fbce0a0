//! The cold path shared by the SIMD lockstep walks: a lane that stopped in a
//! round is ended, crosses a constrained face, or is refilled from the batch.

use super::lanes::Feed;
use super::projection::Projection;
use super::start::Lane;
use super::stop::{Resolved, Stopped};

/// What a SIMD slot does after its lane stopped in a round.
pub(crate) enum AfterStop<P: Projection> {
    /// The ray crossed a constrained face before `t_min` and walks on:
    /// its next tet, entered through the raw link it stopped at.
    Cross(u32),
    /// Its walk ended (outcome stored): load this ray and lane instead.
    Refill(usize, Lane<P>),
    /// Its walk ended and the batch has no ray left: park the slot.
    Park,
}

/// The cold path of the SIMD walks: ray `ray` of `feed` stopped as
/// `stopped` (fields read from the walk's registers, see
/// [`Advance::stopped`](super::stop::Advance::stopped)). Stores its outcome
/// when its walk ended and starts the next queued ray.
pub(crate) fn after_stop<P: Projection>(
    feed: &mut Feed<'_>,
    ray: usize,
    stopped: Stopped,
) -> AfterStop<P> {
    match stopped.resolve(feed.mesh, &feed.rays[ray]) {
        Resolved::Cross(n) => AfterStop::Cross(n),
        Resolved::Done(o) => {
            feed.out[ray] = o;
            match feed.next_lane::<P>() {
                Some((j, lane)) => AfterStop::Refill(j, lane),
                None => AfterStop::Park,
            }
        }
    }
}
