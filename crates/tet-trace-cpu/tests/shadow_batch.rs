//! Shadow rays in batches (`trace_until_batch`, the walks side by side in
//! SIMD lockstep, stopped short of the light's tets by a gate) against
//! the single-ray shadow walk (`trace_until`), bit for bit (outcome kind,
//! hit record, tets visited, failures), for every kernel and every
//! lockstep width the CPU runs: shadow rays from hit points toward lights
//! inside a tet, on vertices, edges and (constrained) faces, and outside
//! the mesh; rays starting in a stop tet (in a tet, on a face), rays with
//! `t_min` windows that cross constrained faces before `t_min`, invalid
//! rays, bad starts, and step caps. And renders with shadows, batched and
//! ray by ray ([`PerRay`]), pixel for pixel.

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::scene::{Camera, PointLight};
use tet_core::synthetic::SplitMix64;
use tet_core::{FACE_VERTICES, NO_TET};
use tet_trace_cpu::kernel::WalkTracer;
use tet_trace_cpu::lockstep::Width;
use tet_trace_cpu::reference::{Aim, random_direction, random_point_inside, random_ray};
use tet_trace_cpu::render::{
    Frame, Lights, PinholeCamera, RenderOptions, render, render_scene_with, shading_normal,
};
use tet_trace_cpu::sctp::SctpTracer;
use tet_trace_cpu::secondary::{
    LightTarget, MeshWalker, OwnShadows, PerRay, ShadowTracer, shadow_ray, trace_shadow,
};
use tet_trace_cpu::tet16::Tet16Tracer;
use tet_trace_cpu::tet20::Tet20Tracer;
use tet_trace_cpu::tet32::Tet32Tracer;
use tet_trace_cpu::tet80::{Tet80ConsistentTracer, Tet80Tracer};
use tet_trace_cpu::walk::{Batch, Topology, trace_until};
use tet_trace_cpu::{
    BatchWalk, DuffF32, DuffF64, Hit, Ray, Start, Starts, TraceOutcome, Tracer, TripleF32,
    Viewpoint,
};

mod common;
use common::{bits, grid};

/// Shadow rays and their starts.
#[derive(Default)]
struct Rays {
    rays: Vec<Ray>,
    starts: Vec<Start>,
}

impl Rays {
    fn push(&mut self, ray: Ray, start: Start) {
        self.rays.push(ray);
        self.starts.push(start);
    }
}

/// Hits of random rays (Tet20 in f64, an independent kernel).
fn random_hits(m: &TetMesh, rng: &mut SplitMix64, n: usize) -> Vec<Hit> {
    let t = Tet20Tracer::<DuffF64>::new(m).unwrap();
    let mut out = Vec::new();
    for _ in 0..20 * n {
        if out.len() == n {
            break;
        }
        let (ray, start) = random_ray(m, rng, Aim::Random);
        if let TraceOutcome::Hit(h) = t.trace(&ray, Start::Tet(start)) {
            out.push(h);
        }
    }
    out
}

/// Lights inside a tet, on a vertex, an edge midpoint, a face centroid, a
/// constrained face's centroid (their stars: 1 to ~30 tets, across
/// constrained faces), and outside the mesh (no star).
fn lights(m: &TetMesh, rng: &mut SplitMix64) -> Vec<LightTarget> {
    let t = (rng.next_u64() % m.tets.len() as u64) as u32;
    let p = m.tet_points(t);
    let s = FACE_VERTICES[(rng.next_u64() % 4) as usize];
    let cf = m.constrained[(rng.next_u64() % m.constrained.len() as u64) as usize];
    let c = cf.vertices.map(|k| m.points[k as usize]);
    let (lo, hi) = m.point_bounds();
    [
        random_point_inside(m, rng).0,
        p[0],
        (p[1] + p[2]) * 0.5,
        (p[s[0]] + p[s[1]] + p[s[2]]) / 3.0,
        (c[0] + c[1] + c[2]) / 3.0,
        hi + (hi - lo) * 0.3,
    ]
    .into_iter()
    .map(|x| LightTarget::locate_or_outside(m, x, 0).unwrap())
    .collect()
}

