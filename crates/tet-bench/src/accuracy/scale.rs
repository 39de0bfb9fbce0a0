//! Accuracy at scale: Maria et al.'s failure rates (2017, Table 4) over
//! 10⁸ rays and more, which no one batch holds in memory. The rays come in
//! batches of [`BATCH_RAYS`] — the first with the camera's 1024² image,
//! each with random interior rays and as many adversarial rays
//! ([`super::adversarial::adversarial_rays`]: aimed at vertices, edges and
//! faces of the tetrahedralization, along edges, started on faces), a new
//! seed per batch —; the f64 reference judges each batch, every method
//! traces it once, and the counters add up. Each method's Mrays/s is its
//! one pass over all the rays (all threads), not a best of repeated passes:
//! the render table measures speed; this measures failures.

use std::time::Instant;

use anyhow::Result;

use super::{CaseAccuracy, MethodAccuracy, Reference, ray_set, trace_all, variants};
use crate::load::{Loaded, spinner};
use crate::methods::method::{Method, Precision};
use crate::methods::tracer_capped;

/// Rays per batch: about 60 MB of rays, starts, reference hits and
/// outcomes per method at a time.
pub const BATCH_RAYS: usize = 1 << 20;

/// Step cap of the walks here (or the default cap where that is lower): a
/// walk longer than this counts as
/// [`tet_trace_cpu::ray::Failure::StepCap`]. A straight walk crosses each
/// tet at most once, and a ray through `n` tets of about even size crosses
/// on the order of `n^(1/3)` of them: the cap is 64 times that, at least
/// [`MIN_STEP_CAP`] and at most [`MAX_STEP_CAP`]. The default cap (twice
/// the tets, up to 2²⁴) would let every cycling walk of the faithful Tet80
/// and ScTP on adversarial rays run hundreds of thousands of steps before
/// it is counted, and those walks would take most of a 10⁸-ray run. A
/// walk that never cycles (Tet20, the exact walk) reaching the cap would
/// show in the table as a step cap.
pub fn step_cap(tets: usize) -> u32 {
    let cube_root = (tets as f64).cbrt();
    ((64.0 * cube_root) as u32).clamp(MIN_STEP_CAP, MAX_STEP_CAP)
}

/// Lower bound of [`step_cap`].
pub const MIN_STEP_CAP: u32 = 1 << 12;

/// Upper bound of [`step_cap`].
pub const MAX_STEP_CAP: u32 = 1 << 16;

/// Side of the camera image of the first batch (Maria et al. count per
/// 1024² image).
const IMAGE_SIDE: u32 = 1024;

/// The seed of batch `k` of a run seeded with `seed`.
pub fn batch_seed(seed: u64, k: u64) -> u64 {
    seed.wrapping_add(k.wrapping_mul(0x9e37_79b9_7f4a_7c15))
}

/// The rays of a batch of `n` rays: `(image side, random, adversarial)`.
/// The first batch opens with the camera image (at most 1024², at most
/// `n`); the rest is half random interior rays, half adversarial ones.
pub fn batch_plan(first: bool, n: usize) -> (u32, usize, usize) {
    let side = if first {
        IMAGE_SIDE.min((n as f64).sqrt() as u32)
    } else {
        0
    };
    let rest = n - (side * side) as usize;
    (side, rest - rest / 2, rest / 2)
}

/// Runs every method (in `precision`) over `total` rays of `loaded` in
/// batches of [`BATCH_RAYS`], against the f64 reference; `quiet` hides the
/// progress line.
pub fn run_streamed(
    case: &str,
    loaded: &Loaded,
    methods: &[Method],
    precision: Precision,
    total: u64,
    seed: u64,
    quiet: bool,
) -> Result<CaseAccuracy> {
    run_in_batches(
        case, loaded, methods, precision, total, seed, quiet, BATCH_RAYS,
    )
}

