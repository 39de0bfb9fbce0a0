//! Stage 3, TetGen and f32 rounding: TetGen runs with `-pY` (surface
//! preserving; Aman et al. and Maria et al. build their meshes this way), in
//! process or isolated ([`crate::tetgen::Isolation`]); its points are
//! rounded to the f32 the mesh stores.
//!
//! TetGen works in the normalised [`Frame`] (the PLC centred and scaled to
//! unit size by a power of two, exactly); its points are mapped back to the
//! user's coordinates and rounded once to the nearest f32
//! ([`Frame::user_point`]).
//!
//! TetGen computes Steiner points in f64. Every tet is checked with the
//! exact f32 orientation. If rounding flattened or inverted some, each
//! Steiner point of those tets is first *snapped*: among the f32 values
//! within ±4 ulps of its f64 position (nearest first) the stage picks one
//! that makes every tet around it positive (exact test), keeping TetGen's
//! connectivity — the mesh stays a valid tetrahedralization of the same
//! domain with the same constrained faces, only no longer exactly Delaunay
//! near that point. Where snapping cannot fix a tet, TetGen is run again
//! with the rounded Steiner points as ordinary input points (its exact
//! predicates then see the very coordinates we store), up to
//! [`BuildOptions::max_rounding_rounds`] times; a failure of such a re-run
//! (e.g. a rounded point landing on a facet) or exhausting the rounds is
//! [`BuildError::RoundingFlattens`], naming the tets. Input points (and
//! fed-back Steiner points) are f32 and map to the frame exactly, so tets
//! made of input points only are never affected, and the exact orientation
//! in the frame is the orientation of the stored points' exact values
//! (the frame is a translation and a positive scaling).

use std::collections::HashMap;
use std::time::{Duration, Instant};

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use tet_core::predicates::{orient3d, orient3d_f32};

use super::error::{BuildError, self_intersection_error};
use super::frame::Frame;
use super::options::{BuildOptions, Stage};
use crate::scene::Scene;
use crate::tetgen::{TetgenError, TetgenInput, TetgenOptions, TetgenOutput, tetrahedralize};

/// TetGen's output with positive tets on f32 points (output of this stage).
pub(super) struct Rounded {
    /// TetGen's last output (its raw tets and adjacency; points in the frame).
    pub out: TetgenOutput,
    /// The input of TetGen's last run (the PLC plus any rounded Steiner
    /// points fed back).
    pub input: TetgenInput,
    /// TetGen's points rounded (and snapped) to f32.
    pub points: Vec<Vec3>,
    /// TetGen's tets, positively oriented: slots 0 and 1 swapped where
    /// TetGen's order was negative, nothing else changed.
    pub tets: Vec<[u32; 4]>,
    /// What the stage did.
    pub stats: RoundingStats,
}

/// What the TetGen and rounding stage did, for the [`super::BuildReport`].
#[derive(Clone, Debug, Default)]
pub(super) struct RoundingStats {
    /// TetGen runs.
    pub rounds: u32,
    /// Tets flat or inverted after rounding, per round (before snapping).
    pub failures: Vec<usize>,
    /// Steiner points snapped to a neighbouring f32 value.
    pub snapped: usize,
    /// TetGen, all rounds, as seen by the caller.
    pub tetgen: Duration,
    /// TetGen, all rounds, as measured around the TetGen call itself.
    pub tetgen_inside: Duration,
    /// The rounding checks and snapping.
    pub rounding: Duration,
    /// Largest peak memory of an isolated worker (KiB).
    pub worker_peak_kib: Option<u64>,
}

