//! Measures Ray-Strips on a generated bumpy sphere (~70 k triangles) and,
//! when present, the Stanford bunny: bytes per triangle, build time, strip
//! statistics and single-ray / 2×2-packet primary-ray throughput (one
//! thread, 512 × 512 camera framing the mesh), for several chunk sizes.
//! Times are this thread's on-CPU seconds (best of 5), which keeps them
//! usable on a shared machine. `chunk_triangles = 1` is the baseline: one triangle per BVH leaf, i.e. a
//! plain SAH BVH over an indexed triangle list (plus the strip header).
//!
//! `cargo run --release -p ray-strips --example measure [-- path/to/mesh.obj ...]`

use std::time::Instant;

use glam::Vec3;
use ray_strips::{BuildOptions, Hit, Ray, RayStrips};

mod common;
use common::{cpu_seconds, framing, load_obj};
const RES: usize = 512;
/// Timed runs per measurement (the best counts).
const RUNS: usize = 5;
/// The Stanford bunny of the repository's `scenes/`.
const BUNNY: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../scenes/stanford-bunny.obj"
);

fn bumpy_sphere(rings: u32, segments: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let point = |theta: f32, phi: f32| {
        let r = 1.0
            + 0.04 * (7.0 * theta).sin() * (9.0 * phi).cos()
            + 0.02 * (23.0 * phi + 5.0 * theta).sin();
        r * Vec3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        )
    };
    let mut v = vec![point(0.0, 0.0)];
    for i in 1..rings {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..segments {
            v.push(point(
                theta,
                std::f32::consts::TAU * j as f32 / segments as f32,
            ));
        }
    }
    v.push(point(std::f32::consts::PI, 0.0));
    let south = v.len() as u32 - 1;
    let id = |i: u32, j: u32| 1 + (i - 1) * segments + j % segments;
    let mut f = Vec::new();
    for j in 0..segments {
        f.push([0, id(1, j), id(1, j + 1)]);
        f.push([south, id(rings - 1, j + 1), id(rings - 1, j)]);
    }
    for i in 1..rings - 1 {
        for j in 0..segments {
            f.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            f.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    (v, f)
}

/// Primary rays of a camera framing the mesh's box, in 2×2 pixel blocks.
fn camera(positions: &[Vec3]) -> Vec<Ray> {
    let (eye, centre) = framing(positions);
    let forward = (centre - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let half = 0.45; // tan of the half field of view
    let mut rays = Vec::with_capacity(RES * RES);
    for by in (0..RES).step_by(2) {
        for bx in (0..RES).step_by(2) {
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let px = ((bx + dx) as f32 + 0.5) / RES as f32 * 2.0 - 1.0;
                let py = ((by + dy) as f32 + 0.5) / RES as f32 * 2.0 - 1.0;
                rays.push(Ray::new(eye, forward + half * (px * right - py * up)));
            }
        }
    }
    rays
}

fn best_of<T>(runs: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut best = f64::INFINITY;
    let mut out = None;
    for _ in 0..runs {
        let (t, c) = (Instant::now(), cpu_seconds());
        let r = f();
        let wall = t.elapsed().as_secs_f64();
        let spent = match (c, cpu_seconds()) {
            (Some(a), Some(b)) => b - a,
            _ => wall,
        };
        best = best.min(spent);
        out = Some(r);
    }
    (best, out.expect("at least one run"))
}

fn measure(name: &str, positions: &[Vec3], triangles: &[[u32; 3]]) {
    let rays = camera(positions);
    println!(
        "\n## {name}: {} triangles, {} vertices, {} rays (512²)",
        triangles.len(),
        positions.len(),
        rays.len()
    );
    println!(
        "| chunk | strips/leaf | swaps | build ms | strips | mean strip | swaps | chunks | geom B/tri | hier B/tri | top B/tri | total B/tri | total MB | hits | single Mrays/s | packet Mrays/s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut configs: Vec<(usize, usize, bool)> = [1, 16, 64, 128, 256, 512, 1024]
        .iter()
        .map(|&c| (c, 1, false))
        .collect();
    configs.extend([
        (36, 16, false),
        (64, 4, false),
        (128, 4, false),
        (256, 4, false),
        (128, 1, true),
    ]);
    for (chunk, strips_per_leaf, strip_swaps) in configs {
        let options = BuildOptions {
            chunk_triangles: chunk,
            strips_per_leaf,
            strip_swaps,
        };
        let (build_s, rs) = best_of(RUNS, || {
            RayStrips::build(positions, triangles, &options).expect("valid mesh")
        });
        let s = rs.stats();
        let b = rs.bytes();
        let n = s.triangles as f64;
        let (single_s, single) = best_of(RUNS, || {
            rays.iter()
                .map(|r| rs.intersect(r))
                .collect::<Vec<Option<Hit>>>()
        });
        let mut packet = vec![None; rays.len()];
        let (packet_s, ()) = best_of(RUNS, || rs.intersect_packet(&rays, &mut packet));
        let same = single.iter().zip(&packet).all(|(a, b)| {
            a.map(|h| (h.triangle, h.t.to_bits())) == b.map(|h| (h.triangle, h.t.to_bits()))
        });
        assert!(same, "packet and single results differ");
        let hits = single.iter().filter(|h| h.is_some()).count();
        let m = rays.len() as f64 / 1e6;
        println!(
            "| {chunk} | {strips_per_leaf} | {strip_swaps} | {:.0} | {} | {:.2} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {hits} | {:.2} | {:.2} |",
            build_s * 1e3,
            s.strips,
            s.mean_strip_triangles,
            s.swap_slots,
            s.chunks,
            b.geometry as f64 / n,
            b.hierarchy as f64 / n,
            b.top_level as f64 / n,
            b.total as f64 / n,
            b.total as f64 / 1e6,
            m / single_s,
            m / packet_s,
        );
    }
}

fn main() {
    let (v, f) = bumpy_sphere(131, 268);
    measure("bumpy sphere", &v, &f);
    let mut paths: Vec<String> = std::env::args().skip(1).collect();
    if paths.is_empty() && std::path::Path::new(BUNNY).exists() {
        paths.push(BUNNY.into());
    }
    for p in paths {
        match load_obj(&p) {
            Some((v, f)) => measure(&p, &v, &f),
            None => eprintln!("could not read {p}"),
        }
    }
}
