//! The facets of a piece in a leaf of the tree (item 3 of [`super`]):
//! its outline subdivided at every point lying on it, triangulated. A
//! triangle inside one leaf is made this way only when its leaf is taken
//! up ([`crate::outofcore::split_parts`]).

use glam::Vec3;

use super::geometry::{Lines, Poly, Registry, outline, triangulate_outline};
use crate::outofcore::error::SeamError;
use crate::outofcore::split_parts::WholeTriangle;
use crate::scene::Scene;

/// The triangles of a piece's outline (subdivided at every point on it),
/// wound like its scene triangle.
pub(super) fn piece_facets(
    poly: &Poly,
    scene: &Scene,
    registry: &Registry,
    lines: &Lines,
) -> Result<Vec<[Vec3; 3]>, SeamError> {
    let l = outline(registry, lines, poly)?;
    let t = scene.triangles[poly.source as usize].map(|v| scene.vertices[v as usize]);
    let normal = (t[1] - t[0]).as_dvec3().cross((t[2] - t[0]).as_dvec3());
    triangulate_outline(&l, normal, poly.source)
}

/// What a triangle inside one leaf is made from: the cleaned scene, and
/// the points lying on segments (a scene vertex may lie on another
/// triangle's axis-parallel edge).
pub(super) struct TreeWhole {
    /// The cleaned (and resolved) scene.
    pub(super) scene: Scene,
    pub(super) registry: Registry,
    pub(super) lines: Lines,
}

impl WholeTriangle for TreeWhole {
    fn facets(&self, t: u32) -> Result<Vec<[Vec3; 3]>, SeamError> {
        let v = self.scene.triangles[t as usize].map(|i| self.scene.vertices[i as usize]);
        piece_facets(
            &Poly::triangle(v, t),
            &self.scene,
            &self.registry,
            &self.lines,
        )
    }
}
