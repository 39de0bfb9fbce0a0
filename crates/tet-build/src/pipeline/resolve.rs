//! Stage 1b, resolve: a cleaned scene whose triangles cross, touch in
//! their interiors or overlap becomes one whose triangles meet only in
//! shared vertices and edges ([`crate::resolve`]), so that TetGen can
//! preserve it.
//!
//! Each piece keeps the *input* id of the triangle it came from, so a hit
//! names the user's triangle exactly as in a clean scene. The scene's
//! vertices stay first and unchanged; added points (on intersection curves
//! and split edges) follow them, with per-vertex normals and texture
//! coordinates interpolated in the parent triangle. A point shared by
//! pieces of parents whose interpolated normals disagree (a point on the
//! curve where two surfaces cross) has no single shading normal and gets a
//! zero normal, as a merged crease vertex does: such triangles are shaded
//! with their geometric normal. A scene that needs nothing goes through
//! untouched.

use std::borrow::Cow;

use glam::{DVec3, Vec2, Vec3};

use super::error::BuildError;
use super::prepare::Cleaned;
use crate::clean::CleanMesh;
use crate::clean::REMOVED;
use crate::resolve::{ResolveError, ResolveOptions, ResolveReport, Resolved, resolve};
use crate::scene::{Scene, SceneObject};

/// Resolves the self-intersections of `cleaned` (output: the scene to
/// tetrahedralize, with its maps back to the input, and what was done).
pub(super) fn resolve_scene(
    cleaned: Cleaned,
    options: &ResolveOptions,
) -> Result<(Cleaned, ResolveReport), BuildError> {
    let Cleaned { scene, map } = cleaned;
    let (scene, map, report) = resolve_cleaned(scene, map, options).map_err(BuildError::Resolve)?;
    Ok((Cleaned { scene, map }, report))
}

/// Resolves the self-intersections of a cleaned scene and its map back to
/// the input (the in-core stage, and the out-of-core builders before they
/// split the scene): the resolved scene, its map (pieces name their input
/// triangle) and what was done. Errors name input triangles.
pub(crate) fn resolve_cleaned(
    scene: Scene,
    map: CleanMesh,
    options: &ResolveOptions,
) -> Result<(Scene, CleanMesh, ResolveReport), ResolveError> {
    // The exact arithmetic wants coordinates of moderate size: resolve in
    // a frame scaled by a power of two (exact both ways, checked), so that
    // the scene's scale does not matter.
    let scale = unit_scale(&scene.vertices);
    let vertices: Cow<'_, [Vec3]> = if scale == 1.0 {
        Cow::Borrowed(&scene.vertices)
    } else {
        Cow::Owned(scene.vertices.iter().map(|&v| v * scale).collect())
    };
    let mut resolved = resolve(&vertices, &scene.triangles, options)
        .map_err(|e| name_input_triangles(e, &map.triangle_source))?;
    if scale != 1.0 {
        let n = scene.vertices.len();
        resolved.vertices[..n].copy_from_slice(&scene.vertices);
        for v in &mut resolved.vertices[n..] {
            *v /= scale;
        }
    }
    let report = resolved.report.clone();
    if unchanged(&resolved, &scene) {
        return Ok((scene, map, report));
    }
    let Cleaned { scene, map } = rebuild(Cleaned { scene, map }, resolved);
    Ok((scene, map, report))
}

/// A power of two that brings the largest coordinate magnitude near 1,
/// when that scaling is exact for every coordinate (no underflow into
/// subnormals, no overflow); 1 otherwise.
fn unit_scale(vertices: &[Vec3]) -> f32 {
    let largest = vertices
        .iter()
        .map(|v| v.abs().max_element())
        .fold(0.0f32, f32::max);
    if !(largest.is_finite() && largest > 0.0) || (1e-8..=1e8).contains(&largest) {
        return 1.0;
    }
    let k = ((largest as f64).log2().ceil() as i32).clamp(-126, 126);
    let scale = (2.0f64).powi(-k) as f32;
    // A power of two scales exactly unless a coordinate falls into the
    // subnormals (or out of range): the round trip says so.
    let exact = vertices.iter().all(|&v| {
        let s = v * scale;
        s.is_finite() && s / scale == v
    });
    if exact { scale } else { 1.0 }
}

