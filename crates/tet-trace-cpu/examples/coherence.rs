//! How coherent are camera rays in the SIMD lockstep walk? The
//! measurement behind a packet walk (lanes standing in the same tet share
//! one record load, broadcast, instead of a gather each).
//!
//! ```text
//! cargo run --release -p tet-trace-cpu --example coherence -- FILE.tmesh \
//!     [--size WxH] [--tile N] [--check N]
//! ```
//!
//! Every camera ray of a `W×H` image (default 1920×1440, the renderer's
//! pixel corners) is walked by the scalar walk ([`walk::trace`], Tet20
//! layout, `DuffF32`) over a [`Topology`] wrapper that records the tet
//! (and the new vertex `idx₃`) of every exit link the walk asks for: the
//! tets a lockstep lane gathers, one per round, in the walk's own order
//! (from a camera inside the mesh the start tet is decided before the
//! rounds, from the mesh, and is not gathered: a ray's recorded steps are
//! its `tets_visited` − 1; from outside the entry tet is the first round's:
//! they equal its `tets_visited`; both checked). The
//! rays are taken in the renderer's tiles of `N×N` pixels (default 16,
//! `render::TILE`) and each tile's rays are put in lanes of 16, grouped as
//! 16×1 (rows: what the renderer's row-major batch gives), 8×2 or 4×4
//! blocks of pixels; the rounds are then simulated offline, two ways:
//!
//! * `no refill`: each group of 16 rays walks on its own until its last
//!   lane ends (finished lanes idle);
//! * `refill lanes, P packs`: the lockstep driver's schedule: `P` packs of
//!   16 lanes stepped in turn, filled from the tile's queue in order, and
//!   a lane whose walk ends refilled at once with the next queued ray
//!   (rays that end before their first round, misses of the mesh, are
//!   skipped). The AVX-512 walk runs 2 packs (`the driver`);
//! * `refill S-lane halves/quarters`: one pack split in slots of `S` = 8
//!   or 4 lanes, a slot refilled with the next `S` queued rays once all of
//!   its lanes have ended (between the two above: lanes refilled together
//!   stay coherent; one shared load per slot and round).
//!
//! Per pack and round it counts the live lanes, the distinct tets among
//! them, the lanes standing in the round's most common tet (what one
//! shared record load would serve) and in its two most common tets (two
//! loads), the same for the pair (tet, new vertex) (lanes that would also
//! share the new vertex's point, i.e. all five words of the step), the
//! lanes served by the rules a SIMD walk would use instead of a histogram
//! (`lead`: the tet of the lowest live lane, one compare, and for two
//! loads also that of the lowest live lane standing elsewhere; `cand`: the
//! most common of four candidate lanes, four compares), the rounds whose
//! live lanes are served entirely by one or two loads (no gather at all),
//! the lanes in their slot's most common tet (one load per slot), and,
//! without refill, a *sticky* packet: the lanes that stood in the
//! packet's most common tet (one or two tets) every round since the
//! start, a lane that stands elsewhere once leaving it for good (to the
//! lockstep walk), as the proposed packet walk would run. The summary
//! line per schedule gives its pack-rounds per walked ray (lane
//! occupancy) and the lane-steps left to gathers under each sharing rule.
//! Lane-step shares are split by the lane's progress along its ray (its
//! steps 0–9, 10–49, 50 on); distinct tets per round by the round's index
//! in its group (no refill) or since the tile started (refill).
//!
//! `--check N` (default 4) also traces the first `N` rays of every tile
//! with the tracer itself (`Tracer::trace`, the walk the renderer's
//! batches reproduce bit for bit) and checks the recorded steps against
//! its `tets_visited`; every ray's recorded steps are checked against the
//! `tets_visited` of the wrapper's own walk.
//!
//! The camera is the one stored with the mesh, else the Torus Knots camera
//! of `tet-build` (`torus_knots_camera`: orbit 0.5, 1.0 rad at distance
//! 20 around the origin, 45°). One thread; a 1920×1440 frame of Torus
//! Knots takes about 2–2.5 minutes (2-core AMD EPYC, shared).

