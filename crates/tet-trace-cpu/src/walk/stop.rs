//! How a walk ends: the step cap, a lost walk, the mesh boundary (a miss)
//! or a constrained face (a hit, a miss beyond `t_max`, or a crossing into
//! the far side before `t_min`), and the f64 hit record.

use glam::DVec3;
use tet_core::input_triangles::plane_barycentrics;
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
///
/// The walk decides *that* the ray crosses the face; this says where: the
/// crossing of the line with the face's plane. A line lying in the face's
/// plane, or running within a millionth of a radian of it, has no such
/// crossing to speak of (that formula gave the centroid's `t`, or a point
/// far off the face): it touches the face along a segment, or runs past it
/// near an edge, where the walk's tie rule took it across (see the walk's
/// module docs, "Why the walk ends"). The hit is then the point of that
/// segment at `t_min` if it holds it, else its end nearer `t_min`
/// (`along_face`), so the hit lies on the face. So is a crossing ahead
/// of `t_min` that lies off the face (more than a millionth, in barycentrics).
pub fn face_hit(mesh: &TetMesh, ray: &Ray, ids: [u32; 3]) -> (f64, [f64; 3]) {
    let o = ray.origin.as_dvec3();
    let d = ray.direction.as_dvec3();
    let v = ids.map(|i| mesh.points[i as usize].as_dvec3());
    let q = v.map(|p| p - o);
    let w = [
        d.dot(q[1].cross(q[2])),
        d.dot(q[2].cross(q[0])),
        d.dot(q[0].cross(q[1])),
    ];
    // `sum = d · n` for the face normal `n = (v₁ − v₀) × (v₂ − v₀)`.
    let sum = w[0] + w[1] + w[2];
    let n = (v[1] - v[0]).cross(v[2] - v[0]);
    if sum.abs() > PARALLEL * d.length() * n.length() && sum.is_finite() {
        let w = w.map(|x| x / sum);
        let hit = q[0] * w[0] + q[1] * w[1] + q[2] * w[2];
        let t = hit.dot(d) / d.length_squared();
        let t_min = ray.t_min as f64;
        if t >= t_min && w.iter().any(|&x| x < -OFF_FACE) {
            let (ta, wa) = along_face(o, d, v, t_min);
            if ta >= t_min {
                return (ta, wa);
            }
        }
        return (t, w);
    }
    along_face(o, d, v, ray.t_min as f64)
}

/// How far outside the face (in barycentrics) [`face_hit`] reports the
/// line's crossing with the face's plane as the hit. Past it, the walk took
/// the line across the face near an edge or vertex the line passes within
/// rounding of, at an angle so grazing that the plane's crossing lies far
/// along the ray (a ray through the vertex where a gear's cap meets its
/// wall was reported 1e-4 of its length beyond the vertex: a leak in 10 M
/// rays). The hit is then the point of the face nearest the line
/// ([`along_face`]), where the walk crossed. Only the hit record moves:
/// whether the face is met before `t_min` (crossed on) is still decided by
/// the plane's crossing, as the GPU walk decides it.
const OFF_FACE: f64 = 1e-6;

/// The sine of the angle between a ray and a face's plane below which
/// [`face_hit`] takes the ray as running along the face: far below any
/// crossing a walk decides in general position, far above the f32
/// rounding of a direction meant to lie in the plane (about 1e-8).
const PARALLEL: f64 = 1e-6;

