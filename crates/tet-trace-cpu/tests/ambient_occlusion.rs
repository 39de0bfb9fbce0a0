//! Ambient-occlusion rays (`render::ambient`): their directions are
//! cosine-distributed on the primary ray's side of the hit face; each
//! kernel's verdict (a constrained face within the AO length, or none)
//! agrees with an f64 brute force over every face; the batches a render
//! traces per tile give the outcomes of tracing each ray alone, bit for
//! bit; and a pixel of a render with AO is its pixel without AO plus the
//! ambient term exactly where its AO ray is open.

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::scene::{Camera, PointLight};
use tet_core::synthetic::SplitMix64;
use tet_trace_cpu::reference::{grazes_an_edge, random_direction, ray_triangle};
use tet_trace_cpu::render::ambient::{ao_length, ao_ray, ao_seed, cosine_direction};
use tet_trace_cpu::render::{AO_AMBIENT, PinholeCamera, RenderOptions, render};
use tet_trace_cpu::sctp::SctpTracer;
use tet_trace_cpu::secondary::face_normal;
use tet_trace_cpu::tet16::Tet16Tracer;
use tet_trace_cpu::tet20::Tet20Tracer;
use tet_trace_cpu::tet80::Tet80Tracer;
use tet_trace_cpu::walk::{BoundaryEntry, EntryHint};
use tet_trace_cpu::{DuffF32, Ray, Start, Starts, TraceOutcome, Tracer, Viewpoint};

mod common;
use common::{EDGE_TOL, bits, grid};

/// A tracer whose batches are traced ray by ray (the trait's defaults):
/// the reference for the batched walks.
struct OneByOne<'a>(&'a dyn Tracer);

impl Tracer for OneByOne<'_> {
    fn name(&self) -> String {
        format!("{} ray by ray", self.0.name())
    }
    fn mesh(&self) -> &TetMesh {
        self.0.mesh()
    }
    fn trace(&self, ray: &Ray, start: Start) -> TraceOutcome {
        self.0.trace(ray, start)
    }
    fn trace_within(&self, ray: &Ray, start: Start) -> TraceOutcome {
        self.0.trace_within(ray, start)
    }
    fn trace_batch_within(&self, rays: &[Ray], starts: Starts<'_>, out: &mut [TraceOutcome]) {
        let Starts::Each(s) = starts else {
            unreachable!("AO rays start on their faces")
        };
        for ((r, &s), o) in rays.iter().zip(s).zip(out.iter_mut()) {
            *o = self.0.trace_within(r, s);
        }
    }
    fn start_outside(
        &self,
        entry: &BoundaryEntry,
        ray: &Ray,
        hint: &mut EntryHint,
    ) -> Result<Start, TraceOutcome> {
        self.0.start_outside(entry, ray, hint)
    }
}

/// Whether `ray` (from a point of face `from`) meets a constrained face
/// other than `from` at `t ∈ (0, t_max]`, by brute force in f64; `None`
/// when that is decided by rounding (a crossing within [`EDGE_TOL`] of
/// either end, or the ray grazing an edge).
fn reference_occluded(mesh: &TetMesh, ray: &Ray, from: u32) -> Option<bool> {
    if grazes_an_edge(mesh, ray, EDGE_TOL) {
        return None;
    }
    let mut occluded = false;
    for (i, cf) in mesh.constrained.iter().enumerate() {
        if i as u32 == from {
            continue;
        }
        let v = cf.vertices.map(|k| mesh.points[k as usize]);
        let Some((t, _)) = ray_triangle(ray, v) else {
            continue;
        };
        let t_max = ray.t_max as f64;
        if t.abs() < EDGE_TOL || (t - t_max).abs() < EDGE_TOL * t_max.max(1.0) {
            return None;
        }
        occluded |= t > 0.0 && t <= t_max;
    }
    Some(occluded)
}

fn camera(position: Vec3) -> Camera {
    Camera {
        position,
        target: Vec3::splat(3.0),
        up: Vec3::Y,
        vfov_deg: 50.0,
    }
}

