//! Point location (Aman et al. §4.2): find the tet containing a point (the
//! camera, a light, a ray origin) by walking from a source tet.
//!
//! The walk is the *visibility walk*: in tet `t`, if the point lies strictly
//! outside face `k` (exact [`tet_core::predicates::orient3d`] `> 0` against
//! the outward face), step to the tet across face `k`. Constrained faces are
//! crossed too (through the constrained-face table), so a point in a region
//! cut off by scene triangles is found. The first face tested rotates with the
//! step count, which breaks the cycles a visibility walk can enter in a
//! non-Delaunay mesh; a step cap plus an exhaustive exact scan backs the walk
//! up, so the answer is always exact: the returned tet contains the point
//! (closed tet: the point may lie on a face, an edge or a vertex).

use glam::Vec3;
use tet_core::predicates::orient3d;
use tet_core::{FACE_VERTICES, TetMesh};
use thiserror::Error;

/// Why a point could not be located.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum LocateError {
    /// The mesh has no tets.
    #[error("the mesh has no tets")]
    EmptyMesh,
    /// The point has a NaN or infinite coordinate.
    #[error("point {point:?} has a non-finite coordinate")]
    NonFinite {
        /// The point.
        point: Vec3,
    },
    /// No tet contains the point.
    #[error("point {point:?} lies outside the mesh")]
    OutsideMesh {
        /// The point.
        point: Vec3,
    },
    /// The source tet does not exist.
    #[error("source tet {tet} is out of bounds ({tets} tets)")]
    BadSource {
        /// The source tet given.
        tet: u32,
        /// Number of tets.
        tets: usize,
    },
}

/// True when the closed tet `tet` contains `p` (exact).
pub fn tet_contains(mesh: &TetMesh, tet: u32, p: Vec3) -> bool {
    let q = p.as_dvec3();
    let v = mesh.tet_points(tet).map(|x| x.as_dvec3());
    FACE_VERTICES
        .iter()
        .all(|s| orient3d(v[s[0]], v[s[1]], v[s[2]], q) <= 0.0)
}

/// Finds a tet containing `p`, walking from `source`.
///
/// Exact: on success the closed tet contains `p`. Errors when `p` is outside
/// every tet, non-finite, or `source` is out of bounds.
pub fn locate(mesh: &TetMesh, p: Vec3, source: u32) -> Result<u32, LocateError> {
    if mesh.tets.is_empty() {
        return Err(LocateError::EmptyMesh);
    }
    if !p.is_finite() {
        return Err(LocateError::NonFinite { point: p });
    }
    if source as usize >= mesh.tets.len() {
        return Err(LocateError::BadSource {
            tet: source,
            tets: mesh.tets.len(),
        });
    }
    if let Some(t) = visibility_walk(mesh, p, source, 4 * mesh.tets.len() + 64) {
        return Ok(t);
    }
    // The boundary or the step cap: outside a convex mesh, but a non-convex
    // one may still hold the point elsewhere: scan, unless the point lies
    // beyond the bounds of the mesh points, in no tet (a camera or light
    // outside a tight enclosing box, every frame).
    let (lo, hi) = mesh.point_bounds();
    if p.cmplt(lo).any() || p.cmpgt(hi).any() {
        return Err(LocateError::OutsideMesh { point: p });
    }
    scan(mesh, p)
}

/// [`locate`]'s visibility walk alone, at most `max_steps` steps: a tet
/// containing `p` (exact), or `None` when the walk reaches the mesh
/// boundary or the cap (no exhaustive search: for callers with a fallback
/// of their own, such as a walk that may start nearer its target).
pub fn locate_near(mesh: &TetMesh, p: Vec3, source: u32, max_steps: usize) -> Option<u32> {
    if !p.is_finite() || source as usize >= mesh.tets.len() {
        return None;
    }
    visibility_walk(mesh, p, source, max_steps)
}

/// The visibility walk from `source` (module docs).
fn visibility_walk(mesh: &TetMesh, p: Vec3, source: u32, cap: usize) -> Option<u32> {
    let q = p.as_dvec3();
    let mut tet = source;
    'walk: for step in 0..cap {
        let v = mesh.tet_points(tet).map(|x| x.as_dvec3());
        for i in 0..4 {
            let k = (i + step) & 3;
            let s = FACE_VERTICES[k];
            if orient3d(v[s[0]], v[s[1]], v[s[2]], q) > 0.0 {
                match mesh.across(tet, k) {
                    Some(side) => {
                        tet = side.tet;
                        continue 'walk;
                    }
                    None => return None,
                }
            }
        }
        return Some(tet);
    }
    None
}

/// Exhaustive exact search (the walk's fallback, also usable alone).
pub fn scan(mesh: &TetMesh, p: Vec3) -> Result<u32, LocateError> {
    if !p.is_finite() {
        return Err(LocateError::NonFinite { point: p });
    }
    (0..mesh.tets.len() as u32)
        .find(|&t| tet_contains(mesh, t, p))
        .ok_or(LocateError::OutsideMesh { point: p })
}

/// Every tet whose closed cell contains `p`, found from `start` (which must
/// contain `p`) by crossing faces that contain `p` (exact). Used to restart a
/// ray whose origin lies on a face, edge or vertex. At most `limit` tets.
pub fn star(mesh: &TetMesh, p: Vec3, start: u32, limit: usize) -> Vec<u32> {
    let q = p.as_dvec3();
    let mut out = vec![start];
    let mut i = 0;
    while i < out.len() && out.len() < limit {
        let t = out[i];
        i += 1;
        let v = mesh.tet_points(t).map(|x| x.as_dvec3());
        for (k, s) in FACE_VERTICES.iter().enumerate() {
            if orient3d(v[s[0]], v[s[1]], v[s[2]], q) == 0.0
                && let Some(side) = mesh.across(t, k)
                && !out.contains(&side.tet)
                && tet_contains(mesh, side.tet, p)
            {
                out.push(side.tet);
            }
        }
    }
    out
}
