//! Test support: an f64 brute-force closest hit over every constrained face,
//! and ray generators (random, aimed at vertices / edge midpoints / face
//! centroids, axis-aligned).
//!
//! The brute force is independent of the walk: it never looks at tets or
//! links, only at [`TetMesh::constrained`] and [`TetMesh::points`]. Its
//! ray–triangle test uses the orientation form: with `qᵢ = Pᵢ − o`, the edge
//! functions `d · (qᵢ × qⱼ)` are evaluated in f64 (on f32 inputs) and
//! triangles are closed (a point on a shared edge counts for both), so no
//! ray slips through a closed surface. Rays whose answer depends on rounding
//! (passing within a tolerance of a triangle edge, see [`grazes_an_edge`];
//! two hits at nearly equal `t`, see [`RefHit::t_gap`]) are what tests skip
//! when they compare kernels with the reference.

use glam::{DVec3, Vec3};
use tet_core::TetMesh;
use tet_core::synthetic::SplitMix64;

use crate::ray::Ray;

/// The closest constrained face along a ray, by brute force in f64.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RefHit {
    /// Constrained-face index.
    pub face: u32,
    /// Scene triangle id.
    pub triangle: u32,
    /// Ray parameter.
    pub t: f64,
    /// Barycentrics w.r.t. the face's `vertices`.
    pub barycentrics: [f64; 3],
    /// Distance from the hit point to the nearest edge of its triangle (0 on
    /// an edge): small values mark rays whose hit triangle is ambiguous.
    pub edge_distance: f64,
    /// Gap in `t` to the next-closest hit on another face (∞ if none).
    pub t_gap: f64,
}

/// Distance from `p` to segment `ab`.
pub fn segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let l = ab.length_squared();
    let s = if l > 0.0 {
        ((p - a).dot(ab) / l).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * s - p).length()
}

/// Distance from `p` to the nearest edge of triangle `v`.
pub fn edge_distance(p: DVec3, v: [DVec3; 3]) -> f64 {
    segment_distance(p, v[0], v[1])
        .min(segment_distance(p, v[1], v[2]))
        .min(segment_distance(p, v[2], v[0]))
}

