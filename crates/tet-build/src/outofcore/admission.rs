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

/// A model of a local builder's own peak resident memory:
/// `base_bytes + bytes_per_triangle × scene triangles`, fitted by
/// measurement ([`BuilderModel::fit`], [`BuilderModel::FITTED`]).
///
/// What it covers is the builder's *planning* peak: the program and its
/// threads, the scene as loaded, its cleaned copy and self-intersection
/// check, the split plan, the triangles the planes cut and the walls
/// (every other triangle joins its part's facets only while that part is
/// built). It is a model, not a measurement, so that the same command
/// plans the same parts on every run; the gate (see the module docs)
/// measures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuilderModel {
    /// Fixed part, bytes: the program, its threads and allocator arenas.
    pub base_bytes: f64,
    /// Bytes per scene triangle.
    pub bytes_per_triangle: f64,
}

/// One measurement of a builder: its scene's triangles and its measured
/// planning peak (resident bytes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuilderSample {
    /// Scene triangles (as loaded, before cleaning).
    pub triangles: usize,
    /// The planning process's peak resident memory, bytes.
    pub peak_bytes: u64,
}

impl BuilderModel {
    /// The constants fitted on this project's 2-core VM (2026-11-28,
    /// release build): [`BuilderModel::fit`] with margin 1.05 on the
    /// larger of the peak resident memory of `build SCENE --plan DIR
    /// --memory-limit 256M` and of the planning stage of `build SCENE
    /// --memory-limit L` (before the first worker starts) on the Stanford
    /// bunny (69 k triangles), Torus Knots in a Box (78 k), Armadillo in a
    /// Box (100 k), Mix in a Box (548 k, crossings resolved) and
    /// `fan-sphere:1m` (1 M) gave 17.95 MiB + 165.7 B per triangle,
    /// rounded up here (since the planner holds the scene once, cleans
    /// with index tables and checks self-intersections a slab of the grid
    /// at a time; before: 11.4 MiB + 256 B). Mix in a Box, an OBJ whose
    /// crossings are resolved, needs the most per triangle (99.6 MiB);
    /// `fan-sphere:1m` 118.6 MiB and `dense-knots:10m` (not in the fit)
    /// 105 B per triangle are well under it (docs/results.md, "Lowest
    /// memory limit per scene" and "The planner's memory"). It covers tree plans; slabs,
    /// which hold the pieces of every triangle they cut, can exceed it
    /// (Armadillo in a Box in 94 slabs: 1.06×; `fan-sphere:1m` in slabs
    /// under 352 MiB: 2.1×). The ignored test
    /// `measure_builder_model` in `tet-bench/tests/tree_limit.rs`
    /// measures and refits it. The model before it (24 MiB + 320 B per
    /// triangle) was about twice the measured peak on the small scenes
    /// and refused builds that fit.
    pub const FITTED: BuilderModel = BuilderModel {
        base_bytes: BUILDER_BASE_BYTES as f64,
        bytes_per_triangle: BUILDER_BYTES_PER_TRIANGLE as f64,
    };

    /// The modelled peak of a builder of a scene of `triangles` triangles,
    /// bytes.
    pub fn bytes(&self, triangles: usize) -> u64 {
        (self.base_bytes + self.bytes_per_triangle * triangles as f64).ceil() as u64
    }

    /// Fits `base + rate × triangles` to `samples`: weighted least squares
    /// with weights `1 / peak²` (the relative error, so that small scenes
    /// count as much as large ones), then both coefficients scaled by
    /// `margin ×` the largest ratio of a measured peak to the fit, so that
    /// the model is at least `margin ×` every sample. `None` with fewer
    /// than two distinct triangle counts, a zero peak or a margin below 1.
    pub fn fit(samples: &[BuilderSample], margin: f64) -> Option<BuilderModel> {
        if samples.iter().any(|s| s.peak_bytes == 0) || margin.is_nan() || margin < 1.0 {
            return None;
        }
        let xs: Vec<f64> = samples.iter().map(|s| s.triangles as f64).collect();
        let ys: Vec<f64> = samples.iter().map(|s| s.peak_bytes as f64).collect();
        if xs.iter().all(|&x| x == xs[0]) {
            return None;
        }
        let ws: Vec<f64> = ys.iter().map(|y| 1.0 / (y * y)).collect();
        let sw: f64 = ws.iter().sum();
        let mx = xs.iter().zip(&ws).map(|(x, w)| w * x).sum::<f64>() / sw;
        let my = ys.iter().zip(&ws).map(|(y, w)| w * y).sum::<f64>() / sw;
        let sxx: f64 = xs.iter().zip(&ws).map(|(x, w)| w * (x - mx).powi(2)).sum();
        let sxy: f64 = (0..xs.len())
            .map(|i| ws[i] * (xs[i] - mx) * (ys[i] - my))
            .sum();
        // A negative rate (the large scenes lighter than the small ones)
        // would leave the model below the samples it is extrapolated to:
        // the rate is at least 0.
        let rate = (sxy / sxx).max(0.0);
        let base = (my - rate * mx).max(0.0);
        let fit = |x: f64| base + rate * x;
        let worst = xs
            .iter()
            .zip(&ys)
            .map(|(&x, &y)| y / fit(x))
            .fold(0.0f64, f64::max);
        let scale = margin * worst;
        scale.is_finite().then_some(BuilderModel {
            base_bytes: base * scale,
            bytes_per_triangle: rate * scale,
        })
    }
}