/// Runs TetGen on `input` (the PLC of `scene`, for naming self-intersecting
/// triangles, in `frame`) until rounding to f32 leaves every tet positive.
pub(super) fn tetrahedralize_rounded(
    scene: &Scene,
    mut input: TetgenInput,
    frame: &Frame,
    tetgen_options: &TetgenOptions,
    options: &BuildOptions,
    progress: &dyn Fn(Stage),
) -> Result<Rounded, BuildError> {
    let mut stats = RoundingStats::default();
    let mut round = 0u32;
    let mut last_bad: Vec<u32> = Vec::new();
    loop {
        round += 1;
        progress(Stage::Tetgen { round });
        let t = Instant::now();
        let out = match tetrahedralize(&input, tetgen_options, &options.isolation) {
            Ok(out) => out,
            // A repair round failed (typically a rounded Steiner point on a facet).
            Err(_) if round > 1 => {
                return Err(BuildError::RoundingFlattens {
                    count: last_bad.len(),
                    tets: last_bad.into_iter().take(16).collect(),
                    rounds: round,
                });
            }
            Err(TetgenError::SelfIntersection) => return Err(self_intersection_error(scene)),
            Err(e) => return Err(e.into()),
        };
        stats.tetgen += t.elapsed();
        stats.tetgen_inside += Duration::from_secs_f64(out.seconds);
        if let Some(w) = out.worker_peak_kib {
            stats.worker_peak_kib = Some(stats.worker_peak_kib.unwrap_or(0).max(w));
        }
        progress(Stage::Rounding);
        let t = Instant::now();
        if out.points.len() < input.points.len() {
            return Err(BuildError::InputPointChanged {
                point: out.points.len(),
            });
        }
        if let Some(i) = (0..input.points.len()).find(|&i| out.points[i] != input.points[i]) {
            return Err(BuildError::InputPointChanged { point: i });
        }
        let mut points: Vec<Vec3> = out.points.iter().map(|&p| frame.user_point(p)).collect();
        let (tets, mut bad) = orient_tets(&out.points, &points, &out.tets);
        stats.failures.push(bad.len());
        if !bad.is_empty() {
            let snapped;
            (snapped, bad) = snap_steiner_points(
                &|v| frame.user_point_f64(out.points[v as usize]),
                &mut points,
                &tets,
                &bad,
                input.points.len(),
            );
            stats.snapped += snapped;
        }
        stats.rounding += t.elapsed();
        if bad.is_empty() {
            stats.rounds = round;
            return Ok(Rounded {
                out,
                input,
                points,
                tets,
                stats,
            });
        }
        // Feed the rounded Steiner points back as input points, in the
        // frame: exact, so TetGen sees the very f32 values we store.
        let to_tetgen = |p| frame.tetgen_point(p);
        if round > options.max_rounding_rounds
            || feed_back_steiner_points(
                &mut input.points,
                &points,
                FeedBack::All,
                &tets,
                &bad,
                &to_tetgen,
            ) == 0
        {
            return Err(BuildError::RoundingFlattens {
                count: bad.len(),
                tets: bad.into_iter().take(16).collect(),
                rounds: round,
            });
        }
        last_bad = bad;
    }
}

/// How far (in ulps per coordinate) snapping looks for an f32 position
/// that keeps every tet around a Steiner point positive: ±4, i.e. 9³
/// candidates, nearest first (±2 left the Neptune scene of scenes.json, in
/// its tight enclosing box, with two flat tets after every TetGen re-run).
const SNAP_ULPS: usize = 4;

/// The bits of an f32 point (`-0.0` as `0.0`), for sorting and equality.
fn key(p: Vec3) -> [u32; 3] {
    (p + Vec3::ZERO).to_array().map(f32::to_bits)
}

/// Which rounded Steiner points a TetGen re-run takes as input points
/// ([`feed_back_steiner_points`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum FeedBack {
    /// Every Steiner point: TetGen then sees the whole rounded mesh's
    /// points (the in-core build; with only the flat tets' points, Neptune
    /// in its wide box still had two flat tets after three runs).
    All,
    /// Only the Steiner points of the flat tets (the out-of-core parts:
    /// feeding back every one made TetGen's re-run of a part of the
    /// 1 M-triangle fan sphere take minutes instead of a second).
    FlatTets,
}

/// Appends to TetGen's input `points` (the first `points.len()` of `p32`)
/// the rounded Steiner points `which` says, once each and without any
/// equal to an input point, in TetGen's coordinates (`to_tetgen`), sorted
/// by their bits. Returns how many were added.
pub(crate) fn feed_back_steiner_points(
    points: &mut Vec<[f64; 3]>,
    p32: &[Vec3],
    which: FeedBack,
    tets: &[[u32; 4]],
    bad: &[u32],
    to_tetgen: &dyn Fn(Vec3) -> [f64; 3],
) -> usize {
    let first = points.len();
    let mut known: Vec<[u32; 3]> = p32[..first].iter().map(|&p| key(p)).collect();
    known.sort_unstable();
    let candidates: Vec<Vec3> = match which {
        FeedBack::All => p32[first..].to_vec(),
        FeedBack::FlatTets => bad
            .iter()
            .flat_map(|&t| tets[t as usize])
            .filter(|&v| v as usize >= first)
            .map(|v| p32[v as usize])
            .collect(),
    };
    let mut extra: Vec<Vec3> = candidates
        .into_iter()
        .filter(|&p| known.binary_search(&key(p)).is_err())
        .collect();
    extra.sort_by_key(|&p| key(p));
    extra.dedup_by_key(|p| key(*p));
    points.extend(extra.iter().map(|&p| to_tetgen(p)));
    extra.len()
}

/// Orients TetGen's tets positively by their exact f64 orientation, and lists
/// the tets whose exact orientation with f32 points is not positive.
///
/// Swapping slots 0 and 1 is the only change made to a tet, so a tet differs
/// from TetGen's exactly when it was flipped ([`super::assemble`] relies on
/// this). Runs in parallel; the result does not depend on the thread count.
pub(crate) fn orient_tets(
    p64: &[[f64; 3]],
    p32: &[Vec3],
    tets: &[[u32; 4]],
) -> (Vec<[u32; 4]>, Vec<u32>) {
    let (out, flat): (Vec<[u32; 4]>, Vec<bool>) = tets
        .par_iter()
        .with_min_len(4096)
        .map(|&t| {
            let [a, b, c, d] = t.map(|v| DVec3::from_array(p64[v as usize]));
            let o = orient3d(a, b, c, d);
            let t = if o < 0.0 { [t[1], t[0], t[2], t[3]] } else { t };
            let [a, b, c, d] = t.map(|v| p32[v as usize]);
            (t, o == 0.0 || orient3d_f32(a, b, c, d) <= 0.0)
        })
        .unzip();
    let bad = flat
        .iter()
        .enumerate()
        .filter(|&(_, &f)| f)
        .map(|(i, _)| i as u32)
        .collect();
    (out, bad)
}

