//! Traces a mesh with the Tet20 kernel: one ray, then a small camera image.
//!
//! ```text
//! cargo run --release -p tet-trace-cpu --example trace_mesh [FILE.tmesh] [OUT.png]
//! ```
//!
//! Without a file, a procedural mesh is built in code: a jittered grid of
//! 6×6×6 cells with a closed shell of constrained faces (a box) inside.

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::scene::Camera;
use tet_core::synthetic::{GridSpec, kuhn_grid};
use tet_trace_cpu::render::{RenderOptions, render};
use tet_trace_cpu::tet20::Tet20Tracer;
use tet_trace_cpu::{DuffF32, Ray, Start, TraceOutcome, Tracer, locate};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mesh: TetMesh = match args.first() {
        Some(path) => tet_core::format::load(path)?,
        None => kuhn_grid(&GridSpec {
            cells: [6; 3],
            shell: Some(([2; 3], [4; 3])),
            ..Default::default()
        }),
    };
    mesh.validate()?;
    println!("{} points, {} tets", mesh.points.len(), mesh.tets.len());

    // The Tet20 layout (20 bytes per tet), walked with the f32 projection.
    let tracer = Tet20Tracer::<DuffF32>::new(&mesh)?;

    // One ray from a point inside the mesh toward the middle of its bounds.
    let (lo, hi) = mesh.point_bounds();
    let centre = (lo + hi) * 0.5;
    let origin = lo + (hi - lo) * Vec3::new(0.1, 0.15, 0.2);
    let start = Start::Tet(locate(&mesh, origin, 0)?);
    match tracer.trace(&Ray::new(origin, centre - origin), start) {
        TraceOutcome::Hit(h) => println!(
            "hit triangle {} at t = {} after {} tets",
            h.triangle, h.t, h.tets_visited
        ),
        other => println!("no hit: {other:?}"),
    }

    // A 160×120 image from a camera at the same point (inside the mesh, or
    // outside it: rays then enter through the boundary).
    let camera = Camera {
        position: origin,
        target: centre,
        up: Vec3::Z,
        vfov_deg: 60.0,
    };
    let opts = RenderOptions {
        width: 160,
        height: 120,
        headlight: true,
        ..Default::default()
    };
    let frame = render(&tracer, &camera, &[], &opts)?;
    let s = &frame.stats;
    println!(
        "{}x{}: {} of {} rays hit, {:.1} tets per ray",
        opts.width,
        opts.height,
        s.hits,
        s.rays,
        s.tets_visited as f64 / s.rays.max(1) as f64
    );
    if let Some(out) = args.get(1) {
        frame.save_png(std::path::Path::new(out))?;
        println!("wrote {out}");
    }
    Ok(())
}