/// The fixed part of a local builder's own memory
/// ([`BuilderModel::FITTED`]; `tet-bench` alone, before it loads a scene,
/// is about 7 MiB resident).
pub const BUILDER_BASE_BYTES: u64 = 18 << 20;

/// A local builder's own memory per scene triangle
/// ([`BuilderModel::FITTED`]): measured as the planning peak less the
/// base, 100 bytes per triangle on `fan-sphere:1m` and 150 on Mix in a
/// Box, whose OBJ loading and resolved crossings leave more behind.
pub const BUILDER_BYTES_PER_TRIANGLE: u64 = 170;

/// What a local build of a scene of `triangles` triangles sets aside for
/// itself from a limit on its whole process tree, before the workers'
/// shares: [`BuilderModel::FITTED`] (a model, not a measurement, so that
/// the same command plans the same parts on every run).
pub fn builder_bytes(triangles: usize) -> u64 {
    BuilderModel::FITTED.bytes(triangles)
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
    fn a_fitted_builder_model_covers_every_sample_within_its_margin() {
        // Peaks of 7 MiB + 250 B per triangle with ±8 % scatter, and one
        // sample far off the line (a scene whose loading leaves more).
        let mib = |m: f64| (m * (1 << 20) as f64) as u64;
        let line = |t: usize| 7.0 + 250.0 * t as f64 / (1 << 20) as f64;
        let samples: Vec<BuilderSample> = [
            (70_000usize, 1.08),
            (80_000, 0.95),
            (100_000, 1.02),
            (550_000, 0.92),
            (1_000_000, 1.0),
        ]
        .into_iter()
        .map(|(triangles, f)| BuilderSample {
            triangles,
            peak_bytes: mib(line(triangles) * f),
        })
        .chain([BuilderSample {
            triangles: 300_000,
            peak_bytes: mib(line(300_000) * 1.2),
        }])
        .collect();
        let m = BuilderModel::fit(&samples, 1.05).unwrap();
        let ratios: Vec<f64> = samples
            .iter()
            .map(|s| m.bytes(s.triangles) as f64 / s.peak_bytes as f64)
            .collect();
        // Never below a sample by less than the margin; the tightest at
        // the margin exactly; none far above (scatter + outlier).
        assert!(ratios.iter().all(|&r| r >= 1.05 - 1e-6), "{ratios:?}");
        assert!(ratios.iter().any(|&r| r < 1.05 + 1e-6), "{ratios:?}");
        assert!(ratios.iter().all(|&r| r < 1.6), "{ratios:?}");
        // Degenerate inputs.
        let one = [samples[0], samples[0]];
        assert_eq!(BuilderModel::fit(&one, 1.05), None);
        assert_eq!(BuilderModel::fit(&samples, 0.9), None);
        let zero = [
            samples[0],
            BuilderSample {
                triangles: 1,
                peak_bytes: 0,
            },
        ];
        assert_eq!(BuilderModel::fit(&zero, 1.0), None);
        // The fitted constants are what `builder_bytes` sets aside.
        assert_eq!(
            builder_bytes(69_463),
            BUILDER_BASE_BYTES + BUILDER_BYTES_PER_TRIANGLE * 69_463
        );
    }

    #[test]
    fn parts_that_do_not_fit_together_run_one_at_a_time_and_all_run() {
        // Under a limit below this process's own memory, every part still
        // runs, alone.
        assert_eq!(most_at_once(Some(1), 1 << 20, 6, 3), 1);
    }
}
