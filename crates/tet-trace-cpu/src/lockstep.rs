//! SIMD lockstep walk: `W` rays of one batch walk side by side, one ray per
//! SIMD lane, one tet per lane per round. This is the
//! [`Tracer::trace_batch`](crate::Tracer::trace_batch) of every projected
//! kernel with [`DuffF32`] (Tet20, Tet16, Tet32); the scalar walks
//! ([`crate::walk::trace`], [`crate::walk::trace_interleaved`], reachable as
//! [`crate::kernel::Interleaved`]) stay as the reference.
//!
//! Each round every lane fetches `VX` of the tet it enters, decodes the new
//! vertex `idx₃ = idx₀ ⊕ idx₁ ⊕ idx₂ ⊕ VX` and fetches its point; the
//! projection of `idx₃` ([`DuffF32`]: `p = (u·(P−o), v·(P−o))`), the three
//! edge determinants `det(p₃, pᵢ)` of Algorithm 1, the exit slot
//! ([`crate::walk::EXIT_SLOT`]), the replacement of the exiting vertex and the
//! exit link (rank of the exit vertex for Tet20 — Algorithm 5 —, two ranks
//! and two xors for Tet16 — Algorithm 7 —, the slot compare for Tet32 —
//! Algorithm 3 —, see [`ExitRule`]) run across the lanes as SIMD arithmetic,
//! compares and blends: no branches and no variable-indexed stores. A lane
//! that needs a rare path (a constrained face or the boundary, the step cap,
//! a decoded vertex out of range) is handed to the scalar engine's
//! `finish_step`; a finished lane is refilled at once from the batch, so
//! lanes idle only at the batch's tail.
//!
//! # Dispatch
//!
//! * x86-64 with AVX-512F (detected at run time) and a layout that exposes
//!   its records as words: the same walk with 16 lanes, 512-bit vectors and
//!   mask registers (`avx512`), two packs in flight; measured 9–10 % faster
//!   than the AVX2 walk on Torus Knots (1920×1440, 2 threads, same machine,
//!   alternating runs: trace only 330–338 ms against 358–373 ms).
//!   `TET_LOCKSTEP=avx2` in the environment keeps the AVX2 walk, for such
//!   comparisons;
//! * x86-64 with AVX2 (detected at run time) and a layout that exposes its
//!   records as words ([`crate::walk::Topology::record_words`]): 8-lane AVX2
//!   intrinsics, all five loads of a step (`VX`, the point's x, y, z, the
//!   link) as `vpgatherdd`/`vgatherdps`, two packs of 8 lanes in flight per
//!   thread so that the core overlaps their gather chains;
//! * x86-64 with AVX2, other layouts: the portable lane loops below compiled
//!   for AVX2 (8 lanes, scalar loads through [`Topology`]);
//! * otherwise: the portable lane loops with 4 lanes on the baseline target
//!   (SSE2 on x86-64), [`trace_lockstep_portable`].
//!
//! Why intrinsics and `unsafe`: the same lane loops left to the
//! auto-vectoriser (the portable path compiled for AVX2, 8 lanes) measured
//! 135 instructions per step against 112 for the scalar interleaved walk and
//! 0.95× its speed — the scalar loads and the transposition of 8 points into
//! SoA vectors cost more than the SIMD arithmetic saves —, while the
//! intrinsics with gathers measured 43.5 and about 2× (below). The only
//! `unsafe` is the call into the `avx2` functions after the run-time
//! check and the gathers, whose indices are clamped in-register to the
//! arrays (`next ≤ tets − 1`, `idx₃ ≤ points − 1`, ranks and slots ≤ 3,
//! offsets checked once per batch by `RecordWords::gatherable`), so no
//! layout, valid or not, can make them read out of bounds. A corrupt layout
//! whose links point past the tet array makes the scalar walk panic on the
//! index; the gather path then reads a clamped record instead (a wrong walk,
//! never an out-of-bounds read); [`tet_core::layout::LayoutMesh::from_mesh`]
//! validates the mesh, so neither happens for a tracer built by `new`.
//!
//! # Identical to the scalar walk
//!
//! Every lane evaluates exactly the scalar formulas of [`DuffF32`] and
//! `Face2::left_mask`: the same IEEE operations on the same operands in the
//! same order, `x = (uₓqₓ + u_y q_y) + u_z q_z` with `q = P − o`, and
//! `det = p₃.x·yᵢ − p₃.y·xᵢ`, with no fused multiply-add (Rust never
//! contracts, and FMA is not enabled here). A zero determinant takes the
//! scalar tie rule for that lane. So every lane visits the same tets and
//! ends with the same outcome as [`crate::walk::trace`] (bit for bit, tested
//! in `tests/lockstep.rs`), and the watertightness argument of
//! [`crate::walk`] carries over unchanged.
//!
//! # Measured (Torus Knots, 318 584 tets, 57.6 tets per ray)
//!
//! Instructions per tet step (callgrind, 80×60, one thread, the whole
//! `trace_batch` including ray set-up and hit records), scalar interleaved →
//! lockstep: Tet20 112.4 → 43.5, Tet16 120.8 → 44.2, Tet32 99.1 → 45.4
//! (ScTP, interleaved only: 160.6). Of Tet20's 43.5, the 8-lane round is
//! about 24 per lane-step; the rest is per ray (start tet, f64 hit record)
//! and the lane refills. 1920×1440, 2 threads, rays per CPU-second in the
//! same run (a loaded shared machine): Tet20 ×2.0, Tet16 ×1.9, Tet32 ×2.4
//! against the interleaved scalar walk. Two packs in flight against one:
//! +2–6 % per CPU-second (noisy; four: no further gain); prefetching the
//! next records (as the scalar walk does) measured no gain and is off
//! (`avx2::PREFETCH`). Rerun: `benches/walk_step.rs`.
//!
//! Later, with the tight enclosing box (40.9 tets per ray, rays entering
//! through the boundary) and the AVX-512 walk (packs kept in registers,
//! only the fields a stopped lane needs read, `x, y` gathered as one 64-bit
//! pair): tet20 11.06 Mrays/s; the AVX2 walk (`TET_LOCKSTEP=avx2`, packs
//! likewise kept in registers) 9.65, same build, same machine (`tet-bench
//! render FILE --method tet20 --width 1920 --height 1440 --threads 2
//! --frames 5`). Three packs of 16 in flight: 3–4 % slower than two; one:
//! 13 % slower.

use glam::{Vec2, Vec3};
use tet_core::{Link, TetMesh};

use crate::ray::{Ray, TraceOutcome};
use crate::walk::{
    Advance, AfterStop, DuffF32, Face2, Lane, Queue, Starts, Topology, after_stop, next_lane,
};

/// Lanes of the AVX2 lockstep walk (256-bit vectors of f32 / u32).
pub const WIDE: usize = 8;
/// Lanes of the portable lockstep walk (128-bit vectors).
pub const NARROW: usize = 4;

/// How the lockstep walk finds a tet's exit link among its record's 32-bit
/// words (offsets in words within a record).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExitRule {
    /// Tet20 (Algorithm 5): the link at word `links + rank(exiting)`.
    Rank {
        /// Word of the rank-0 link.
        links: usize,
    },
    /// Tet16 (Algorithm 7): `entry ⊕ NX(rank(idx₃)) ⊕ NX(rank(exiting))`
    /// with `NX_r` at word `links + r` and `NX_3 = 0`.
    RankXor {
        /// Word of `NX_0`.
        links: usize,
    },
    /// Tet32 (Algorithm 3): the slot `k` of the exiting vertex among the ids
    /// at words `ids..ids + 3` (3 when none of them), link at `links + k`.
    Slot {
        /// Word of the slot-0 vertex id.
        ids: usize,
        /// Word of the slot-0 link.
        links: usize,
    },
    /// The 32-byte baseline (ScTP): no `VX` word; the new vertex is the one
    /// of the four ids at words `ids..ids + 4` not on the entry face, the
    /// link that of the exiting vertex's slot among the first three (3:
    /// none), at `links + slot`. Walked by `crate::sctp_lockstep` only.
    Ids {
        /// Word of the slot-0 vertex id.
        ids: usize,
        /// Word of the slot-0 link.
        links: usize,
    },
}