/// True when the resolved soup is the cleaned scene itself.
fn unchanged(r: &Resolved, scene: &Scene) -> bool {
    r.vertices.len() == scene.vertices.len()
        && r.triangles == scene.triangles
        && r.parent.iter().enumerate().all(|(i, &p)| p as usize == i)
}

/// The error with cleaned triangle ids replaced by input triangle ids.
fn name_input_triangles(e: ResolveError, source: &[u32]) -> ResolveError {
    let input = |t: u32| source.get(t as usize).copied().unwrap_or(t);
    match e {
        ResolveError::NotConverged {
            rounds,
            pairs,
            total,
        } => ResolveError::NotConverged {
            rounds,
            pairs: pairs
                .into_iter()
                .map(|(a, b)| (input(a), input(b)))
                .collect(),
            total,
        },
        other => other,
    }
}

/// The cleaned scene with its triangles replaced by the pieces (ordered by
/// parent, so every object keeps a contiguous triangle range) and the
/// added points' attributes interpolated.
fn rebuild(cleaned: Cleaned, resolved: Resolved) -> Cleaned {
    let Cleaned { scene, mut map } = cleaned;
    let mut order: Vec<usize> = (0..resolved.triangles.len()).collect();
    order.sort_by_key(|&i| resolved.parent[i]);
    let triangles: Vec<[u32; 3]> = order.iter().map(|&i| resolved.triangles[i]).collect();
    let parent: Vec<u32> = order.iter().map(|&i| resolved.parent[i]).collect();

    let first_added = scene.vertices.len();
    let added = Added::new(&resolved.vertices, &triangles, &parent, first_added);
    let normals = scene.normals.as_ref().map(|n| {
        let mut out = n.clone();
        out.extend(added.normals(&scene, n));
        out
    });
    let uvs = scene.uvs.as_ref().map(|uv| {
        let mut out = uv.clone();
        out.extend(added.uvs(&scene, uv));
        out
    });
    let objects = scene
        .objects
        .iter()
        .map(|o| {
            let first = parent.partition_point(|&p| p < o.first_triangle);
            let end = parent.partition_point(|&p| p < o.first_triangle + o.triangle_count);
            SceneObject {
                first_triangle: first as u32,
                triangle_count: (end - first) as u32,
                ..o.clone()
            }
        })
        .collect();

    map.triangle_source = parent
        .iter()
        .map(|&p| map.triangle_source[p as usize])
        .collect();
    map.vertex_source.resize(resolved.vertices.len(), REMOVED);
    let scene = Scene {
        vertices: resolved.vertices,
        triangles,
        normals,
        uvs,
        objects,
        ..scene
    };
    Cleaned { scene, map }
}

/// The added points and, for each, the pieces' parents it lies in.
struct Added {
    /// Per added point: its position and the parents (cleaned triangle ids)
    /// of the pieces that use it.
    points: Vec<(Vec3, Vec<u32>)>,
}

impl Added {
    fn new(vertices: &[Vec3], pieces: &[[u32; 3]], parent: &[u32], first: usize) -> Added {
        let mut points: Vec<(Vec3, Vec<u32>)> =
            vertices[first..].iter().map(|&p| (p, Vec::new())).collect();
        for (piece, &p) in pieces.iter().zip(parent) {
            for &v in piece {
                if let Some(slot) = (v as usize).checked_sub(first) {
                    let parents = &mut points[slot].1;
                    if !parents.contains(&p) {
                        parents.push(p);
                    }
                }
            }
        }
        Added { points }
    }

