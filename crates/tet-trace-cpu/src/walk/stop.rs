//! How a walk ends: the step cap, a lost walk, the mesh boundary (a miss)
//! or a constrained face (a hit, a miss beyond `t_max`, or a crossing into
//! the far side before `t_min`), and the f64 hit record.

use tet_core::{Link, NO_TET, TetMesh};

use crate::ray::{Failure, Hit, Ray, TraceOutcome};

/// Where a walk that reached a non-tet link goes.
pub(crate) enum Resolved {
    /// It ended with this outcome.
    Done(TraceOutcome),
    /// It crossed a constrained face before `t_min` into this tet.
    Cross(u32),
}

/// The ray reached constrained face `c` (vertices `ids`) from tet `tet`
/// (`NO_TET`: from outside the mesh) after `visited` tets: a hit, a miss
/// beyond `t_max`, or a crossing into the far side when before `t_min`.
pub(crate) fn resolve_constrained(
    mesh: &TetMesh,
    ray: &Ray,
    c: u32,
    ids: [u32; 3],
    tet: u32,
    visited: u32,
) -> Resolved {
    let cf = &mesh.constrained[c as usize];
    let (t, w) = face_hit(mesh, ray, ids);
    if t < ray.t_min as f64 {
        return match cf.other_side(tet) {
            Some(s) if s.exists() => Resolved::Cross(s.tet),
            _ => Resolved::Done(TraceOutcome::Miss {
                tets_visited: visited,
            }),
        };
    }
    if t > ray.t_max as f64 {
        return Resolved::Done(TraceOutcome::Miss {
            tets_visited: visited,
        });
    }
    let mut bary = [0f32; 3];
    for (k, &vk) in cf.vertices.iter().enumerate() {
        let j = ids.iter().position(|&x| x == vk).unwrap_or(k);
        bary[k] = w[j] as f32;
    }
    if degenerate_crossing(t, &bary) {
        return Resolved::Done(TraceOutcome::Failed {
            failure: Failure::Lost,
            tets_visited: visited,
        });
    }
    let far = cf.other_side(tet).map_or(NO_TET, |s| s.tet);
    Resolved::Done(TraceOutcome::Hit(Hit {
        triangle: cf.triangle,
        face: c,
        t: t as f32,
        barycentrics: bary,
        tet,
        far_tet: far,
        tets_visited: visited,
    }))
}

/// True when a crossing's hit record would hold infinities: the ray runs
/// (numerically) inside the face's plane, e.g. a direction mixing subnormal
/// and ordinary components. Kernels report such a walk as
/// [`Failure::Lost`] instead of returning a meaningless hit.
pub(crate) fn degenerate_crossing(t: f64, bary: &[f32; 3]) -> bool {
    !(t as f32).is_finite() || bary.iter().any(|b| !b.is_finite())
}

/// Ray parameter and barycentrics (w.r.t. `ids`) of the line's crossing with
/// triangle `ids`, in f64 (computed once per ray, at the hit).
pub fn face_hit(mesh: &TetMesh, ray: &Ray, ids: [u32; 3]) -> (f64, [f64; 3]) {
    let o = ray.origin.as_dvec3();
    let d = ray.direction.as_dvec3();
    let q = ids.map(|i| mesh.points[i as usize].as_dvec3() - o);
    let w = [
        d.dot(q[1].cross(q[2])),
        d.dot(q[2].cross(q[0])),
        d.dot(q[0].cross(q[1])),
    ];
    let sum = w[0] + w[1] + w[2];
    let w = if sum != 0.0 && sum.is_finite() {
        w.map(|x| x / sum)
    } else {
        [1.0 / 3.0; 3]
    };
    let hit = q[0] * w[0] + q[1] * w[1] + q[2] * w[2];
    (hit.dot(d) / d.length_squared(), w)
}

/// What one [`advance`](super::step::advance) did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Advance {
    /// Entered a tet and moved to its exit neighbour: keep walking.
    Go,
    /// The step cap was reached before the step (state unchanged).
    Cap,
    /// The new vertex id was out of range (state unchanged; impossible on a
    /// valid layout, reported instead of panicking).
    Lost,
    /// Entered a tet whose exit link is not a tet (constrained face or
    /// boundary): `finish_step` resolves it.
    Face,
}

/// A walk that stopped (not [`Advance::Go`]), by the few fields needed to
/// end it or let it cross: what [`finish_step`](super::step::finish_step)
/// reads from a scalar lane, and the SIMD walks from their registers.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Stopped {
    /// Why the step stopped.
    pub(crate) adv: Advance,
    /// The entry face of the tet just entered (counter-clockwise).
    pub(crate) ids: [u32; 3],
    /// The tet just entered.
    pub(crate) tet: u32,
    /// Tets visited so far.
    pub(crate) visited: u32,
    /// The raw exit link reached.
    pub(crate) link: u32,
}

impl Stopped {
    /// Where the walk of `ray` goes: ended (hit, miss or failure) or
    /// crossing a constrained face before `t_min`.
    pub(crate) fn resolve(&self, mesh: &TetMesh, ray: &Ray) -> Resolved {
        let Stopped {
            adv,
            ids,
            tet,
            visited,
            link,
        } = *self;
        let failed = |failure| {
            Resolved::Done(TraceOutcome::Failed {
                failure,
                tets_visited: visited,
            })
        };
        match adv {
            Advance::Cap => failed(Failure::StepCap),
            Advance::Lost => failed(Failure::Lost),
            Advance::Go | Advance::Face => match Link(link).as_constrained() {
                Some(c) => resolve_constrained(mesh, ray, c, ids, tet, visited),
                None => Resolved::Done(TraceOutcome::Miss {
                    tets_visited: visited,
                }),
            },
        }
    }
}

impl Advance {
    /// The stop of a SIMD lane that did not move on in a round, checked in
    /// the order of [`advance`](super::step::advance): the step cap, then a new vertex out of
    /// range, else a non-tet exit link.
    pub(crate) fn stopped(capped: bool, lost: bool) -> Advance {
        if capped {
            Advance::Cap
        } else if lost {
            Advance::Lost
        } else {
            Advance::Face
        }
    }
}