/// The shadow rays toward `light` from `hits`, and adversarial ones:
/// starting in its star (in a tet, on a face), toward it from random
/// points with `t_min` windows, invalid, and with bad starts.
fn shadow_rays(m: &TetMesh, rng: &mut SplitMix64, hits: &[Hit], light: &LightTarget) -> Rays {
    let mut r = Rays::default();
    for hit in hits {
        if let Some((ray, start)) = shadow_ray(m, hit, light.position) {
            r.push(ray, start);
        }
    }
    // From inside a star tet (the walk ends before it starts), and from
    // the constrained faces of star tets, on both sides.
    for &t in light.tets().iter().take(6) {
        let p = m.tet_points(t);
        let o = (p[0] + p[1] + p[2] + p[3]) * 0.25;
        r.push(Ray::new(o, random_direction(rng)), Start::Tet(t));
        for cf in m.constrained.iter().enumerate() {
            let (face, cf) = (cf.0 as u32, cf.1);
            for side in [cf.front, cf.back] {
                if side.tet == t {
                    let c = cf.vertices.map(|k| m.points[k as usize]);
                    let o = (c[0] + c[1] + c[2]) / 3.0;
                    let start = Start::Face { face, tet: t };
                    r.push(Ray::new(o, light.position - o), start);
                    // Invalid, from a stop tet: the walk reports it invalid.
                    r.push(Ray::new(o, Vec3::ZERO), start);
                }
            }
        }
    }
    // Toward the light from random points, some with `t_min` windows that
    // cross constrained faces before `t_min`, some ending short of it.
    for i in 0..60 {
        let (o, t) = random_point_inside(m, rng);
        let mut ray = Ray {
            origin: o,
            direction: light.position - o,
            t_min: 0.0,
            t_max: 1.0,
        };
        match i % 4 {
            0 => ray.t_min = rng.range_f32(0.0, 0.9),
            1 => ray.t_max = rng.range_f32(0.0, 1.0),
            2 => ray.direction = random_direction(rng),
            _ => {}
        }
        r.push(ray, Start::Tet(t));
    }
    // Invalid rays and bad starts.
    let o = random_point_inside(m, rng);
    r.push(
        Ray::new(o.0, Vec3::new(f32::NAN, 1.0, 0.0)),
        Start::Tet(o.1),
    );
    r.push(Ray::new(o.0, Vec3::X), Start::Tet(m.tets.len() as u32 + 5));
    r.push(
        Ray::new(o.0, Vec3::Y),
        Start::Face {
            face: 0,
            tet: NO_TET,
        },
    );
    r
}

/// Scenes: jittered grids with random constrained faces, one with a
/// closed shell; per scene every light and its shadow rays.
fn scenes() -> Vec<(TetMesh, Vec<(LightTarget, Rays)>)> {
    (0..6u64)
        .map(|seed| {
            let m = grid(4, 0.12, 0.12, seed % 2 == 1, seed);
            let mut rng = SplitMix64(seed * 31 + 7);
            let hits = random_hits(&m, &mut rng, 120);
            let cases = lights(&m, &mut rng)
                .into_iter()
                .map(|l| {
                    let rays = shadow_rays(&m, &mut rng, &hits, &l);
                    (l, rays)
                })
                .collect();
            (m, cases)
        })
        .collect()
}

fn fresh(n: usize) -> Vec<TraceOutcome> {
    vec![
        TraceOutcome::Miss {
            tets_visited: u32::MAX
        };
        n
    ]
}

fn assert_same(name: &str, how: &str, r: &Rays, got: &[TraceOutcome], want: &[TraceOutcome]) {
    assert_eq!(got.len(), want.len());
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        assert_eq!(
            bits(g),
            bits(w),
            "{name} {how}: ray {:?} from {:?}: batch {g:?}, single {w:?}",
            r.rays[i],
            r.starts[i]
        );
    }
}

/// A projected kernel: `trace_until_batch_at` at every width, the trait
/// methods (its own, `ShadowTracer`'s, through `OwnShadows`) and odd
/// batch sizes, against `Tracer::trace_until` ray by ray. `lockstep`: the
/// widths the CPU runs walk in lockstep.
fn check_walk<L: Topology, P: BatchWalk>(
    name: &str,
    t: &WalkTracer<'_, L, P>,
    stop: &[u32],
    r: &Rays,
    lockstep: bool,
) {
    let want: Vec<TraceOutcome> = r
        .rays
        .iter()
        .zip(&r.starts)
        .map(|(ray, s)| Tracer::trace_until(t, ray, *s, stop))
        .collect();
    for width in Width::ALL.into_iter().chain([Width::Auto]) {
        let mut got = fresh(want.len());
        let ran = t.trace_until_batch_at(&r.rays, &r.starts, stop, &mut got, width);
        assert_eq!(ran, lockstep && width.available(), "{name} {width:?}");
        assert_same(name, &format!("{width:?}"), r, &got, &want);
    }
    let mut got = fresh(want.len());
    ShadowTracer::trace_until_batch(t, &r.rays, &r.starts, stop, &mut got);
    assert_same(name, "ShadowTracer", r, &got, &want);
    for chunk in [1, 5, 37] {
        let mut got = fresh(want.len());
        for ((rays, starts), out) in r
            .rays
            .chunks(chunk)
            .zip(r.starts.chunks(chunk))
            .zip(got.chunks_mut(chunk))
        {
            OwnShadows(t).trace_until_batch(rays, starts, stop, out);
        }
        assert_same(name, &format!("chunks of {chunk}"), r, &got, &want);
    }
}

