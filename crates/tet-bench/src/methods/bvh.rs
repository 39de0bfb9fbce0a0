//! The BVH baseline: obvhs's BVH2 (`slow_build` preset, SAH with
//! reinsertion) over the scene triangles (as the user gave them:
//! [`InputTriangles`] merges the pieces a resolved crossing or a wall cut
//! a triangle into), with precomputed intersection
//! triangles reordered to the BVH's primitive order — the strongest obvhs
//! configuration for closest-hit single rays. It implements the same
//! [`Tracer`] interface as the tet walks so every method renders the same
//! rays through the same code.
//!
//! obvhs counts nothing, so [`BvhTracer::counting`] gives a second tracer
//! over the *same* BVH that walks its `Bvh2` nodes with our own copy of
//! obvhs's stack traversal ([`BvhTracer::count_trace`]: same child order,
//! same pruning by the closest hit so far) and reports the number of nodes
//! whose bounding box was tested (root included) as `tets_visited`: the
//! "visited node count per pixel" of Aman et al. (2022) Table 5 (pbrt
//! counts a node when it tests its bounds). Timed renders use obvhs's own traversal; the
//! counting one is run once, untimed, and checked to return the same hits.

use std::time::Duration;

use glam::Vec3;
use glam::Vec3A;
use obvhs::BvhBuildParams;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::builder::build_bvh2_from_tris;
use obvhs::ray::{Ray as BvhRay, RayHit};
use obvhs::rt_triangle::RtTriangle;
use obvhs::triangle::Triangle;
use tet_core::input_triangles::plane_barycentrics;
use tet_core::{InputTriangles, TetMesh};
use tet_trace_cpu::kernel::Tracer;
use tet_trace_cpu::ray::{Hit, Ray, TraceOutcome};
use tet_trace_cpu::walk::{Start, walk_scale};

/// A BVH2 over the scene triangles of a mesh (its constrained faces
/// merged back into their input triangles).
pub struct BvhTracer<'m> {
    /// The mesh whose input triangles are the primitives.
    mesh: &'m TetMesh,
    /// Its input triangles and their pieces.
    inputs: InputTriangles,
    /// obvhs's BVH2 over the triangles.
    bvh: Bvh2,
    /// Intersection triangles in BVH primitive order.
    tris: Vec<RtTriangle>,
    /// Input-triangle index of each BVH primitive.
    prims: Vec<u32>,
    /// Trace with [`BvhTracer::count_trace`] (nodes visited reported as
    /// `tets_visited`) instead of obvhs's traversal.
    count_nodes: bool,
    /// The power of two the BVH's triangles were scaled by ([`unit_scale`]).
    scale: f32,
}

/// A power of two that brings a mesh's largest coordinate near 1 when it
/// lies outside `[2⁻¹⁶, 2¹⁶]` (else 1): obvhs's surface areas and inverse
/// directions over- or underflow f32 for scenes at 1e30 or 1e-30, so its
/// BVHs are built on the scene scaled exactly and traversed with rays
/// scaled the same way (the same `t`).
pub fn unit_scale(mesh: &TetMesh) -> f32 {
    let m = mesh
        .points
        .iter()
        .map(|p| p.abs().max_element())
        .fold(0.0f32, f32::max);
    let s = walk_scale(m as f64);
    if s == 1.0 {
        return 1.0;
    }
    // Exact unless a coordinate falls into the subnormals: then unscaled.
    let exact = mesh.points.iter().all(|&p| (p * s) / s == p);
    if exact { s } else { 1.0 }
}

/// `v` in obvhs's vector type.
fn a(v: Vec3) -> Vec3A {
    Vec3A::new(v.x, v.y, v.z)
}