use std::sync::Mutex;
use std::time::Instant;

use glam::Vec3;
use tet_core::scene::Camera;
use tet_trace_cpu::lockstep::ByLane;
use tet_trace_cpu::render::PinholeCamera;
use tet_trace_cpu::tet20::Tet20Tracer;
use tet_trace_cpu::walk::{self, Topology};
use tet_trace_cpu::{DuffF32, TraceOutcome, Tracer, Viewpoint};

type Error = Box<dyn std::error::Error>;

/// Lanes per pack (the AVX-512 lockstep walk).
const W: usize = 16;

/// A [`Topology`] that records, in order, every tet whose exit link the
/// walk asks for, with its new vertex `d` (single-threaded use; the mutex
/// only makes it `Sync`).
struct Recorder<'a, T> {
    inner: &'a T,
    log: Mutex<Vec<(u32, u32)>>,
}

impl<T: Topology> Topology for Recorder<'_, T> {
    type Exit = ByLane;
    #[inline(always)]
    fn vx(&self, tet: u32) -> u32 {
        self.inner.vx(tet)
    }
    #[inline(always)]
    fn exit_link(&self, tet: u32, face: [u32; 3], d: u32, exiting: u32, entry_raw: u32) -> u32 {
        self.log.lock().unwrap().push((tet, d));
        self.inner.exit_link(tet, face, d, exiting, entry_raw)
    }
    #[inline(always)]
    fn prefetch(&self, tet: u32) {
        self.inner.prefetch(tet)
    }
}

/// The Torus Knots camera of `tet-build` (`orbit_camera(0.5, 1.0, 20, 0)`).
fn torus_knots_camera() -> Camera {
    let (ox, oy) = (0.5f64, 1.0f64);
    let (sx, cx) = ox.sin_cos();
    let (sy, cy) = oy.sin_cos();
    let dir = glam::DVec3::new(cy * cx, sx, sy * cx);
    Camera {
        position: (20.0 * dir).as_vec3(),
        target: Vec3::ZERO,
        up: Vec3::Y,
        vfov_deg: 45.0,
    }
}

struct Args {
    path: String,
    size: (u32, u32),
    tile: u32,
    check: usize,
}

fn args() -> Result<Args, Error> {
    let mut a = Args {
        path: String::new(),
        size: (1920, 1440),
        tile: tet_trace_cpu::render::TILE,
        check: 4,
    };
    let mut it = std::env::args().skip(1);
    while let Some(x) = it.next() {
        let mut value = || it.next().ok_or(format!("{x} needs a value"));
        match x.as_str() {
            "--size" => {
                let v = value()?;
                let (w, h) = v.split_once('x').ok_or("--size WxH")?;
                a.size = (w.parse()?, h.parse()?);
            }
            "--tile" => a.tile = value()?.parse()?,
            "--check" => a.check = value()?.parse()?,
            _ if a.path.is_empty() && !x.starts_with("--") => a.path = x,
            _ => return Err(format!("unknown argument `{x}`").into()),
        }
    }
    if a.path.is_empty() || a.tile == 0 {
        return Err("usage: coherence FILE.tmesh [--size WxH] [--tile N] [--check N]".into());
    }
    Ok(a)
}

/// Progress bands: steps (or rounds) 0–9, 10–49, 50 on.
const BANDS: [&str; 3] = ["0-9", "10-49", "50+"];

fn band(step: usize) -> usize {
    match step {
        0..10 => 0,
        10..50 => 1,
        _ => 2,
    }
}