/// A layout's records as 32-bit words, for the gathers of the AVX2 lockstep
/// walk ([`crate::walk::Topology::record_words`]).
#[derive(Clone, Copy, Debug)]
pub struct RecordWords<'a> {
    /// All records, word by word (`stride` words per tet).
    pub words: &'a [u32],
    /// Words per record.
    pub stride: usize,
    /// Word of `VX` within a record.
    pub vx: usize,
    /// Where the exit link is.
    pub rule: ExitRule,
}

impl RecordWords<'_> {
    /// True when every gather index the walk can form fits in an `i32` and
    /// stays inside a record (`next` and the decoded vertex are clamped to
    /// the arrays, ranks and slots to 0..=3).
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    pub(crate) fn gatherable(&self, points: usize) -> bool {
        let s = self.stride;
        let inside = match self.rule {
            ExitRule::Rank { links } => links + 3 < s,
            ExitRule::RankXor { links } => links + 2 < s,
            ExitRule::Slot { ids, links } => ids + 2 < s && links + 3 < s,
            ExitRule::Ids { ids, links } => ids + 3 < s && links + 3 < s,
        };
        inside
            && self.vx < s
            && s > 0
            && self.words.len().is_multiple_of(s)
            && !self.words.is_empty()
            && self.words.len() <= i32::MAX as usize
            && points > 0
            && points <= i32::MAX as usize / 3
    }
}

/// Traces `rays` from `start` (at most `cap` tets each) with [`DuffF32`]
/// lanes in lockstep; `out[i]` is exactly
/// [`crate::walk::trace`]`::<DuffF32, T>` of `rays[i]`. `out.len()` must
/// equal `rays.len()` (the shorter length is used otherwise).
pub fn trace_lockstep<T: Topology>(
    mesh: &TetMesh,
    topo: &T,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
) {
    #[cfg(target_arch = "x86_64")]
    let wide = !avx2_only();
    #[cfg(not(target_arch = "x86_64"))]
    let wide = false;
    dispatch(mesh, topo, rays, start, cap, out, wide);
}

/// [`trace_lockstep`] without the AVX-512 walk (the AVX2 walk where the CPU
/// has AVX2, else the portable one): public so that tests cover the AVX2
/// walk on machines with AVX-512 too.
pub fn trace_lockstep_avx2<T: Topology>(
    mesh: &TetMesh,
    topo: &T,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
) {
    dispatch(mesh, topo, rays, start, cap, out, false);
}

/// The widest walk the CPU supports (AVX-512 only when `wide`).
fn dispatch<T: Topology>(
    mesh: &TetMesh,
    topo: &T,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
    wide: bool,
) {
    #[cfg(not(target_arch = "x86_64"))]
    let _ = wide;
    #[cfg(target_arch = "x86_64")]
    // Records the gathers of the projected walks can read (the baseline's
    // `Ids` rule is ScTP's, `crate::sctp_lockstep`).
    #[cfg(target_arch = "x86_64")]
    let words = topo
        .record_words()
        .filter(|rw| rw.gatherable(mesh.points.len()) && !matches!(rw.rule, ExitRule::Ids { .. }));
    #[cfg(target_arch = "x86_64")]
    if wide
        && std::arch::is_x86_feature_detected!("avx512f")
        && let Some(rw) = words
    {
        // SAFETY (all three): the `avx512f` functions only require the
        // CPU to support AVX-512F, which was detected just above.
        match rw.rule {
            ExitRule::Rank { .. } => unsafe {
                avx512::run_gather::<RANK>(mesh, rw, rays, start, cap, out)
            },
            ExitRule::RankXor { .. } => unsafe {
                avx512::run_gather::<RANK_XOR>(mesh, rw, rays, start, cap, out)
            },
            ExitRule::Slot { .. } | ExitRule::Ids { .. } => unsafe {
                avx512::run_gather::<SLOT>(mesh, rw, rays, start, cap, out)
            },
        }
        return;
    }
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        match words {
            Some(rw) => {
                // SAFETY (all three): the `avx2` functions only require the
                // CPU to support AVX2, which was detected just above.
                match rw.rule {
                    ExitRule::Rank { .. } => unsafe {
                        avx2::run_gather::<RANK>(mesh, rw, rays, start, cap, out)
                    },
                    ExitRule::RankXor { .. } => unsafe {
                        avx2::run_gather::<RANK_XOR>(mesh, rw, rays, start, cap, out)
                    },
                    ExitRule::Slot { .. } | ExitRule::Ids { .. } => unsafe {
                        avx2::run_gather::<SLOT>(mesh, rw, rays, start, cap, out)
                    },
                }
            }
            // SAFETY: as above.
            _ => unsafe { trace_avx2(mesh, topo, rays, start, cap, out) },
        }
        return;
    }
    run::<T, NARROW>(mesh, topo, rays, start, cap, out);
}

/// True when `TET_LOCKSTEP=avx2` asks the lockstep walk to keep to 8-lane
/// AVX2 on a CPU with AVX-512 (read once; for same-machine comparisons).
#[cfg(target_arch = "x86_64")]
fn avx2_only() -> bool {
    static AVX2_ONLY: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *AVX2_ONLY.get_or_init(|| std::env::var("TET_LOCKSTEP").is_ok_and(|v| v == "avx2"))
}

/// [`trace_lockstep`] with `W` lanes compiled for the baseline target (no
/// run-time dispatch): the portable fallback, public so that tests cover it
/// on machines with AVX2 too.
pub fn trace_lockstep_portable<T: Topology, const W: usize>(
    mesh: &TetMesh,
    topo: &T,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
) {
    run::<T, W>(mesh, topo, rays, start, cap, out);
}

/// The lockstep walk with AVX2 code generation (8 lanes).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn trace_avx2<T: Topology>(
    mesh: &TetMesh,
    topo: &T,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
) {
    run::<T, WIDE>(mesh, topo, rays, start, cap, out);
}

/// `W` walks in structure-of-arrays form: entry `[l]` of every field is
/// lane `l`.
#[derive(Clone, Copy)]
struct Pack<const W: usize> {
    /// Ray origin `o` (x, y, z).
    o: [[f32; W]; 3],
    /// Duff basis columns: `c[0] = (uₓ, vₓ)`, `c[1] = (u_y, v_y)`,
    /// `c[2] = (u_z, v_z)`, as `[axis][coordinate][lane]`.
    c: [[[f32; W]; 2]; 3],
    /// Entry face ids `idx₀..₂` (counter-clockwise).
    ids: [[u32; W]; 3],
    /// Their projections.
    xs: [[f32; W]; 3],
    ys: [[f32; W]; 3],
    /// Tet entered next.
    next: [u32; W],
    /// Raw link it is entered through.
    entry: [u32; W],
    /// Tets visited so far.
    visited: [u32; W],
    /// Lane holds a walk (else parked: its state is frozen, its loads stay
    /// in range, its results are ignored).
    live: [bool; W],
    /// Index of the lane's ray in the batch.
    ray: [usize; W],
    /// The lane's projection (cold: rebuilding the scalar lane).
    proj: [DuffF32; W],
}

/// What a round left for the cold path, per lane: the exit link and whether
/// the decoded vertex was out of range.
struct Round<const W: usize> {
    raw: [u32; W],
    lost: [bool; W],
    capped: [bool; W],
}

