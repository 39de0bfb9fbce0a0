//! Rays built to hurt a floating-point walk (`accuracy --adversarial`, the
//! robustness table's batches): aimed exactly at mesh features or started
//! on them, where every decision is a tie to break.

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::synthetic::SplitMix64;
use tet_trace_cpu::ray::Ray;
use tet_trace_cpu::reference::random_direction;
use tet_trace_cpu::walk::Start;

/// `n` rays (`accuracy --adversarial`) aimed at or started on the mesh's
/// features, where a floating-point walk must decide ties: in turn, from a
/// random interior point exactly at a vertex, at a point of an edge, at a
/// point of a face; along an edge (from one vertex of a tet towards
/// another); from a point of a face, and from a vertex, in a random
/// direction; and lying in the triangle's plane (the rays of flat
/// surfaces: CAD caps, walls, floors): from a point of the face, and from
/// a point of the plane a random distance before a point of an edge (the
/// edge point itself where that lies outside the mesh), in a
/// random direction of the plane (exactly in it when the plane is
/// axis-aligned, else up to the direction's f32 rounding). The triangle
/// each ray uses is a scene triangle every other ray and a face of a
/// random tet (a scene triangle or not) otherwise.
/// Points of edges and faces are random combinations rounded to f32 (on
/// the feature up to that rounding). Each ray starts in a tet holding its
/// origin (exact location).
pub fn adversarial_rays(mesh: &TetMesh, n: usize, seed: u64) -> Vec<(Ray, Option<Start>)> {
    let mut rng = SplitMix64(seed ^ 0xad5e_7a71);
    let mut out = Vec::with_capacity(n);
    if mesh.tets.is_empty() {
        return out;
    }
    let (tets, scene) = (mesh.tets.len() as u64, mesh.constrained.len() as u64);
    for k in 0..n {
        let t = (rng.next_u64() % tets) as u32;
        let p = mesh.tet_points(t);
        let (tri, near) = if k % 2 == 0 && scene > 0 {
            let cf = &mesh.constrained[(rng.next_u64() % scene) as usize];
            let near = if cf.front.exists() {
                cf.front.tet
            } else {
                cf.back.tet
            };
            (cf.vertices.map(|v| mesh.points[v as usize]), near)
        } else {
            let f = tet_core::FACE_VERTICES[(rng.next_u64() % 4) as usize];
            (f.map(|s| p[s]), t)
        };
        let (a, b) = (rng.next_f64(), rng.next_f64());
        let on_edge = tri[0].as_dvec3().lerp(tri[1].as_dvec3(), a).as_vec3();
        let (a, b) = if a + b > 1.0 {
            (1.0 - a, 1.0 - b)
        } else {
            (a, b)
        };
        let d = tri.map(|v| v.as_dvec3());
        let on_face = (d[0] + (d[1] - d[0]) * a + (d[2] - d[0]) * b).as_vec3();
        let (origin, dir, hint) = match k % 8 {
            0..=2 => {
                let (o, at) = tet_trace_cpu::reference::random_point_inside(mesh, &mut rng);
                let target = [tri[0], on_edge, on_face][k % 8];
                (o, target - o, at)
            }
            3 => {
                let r = rng.next_u64() as usize;
                let (i, j) = (r % 4, (r % 4 + 1 + r / 4 % 3) % 4);
                (p[i], p[j] - p[i], t)
            }
            4 => (on_face, random_direction(&mut rng), near),
            5 => (tri[0], random_direction(&mut rng), near),
            6 => (on_face, in_plane(&d, &mut rng), near),
            _ => {
                // From a point of the plane before the edge; from the edge
                // itself where that point lies outside the mesh.
                let dir = in_plane(&d, &mut rng);
                let back = (d[1] - d[0]).length().max((d[2] - d[0]).length()) * rng.next_f64();
                let before = on_edge - dir * back as f32;
                let inside = tet_trace_cpu::locate(mesh, before, t).is_ok();
                (if inside { before } else { on_edge }, dir, near)
            }
        };
        if dir == Vec3::ZERO || !dir.is_finite() {
            continue;
        }
        let hint = if hint < mesh.tets.len() as u32 {
            hint
        } else {
            t
        };
        if let Ok(start) = tet_trace_cpu::locate(mesh, origin, hint) {
            out.push((Ray::new(origin, dir), Some(Start::Tet(start))));
        }
    }
    out
}

/// A random unit direction in the plane of triangle `v` (f64, rounded to
/// f32); zero for a degenerate triangle (the ray is then skipped).
fn in_plane(v: &[glam::DVec3; 3], rng: &mut SplitMix64) -> Vec3 {
    let n = (v[1] - v[0]).cross(v[2] - v[0]);
    if n.length_squared() == 0.0 {
        return Vec3::ZERO;
    }
    let n = n.normalize();
    loop {
        let r = random_direction(rng).as_dvec3();
        let d = r - n * r.dot(n);
        if d.length() > 0.1 {
            return d.normalize().as_vec3();
        }
    }
}
