//! The exact reference walk (`exact`): a tet walk whose every decision is
//! exact and perturbed symbolically, the yardstick the accuracy
//! measurement (Maria et al. 2017, Table 4: failures per 1024² rays) holds the
//! floating-point kernels against when an O(faces) brute force per ray is
//! too slow.
//!
//! # Decisions
//!
//! Like the Plücker walk of [`crate::tet80`], a tet entered through face
//! `e` is left through one of the three faces around the apex `V_e`,
//! decided by the signs of two side products `d · ((V_e − o) × (X − o))`
//! with edges `V_e → X` of the entry face. Every sign is the exact sign of
//! that product of the f32 inputs, decided by the simulation of simplicity
//! of `predicates` when it is zero: the ray's line is replaced by an
//! infinitesimally perturbed real line in general position. So
//!
//! * no decision is ever a tie, and the sign of an edge depends on the
//!   edge and the ray only (never on the tet), exactly antisymmetric: two
//!   tets can never disagree, and the walk follows the tets the perturbed
//!   line crosses, in order;
//! * a line crosses each (convex) tet at most once, so the walk visits each
//!   tet at most once and terminates within the number of tets (a step cap
//!   is kept anyway and reported as [`Failure::StepCap`]);
//! * the walk crosses exactly the faces the perturbed line crosses: a ray
//!   aimed exactly at a vertex or an edge, or running along an edge or in a
//!   face plane, still goes through one well-defined tet after the other.
//!
//! Cost: the side products are first evaluated in f64 with an error bound
//! (`predicates`); the exact sum (a 960-bit fixed-point accumulation)
//! only runs when the bound cannot decide, which in practice is a ray
//! through (or within ~10⁻¹⁴ relative of) a vertex or an edge. Per tet:
//! the entry face from the previous tet's ids, three vertices relative to
//! the origin in f64 and two filtered side products. Batches walk
//! [`LANES`] rays per thread round-robin, each prefetching its next tet,
//! with the same outcomes as [`Tracer::trace`] ray by ray. It is a scalar
//! walk over the canonical mesh (no compact layout, no SIMD): about the
//! speed of the scalar Plücker walk ([`crate::tet80`]), several times
//! slower than the lockstep Tet20 walk.
//!
//! # Start
//!
//! From `Start::Tet(t)` (the origin in the closed tet `t`, checked with
//! exact orientation tests, else [`Failure::Lost`]), the perturbation moves
//! the origin towards `t`'s centroid first (`predicates`), so the
//! perturbed origin lies strictly inside `t` even when the origin lies on
//! its boundary: the walk leaves `t` through the face its line exits by.
//! The caller's start tet thus decides on which side of a face, edge or
//! vertex a ray starts, as for the other walks; a ray started on a hull
//! vertex and pointing out of the mesh leaves the start tet through a
//! boundary face and misses. `Start::Face` and `Start::Entry` perturb
//! towards the centroid of their tet the same way.
//!
//! # Hits
//!
//! The first constrained face crossed whose `t` (f64, [`face_hit`]) is at
//! least `t_min` is the hit; with `t_min ≤ 0`, every face crossed from a
//! `Start::Tet` lies ahead of the perturbed origin, so it is accepted
//! whatever the rounding of `t` (which is then clamped to 0). `t` and the
//! barycentrics are computed in f64, so they are as accurate as the
//! brute force's, but only the face is exact.

mod predicates;

use glam::Vec3;
use tet_core::link::Link;
use tet_core::{FACE_VERTICES, NO_TET, TetMesh};

use crate::ray::{Failure, Hit, Ray, TraceOutcome};
use crate::tracer::Tracer;
use crate::walk::{EntryHint, LANES, Start, Starts, face_hit, prefetch_index, step_cap};
use predicates::{Line, side_filtered};
use tet_core::predicates::orient3d_f32;

/// `NEXT[k][x] = y`: the face through slots `k` and `x` whose outward
/// order, rotated to begin with `k`, is `(k, x, y)`.
const NEXT: [[u8; 4]; 4] = {
    let mut t = [[u8::MAX; 4]; 4];
    let mut j = 0;
    while j < 4 {
        let f = FACE_VERTICES[j];
        let mut r = 0;
        while r < 3 {
            t[f[r]][f[(r + 1) % 3]] = f[(r + 2) % 3] as u8;
            r += 1;
        }
        j += 1;
    }
    t
};

/// The exact reference walk (see the module docs).
pub struct ExactTracer<'m> {
    mesh: &'m TetMesh,
    cap: u32,
}

impl<'m> ExactTracer<'m> {
    /// The exact walk over `mesh`, with the step cap of the other walks
    /// (twice the tets, plus 1024).
    pub fn new(mesh: &'m TetMesh) -> Self {
        ExactTracer {
            mesh,
            cap: step_cap(mesh),
        }
    }

    /// Replaces the step cap (tets visited before a walk reports failure).
    pub fn with_step_cap(mut self, cap: u32) -> Self {
        self.cap = cap;
        self
    }