impl<const W: usize> Pack<W> {
    /// Loads the scalar lane `lane` (ray `ray`) into slot `l`.
    fn set(&mut self, l: usize, ray: usize, lane: &Lane<DuffF32>) {
        let p = lane.proj;
        self.o[0][l] = p.o.x;
        self.o[1][l] = p.o.y;
        self.o[2][l] = p.o.z;
        for (axis, col) in [p.cx, p.cy, p.cz].iter().enumerate() {
            self.c[axis][0][l] = col.x;
            self.c[axis][1][l] = col.y;
        }
        for k in 0..3 {
            self.ids[k][l] = lane.st.ids[k];
            self.xs[k][l] = lane.st.p.xs[k];
            self.ys[k][l] = lane.st.p.ys[k];
        }
        self.next[l] = lane.next;
        self.entry[l] = lane.entry_raw;
        self.visited[l] = lane.st.visited;
        self.live[l] = true;
        self.ray[l] = ray;
        self.proj[l] = p;
    }

    /// Parks slot `l`: tet 0 (exists whenever a walk started) keeps its
    /// loads in range.
    fn park(&mut self, l: usize) {
        self.live[l] = false;
        self.next[l] = 0;
    }
}

/// The lockstep driver (see the module docs).
#[inline(always)]
fn run<T: Topology, const W: usize>(
    mesh: &TetMesh,
    topo: &T,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
) {
    let n = rays.len().min(out.len());
    let (rays, out) = (&rays[..n], &mut out[..n]);
    let mut queued = Queue::default();
    let (mut pk, mut live) = fill::<W>(mesh, rays, start, &mut queued, out);
    // A walk started only if the mesh has points and tets (its start tet
    // and vertices exist), so the loads of `step` have something to clamp to.
    if live == 0 || mesh.points.is_empty() {
        return;
    }
    let points = &mesh.points[..];
    while live > 0 {
        let (events, round) = step(&mut pk, points, topo, cap);
        if events != 0 {
            live -= lane_events(mesh, rays, start, &mut queued, out, &mut pk, events, &round);
        }
    }
}

/// `W` lanes filled with the first walks of the batch that do not end in
/// their start tet (the others are written to `out`), parked when there are
/// fewer; and the number of live lanes.
fn fill<const W: usize>(
    mesh: &TetMesh,
    rays: &[Ray],
    start: Starts<'_>,
    queued: &mut Queue,
    out: &mut [TraceOutcome],
) -> (Pack<W>, usize) {
    let mut pk = Pack::<W> {
        o: [[0.0; W]; 3],
        c: [[[0.0; W]; 2]; 3],
        ids: [[0; W]; 3],
        xs: [[0.0; W]; 3],
        ys: [[0.0; W]; 3],
        next: [0; W],
        entry: [0; W],
        visited: [0; W],
        live: [false; W],
        ray: [0; W],
        proj: [DuffF32::default(); W],
    };
    let mut live = 0;
    for l in 0..W {
        match next_lane::<DuffF32>(mesh, rays, start, queued, out) {
            Some((i, lane)) => {
                pk.set(l, i, &lane);
                live += 1;
            }
            None => pk.park(l),
        }
    }
    (pk, live)
}

/// One round: every live lane enters its next tet and, in the common case,
/// moves on to the exit neighbour. Returns the bit mask of live lanes that
/// need the cold path (the step cap, an out-of-range vertex, a non-tet exit
/// link) with what it needs.
// Lane loops index several structure-of-arrays fields by lane and slot,
// written for the auto-vectoriser.
#[allow(clippy::needless_range_loop)]
#[inline(always)]
fn step<T: Topology, const W: usize>(
    pk: &mut Pack<W>,
    points: &[Vec3],
    topo: &T,
    cap: u32,
) -> (u32, Round<W>) {
    let last = points.len() - 1;
    // Loads: `VX` of the next tet, the new vertex id and its point.
    let mut d = [0u32; W];
    let mut lost = [false; W];
    let mut q = [[0f32; W]; 3];
    for l in 0..W {
        let dv = pk.ids[0][l] ^ pk.ids[1][l] ^ pk.ids[2][l] ^ topo.vx(pk.next[l]);
        d[l] = dv;
        lost[l] = dv as usize > last;
        let p = points[(dv as usize).min(last)];
        q[0][l] = p.x;
        q[1][l] = p.y;
        q[2][l] = p.z;
    }
    // Projection (`DuffF32::project`, lane by lane the same operations).
    let mut px = [0f32; W];
    let mut py = [0f32; W];
    for l in 0..W {
        let qx = q[0][l] - pk.o[0][l];
        let qy = q[1][l] - pk.o[1][l];
        let qz = q[2][l] - pk.o[2][l];
        px[l] = pk.c[0][0][l] * qx + pk.c[1][0][l] * qy + pk.c[2][0][l] * qz;
        py[l] = pk.c[0][1][l] * qx + pk.c[1][1][l] * qy + pk.c[2][1][l] * qz;
    }
    // Algorithm 1's edge tests `det(p₃, pᵢ)` (`Face2::left_mask`).
    let mut left = [[false; W]; 3];
    let mut tie = [false; W];
    for l in 0..W {
        for k in 0..3 {
            let det = px[l] * pk.ys[k][l] - py[l] * pk.xs[k][l];
            left[k][l] = det > 0.0;
            tie[l] |= det == 0.0;
        }
    }
    if tie.iter().any(|&t| t) {
        ties(pk, &d, &px, &py, &tie, &mut left);
    }
    // Exit slot (`EXIT_SLOT`): 2 when left of d→a and right of d→b, 1 when
    // right of d→a and left of d→c, else 0; the exiting vertex.
    let mut s1 = [false; W];
    let mut s2 = [false; W];
    let mut exiting = [0u32; W];
    for l in 0..W {
        s2[l] = left[0][l] & !left[1][l];
        s1[l] = !left[0][l] & left[2][l];
        exiting[l] = if s1[l] {
            pk.ids[1][l]
        } else if s2[l] {
            pk.ids[2][l]
        } else {
            pk.ids[0][l]
        };
    }
    // Exit links, per lane from the layout.
    let mut raw = [0u32; W];
    for l in 0..W {
        let face = [pk.ids[0][l], pk.ids[1][l], pk.ids[2][l]];
        raw[l] = topo.exit_link(pk.next[l], face, d[l], exiting[l], pk.entry[l]);
    }
    // Commit: replace the exiting vertex, count the tet, move on.
    let mut events = 0u32;
    let mut capped = [false; W];
    for l in 0..W {
        capped[l] = pk.visited[l] >= cap;
        let go = pk.live[l] & !capped[l] & !lost[l];
        let sel = [go & !s1[l] & !s2[l], go & s1[l], go & s2[l]];
        for k in 0..3 {
            pk.ids[k][l] = if sel[k] { d[l] } else { pk.ids[k][l] };
            pk.xs[k][l] = if sel[k] { px[l] } else { pk.xs[k][l] };
            pk.ys[k][l] = if sel[k] { py[l] } else { pk.ys[k][l] };
        }
        pk.visited[l] += go as u32;
        let moving = go & (raw[l] < Link::BOUNDARY.0);
        pk.entry[l] = if moving { pk.next[l] } else { pk.entry[l] };
        pk.next[l] = if moving { raw[l] } else { pk.next[l] };
        events |= ((pk.live[l] & !moving) as u32) << l;
    }
    // A prefetch never faults: parked and stopped lanes prefetch harmlessly.
    for &r in &raw {
        topo.prefetch(r);
    }
    (events, Round { raw, lost, capped })
}