impl<'m> BvhTracer<'m> {
    /// Builds the BVH over the input triangles of `mesh.constrained`.
    pub fn new(mesh: &'m TetMesh) -> Self {
        let scale = unit_scale(mesh);
        let inputs = InputTriangles::of(mesh);
        let source: Vec<Triangle> = inputs
            .corners
            .iter()
            .map(|c| {
                let [v0, v1, v2] = c.map(|v| a(mesh.points[v as usize] * scale));
                Triangle { v0, v1, v2 }
            })
            .collect();
        let bvh = build_bvh2_from_tris(
            &source,
            BvhBuildParams::slow_build(),
            &mut Duration::default(),
        );
        let prims: Vec<u32> = bvh.primitive_indices.clone();
        let tris = prims
            .iter()
            .map(|&f| RtTriangle::from(&source[f as usize]))
            .collect();
        BvhTracer {
            mesh,
            inputs,
            bvh,
            tris,
            prims,
            count_nodes: false,
            scale,
        }
    }

    /// The same BVH traced by [`BvhTracer::count_trace`]: hits as obvhs's
    /// traversal, `tets_visited` = BVH nodes visited.
    pub fn counting(mut self) -> Self {
        self.count_nodes = true;
        self
    }

    /// Nodes in the BVH.
    #[cfg(test)]
    pub fn node_count(&self) -> usize {
        self.bvh.nodes.len()
    }

    /// Heap bytes traversal reads: `(hierarchy, geometry)` = the BVH
    /// nodes, and the precomputed intersection triangles with their face
    /// ids (the optimised triangle representation of Ray-Strips' Table 1).
    pub fn bytes(&self) -> (usize, usize) {
        (
            std::mem::size_of_val(self.bvh.nodes.as_slice()),
            std::mem::size_of_val(self.tris.as_slice())
                + std::mem::size_of_val(self.prims.as_slice()),
        )
    }

    /// Closest hit `(primitive in BVH order, t)` and the number of nodes
    /// whose box was tested, by obvhs's stack traversal
    /// (`Bvh2::ray_traverse_dynamic`) re-written with a counter: the two
    /// children of the current node are tested together, the nearer one
    /// is visited first, the farther one pushed; leaves are intersected
    /// when their box is hit before the current closest hit.
    pub fn count_trace(
        &self,
        ray: &BvhRay,
        mut accept: impl FnMut(usize) -> bool,
    ) -> (Option<(usize, f32)>, u32) {
        let nodes = &self.bvh.nodes;
        let mut tmax = ray.tmax;
        let mut best: Option<(usize, f32)> = None;
        let mut visited = 0u32;
        let Some(root) = nodes.first() else {
            return (None, 0);
        };
        visited += 1;
        if root.aabb().intersect_ray(ray) >= tmax {
            return (None, visited);
        }
        let mut leaf = |node: &obvhs::bvh2::node::Bvh2Node, tmax: &mut f32| {
            for id in node.first_index..node.first_index + node.prim_count {
                let id = id as usize;
                if !accept(id) {
                    continue;
                }
                let mut r = *ray;
                r.tmax = *tmax;
                let t = self.tris[id].intersect(&r);
                if t < *tmax {
                    *tmax = t;
                    best = Some((id, t));
                }
            }
        };
        if root.is_leaf() {
            leaf(root, &mut tmax);
            return (best, visited);
        }
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        let mut current = root.first_index as usize;
        loop {
            let (mut near, mut far) = (&nodes[current], &nodes[current + 1]);
            visited += 2;
            let (mut tn, mut tf) = (
                near.aabb().intersect_ray(ray),
                far.aabb().intersect_ray(ray),
            );
            if tn > tf {
                std::mem::swap(&mut tn, &mut tf);
                std::mem::swap(&mut near, &mut far);
            }
            let go_near = if tn < tmax && near.is_leaf() {
                leaf(near, &mut tmax);
                false
            } else {
                tn < tmax
            };
            let go_far = if tf < tmax && far.is_leaf() {
                leaf(far, &mut tmax);
                false
            } else {
                tf < tmax
            };
            match (go_near, go_far) {
                (true, true) => {
                    current = near.first_index as usize;
                    stack.push(far.first_index);
                }
                (true, false) => current = near.first_index as usize,
                (false, true) => current = far.first_index as usize,
                (false, false) => match stack.pop() {
                    Some(n) => current = n as usize,
                    None => return (best, visited),
                },
            }
        }
    }
}

