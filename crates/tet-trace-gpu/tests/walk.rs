//! GPU kernels (Tet20, Tet32, Tet16 projected walks; Tet80 Plücker walk)
//! against the CPU kernels of the same layout and an f64 brute-force
//! reference on procedural meshes (`tet_core::synthetic::kuhn_grid`).
//!
//! Runs on any wgpu adapter; without a GPU, install lavapipe
//! (`apt-get install -y mesa-vulkan-drivers`). When no adapter is found the
//! tests print a skip message, unless `TET_GPU_REQUIRED=1` is set (CI), which
//! turns that into a failure.
//!
//! Tolerance: a ray is *grazing* when its line passes within [`GRAZE`] of an
//! edge of some constrained face (`reference::grazes_an_edge`); only there may
//! the hit triangle legitimately depend on rounding. Every other ray must hit
//! the same triangle as the brute force, and the GPU walk must equal the CPU
//! walk (same face, same tets visited). Tet80 is not watertight (on the CPU
//! either): there the GPU must equal the CPU, and disagreements with the
//! brute force are counted and printed (see `check`). Where a walk lost its
//! way (the default step cap, or no start), the CPU tracers and the GPU
//! tracer (on the host) both take the exact walk from the same start, so
//! the outcomes must be equal there too (see
//! `lost_walks_are_rewalked_exactly_on_the_host` and
//! `lost_camera_rays_are_rewalked_exactly_on_the_host`).

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::scene::Camera;
use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};
use tet_trace_cpu::reference::{axis_ray, closest_hit, grazes_an_edge};
use tet_trace_cpu::render::PinholeCamera;
use tet_trace_cpu::tet16::Tet16Tracer;
use tet_trace_cpu::tet20::Tet20Tracer;
use tet_trace_cpu::tet32::Tet32Tracer;
use tet_trace_cpu::tet80::Tet80Tracer;
use tet_trace_cpu::{Failure, Ray, Start, TraceOutcome, Tracer, Viewpoint, locate};
use tet_trace_gpu::{GpuContext, GpuError, GpuFrame, GpuLayout, GpuOptions, GpuTracer};

mod common;
use common::{GRAZE, gpu, gpu_with, random_rays, shell_in_view};

/// Same walk: same outcome kind, face and tets visited (t and barycentrics
/// may differ in the last bits: f32 on the GPU, f64 on the CPU).
fn same_walk(a: &TraceOutcome, b: &TraceOutcome) -> bool {
    match (a, b) {
        (TraceOutcome::Hit(x), TraceOutcome::Hit(y)) => {
            x.face == y.face
                && x.triangle == y.triangle
                && x.tet == y.tet
                && x.far_tet == y.far_tet
                && x.tets_visited == y.tets_visited
        }
        _ => a == b,
    }
}

/// True when `o` is a hit on a face the ray runs along (within a millionth
/// of a radian of its plane): there the CPU reports the point of the face
/// along the ray and the GPU the crossing with the plane in f32, so their
/// `t < t_min` decisions (cross on, or hit) may differ (see the crate docs,
/// "Hit point").
fn along_a_face(mesh: &TetMesh, ray: &Ray, o: &TraceOutcome) -> bool {
    let Some(h) = o.hit() else { return false };
    let v = mesh.constrained[h.face as usize]
        .vertices
        .map(|k| mesh.points[k as usize].as_dvec3());
    let n = (v[1] - v[0]).cross(v[2] - v[0]);
    let d = ray.direction.as_dvec3();
    n.dot(d).abs() <= 1e-6 * n.length() * d.length()
}

/// Walks that differ from the CPU's, and those of them at a hit along a
/// face ([`along_a_face`]), which the GPU decides in f32.
fn differences(
    mesh: &TetMesh,
    rays: &[Ray],
    gpu: &[TraceOutcome],
    cpu: &[TraceOutcome],
) -> (usize, usize) {
    let (mut differ, mut along) = (0, 0);
    for ((r, g), c) in rays.iter().zip(gpu).zip(cpu) {
        if !same_walk(g, c) {
            if along_a_face(mesh, r, g) || along_a_face(mesh, r, c) {
                along += 1;
            } else {
                differ += 1;
            }
        }
    }
    (differ, along)
}

/// True when a walk lost its way (its step cap, or no start): where a
/// tracer at the default cap re-walks the ray with the exact walk
/// (`tet_trace_cpu::lost` on the CPU, the host-side fallback on the GPU).
fn lost(o: &TraceOutcome) -> bool {
    matches!(
        o,
        TraceOutcome::Failed {
            failure: Failure::StepCap | Failure::Lost,
            ..
        }
    )
}

fn triangle_of(o: &TraceOutcome) -> Option<u32> {
    o.hit().map(|h| h.triangle)
}