/// The scalar tie rule (`Face2::left_mask_ties`) for the lanes with a zero
/// determinant.
#[cold]
#[inline(never)]
fn ties<const W: usize>(
    pk: &Pack<W>,
    d: &[u32; W],
    px: &[f32; W],
    py: &[f32; W],
    tie: &[bool; W],
    left: &mut [[bool; W]; 3],
) {
    for l in 0..W {
        if !tie[l] {
            continue;
        }
        let pt = |k: usize| Vec2::new(pk.xs[k][l], pk.ys[k][l]);
        let face = Face2::new([pt(0), pt(1), pt(2)]);
        let ids = [pk.ids[0][l], pk.ids[1][l], pk.ids[2][l]];
        let m = face.left_mask_ties(Vec2::new(px[l], py[l]), d[l], &ids);
        for (k, lk) in left.iter_mut().enumerate() {
            lk[l] = m >> k & 1 != 0;
        }
    }
}

/// The cold part of a round: each lane in `events` stopped; finish its
/// step with the scalar engine, and when its walk ended store the outcome
/// and refill the lane (or park it). Returns the number of lanes parked.
#[cold]
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn lane_events<const W: usize>(
    mesh: &TetMesh,
    rays: &[Ray],
    start: Starts<'_>,
    queued: &mut Queue,
    out: &mut [TraceOutcome],
    pk: &mut Pack<W>,
    events: u32,
    round: &Round<W>,
) -> usize {
    let mut parked = 0;
    for l in 0..W {
        if events >> l & 1 == 0 {
            continue;
        }
        let ids = [pk.ids[0][l], pk.ids[1][l], pk.ids[2][l]];
        let adv = Advance::stopped(round.capped[l], round.lost[l]);
        let (tet, visited, link) = (pk.next[l], pk.visited[l], round.raw[l]);
        match after_stop(
            mesh, rays, start, queued, out, pk.ray[l], adv, ids, tet, visited, link,
        ) {
            AfterStop::Cross(n) => {
                pk.entry[l] = link;
                pk.next[l] = n;
            }
            AfterStop::Refill(j, lane) => pk.set(l, j, &lane),
            AfterStop::Park => {
                pk.park(l);
                parked += 1;
            }
        }
    }
    parked
}

/// Array bases and bounds of the gathers of the AVX2 and AVX-512 walks.
#[cfg(target_arch = "x86_64")]
pub(crate) struct Geo<'a> {
    pub(crate) points: &'a [Vec3],
    pub(crate) words: &'a [u32],
    pub(crate) last_point: i32,
    pub(crate) last_tet: i32,
    pub(crate) stride: i32,
    pub(crate) vx: i32,
    pub(crate) ids: i32,
    pub(crate) links: i32,
}

#[cfg(target_arch = "x86_64")]
impl<'a> Geo<'a> {
    /// The gathers' view of `mesh` and its records `rw`, which must be
    /// [`RecordWords::gatherable`] (checked: the gathers' bounds rest on it).
    pub(crate) fn new(mesh: &'a TetMesh, rw: &RecordWords<'a>) -> Geo<'a> {
        assert!(
            rw.gatherable(mesh.points.len()),
            "record words not gatherable"
        );
        let (ids, links) = match rw.rule {
            ExitRule::Rank { links } | ExitRule::RankXor { links } => (0, links),
            ExitRule::Slot { ids, links } | ExitRule::Ids { ids, links } => (ids, links),
        };
        Geo {
            points: &mesh.points,
            words: rw.words,
            last_point: (mesh.points.len() - 1) as i32,
            last_tet: (rw.words.len() / rw.stride - 1) as i32,
            stride: rw.stride as i32,
            vx: rw.vx as i32,
            ids: ids as i32,
            links: links as i32,
        }
    }
}

#[cfg(target_arch = "x86_64")]
const RANK: u8 = 0;
#[cfg(target_arch = "x86_64")]
const RANK_XOR: u8 = 1;
#[cfg(target_arch = "x86_64")]
const SLOT: u8 = 2;

/// The 8-lane lockstep walk in AVX2 intrinsics, with the record words, the
/// new vertices' points and the exit links fetched by gathers.
#[cfg(target_arch = "x86_64")]
mod avx2 {
    use std::arch::x86_64::*;

    use super::*;

    /// [`Pack`] in registers (the hot fields only).
    #[derive(Clone, Copy)]
    struct V8 {
        o: [__m256; 3],
        c: [[__m256; 2]; 3],
        ids: [__m256i; 3],
        xs: [__m256; 3],
        ys: [__m256; 3],
        next: __m256i,
        entry: __m256i,
        visited: __m256i,
        /// All ones in live lanes.
        live: __m256i,
    }

    impl V8 {
        fn load(pk: &Pack<8>) -> V8 {
            let f = |a: [f32; 8]| bytemuck::cast::<[f32; 8], __m256>(a);
            let u = |a: [u32; 8]| bytemuck::cast::<[u32; 8], __m256i>(a);
            V8 {
                o: pk.o.map(f),
                c: pk.c.map(|a| a.map(f)),
                ids: pk.ids.map(u),
                xs: pk.xs.map(f),
                ys: pk.ys.map(f),
                next: u(pk.next),
                entry: u(pk.entry),
                visited: u(pk.visited),
                live: u(pk.live.map(|b| if b { u32::MAX } else { 0 })),
            }
        }

        /// Loads scalar lane `lane` into lane `l` (blends of broadcasts: the
        /// other lanes stay in their registers).
        #[target_feature(enable = "avx2")]
        fn put(&mut self, l: usize, lane: &Lane<DuffF32>) {
            let sel = lane_mask(l);
            let self_ps = _mm256_castsi256_ps(sel);
            let f = |x: &mut __m256, v: f32| *x = _mm256_blendv_ps(*x, _mm256_set1_ps(v), self_ps);
            let u = |x: &mut __m256i, v: u32| {
                *x = _mm256_blendv_epi8(*x, _mm256_set1_epi32(v as i32), sel)
            };
            let p = lane.proj;
            f(&mut self.o[0], p.o.x);
            f(&mut self.o[1], p.o.y);
            f(&mut self.o[2], p.o.z);
            for (a, col) in [p.cx, p.cy, p.cz].iter().enumerate() {
                f(&mut self.c[a][0], col.x);
                f(&mut self.c[a][1], col.y);
            }
            for s in 0..3 {
                u(&mut self.ids[s], lane.st.ids[s]);
                f(&mut self.xs[s], lane.st.p.xs[s]);
                f(&mut self.ys[s], lane.st.p.ys[s]);
            }
            u(&mut self.next, lane.next);
            u(&mut self.entry, lane.entry_raw);
            u(&mut self.visited, lane.st.visited);
            self.live = _mm256_or_si256(self.live, sel);
        }

        /// Parks lane `l` (tet 0 keeps its loads in range).
        #[target_feature(enable = "avx2")]
        fn park(&mut self, l: usize) {
            let sel = lane_mask(l);
            self.live = _mm256_andnot_si256(sel, self.live);
            self.next = _mm256_andnot_si256(sel, self.next);
        }
    }