/// A Tet80 kernel, as [`check_walk`], and at low step caps.
fn check_tet80<const C: bool>(name: &str, t: &Tet80Tracer<'_, C>, stop: &[u32], r: &Rays) {
    let want: Vec<TraceOutcome> = r
        .rays
        .iter()
        .zip(&r.starts)
        .map(|(ray, s)| ShadowTracer::trace_until(t, ray, *s, stop))
        .collect();
    for width in Width::ALL.into_iter().chain([Width::Auto]) {
        let mut got = fresh(want.len());
        let ran = t.trace_until_batch_at(&r.rays, &r.starts, stop, &mut got, width);
        assert_eq!(ran, width.available(), "{name} {width:?}");
        assert_same(name, &format!("{width:?}"), r, &got, &want);
    }
    let mut got = fresh(want.len());
    OwnShadows(t).trace_until_batch(&r.rays, &r.starts, stop, &mut got);
    assert_same(name, "OwnShadows", r, &got, &want);
}

#[test]
fn batched_shadow_walks_equal_single_ray_walks_for_every_kernel_and_width() {
    let mut stopped = [0usize; 3];
    for (m, cases) in scenes() {
        let t20 = Tet20Tracer::<DuffF32>::new(&m).unwrap();
        let t16 = Tet16Tracer::<DuffF32>::new(&m).unwrap();
        let t32 = Tet32Tracer::<DuffF32>::new(&m).unwrap();
        let t64 = Tet20Tracer::<DuffF64>::new(&m).unwrap();
        let sctp = <SctpTracer<'_>>::new(&m).unwrap();
        let t80 = Tet80Tracer::new(&m).unwrap();
        let t80c = Tet80ConsistentTracer::consistent(&m).unwrap();
        let walker = MeshWalker::new(&m);
        for (light, r) in &cases {
            let stop = light.tets();
            check_walk("tet20", &t20, stop, r, true);
            check_walk("tet16", &t16, stop, r, true);
            check_walk("tet32", &t32, stop, r, true);
            check_walk("tet20/f64", &t64, stop, r, false);
            check_walk("sctp", &sctp, stop, r, true);
            check_tet80("tet80", &t80, stop, r);
            check_tet80("tet80-consistent", &t80c, stop, r);
            let want: Vec<TraceOutcome> = r
                .rays
                .iter()
                .zip(&r.starts)
                .map(|(ray, s)| walker.trace_until(ray, *s, stop))
                .collect();
            let mut got = fresh(want.len());
            walker.trace_until_batch(&r.rays, &r.starts, stop, &mut got);
            assert_same("mesh walker", "batch", r, &got, &want);
            // The cases are what they claim: walks stopped in the star,
            // occluded, and stopped at their start.
            for (o, s) in want.iter().zip(&r.starts) {
                let start_tet = match *s {
                    Start::Tet(t) | Start::Face { tet: t, .. } | Start::Entry { tet: t, .. } => t,
                };
                match o {
                    TraceOutcome::Miss { tets_visited: 1 } if stop.contains(&start_tet) => {
                        stopped[2] += 1
                    }
                    TraceOutcome::Miss { .. } if !stop.is_empty() => stopped[0] += 1,
                    TraceOutcome::Hit(_) => stopped[1] += 1,
                    _ => {}
                }
            }
        }
    }
    assert!(
        stopped.iter().all(|&n| n > 50),
        "misses toward lights in the mesh, occluded, stopped at the start: {stopped:?}"
    );
}

