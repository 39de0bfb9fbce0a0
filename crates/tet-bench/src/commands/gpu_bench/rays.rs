//! The rays of a run and the CPU walk over them: the camera's primary
//! rays (the CPU renderer's [`PinholeCamera`], neptun's pixel corners, as
//! the GPU tracer makes them), and the secondary rays the CPU gives the
//! GPU (Aman et al. 2022, §6): from every primary hit of the CPU Tet20
//! walk, one shadow ray to the scene's first point light and one diffuse
//! bounce.

use glam::Vec3;
use rayon::prelude::*;
use tet_core::TetMesh;
use tet_trace_cpu::render::PinholeCamera;
use tet_trace_cpu::render::ambient::{ao_ray, ao_seed};
use tet_trace_cpu::secondary::{hit_point, start_beyond};
use tet_trace_cpu::{Ray, Start, Starts, TraceOutcome, Tracer, Viewpoint};

/// Rays per task of the parallel CPU walks.
const CHUNK: usize = 4096;

/// Seed of the bounce directions (mixed with the pixel index).
const BOUNCE_SEED: u64 = 0x6770_7562_656e_6368;

/// The camera rays of a `width × height` image: ray `y · width + x`
/// through pixel `(x, y)`'s corner.
pub struct CameraRays {
    /// The generator.
    pub camera: PinholeCamera,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
}

impl CameraRays {
    /// Ray `i`.
    pub fn ray(&self, i: usize) -> Ray {
        self.camera
            .ray(i as u32 % self.width, i as u32 / self.width)
    }

    /// Rays in all.
    pub fn len(&self) -> usize {
        self.width as usize * self.height as usize
    }
}

/// The CPU walk of `tracer` over every camera ray, from `view` (the
/// camera's tet, or each ray's entry into the mesh), one image row per
/// batch, rows in parallel.
pub fn cpu_primary(tracer: &dyn Tracer, view: &Viewpoint, rays: &CameraRays) -> Vec<TraceOutcome> {
    let w = rays.width as usize;
    let mut out = vec![TraceOutcome::Miss { tets_visited: 0 }; rays.len()];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        let batch: Vec<Ray> = (0..w).map(|x| rays.ray(y * w + x)).collect();
        let starts = match view {
            Viewpoint::Inside(t) => Starts::Same(Start::Tet(*t)),
            Viewpoint::Outside(entry) => Starts::Outside(entry),
        };
        tracer.trace_batch_from(&batch, starts, row);
    });
    out
}

/// A batch of secondary rays, each with the start the CPU chose.
pub struct Secondary {
    /// `shadow` or `bounce`.
    pub kind: &'static str,
    /// The rays.
    pub rays: Vec<Ray>,
    /// Where each starts: on its primary hit's face, in the tet on the
    /// side it leaves by.
    pub starts: Vec<Start>,
}

/// One shadow ray per primary hit toward `light`: from the hit point,
/// direction `light − point`, `t_max = 1` (a hit beyond the light is a
/// miss). Hits whose face has no tet on the light's side, or whose point
/// is the light, cast none.
pub fn shadow_rays(mesh: &TetMesh, primary: &[TraceOutcome], light: Vec3) -> Secondary {
    let (mut rays, mut starts) = (Vec::new(), Vec::new());
    for o in primary {
        let TraceOutcome::Hit(hit) = o else {
            continue;
        };
        let p = hit_point(mesh, hit);
        let dir = light - p;
        if dir == Vec3::ZERO || !dir.is_finite() {
            continue;
        }
        if let Some(start) = start_beyond(mesh, hit.face, dir) {
            rays.push(Ray {
                origin: p,
                direction: dir,
                t_min: 0.0,
                t_max: 1.0,
            });
            starts.push(start);
        }
    }
    Secondary {
        kind: "shadow",
        rays,
        starts,
    }
}

/// One diffuse bounce per primary hit: a cosine-distributed direction on
/// the side of the hit face the camera ray came from, unbounded (the
/// renderer's ambient-occlusion ray without its length).
pub fn bounce_rays(mesh: &TetMesh, primary: &[TraceOutcome], camera: &CameraRays) -> Secondary {
    let (mut rays, mut starts) = (Vec::new(), Vec::new());
    for (i, o) in primary.iter().enumerate() {
        let TraceOutcome::Hit(hit) = o else {
            continue;
        };
        let seed = ao_seed(BOUNCE_SEED, i as u32);
        if let Some((ray, start)) = ao_ray(mesh, &camera.ray(i), hit, f32::INFINITY, seed) {
            rays.push(ray);
            starts.push(start);
        }
    }
    Secondary {
        kind: "bounce",
        rays,
        starts,
    }
}

/// The CPU walk of `tracer` over a batch of secondary rays, in parallel.
pub fn cpu_secondary(tracer: &dyn Tracer, batch: &Secondary) -> Vec<TraceOutcome> {
    let mut out = vec![TraceOutcome::Miss { tets_visited: 0 }; batch.rays.len()];
    out.par_chunks_mut(CHUNK)
        .zip(
            batch
                .rays
                .par_chunks(CHUNK)
                .zip(batch.starts.par_chunks(CHUNK)),
        )
        .for_each(|(o, (r, s))| tracer.trace_batch_from(r, Starts::Each(s), o));
    out
}