/// [`run_streamed`] with batches of `batch` rays.
#[allow(clippy::too_many_arguments)]
fn run_in_batches(
    case: &str,
    loaded: &Loaded,
    methods: &[Method],
    precision: Precision,
    total: u64,
    seed: u64,
    quiet: bool,
    batch_rays: usize,
) -> Result<CaseAccuracy> {
    let mesh = &loaded.mesh;
    let reference = Reference::new(mesh);
    let cap = Some(step_cap(mesh.tets.len()).min(tet_trace_cpu::walk::step_cap(mesh)));
    let mut tracers = Vec::new();
    for &m in methods {
        for (f64, label) in variants(m, precision) {
            tracers.push((tracer_capped(m, f64, mesh, cap)?, label));
        }
    }
    let mut counts: Vec<(MethodAccuracy, f64)> = tracers
        .iter()
        .map(|(t, p)| {
            let m = MethodAccuracy {
                method: t.name(),
                precision: p,
                ..Default::default()
            };
            (m, 0.0)
        })
        .collect();
    let bar = spinner(quiet);
    let (mut done, mut ambiguous, mut batch) = (0u64, 0usize, 0u64);
    while done < total {
        let left = (total - done).min(batch_rays.max(1) as u64) as usize;
        let (side, random, adversarial) = batch_plan(batch == 0, left);
        let set = ray_set(
            loaded,
            mesh,
            side,
            random,
            adversarial,
            batch_seed(seed, batch),
        )?;
        let expected = set.reference_hits(&reference);
        ambiguous += expected
            .iter()
            .filter(|e| e.is_some_and(|e| e.ambiguous()))
            .count();
        for ((t, _), (m, secs)) in tracers.iter().zip(&mut counts) {
            let start = Instant::now();
            let outcomes = trace_all(t.as_ref(), &set);
            *secs += start.elapsed().as_secs_f64();
            m.tally(&reference, &set, &outcomes, &expected);
        }
        done += set.len() as u64;
        batch += 1;
        bar.set_message(format!(
            "{case}: {done} of {total} rays ({:.0} %)",
            100.0 * done as f64 / total as f64
        ));
        if set.len() == 0 {
            break;
        }
    }
    bar.finish_and_clear();
    let methods = counts
        .into_iter()
        .map(|(mut m, secs)| {
            m.finish();
            m.mrays_per_s = m.rays as f64 / secs.max(1e-9) / 1e6;
            m
        })
        .collect();
    Ok(CaseAccuracy {
        case: case.into(),
        tets: mesh.tets.len(),
        tolerance: reference.tol,
        rays: done as usize,
        reference_ambiguous: ambiguous,
        methods,
        skipped: None,
        left_out: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accuracy::{RayPlan, run_case};
    use crate::load::camera::framing_camera;
    use tet_core::synthetic::{GridSpec, kuhn_grid};

    /// Batches add up to exactly what the one-batch harness
    /// ([`run_case`]) counts on the same rays, batch by batch.
    #[test]
    fn batches_add_up_to_the_one_batch_counts() {
        // A jittered grid with a closed shell of constrained faces, seen
        // from outside (rays enter through the convex boundary).
        let mesh = kuhn_grid(&GridSpec {
            cells: [5, 5, 5],
            jitter: 0.25,
            shell: Some(([1, 1, 1], [4, 4, 4])),
            ..Default::default()
        });
        let loaded = Loaded {
            name: "shell".into(),
            camera: framing_camera(&mesh),
            mesh,
            scene: None,
            lights: Vec::new(),
            build: None,
        };
        let methods = [Method::Tet20, Method::Tet80, Method::Sctp];
        let (total, batch, seed) = (7_000u64, 3_000usize, 5);
        let streamed = run_in_batches(
            "as-is",
            &loaded,
            &methods,
            Precision::F32,
            total,
            seed,
            true,
            batch,
        )
        .unwrap();
        assert_eq!(streamed.rays as u64, total);
        let mut sums: Vec<MethodAccuracy> = Vec::new();
        let mut ambiguous = 0;
        for (k, n) in [(0u64, 3_000usize), (1, 3_000), (2, 1_000)] {
            let (side, random, adversarial) = batch_plan(k == 0, n);
            let plan = RayPlan {
                side,
                random,
                seed: batch_seed(seed, k),
                min_time_s: 0.0,
                adversarial,
            };
            let one = run_case("as-is", &loaded, &methods, Precision::F32, plan).unwrap();
            assert_eq!(one.rays, n);
            ambiguous += one.reference_ambiguous;
            if sums.is_empty() {
                sums = one.methods;
            } else {
                for (s, m) in sums.iter_mut().zip(one.methods) {
                    s.rays += m.rays;
                    s.agree += m.agree;
                    s.ambiguous += m.ambiguous;
                    s.failures += m.failures;
                    s.leaks += m.leaks;
                    s.step_cap += m.step_cap;
                }
            }
        }
        assert_eq!(streamed.reference_ambiguous, ambiguous);
        assert_eq!(streamed.methods.len(), sums.len());
        for (s, m) in sums.iter().zip(&streamed.methods) {
            assert_eq!(
                (
                    &s.method,
                    s.rays,
                    s.agree,
                    s.ambiguous,
                    s.failures,
                    s.leaks,
                    s.step_cap
                ),
                (
                    &m.method,
                    m.rays,
                    m.agree,
                    m.ambiguous,
                    m.failures,
                    m.leaks,
                    m.step_cap
                )
            );
            assert!(m.mrays_per_s > 0.0);
        }
        // The first batch opened with the camera image.
        assert_eq!(batch_plan(true, 3_000).0, 54);
    }

    /// The cap grows with the cube root of the tets, within its bounds.
    #[test]
    fn the_step_cap_follows_the_mesh_size() {
        assert_eq!(step_cap(0), MIN_STEP_CAP);
        assert_eq!(step_cap(1000), MIN_STEP_CAP);
        // 64 · 512 for 512³ tets (within the bounds).
        assert_eq!(step_cap(512 * 512 * 512), 64 * 512);
        assert_eq!(step_cap(usize::MAX), MAX_STEP_CAP);
    }
}