/// The step cap decides before the stop tet, as in the single-ray walk:
/// every cap from 0 up, for the projected walks (through
/// [`BatchWalk::trace_until_batch`] over a batch with that cap, against
/// [`trace_until`]) and the Tet80 walks (`with_step_cap`), at every width.
#[test]
fn batched_shadow_walks_equal_single_ray_walks_at_low_step_caps() {
    let (m, cases) = scenes().swap_remove(0);
    let t20 = Tet20Tracer::<DuffF32>::new(&m).unwrap();
    let sctp = <SctpTracer<'_>>::new(&m).unwrap();
    let mut capped = 0;
    for cap in [0, 1, 2, 3, 5, 8] {
        let t80 = Tet80Tracer::new(&m).unwrap().with_step_cap(cap);
        for (light, r) in &cases {
            let stop = light.tets();
            check_tet80("tet80 capped", &t80, stop, r);
            let want: Vec<TraceOutcome> = r
                .rays
                .iter()
                .zip(&r.starts)
                .map(|(ray, s)| trace_until::<DuffF32, _>(&m, t20.layout(), ray, *s, stop, cap))
                .collect();
            capped += want.iter().filter(|o| o.is_failure()).count();
            for width in Width::ALL {
                let mut got = fresh(want.len());
                let starts = Starts::Each(&r.starts);
                let batch = Batch {
                    cap,
                    ..t20.batch(&r.rays, starts, &mut got)
                };
                DuffF32::trace_until_batch(batch, stop, width);
                assert_same(
                    "tet20 capped",
                    &format!("{width:?} cap {cap}"),
                    r,
                    &got,
                    &want,
                );
            }
            let want: Vec<TraceOutcome> = r
                .rays
                .iter()
                .zip(&r.starts)
                .map(|(ray, s)| trace_until::<TripleF32, _>(&m, sctp.layout(), ray, *s, stop, cap))
                .collect();
            let mut got = fresh(want.len());
            let starts = Starts::Each(&r.starts);
            let batch = Batch {
                cap,
                ..sctp.batch(&r.rays, starts, &mut got)
            };
            TripleF32::trace_until_batch(batch, stop, Width::Auto);
            assert_same("sctp capped", &format!("cap {cap}"), r, &got, &want);
        }
    }
    assert!(capped > 500, "walks stopped by the cap: {capped}");
}

/// Frames equal in every pixel and statistic (but the time).
fn assert_same_frame(name: &str, a: &Frame, b: &Frame) {
    let color = |f: &Frame| {
        f.color
            .iter()
            .map(|c| c.to_array().map(f32::to_bits))
            .collect::<Vec<_>>()
    };
    assert_eq!(color(a), color(b), "{name}: colours");
    assert_eq!(a.tets, b.tets, "{name}: tets");
    assert_eq!(a.triangle, b.triangle, "{name}: triangles");
    assert_eq!(a.stats.counts(), b.stats.counts(), "{name}: statistics");
}

/// The colours and shadow-ray statistics (rays, failures) of a render
/// with shadows, written out pixel by pixel as the renderer shaded before
/// its shadow rays were batched: each pixel's primary ray, then per point
/// light in front of the surface one shadow ray ([`trace_shadow`]).
fn reference_shading(
    t: &dyn Tracer,
    camera: &Camera,
    lights: &[PointLight],
    opts: &RenderOptions,
) -> (Vec<Vec3>, u64, u64) {
    let m = t.mesh();
    let view = Viewpoint::locate(m, camera.position).unwrap();
    let from = match view {
        Viewpoint::Inside(t) => t,
        Viewpoint::Outside(_) => 0,
    };
    let targets: Vec<LightTarget> = lights
        .iter()
        .map(|l| LightTarget::locate_or_outside(m, l.position, from).unwrap())
        .collect();
    let cam = PinholeCamera::new(camera, opts.width, opts.height, opts.pixel_centers);
    let (mut colors, mut rays, mut failures) = (Vec::new(), 0, 0);
    for j in 0..opts.height {
        for i in 0..opts.width {
            let ray = cam.ray(i, j);
            let mut out = [TraceOutcome::Miss { tets_visited: 0 }];
            view.trace_batch(t, &[ray], &mut out);
            let TraceOutcome::Hit(hit) = out[0] else {
                colors.push(Vec3::splat(opts.background));
                continue;
            };
            let (n, p) = (shading_normal(m, &hit), ray.at(hit.t));
            let mut c = Vec3::ZERO;
            for (light, target) in lights.iter().zip(&targets) {
                let cos = n
                    .dot((light.position - p).normalize_or_zero())
                    .clamp(0.0, 1.0);
                if cos <= 0.0 {
                    continue;
                }
                rays += 1;
                match trace_shadow(&OwnShadows(t), &hit, target) {
                    Some(TraceOutcome::Hit(_)) => continue,
                    Some(TraceOutcome::Failed { .. }) => failures += 1,
                    _ => {}
                }
                c += light.color * light.intensity * cos;
            }
            colors.push(c);
        }
    }
    (colors, rays, failures)
}