/// The power of two that brings the largest component of a (valid)
/// direction near 1 when it lies outside `[2⁻¹⁶, 2¹⁶]`, else 1 (the walks'
/// [`walk_scale`]): obvhs treats components below `f32::EPSILON` as zero.
fn direction_scale(d: Vec3) -> f32 {
    walk_scale(d.abs().max_element() as f64)
}

/// The hit record of a tracer over input triangles that found input
/// triangle `i` at distance `t` along `ray`: [`face_hit`] on the piece of
/// the triangle that holds the hit point.
pub fn input_hit(mesh: &TetMesh, inputs: &InputTriangles, ray: &Ray, i: u32, t: f32) -> Hit {
    let p = ray.origin.as_dvec3() + ray.direction.as_dvec3() * t as f64;
    face_hit(mesh, ray, inputs.piece_at(mesh, i as usize, p), t)
}

/// The hit record of a BVH-style tracer that found constrained face `face`
/// at distance `t` along `ray`: barycentrics and the tets on both sides
/// recomputed from the mesh (so every method reports the same record;
/// `tets_visited` is 0).
pub fn face_hit(mesh: &TetMesh, ray: &Ray, face: u32, t: f32) -> Hit {
    let cf = &mesh.constrained[face as usize];
    let v = cf.vertices.map(|v| mesh.points[v as usize].as_dvec3());
    let p = ray.origin.as_dvec3() + ray.direction.as_dvec3() * t as f64;
    let (b, n) = plane_barycentrics(v, p);
    let from_front = ray.direction.as_dvec3().dot(n) < 0.0;
    let (near, far) = if from_front {
        (cf.front.tet, cf.back.tet)
    } else {
        (cf.back.tet, cf.front.tet)
    };
    Hit {
        triangle: cf.triangle,
        face,
        t,
        barycentrics: b.map(|w| w as f32),
        tet: near,
        far_tet: far,
        tets_visited: 0,
    }
}

