//! Shadow-ray throughput of a render: the same frame without shadows,
//! with its shadow rays traced one by one (`PerRay`, the renderer's
//! earlier path) and in batches (`trace_until_batch`: side by side, in
//! SIMD lockstep), alternating, best of several rounds.
//!
//! ```text
//! cargo run --release -p tet-trace-cpu --example shadow_speed -- FILE.tmesh \
//!     [--kernel tet20|tet16|tet32|sctp|tet80|tet80-consistent] [--rounds N] \
//!     [--threads N] [--size WxH] [--light X,Y,Z]
//! ```
//!
//! The camera and lights are the ones stored with the mesh, else those of
//! `tet-bench` for a mesh without a scene: a camera on the +z side of the
//! surface's bounding box framing it (60° vertical field of view) and one
//! white light at the camera. `--light` puts the one light elsewhere (a
//! light inside the mesh stops its shadow walks on entering its tets).
//! Shadow Mrays/s = shadow rays per frame ÷ (the shadowed frame's time −
//! the unshadowed frame's time), from the best frame of each.

use std::time::Instant;

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::scene::{Camera, PointLight};
use tet_trace_cpu::render::{Frame, FrameStats, Lights, RenderOptions, render_scene_into};
use tet_trace_cpu::secondary::{LightTarget, OwnShadows, PerRay, ShadowTracer};
use tet_trace_cpu::{DuffF32, Tracer};

type Error = Box<dyn std::error::Error>;

/// The camera of `tet-bench` for a mesh without one: on the +z side of
/// the bounding box of the surface (the constrained faces' vertices),
/// looking at its centre, far enough for the bounding sphere to fill 91 %
/// of a 60° vertical field of view.
fn framing_camera(mesh: &TetMesh) -> Camera {
    let (lo, hi) = mesh
        .constrained
        .iter()
        .flat_map(|cf| cf.vertices)
        .map(|v| mesh.points[v as usize])
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), p| {
            (a.min(p), b.max(p))
        });
    let (lo, hi) = if lo.cmple(hi).all() {
        (lo, hi)
    } else {
        mesh.point_bounds()
    };
    let center = (lo + hi) * 0.5;
    let radius = ((hi - lo).length() * 0.5).max(1e-6);
    let vfov_deg = 60.0f32;
    let distance = 1.1 * radius / (vfov_deg * 0.5).to_radians().sin();
    Camera {
        position: center + Vec3::Z * distance,
        target: center,
        up: Vec3::Y,
        vfov_deg,
    }
}

fn parse_vec3(s: &str) -> Result<Vec3, Error> {
    let v: Vec<f32> = s
        .split(',')
        .map(|x| x.trim().parse::<f32>())
        .collect::<Result<_, _>>()?;
    match v[..] {
        [x, y, z] => Ok(Vec3::new(x, y, z)),
        _ => Err(format!("`{s}`: give X,Y,Z").into()),
    }
}

struct Args {
    path: String,
    kernel: String,
    rounds: usize,
    threads: usize,
    size: (u32, u32),
    light: Option<Vec3>,
}

fn args() -> Result<Args, Error> {
    let mut a = Args {
        path: String::new(),
        kernel: "tet20".into(),
        rounds: 5,
        threads: 2,
        size: (1920, 1440),
        light: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(x) = it.next() {
        let mut value = || it.next().ok_or(format!("{x} needs a value"));
        match x.as_str() {
            "--kernel" => a.kernel = value()?,
            "--rounds" => a.rounds = value()?.parse()?,
            "--threads" => a.threads = value()?.parse()?,
            "--size" => {
                let v = value()?;
                let (w, h) = v.split_once('x').ok_or("--size WxH")?;
                a.size = (w.parse()?, h.parse()?);
            }
            "--light" => a.light = Some(parse_vec3(&value()?)?),
            _ if a.path.is_empty() && !x.starts_with("--") => a.path = x,
            _ => return Err(format!("unknown argument `{x}`").into()),
        }
    }
    if a.rounds == 0 {
        return Err("--rounds must be at least 1".into());
    }
    if a.path.is_empty() {
        return Err("usage: shadow_speed FILE.tmesh [--kernel K] [--rounds N] \
                    [--threads N] [--size WxH] [--light X,Y,Z]"
            .into());
    }
    Ok(a)
}

fn kernel<'m>(name: &str, mesh: &'m TetMesh) -> Result<Box<dyn Tracer + 'm>, Error> {
    use tet_trace_cpu::{sctp, tet16, tet20, tet32, tet80};
    Ok(match name {
        "tet20" => Box::new(tet20::Tet20Tracer::<DuffF32>::new(mesh)?),
        "tet16" => Box::new(tet16::Tet16Tracer::<DuffF32>::new(mesh)?),
        "tet32" => Box::new(tet32::Tet32Tracer::<DuffF32>::new(mesh)?),
        "sctp" => Box::new(<sctp::SctpTracer<'_>>::new(mesh)?),
        "tet80" => Box::new(tet80::Tet80Tracer::new(mesh)?),
        "tet80-consistent" => Box::new(tet80::Tet80ConsistentTracer::consistent(mesh)?),
        _ => return Err(format!("unknown kernel `{name}`").into()),
    })
}