/// Cosine-distributed directions: unit, in the normal's hemisphere, with
/// the mean cosine 2/3 and the mean squared cosine 1/2 of that density.
#[test]
fn ao_directions_are_cosine_distributed() {
    let mut rng = SplitMix64(11);
    for _ in 0..20 {
        let n = random_direction(&mut rng);
        let (mut c1, mut c2) = (0.0f64, 0.0f64);
        let k = 20_000;
        for _ in 0..k {
            let d = cosine_direction(n, rng.next_f64() as f32, rng.next_f64() as f32);
            assert!((d.length() - 1.0).abs() < 1e-5, "{d}");
            let c = d.dot(n) as f64;
            assert!(c >= -1e-6, "{n} {d}");
            c1 += c;
            c2 += c * c;
        }
        let (m1, m2) = (c1 / k as f64, c2 / k as f64);
        assert!((m1 - 2.0 / 3.0).abs() < 0.01, "mean cosine {m1}");
        assert!((m2 - 0.5).abs() < 0.01, "mean squared cosine {m2}");
    }
}

/// Every kernel's AO verdicts, batched per tile as a render traces them,
/// against the f64 brute force, and bit for bit against the same rays
/// traced one by one; the walks bounded by the rays' length (as the
/// renderer traces them) find what the whole walks find, in fewer tets.
#[test]
fn ao_rays_agree_with_the_brute_force_and_with_single_rays() {
    let m = grid(6, 0.1, 0.08, true, 9);
    let t20 = Tet20Tracer::<DuffF32>::new(&m).unwrap();
    let t16 = Tet16Tracer::<DuffF32>::new(&m).unwrap();
    let sctp = <SctpTracer<'_>>::new(&m).unwrap();
    let t80 = Tet80Tracer::new(&m).unwrap();
    let tracers: [&dyn Tracer; 4] = [&t20, &t16, &sctp, &t80];
    let length = ao_length(&m, 0.3);
    assert!(length > 1.0 && length < 4.0, "{length}");
    let (mut checked, mut occluded) = (0, 0);
    // Tets walked by each tracer: bounded, whole.
    let mut tets = [(0u64, 0u64); 4];
    for position in [Vec3::new(0.6, 1.1, 5.4), Vec3::new(8.0, 7.0, 9.5)] {
        let cam = PinholeCamera::new(&camera(position), 48, 40, false);
        let view = Viewpoint::locate(&m, position).unwrap();
        let primary: Vec<Ray> = (0..40)
            .flat_map(|j| (0..48).map(move |i| (i, j)))
            .map(|(i, j)| cam.ray(i, j))
            .collect();
        let mut hits = vec![TraceOutcome::Miss { tets_visited: 0 }; primary.len()];
        view.trace_batch(&t20, &primary, &mut hits);
        let (mut rays, mut starts, mut from) = (Vec::new(), Vec::new(), Vec::new());
        for (k, (r, o)) in primary.iter().zip(&hits).enumerate() {
            let TraceOutcome::Hit(h) = o else { continue };
            if let Some((ray, start)) = ao_ray(&m, r, h, length, ao_seed(3, k as u32)) {
                // It leaves on the primary ray's side of the face.
                let n = face_normal(&m, h.face);
                assert!(ray.direction.dot(n) * r.direction.dot(n) < 0.0, "{ray:?}");
                rays.push(ray);
                starts.push(start);
                from.push(h.face);
            }
        }
        assert!(rays.len() > 500, "{} AO rays", rays.len());
        for (t, tets) in tracers.into_iter().zip(&mut tets) {
            let mut batched = vec![TraceOutcome::Miss { tets_visited: 0 }; rays.len()];
            t.trace_batch_within(&rays, Starts::Each(&starts), &mut batched);
            let mut single = batched.clone();
            OneByOne(t).trace_batch_within(&rays, Starts::Each(&starts), &mut single);
            let b: Vec<_> = batched.iter().map(bits).collect();
            let s: Vec<_> = single.iter().map(bits).collect();
            assert_eq!(b, s, "{}", t.name());
            let mut whole = batched.clone();
            t.trace_batch_from(&rays, Starts::Each(&starts), &mut whole);
            for (w, o) in whole.iter().zip(&batched) {
                assert_eq!(w.hit(), o.hit(), "{}: bounded {o:?}, whole {w:?}", t.name());
                assert!(o.tets_visited() <= w.tets_visited(), "{}", t.name());
                tets.0 += o.tets_visited() as u64;
                tets.1 += w.tets_visited() as u64;
            }
            for ((ray, o), &f) in rays.iter().zip(&batched).zip(&from) {
                assert!(!o.is_failure(), "{}: {o:?}", t.name());
                let Some(want) = reference_occluded(&m, ray, f) else {
                    continue;
                };
                assert_eq!(o.hit().is_some(), want, "{}: {ray:?} {o:?}", t.name());
                if let Some(h) = o.hit() {
                    assert_ne!(h.face, f, "{}: its own face", t.name());
                    assert!(h.t <= ray.t_max, "{}: {h:?}", t.name());
                }
                checked += 1;
                occluded += want as usize;
            }
        }
    }
    // The projected walks (Tet20, Tet16, ScTP) stop past the length; Tet80
    // walks whole.
    for (k, &(bounded, whole)) in tets.iter().enumerate() {
        eprintln!(
            "{}: {bounded} tets bounded, {whole} whole",
            tracers[k].name()
        );
        if k < 3 {
            assert!(bounded < whole, "{bounded} vs {whole}");
        }
    }
    assert!(
        checked > 4000 && occluded > checked / 10 && occluded < checked * 9 / 10,
        "{checked} checked, {occluded} occluded"
    );
}

