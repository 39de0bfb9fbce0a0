//! The boundary face a ray from outside enters the volume through, found
//! with a small BVH over the boundary faces.
//!
//! [`crate::entry::BoundaryEntry`] scans the faces a viewpoint sees, which
//! suits a tight enclosing box (a dozen faces) but not a volume mesh, whose
//! boundary has thousands. Here the faces sit in a median-split BVH; a face
//! is entered when the walk's own edge test ([`DuffF32`], with its tie
//! rule) finds its inward-ordered projection counter-clockwise around the
//! ray and the origin lies on or outside its plane (exact `orient3d`), the
//! same decision as `BoundaryEntry`, so entry and walk agree on every
//! boundary edge. The face the previous ray entered is tested first.

use glam::Vec3;
use tet_core::predicates::orient3d_f32;
use tet_core::{Link, TetMesh};

use super::marching::RayPre;
use crate::walk::{DuffF32, EntryHint, Projection, Start};

/// Faces per leaf.
const LEAF: usize = 4;

#[derive(Clone, Copy, Debug)]
struct Face {
    tet: u32,
    face: u8,
    /// Inward (counter-clockwise seen by an entering ray) vertex order.
    ids: [u32; 3],
}

#[derive(Clone, Copy, Debug)]
struct Node {
    lo: Vec3,
    hi: Vec3,
    /// Inner: right child; leaf: first face.
    index: u32,
    /// Leaf: face count; inner: 0.
    count: u32,
}

/// The boundary faces of a mesh in a BVH.
#[derive(Clone, Debug)]
pub(crate) struct Hull {
    faces: Vec<Face>,
    nodes: Vec<Node>,
}

impl Hull {
    /// Every face of `mesh` linked to [`Link::BOUNDARY`].
    pub(crate) fn new(mesh: &TetMesh) -> Hull {
        let mut faces = Vec::new();
        for (t, links) in mesh.neighbors.iter().enumerate() {
            for (k, &l) in links.iter().enumerate() {
                if l == Link::BOUNDARY {
                    let [a, b, c] = mesh.face_vertices(t as u32, k);
                    faces.push(Face {
                        tet: t as u32,
                        face: k as u8,
                        ids: [a, c, b],
                    });
                }
            }
        }
        let mut hull = Hull {
            faces,
            nodes: Vec::new(),
        };
        if !hull.faces.is_empty() {
            let n = hull.faces.len();
            let mut faces = std::mem::take(&mut hull.faces);
            build(mesh, &mut faces, 0, &mut hull.nodes);
            debug_assert_eq!(faces.len(), n);
            hull.faces = faces;
        }
        hull
    }

    /// Bytes of the structure.
    pub(crate) fn bytes(&self) -> usize {
        std::mem::size_of_val(&self.faces[..]) + std::mem::size_of_val(&self.nodes[..])
    }

    /// The walk start of `ray` (origin outside the mesh) where its line
    /// enters ahead of the origin, or `None` when it never enters.
    pub(crate) fn start(
        &self,
        mesh: &TetMesh,
        pre: &RayPre,
        hint: &mut EntryHint,
    ) -> Option<Start> {
        let enters = |f: &Face| {
            let p = f.ids.map(|i| pre.proj.project(mesh.points[i as usize]));
            let proj: &DuffF32 = &pre.proj;
            proj.left(p[0], f.ids[0], p[1], f.ids[1])
                && proj.left(p[1], f.ids[1], p[2], f.ids[2])
                && proj.left(p[2], f.ids[2], p[0], f.ids[0])
                && {
                    let [a, b, c] = mesh.face_vertices(f.tet, f.face as usize);
                    let q = |i: u32| mesh.points[i as usize];
                    orient3d_f32(q(a), q(b), q(c), pre.ray.origin) >= 0.0
                }
        };
        let start = |f: &Face| Start::Entry {
            tet: f.tet,
            face: f.face,
        };
        if let Some(f) = self.faces.get(hint.0)
            && enters(f)
        {
            return Some(start(f));
        }
        if self.nodes.is_empty() {
            return None;
        }
        let mut stack = [0u32; 64];
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            let i = stack[sp] as usize;
            let n = &self.nodes[i];
            let (t0, t1) = pre.slab(n.lo, n.hi);
            if !(t0 <= t1 && t1 >= 0.0) {
                continue;
            }
            if n.count > 0 {
                let range = n.index as usize..(n.index + n.count) as usize;
                for j in range {
                    if enters(&self.faces[j]) {
                        hint.0 = j;
                        return Some(start(&self.faces[j]));
                    }
                }
            } else if sp + 2 <= stack.len() {
                stack[sp] = n.index;
                stack[sp + 1] = i as u32 + 1;
                sp += 2;
            } else {
                // Deeper than any median-split tree of < 2⁶² faces.
                break;
            }
        }
        None
    }
}

/// Median-split build over `faces` (global offset `first`); bounds padded by
/// a relative 2⁻¹⁸ so that rounding never drops the face a ray enters.
fn build(mesh: &TetMesh, faces: &mut [Face], first: usize, nodes: &mut Vec<Node>) {
    let pts = |f: &Face| f.ids.map(|i| mesh.points[i as usize]);
    let (lo, hi) = faces
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), f| {
            let p = pts(f);
            (
                lo.min(p[0].min(p[1]).min(p[2])),
                hi.max(p[0].max(p[1]).max(p[2])),
            )
        });
    let pad = lo.abs().max(hi.abs()) * (1.0 / 262_144.0) + Vec3::splat(1e-30);
    let me = nodes.len();
    nodes.push(Node {
        lo: lo - pad,
        hi: hi + pad,
        index: first as u32,
        count: faces.len() as u32,
    });
    if faces.len() <= LEAF {
        return;
    }
    let axis = (hi - lo).max_position();
    let mid = faces.len() / 2;
    let key = |f: &Face| {
        let p = pts(f);
        p[0][axis] + p[1][axis] + p[2][axis]
    };
    faces.select_nth_unstable_by(mid, |a, b| key(a).total_cmp(&key(b)));
    let (l, r) = faces.split_at_mut(mid);
    build(mesh, l, first, nodes);
    let right = nodes.len();
    build(mesh, r, first + mid, nodes);
    nodes[me].index = right as u32;
    nodes[me].count = 0;
}