/// Counts of one schedule (grouping × refill mode), per band.
#[derive(Clone, Debug, Default)]
struct Stats {
    /// Pack-rounds with a live lane, by round band.
    rounds: [u64; 3],
    /// Live lanes summed over those rounds, by round band.
    live: [u64; 3],
    /// Distinct tets summed over those rounds, by round band.
    distinct: [u64; 3],
    /// Rounds whose live lanes all stand in one tet / in two tets.
    whole1: u64,
    whole2: u64,
    /// Lane-steps, by the lane's step band.
    steps: [u64; 3],
    /// Lane-steps in the round's most common tet / two most common.
    top1: [u64; 3],
    top2: [u64; 3],
    /// The same for the pair (tet, new vertex).
    key1: [u64; 3],
    key2: [u64; 3],
    /// Lane-steps served by a sticky packet (no refill only): the lanes
    /// still in the packet that stand in its most common tet (one load) /
    /// two most common (two loads); a lane that stands elsewhere leaves
    /// the packet for good (to the lockstep walk).
    sticky1: [u64; 3],
    sticky2: [u64; 3],
    /// Lane-steps in the most common tet of their slot (the lanes refilled
    /// together): one load per slot and round.
    slot1: [u64; 3],
    /// Lane-steps served by the leader rule (what SIMD finds with one
    /// compare, no histogram): the tet of the lowest live lane (one load),
    /// and that of the lowest live lane standing elsewhere (two loads).
    lead1: [u64; 3],
    lead2: [u64; 3],
    /// The same with four candidates (the live lanes at a quarter's
    /// steps: the first, n/4, n/2, 3n/4-th), the most common of them (four
    /// compares and popcounts): one load; two: also the most common
    /// candidate elsewhere, else the lowest live lane elsewhere.
    cand1: [u64; 3],
    cand2: [u64; 3],
}

/// The most common tet among the candidates `c` (by their count among
/// `tets`), skipping `not`.
fn best_candidate(tets: &[u32], c: &[u32], not: Option<u32>) -> Option<u32> {
    c.iter()
        .copied()
        .filter(|&t| Some(t) != not)
        .max_by_key(|&t| tets.iter().filter(|&&x| x == t).count())
}

/// The two most common values among `v` (with their counts; the second
/// `None` when all agree).
fn top_two<K: Ord + Copy>(v: &[K]) -> (K, usize, Option<(K, usize)>) {
    let mut s: Vec<K> = v.to_vec();
    s.sort_unstable();
    let mut best: Vec<(usize, K)> = Vec::with_capacity(s.len());
    let mut i = 0;
    while i < s.len() {
        let j = i + s[i..].iter().take_while(|&&x| x == s[i]).count();
        best.push((j - i, s[i]));
        i = j;
    }
    best.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
    (best[0].1, best[0].0, best.get(1).map(|&(c, k)| (k, c)))
}

impl Stats {
    /// One pack-round: `lanes` holds (step index along its ray, tet, new
    /// vertex) of each live lane; `round` is the round's index.
    fn round(&mut self, round: usize, lanes: &[(usize, u32, u32, usize)]) {
        if lanes.is_empty() {
            return;
        }
        let rb = band(round);
        self.rounds[rb] += 1;
        self.live[rb] += lanes.len() as u64;
        let tets: Vec<u32> = lanes.iter().map(|l| l.1).collect();
        let keys: Vec<(u32, u32)> = lanes.iter().map(|l| (l.1, l.2)).collect();
        let mut distinct = tets.clone();
        distinct.sort_unstable();
        distinct.dedup();
        self.distinct[rb] += distinct.len() as u64;
        self.whole1 += (distinct.len() == 1) as u64;
        self.whole2 += (distinct.len() <= 2) as u64;
        let (t1, _, t2) = top_two(&tets);
        let (k1, _, k2) = top_two(&keys);
        // The most common tet of each slot (the lanes refilled together).
        let slots = lanes.iter().map(|l| l.3).max().unwrap_or(0) + 1;
        let slot_top: Vec<Option<u32>> = (0..slots)
            .map(|k| {
                let t: Vec<u32> = lanes.iter().filter(|l| l.3 == k).map(|l| l.1).collect();
                (!t.is_empty()).then(|| top_two(&t).0)
            })
            .collect();
        let l1 = lanes[0].1;
        let l2 = lanes.iter().map(|l| l.1).find(|&t| t != l1);
        let n = tets.len();
        let cands = [tets[0], tets[n / 4], tets[n / 2], tets[3 * n / 4]];
        let c1 = best_candidate(&tets, &cands, None);
        let c2 = best_candidate(&tets, &cands, c1)
            .or_else(|| tets.iter().copied().find(|&t| Some(t) != c1));
        for &(step, tet, d, slot) in lanes {
            let b = band(step);
            self.steps[b] += 1;
            let in1 = tet == t1;
            let in2 = in1 || t2.is_some_and(|(t, _)| t == tet);
            self.top1[b] += in1 as u64;
            self.top2[b] += in2 as u64;
            let k = (tet, d);
            let kin1 = k == k1;
            let kin2 = kin1 || k2.is_some_and(|(x, _)| x == k);
            self.key1[b] += kin1 as u64;
            self.key2[b] += kin2 as u64;
            self.slot1[b] += (slot_top[slot] == Some(tet)) as u64;
            self.lead1[b] += (tet == l1) as u64;
            self.lead2[b] += (tet == l1 || Some(tet) == l2) as u64;
            self.cand1[b] += (Some(tet) == c1) as u64;
            self.cand2[b] += (Some(tet) == c1 || Some(tet) == c2) as u64;
        }
    }
}

