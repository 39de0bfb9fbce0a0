//! How far do ambient-occlusion rays walk past their length? The
//! measurement behind a `t_max` bound in the walk.
//!
//! ```text
//! cargo run --release -p tet-trace-cpu --example ao_reach -- FILE.tmesh [--size WxH] [--share S]
//! ```
//!
//! The camera rays of a `W×H` image (default 480×360) are traced with
//! Tet20; per hit the renderer's AO ray (`render::ambient::ao_ray`, length
//! `S` of the scene's diagonal, default the renderer's 0.1, seeded as the
//! renderer seeds pixel `k`) is walked by the scalar walk over a topology
//! that records every exit face the walk crosses. A walk that knew its
//! `t_max` could stop at the first crossed face whose three vertices all
//! lie beyond `t_max` along the ray (the crossing is a convex combination
//! of them, so it lies beyond too). Printed: tets per AO ray as walked
//! today and with that stop, for the rays that end in a miss (no face
//! within reach) and in a hit. One thread.

use std::sync::Mutex;

use tet_core::TetMesh;
use tet_trace_cpu::lockstep::ByLane;
use tet_trace_cpu::render::ambient::{ao_length, ao_ray, ao_seed};
use tet_trace_cpu::render::{AO_SHARE, PinholeCamera};
use tet_trace_cpu::tet20::Tet20Tracer;
use tet_trace_cpu::walk::{self, Topology};
use tet_trace_cpu::{DuffF32, Ray, TraceOutcome, Viewpoint};

type Error = Box<dyn std::error::Error>;

/// A [`Topology`] that records the vertices of every face the walk leaves
/// a tet through (single-threaded use; the mutex only makes it `Sync`).
struct Recorder<'a, T> {
    inner: &'a T,
    log: Mutex<Vec<[u32; 3]>>,
}

impl<T: Topology> Topology for Recorder<'_, T> {
    type Exit = ByLane;
    fn vx(&self, tet: u32) -> u32 {
        self.inner.vx(tet)
    }
    fn exit_link(&self, tet: u32, face: [u32; 3], d: u32, exiting: u32, entry_raw: u32) -> u32 {
        // The face left: the three of the tet's four vertices other than
        // the one `exiting` names.
        let all = [face[0], face[1], face[2], d];
        let mut left = [0; 3];
        let mut k = 0;
        for v in all {
            if v != exiting && k < 3 {
                left[k] = v;
                k += 1;
            }
        }
        self.log.lock().unwrap().push(left);
        self.inner.exit_link(tet, face, d, exiting, entry_raw)
    }
    fn prefetch(&self, tet: u32) {
        self.inner.prefetch(tet)
    }
}

/// Recorded exits up to and including the first face wholly beyond
/// `t_max` along `ray` (unit direction): the steps a walk stopping there
/// would take.
fn steps_with_stop(mesh: &TetMesh, ray: &Ray, faces: &[[u32; 3]]) -> usize {
    let depth = |v: u32| (mesh.points[v as usize] - ray.origin).dot(ray.direction);
    faces
        .iter()
        .position(|f| f.iter().all(|&v| depth(v) > ray.t_max))
        .map_or(faces.len(), |i| i + 1)
}

fn main() -> Result<(), Error> {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .ok_or("usage: ao_reach FILE.tmesh [--size WxH] [--share S]")?;
    let (mut w, mut h, mut share) = (480u32, 360u32, AO_SHARE);
    while let Some(flag) = args.next() {
        let value = args.next().ok_or("a flag without a value")?;
        match flag.as_str() {
            "--size" => {
                let (a, b) = value.split_once('x').ok_or("--size WxH")?;
                (w, h) = (a.parse()?, b.parse()?);
            }
            "--share" => share = value.parse()?,
            _ => return Err(format!("unknown flag {flag}").into()),
        }
    }
    let (mesh, stored) = tet_core::format::load_with_scene(&path)?;
    let camera = stored.camera.ok_or("the mesh file stores no camera")?;
    let tracer = Tet20Tracer::<DuffF32>::new(&mesh)?;
    let rec = Recorder {
        inner: tracer.layout(),
        log: Mutex::new(Vec::new()),
    };
    let view = Viewpoint::locate(&mesh, camera.position)?;
    let cam = PinholeCamera::new(&camera, w, h, false);
    let length = ao_length(&mesh, share);
    // (rays, tets today, tets with the stop) for misses and hits.
    let mut tally = [(0u64, 0u64, 0u64); 2];
    for j in 0..h {
        for i in 0..w {
            let primary = cam.ray(i, j);
            let mut out = [TraceOutcome::Miss { tets_visited: 0 }];
            view.trace_batch(&tracer, &[primary], &mut out);
            let TraceOutcome::Hit(hit) = out[0] else {
                continue;
            };
            let k = j * w + i;
            let Some((ray, start)) = ao_ray(&mesh, &primary, &hit, length, ao_seed(0, k)) else {
                continue;
            };
            rec.log.lock().unwrap().clear();
            let o = walk::trace::<DuffF32, _>(&mesh, &rec, &ray, start, tracer.step_cap());
            let faces = rec.log.lock().unwrap().clone();
            let unit = Ray {
                direction: ray.direction.normalize(),
                ..ray
            };
            let stopped = steps_with_stop(&mesh, &unit, &faces);
            let slot = &mut tally[o.hit().is_some() as usize];
            slot.0 += 1;
            slot.1 += faces.len() as u64 + 1;
            slot.2 += stopped as u64 + 1;
        }
    }
    println!(
        "{path}: {w}x{h}, AO length {length:.4} ({share} of the scene's diagonal), {} tets",
        mesh.tets.len()
    );
    for (name, (n, today, stop)) in ["miss (nothing within reach)", "hit"].iter().zip(tally) {
        let n1 = n.max(1) as f64;
        println!(
            "{name}: {n} rays, tets per ray {:.1} walked, {:.1} with the stop ({:.0} % of the steps)",
            today as f64 / n1,
            stop as f64 / n1,
            100.0 * stop as f64 / today.max(1) as f64
        );
    }
    let (n, today, stop) = (
        tally[0].0 + tally[1].0,
        tally[0].1 + tally[1].1,
        tally[0].2 + tally[1].2,
    );
    println!(
        "all: {n} rays, tets per ray {:.1} walked, {:.1} with the stop",
        today as f64 / n.max(1) as f64,
        stop as f64 / n.max(1) as f64
    );
    Ok(())
}
