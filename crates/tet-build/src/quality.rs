//! Tetrahedron quality metrics, in f64, as reported by Erkoç et al. (2021,
//! Table 3).
//!
//! | paper              | code                           | definition                                   |
//! |--------------------|--------------------------------|----------------------------------------------|
//! | aspect ratio       | [`aspect_ratio`]               | longest edge / smallest height               |
//! | radius-edge ratio  | [`radius_edge_ratio`]          | circumradius / shortest edge                 |
//! | min / max / mean   | [`Stats`]                      | over all tets of a mesh ([`mesh_quality`])  |
//!
//! The smallest height of a tet is `3V / A_max` (volume over the largest face
//! area). For the regular tetrahedron the aspect ratio is `sqrt(3/2)` and the
//! radius-edge ratio `sqrt(6)/4`, the minima of both measures. A flat tet
//! (zero volume) has both ratios infinite.

use glam::DVec3;
use tet_core::TetMesh;

/// Longest edge over smallest height (∞ for a flat tet).
pub fn aspect_ratio(p: [DVec3; 4]) -> f64 {
    let volume6 = (p[1] - p[0]).cross(p[2] - p[0]).dot(p[3] - p[0]).abs();
    if volume6 == 0.0 {
        return f64::INFINITY;
    }
    let longest = edges(p).into_iter().fold(0.0f64, f64::max);
    // Twice the face areas: |cross| of two edges of each face.
    let faces = [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]];
    let max_area2 = faces
        .iter()
        .map(|f| (p[f[1]] - p[f[0]]).cross(p[f[2]] - p[f[0]]).length())
        .fold(0.0f64, f64::max);
    // height = 3V / A = (volume6 / 2) / (max_area2 / 2) = volume6 / max_area2.
    let min_height = volume6 / max_area2;
    longest / min_height
}

/// Circumradius over shortest edge (∞ for a flat tet).
pub fn radius_edge_ratio(p: [DVec3; 4]) -> f64 {
    let a = p[1] - p[0];
    let b = p[2] - p[0];
    let c = p[3] - p[0];
    let det = a.dot(b.cross(c));
    if det == 0.0 {
        return f64::INFINITY;
    }
    let center = (a.length_squared() * b.cross(c)
        + b.length_squared() * c.cross(a)
        + c.length_squared() * a.cross(b))
        / (2.0 * det);
    let radius = center.length();
    let shortest = edges(p).into_iter().fold(f64::INFINITY, f64::min);
    radius / shortest
}

fn edges(p: [DVec3; 4]) -> [f64; 6] {
    [
        p[0].distance(p[1]),
        p[0].distance(p[2]),
        p[0].distance(p[3]),
        p[1].distance(p[2]),
        p[1].distance(p[3]),
        p[2].distance(p[3]),
    ]
}

/// Minimum, maximum and mean of a metric over a set of tets.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stats {
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// Arithmetic mean.
    pub mean: f64,
}

impl Stats {
    /// Statistics of `values` (`None` when empty).
    pub fn of(values: impl IntoIterator<Item = f64>) -> Option<Stats> {
        let mut n = 0usize;
        let mut sum = 0.0;
        let mut min = f64::INFINITY;
        let mut max = f64::NEG_INFINITY;
        for v in values {
            n += 1;
            sum += v;
            min = min.min(v);
            max = max.max(v);
        }
        (n > 0).then(|| Stats {
            min,
            max,
            mean: sum / n as f64,
        })
    }
}

/// Quality of a whole mesh (Erkoç et al. Table 3 columns).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QualityReport {
    /// Number of tets measured.
    pub tets: usize,
    /// Aspect ratio statistics.
    pub aspect_ratio: Stats,
    /// Radius-edge ratio statistics.
    pub radius_edge: Stats,
}

/// Measures every tet of `mesh` (`None` for a mesh without tets).
pub fn mesh_quality(mesh: &TetMesh) -> Option<QualityReport> {
    let corners = |t: usize| mesh.tet_points(t as u32).map(|v| v.as_dvec3());
    let n = mesh.tets.len();
    Some(QualityReport {
        tets: n,
        aspect_ratio: Stats::of((0..n).map(|t| aspect_ratio(corners(t))))?,
        radius_edge: Stats::of((0..n).map(|t| radius_edge_ratio(corners(t))))?,
    })
}