/// Round `r` of the sticky packet of `group` holding the lanes of
/// `members` with `loads` shared record loads per round: the lanes that
/// stay (updates `members`), i.e. those served.
fn sticky(group: &[&[(u32, u32)]], r: usize, members: &mut u32, loads: usize) -> u64 {
    let live: Vec<(usize, u32)> = (0..group.len())
        .filter(|&k| *members >> k & 1 != 0 && r < group[k].len())
        .map(|k| (k, group[k][r].0))
        .collect();
    *members = 0;
    if live.is_empty() {
        return 0;
    }
    let tets: Vec<u32> = live.iter().map(|l| l.1).collect();
    let (t1, _, t2) = top_two(&tets);
    for &(k, t) in &live {
        if t == t1 || (loads == 2 && t2.is_some_and(|(x, _)| x == t)) {
            *members |= 1 << k;
        }
    }
    members.count_ones() as u64
}

/// Rays `seqs` (in queue order) in groups of 16 walked until the group's
/// last lane ends, no refill.
fn no_refill(seqs: &[&[(u32, u32)]], stats: &mut Stats) {
    let mut lanes = Vec::with_capacity(W);
    for group in seqs.chunks(W) {
        let rounds = group.iter().map(|s| s.len()).max().unwrap_or(0);
        let (mut in1, mut in2) = (u32::MAX, u32::MAX);
        for r in 0..rounds {
            stats.sticky1[band(r)] += sticky(group, r, &mut in1, 1);
            stats.sticky2[band(r)] += sticky(group, r, &mut in2, 2);
            lanes.clear();
            lanes.extend(
                group
                    .iter()
                    .filter(|s| r < s.len())
                    .map(|s| (r, s[r].0, s[r].1, 0)),
            );
            stats.round(r, &lanes);
        }
    }
}

/// A lane of a pack: the (tet, new vertex) sequence of its ray and its
/// next step, or `None` when parked.
type Lane<'a> = Option<(&'a [(u32, u32)], usize)>;