impl Tracer for BvhTracer<'_> {
    fn name(&self) -> String {
        if self.count_nodes {
            "obvhs-bvh2-counting/f32".into()
        } else {
            "obvhs-bvh2/f32".into()
        }
    }

    fn mesh(&self) -> &TetMesh {
        self.mesh
    }

    fn walks_tets(&self) -> bool {
        false
    }

    fn trace(&self, ray: &Ray, start: Start) -> TraceOutcome {
        if !ray.is_valid() {
            return TraceOutcome::Failed {
                failure: tet_trace_cpu::ray::Failure::InvalidRay,
                tets_visited: 0,
            };
        }
        // A ray leaving a face skips the whole input triangle (its plane).
        let skip = start
            .on_face()
            .and_then(|f| self.inputs.of_face(f))
            .unwrap_or(u32::MAX);
        // obvhs treats direction components below f32::EPSILON as zero: a
        // ray of a tiny (or huge) scene traverses with its direction
        // scaled by a power of two `k` (exact; `t` is then `t' · k`).
        let k = direction_scale(ray.direction * self.scale);
        let mut r = BvhRay::new(
            a(ray.origin * self.scale),
            a(ray.direction * self.scale * k),
            ray.t_min.max(0.0) / k,
            ray.t_max / k,
        );
        r.tmin = ray.t_min / k;
        if self.count_nodes {
            let (best, nodes) = self.count_trace(&r, |id| self.prims[id] != skip);
            return match best {
                Some((id, t)) => {
                    let mut h = input_hit(self.mesh, &self.inputs, ray, self.prims[id], t * k);
                    h.tets_visited = nodes;
                    TraceOutcome::Hit(h)
                }
                None => TraceOutcome::Miss {
                    tets_visited: nodes,
                },
            };
        }
        let mut hit = RayHit::none();
        let found = self.bvh.ray_traverse(r, &mut hit, |r, id| {
            if self.prims[id] == skip {
                f32::INFINITY
            } else {
                self.tris[id].intersect(r)
            }
        });
        if found {
            let i = self.prims[hit.primitive_id as usize];
            TraceOutcome::Hit(input_hit(self.mesh, &self.inputs, ray, i, hit.t * k))
        } else {
            TraceOutcome::Miss { tets_visited: 0 }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};
    use tet_trace_cpu::reference::{Aim, random_ray};

    /// The counting traversal returns obvhs's hits, and visits at least
    /// the path from the root to the hit leaf (both children tested at
    /// every level: `1 + 2·depth` nodes) and at most every node once.
    #[test]
    fn counting_traversal_matches_obvhs_and_counts_the_path() {
        let mesh = kuhn_grid(&GridSpec {
            cells: [6; 3],
            jitter: 0.1,
            constrained_fraction: 0.08,
            seed: 5,
            ..Default::default()
        });
        let plain = BvhTracer::new(&mesh);
        let counting = BvhTracer::new(&mesh).counting();
        // Depth of each primitive's leaf, from an independent parent walk.
        let nodes = &plain.bvh.nodes;
        let mut depth = vec![0usize; nodes.len()];
        let mut leaf_depth = vec![usize::MAX; plain.prims.len()];
        for (i, n) in nodes.iter().enumerate() {
            if n.is_leaf() {
                for p in n.first_index..n.first_index + n.prim_count {
                    leaf_depth[p as usize] = depth[i];
                }
            } else {
                depth[n.first_index as usize] = depth[i] + 1;
                depth[n.first_index as usize + 1] = depth[i] + 1;
            }
        }
        let mut rng = SplitMix64(11);
        let mut hits = 0;
        for _ in 0..2000 {
            let (ray, tet) = random_ray(&mesh, &mut rng, Aim::Random);
            let a = plain.trace(&ray, Start::Tet(tet));
            let b = counting.trace(&ray, Start::Tet(tet));
            let nodes_visited = b.tets_visited();
            assert!(nodes_visited >= 1 && nodes_visited as usize <= counting.node_count());
            match (a, b) {
                (TraceOutcome::Hit(x), TraceOutcome::Hit(y)) => {
                    hits += 1;
                    assert_eq!((x.face, x.t), (y.face, y.t));
                    let input = plain.inputs.of_face(y.face).unwrap();
                    let prim = plain.prims.iter().position(|&i| i == input).unwrap();
                    assert!(nodes_visited as usize > 2 * leaf_depth[prim]);
                }
                (TraceOutcome::Miss { .. }, TraceOutcome::Miss { .. }) => {}
                (x, y) => panic!("obvhs {x:?} vs counting {y:?}"),
            }
        }
        assert!(
            hits > 500,
            "many random rays hit a constrained face: {hits}"
        );
    }
}

#[cfg(test)]
mod face_hit_tests {
    use super::*;
    use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};
    use tet_trace_cpu::reference::{Aim, closest_hit, random_ray};

    /// The BVH's hit record has the f64 brute force's face, `t` and
    /// barycentrics (in the constrained face's vertex order).
    #[test]
    fn hit_records_match_the_brute_force() {
        let mesh = kuhn_grid(&GridSpec {
            cells: [5; 3],
            jitter: 0.1,
            constrained_fraction: 0.1,
            seed: 9,
            ..Default::default()
        });
        let bvh = BvhTracer::new(&mesh);
        let mut rng = SplitMix64(4);
        let mut checked = 0;
        for _ in 0..1000 {
            let (ray, tet) = random_ray(&mesh, &mut rng, Aim::Random);
            let (Some(r), TraceOutcome::Hit(h)) =
                (closest_hit(&mesh, &ray), bvh.trace(&ray, Start::Tet(tet)))
            else {
                continue;
            };
            if r.edge_distance < 1e-3 {
                continue;
            }
            assert_eq!(h.face, r.face);
            for k in 0..3 {
                assert!(
                    (h.barycentrics[k] as f64 - r.barycentrics[k]).abs() < 1e-4,
                    "{h:?} vs {r:?}"
                );
            }
            checked += 1;
        }
        assert!(checked > 300, "{checked}");
    }
}