/// Compares GPU outcomes with the CPU kernel of the same layout (same walk
/// on every non-grazing ray) and with the brute force (same triangle on every
/// non-grazing ray). Tet80's Plücker walk is not watertight: where a ray runs
/// exactly through a mesh vertex it can leave the ray's line, on the CPU as
/// well, so for Tet80 brute-force disagreements are counted and printed (and
/// the GPU must still reproduce the CPU). Returns the number of walks that
/// differ from the CPU.
fn check(
    mesh: &TetMesh,
    layout: GpuLayout,
    rays: &[Ray],
    gpu: &[TraceOutcome],
    cpu: &[TraceOutcome],
) -> usize {
    let mut wrong = 0;
    let mut grazing = 0;
    let mut differ = 0;
    let mut bits_differ = 0;
    let cap = tet_trace_cpu::walk::step_cap(mesh);
    let mut exact = 0;
    for (i, ((ray, g), c)) in rays.iter().zip(gpu).zip(cpu).enumerate() {
        let graze = grazes_an_edge(mesh, ray, GRAZE);
        // Where the CPU walk lost its way (the step cap) its tracer took
        // the exact walk (`tet_trace_cpu::lost`), and so does the GPU
        // tracer on the host: the same ray from the same start, so the
        // same outcome bit for bit (both walks' tets counted), unless the
        // ray grazes an edge (where the GPU walk may not have been capped).
        if c.tets_visited() >= cap {
            assert!(
                g == c || graze,
                "{layout:?} ray {i} {ray:?}: the CPU walk was capped (then exact: {c:?}), \
                 the GPU gave {g:?}"
            );
            exact += 1;
        }
        let tet80_as_cpu = layout == GpuLayout::Tet80 && same_walk(g, c);
        assert!(
            !g.is_failure() || graze || tet80_as_cpu,
            "{layout:?} ray {i} {ray:?}: GPU failed: {g:?}, CPU {c:?}"
        );
        if g.is_failure() && !graze {
            wrong += 1;
            continue;
        }
        assert!(
            !g.is_failure() || graze,
            "ray {i} {ray:?}: GPU failed: {g:?}"
        );
        grazing += graze as usize;
        if !same_walk(g, c) {
            differ += 1;
            assert!(graze, "ray {i} {ray:?}: GPU {g:?} != CPU {c:?}");
            continue;
        }
        if g != c {
            bits_differ += 1;
        }
        if graze {
            continue;
        }
        let r = closest_hit(mesh, ray);
        if layout == GpuLayout::Tet80 && triangle_of(g) != r.map(|h| h.triangle) {
            wrong += 1;
            continue;
        }
        assert_eq!(
            triangle_of(g),
            r.map(|h| h.triangle),
            "ray {i} {ray:?}: GPU {g:?} vs brute force {r:?}"
        );
        if let (Some(h), Some(r)) = (g.hit(), r) {
            let scale = ray.direction.length() as f64;
            assert!(
                (h.t as f64 - r.t).abs() * scale < 1e-4 * (1.0 + r.t * scale),
                "ray {i}: t {} vs {}",
                h.t,
                r.t
            );
            for k in 0..3 {
                assert!(
                    (h.barycentrics[k] as f64 - r.barycentrics[k]).abs() < 1e-3,
                    "ray {i}: barycentrics {:?} vs {:?}",
                    h.barycentrics,
                    r.barycentrics
                );
            }
        }
    }
    eprintln!(
        "{layout:?}: {} rays: {grazing} grazing, {differ} walks differ from the CPU (all \
         grazing), {bits_differ} same walks with different t/barycentric bits, {wrong} \
         non-grazing rays disagree with the brute force or fail (CPU and GPU alike); \
         {exact} CPU walks capped, where CPU and GPU took the exact walk",
        rays.len()
    );
    differ
}

/// The CPU kernel of the same layout (f32 Duff projection).
fn cpu_tracer(mesh: &TetMesh, layout: GpuLayout, cap: Option<u32>) -> Box<dyn Tracer + '_> {
    let cap = cap.unwrap_or(tet_trace_cpu::walk::step_cap(mesh));
    match layout {
        GpuLayout::Tet20 => {
            let t: Tet20Tracer = Tet20Tracer::new(mesh).unwrap();
            Box::new(t.with_step_cap(cap))
        }
        GpuLayout::Tet32 => {
            let t: Tet32Tracer = Tet32Tracer::new(mesh).unwrap();
            Box::new(t.with_step_cap(cap))
        }
        GpuLayout::Tet16 => {
            let t: Tet16Tracer = Tet16Tracer::new(mesh).unwrap();
            Box::new(t.with_step_cap(cap))
        }
        GpuLayout::Tet80 => Box::new(Tet80Tracer::new(mesh).unwrap().with_step_cap(cap)),
    }
}