/// A render's shadow rays traced in batches give the image and statistics
/// of tracing them one by one ([`PerRay`]) and of the renderer's shading
/// before the batches ([`reference_shading`]): cameras inside and outside
/// the mesh, lights inside a tet, on a vertex and outside the mesh, every
/// kernel.
#[test]
fn renders_with_batched_shadows_equal_renders_ray_by_ray() {
    let m = grid(6, 0.1, 0.06, true, 5);
    let lights = [
        Vec3::new(0.7, 5.2, 4.9),
        Vec3::new(1.0, 1.0, 5.0),
        Vec3::new(9.0, 8.0, 7.5),
    ]
    .map(|position| PointLight {
        position,
        color: Vec3::ONE,
        intensity: 0.6,
    });
    let opts = RenderOptions {
        width: 64,
        height: 48,
        shadows: true,
        ..Default::default()
    };
    let cameras = [Vec3::new(0.6, 1.1, 5.4), Vec3::new(8.0, 7.0, 9.5)].map(|position| Camera {
        position,
        target: Vec3::splat(3.0),
        up: Vec3::Y,
        vfov_deg: 50.0,
    });
    let t20 = Tet20Tracer::<DuffF32>::new(&m).unwrap();
    let t16 = Tet16Tracer::<DuffF32>::new(&m).unwrap();
    let sctp = <SctpTracer<'_>>::new(&m).unwrap();
    let t80 = Tet80Tracer::new(&m).unwrap();
    // A low step cap: shadow walks that fail (and count as lit).
    let t80_capped = Tet80Tracer::new(&m).unwrap().with_step_cap(9);
    let tracers: [(&str, &dyn Tracer); 5] = [
        ("tet20", &t20),
        ("tet16", &t16),
        ("sctp", &sctp),
        ("tet80", &t80),
        ("tet80 capped", &t80_capped),
    ];
    let all = Lights {
        points: &lights,
        areas: &[],
    };
    for camera in &cameras {
        for (name, t) in tracers {
            let batched = render_scene_with(t, &OwnShadows(t), camera, &all, &opts).unwrap();
            let per_ray =
                render_scene_with(t, &PerRay(&OwnShadows(t)), camera, &all, &opts).unwrap();
            assert_same_frame(name, &batched, &per_ray);
            assert_same_frame(name, &render(t, camera, &lights, &opts).unwrap(), &per_ray);
            let (colors, rays, failures) = reference_shading(t, camera, &lights, &opts);
            let bits = |c: &[Vec3]| {
                c.iter()
                    .map(|c| c.to_array().map(f32::to_bits))
                    .collect::<Vec<_>>()
            };
            assert_eq!(bits(&batched.color), bits(&colors), "{name}: colours");
            assert_eq!(
                (batched.stats.shadow_rays, batched.stats.shadow_failures),
                (rays, failures),
                "{name}: shadow rays, failures"
            );
            assert_eq!(
                failures > 0,
                name == "tet80 capped",
                "{name}: {failures} failures"
            );
            // Shadows do fall, and from every light.
            let lit = render(
                t,
                camera,
                &lights,
                &RenderOptions {
                    shadows: false,
                    ..opts.clone()
                },
            )
            .unwrap();
            let shadowed = lit
                .color
                .iter()
                .zip(&batched.color)
                .filter(|(a, b)| a != b)
                .count();
            assert!(
                shadowed > 100 && batched.stats.shadow_rays > 1500,
                "{name}: {shadowed} shadowed pixels, {} shadow rays",
                batched.stats.shadow_rays
            );
        }
        // Another tracer's shadow walker, batched and ray by ray.
        let walker = MeshWalker::new(&m);
        let batched = render_scene_with(&t20, &walker, camera, &all, &opts).unwrap();
        let per_ray = render_scene_with(&t20, &PerRay(&walker), camera, &all, &opts).unwrap();
        assert_same_frame("mesh walker", &batched, &per_ray);
    }
}