    /// All ones in lane `l`, zeros elsewhere.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn lane_mask(l: usize) -> __m256i {
        _mm256_cmpeq_epi32(
            _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7),
            _mm256_set1_epi32(l as i32),
        )
    }

    /// Element `l` of `x`.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn lane_u32(x: __m256i, l: usize) -> u32 {
        _mm256_cvtsi256_si32(_mm256_permutevar8x32_epi32(x, _mm256_set1_epi32(l as i32))) as u32
    }

    /// The cold part of a round in registers (as the AVX-512 walk's): a
    /// stopped lane reads only what ending or crossing needs; a crossing
    /// rewrites its next tet and entry link. Returns the lanes parked.
    #[cold]
    #[inline(never)]
    #[target_feature(enable = "avx2")]
    #[allow(clippy::too_many_arguments, clippy::needless_range_loop)]
    fn events8(
        mesh: &TetMesh,
        rays: &[Ray],
        start: Starts<'_>,
        queued: &mut Queue,
        out: &mut [TraceOutcome],
        v: &mut V8,
        ray: &mut [usize; 8],
        events: u32,
        round: &Round<8>,
    ) -> usize {
        let mut parked = 0;
        for l in 0..8 {
            if events >> l & 1 == 0 {
                continue;
            }
            let u = |x: __m256i| lane_u32(x, l);
            let ids = [u(v.ids[0]), u(v.ids[1]), u(v.ids[2])];
            let (tet, visited, link) = (u(v.next), u(v.visited), round.raw[l]);
            let adv = Advance::stopped(round.capped[l], round.lost[l]);
            match after_stop(
                mesh, rays, start, queued, out, ray[l], adv, ids, tet, visited, link,
            ) {
                AfterStop::Cross(n) => {
                    let sel = lane_mask(l);
                    v.entry = _mm256_blendv_epi8(v.entry, _mm256_set1_epi32(link as i32), sel);
                    v.next = _mm256_blendv_epi8(v.next, _mm256_set1_epi32(n as i32), sel);
                }
                AfterStop::Refill(j, lane) => {
                    v.put(l, &lane);
                    ray[l] = j;
                }
                AfterStop::Park => {
                    v.park(l);
                    parked += 1;
                }
            }
        }
        parked
    }

    #[target_feature(enable = "avx2")]
    #[inline]
    fn splat(x: i32) -> __m256i {
        _mm256_set1_epi32(x)
    }

    /// Gathers `words[idx]` per lane.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn gather_words(g: &Geo<'_>, idx: __m256i) -> __m256i {
        // SAFETY: every caller forms `idx = min(next, last_tet) · stride + k`
        // with `0 ≤ k < stride` (checked by `RecordWords::gatherable`), so
        // each lane reads a word inside `g.words`.
        unsafe { _mm256_i32gather_epi32::<4>(g.words.as_ptr() as *const i32, idx) }
    }

    /// Gathers coordinate `axis` (0..=2) of `points[i]` per lane, `i ≤ last_point`.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn gather_points(g: &Geo<'_>, i3: __m256i, axis: usize) -> __m256 {
        // `Vec3` is `#[repr(C)]` `{x, y, z}`: 3 f32 words per point.
        let base = g.points.as_ptr() as *const f32;
        // SAFETY: `i3 = 3·i` with `i ≤ last_point = points.len() − 1` per
        // lane, so word `i3 + axis` (axis ≤ 2) lies inside `points`;
        // `wrapping_add` only forms the base address.
        unsafe { _mm256_i32gather_ps::<4>(base.wrapping_add(axis), i3) }
    }

    /// What the cold path needs after a round with events.
    struct Cold {
        events: u32,
        round: Round<8>,
    }

    /// One round of the walk (see `super::step`, the same decisions).
    #[target_feature(enable = "avx2")]
    #[inline]
    fn step<const RULE: u8>(v: &mut V8, g: &Geo<'_>, cap: u32) -> Option<Cold> {
        let zero = _mm256_setzero_ps();
        let ones = _mm256_set1_epi32(-1);
        // Loads: `VX`, the new vertex `d = idx₀ ⊕ idx₁ ⊕ idx₂ ⊕ VX`, its point.
        let tet = _mm256_min_epu32(v.next, splat(g.last_tet));
        let base = _mm256_mullo_epi32(tet, splat(g.stride));
        let vxw = gather_words(g, _mm256_add_epi32(base, splat(g.vx)));
        let d = _mm256_xor_si256(
            _mm256_xor_si256(v.ids[0], v.ids[1]),
            _mm256_xor_si256(v.ids[2], vxw),
        );
        let dc = _mm256_min_epu32(d, splat(g.last_point));
        let lost = _mm256_xor_si256(_mm256_cmpeq_epi32(dc, d), ones);
        let i3 = _mm256_add_epi32(_mm256_add_epi32(dc, dc), dc);
        let qx = _mm256_sub_ps(gather_points(g, i3, 0), v.o[0]);
        let qy = _mm256_sub_ps(gather_points(g, i3, 1), v.o[1]);
        let qz = _mm256_sub_ps(gather_points(g, i3, 2), v.o[2]);
        // Projection: `(c₀·qₓ + c₁·q_y) + c₂·q_z`, no FMA.
        let proj = |k: usize| {
            _mm256_add_ps(
                _mm256_add_ps(_mm256_mul_ps(v.c[0][k], qx), _mm256_mul_ps(v.c[1][k], qy)),
                _mm256_mul_ps(v.c[2][k], qz),
            )
        };
        let (px, py) = (proj(0), proj(1));
        // `det(p₃, pᵢ) = p₃.x·yᵢ − p₃.y·xᵢ`.
        let det = |k: usize| _mm256_sub_ps(_mm256_mul_ps(px, v.ys[k]), _mm256_mul_ps(py, v.xs[k]));
        let dets = [det(0), det(1), det(2)];
        let mut left = dets.map(|x| _mm256_cmp_ps::<_CMP_GT_OQ>(x, zero));
        let tie = _mm256_or_ps(
            _mm256_or_ps(
                _mm256_cmp_ps::<_CMP_EQ_OQ>(dets[0], zero),
                _mm256_cmp_ps::<_CMP_EQ_OQ>(dets[1], zero),
            ),
            _mm256_cmp_ps::<_CMP_EQ_OQ>(dets[2], zero),
        );
        let tie = _mm256_and_ps(tie, _mm256_castsi256_ps(v.live));
        if _mm256_movemask_ps(tie) != 0 {
            left = ties8(v, d, px, py, tie, left);
        }
        // Exit slot and exiting vertex (`EXIT_SLOT`).
        let s2 = _mm256_castps_si256(_mm256_andnot_ps(left[1], left[0]));
        let s1 = _mm256_castps_si256(_mm256_andnot_ps(left[0], left[2]));
        let s0 = _mm256_xor_si256(_mm256_or_si256(s1, s2), ones);
        let e = _mm256_blendv_epi8(_mm256_blendv_epi8(v.ids[0], v.ids[2], s2), v.ids[1], s1);
        // Exit link. Ids are < 2³¹ (`gatherable`), so signed compares order
        // them; `a > b` is −1, so a sum of compares is minus a count.
        let rank = |x: __m256i, of: [__m256i; 4]| {
            let c = of.map(|y| _mm256_cmpgt_epi32(x, y));
            let n = _mm256_add_epi32(_mm256_add_epi32(c[0], c[1]), _mm256_add_epi32(c[2], c[3]));
            _mm256_min_epu32(_mm256_sub_epi32(_mm256_setzero_si256(), n), splat(3))
        };
        let links = _mm256_add_epi32(base, splat(g.links));
        let link = match RULE {
            RANK => {
                let r = rank(e, [v.ids[0], v.ids[1], v.ids[2], d]);
                gather_words(g, _mm256_add_epi32(links, r))
            }
            RANK_XOR => {
                // `rank(d)` among the entry face (d itself never counts).
                let rd = rank(d, [v.ids[0], v.ids[1], v.ids[2], d]);
                let re = rank(e, [v.ids[0], v.ids[1], v.ids[2], d]);
                let nx = |r: __m256i| {
                    let m = _mm256_cmpgt_epi32(splat(3), r);
                    let idx = _mm256_and_si256(_mm256_add_epi32(links, r), m);
                    // Lanes with rank 3 read word 0 (in range) and drop it.
                    _mm256_and_si256(gather_words(g, _mm256_blendv_epi8(base, idx, m)), m)
                };
                _mm256_xor_si256(_mm256_xor_si256(v.entry, nx(rd)), nx(re))
            }
            _ => {
                let ids = _mm256_add_epi32(base, splat(g.ids));
                let vid = |k: i32| gather_words(g, _mm256_add_epi32(ids, splat(k)));
                let mut slot = splat(3);
                for k in (0..3).rev() {
                    let hit = _mm256_cmpeq_epi32(e, vid(k));
                    slot = _mm256_blendv_epi8(slot, splat(k), hit);
                }
                gather_words(g, _mm256_add_epi32(links, slot))
            }
        };
        // Commit.
        let capped = _mm256_cmpeq_epi32(
            _mm256_min_epu32(v.visited, splat(cap as i32)),
            splat(cap as i32),
        );
        let go = _mm256_andnot_si256(_mm256_or_si256(capped, lost), v.live);
        for (k, s) in [s0, s1, s2].into_iter().enumerate() {
            let sel = _mm256_and_si256(go, s);
            let self_ps = _mm256_castsi256_ps(sel);
            v.ids[k] = _mm256_blendv_epi8(v.ids[k], d, sel);
            v.xs[k] = _mm256_blendv_ps(v.xs[k], px, self_ps);
            v.ys[k] = _mm256_blendv_ps(v.ys[k], py, self_ps);
        }
        v.visited = _mm256_sub_epi32(v.visited, go);
        let boundary = splat(Link::BOUNDARY.0 as i32);
        let is_tet = _mm256_xor_si256(
            _mm256_cmpeq_epi32(_mm256_min_epu32(link, boundary), boundary),
            ones,
        );
        let moving = _mm256_and_si256(go, is_tet);
        v.entry = _mm256_blendv_epi8(v.entry, v.next, moving);
        v.next = _mm256_blendv_epi8(v.next, link, moving);
        let raw = bytemuck::cast::<__m256i, [u32; 8]>(link);
        if PREFETCH {
            for &r in &raw {
                crate::walk::prefetch_index(g.words, r.wrapping_mul(g.stride as u32));
            }
        }
        let events = _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_andnot_si256(moving, v.live)));
        if events == 0 {
            return None;
        }
        let flags = |m: __m256i| bytemuck::cast::<__m256i, [u32; 8]>(m).map(|x| x != 0);
        Some(Cold {
            events: events as u32,
            round: Round {
                raw,
                lost: flags(lost),
                capped: flags(capped),
            },
        })
    }

    /// Prefetch the next tets' records (measured: see the module docs).
    const PREFETCH: bool = false;

    /// The scalar tie rule for the lanes with a zero determinant (`tie`).
    #[target_feature(enable = "avx2")]
    #[inline(never)]
    #[cold]
    fn ties8(
        v: &V8,
        d: __m256i,
        px: __m256,
        py: __m256,
        tie: __m256,
        left: [__m256; 3],
    ) -> [__m256; 3] {
        let f = |a: __m256| bytemuck::cast::<__m256, [f32; 8]>(a);
        let u = |a: __m256i| bytemuck::cast::<__m256i, [u32; 8]>(a);
        let (xs, ys, ids) = (v.xs.map(f), v.ys.map(f), v.ids.map(u));
        let (d, px, py, tie) = (u(d), f(px), f(py), f(tie));
        let mut left = left.map(f);
        for l in 0..8 {
            if tie[l].to_bits() == 0 {
                continue;
            }
            let pt = |k: usize| Vec2::new(xs[k][l], ys[k][l]);
            let face = Face2::new([pt(0), pt(1), pt(2)]);
            let id = [ids[0][l], ids[1][l], ids[2][l]];
            let m = face.left_mask_ties(Vec2::new(px[l], py[l]), d[l], &id);
            for (k, lk) in left.iter_mut().enumerate() {
                lk[l] = f32::from_bits(if m >> k & 1 != 0 { u32::MAX } else { 0 });
            }
        }
        left.map(bytemuck::cast::<[f32; 8], __m256>)
    }

    /// The AVX2 lockstep driver with exit rule `RULE`; `rw` must be
    /// [`RecordWords::gatherable`] for `mesh.points`.
    #[target_feature(enable = "avx2")]
    pub(super) fn run_gather<const RULE: u8>(
        mesh: &TetMesh,
        rw: RecordWords<'_>,
        rays: &[Ray],
        start: Starts<'_>,
        cap: u32,
        out: &mut [TraceOutcome],
    ) {
        let n = rays.len().min(out.len());
        let (rays, out) = (&rays[..n], &mut out[..n]);
        let g = Geo::new(mesh, &rw);
        let mut queued = Queue::default();
        // `GROUPS` independent packs of 8 lanes, stepped in turn: the
        // out-of-order core overlaps their dependent gather chains.
        let mut groups: [(V8, [usize; 8], usize); GROUPS] = std::array::from_fn(|_| {
            let (pk, live) = fill::<8>(mesh, rays, start, &mut queued, out);
            (V8::load(&pk), pk.ray, live)
        });
        loop {
            let mut any = false;
            for (v, ray, live) in groups.iter_mut() {
                if *live == 0 {
                    continue;
                }
                any = true;
                if let Some(c) = step::<RULE>(v, &g, cap) {
                    *live -= events8(
                        mesh,
                        rays,
                        start,
                        &mut queued,
                        out,
                        v,
                        ray,
                        c.events,
                        &c.round,
                    );
                }
            }
            if !any {
                break;
            }
        }
    }

    /// Packs of 8 lanes in flight per thread (measured: see the module docs).
    const GROUPS: usize = 2;
}