fn cpu_trace(
    mesh: &TetMesh,
    layout: GpuLayout,
    rays: &[Ray],
    starts: &[Start],
    cap: Option<u32>,
) -> Vec<TraceOutcome> {
    let cpu = cpu_tracer(mesh, layout, cap);
    rays.iter()
        .zip(starts)
        .map(|(r, &s)| cpu.trace(r, s))
        .collect()
}

#[test]
fn random_faces_agree_with_cpu_and_brute_force() {
    let Some(ctx) = gpu() else { return };
    let mesh = kuhn_grid(&GridSpec {
        cells: [5, 5, 5],
        jitter: 0.12,
        constrained_fraction: 0.15,
        seed: 11,
        ..Default::default()
    });
    for layout in GpuLayout::ALL {
        eprintln!("layout {layout:?}");
        random_faces_case(&ctx, &mesh, layout);
    }
}

fn random_faces_case(ctx: &GpuContext, mesh: &TetMesh, layout: GpuLayout) {
    let gpu = GpuTracer::new(ctx, mesh, layout).unwrap();
    let (mut rays, mut starts) = random_rays(mesh, 2000, 5);
    // An invalid ray and an out-of-range start tet: reported, not traced.
    rays.push(Ray::new(Vec3::splat(1.0), Vec3::new(f32::NAN, 0.0, 1.0)));
    starts.push(Start::Tet(0));
    rays.push(Ray::new(Vec3::splat(1.0), Vec3::X));
    starts.push(Start::Tet(u32::MAX - 1));
    let (out, stats) = gpu.trace_batch(&rays, &starts).unwrap();
    let cpu = cpu_trace(mesh, layout, &rays, &starts, None);
    let n = rays.len();
    assert_eq!(out[n - 2], cpu[n - 2]);
    assert!(matches!(
        out[n - 2],
        TraceOutcome::Failed {
            failure: Failure::InvalidRay,
            ..
        }
    ));
    assert!(matches!(
        out[n - 1],
        TraceOutcome::Failed {
            failure: Failure::Lost,
            ..
        }
    ));
    check(mesh, layout, &rays[..n - 2], &out[..n - 2], &cpu[..n - 2]);
    assert_eq!(stats.rays, n as u64);
    let failures = out.iter().filter(|o| o.is_failure()).count() as u64;
    assert_eq!(stats.failures, failures);
    if layout != GpuLayout::Tet80 {
        assert_eq!(failures, 2);
    }
    assert_eq!(
        stats.hits,
        out.iter().filter(|o| o.hit().is_some()).count() as u64
    );
    assert!(stats.hits > 500, "too few hits to be a test: {stats:?}");
    eprintln!("{stats:?}, memory {:?}", gpu.memory());

    // Secondary rays: continue every hit with a far side through its face.
    let (mut rays2, mut starts2) = (Vec::new(), Vec::new());
    for (r, o) in rays.iter().zip(&out) {
        if let Some(h) = o.hit()
            && h.has_far_side()
        {
            rays2.push(Ray::new(r.at(h.t), r.direction));
            starts2.push(Start::Face {
                face: h.face,
                tet: h.far_tet,
            });
        }
    }
    let (out2, _) = gpu.trace_batch(&rays2, &starts2).unwrap();
    let cpu2 = cpu_trace(mesh, layout, &rays2, &starts2, None);
    let mut differ = 0;
    let cap = tet_trace_cpu::walk::step_cap(mesh);
    for (i, (g, c)) in out2.iter().zip(&cpu2).enumerate() {
        if c.tets_visited() >= cap {
            // The CPU walk was capped and its tracer took the exact walk
            // (`tet_trace_cpu::lost`), as the GPU tracer does on the host:
            // the same outcome, or the ray grazes an edge (where the GPU
            // walk may not have been capped).
            assert!(
                g == c || grazes_an_edge(mesh, &rays2[i], GRAZE),
                "secondary ray {i}: the CPU walk was capped (then exact: {c:?}), the GPU \
                 gave {g:?}"
            );
        }
        assert!(
            !g.is_failure()
                || grazes_an_edge(mesh, &rays2[i], GRAZE)
                || (layout == GpuLayout::Tet80 && same_walk(g, c)),
            "secondary ray {i} {:?}: GPU {g:?}, CPU {c:?}",
            rays2[i]
        );
        if !same_walk(g, c) {
            differ += 1;
            assert!(
                grazes_an_edge(mesh, &rays2[i], GRAZE),
                "secondary ray {i} {:?}: GPU {g:?} != CPU {c:?}",
                rays2[i]
            );
        }
    }
    eprintln!("{} secondary rays, {differ} differ (grazing)", rays2.len());
}

