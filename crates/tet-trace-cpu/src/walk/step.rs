//! The scalar walk: one step of Algorithm 1 ([`advance`], the hot loop
//! body, and its exit table [`EXIT_SLOT`]), its cold path ([`finish_step`])
//! and the single-ray walk [`trace`].

use glam::Vec3;
use tet_core::{Link, TetMesh};

use super::projection::Projection;
use super::start::{Lane, Start, begin};
use super::stop::{Advance, Resolved, Stopped};
use super::topology::Topology;
use crate::ray::{DEFAULT_STEP_CAP, Ray, TraceOutcome};

/// Which slot of the counter-clockwise entry face `(a, b, c)` the new vertex
/// `d` replaces (paper Algorithm 1): the exit face is the entry face with that
/// slot replaced by `d`.
///
/// Algorithm 1 as written: if the ray is left of `d → a`, the exit face is
/// `(a, b, d)` (slot 2) when it is right of `d → b`, else `(d, b, c)` (slot
/// 0); if it is right of `d → a`, the exit face is `(c, a, d)` (slot 1) when
/// it is left of `d → c`, else slot 0. That needs two edge tests but a
/// data-dependent branch per step that mispredicts about half the time, so
/// the three signs are computed branch-free and the same decision is looked
/// up in [`EXIT_SLOT`] (one more determinant, no misprediction). Both forms
/// give identical results (the table ignores `d → c` when left of `d → a`
/// and `d → b` otherwise), so the watertightness argument is unchanged.
#[inline(always)]
pub fn exit_slot<P: Projection>(
    proj: &P,
    p: &[P::P; 3],
    ids: &[u32; 3],
    pd: P::P,
    d: u32,
) -> usize {
    EXIT_SLOT[proj.left_mask(pd, d, &P::face(*p), ids) & 7] as usize
}

/// Algorithm 1 as a table over `left(d→a) | left(d→b) << 1 | left(d→c) << 2`.
pub const EXIT_SLOT: [u8; 8] = [0, 2, 0, 0, 1, 2, 1, 0];

/// Traces `ray` from `start` with projection `P` over layout `topo`, visiting
/// at most `cap` tets. `mesh` provides the cold data (points, start tet,
/// constrained-face table) and must be the mesh `topo` was built from.
pub fn trace<P: Projection, T: Topology>(
    mesh: &TetMesh,
    topo: &T,
    ray: &Ray,
    start: Start,
    cap: u32,
) -> TraceOutcome {
    match begin::<P>(mesh, ray, start) {
        Ok(lane) => walk_on(mesh, topo, ray, lane, cap),
        Err(out) => out,
    }
}

/// [`trace`] as a bounded walk: it ends as a miss as soon as the face it
/// leaves through lies wholly past `ray.t_max` (by a conservative f32
/// test on each vertex, the same in the SIMD lockstep walk; the rule and
/// its error bound are in the crate's `walk/reach.rs`). The
/// same hit or miss as [`trace`] (a walk that would reach the step cap
/// past `t_max` ends as a miss instead), in fewer tets.
pub fn trace_within<P: Projection, T: Topology>(
    mesh: &TetMesh,
    topo: &T,
    ray: &Ray,
    start: Start,
    cap: u32,
) -> TraceOutcome {
    match begin::<P>(mesh, ray, start).and_then(|lane| lane.bounded(mesh, ray)) {
        Ok(lane) => walk_on(mesh, topo, ray, lane, cap),
        Err(out) => out,
    }
}

/// The hot loop of [`trace`] from a started lane.
#[inline(always)]
fn walk_on<P: Projection, T: Topology>(
    mesh: &TetMesh,
    topo: &T,
    ray: &Ray,
    mut lane: Lane<P>,
    cap: u32,
) -> TraceOutcome {
    let points = &mesh.points[..];
    loop {
        let adv = advance(points, topo, &mut lane, cap);
        if adv != Advance::Go
            && let Some(out) = finish_step(mesh, ray, &mut lane, adv)
        {
            return out;
        }
    }
}

/// The hot loop body: enter `lane.next` through the face `lane.st.ids`
/// (raw back-link `lane.entry_raw`), choose the exit face, follow its link
/// when it is a tet. Everything rarer (a constrained face or the boundary,
/// the step cap) is left to the out-of-line [`finish_step`].
#[inline(always)]
pub(crate) fn advance<P: Projection, T: Topology>(
    points: &[Vec3],
    topo: &T,
    lane: &mut Lane<P>,
    cap: u32,
) -> Advance {
    let st = &mut lane.st;
    if st.visited >= cap {
        return Advance::Cap;
    }
    let next = lane.next;
    let d = st.ids[0] ^ st.ids[1] ^ st.ids[2] ^ topo.vx(next);
    let Some(&pd3) = points.get(d as usize) else {
        return Advance::Lost;
    };
    let pd = lane.proj.project(pd3);
    // `EXIT_SLOT` holds 0..=2, so `min(·, 2)` is the identity; it only lets
    // the compiler drop the bounds checks of the indexings below.
    let slot = usize::min(
        EXIT_SLOT[lane.proj.left_mask(pd, d, &st.p, &st.ids) & 7] as usize,
        2,
    );
    let exiting = st.ids[slot];
    let raw = topo.exit_link(next, st.ids, d, exiting, lane.entry_raw);
    // The lane state lives in memory (several lanes are in flight), so a
    // variable-indexed store is one instruction per array.
    st.ids[slot] = d;
    P::set_point(&mut st.p, slot, pd);
    st.visited += 1;
    if let Some(r) = &lane.reach {
        let b = lane.beyond & !(1 << slot) | (r.beyond(pd3) as u8) << slot;
        lane.beyond = b;
        if b == 7 {
            st.tet = next;
            st.link = raw;
            return Advance::Beyond;
        }
    }
    if raw < Link::BOUNDARY.0 {
        topo.prefetch(raw);
        lane.entry_raw = next;
        lane.next = raw;
        Advance::Go
    } else {
        // `tet` and `link` are read only when resolving a face.
        st.tet = next;
        st.link = raw;
        Advance::Face
    }
}

/// The rare outcomes of [`advance`]: `Some` when the walk ended, `None` when
/// it crossed a constrained face before `t_min` and goes on.
#[cold]
#[inline(never)]
pub(crate) fn finish_step<P: Projection>(
    mesh: &TetMesh,
    ray: &Ray,
    lane: &mut Lane<P>,
    adv: Advance,
) -> Option<TraceOutcome> {
    if adv == Advance::Go {
        return None;
    }
    let st = &lane.st;
    let stopped = Stopped {
        adv,
        ids: st.ids,
        tet: st.tet,
        visited: st.visited,
        link: st.link,
    };
    match stopped.resolve(mesh, ray) {
        Resolved::Done(out) => Some(out),
        Resolved::Cross(n) => {
            lane.entry_raw = st.link;
            lane.next = n;
            None
        }
    }
}

/// Default step cap for a mesh: `2 × tets + 1024`, at most
/// [`DEFAULT_STEP_CAP`] (a straight walk never visits a tet twice).
pub fn step_cap(mesh: &TetMesh) -> u32 {
    (2 * mesh.tets.len() as u64 + 1024).min(DEFAULT_STEP_CAP as u64) as u32
}
