//! The boundary face a ray from outside enters the volume through, found
//! with a small BVH over the boundary faces.
//!
//! [`crate::boundary_entry::BoundaryEntry`] scans the faces a viewpoint sees, which
//! suits a tight enclosing box (a dozen faces) but not a volume mesh, whose
//! boundary has thousands. Here the faces sit in a median-split BVH; a face
//! is entered when the walk's own edge test ([`DuffF32`], with its tie
//! rule) finds its inward-ordered projection counter-clockwise around the
//! ray and the origin lies on or outside its plane (exact `orient3d`), the
//! same decision as `BoundaryEntry`, so entry and walk agree on every
//! boundary edge. The face the previous ray entered is tested first; when
//! the ray misses it, a short walk over the boundary surface follows (to
//! the neighbour across the first edge the ray lies right of, a few steps
//! at most, front faces only) before the BVH is searched. Exactly one face
//! passes the test for a ray that enters (the tie rule gives every edge one
//! side), so the walk and the BVH find the same face.

use glam::Vec3;
use tet_core::predicates::orient3d_f32;
use tet_core::{Link, TetMesh};

use super::marching::RayPre;
use crate::walk::{DuffF32, EntryHint, Projection, Start};

/// Faces per leaf.
const LEAF: usize = 4;

/// Steps of the surface walk from the hint face before the BVH search.
const SURFACE_STEPS: usize = 8;

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
    /// Per face (in `faces` order), the face across its edge `k`
    /// (`ids[k] → ids[k + 1]`), or `u32::MAX` when the edge is not shared
    /// by exactly two boundary faces.
    across: Vec<[u32; 3]>,
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
            across: Vec::new(),
        };
        if !hull.faces.is_empty() {
            let n = hull.faces.len();
            let mut faces = std::mem::take(&mut hull.faces);
            build(mesh, &mut faces, 0, &mut hull.nodes);
            debug_assert_eq!(faces.len(), n);
            hull.faces = faces;
        }
        hull.across = adjacency(&hull.faces);
        hull
    }

    /// Bytes of the structure.
    pub(crate) fn bytes(&self) -> usize {
        std::mem::size_of_val(&self.faces[..])
            + std::mem::size_of_val(&self.nodes[..])
            + std::mem::size_of_val(&self.across[..])
    }

    /// The walk start of `ray` (origin outside the mesh) where its line
    /// enters ahead of the origin, or `None` when it never enters.
    pub(crate) fn start(
        &self,
        mesh: &TetMesh,
        pre: &RayPre,
        hint: &mut EntryHint,
    ) -> Option<Start> {
        // The edge tests of face `f`: bit `k` set when the ray lies left of
        // edge `k` (all three: inside the projected face).
        let edges = |f: &Face| {
            let p = f.ids.map(|i| pre.proj.project(mesh.points[i as usize]));
            let proj: &DuffF32 = &pre.proj;
            proj.left(p[0], f.ids[0], p[1], f.ids[1]) as u32
                | (proj.left(p[1], f.ids[1], p[2], f.ids[2]) as u32) << 1
                | (proj.left(p[2], f.ids[2], p[0], f.ids[0]) as u32) << 2
        };
        let front = |f: &Face| {
            let [a, b, c] = mesh.face_vertices(f.tet, f.face as usize);
            let q = |i: u32| mesh.points[i as usize];
            orient3d_f32(q(a), q(b), q(c), pre.ray.origin) >= 0.0
        };
        let enters = |f: &Face| edges(f) == 7 && front(f);
        let start = |f: &Face| Start::Entry {
            tet: f.tet,
            face: f.face,
        };
        // A ray that misses the root box enters nowhere.
        let root = self.nodes.first()?;
        let (t0, t1) = pre.slab(root.lo, root.hi);
        if !(t0 <= t1 && t1 >= 0.0) {
            return None;
        }
        // The surface walk from the hint face.
        let mut at = hint.face;
        for _ in 0..SURFACE_STEPS {
            let Some(f) = self.faces.get(at) else { break };
            if !front(f) {
                break;
            }
            let m = edges(f);
            if m == 7 {
                hint.face = at;
                return Some(start(f));
            }
            let k = (!m).trailing_zeros() as usize;
            at = self.across[at][k.min(2)] as usize;
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
                        hint.face = j;
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

/// The face across each edge of each face (see [`Hull::across`]).
fn adjacency(faces: &[Face]) -> Vec<[u32; 3]> {
    use std::collections::HashMap;
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    let mut by_edge: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    for (j, f) in faces.iter().enumerate() {
        for k in 0..3 {
            by_edge
                .entry(key(f.ids[k], f.ids[(k + 1) % 3]))
                .or_default()
                .push(j as u32);
        }
    }
    faces
        .iter()
        .enumerate()
        .map(|(j, f)| {
            std::array::from_fn(|k| match by_edge[&key(f.ids[k], f.ids[(k + 1) % 3])][..] {
                [x, y] => {
                    if x == j as u32 {
                        y
                    } else {
                        x
                    }
                }
                _ => u32::MAX,
            })
        })
        .collect()
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
