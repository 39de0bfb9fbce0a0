//! Every GPU hit checked against the CPU walk on the same rays: the rays
//! whose outcome differs, each explained or not ([`Differences`]).
//!
//! A ray that grazes an edge may be decided either way: the GPU's camera
//! rays may differ from the CPU's in the last bit, drivers may fuse the
//! projection's sums into FMAs, the Tet80 walk is not watertight (see the
//! `tet-trace-gpu` crate docs, "Where the GPU may differ"). Such a ray hits
//! one triangle near its edge on at least one side: the hit point lies
//! within [`EDGE_TOLERANCE`] of the ray's scale of an edge of its
//! triangle. A difference with no hit near an edge and no failed walk is
//! unexplained.

use std::collections::HashMap;

use glam::DVec3;
use tet_core::TetMesh;
use tet_trace_cpu::{Ray, TraceOutcome};

use super::doc::{Differences, Example, Seen};

/// How near an edge a hit point must lie to explain a difference,
/// relative to the ray's scale (`|origin|∞ + t·|direction|`): about 80
/// f32 rounding units, far more than a last-bit change of the ray or a
/// fused sum moves it, far less than a triangle of the scenes here.
pub const EDGE_TOLERANCE: f64 = 1e-5;

/// Examples kept per row.
const EXAMPLES: usize = 5;

/// What an outcome found.
pub fn seen(o: &TraceOutcome) -> Seen {
    match o {
        TraceOutcome::Hit(h) => Seen::Hit {
            triangle: h.triangle,
            t: h.t,
        },
        TraceOutcome::Miss { .. } => Seen::Miss,
        TraceOutcome::Failed { .. } => Seen::Failed,
    }
}

/// Hits among `found`.
pub fn hits(found: &[Seen]) -> u64 {
    found
        .iter()
        .filter(|s| matches!(s, Seen::Hit { .. }))
        .count() as u64
}

/// The rays whose outcomes differ between `gpu` and `cpu` (same rays, ray
/// `i` given by `ray_of(i)`), classed.
pub fn differences(
    mesh: &TetMesh,
    ray_of: impl Fn(usize) -> Ray,
    gpu: &[Seen],
    cpu: &[Seen],
) -> Differences {
    let mut d = Differences::default();
    let mut faces: Option<HashMap<u32, Vec<u32>>> = None;
    let mut examples = Vec::new();
    for (i, (&g, &c)) in gpu.iter().zip(cpu).enumerate() {
        if same(g, c) {
            continue;
        }
        d.rays += 1;
        let class = if matches!(g, Seen::Failed) || matches!(c, Seen::Failed) {
            d.failed += 1;
            "failed"
        } else {
            let faces = faces.get_or_insert_with(|| faces_of_triangles(mesh));
            let ray = ray_of(i);
            if [g, c].iter().any(|s| near_edge(mesh, faces, &ray, *s)) {
                d.near_edge += 1;
                "near-edge"
            } else {
                d.unexplained += 1;
                "unexplained"
            }
        };
        examples.push(Example {
            ray: i,
            class,
            gpu: g,
            cpu: c,
        });
    }
    // The unexplained first, then in ray order.
    examples.sort_by_key(|e| (e.class != "unexplained", e.ray));
    examples.truncate(EXAMPLES);
    d.examples = examples;
    d
}

/// The same outcome: both miss, both fail, or both hit the same triangle
/// (at any `t`: the GPU computes it in f32, the CPU in f64).
fn same(a: Seen, b: Seen) -> bool {
    match (a, b) {
        (Seen::Hit { triangle: x, .. }, Seen::Hit { triangle: y, .. }) => x == y,
        (Seen::Miss, Seen::Miss) | (Seen::Failed, Seen::Failed) => true,
        _ => false,
    }
}

/// The constrained faces of each scene triangle (a triangle split where
/// others cross it has several).
fn faces_of_triangles(mesh: &TetMesh) -> HashMap<u32, Vec<u32>> {
    let mut map: HashMap<u32, Vec<u32>> = HashMap::new();
    for (i, cf) in mesh.constrained.iter().enumerate() {
        map.entry(cf.triangle).or_default().push(i as u32);
    }
    map
}

/// True when `seen` is a hit whose point on `ray` lies within
/// [`EDGE_TOLERANCE`] of the ray's scale of an edge of one of its
/// triangle's faces.
fn near_edge(mesh: &TetMesh, faces: &HashMap<u32, Vec<u32>>, ray: &Ray, seen: Seen) -> bool {
    let Seen::Hit { triangle, t } = seen else {
        return false;
    };
    let (o, d) = (ray.origin.as_dvec3(), ray.direction.as_dvec3());
    let p = o + d * t as f64;
    let tol = EDGE_TOLERANCE * (o.abs().max_element() + (d * t as f64).length());
    faces.get(&triangle).into_iter().flatten().any(|&f| {
        let v = mesh.constrained[f as usize]
            .vertices
            .map(|i| mesh.points[i as usize].as_dvec3());
        (0..3).any(|k| segment_distance(p, v[k], v[(k + 1) % 3]) <= tol)
    })
}

/// Distance from `p` to the segment `a b`.
fn segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let s = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * s)).length()
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use tet_core::{ConstrainedFace, FaceSide};

    use super::*;

    /// A mesh with one constrained face (triangle 7) in the plane z = 0
    /// (the comparison reads the points and the face table only).
    fn one_face() -> TetMesh {
        TetMesh {
            points: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            constrained: vec![ConstrainedFace {
                triangle: 7,
                vertices: [0, 1, 2],
                front: FaceSide::NONE,
                back: FaceSide::NONE,
            }],
            ..TetMesh::default()
        }
    }

    #[test]
    fn differences_are_classed() {
        let mesh = one_face();
        let cf = mesh.constrained[0];
        let v = cf.vertices.map(|i| mesh.points[i as usize]);
        // A ray straight at the middle of edge v0 v1, and one at the
        // face's centroid, both from 1 unit away along the normal.
        let n = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
        let edge = (v[0] + v[1]) * 0.5;
        let centre = (v[0] + v[1] + v[2]) / 3.0;
        let rays = [Ray::new(edge + n, -n), Ray::new(centre + n, -n)];
        let hit = Seen::Hit {
            triangle: 7,
            t: 1.0,
        };
        let gpu = [Seen::Miss, Seen::Miss, Seen::Failed, hit];
        let cpu = [hit, hit, hit, hit];
        let d = differences(&mesh, |i| rays[i % 2], &gpu, &cpu);
        assert_eq!((d.rays, d.near_edge, d.failed, d.unexplained), (3, 1, 1, 1));
        assert_eq!(d.examples[0].class, "unexplained");
        assert_eq!(d.examples[0].ray, 1);
        assert_eq!(hits(&gpu), 1);
    }

    #[test]
    fn segment_distances() {
        let (a, b) = (DVec3::ZERO, DVec3::X);
        assert_eq!(segment_distance(DVec3::new(0.5, 1.0, 0.0), a, b), 1.0);
        assert_eq!(segment_distance(DVec3::new(2.0, 0.0, 0.0), a, b), 1.0);
        assert_eq!(segment_distance(DVec3::new(3.0, 0.0, 0.0), a, a), 3.0);
    }
}
