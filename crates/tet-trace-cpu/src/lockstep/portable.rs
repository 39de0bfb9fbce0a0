//! The portable lockstep walk: plain lane loops over a [`Pack`] of `W`
//! lanes, written for the auto-vectoriser, with per-lane loads through
//! [`Topology`]: 4 lanes on the baseline target, 8 compiled for AVX2 for
//! layouts whose records the gathers cannot read.

use glam::{Vec2, Vec3};
use tet_core::{Link, TetMesh};

#[cfg(target_arch = "x86_64")]
use super::pack::WIDE;
use super::pack::{Pack, Round, fill};
use crate::ray::{Ray, TraceOutcome};
use crate::walk::lanes::{Feed, Starts};
use crate::walk::projection::Face2;
use crate::walk::stop::{Advance, Stopped};
use crate::walk::stopped::{AfterStop, after_stop};
use crate::walk::topology::Topology;

/// The lockstep driver (see [`crate::lockstep`]).
#[inline(always)]
pub(crate) fn run<T: Topology, const W: usize>(
    mesh: &TetMesh,
    topo: &T,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
) {
    let mut feed = Feed::new(mesh, rays, start, out);
    let (mut pk, mut live) = fill::<W>(&mut feed);
    // A walk started only if the mesh has points and tets (its start tet
    // and vertices exist), so the loads of `step` have something to clamp to.
    if live == 0 || mesh.points.is_empty() {
        return;
    }
    let points = &mesh.points[..];
    while live > 0 {
        let (events, round) = step(&mut pk, points, topo, cap);
        if events != 0 {
            live -= lane_events(&mut feed, &mut pk, events, &round);
        }
    }
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
fn lane_events<const W: usize>(
    feed: &mut Feed<'_>,
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
        let stopped = Stopped {
            adv,
            ids,
            tet,
            visited,
            link,
        };
        match after_stop(feed, pk.ray[l], stopped) {
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

/// The lockstep walk with AVX2 code generation (8 lanes).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
pub(crate) fn trace_avx2<T: Topology>(
    mesh: &TetMesh,
    topo: &T,
    rays: &[Ray],
    start: Starts<'_>,
    cap: u32,
    out: &mut [TraceOutcome],
) {
    run::<T, WIDE>(mesh, topo, rays, start, cap, out);
}