    /// Per added point, the normal interpolated in its parents, or zero
    /// where they disagree (a crossing curve).
    fn normals<'a>(&'a self, scene: &'a Scene, n: &'a [Vec3]) -> impl Iterator<Item = Vec3> + 'a {
        self.points.iter().map(move |(p, parents)| {
            let mut candidates = parents.iter().map(|&t| {
                let tri = scene.triangles[t as usize];
                let w = barycentric(*p, tri.map(|v| scene.vertices[v as usize]));
                (n[tri[0] as usize] * w[0] + n[tri[1] as usize] * w[1] + n[tri[2] as usize] * w[2])
                    .normalize_or_zero()
            });
            let Some(first) = candidates.next() else {
                return Vec3::ZERO;
            };
            if candidates.all(|c| c.dot(first) > 1.0 - 1e-5) {
                first
            } else {
                Vec3::ZERO
            }
        })
    }

    /// Per added point, the texture coordinates interpolated in its first
    /// parent.
    fn uvs<'a>(&'a self, scene: &'a Scene, uv: &'a [Vec2]) -> impl Iterator<Item = Vec2> + 'a {
        self.points.iter().map(move |(p, parents)| {
            parents.first().map_or(Vec2::ZERO, |&t| {
                let tri = scene.triangles[t as usize];
                let w = barycentric(*p, tri.map(|v| scene.vertices[v as usize]));
                uv[tri[0] as usize] * w[0] + uv[tri[1] as usize] * w[1] + uv[tri[2] as usize] * w[2]
            })
        })
    }
}

/// Barycentric weights of `p`'s projection onto the plane of `t`, clamped
/// to the triangle (added points lie in their parent up to f32 rounding).
fn barycentric(p: Vec3, t: [Vec3; 3]) -> [f32; 3] {
    let [a, b, c] = t.map(|v| v.as_dvec3());
    let (e1, e2, q) = (b - a, c - a, p.as_dvec3() - a);
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (q1, q2) = (q.dot(e1), q.dot(e2));
    let det = d11 * d22 - d12 * d12;
    if det <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let v = ((d22 * q1 - d12 * q2) / det).max(0.0);
    let w = ((d11 * q2 - d12 * q1) / det).max(0.0);
    let u = (1.0 - v - w).max(0.0);
    let s = u + v + w;
    let w3 = DVec3::new(u, v, w) / s;
    [w3.x as f32, w3.y as f32, w3.z as f32]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_resolve_frame_is_an_exact_power_of_two() {
        let at = |x: f32| {
            vec![
                Vec3::new(x, -0.75 * x, 0.0),
                Vec3::new(0.5 * x, x, 0.25 * x),
            ]
        };
        // Moderate scenes are left alone.
        assert_eq!(unit_scale(&at(3.0)), 1.0);
        for x in [1e30f32, 1e-30, 3e38, 1e20] {
            let v = at(x);
            let s = unit_scale(&v);
            assert!(s != 1.0 && s.log2().fract() == 0.0, "{x}: {s}");
            let largest = v
                .iter()
                .map(|p| (*p * s).abs().max_element())
                .fold(0.0, f32::max);
            assert!((0.5..=4.0).contains(&largest), "{x}: {largest}");
            assert!(v.iter().all(|&p| (p * s) / s == p));
        }
        // A tiny coordinate that would fall into the subnormals: no scaling.
        let v = vec![Vec3::new(1e30, 1e-30, 0.0)];
        assert_eq!(unit_scale(&v), 1.0);
    }

    #[test]
    fn barycentric_weights_reproduce_the_point() {
        let t = [
            Vec3::ZERO,
            Vec3::new(4.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        ];
        let p = Vec3::new(1.0, 0.5, 0.0);
        let w = barycentric(p, t);
        let back = t[0] * w[0] + t[1] * w[1] + t[2] * w[2];
        assert!((back - p).length() < 1e-6, "{back:?}");
        // A point off the plane projects onto it.
        let w_off = barycentric(p + Vec3::Z, t);
        assert_eq!(w, w_off);
        // Outside the triangle: clamped weights still sum to one.
        let w_out = barycentric(Vec3::new(-1.0, -1.0, 0.0), t);
        assert!((w_out.iter().sum::<f32>() - 1.0).abs() < 1e-6 && w_out.iter().all(|&x| x >= 0.0));
    }
}