/// Distance from the line `o + s·d` to segment `ab`: small when the line
/// passes close to the segment anywhere, which for a ray nearly parallel to
/// a triangle happens far from where it meets the triangle.
pub fn line_segment_distance(o: DVec3, d: DVec3, a: DVec3, b: DVec3) -> f64 {
    let dd = d.length_squared();
    // Components across the line: the distance of `a + u·(b − a)` to the
    // line is `|pa + u·pe|`, a convex function of `u`.
    let across = |v: DVec3| {
        if dd > 0.0 { v - d * (v.dot(d) / dd) } else { v }
    };
    let (pa, pe) = (across(a - o), across(b - a));
    let ee = pe.length_squared();
    let u = if ee > 0.0 {
        (-pa.dot(pe) / ee).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (pa + pe * u).length()
}

/// Distance from the line `o + s·d` to the nearest edge of triangle `v`.
pub fn line_edge_distance(o: DVec3, d: DVec3, v: [DVec3; 3]) -> f64 {
    line_segment_distance(o, d, v[0], v[1])
        .min(line_segment_distance(o, d, v[1], v[2]))
        .min(line_segment_distance(o, d, v[2], v[0]))
}

/// Where the line `o + s·d` passes through triangle `v` (closed), in f64:
/// its barycentrics w.r.t. `v`, or `None` when the line misses the
/// triangle or is parallel to it.
pub fn line_triangle(o: DVec3, d: DVec3, v: [DVec3; 3]) -> Option<[f64; 3]> {
    let q = v.map(|p| p - o);
    let w = [
        d.dot(q[1].cross(q[2])),
        d.dot(q[2].cross(q[0])),
        d.dot(q[0].cross(q[1])),
    ];
    let inside =
        (w[0] >= 0.0 && w[1] >= 0.0 && w[2] >= 0.0) || (w[0] <= 0.0 && w[1] <= 0.0 && w[2] <= 0.0);
    let sum = w[0] + w[1] + w[2];
    if !inside || sum == 0.0 {
        return None;
    }
    Some(w.map(|x| x / sum))
}

/// Intersection of the ray's line with triangle `v` (closed), as
/// `(t, barycentrics)`; `None` when the line misses it or is parallel.
pub fn ray_triangle(ray: &Ray, v: [Vec3; 3]) -> Option<(f64, [f64; 3])> {
    let o = ray.origin.as_dvec3();
    let d = ray.direction.as_dvec3();
    let v = v.map(|p| p.as_dvec3());
    let b = line_triangle(o, d, v)?;
    let q = v.map(|p| p - o);
    let p = q[0] * b[0] + q[1] * b[1] + q[2] * b[2];
    Some((p.dot(d) / d.length_squared(), b))
}

/// The closest constrained face with `t ∈ [ray.t_min, ray.t_max]`, by brute force.
pub fn closest_hit(mesh: &TetMesh, ray: &Ray) -> Option<RefHit> {
    let mut best: Option<RefHit> = None;
    let mut second = f64::INFINITY;
    for (i, cf) in mesh.constrained.iter().enumerate() {
        let v = cf.vertices.map(|k| mesh.points[k as usize]);
        let Some((t, b)) = ray_triangle(ray, v) else {
            continue;
        };
        if t < ray.t_min as f64 || t > ray.t_max as f64 {
            continue;
        }
        if best.is_none_or(|h| t < h.t) {
            if let Some(h) = best {
                second = h.t;
            }
            let vd = v.map(|p| p.as_dvec3());
            let p = ray.origin.as_dvec3() + ray.direction.as_dvec3() * t;
            let edge_distance = edge_distance(p, vd);
            best = Some(RefHit {
                face: i as u32,
                triangle: cf.triangle,
                t,
                barycentrics: b,
                edge_distance,
                t_gap: f64::INFINITY,
            });
        } else {
            second = second.min(t);
        }
    }
    best.map(|mut h| {
        h.t_gap = second - h.t;
        h
    })
}

/// True when the ray's line crosses the plane of some constrained face (with
/// `t ≥ t_min − tol`) within distance `tol` of one of that face's edges: the
/// first hit of such a ray depends on rounding (it may land on the
/// neighbouring face, or slip past a free edge), so comparisons skip it.
pub fn grazes_an_edge(mesh: &TetMesh, ray: &Ray, tol: f64) -> bool {
    let o = ray.origin.as_dvec3();
    let d = ray.direction.as_dvec3();
    mesh.constrained.iter().any(|cf| {
        let v = cf.vertices.map(|k| mesh.points[k as usize].as_dvec3());
        let n = (v[1] - v[0]).cross(v[2] - v[0]);
        let den = n.dot(d);
        if den == 0.0 {
            // Parallel: ambiguous if the line lies in (or very near) the plane.
            return (n.dot(v[0] - o) / n.length()).abs() < tol;
        }
        let t = n.dot(v[0] - o) / den;
        if t < ray.t_min as f64 - tol || t > ray.t_max as f64 + tol {
            return false;
        }
        let p = o + d * t;
        edge_distance(p, v) < tol
    })
}

/// A uniformly random unit direction.
pub fn random_direction(rng: &mut SplitMix64) -> Vec3 {
    loop {
        let v = Vec3::new(
            rng.range_f32(-1.0, 1.0),
            rng.range_f32(-1.0, 1.0),
            rng.range_f32(-1.0, 1.0),
        );
        let l = v.length_squared();
        if l > 1e-4 && l <= 1.0 {
            return v / l.sqrt();
        }
    }
}

/// A random point inside a random tet (by random barycentrics), with the tet.
pub fn random_point_inside(mesh: &TetMesh, rng: &mut SplitMix64) -> (Vec3, u32) {
    let t = (rng.next_u64() % mesh.tets.len() as u64) as u32;
    let p = mesh.tet_points(t).map(|x| x.as_dvec3());
    let mut w = [0f64; 4];
    for x in &mut w {
        *x = -rng.next_f64().max(1e-12).ln();
    }
    let s: f64 = w.iter().sum();
    let q = (p[0] * w[0] + p[1] * w[1] + p[2] * w[2] + p[3] * w[3]) / s;
    // Rounded to f32, a point of a small tet far from the origin can fall
    // outside it (the ulp at 1e5 is 0.008): the start tet is then the one
    // that contains the rounded point, found by an exact walk from `t`.
    let q = q.as_vec3();
    (q, crate::locate(mesh, q, t).unwrap_or(t))
}

/// What a generated ray is aimed at.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Aim {
    /// A random direction.
    Random,
    /// Exactly at a mesh vertex (the direction is `vertex − origin`).
    Vertex,
    /// At the midpoint of a tet edge.
    EdgeMidpoint,
    /// At the centroid of a tet face.
    FaceCentroid,
}

/// A ray from a random point inside the mesh, aimed as asked, with a
/// tet that contains its origin.
pub fn random_ray(mesh: &TetMesh, rng: &mut SplitMix64, aim: Aim) -> (Ray, u32) {
    let (o, t) = random_point_inside(mesh, rng);
    let pick = |rng: &mut SplitMix64| {
        let t = (rng.next_u64() % mesh.tets.len() as u64) as usize;
        (mesh.tet_points(t as u32), rng.next_u64())
    };
    let target = match aim {
        Aim::Random => return (Ray::new(o, random_direction(rng)), t),
        Aim::Vertex => {
            let (p, r) = pick(rng);
            p[(r % 4) as usize]
        }
        Aim::EdgeMidpoint => {
            let (p, r) = pick(rng);
            let a = (r % 4) as usize;
            let b = (a + 1 + (r / 4 % 3) as usize) % 4;
            (p[a] + p[b]) * 0.5
        }
        Aim::FaceCentroid => {
            let (p, r) = pick(rng);
            let k = (r % 4) as usize;
            let s = tet_core::FACE_VERTICES[k];
            (p[s[0]] + p[s[1]] + p[s[2]]) / 3.0
        }
    };
    let d = target - o;
    if d.length_squared() > 0.0 {
        (Ray::new(o, d), t)
    } else {
        (Ray::new(o, Vec3::X), t)
    }
}

