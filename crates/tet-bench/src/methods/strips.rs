//! The Ray-Strips method (Lauterbach et al. 2007; the `ray-strips`
//! crate) behind the same [`Tracer`] interface as the tet walks and the
//! BVH: the structure is built over the mesh's input triangles (its
//! constrained faces merged back into the scene's triangles:
//! [`InputTriangles`], exactly the BVH baseline's primitives), and a hit
//! is reported as the BVH's record ([`super::bvh::input_hit`]), so every
//! method renders and is checked the same way.
//!
//! `strips` traces one ray at a time; `strips-packets` hands each batch to
//! [`RayStrips::intersect_packet`], which groups four consecutive rays
//! into a 2×2-style packet when their directions share signs (the
//! renderer's tile rows give runs of four neighbouring pixels).

use std::time::Instant;

use ray_strips::{BuildOptions, RayStrips};
use tet_core::{InputTriangles, TetMesh};
use tet_trace_cpu::kernel::Tracer;
use tet_trace_cpu::ray::{Ray, TraceOutcome};
use tet_trace_cpu::walk::{Start, Starts};

use super::bvh::input_hit;

/// Ray-Strips over the input triangles of a mesh.
pub struct StripsTracer<'m> {
    /// The mesh whose input triangles are the triangles.
    mesh: &'m TetMesh,
    /// Its input triangles.
    inputs: InputTriangles,
    /// The structure (triangle `i` = input triangle `i`).
    strips: RayStrips,
    /// Trace batches as packets.
    packets: bool,
    /// Build time in seconds.
    build_s: f64,
}

impl<'m> StripsTracer<'m> {
    /// Builds Ray-Strips over the input triangles of `mesh.constrained`
    /// with the crate's default options; `packets` selects the packet path
    /// for batches.
    pub fn new(mesh: &'m TetMesh, packets: bool) -> anyhow::Result<Self> {
        let inputs = InputTriangles::of(mesh);
        let t = Instant::now();
        // Scenes at 1e30 or 1e-30 need no scaling here: the crate works in
        // a frame of its own.
        let strips = RayStrips::build(&mesh.points, &inputs.corners, &BuildOptions::default())?;
        Ok(StripsTracer {
            mesh,
            inputs,
            strips,
            packets,
            build_s: t.elapsed().as_secs_f64(),
        })
    }

    /// The structure (bytes, counts).
    pub fn strips(&self) -> &RayStrips {
        &self.strips
    }

    /// Build time in seconds.
    pub fn build_s(&self) -> f64 {
        self.build_s
    }

    /// The hit record of a Ray-Strips hit.
    fn outcome(&self, ray: &Ray, hit: Option<ray_strips::Hit>) -> TraceOutcome {
        match hit {
            Some(h) => TraceOutcome::Hit(input_hit(self.mesh, &self.inputs, ray, h.triangle, h.t)),
            None => TraceOutcome::Miss { tets_visited: 0 },
        }
    }

    /// Closest hit skipping the input triangle of constrained face `skip`
    /// (a secondary ray leaving it): the ray is re-cast just past each hit
    /// on that triangle.
    fn closest(&self, ray: &Ray, skip: Option<u32>) -> Option<ray_strips::Hit> {
        let skip = skip.and_then(|f| self.inputs.of_face(f));
        let mut r = to_strips(ray);
        for _ in 0..8 {
            let h = self.strips.intersect(&r)?;
            if Some(h.triangle) != skip {
                return Some(h);
            }
            r.t_min = next_up(h.t);
        }
        None
    }
}

/// The same ray for the `ray-strips` crate (negative `t_min` clamped to 0,
/// as the BVH baseline does).
fn to_strips(ray: &Ray) -> ray_strips::Ray {
    ray_strips::Ray {
        origin: ray.origin,
        direction: ray.direction,
        t_min: ray.t_min.max(0.0),
        t_max: ray.t_max,
    }
}

/// The next f32 above `t` (`t ≥ 0`).
fn next_up(t: f32) -> f32 {
    f32::from_bits(t.max(0.0).to_bits() + 1)
}

impl Tracer for StripsTracer<'_> {
    fn name(&self) -> String {
        if self.packets {
            "ray-strips-2x2/f32".into()
        } else {
            "ray-strips/f32".into()
        }
    }

    fn mesh(&self) -> &TetMesh {
        self.mesh
    }

    fn walks_tets(&self) -> bool {
        false
    }

    fn trace(&self, ray: &Ray, start: Start) -> TraceOutcome {
        self.outcome(ray, self.closest(ray, start.on_face()))
    }

    fn trace_batch(&self, rays: &[Ray], start: Start, out: &mut [TraceOutcome]) {
        self.trace_batch_from(rays, Starts::Same(start), out);
    }

    fn trace_batch_from(&self, rays: &[Ray], starts: Starts<'_>, out: &mut [TraceOutcome]) {
        // Packets only where no ray starts on a face (primary rays).
        let on_face = |i: usize| match starts {
            Starts::Same(s) => s.on_face(),
            Starts::Each(s) => s.get(i).and_then(|s| s.on_face()),
            Starts::Outside(_) => None,
        };
        if !self.packets || (0..rays.len()).any(|i| on_face(i).is_some()) {
            for (i, (r, o)) in rays.iter().zip(out.iter_mut()).enumerate() {
                *o = self.outcome(r, self.closest(r, on_face(i)));
            }
            return;
        }
        let n = rays.len().min(out.len());
        let converted: Vec<ray_strips::Ray> = rays[..n].iter().map(to_strips).collect();
        let mut hits = vec![None; n];
        self.strips.intersect_packet(&converted, &mut hits);
        for ((r, h), o) in rays.iter().zip(hits).zip(out.iter_mut()) {
            *o = self.outcome(r, h);
        }
    }
}