/// [`face_hit`] for a line lying in (or running nearly parallel to) the
/// plane of triangle `v`: the points of the triangle's edges nearest to the
/// line bound the segment `[t₀, t₁]` of the line along the triangle; the
/// hit is at `t_min` when `t₀ ≤ t_min ≤ t₁`, else at `t₀` (ahead of
/// `t_min`) or `t₁` (behind it: the walk crosses on), with the
/// barycentrics of the nearest point of the triangle, clamped onto it.
fn along_face(o: DVec3, d: DVec3, v: [DVec3; 3], t_min: f64) -> (f64, [f64; 3]) {
    let a = d.length_squared();
    // (t, point of the triangle, distance) for each edge: the nearest
    // point, or both ends when the line runs parallel to the edge.
    let mut near = [(0.0, DVec3::ZERO, f64::INFINITY); 6];
    for i in 0..3 {
        let (p, e) = (v[i], v[(i + 1) % 3] - v[i]);
        let w0 = o - p;
        let (b, c, dw, ew) = (d.dot(e), e.dot(e), d.dot(w0), e.dot(w0));
        let den = a * c - b * b;
        let ends = if den > 1e-12 * a * c {
            let s = ((a * ew - b * dw) / den).clamp(0.0, 1.0);
            [s, s]
        } else {
            [0.0, 1.0]
        };
        for (k, s) in ends.into_iter().enumerate() {
            let t = (s * b - dw) / a;
            let x = p + e * s;
            near[2 * i + k] = (t, x, (o + d * t - x).length());
        }
    }
    let best = near.iter().map(|n| n.2).fold(f64::INFINITY, f64::min);
    let scale = v.iter().map(|p| (*p - o).length()).fold(0.0, f64::max);
    let touching = near.iter().filter(|n| n.2 <= best + 1e-9 * scale);
    let first = touching.clone().min_by(|x, y| x.0.total_cmp(&y.0));
    let last = touching.max_by(|x, y| x.0.total_cmp(&y.0));
    let (Some(&(t0, x0, _)), Some(&(t1, x1, _))) = (first, last) else {
        return (f64::NAN, [f64::NAN; 3]);
    };
    let (t, x) = if t0 >= t_min {
        (t0, x0)
    } else if t1 < t_min {
        (t1, x1)
    } else {
        (t_min, o + d * t_min)
    };
    let (b, _) = plane_barycentrics(v, x);
    let b = b.map(|x| x.clamp(0.0, 1.0));
    let sum = b[0] + b[1] + b[2];
    (
        t,
        if sum > 0.0 {
            b.map(|x| x / sum)
        } else {
            [1.0 / 3.0; 3]
        },
    )
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
    /// Entered a tet whose exit face lies wholly past the ray's `t_max`
    /// (a bounded walk, [`super::reach`]): a miss.
    Beyond,
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
            Advance::Beyond => Resolved::Done(TraceOutcome::Miss {
                tets_visited: visited,
            }),
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
    /// range, then an exit face past `t_max`, else a non-tet exit link.
    pub(crate) fn stopped(capped: bool, lost: bool, beyond: bool) -> Advance {
        if capped {
            Advance::Cap
        } else if lost {
            Advance::Lost
        } else if beyond {
            Advance::Beyond
        } else {
            Advance::Face
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// Triangle (0,0,0), (1,0,0), (0,1,0) in z = 0, and a line through
    /// (0, 0, δ) at `t = 1`, δ = 2⁻³⁰ above the vertex, falling with slope
    /// s = 2⁻¹⁶ away from the triangle: it crosses the plane off the face
    /// at `t = 1 + δ/s` (barycentrics −6e-5), where a walk that took it
    /// across near the vertex would have reported it beyond the vertex.
    fn grazing_past_vertex(t_min: f32) -> (TetMesh, Ray) {
        let mesh = TetMesh {
            points: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            ..TetMesh::default()
        };
        let (delta, s) = (2f32.powi(-30), 2f32.powi(-16));
        let d = Vec3::new(-1.0, -1.0, -s);
        let mut ray = Ray::new(Vec3::new(0.0, 0.0, delta) - d, d);
        ray.t_min = t_min;
        (mesh, ray)
    }

    #[test]
    fn a_grazing_crossing_off_the_face_is_reported_at_the_face() {
        let (mesh, ray) = grazing_past_vertex(0.0);
        let (t, w) = face_hit(&mesh, &ray, [0, 1, 2]);
        assert!((t - 1.0).abs() < 1e-6, "t = {t}, the vertex is at t = 1");
        assert!(
            (w[0] - 1.0).abs() < 1e-6 && w[1] >= 0.0 && w[2] >= 0.0,
            "{w:?}"
        );
    }

    #[test]
    fn whether_a_face_lies_before_t_min_is_the_planes_crossing() {
        let plane_t = 1.0 + 2f64.powi(-14);
        // t_min between the face's nearest point (t = 1) and the plane's
        // crossing: the crossing is ahead of t_min, so the face is met.
        for t_min in [1.0 + 2f32.powi(-15), 1.001] {
            let (mesh, ray) = grazing_past_vertex(t_min);
            let (t, _) = face_hit(&mesh, &ray, [0, 1, 2]);
            assert!(
                (t - plane_t).abs() < 1e-9,
                "t_min {t_min}: t = {t}, the plane's crossing is {plane_t}"
            );
        }
    }
}