/// Snaps the Steiner points (index ≥ `first_steiner`) of the `bad` tets to
/// a nearby f32 value that makes all their tets positive (exact test),
/// nearest to TetGen's point first (`target(v)`: point `v` as TetGen
/// computed it, in user coordinates). Returns how many points moved and
/// the tets still bad. The out-of-core parts use it too.
pub(crate) fn snap_steiner_points(
    target: &dyn Fn(u32) -> DVec3,
    p32: &mut [Vec3],
    tets: &[[u32; 4]],
    bad: &[u32],
    first_steiner: usize,
) -> (usize, Vec<u32>) {
    let mut around: HashMap<u32, Vec<u32>> = HashMap::new();
    for &t in bad {
        for v in tets[t as usize] {
            if v as usize >= first_steiner {
                around.entry(v).or_default();
            }
        }
    }
    if around.is_empty() {
        return (0, bad.to_vec());
    }
    for (t, tet) in tets.iter().enumerate() {
        for v in tet {
            if let Some(list) = around.get_mut(v) {
                list.push(t as u32);
            }
        }
    }
    let positive = |p32: &[Vec3], t: u32| {
        let [a, b, c, d] = tets[t as usize].map(|v| p32[v as usize]);
        orient3d_f32(a, b, c, d) > 0.0
    };
    let steps = |x: f32| {
        let mut v = vec![x];
        let (mut up, mut down) = (x, x);
        for _ in 0..SNAP_ULPS {
            up = up.next_up();
            down = down.next_down();
            v.push(up);
            v.push(down);
        }
        v
    };
    let mut moved = 0;
    let mut vertices: Vec<u32> = around.keys().copied().collect();
    vertices.sort_unstable();
    for _pass in 0..3 {
        let mut changed = false;
        for &v in &vertices {
            let incident = &around[&v];
            if incident.iter().all(|&t| positive(p32, t)) {
                continue;
            }
            let target = target(v);
            let r = p32[v as usize];
            let mut candidates = Vec::with_capacity(125);
            for x in steps(r.x) {
                for y in steps(r.y) {
                    for z in steps(r.z) {
                        candidates.push(Vec3::new(x, y, z));
                    }
                }
            }
            candidates.sort_by(|a, b| {
                a.as_dvec3()
                    .distance_squared(target)
                    .total_cmp(&b.as_dvec3().distance_squared(target))
            });
            let original = p32[v as usize];
            let mut found = false;
            for c in candidates {
                p32[v as usize] = c;
                if incident.iter().all(|&t| positive(p32, t)) {
                    found = true;
                    break;
                }
            }
            if found {
                moved += 1;
                changed = true;
            } else {
                p32[v as usize] = original;
            }
        }
        if !changed {
            break;
        }
    }
    let still: Vec<u32> = bad.iter().copied().filter(|&t| !positive(p32, t)).collect();
    // Snapping may have broken tets outside `bad` only through the moved
    // points, whose incident tets were all checked positive when moved; a
    // later move of a neighbouring point re-checks its own incident tets.
    let mut all_bad = still;
    for (&_v, incident) in &around {
        for &t in incident {
            if !positive(p32, t) && !all_bad.contains(&t) {
                all_bad.push(t);
            }
        }
    }
    all_bad.sort_unstable();
    (moved, all_bad)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn snapping_moves_a_flattened_steiner_point_off_the_plane() {
        // Tet (0,1,2,3) with Steiner point 3 at height 1e-50: positive in
        // f64, flat once rounded to f32 (1e-50 → 0). Snapping must move it
        // to a positive f32 height (the next f32 above 0), keeping the tet.
        let p64 = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.25, 0.25, 1e-50],
        ];
        let mut p32: Vec<Vec3> = p64
            .iter()
            .map(|p| Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32))
            .collect();
        let (tets, bad) = orient_tets(&p64, &p32, &[[0, 1, 2, 3]]);
        assert_eq!(bad, vec![0]);
        let frame = Frame::IDENTITY;
        let target = |v: u32| frame.user_point_f64(p64[v as usize]);
        let (moved, still) = snap_steiner_points(&target, &mut p32, &tets, &bad, 3);
        assert_eq!((moved, still), (1, vec![]));
        assert!(p32[3].z > 0.0 && p32[3].z <= 3.0 * f32::from_bits(1));
        assert_eq!(p32[3].x, 0.25);
        // Input points (index < first_steiner) are never moved.
        let mut q32: Vec<Vec3> = p64
            .iter()
            .map(|p| Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32))
            .collect();
        let (moved, still) = snap_steiner_points(&target, &mut q32, &tets, &bad, 4);
        assert_eq!((moved, still), (0, vec![0]));
    }
}