/// The lockstep driver's schedule over `seqs` (queue order): `packs` packs
/// of 16 lanes stepped in turn, each split in slots of `sub` lanes; a slot
/// whose lanes have all ended is refilled at once with the next `sub`
/// queued rays. `sub` = 1 is the driver (each lane refilled on its own).
fn refill(seqs: &[&[(u32, u32)]], packs: usize, sub: usize, stats: &mut Stats) {
    let mut queue = seqs.iter().filter(|s| !s.is_empty());
    // Per pack and lane: (ray's sequence, next step).
    let mut state: Vec<Vec<Lane<'_>>> = (0..packs)
        .map(|_| (0..W).map(|_| queue.next().map(|s| (*s, 0))).collect())
        .collect();
    let mut lanes = Vec::with_capacity(W);
    let mut round = 0;
    loop {
        let mut any = false;
        for pack in state.iter_mut() {
            lanes.clear();
            for (k, lane) in pack.iter().enumerate() {
                if let Some((seq, at)) = lane {
                    lanes.push((*at, seq[*at].0, seq[*at].1, k / sub));
                }
            }
            if lanes.is_empty() {
                continue;
            }
            any = true;
            stats.round(round, &lanes);
            for lane in pack.iter_mut() {
                if let Some((seq, at)) = lane {
                    *at += 1;
                    if *at == seq.len() {
                        *lane = None;
                    }
                }
            }
            for slot in pack.chunks_mut(sub) {
                if slot.iter().all(Option::is_none) {
                    for lane in slot.iter_mut() {
                        *lane = queue.next().map(|s| (*s, 0));
                    }
                }
            }
        }
        if !any {
            break;
        }
        round += 1;
    }
}

/// The tile's pixels (`x0..x1 × y0..y1`, row-major indices into the
/// tile) in queue order for blocks of `bw × bh` pixels: blocks row-major,
/// pixels row-major in each block.
fn block_order(tw: u32, th: u32, bw: u32, bh: u32) -> Vec<usize> {
    let mut order = Vec::with_capacity((tw * th) as usize);
    for by in (0..th).step_by(bh as usize) {
        for bx in (0..tw).step_by(bw as usize) {
            for y in by..(by + bh).min(th) {
                for x in bx..(bx + bw).min(tw) {
                    order.push((y * tw + x) as usize);
                }
            }
        }
    }
    order
}

fn pct(a: u64, b: u64) -> f64 {
    if b == 0 {
        0.0
    } else {
        100.0 * a as f64 / b as f64
    }
}

fn sum(a: &[u64; 3]) -> u64 {
    a.iter().sum()
}