/// The 16-lane lockstep walk in AVX-512 intrinsics: the AVX2 walk of
/// [`avx2`] with 512-bit vectors and mask registers (same decisions, lane
/// by lane the same IEEE operations), one pack of 16 lanes in flight per
/// group.
#[cfg(target_arch = "x86_64")]
pub(crate) mod avx512 {
    use std::arch::x86_64::*;

    use super::*;

    /// [`Pack`] in registers (the hot fields only).
    #[derive(Clone, Copy)]
    struct V16 {
        o: [__m512; 3],
        c: [[__m512; 2]; 3],
        ids: [__m512i; 3],
        xs: [__m512; 3],
        ys: [__m512; 3],
        next: __m512i,
        entry: __m512i,
        visited: __m512i,
        /// Live lanes.
        live: __mmask16,
    }

    impl V16 {
        fn load(pk: &Pack<16>) -> V16 {
            let f = |a: [f32; 16]| bytemuck::cast::<[f32; 16], __m512>(a);
            let u = |a: [u32; 16]| bytemuck::cast::<[u32; 16], __m512i>(a);
            let live = pk
                .live
                .iter()
                .enumerate()
                .fold(0u16, |m, (l, &b)| m | ((b as u16) << l));
            V16 {
                o: pk.o.map(f),
                c: pk.c.map(|a| a.map(f)),
                ids: pk.ids.map(u),
                xs: pk.xs.map(f),
                ys: pk.ys.map(f),
                next: u(pk.next),
                entry: u(pk.entry),
                visited: u(pk.visited),
                live,
            }
        }