/// A ray starting exactly on a mesh vertex, an edge midpoint or a face
/// centroid (`aim`), in a random direction, with `t_min = 0`. The origin lies
/// on tet boundaries, the hardest case for a start tet. Returns the ray only;
/// locate its origin with [`crate::locate::locate`].
pub fn ray_from_feature(mesh: &TetMesh, rng: &mut SplitMix64, aim: Aim) -> Ray {
    let t = (rng.next_u64() % mesh.tets.len() as u64) as u32;
    let p = mesh.tet_points(t);
    let r = rng.next_u64();
    let o = match aim {
        Aim::Random | Aim::Vertex => p[(r % 4) as usize],
        Aim::EdgeMidpoint => {
            let a = (r % 4) as usize;
            let b = (a + 1 + (r / 4 % 3) as usize) % 4;
            (p[a] + p[b]) * 0.5
        }
        Aim::FaceCentroid => {
            let s = tet_core::FACE_VERTICES[(r % 4) as usize];
            (p[s[0]] + p[s[1]] + p[s[2]]) / 3.0
        }
    };
    Ray::new(o, random_direction(rng))
}

/// An axis-aligned ray (direction `±x`, `±y` or `±z`) from a point whose
/// coordinates are multiples of `1/4` inside the box `[lo, hi]`: on an
/// unjittered grid mesh it runs exactly along edges, through vertices and in
/// face planes.
pub fn axis_ray(rng: &mut SplitMix64, lo: Vec3, hi: Vec3) -> Ray {
    let q = |rng: &mut SplitMix64, a: f32, b: f32| {
        let steps = ((b - a) * 4.0).floor().max(0.0) as u64;
        let k = if steps > 2 {
            1 + rng.next_u64() % (steps - 1)
        } else {
            1
        };
        (a + k as f32 * 0.25).min(b)
    };
    let o = Vec3::new(q(rng, lo.x, hi.x), q(rng, lo.y, hi.y), q(rng, lo.z, hi.z));
    let axis = (rng.next_u64() % 6) as usize;
    let mut d = Vec3::ZERO;
    d[axis % 3] = if axis < 3 { 1.0 } else { -1.0 };
    Ray::new(o, d)
}

/// The outcome of `tracer` on the ray from `origin` along `direction`,
/// started in the tet that contains `origin` (located from tet 0): a
/// primary ray as a test writes it in one line.
pub fn trace_from(
    tracer: &dyn crate::Tracer,
    origin: Vec3,
    direction: Vec3,
) -> Result<crate::TraceOutcome, crate::LocateError> {
    let start = crate::locate(tracer.mesh(), origin, 0)?;
    Ok(tracer.trace(&Ray::new(origin, direction), crate::Start::Tet(start)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed form against a dense sampling of the segment (each
    /// sample's distance to the line by the cross product).
    #[test]
    fn line_segment_distance_matches_sampling() {
        let mut rng = SplitMix64(7);
        let mut coord = || rng.next_f64() * 4.0 - 2.0;
        for _ in 0..200 {
            let o = DVec3::new(coord(), coord(), coord());
            let d = DVec3::new(coord(), coord(), coord());
            let a = DVec3::new(coord(), coord(), coord());
            // Every tenth segment parallel to the line.
            let b = if coord() > 1.6 {
                a + d * 0.7
            } else {
                DVec3::new(coord(), coord(), coord())
            };
            let sampled = (0..=4000)
                .map(|k| {
                    let p = a + (b - a) * (k as f64 / 4000.0);
                    (p - o).cross(d).length() / d.length()
                })
                .fold(f64::INFINITY, f64::min);
            let exact = line_segment_distance(o, d, a, b);
            assert!(exact <= sampled + 1e-12, "{exact} > {sampled}");
            assert!(
                sampled - exact < 2e-3 * (b - a).length(),
                "{exact} vs {sampled}"
            );
        }
        // A line through a vertex of a triangle, in the triangle's plane.
        let v = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let o = DVec3::new(-1.0, -1.0, 0.0);
        assert!(line_edge_distance(o, DVec3::ONE.with_z(0.0), v) < 1e-15);
        assert!((line_edge_distance(o, DVec3::Z, v) - 2f64.sqrt()).abs() < 1e-12);
    }
}
