//! Starting TetGen workers only while the whole process tree fits a
//! memory limit: the planner keeps every part's *prediction* under its
//! share of the limit, but what this process holds while the parts run
//! (the scene, the facets of the parts running, the results being taken
//! in) is only known then. Before a worker starts, this process's
//! resident memory *now*, the commitments of the parts still running and
//! the new part's commitment must fit the limit; otherwise the part
//! waits for one to finish. A part with nothing else running always starts (it was planned
//! to fit alone), so the parts never wait for each other forever.
//!
//! A part's commitment ([`commitment`]) is its predicted TetGen peak and
//! a quarter more ([`PARENT_SHARE_DIVISOR`]): the worker, and what this
//! process holds of its result until the part is handed on.
//!
//! The planner's side is [`worker_share`]: a model of this process's own
//! memory ([`builder_bytes`]) is set aside from the limit and the rest is
//! split into commitments. The gate measures instead of modelling, so a
//! model that is too low costs parallelism, never the limit (but for the
//! one part that always starts).

use std::sync::{Condvar, Mutex};
use std::time::Duration;

use super::tree_memory::own_resident_bytes;

/// What this process holds of a part's result while it takes it in (the
/// reply, the checked part, its sort and part file), as a fraction of the
/// part's predicted TetGen peak: `1 / PARENT_SHARE_DIVISOR` (measured on
/// Torus Knots in a Box under 100–200 MiB: about 0.13 with two parts at
/// once; 0.25 for a margin).
pub const PARENT_SHARE_DIVISOR: u64 = 4;

/// The fixed part of a local builder's own memory: the program, its
/// threads and the scene as loaded (measured: 13–24 MiB resident when
/// planning Torus Knots in a Box and Armadillo in a Box).
pub const BUILDER_BASE_BYTES: u64 = 24 << 20;

/// A local builder's own memory per scene triangle: the scene as loaded,
/// its cleaned copy and self-intersection check, the triangles the planes
/// cut and the walls (every other triangle joins its part's facets only
/// while that part is built). Measured as the planner's peak resident
/// memory: about 200 bytes per triangle on a 1 M-triangle closed mesh,
/// 270 on Mix in a Box (548 k triangles, crossings resolved); more for a
/// margin.
pub const BUILDER_BYTES_PER_TRIANGLE: u64 = 320;

/// What a local build of a scene of `triangles` triangles sets aside for
/// itself from a limit on its whole process tree, before the workers'
/// shares: a model (not a measurement), so that the same command plans the
/// same parts on every run.
pub fn builder_bytes(triangles: usize) -> u64 {
    BUILDER_BASE_BYTES + BUILDER_BYTES_PER_TRIANGLE * triangles as u64
}

/// The predicted TetGen peak each of `p` workers at once may have when
/// the process tree of a local build of `triangles` triangles is limited
/// to `limit`: what [`builder_bytes`] leaves, split into `p` slots of a
/// worker and the builder's share of its result ([`commitment`]).
pub fn worker_share(limit: u64, triangles: usize, p: usize) -> u64 {
    let left = limit.saturating_sub(builder_bytes(triangles));
    left / (p.max(1) as u64) * PARENT_SHARE_DIVISOR / (PARENT_SHARE_DIVISOR + 1)
}

/// How often a waiting part looks at this process's memory again when no
/// part finishes.
const RECHECK: Duration = Duration::from_millis(20);

/// The gate of [`super::parts`]' worker threads.
pub(super) struct Admission {
    limit: Option<u64>,
    /// Commitments of the parts running, bytes, and how many there are.
    running: Mutex<(u64, usize)>,
    finished: Condvar,
}

/// A running part's commitment, given back on drop.
pub(super) struct Ticket<'a> {
    gate: &'a Admission,
    bytes: u64,
}

/// The bytes a running part predicted `predicted` holds: its worker and
/// the builder's share of its result.
pub fn commitment(predicted: u64) -> u64 {
    predicted + predicted / PARENT_SHARE_DIVISOR
}