#[test]
fn closed_shell_is_watertight() {
    let Some(ctx) = gpu() else { return };
    let mesh = kuhn_grid(&GridSpec {
        cells: [5, 5, 5],
        jitter: 0.1,
        shell: Some(([1, 1, 1], [4, 4, 4])),
        seed: 3,
        ..Default::default()
    });
    let (rays, starts) = random_rays(&mesh, 1500, 9);
    for layout in GpuLayout::ALL {
        let gpu = GpuTracer::new(&ctx, &mesh, layout).unwrap();
        let (out, _) = gpu.trace_batch(&rays, &starts).unwrap();
        let cpu = cpu_trace(&mesh, layout, &rays, &starts, None);
        check(&mesh, layout, &rays, &out, &cpu);
        shell_rays_hit(layout, &rays, &out);
    }
}

/// Rays starting strictly inside the shell must hit it. The projected walks
/// are watertight, so that holds for every ray; the Plücker walk (Tet80) is
/// not (see [`check`]): its escapes are counted and printed.
fn shell_rays_hit(layout: GpuLayout, rays: &[Ray], out: &[TraceOutcome]) {
    // Jitter moves shell vertices by at most 0.15: an origin in
    // [1.2, 3.8]^3 is strictly inside the shell, so every such ray must hit
    // it, grazing or not.
    let mut inside = 0;
    let mut escaped = 0;
    for (r, o) in rays.iter().zip(out) {
        if r.origin.cmpgt(Vec3::splat(1.2)).all() && r.origin.cmplt(Vec3::splat(3.8)).all() {
            inside += 1;
            if o.hit().is_none() {
                escaped += 1;
                assert_eq!(
                    layout,
                    GpuLayout::Tet80,
                    "{layout:?}: ray {r:?} escaped the shell: {o:?}"
                );
            }
        }
    }
    assert!(inside > 100, "only {inside} rays inside the shell");
    eprintln!("{layout:?}: {escaped} of {inside} rays from inside escaped the shell");
}

/// A 4³ Kuhn grid without jitter (every face in an axis or diagonal plane),
/// 30 % of its faces constrained.
fn unjittered_grid(seed: u64) -> TetMesh {
    kuhn_grid(&GridSpec {
        cells: [4, 4, 4],
        jitter: 0.0,
        constrained_fraction: 0.3,
        seed,
        ..Default::default()
    })
}

/// The tet holding each ray's origin.
fn located(mesh: &TetMesh, rays: &[Ray]) -> Vec<Start> {
    rays.iter()
        .map(|r| Start::Tet(locate(mesh, r.origin, 0).unwrap()))
        .collect()
}

#[test]
fn exact_ties_on_an_unjittered_grid_match_the_cpu() {
    // Axis-aligned rays through vertices, along edges and in face planes:
    // every decision is a tie-rule decision.
    let Some(ctx) = gpu() else { return };
    let mesh = unjittered_grid(5);
    let mut rng = SplitMix64(21);
    let rays: Vec<Ray> = (0..600)
        .map(|_| axis_ray(&mut rng, Vec3::ZERO, Vec3::splat(4.0)))
        .collect();
    let starts = located(&mesh, &rays);
    for layout in GpuLayout::ALL {
        let gpu = GpuTracer::new(&ctx, &mesh, layout).unwrap();
        let (out, _) = gpu.trace_batch(&rays, &starts).unwrap();
        let cpu = cpu_trace(&mesh, layout, &rays, &starts, None);
        for (i, g) in out.iter().enumerate() {
            assert!(!g.is_failure(), "{layout:?} ray {i} {:?}: {g:?}", rays[i]);
        }
        let (differ, along) = differences(&mesh, &rays, &out, &cpu);
        eprintln!(
            "{layout:?}: {} tie-rule rays, {differ} walks differ from the CPU ({along} more at \
             a hit along a face)",
            rays.len()
        );
        assert_eq!(differ, 0, "{layout:?}: tie decisions differ from the CPU");
    }
}