        /// Loads scalar lane `lane` into lane `l` (masked broadcasts: the
        /// other lanes stay in their registers).
        #[target_feature(enable = "avx512f")]
        fn put(&mut self, l: usize, lane: &Lane<DuffF32>) {
            let k: __mmask16 = 1 << l;
            let f = |x: &mut __m512, v: f32| *x = _mm512_mask_mov_ps(*x, k, _mm512_set1_ps(v));
            let u = |x: &mut __m512i, v: u32| *x = _mm512_mask_set1_epi32(*x, k, v as i32);
            let p = lane.proj;
            f(&mut self.o[0], p.o.x);
            f(&mut self.o[1], p.o.y);
            f(&mut self.o[2], p.o.z);
            for (a, col) in [p.cx, p.cy, p.cz].iter().enumerate() {
                f(&mut self.c[a][0], col.x);
                f(&mut self.c[a][1], col.y);
            }
            for s in 0..3 {
                u(&mut self.ids[s], lane.st.ids[s]);
                f(&mut self.xs[s], lane.st.p.xs[s]);
                f(&mut self.ys[s], lane.st.p.ys[s]);
            }
            u(&mut self.next, lane.next);
            u(&mut self.entry, lane.entry_raw);
            u(&mut self.visited, lane.st.visited);
            self.live |= k;
        }

        /// Parks lane `l` (see [`Pack::park`]).
        #[target_feature(enable = "avx512f")]
        fn park(&mut self, l: usize) {
            let k: __mmask16 = 1 << l;
            self.live &= !k;
            self.next = _mm512_mask_set1_epi32(self.next, k, 0);
        }
    }

    /// The cold part of a round in registers (see [`super::lane_events`]):
    /// only the lanes with an event are read and rewritten. Returns the
    /// number of lanes parked.
    #[cold]
    #[inline(never)]
    #[target_feature(enable = "avx512f")]
    // Lane `l` indexes the round's flags, the ray slots and the registers.
    #[allow(clippy::too_many_arguments, clippy::needless_range_loop)]
    fn events16(
        mesh: &TetMesh,
        rays: &[Ray],
        start: Starts<'_>,
        queued: &mut Queue,
        out: &mut [TraceOutcome],
        v: &mut V16,
        ray: &mut [usize; 16],
        events: u32,
        round: &Round<16>,
    ) -> usize {
        let mut parked = 0;
        for l in 0..16 {
            if events >> l & 1 == 0 {
                continue;
            }
            // Only what ending or crossing needs is read from the registers;
            // a lane that crosses keeps them all but its next tet.
            let k: __mmask16 = 1 << l;
            let u = |x: __m512i| lane_u32(x, l);
            let ids = [u(v.ids[0]), u(v.ids[1]), u(v.ids[2])];
            let (tet, visited, link) = (u(v.next), u(v.visited), round.raw[l]);
            let adv = Advance::stopped(round.capped[l], round.lost[l]);
            match after_stop(
                mesh, rays, start, queued, out, ray[l], adv, ids, tet, visited, link,
            ) {
                AfterStop::Cross(n) => {
                    v.entry = _mm512_mask_set1_epi32(v.entry, k, link as i32);
                    v.next = _mm512_mask_set1_epi32(v.next, k, n as i32);
                }
                AfterStop::Refill(j, lane) => {
                    v.put(l, &lane);
                    ray[l] = j;
                }
                AfterStop::Park => {
                    v.park(l);
                    parked += 1;
                }
            }
        }
        parked
    }

    /// Element `l` of `x` (one permute brings it to element 0).
    #[target_feature(enable = "avx512f")]
    #[inline]
    pub(crate) fn lane_u32(x: __m512i, l: usize) -> u32 {
        let at = _mm512_set1_epi32(l as i32);
        _mm_cvtsi128_si32(_mm512_castsi512_si128(_mm512_permutexvar_epi32(at, x))) as u32
    }

    #[target_feature(enable = "avx512f")]
    #[inline]
    pub(crate) fn splat(x: i32) -> __m512i {
        _mm512_set1_epi32(x)
    }

    /// Gathers `words[idx]` per lane.
    #[target_feature(enable = "avx512f")]
    #[inline]
    pub(crate) fn gather_words(g: &Geo<'_>, idx: __m512i) -> __m512i {
        // SAFETY: every caller forms `idx = min(next, last_tet) · stride + k`
        // with `0 ≤ k < stride` (checked by `RecordWords::gatherable`), so
        // each lane reads a word inside `g.words`.
        unsafe { _mm512_i32gather_epi32::<4>(idx, g.words.as_ptr() as *const i32) }
    }

    /// `(x, y, z)` of `points[i]` per lane, `i3 = 3·i`, `i ≤ last_point`.
    #[target_feature(enable = "avx512f")]
    #[inline]
    pub(crate) fn gather_point(g: &Geo<'_>, i3: __m512i) -> [__m512; 3] {
        let (x, y) = gather_xy(g, i3);
        [x, y, gather_points(g, i3, 2)]
    }

    /// Gathers coordinate `axis` (0..=2) of `points[i]` per lane, `i ≤ last_point`.
    #[target_feature(enable = "avx512f")]
    #[inline]
    fn gather_points(g: &Geo<'_>, i3: __m512i, axis: usize) -> __m512 {
        let base = g.points.as_ptr() as *const f32;
        // SAFETY: `i3 = 3·i` with `i ≤ last_point = points.len() − 1` per
        // lane, so word `i3 + axis` (axis ≤ 2) lies inside `points`;
        // `wrapping_add` only forms the base address.
        unsafe { _mm512_i32gather_ps::<4>(i3, base.wrapping_add(axis)) }
    }

    /// Gathers `(x, y)` of `points[i]` per lane (`i3 = 3·i`, `i ≤
    /// last_point`) as two 8-lane gathers of 64-bit pairs, deinterleaved:
    /// 16 loads instead of the 32 of two 16-lane gathers.
    #[target_feature(enable = "avx512f")]
    #[inline]
    fn gather_xy(g: &Geo<'_>, i3: __m512i) -> (__m512, __m512) {
        let base = g.points.as_ptr() as *const i64;
        let lo = _mm512_castsi512_si256(i3);
        let hi = _mm512_extracti64x4_epi64::<1>(i3);
        // SAFETY: as `gather_points`: lane `k` reads the 8 bytes at word
        // `3·i`, the point's x and y, inside `points`.
        let (a, b) = unsafe {
            (
                _mm512_i32gather_epi64::<4>(lo, base),
                _mm512_i32gather_epi64::<4>(hi, base),
            )
        };
        let (a, b) = (_mm512_castsi512_ps(a), _mm512_castsi512_ps(b));
        let even = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
        let odd = _mm512_setr_epi32(1, 3, 5, 7, 9, 11, 13, 15, 17, 19, 21, 23, 25, 27, 29, 31);
        (
            _mm512_permutex2var_ps(a, even, b),
            _mm512_permutex2var_ps(a, odd, b),
        )
    }

    /// Per-lane flags of a mask.
    fn flags(m: __mmask16) -> [bool; 16] {
        std::array::from_fn(|l| m >> l & 1 != 0)
    }