impl Admission {
    /// A gate for `limit` (`None`: every part starts at once).
    pub(super) fn new(limit: Option<u64>) -> Admission {
        Admission {
            limit,
            running: Mutex::new((0, 0)),
            finished: Condvar::new(),
        }
    }

    /// Waits until a part predicted `predicted` bytes may start.
    pub(super) fn enter(&self, predicted: u64) -> Ticket<'_> {
        let bytes = commitment(predicted);
        let mut running = self.running.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(limit) = self.limit {
            while running.1 > 0 && own_resident_bytes() + running.0 + bytes > limit {
                running = self
                    .finished
                    .wait_timeout(running, RECHECK)
                    .unwrap_or_else(|e| e.into_inner())
                    .0;
            }
        }
        running.0 += bytes;
        running.1 += 1;
        Ticket { gate: self, bytes }
    }
}

impl Drop for Ticket<'_> {
    fn drop(&mut self) {
        let mut running = self.gate.running.lock().unwrap_or_else(|e| e.into_inner());
        running.0 -= self.bytes;
        running.1 -= 1;
        drop(running);
        self.gate.finished.notify_all();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// Runs `n` parts of `predicted` bytes on `threads` threads under
    /// `limit`; the most that ran at once.
    fn most_at_once(limit: Option<u64>, predicted: u64, n: usize, threads: usize) -> usize {
        let gate = Admission::new(limit);
        let (now, most, next) = (
            AtomicUsize::new(0),
            AtomicUsize::new(0),
            AtomicUsize::new(0),
        );
        std::thread::scope(|s| {
            for _ in 0..threads {
                s.spawn(|| {
                    while next.fetch_add(1, Ordering::SeqCst) < n {
                        let _t = gate.enter(predicted);
                        let k = now.fetch_add(1, Ordering::SeqCst) + 1;
                        most.fetch_max(k, Ordering::SeqCst);
                        std::thread::sleep(Duration::from_millis(30));
                        now.fetch_sub(1, Ordering::SeqCst);
                    }
                });
            }
        });
        most.load(Ordering::SeqCst)
    }

    #[test]
    fn as_many_parts_run_at_once_as_fit_the_limit() {
        // Commitments of 250 MiB (nothing is allocated) under this
        // process's memory + 625 MiB: two fit, three do not, whatever
        // other tests of this binary allocate meanwhile (< 125 MiB).
        let predicted = 200 << 20;
        let limit = own_resident_bytes() + 625 * (1 << 20);
        assert_eq!(commitment(predicted), 250 << 20);
        assert_eq!(most_at_once(Some(limit), predicted, 8, 4), 2);
        assert_eq!(most_at_once(None, predicted, 8, 4), 4);
    }

    #[test]
    fn a_share_and_its_commitment_fit_the_limit_with_the_builder() {
        for triangles in [0, 2880, 1_000_000] {
            for limit in [0u64, 1 << 20, 100 << 20, 1 << 30, 1 << 40] {
                for p in 1..=4 {
                    let share = worker_share(limit, triangles, p);
                    if limit > builder_bytes(triangles) {
                        assert!(
                            builder_bytes(triangles) + p as u64 * commitment(share) <= limit,
                            "{triangles} triangles, limit {limit}, {p} at once"
                        );
                    } else {
                        assert_eq!(share, 0);
                    }
                }
            }
        }
        // What is left goes to the workers (but for rounding).
        let share = worker_share(1 << 30, 2880, 2);
        let left = (1u64 << 30) - builder_bytes(2880);
        assert!(left - 2 * commitment(share) < 16);
    }

    #[test]
    fn parts_that_do_not_fit_together_run_one_at_a_time_and_all_run() {
        // Under a limit below this process's own memory, every part still
        // runs, alone.
        assert_eq!(most_at_once(Some(1), 1 << 20, 6, 3), 1);
    }
}