/// Rays lying in the grid's planes in every direction of the plane (not
/// only along the axes), from points of the plane: every vertex of the
/// plane projects to within rounding of one line through the ray, and
/// equal rounded products must be decided by the exact determinant
/// (`product_error` in WGSL, `ExactDet` on the CPU), or the walks circle
/// to the step cap. Every GPU and CPU walk of the 2-D layouts must end.
#[test]
fn rays_in_grid_planes_end() {
    let Some(ctx) = gpu() else { return };
    let mesh = unjittered_grid(9);
    let mut rng = SplitMix64(31);
    let rays: Vec<Ray> = (0..900)
        .map(|i| {
            let axis = i % 3;
            let level = (1 + rng.next_u64() % 3) as f32;
            let a = rng.next_f64() as f32 * std::f32::consts::TAU;
            let (u, v) = (
                0.2 + 3.6 * rng.next_f64() as f32,
                0.2 + 3.6 * rng.next_f64() as f32,
            );
            let mut o = [u, v, 0.0];
            let mut d = [a.cos(), a.sin(), 0.0];
            o.rotate_right(axis);
            d.rotate_right(axis);
            o[axis] = level;
            Ray::new(Vec3::from_array(o), Vec3::from_array(d))
        })
        .collect();
    let starts = located(&mesh, &rays);
    for layout in GpuLayout::ALL {
        let gpu = GpuTracer::new(&ctx, &mesh, layout).unwrap();
        let (out, _) = gpu.trace_batch(&rays, &starts).unwrap();
        let cpu = cpu_trace(&mesh, layout, &rays, &starts, None);
        for (i, (g, c)) in out.iter().zip(&cpu).enumerate() {
            if layout != GpuLayout::Tet80 {
                assert!(!g.is_failure(), "{layout:?} ray {i} {:?}: {g:?}", rays[i]);
                assert!(
                    !c.is_failure(),
                    "CPU {layout:?} ray {i} {:?}: {c:?}",
                    rays[i]
                );
            }
        }
        let (differ, along) = differences(&mesh, &rays, &out, &cpu);
        eprintln!(
            "{layout:?}: {} rays in grid planes, {differ} walks differ from the CPU ({along} \
             more at a hit along a face)",
            rays.len()
        );
        // Not asserted equal: every vertex of the plane projects to within
        // rounding of the ray, so the driver's own rounding of the
        // projection (fused multiply-adds, see the crate docs) picks
        // among equally valid walks far more often than in general
        // position.
        let _ = differ;
    }
}

/// Renders `camera` on the GPU and compares every pixel with the CPU Tet20
/// kernel on the CPU camera's ray; returns the frame.
fn camera_case(
    ctx: &GpuContext,
    layout: GpuLayout,
    mesh: &TetMesh,
    camera: &Camera,
    w: u32,
    h: u32,
) -> GpuFrame {
    let view = Viewpoint::locate(mesh, camera.position).unwrap();
    let gpu = GpuTracer::new(ctx, mesh, layout).unwrap();
    let frame = gpu.render_view(camera, w, h, false, &view).unwrap();
    assert_eq!(frame.outcomes.len(), (w * h) as usize);
    let cam = PinholeCamera::new(camera, w, h, false);
    let cpu = cpu_tracer(mesh, layout, None);
    let mut grazing = 0;
    let mut differ = 0;
    for j in 0..h {
        for i in 0..w {
            let ray = cam.ray(i, j);
            let g = &frame.outcomes[(j * w + i) as usize];
            let c = match view.start(cpu.as_ref(), &ray) {
                Ok(s) => cpu.trace(&ray, s),
                Err(done) => done,
            };
            let graze = grazes_an_edge(mesh, &ray, GRAZE);
            assert!(
                !g.is_failure() || (layout == GpuLayout::Tet80 && same_walk(g, &c)),
                "{layout:?} pixel ({i}, {j}): {g:?}"
            );
            grazing += graze as usize;
            if !same_walk(g, &c) {
                differ += 1;
                assert!(
                    graze,
                    "{layout:?} pixel ({i}, {j}) {ray:?}: GPU {g:?} != CPU {c:?}"
                );
            }
        }
    }
    let hits = frame.outcomes.iter().filter(|o| o.hit().is_some()).count();
    assert_eq!(frame.stats.hits, hits as u64);
    assert_eq!(frame.stats.rays, (w * h) as u64);
    let failures = frame.outcomes.iter().filter(|o| o.is_failure()).count();
    assert_eq!(frame.stats.failures, failures as u64);
    eprintln!(
        "{layout:?} camera {w}x{h}: {grazing} grazing, {differ} differ, {} re-traced, {:?}",
        frame.retraced, frame.stats
    );
    frame
}

#[test]
fn camera_rays_generated_on_the_gpu_match_the_cpu_camera() {
    let Some(ctx) = gpu() else { return };
    let (mesh, camera) = shell_in_view();
    for layout in GpuLayout::ALL {
        let frame = camera_case(&ctx, layout, &mesh, &camera, 40, 30);
        let hits = frame.outcomes.iter().filter(|o| o.hit().is_some()).count();
        assert!(
            hits > 200,
            "the shell should fill much of the image: {hits}"
        );
    }
    // From outside the mesh (a tight enclosing box): rays enter through the
    // boundary, chosen on the host; the rays around the mesh visit no tet.
    let outside = Camera {
        position: Vec3::new(7.0, 6.0, 9.0),
        ..camera
    };
    for layout in GpuLayout::ALL {
        let frame = camera_case(&ctx, layout, &mesh, &outside, 40, 30);
        let hits = frame.outcomes.iter().filter(|o| o.hit().is_some()).count();
        let untouched = frame
            .outcomes
            .iter()
            .filter(|o| o.tets_visited() == 0)
            .count();
        assert!(
            hits > 100 && untouched > 50,
            "{layout:?}: {hits} hits, {untouched} untouched"
        );
    }
}