/// A render with AO: batched and ray by ray the same frame, and each pixel
/// its colour without AO plus [`AO_AMBIENT`] exactly where its own AO ray
/// (rebuilt from its seed and traced alone) finds nothing.
#[test]
fn renders_with_ao_add_the_ambient_term_where_the_ray_is_open() {
    let m = grid(6, 0.1, 0.08, true, 4);
    let lights = [PointLight {
        position: Vec3::new(0.7, 5.2, 4.9),
        color: Vec3::ONE,
        intensity: 0.6,
    }];
    let opts = RenderOptions {
        width: 40,
        height: 32,
        shadows: true,
        ambient_occlusion: true,
        ao_share: 0.3,
        seed: 5,
        ..Default::default()
    };
    let plain = RenderOptions {
        ambient_occlusion: false,
        ..opts.clone()
    };
    let t20 = Tet20Tracer::<DuffF32>::new(&m).unwrap();
    let t16 = Tet16Tracer::<DuffF32>::new(&m).unwrap();
    let length = ao_length(&m, opts.ao_share);
    for position in [Vec3::new(0.6, 1.1, 5.4), Vec3::new(8.0, 7.0, 9.5)] {
        let cam = camera(position);
        let pinhole = PinholeCamera::new(&cam, opts.width, opts.height, false);
        for t in [&t20 as &dyn Tracer, &t16] {
            let with = render(t, &cam, &lights, &opts).unwrap();
            let alone = render(&OneByOne(t), &cam, &lights, &opts).unwrap();
            let colour_bits = |c: &[Vec3]| {
                c.iter()
                    .map(|c| c.to_array().map(f32::to_bits))
                    .collect::<Vec<_>>()
            };
            assert_eq!(
                colour_bits(&with.color),
                colour_bits(&alone.color),
                "{}",
                t.name()
            );
            assert_eq!(with.stats.counts(), alone.stats.counts(), "{}", t.name());
            let without = render(t, &cam, &lights, &plain).unwrap();
            assert_eq!(without.stats.ao_rays, 0);
            let (mut open, mut cast) = (0, 0);
            for k in 0..with.color.len() {
                let (i, j) = (k as u32 % opts.width, k as u32 / opts.width);
                let primary = pinhole.ray(i, j);
                let expected_open = match alone.triangle[k] {
                    u32::MAX => false,
                    _ => {
                        let mut hit = vec![TraceOutcome::Miss { tets_visited: 0 }];
                        let view = Viewpoint::locate(&m, position).unwrap();
                        view.trace_batch(t, &[primary], &mut hit);
                        let h = *hit[0].hit().unwrap();
                        match ao_ray(&m, &primary, &h, length, ao_seed(opts.seed, k as u32)) {
                            None => true,
                            Some((ray, start)) => {
                                cast += 1;
                                t.trace(&ray, start).hit().is_none()
                            }
                        }
                    }
                };
                open += expected_open as usize;
                let add = if expected_open { AO_AMBIENT } else { 0.0 };
                assert_eq!(
                    with.color[k],
                    without.color[k] + Vec3::splat(add),
                    "{} pixel {k}",
                    t.name()
                );
            }
            assert_eq!(with.stats.ao_rays, cast, "{}", t.name());
            assert!(
                open > 50 && open < cast as usize,
                "{}: {open} open of {cast}",
                t.name()
            );
        }
    }
}