fn main() -> Result<(), Error> {
    let a = args()?;
    let (mesh, stored) = tet_core::format::load_with_scene(&a.path)?;
    let (camera, which) = match stored.camera {
        Some(c) => (c, "stored"),
        None => (torus_knots_camera(), "Torus Knots (not stored)"),
    };
    let tracer = Tet20Tracer::<DuffF32>::new(&mesh)?;
    let cap = tracer.step_cap();
    let rec = Recorder {
        inner: tracer.layout(),
        log: Mutex::new(Vec::new()),
    };
    let view = Viewpoint::locate(&mesh, camera.position)?;
    let (w, h) = a.size;
    let cam = PinholeCamera::new(&camera, w, h, false);
    // Steps recorded per ray = tets visited − `inside` (see the top).
    let inside = matches!(view, Viewpoint::Inside(_)) as u32;
    println!(
        "{}: {} tets, {} triangles; camera {which} at {:?} → {:?}, {}°, {}; \
         {w}x{h}, tiles {t}x{t}, load {}",
        a.path,
        mesh.tets.len(),
        mesh.constrained.len(),
        camera.position,
        camera.target,
        camera.vfov_deg,
        match view {
            Viewpoint::Inside(t) => format!("inside the mesh (tet {t})"),
            Viewpoint::Outside(_) => "outside the mesh".into(),
        },
        std::fs::read_to_string("/proc/loadavg")
            .unwrap_or_default()
            .trim(),
        t = a.tile,
    );
    let groupings: [(&str, u32, u32); 3] = [("16x1", 16, 1), ("8x2", 8, 2), ("4x4", 4, 4)];
    // (name, packs, lanes refilled together; 16 = no refill).
    let modes: [(&str, usize, usize); 5] = [
        ("no refill", 1, W),
        ("refill 8-lane halves, 1 pack", 1, 8),
        ("refill 4-lane quarters, 1 pack", 1, 4),
        ("refill lanes, 1 pack", 1, 1),
        ("refill lanes, 2 packs (the driver)", 2, 1),
    ];
    let mut stats = vec![vec![Stats::default(); modes.len()]; groupings.len()];
    let (mut rays, mut visited, mut recorded, mut lost, mut mismatch) = (0u64, 0u64, 0u64, 0, 0);
    let (mut checked, mut check_bad, mut walked) = (0u64, 0u64, 0u64);
    let mut lengths = vec![0u64; 8];
    let t0 = Instant::now();
    let mut seqs: Vec<Vec<(u32, u32)>> = Vec::new();
    for y0 in (0..h).step_by(a.tile as usize) {
        for x0 in (0..w).step_by(a.tile as usize) {
            let (x1, y1) = ((x0 + a.tile).min(w), (y0 + a.tile).min(h));
            seqs.clear();
            for j in y0..y1 {
                for i in x0..x1 {
                    let ray = cam.ray(i, j);
                    rays += 1;
                    let (out, seq) = match view.start(&tracer, &ray) {
                        Err(out) => (out, Vec::new()),
                        Ok(start) => {
                            rec.log.lock().unwrap().clear();
                            let out = walk::trace::<DuffF32, _>(&mesh, &rec, &ray, start, cap);
                            let seq = std::mem::take(&mut *rec.log.lock().unwrap());
                            if (j - y0) * (x1 - x0) + (i - x0) < a.check as u32 {
                                checked += 1;
                                let real = tracer.trace(&ray, start);
                                check_bad +=
                                    (real.tets_visited() != seq.len() as u32 + inside) as u64;
                            }
                            (out, seq)
                        }
                    };
                    if matches!(out, TraceOutcome::Failed { .. }) {
                        lost += 1;
                    }
                    walked += !seq.is_empty() as u64;
                    let tv = out.tets_visited() as u64;
                    visited += tv;
                    recorded += seq.len() as u64;
                    if !seq.is_empty() && tv != seq.len() as u64 + inside as u64 {
                        mismatch += 1;
                    }
                    let lb = (usize::BITS - seq.len().leading_zeros()) as usize;
                    lengths[lb.min(7)] += 1;
                    seqs.push(seq);
                }
            }
            let (tw, th) = (x1 - x0, y1 - y0);
            for (g, &(_, bw, bh)) in groupings.iter().enumerate() {
                let order: Vec<&[(u32, u32)]> = block_order(tw, th, bw, bh)
                    .into_iter()
                    .map(|k| &seqs[k][..])
                    .collect();
                no_refill(&order, &mut stats[g][0]);
                for (m, &(_, packs, sub)) in modes.iter().enumerate().skip(1) {
                    refill(&order, packs, sub, &mut stats[g][m]);
                }
            }
        }
    }
    println!(
        "{rays} rays, {visited} tets visited ({:.1} per ray), {recorded} recorded steps \
         (+ walked rays from inside: must equal the tets visited); rays whose steps differ {mismatch}, \
         failed walks {lost}; tracer check: {checked} rays, {check_bad} differ; {:.1} s",
        visited as f64 / rays as f64,
        t0.elapsed().as_secs_f64(),
    );
    println!(
        "recorded steps per ray, by power of two (0, 1, 2-3, 4-7, ..., 64+): {:?}",
        lengths
    );
    println!(
        "\nper pack-round (16 lanes): live lanes, distinct tets among them (by round band), \
         rounds wholly served by 1 / 2 loads;\nlane-steps served by the round's most common \
         tet (1 load) / two most common (2 loads), by the lane's step band; \
         [t+v3]: same for (tet, new vertex);\nlead: \
         the tet of the lowest live lane (1 load), and of the lowest live lane elsewhere (2 loads); \
         cand: the most common of 4 candidate lanes (1 load), and the next (2 loads); \
         sticky: a packet that \
         keeps the lanes in its most common tet (1 load) or two (2 loads) and loses the others \
         for good (no refill only)"
    );
    for (g, &(gname, _, _)) in groupings.iter().enumerate() {
        for (m, &(mode, _, sub)) in modes.iter().enumerate() {
            let s = &stats[g][m];
            let r = sum(&s.rounds);
            println!(
                "\n{gname} {mode}: {r} pack-rounds, live {:.2}/16, distinct {:.2}, \
                 whole rounds 1 load {:.1} %, 2 loads {:.1} %",
                sum(&s.live) as f64 / r as f64,
                sum(&s.distinct) as f64 / r as f64,
                pct(s.whole1, r),
                pct(s.whole2, r),
            );
            println!(
                "  {:>6} {:>10} {:>6} {:>9} {:>12} {:>7} {:>7} {:>9} {:>9} {:>7} {:>7} {:>7} {:>7} {:>8} {:>8}",
                "band",
                "rounds",
                "live",
                "distinct",
                "lane-steps",
                "1 load",
                "2 loads",
                "1 [t+v3]",
                "2 [t+v3]",
                "lead1",
                "lead2",
                "cand1",
                "cand2",
                "sticky1",
                "sticky2"
            );
            let row = |name: &str, b: Option<usize>| {
                let f = |x: &[u64; 3]| b.map_or(sum(x), |b| x[b]);
                let (rounds, live, steps) = (f(&s.rounds), f(&s.live), f(&s.steps));
                let st = |x: &[u64; 3]| {
                    if m == 0 {
                        format!("{:.1}%", pct(f(x), steps))
                    } else {
                        "-".into()
                    }
                };
                println!(
                    "  {:>6} {:>10} {:>6.2} {:>9.2} {:>12} {:>6.1}% {:>6.1}% {:>8.1}% {:>8.1}% {:>6.1}% {:>6.1}% {:>6.1}% {:>6.1}% {:>8} {:>8}",
                    name,
                    rounds,
                    live as f64 / rounds.max(1) as f64,
                    f(&s.distinct) as f64 / rounds.max(1) as f64,
                    steps,
                    pct(f(&s.top1), steps),
                    pct(f(&s.top2), steps),
                    pct(f(&s.key1), steps),
                    pct(f(&s.key2), steps),
                    pct(f(&s.lead1), steps),
                    pct(f(&s.lead2), steps),
                    pct(f(&s.cand1), steps),
                    pct(f(&s.cand2), steps),
                    st(&s.sticky1),
                    st(&s.sticky2),
                );
            };
            for (b, name) in BANDS.iter().enumerate() {
                row(name, Some(b));
            }
            row("all", None);
            // Lane-steps left to gathers, per schedule: all of them in the
            // lockstep walk; those outside the shared tets in a packet walk.
            let steps = sum(&s.steps) as f64;
            let left = |x: &[u64; 3]| (steps - sum(x) as f64) / steps;
            println!(
                "  pack-rounds {:.3} per walked ray ({:.2}x the 2-pack driver's); lane-steps \
                 left to gathers: 1 load {:.1} %, 2 loads {:.1} % (leader rule {:.1} %, {:.1} %; \
                 4 candidates {:.1} %, {:.1} %){}",
                r as f64 / walked as f64,
                r as f64 / sum(&stats[g][4].rounds) as f64,
                100.0 * left(&s.top1),
                100.0 * left(&s.top2),
                100.0 * left(&s.lead1),
                100.0 * left(&s.lead2),
                100.0 * left(&s.cand1),
                100.0 * left(&s.cand2),
                if m == 0 {
                    format!(
                        ", sticky packet 1 load {:.1} %, 2 loads {:.1} %",
                        100.0 * left(&s.sticky1),
                        100.0 * left(&s.sticky2)
                    )
                } else if sub > 1 {
                    format!(
                        ", one load per slot of {sub} ({} loads per round) {:.1} %",
                        W / sub,
                        100.0 * left(&s.slot1)
                    )
                } else {
                    String::new()
                }
            );
        }
    }
    Ok(())
}