#[test]
fn camera_on_a_mesh_vertex_retraces_lost_starts() {
    // The eye sits exactly on a grid vertex: for most directions no face of
    // the located tet winds around it, so the GPU start fails and those rays
    // go through the batch path (the CPU's start over the vertex star).
    let Some(ctx) = gpu() else { return };
    let mesh = kuhn_grid(&GridSpec {
        cells: [4, 4, 4],
        jitter: 0.0,
        shell: Some(([2, 1, 1], [3, 3, 3])),
        seed: 6,
        ..Default::default()
    });
    let camera = Camera {
        position: Vec3::new(1.0, 2.0, 1.0),
        target: Vec3::new(2.5, 2.0, 2.0),
        up: Vec3::Y,
        vfov_deg: 45.0,
    };
    for layout in GpuLayout::ALL {
        let frame = camera_case(&ctx, layout, &mesh, &camera, 16, 12);
        assert!(frame.retraced > 0, "no ray needed the batch start");
    }
}

#[test]
fn step_cap_is_reported_like_the_cpu() {
    let Some(ctx) = gpu() else { return };
    let mesh = kuhn_grid(&GridSpec {
        cells: [6, 6, 6],
        jitter: 0.1,
        seed: 2,
        ..Default::default()
    });
    let cap = 4;
    let (rays, starts) = random_rays(&mesh, 400, 13);
    for layout in GpuLayout::ALL {
        let gpu = GpuTracer::new(&ctx, &mesh, layout)
            .unwrap()
            .with_step_cap(cap);
        let (out, stats) = gpu.trace_batch(&rays, &starts).unwrap();
        let cpu = cpu_trace(&mesh, layout, &rays, &starts, Some(cap));
        step_cap_case(cap, &out, &cpu, stats.failures);
    }
}

fn step_cap_case(cap: u32, out: &[TraceOutcome], cpu: &[TraceOutcome], failures: u64) {
    let mut capped = 0;
    for (i, (g, c)) in out.iter().zip(cpu).enumerate() {
        if let TraceOutcome::Failed {
            failure,
            tets_visited,
        } = g
        {
            assert_eq!(*failure, Failure::StepCap, "ray {i}");
            assert_eq!(*tets_visited, cap, "ray {i}");
            capped += 1;
        }
        // Without constrained faces there is nothing to graze: every walk
        // must match the CPU.
        assert!(same_walk(g, c), "ray {i}: GPU {g:?} != CPU {c:?}");
    }
    assert!(capped > 100, "only {capped} rays reached the cap");
    assert_eq!(failures, capped as u64);
}

#[test]
fn limits_give_typed_errors_and_split_buffers_and_batches() {
    let mesh = kuhn_grid(&GridSpec {
        cells: [3, 3, 3],
        jitter: 0.1,
        constrained_fraction: 0.05,
        seed: 4,
        ..Default::default()
    });
    // 162 tets × 20 B = 3240 B of Tet20 records; with a 256 B cap they would
    // need 13 bindings of 256 B, more than the 4 the kernels use.
    let Some(tiny) = gpu_with(&GpuOptions {
        max_buffer_bytes: Some(256),
        ..Default::default()
    }) else {
        return;
    };
    match GpuTracer::new(&tiny, &mesh, GpuLayout::Tet20) {
        Err(GpuError::TooLarge {
            buffer,
            bytes,
            limit,
            value,
        }) => {
            assert_eq!(buffer, "tet records");
            assert_eq!(bytes, 20 * mesh.tets.len() as u64);
            assert!(limit.starts_with("max_storage_buffer_binding_size"));
            assert_eq!(value, 256);
        }
        Err(e) => panic!("wrong error: {e}"),
        Ok(_) => panic!("a mesh over the limit was accepted"),
    }
    // A 4 KiB cap: records split over ceil(bytes / 4096) bindings, and only
    // 64 rays (64 B each) per dispatch; results equal the unsplit run.
    let cap = 4096u64;
    let small = gpu_with(&GpuOptions {
        max_buffer_bytes: Some(cap),
        ..Default::default()
    })
    .unwrap();
    let full_ctx = gpu().unwrap();
    let (rays, starts) = random_rays(&mesh, 1000, 8);
    for layout in GpuLayout::ALL {
        let split = GpuTracer::new(&small, &mesh, layout).unwrap();
        let bytes = (layout.record_bytes() * mesh.tets.len()) as u64;
        assert_eq!(
            split.tet_bindings() as u64,
            bytes.div_ceil(cap),
            "{layout:?}"
        );
        let (a, sa) = split.trace_batch(&rays, &starts).unwrap();
        assert_eq!(sa.dispatches, 1000u32.div_ceil(64));
        let full = GpuTracer::new(&full_ctx, &mesh, layout).unwrap();
        assert_eq!(full.tet_bindings(), 1);
        let (b, sb) = full.trace_batch(&rays, &starts).unwrap();
        assert_eq!(sb.dispatches, 1);
        assert_eq!(a, b, "{layout:?}");
        assert!(a.iter().filter(|o| o.hit().is_some()).count() > 100);
    }
}

