//! The BVH baseline: obvhs's BVH2 (`slow_build` preset, SAH with
//! reinsertion) over the scene triangles, with precomputed intersection
//! triangles reordered to the BVH's primitive order — the strongest obvhs
//! configuration for closest-hit single rays. It implements the same
//! [`Tracer`] interface as the tet walks so every method renders the same
//! rays through the same code.

use std::time::Duration;

use glam::Vec3;
use glam_obvhs::Vec3A;
use obvhs::BvhBuildParams;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::builder::build_bvh2_from_tris;
use obvhs::ray::{Ray as BvhRay, RayHit};
use obvhs::rt_triangle::RtTriangle;
use obvhs::triangle::Triangle;
use tet_core::TetMesh;
use tet_trace_cpu::kernel::Tracer;
use tet_trace_cpu::ray::{Hit, Ray, TraceOutcome};
use tet_trace_cpu::walk::Start;

/// A BVH2 over the constrained faces of a mesh (the scene triangles).
pub struct BvhTracer<'m> {
    mesh: &'m TetMesh,
    bvh: Bvh2,
    /// Intersection triangles in BVH primitive order.
    tris: Vec<RtTriangle>,
    /// Constrained-face index of each BVH primitive.
    faces: Vec<u32>,
}

fn a(v: Vec3) -> Vec3A {
    Vec3A::new(v.x, v.y, v.z)
}

impl<'m> BvhTracer<'m> {
    /// Builds the BVH over `mesh.constrained`.
    pub fn new(mesh: &'m TetMesh) -> Self {
        let source: Vec<Triangle> = mesh
            .constrained
            .iter()
            .map(|cf| {
                let [v0, v1, v2] = cf.vertices.map(|v| a(mesh.points[v as usize]));
                Triangle { v0, v1, v2 }
            })
            .collect();
        let bvh = build_bvh2_from_tris(
            &source,
            BvhBuildParams::slow_build(),
            &mut Duration::default(),
        );
        let faces: Vec<u32> = bvh.primitive_indices.clone();
        let tris = faces
            .iter()
            .map(|&f| RtTriangle::from(&source[f as usize]))
            .collect();
        BvhTracer {
            mesh,
            bvh,
            tris,
            faces,
        }
    }

    fn hit_record(&self, ray: &Ray, face: u32, t: f32) -> Hit {
        let cf = &self.mesh.constrained[face as usize];
        let [p0, p1, p2] = cf.vertices.map(|v| self.mesh.points[v as usize]);
        let n = (p1 - p0).cross(p2 - p0);
        let p = ray.at(t);
        let area = n.length_squared().max(f32::MIN_POSITIVE);
        let b1 = (p0 - p).cross(p2 - p).dot(n) / area;
        let b2 = (p1 - p).cross(p0 - p).dot(n) / area;
        let from_front = ray.direction.dot(n) < 0.0;
        let (near, far) = if from_front {
            (cf.front.tet, cf.back.tet)
        } else {
            (cf.back.tet, cf.front.tet)
        };
        Hit {
            triangle: cf.triangle,
            face,
            t,
            barycentrics: [1.0 - b1 - b2, b1, b2],
            tet: near,
            far_tet: far,
            tets_visited: 0,
        }
    }
}

impl Tracer for BvhTracer<'_> {
    fn name(&self) -> String {
        "obvhs-bvh2/f32".into()
    }

    fn mesh(&self) -> &TetMesh {
        self.mesh
    }

    fn trace(&self, ray: &Ray, start: Start) -> TraceOutcome {
        let skip = match start {
            Start::Face { face, .. } => face,
            Start::Tet(_) => u32::MAX,
        };
        let mut r = BvhRay::new(
            a(ray.origin),
            a(ray.direction),
            ray.t_min.max(0.0),
            ray.t_max,
        );
        r.tmin = ray.t_min;
        let mut hit = RayHit::none();
        let found = self.bvh.ray_traverse(r, &mut hit, |r, id| {
            if self.faces[id] == skip {
                f32::INFINITY
            } else {
                self.tris[id].intersect(r)
            }
        });
        if found {
            let face = self.faces[hit.primitive_id as usize];
            TraceOutcome::Hit(self.hit_record(ray, face, hit.t))
        } else {
            TraceOutcome::Miss { tets_visited: 0 }
        }
    }
}