    fn points(&self, tet: u32) -> [Vec3; 4] {
        self.mesh.tet_points(tet)
    }

    /// The exit face of `tet` entered through face `entry`: two side
    /// products around the apex (see the module docs).
    #[inline(always)]
    fn exit_from(&self, line: &Line, tet: u32, entry: usize) -> usize {
        let ids = &self.mesh.tets[tet as usize];
        let rel = |slot: usize| line.rel(self.mesh.points[ids[slot] as usize]);
        let apex = rel(entry);
        let x0 = FACE_VERTICES[entry][0];
        let x1 = NEXT[entry][x0] as usize;
        let x2 = NEXT[entry][x1] as usize;
        // Faces around the apex: (apex, x0, x1) opposite x2, (apex, x1, x2)
        // opposite x0, (apex, x2, x0) opposite x1; the line leaves through
        // the one whose first edge it passes left of and second right of.
        if side_filtered(line, &apex, &rel(x0)) {
            if side_filtered(line, &apex, &rel(x1)) {
                x0
            } else {
                x2
            }
        } else if side_filtered(line, &apex, &rel(x2)) {
            x1
        } else {
            x0
        }
    }

    /// The face of `tet` whose three outward edges the line passes left
    /// of: the face it leaves through; `None` when the line misses the tet.
    fn crossing_face(&self, line: &Line, tet: u32) -> Option<usize> {
        let p = self.points(tet);
        let r = p.map(|q| line.rel(q));
        (0..4).find(|&j| {
            let [a, b, c] = FACE_VERTICES[j];
            [(a, b), (b, c), (c, a)]
                .iter()
                .all(|&(x, y)| side_filtered(line, &r[x], &r[y]))
        })
    }

    /// True when `o` lies in the closed tet `tet` (exact).
    fn holds(&self, o: Vec3, tet: u32) -> bool {
        let p = self.points(tet);
        FACE_VERTICES
            .iter()
            .all(|&[a, b, c]| orient3d_f32(p[a], p[b], p[c], o) <= 0.0)
    }

    /// One step of `w`: enters its tet and leaves it; `Some(outcome)` when
    /// the walk ends. Moving on to a neighbour prefetches its records, and
    /// the entry face there is found at the next step (by then loaded).
    #[inline(always)]
    fn step(&self, ray: &Ray, w: &mut Walk) -> Option<TraceOutcome> {
        if w.visited >= self.cap {
            return Some(TraceOutcome::Failed {
                failure: Failure::StepCap,
                tets_visited: w.visited,
            });
        }
        w.visited += 1;
        let (tet, line) = (w.tet, &w.line);
        let exit = match w.entry {
            Entry::Face(e) => self.exit_from(line, tet, e as usize),
            Entry::From(prev) => match self.mesh.face_towards(tet, prev) {
                Some(e) => self.exit_from(line, tet, e),
                None => return Some(lost(w.visited)),
            },
            Entry::Any => match self.crossing_face(line, tet) {
                Some(x) => x,
                None => return Some(lost(w.visited)),
            },
        };
        let link: Link = self.mesh.neighbors[tet as usize][exit];
        if let Some(n) = link.as_tet() {
            prefetch_index(&self.mesh.tets, n);
            prefetch_index(&self.mesh.neighbors, n);
            w.tet = n;
            w.entry = Entry::From(tet);
            return None;
        }
        let miss = TraceOutcome::Miss {
            tets_visited: w.visited,
        };
        let Some(c) = link.as_constrained() else {
            return Some(miss);
        };
        let Some(cf) = self.mesh.constrained.get(c as usize) else {
            return Some(lost(w.visited));
        };
        if w.accept.skip != Some(c) {
            let (t, bary) = face_hit(self.mesh, ray, cf.vertices);
            if w.accept.any_t || t >= ray.t_min as f64 {
                if t > ray.t_max as f64 {
                    return Some(miss);
                }
                let far = cf.other_side(tet).map_or(NO_TET, |s| s.tet);
                return Some(TraceOutcome::Hit(Hit {
                    triangle: cf.triangle,
                    face: c,
                    t: t.max(0.0) as f32,
                    barycentrics: bary.map(|x| x as f32),
                    tet,
                    far_tet: far,
                    tets_visited: w.visited,
                }));
            }
        }
        match cf.other_side(tet).filter(|s| s.exists()) {
            Some(s) => {
                w.tet = s.tet;
                w.entry = Entry::Face(s.face as u8);
                None
            }
            None => Some(miss),
        }
    }