/// The host-side fallback on real dispatches: a tracer at the default step
/// cap against the same tracer one step below it (where a lost walk keeps
/// its failure, as on the CPU). Every walk that the lower cap reports lost
/// (its step cap, or no start) is, at the default cap, the exact walk from
/// the same start with both walks' tets, counted in
/// `DispatchStats::host_rewalks`; every other walk is the same; and the
/// outcomes equal the CPU tracer's wherever the walks agree.
fn fallback_case(
    ctx: &GpuContext,
    mesh: &TetMesh,
    layout: GpuLayout,
    rays: &[Ray],
    starts: &[Start],
) -> (usize, usize) {
    let cap = tet_trace_cpu::walk::step_cap(mesh);
    let gpu = GpuTracer::new(ctx, mesh, layout).unwrap();
    assert_eq!(gpu.step_cap(), cap);
    let raw_gpu = GpuTracer::new(ctx, mesh, layout)
        .unwrap()
        .with_step_cap(cap - 1);
    let (out, stats) = gpu.trace_batch(rays, starts).unwrap();
    let (raw, raw_stats) = raw_gpu.trace_batch(rays, starts).unwrap();
    assert_eq!(
        raw_stats.host_rewalks, 0,
        "{layout:?}: a lower cap re-walks nothing"
    );
    let exact = tet_trace_cpu::exact::ExactTracer::new(mesh);
    let mut rewalked = 0;
    for (i, (o, r)) in out.iter().zip(&raw).enumerate() {
        if !lost(r) {
            assert_eq!(o, r, "{layout:?} ray {i}: not lost, yet changed");
            continue;
        }
        rewalked += 1;
        // The tets of the GPU walk: at the default cap, one more than the
        // lower cap's where that stopped the walk.
        let spent = match r {
            TraceOutcome::Failed {
                failure: Failure::StepCap,
                ..
            } => cap,
            _ => r.tets_visited(),
        };
        let mut want = exact.trace(&rays[i], starts[i]);
        match &mut want {
            TraceOutcome::Hit(h) => h.tets_visited += spent,
            TraceOutcome::Miss { tets_visited } | TraceOutcome::Failed { tets_visited, .. } => {
                *tets_visited += spent
            }
        }
        assert_eq!(*o, want, "{layout:?} ray {i}: lost as {r:?}");
    }
    assert_eq!(stats.host_rewalks, rewalked as u64, "{layout:?}");
    assert_eq!(
        stats.tets_visited,
        out.iter().map(|o| o.tets_visited() as u64).sum()
    );
    let cpu = cpu_trace(mesh, layout, rays, starts, None);
    let differ = out
        .iter()
        .zip(&cpu)
        .filter(|(g, c)| !same_walk(g, c))
        .count();
    let fixed = out
        .iter()
        .zip(&raw)
        .zip(&cpu)
        .filter(|((o, r), c)| lost(r) && same_walk(o, c))
        .count();
    let recovered = out
        .iter()
        .zip(&raw)
        .filter(|(o, r)| lost(r) && !o.is_failure())
        .count();
    eprintln!(
        "{layout:?}: {} rays, {rewalked} lost on the GPU and re-walked on the host ({recovered} \
         no longer failed, {fixed} now as the CPU tracer, {:.2} ms), {differ} walks differ \
         from the CPU",
        rays.len(),
        stats.host_rewalk_ms
    );
    (rewalked, recovered)
}

