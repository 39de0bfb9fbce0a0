//! The parts of a split, made when a part is taken up: what the cut made
//! ahead for a part (the pieces of the triangles the planes cut, and the
//! seam or wall triangles on its faces) is kept, a small share of the
//! scene; the triangles lying inside the part are added from the scene
//! itself when the part is written or built. A planner or a local build so
//! holds the scene once, and one part's facets at a time per worker, never
//! every part's facets at once.

use glam::Vec3;

use super::error::SeamError;
use super::parts::{FacetKind, PartFacetList, PartFacets};

/// The scene triangles lying inside each part, in scene order (compressed
/// rows: part `k`'s are `ids[starts[k]..starts[k + 1]]`).
pub(super) struct PartTriangles {
    starts: Vec<usize>,
    ids: Vec<u32>,
}

impl PartTriangles {
    /// From each triangle's part (`None`: it is not inside one part).
    pub(super) fn new(
        parts: usize,
        part_of: impl Fn(usize) -> Option<usize>,
        triangles: usize,
    ) -> Self {
        let mut starts = vec![0usize; parts + 1];
        for t in 0..triangles {
            if let Some(k) = part_of(t) {
                starts[k + 1] += 1;
            }
        }
        for k in 0..parts {
            starts[k + 1] += starts[k];
        }
        let mut next = starts.clone();
        let mut ids = vec![0u32; starts[parts]];
        for t in 0..triangles {
            if let Some(k) = part_of(t) {
                ids[next[k]] = t as u32;
                next[k] += 1;
            }
        }
        PartTriangles { starts, ids }
    }

    /// Part `k`'s triangles.
    pub(super) fn of(&self, k: usize) -> &[u32] {
        &self.ids[self.starts[k]..self.starts[k + 1]]
    }
}

/// The facets of a scene triangle lying inside one part (the triangle, or
/// its outline subdivided at points lying on it).
pub(super) trait WholeTriangle: Send + Sync {
    /// The facets of cleaned scene triangle `t`, wound like it.
    fn facets(&self, t: u32) -> Result<Vec<[Vec3; 3]>, SeamError>;
}

/// The seam (or wall) triangles on each part's faces.
pub(super) trait PartWalls: Send + Sync {
    /// How many of them part `k` has.
    fn count(&self, k: usize) -> usize;
    /// Part `k`'s.
    fn of(&self, k: usize) -> Vec<([Vec3; 3], FacetKind)>;
}

/// Every part's wall triangles, made ahead (the slabs': a slab's two
/// seams only).
impl PartWalls for Vec<Vec<([Vec3; 3], FacetKind)>> {
    fn count(&self, k: usize) -> usize {
        self[k].len()
    }
    fn of(&self, k: usize) -> Vec<([Vec3; 3], FacetKind)> {
        self[k].clone()
    }
}

/// The parts of a split (see the module docs).
pub(super) struct SplitParts<W, L> {
    /// Makes the facets of the triangles inside a part.
    pub(super) whole: W,
    /// The triangles inside each part.
    pub(super) inside: PartTriangles,
    /// Per part: the pieces the cut made, each with its cleaned scene
    /// triangle (in scene order) and triangulation.
    pub(super) clipped: Vec<Vec<(u32, Vec<[Vec3; 3]>)>>,
    /// Per part: the seam (or wall) triangles on its faces.
    pub(super) walls: L,
    /// Per part: its box faces (unmarked facets).
    pub(super) box_faces: Vec<Vec<[Vec3; 3]>>,
}

impl<W: WholeTriangle, L: PartWalls> PartFacets for SplitParts<W, L> {
    fn len(&self) -> usize {
        self.box_faces.len()
    }

    fn size(&self, k: usize) -> usize {
        let clipped: usize = self.clipped[k].iter().map(|(_, f)| f.len()).sum();
        self.inside.of(k).len() + clipped + self.walls.count(k) + self.box_faces[k].len()
    }

    /// The scene pieces in scene order (the part's own triangles and the
    /// clipped pieces merged), then the seam or wall triangles.
    fn facets(&self, k: usize) -> Result<PartFacetList, SeamError> {
        let mut facets = Vec::with_capacity(self.size(k));
        let (mut inside, mut clipped) = (
            self.inside.of(k).iter().peekable(),
            self.clipped[k].iter().peekable(),
        );
        loop {
            let whole_first = match (inside.peek(), clipped.peek()) {
                (Some(&&t), Some((s, _))) => t < *s,
                (Some(_), None) => true,
                (None, Some(_)) => false,
                (None, None) => break,
            };
            if whole_first {
                let Some(&t) = inside.next() else { break };
                let tris = self.whole.facets(t)?;
                facets.extend(tris.into_iter().map(|f| (f, FacetKind::Scene(t))));
            } else if let Some((s, tris)) = clipped.next() {
                facets.extend(tris.iter().map(|&f| (f, FacetKind::Scene(*s))));
            }
        }
        facets.extend(self.walls.of(k));
        Ok(PartFacetList {
            facets,
            box_faces: self.box_faces[k].clone(),
        })
    }
}