    /// One round of the walk (see `super::step`, the same decisions).
    #[target_feature(enable = "avx512f")]
    #[inline]
    fn step<const RULE: u8>(v: &mut V16, g: &Geo<'_>, cap: u32) -> Option<(u32, Round<16>)> {
        let zero = _mm512_setzero_ps();
        let one = splat(1);
        // Loads: `VX`, the new vertex `d = idx₀ ⊕ idx₁ ⊕ idx₂ ⊕ VX`, its point.
        let tet = _mm512_min_epu32(v.next, splat(g.last_tet));
        let base = _mm512_mullo_epi32(tet, splat(g.stride));
        let vxw = gather_words(g, _mm512_add_epi32(base, splat(g.vx)));
        let d = _mm512_xor_si512(
            _mm512_xor_si512(v.ids[0], v.ids[1]),
            _mm512_xor_si512(v.ids[2], vxw),
        );
        let dc = _mm512_min_epu32(d, splat(g.last_point));
        let lost = _mm512_cmpneq_epi32_mask(dc, d);
        let i3 = _mm512_add_epi32(_mm512_add_epi32(dc, dc), dc);
        let [px3, py3, pz3] = gather_point(g, i3);
        let qx = _mm512_sub_ps(px3, v.o[0]);
        let qy = _mm512_sub_ps(py3, v.o[1]);
        let qz = _mm512_sub_ps(pz3, v.o[2]);
        // Projection: `(c₀·qₓ + c₁·q_y) + c₂·q_z`, no FMA.
        let proj = |k: usize| {
            _mm512_add_ps(
                _mm512_add_ps(_mm512_mul_ps(v.c[0][k], qx), _mm512_mul_ps(v.c[1][k], qy)),
                _mm512_mul_ps(v.c[2][k], qz),
            )
        };
        let (px, py) = (proj(0), proj(1));
        // `det(p₃, pᵢ) = p₃.x·yᵢ − p₃.y·xᵢ`.
        let det = |k: usize| _mm512_sub_ps(_mm512_mul_ps(px, v.ys[k]), _mm512_mul_ps(py, v.xs[k]));
        let dets = [det(0), det(1), det(2)];
        let mut left = dets.map(|x| _mm512_cmp_ps_mask::<_CMP_GT_OQ>(x, zero));
        let tie = (_mm512_cmp_ps_mask::<_CMP_EQ_OQ>(dets[0], zero)
            | _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(dets[1], zero)
            | _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(dets[2], zero))
            & v.live;
        if tie != 0 {
            left = ties16(v, d, px, py, tie, left);
        }
        // Exit slot and exiting vertex (`EXIT_SLOT`).
        let s2 = left[0] & !left[1];
        let s1 = !left[0] & left[2];
        let s0 = !(s1 | s2);
        let e = _mm512_mask_blend_epi32(
            s1,
            _mm512_mask_blend_epi32(s2, v.ids[0], v.ids[2]),
            v.ids[1],
        );
        // Exit link. Ids are < 2³¹ (`gatherable`), so signed compares order them.
        let rank = |x: __m512i, of: [__m512i; 4]| {
            let mut r = _mm512_setzero_si512();
            for y in of {
                r = _mm512_mask_add_epi32(r, _mm512_cmpgt_epi32_mask(x, y), r, one);
            }
            _mm512_min_epu32(r, splat(3))
        };
        let links = _mm512_add_epi32(base, splat(g.links));
        let link = match RULE {
            RANK => {
                let r = rank(e, [v.ids[0], v.ids[1], v.ids[2], d]);
                gather_words(g, _mm512_add_epi32(links, r))
            }
            RANK_XOR => {
                let rd = rank(d, [v.ids[0], v.ids[1], v.ids[2], d]);
                let re = rank(e, [v.ids[0], v.ids[1], v.ids[2], d]);
                let nx = |r: __m512i| {
                    let m = _mm512_cmplt_epu32_mask(r, splat(3));
                    // Lanes with rank 3 read word `base` (in range) and drop it.
                    let idx = _mm512_mask_blend_epi32(m, base, _mm512_add_epi32(links, r));
                    _mm512_maskz_mov_epi32(m, gather_words(g, idx))
                };
                _mm512_xor_si512(_mm512_xor_si512(v.entry, nx(rd)), nx(re))
            }
            _ => {
                let ids = _mm512_add_epi32(base, splat(g.ids));
                let vid = |k: i32| gather_words(g, _mm512_add_epi32(ids, splat(k)));
                let mut slot = splat(3);
                for k in (0..3).rev() {
                    let hit = _mm512_cmpeq_epi32_mask(e, vid(k));
                    slot = _mm512_mask_blend_epi32(hit, slot, splat(k));
                }
                gather_words(g, _mm512_add_epi32(links, slot))
            }
        };
        // Commit.
        let capped = _mm512_cmpge_epu32_mask(v.visited, splat(cap as i32));
        let go = v.live & !(capped | lost);
        for (k, s) in [s0, s1, s2].into_iter().enumerate() {
            let sel = go & s;
            v.ids[k] = _mm512_mask_blend_epi32(sel, v.ids[k], d);
            v.xs[k] = _mm512_mask_blend_ps(sel, v.xs[k], px);
            v.ys[k] = _mm512_mask_blend_ps(sel, v.ys[k], py);
        }
        v.visited = _mm512_mask_add_epi32(v.visited, go, v.visited, one);
        let is_tet = _mm512_cmplt_epu32_mask(link, splat(Link::BOUNDARY.0 as i32));
        let moving = go & is_tet;
        v.entry = _mm512_mask_blend_epi32(moving, v.entry, v.next);
        v.next = _mm512_mask_blend_epi32(moving, v.next, link);
        let events = v.live & !moving;
        if events == 0 {
            return None;
        }
        Some((
            events as u32,
            Round {
                raw: bytemuck::cast::<__m512i, [u32; 16]>(link),
                lost: flags(lost),
                capped: flags(capped),
            },
        ))
    }

    /// The scalar tie rule for the lanes with a zero determinant (`tie`).
    #[target_feature(enable = "avx512f")]
    #[inline(never)]
    #[cold]
    fn ties16(
        v: &V16,
        d: __m512i,
        px: __m512,
        py: __m512,
        tie: __mmask16,
        left: [__mmask16; 3],
    ) -> [__mmask16; 3] {
        let f = |a: __m512| bytemuck::cast::<__m512, [f32; 16]>(a);
        let u = |a: __m512i| bytemuck::cast::<__m512i, [u32; 16]>(a);
        let (xs, ys, ids) = (v.xs.map(f), v.ys.map(f), v.ids.map(u));
        let (d, px, py) = (u(d), f(px), f(py));
        let mut left = left;
        for l in 0..16 {
            if tie >> l & 1 == 0 {
                continue;
            }
            let pt = |k: usize| Vec2::new(xs[k][l], ys[k][l]);
            let face = Face2::new([pt(0), pt(1), pt(2)]);
            let id = [ids[0][l], ids[1][l], ids[2][l]];
            let m = face.left_mask_ties(Vec2::new(px[l], py[l]), d[l], &id);
            for (k, lk) in left.iter_mut().enumerate() {
                let bit = 1u16 << l;
                *lk = if m >> k & 1 != 0 {
                    *lk | bit
                } else {
                    *lk & !bit
                };
            }
        }
        left
    }

    /// The AVX-512 lockstep driver with exit rule `RULE`; `rw` must be
    /// [`RecordWords::gatherable`] for `mesh.points`.
    #[target_feature(enable = "avx512f")]
    pub(super) fn run_gather<const RULE: u8>(
        mesh: &TetMesh,
        rw: RecordWords<'_>,
        rays: &[Ray],
        start: Starts<'_>,
        cap: u32,
        out: &mut [TraceOutcome],
    ) {
        let n = rays.len().min(out.len());
        let (rays, out) = (&rays[..n], &mut out[..n]);
        let g = Geo::new(mesh, &rw);
        let mut queued = Queue::default();
        // The packs live in registers; a lane's ray index is the only cold
        // state (its projection is rebuilt from the registers).
        let mut groups: [(V16, [usize; 16], usize); GROUPS] = std::array::from_fn(|_| {
            let (pk, live) = fill::<16>(mesh, rays, start, &mut queued, out);
            (V16::load(&pk), pk.ray, live)
        });
        loop {
            let mut any = false;
            for (v, ray, live) in groups.iter_mut() {
                if *live == 0 {
                    continue;
                }
                any = true;
                if let Some((events, round)) = step::<RULE>(v, &g, cap) {
                    *live -= events16(mesh, rays, start, &mut queued, out, v, ray, events, &round);
                }
            }
            if !any {
                break;
            }
        }
    }

    /// Packs of 16 lanes in flight per thread (1: 13 % slower, Torus Knots)
    const GROUPS: usize = 2;
}
