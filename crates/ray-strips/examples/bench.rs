//! Quick single-ray benchmark for tuning: the Stanford bunny (framed by
//! the camera of the `measure` example) and a "Torus Knots"-like scene
//! (27 (2, 3) torus knots, 12-sided tube over 120 segments, on a
//! `{−5, 0, 5}³` grid, seen from an orbit camera at distance 20), each at
//! the crate's default options or at `chunk strips_per_leaf` from the
//! command line. Prints bytes, strip statistics and single-ray
//! throughput (this thread's CPU time, best of 5).
//!
//! `cargo run --release -p ray-strips --example bench [-- CHUNK STRIPS_PER_LEAF [SWAPS: 0 or 1]]`

use std::time::Instant;

use glam::Vec3;
use ray_strips::{BuildOptions, Ray, RayStrips};

mod common;
use common::{cpu_seconds, framing, load_obj};
/// The Stanford bunny of the repository's `scenes/`.
const BUNNY: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../scenes/stanford-bunny.obj"
);

/// The Torus Knots scene: a copy of `tet_build::procedural::torus_knot` on
/// its grid, kept here so that this crate does not depend on the tet crates.
fn torus_knots() -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let (segments, sides) = (120u32, 12u32);
    let (p, q, c, k, r) = (2.0f64, 3.0f64, 0.91555f64, 5.0 / 11.0, 0.40711f64);
    let mut knot = Vec::new();
    for s in 0..segments {
        let t = std::f64::consts::TAU * s as f64 / segments as f64;
        let (u, th) = (q * t, -p * t);
        let denom = 1.0 - k * u.sin();
        let rho = c / denom;
        let drho = c * k * q * u.cos() / (denom * denom);
        let centre = glam::DVec3::new(rho * th.cos(), rho * u.cos(), rho * th.sin());
        let tangent = glam::DVec3::new(
            drho * th.cos() + rho * p * th.sin(),
            drho * u.cos() - rho * q * u.sin(),
            drho * th.sin() - rho * p * th.cos(),
        )
        .normalize();
        let radial = (centre - centre.dot(tangent) * tangent).normalize();
        let binormal = tangent.cross(radial);
        for j in 0..sides {
            let phi = std::f64::consts::FRAC_PI_2 - std::f64::consts::TAU * j as f64 / sides as f64;
            knot.push(centre + r * (phi.cos() * radial + phi.sin() * binormal));
        }
    }
    let idx = |s: u32, j: u32| (s % segments) * sides + (j % sides);
    let mut v = Vec::new();
    let mut f = Vec::new();
    for x in [-5.0, 0.0, 5.0] {
        for y in [-5.0, 0.0, 5.0] {
            for z in [-5.0, 0.0, 5.0] {
                let base = v.len() as u32;
                let t = glam::DVec3::new(x, y, z);
                v.extend(knot.iter().map(|&p| (p + t).as_vec3()));
                for s in 0..segments {
                    for j in 0..sides {
                        let (a, b, c2, d) =
                            (idx(s, j), idx(s + 1, j), idx(s + 1, j + 1), idx(s, j + 1));
                        f.push([a, b, c2].map(|i| i + base));
                        f.push([a, c2, d].map(|i| i + base));
                    }
                }
            }
        }
    }
    (v, f)
}

fn rays_towards(eye: Vec3, centre: Vec3, half: f32) -> Vec<Ray> {
    let res: usize = std::env::var("RES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(512);
    let forward = (centre - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let mut rays = Vec::with_capacity(res * res);
    for py in 0..res {
        for px in 0..res {
            let x = (px as f32 + 0.5) / res as f32 * 2.0 - 1.0;
            let y = (py as f32 + 0.5) / res as f32 * 2.0 - 1.0;
            rays.push(Ray::new(eye, forward + half * (x * right - y * up)));
        }
    }
    rays
}

fn bunny_rays(positions: &[Vec3]) -> Vec<Ray> {
    let (eye, centre) = framing(positions);
    rays_towards(eye, centre, 0.45)
}

fn knots_rays() -> Vec<Ray> {
    let (ox, oy) = (0.5f32, 1.0f32);
    let dir = Vec3::new(oy.cos() * ox.cos(), ox.sin(), oy.sin() * ox.cos());
    rays_towards(20.0 * dir, Vec3::ZERO, (22.5f32).to_radians().tan())
}

/// All rays once: hit count and a checksum of the hits.
#[inline(never)]
fn trace_all(rs: &RayStrips, rays: &[Ray]) -> (usize, f64) {
    let mut hits = 0;
    let mut tsum = 0.0f64;
    for r in rays {
        if let Some(h) = rs.intersect(r) {
            hits += 1;
            tsum += f64::from(h.t) + f64::from(h.triangle);
        }
    }
    (hits, tsum)
}

fn run(name: &str, positions: &[Vec3], triangles: &[[u32; 3]], rays: &[Ray], o: &BuildOptions) {
    let t = Instant::now();
    let rs = RayStrips::build(positions, triangles, o).expect("valid mesh");
    let build = t.elapsed().as_secs_f64();
    let s = rs.stats();
    let b = rs.bytes();
    let n = s.triangles as f64;
    let runs: usize = std::env::var("RUNS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(5);
    let mut best = f64::INFINITY;
    let mut hits = 0;
    let mut tsum = 0.0f64;
    for _ in 0..runs {
        let c = cpu_seconds().unwrap_or(0.0);
        (hits, tsum) = trace_all(&rs, rays);
        best = best.min(cpu_seconds().unwrap_or(0.0) - c);
    }
    println!(
        "{name}: {:?} build {:.0} ms, {} strips, mean {:.2}, max {}, {} nodes, B/tri geom {:.2} hier {:.2} top {:.2} total {:.2} ({:.3} MB), hits {hits} (check {tsum:.6e}), {:.2} Mrays/s",
        o,
        build * 1e3,
        s.strips,
        s.mean_strip_triangles,
        s.max_strip_triangles,
        s.top_level_nodes,
        b.geometry as f64 / n,
        b.hierarchy as f64 / n,
        b.top_level as f64 / n,
        b.total as f64 / n,
        b.total as f64 / 1e6,
        rays.len() as f64 / best / 1e6,
    );
}

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let mut o = BuildOptions::default();
    if let [c, s, ..] = args[..] {
        o.chunk_triangles = c;
        o.strips_per_leaf = s;
    }
    o.strip_swaps = args.get(2) == Some(&1);
    let only = std::env::var("SCENE").unwrap_or_default();
    if only != "knots" {
        let (v, f) = load_obj(BUNNY).expect("the bunny");
        run("bunny", &v, &f, &bunny_rays(&v), &o);
    }
    if only != "bunny" {
        let (v, f) = torus_knots();
        run("knots", &v, &f, &knots_rays(), &o);
    }
}