#[test]
fn lost_walks_are_rewalked_exactly_on_the_host() {
    let Some(ctx) = gpu() else { return };
    // Axis rays through the vertices of an unjittered grid (where the
    // Plücker walk of Tet80, not watertight, loses its start or its way),
    // and random rays on a jittered one; plus starts that cannot start.
    let grid = unjittered_grid(5);
    let mut rng = SplitMix64(21);
    let mut rays: Vec<Ray> = (0..600)
        .map(|_| axis_ray(&mut rng, Vec3::ZERO, Vec3::splat(4.0)))
        .collect();
    let mut starts = located(&grid, &rays);
    rays.push(Ray::new(Vec3::splat(1.5), Vec3::X));
    starts.push(Start::Tet(u32::MAX - 1));
    let (mut total, mut recovered) = (0, 0);
    let mut add = |(t, r)| {
        total += t;
        recovered += r;
    };
    for layout in GpuLayout::ALL {
        add(fallback_case(&ctx, &grid, layout, &rays, &starts));
    }
    let jittered = kuhn_grid(&GridSpec {
        cells: [5, 5, 5],
        jitter: 0.12,
        constrained_fraction: 0.15,
        seed: 11,
        ..Default::default()
    });
    let (rays, starts) = random_rays(&jittered, 1000, 5);
    for layout in GpuLayout::ALL {
        add(fallback_case(&ctx, &jittered, layout, &rays, &starts));
    }
    eprintln!("{total} walks re-walked on the host, {recovered} of them no longer failed");
    // The unjittered grid's impossible start is re-walked in every layout
    // (and stays lost); on the jittered grid the Plücker walk of one ray
    // circles to its step cap (on lavapipe, as on the CPU), which the
    // exact walk ends at a hit.
    assert!(total > GpuLayout::ALL.len(), "no walk lost its way");
    assert!(
        recovered > 0,
        "no lost walk was recovered by the exact walk"
    );
}

/// The fallback of camera rays made on the GPU ([`GpuTracer::render`]): a
/// narrow camera whose centre ray is a ray on which the Plücker walk (Tet80)
/// circles to its step cap (found among `random_rays(_, 2000, 5)`, on the
/// CPU as on lavapipe). The host re-walks it from the camera's start tet
/// with the exact walk, so every pixel equals the CPU tracer's outcome on
/// the CPU camera's ray, the centre pixel bit for bit.
#[test]
fn lost_camera_rays_are_rewalked_exactly_on_the_host() {
    let Some(ctx) = gpu() else { return };
    let mesh = kuhn_grid(&GridSpec {
        cells: [5, 5, 5],
        jitter: 0.12,
        constrained_fraction: 0.15,
        seed: 11,
        ..Default::default()
    });
    let (rays, starts) = random_rays(&mesh, 2000, 5);
    let (ray, start) = (rays[1161], starts[1161]);
    let Start::Tet(start_tet) = start else {
        unreachable!("random rays start in a tet")
    };
    let camera = Camera {
        position: ray.origin,
        target: ray.origin + ray.direction,
        up: Vec3::Y,
        vfov_deg: 1e-3,
    };
    let layout = GpuLayout::Tet80;
    let cap = tet_trace_cpu::walk::step_cap(&mesh);
    let cpu = cpu_tracer(&mesh, layout, None);
    let raw_cpu = cpu_tracer(&mesh, layout, Some(cap - 1));
    let (n, centre) = (3, 4);
    let cam = PinholeCamera::new(&camera, n, n, true);
    assert!(
        lost(&raw_cpu.trace(&cam.ray(1, 1), start)),
        "the centre ray's walk no longer loses its way: pick another ray"
    );
    let gpu = GpuTracer::new(&ctx, &mesh, layout).unwrap();
    let view = Viewpoint::Inside(start_tet);
    for frame in [
        gpu.render(&camera, n, n, true, start_tet).unwrap(),
        gpu.render_view(&camera, n, n, true, &view).unwrap(),
    ] {
        assert!(frame.stats.host_rewalks > 0, "{:?}", frame.stats);
        for (k, g) in frame.outcomes.iter().enumerate() {
            let r = cam.ray(k as u32 % n, k as u32 / n);
            let c = cpu.trace(&r, start);
            assert!(
                same_walk(g, &c) || grazes_an_edge(&mesh, &r, GRAZE),
                "pixel {k}: GPU {g:?} != CPU {c:?}"
            );
            assert!(!lost(g), "pixel {k}: {g:?}");
        }
        let c = cpu.trace(&cam.ray(1, 1), start);
        assert_eq!(frame.outcomes[centre], c);
        assert!(c.tets_visited() >= cap, "both walks' tets: {c:?}");
        assert_eq!(
            frame.stats.tets_visited,
            frame.outcomes.iter().map(|o| o.tets_visited() as u64).sum()
        );
        eprintln!("{:?}", frame.stats);
    }
    // Under a lower cap the failure stays, as on the CPU.
    let low = GpuTracer::new(&ctx, &mesh, layout)
        .unwrap()
        .with_step_cap(cap - 1);
    let frame = low.render(&camera, n, n, true, start_tet).unwrap();
    assert_eq!(frame.stats.host_rewalks, 0);
    assert!(
        lost(&frame.outcomes[centre]),
        "{:?}",
        frame.outcomes[centre]
    );
}
