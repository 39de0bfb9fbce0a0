//! The facets of a piece in a leaf of the tree (item 3 of [`super`]):
//! its outline subdivided at every point lying on it, triangulated. A
//! triangle inside one leaf is made this way only when its leaf is taken
//! up ([`crate::outofcore::split_parts`]).

use std::borrow::Cow;

use glam::Vec3;

use super::clip::Cut;
use super::geometry::{Lines, Poly, Registry, WallTriangle, outline, triangulate_outline};
use crate::outofcore::error::SeamError;
use crate::outofcore::parts::FacetKind;
use crate::outofcore::split_parts::{PartWalls, WholeTriangle};
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
pub(super) struct TreeWhole<'a> {
    /// The cleaned (and resolved) scene.
    pub(super) scene: Cow<'a, Scene>,
    pub(super) registry: Registry,
    pub(super) lines: Lines,
}

impl WholeTriangle for TreeWhole<'_> {
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

/// A face of a leaf's box: the wall it lies on and its rectangle there.
pub(super) type LeafFace = (usize, Vec3, Vec3);

/// The six faces of leaf `id`'s box, each with the wall it lies on.
pub(super) fn leaf_faces(cut: &Cut, id: usize) -> [LeafFace; 6] {
    let node = &cut.nodes[id];
    std::array::from_fn(|f| {
        let axis = f / 2;
        let value = if f % 2 == 0 { node.lo } else { node.hi }[axis];
        let (mut flo, mut fhi) = (node.lo, node.hi);
        flo[axis] = value;
        fhi[axis] = value;
        let wall = cut
            .walls
            .iter()
            .position(|w| {
                w.plane.axis == axis
                    && w.plane.value == value
                    && (0..3).all(|a| w.lo[a] <= flo[a] && fhi[a] <= w.hi[a])
            })
            .expect("every leaf face lies on a seam or on the enclosing box");
        (wall, flo, fhi)
    })
}

/// The wall triangles on each leaf's faces, picked from the walls when
/// the leaf is taken up: every wall's triangulation is held once, where
/// every leaf's own copies held each of them twice (once per side), 16
/// bytes per scene triangle of a planner's memory at 3 M triangles.
pub(super) struct LeafWalls {
    /// Each wall's triangles.
    walls: Vec<Vec<WallTriangle>>,
    /// Each leaf's faces.
    faces: Vec<[LeafFace; 6]>,
    /// Each leaf's wall triangles, counted.
    counts: Vec<usize>,
}

impl LeafWalls {
    pub(super) fn new(walls: Vec<Vec<WallTriangle>>, faces: Vec<[LeafFace; 6]>) -> LeafWalls {
        let mut lw = LeafWalls {
            walls,
            faces,
            counts: Vec::new(),
        };
        lw.counts = (0..lw.faces.len())
            .map(|k| lw.on_faces(k).count())
            .collect();
        lw
    }

    /// Leaf `k`'s wall triangles: those of the walls its faces lie on
    /// that lie inside the faces.
    fn on_faces(&self, k: usize) -> impl Iterator<Item = &WallTriangle> + '_ {
        self.faces[k].iter().flat_map(move |&(w, flo, fhi)| {
            self.walls[w].iter().filter(move |(t, _)| {
                t.iter()
                    .all(|p| (0..3).all(|a| p[a] >= flo[a] && p[a] <= fhi[a]))
            })
        })
    }
}

impl PartWalls for LeafWalls {
    fn count(&self, k: usize) -> usize {
        self.counts[k]
    }

    fn of(&self, k: usize) -> Vec<([Vec3; 3], FacetKind)> {
        self.on_faces(k)
            .map(|(t, s)| (*t, s.map_or(FacetKind::Seam, FacetKind::Scene)))
            .collect()
    }
}