    /// The walk of `ray` from `start`, ready for its first step, or the
    /// outcome when it cannot begin.
    fn begin(&self, ray: &Ray, start: Start) -> Result<Walk, TraceOutcome> {
        if !ray.is_valid() {
            return Err(TraceOutcome::Failed {
                failure: Failure::InvalidRay,
                tets_visited: 0,
            });
        }
        let n = self.mesh.tets.len() as u32;
        let (tet, skip) = match start {
            Start::Tet(t) if t < n && self.holds(ray.origin, t) => (t, None),
            Start::Face { face, tet } if tet < n => {
                match self.mesh.constrained.get(face as usize) {
                    Some(cf) if cf.side_of(tet).is_some() => (tet, Some(face)),
                    _ => return Err(lost(0)),
                }
            }
            Start::Entry { tet, face } if self.mesh.is_boundary_face(tet, face) => (tet, None),
            _ => return Err(lost(0)),
        };
        Ok(Walk {
            line: Line::new(ray.origin, ray.direction, self.points(tet)),
            accept: Accept {
                any_t: matches!(start, Start::Tet(_)) && ray.t_min <= 0.0,
                skip,
            },
            tet,
            entry: Entry::Any,
            visited: 0,
        })
    }
}

/// How a walk entered its current tet.
#[derive(Clone, Copy)]
enum Entry {
    /// The first tet: the exit is searched among all four faces.
    Any,
    /// Through this face.
    Face(u8),
    /// From this neighbour (the face is found when the tet is loaded).
    From(u32),
}

/// One walk in progress.
#[derive(Clone, Copy)]
struct Walk {
    line: Line,
    accept: Accept,
    tet: u32,
    entry: Entry,
    visited: u32,
}

/// The exact walk's decision for one directed edge: true when `ray`'s
/// line passes left of `a → b`, i.e. the side product
/// `d · ((a − o) × (b − o))` is positive, ties decided by the symbolic
/// perturbation of the module docs for a walk whose first tet has vertices
/// `first`. Never equal for `a → b` and `b → a` when `a ≠ b`.
pub fn left_of(a: Vec3, b: Vec3, ray: &Ray, first: [Vec3; 4]) -> bool {
    predicates::side_exact(&Line::new(ray.origin, ray.direction, first), a, b)
}

/// Which constrained faces a walk reports.
#[derive(Clone, Copy)]
struct Accept {
    /// Every crossing is a hit, whatever its rounded `t` (a `Start::Tet`
    /// walk with `t_min ≤ 0`: every face it crosses lies ahead of the
    /// perturbed origin); else from `t ≥ t_min` on.
    any_t: bool,
    /// The face a secondary ray starts on, never reported.
    skip: Option<u32>,
}

fn lost(tets_visited: u32) -> TraceOutcome {
    TraceOutcome::Failed {
        failure: Failure::Lost,
        tets_visited,
    }
}

impl Tracer for ExactTracer<'_> {
    fn name(&self) -> String {
        "exact".into()
    }
    fn mesh(&self) -> &TetMesh {
        self.mesh
    }
    fn trace(&self, ray: &Ray, start: Start) -> TraceOutcome {
        let mut w = match self.begin(ray, start) {
            Ok(w) => w,
            Err(out) => return out,
        };
        loop {
            if let Some(out) = self.step(ray, &mut w) {
                return out;
            }
        }
    }

    fn trace_batch(&self, rays: &[Ray], start: Start, out: &mut [TraceOutcome]) {
        self.trace_batch_from(rays, Starts::Same(start), out)
    }

    /// [`LANES`] walks per thread, one step each per round (the same steps
    /// as [`Tracer::trace`], so the same outcomes): their memory loads
    /// overlap.
    fn trace_batch_from(&self, rays: &[Ray], starts: Starts<'_>, out: &mut [TraceOutcome]) {
        let n = starts.batch_len(rays.len(), out.len());
        let mut hint = EntryHint::default();
        let mut lanes: [Option<(usize, Walk)>; LANES] = [None; LANES];
        let mut next = 0;
        loop {
            let mut active = false;
            for lane in lanes.iter_mut() {
                while lane.is_none() && next < n {
                    let (i, r) = (next, &rays[next]);
                    next += 1;
                    let start = match starts {
                        Starts::Same(s) => Ok(s),
                        Starts::Each(s) => Ok(s[i]),
                        Starts::Outside(entry) => self.start_outside(entry, r, &mut hint),
                    };
                    match start.and_then(|s| self.begin(r, s)) {
                        Ok(w) => *lane = Some((i, w)),
                        Err(done) => out[i] = done,
                    }
                }
                if let Some((i, w)) = lane {
                    active = true;
                    if let Some(o) = self.step(&rays[*i], w) {
                        out[*i] = o;
                        *lane = None;
                    }
                }
            }
            if !active {
                break;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `NEXT` names, for every face around every slot, the outward cyclic
    /// successor: each ordered pair of distinct slots has one.
    #[test]
    fn next_table_is_complete() {
        for (k, row) in NEXT.iter().enumerate() {
            for (x, &y) in row.iter().enumerate() {
                assert_eq!(y == u8::MAX, k == x, "{k} {x}");
                if k != x {
                    let y = y as usize;
                    assert!(y != k && y != x);
                    // (k, x, y) is a rotation of the outward face opposite
                    // the fourth slot.
                    let j = 6 - k - x - y;
                    let f = FACE_VERTICES[j];
                    let r = f.iter().position(|&s| s == k).unwrap();
                    assert_eq!((f[(r + 1) % 3], f[(r + 2) % 3]), (x, y));
                }
            }
        }
    }
}