/// One measured configuration: its name, whether it casts shadow rays,
/// and its frame times.
struct Run {
    name: &'static str,
    shadows: bool,
    per_ray: bool,
    ms: Vec<f64>,
    frame: Frame,
}

fn best(ms: &[f64]) -> f64 {
    ms.iter().copied().fold(f64::INFINITY, f64::min)
}

fn median(ms: &[f64]) -> f64 {
    let mut v = ms.to_vec();
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn load() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "?".into())
}

fn main() -> Result<(), Error> {
    let a = args()?;
    let (mesh, stored) = tet_core::format::load_with_scene(&a.path)?;
    let camera = stored.camera.unwrap_or_else(|| framing_camera(&mesh));
    let lights = match a.light {
        Some(position) => vec![PointLight {
            position,
            color: Vec3::ONE,
            intensity: 1.0,
        }],
        None if stored.lights.is_empty() => vec![PointLight {
            position: camera.position,
            color: Vec3::ONE,
            intensity: 1.0,
        }],
        None => stored.lights,
    };
    let tracer = kernel(&a.kernel, &mesh)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(a.threads)
        .build()?;
    let (lo, hi) = mesh.point_bounds();
    println!(
        "{}: {} tets, {} triangles, bounds {lo:?}..{hi:?}; {}, {} thread(s), {}x{}; \
         camera {:?}, lights {:?}",
        a.path,
        mesh.tets.len(),
        mesh.constrained.len(),
        tracer.name(),
        a.threads,
        a.size.0,
        a.size.1,
        camera.position,
        lights.iter().map(|l| l.position).collect::<Vec<_>>()
    );
    for l in &lights {
        let star = LightTarget::locate_or_outside(&mesh, l.position, 0)?;
        match star.tets().len() {
            0 => println!("light {:?}: outside the mesh", l.position),
            n => println!("light {:?}: inside the mesh, {n} tet(s)", l.position),
        }
    }
    let all = Lights {
        points: &lights,
        areas: &[],
    };
    let own = OwnShadows(tracer.as_ref());
    let per_ray = PerRay(&own);
    let mut runs: Vec<Run> = [
        ("no shadows", false, false),
        ("shadows, per ray", true, true),
        ("shadows, batched", true, false),
    ]
    .into_iter()
    .map(|(name, shadows, per_ray)| Run {
        name,
        shadows,
        per_ray,
        ms: Vec::new(),
        frame: Frame {
            width: 0,
            height: 0,
            color: Vec::new(),
            tets: Vec::new(),
            triangle: Vec::new(),
            stats: FrameStats::default(),
        },
    })
    .collect();
    // One frame each to warm up (page in the layout, size the buffers),
    // then the rounds, each in a rotated order.
    for round in 0..=a.rounds {
        let n = runs.len();
        for k in 0..n {
            let run = &mut runs[(k + round) % n];
            let opts = RenderOptions {
                width: a.size.0,
                height: a.size.1,
                shadows: run.shadows,
                ..Default::default()
            };
            let shadow: &dyn ShadowTracer = if run.per_ray { &per_ray } else { &own };
            let t0 = Instant::now();
            pool.install(|| {
                render_scene_into(
                    tracer.as_ref(),
                    shadow,
                    &camera,
                    &all,
                    &opts,
                    &mut run.frame,
                )
            })?;
            if round > 0 {
                run.ms.push(t0.elapsed().as_secs_f64() * 1e3);
            }
        }
    }
    let same = runs[1].frame.color == runs[2].frame.color && {
        let (mut s1, s2) = (runs[1].frame.stats, runs[2].frame.stats);
        s1.ms = s2.ms;
        s1 == s2
    };
    let primary = best(&runs[0].ms);
    let shadow_rays = runs[2].frame.stats.shadow_rays;
    for run in &runs {
        let b = best(&run.ms);
        print!(
            "{:<18} best {:8.1} ms  median {:8.1} ms",
            run.name,
            b,
            median(&run.ms)
        );
        if run.shadows {
            let s = run.frame.stats;
            print!(
                "  {} shadow rays ({} failed)  shadow {:.2} Mrays/s",
                s.shadow_rays,
                s.shadow_failures,
                s.shadow_rays as f64 / ((b - primary) * 1e3)
            );
        }
        println!();
    }
    let ratios: Vec<f64> = runs[1]
        .ms
        .iter()
        .zip(&runs[2].ms)
        .zip(&runs[0].ms)
        .map(|((p, b), z)| (p - z) / (b - z))
        .collect();
    println!(
        "shadow time per ray / batched, per round: {:?}; best-of ratio {:.2}; \
         {shadow_rays} shadow rays per frame; batched frame == per-ray frame: {same}; \
         load average {}",
        ratios.iter().map(|r| format!("{r:.2}")).collect::<Vec<_>>(),
        (best(&runs[1].ms) - primary) / (best(&runs[2].ms) - primary),
        load()
    );
    if !same {
        return Err("the batched frame differs from the per-ray frame".into());
    }
    Ok(())
}
