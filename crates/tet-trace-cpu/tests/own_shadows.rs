//! `render` traces shadow rays with the primary tracer itself
//! (`Tracer::trace_until`): a tracer without tets (here an f64 brute force
//! that runs every shadow ray to the light) and the tet kernels (which stop
//! at the light's tets) must shade the same pixels the same way.

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::scene::{Camera, PointLight};
use tet_core::synthetic::{GridSpec, constrain_faces, kuhn_grid};
use tet_trace_cpu::reference::ray_triangle;
use tet_trace_cpu::render::{RenderOptions, render};
use tet_trace_cpu::tet20::Tet20Tracer;
use tet_trace_cpu::tet80::Tet80Tracer;
use tet_trace_cpu::{DuffF32, Hit, Ray, Start, TraceOutcome, Tracer, locate};

/// Every constrained face by brute force in f64; no tets, so shadow rays
/// keep the default `trace_until` and run to `t_max`.
struct Brute<'m>(&'m TetMesh);

impl Tracer for Brute<'_> {
    fn name(&self) -> String {
        "brute".into()
    }
    fn mesh(&self) -> &TetMesh {
        self.0
    }
    fn trace(&self, ray: &Ray, start: Start) -> TraceOutcome {
        let skip = start.on_face().unwrap_or(u32::MAX);
        let mut best: Option<(f64, u32, [f64; 3])> = None;
        for (i, cf) in self.0.constrained.iter().enumerate() {
            if i as u32 == skip {
                continue;
            }
            let v = cf.vertices.map(|k| self.0.points[k as usize]);
            if let Some((t, b)) = ray_triangle(ray, v)
                // Past the start point's own plane: a shadow ray leaves a
                // floor point that other floor triangles touch at t ≈ 0.
                && t > ray.t_min as f64 + 1e-4
                && t <= ray.t_max as f64
                && best.is_none_or(|(bt, _, _)| t < bt)
            {
                best = Some((t, i as u32, b));
            }
        }
        let Some((t, face, b)) = best else {
            return TraceOutcome::Miss { tets_visited: 0 };
        };
        let cf = &self.0.constrained[face as usize];
        let v = cf.vertices.map(|k| self.0.points[k as usize]);
        let n = (v[1] - v[0]).cross(v[2] - v[0]);
        let (near, far) = if ray.direction.dot(n) < 0.0 {
            (cf.front.tet, cf.back.tet)
        } else {
            (cf.back.tet, cf.front.tet)
        };
        TraceOutcome::Hit(Hit {
            triangle: cf.triangle,
            face,
            t: t as f32,
            barycentrics: b.map(|x| x as f32),
            tet: near,
            far_tet: far,
            tets_visited: 0,
        })
    }
}

#[test]
fn shadows_agree_between_a_tracer_without_tets_and_the_kernels() {
    // A floor (z = 1) under a floating square occluder (z = 2, x, y ∈ [1, 2])
    // whose shadow covers about [0.2, 1.7]² of the floor.
    let g = kuhn_grid(&GridSpec {
        cells: [4, 4, 4],
        jitter: 0.0,
        ..Default::default()
    });
    let mesh = constrain_faces(
        g,
        |v| {
            v.iter().all(|p| p.z == 1.0)
                || v.iter()
                    .all(|p| p.z == 2.0 && (1.0..=2.0).contains(&p.x) && (1.0..=2.0).contains(&p.y))
        },
        Some(Vec3::Z),
    );
    let camera = Camera {
        position: Vec3::new(3.8, 3.7, 2.6),
        target: Vec3::new(1.2, 1.1, 1.0),
        up: Vec3::Z,
        vfov_deg: 60.0,
    };
    let lights = [PointLight {
        position: Vec3::new(2.5, 2.5, 3.9),
        color: Vec3::ONE,
        intensity: 1.0,
    }];
    let opts = RenderOptions {
        width: 48,
        height: 36,
        shadows: true,
        ..Default::default()
    };
    let brute = Brute(&mesh);
    let reference = render(&brute, &camera, &lights, &opts).unwrap();
    let lit_floor = |f: &tet_trace_cpu::render::Frame| {
        f.color
            .iter()
            .zip(&f.triangle)
            .filter(|(c, t)| **t != u32::MAX && c.length() > 0.05)
            .count()
    };
    let hits = reference
        .triangle
        .iter()
        .filter(|&&t| t != u32::MAX)
        .count();
    let lit = lit_floor(&reference);
    assert!(
        hits > 500 && lit > 200 && lit + 30 < hits,
        "the scene has both lit and shadowed pixels: {hits} hits, {lit} lit"
    );
    let t20 = <Tet20Tracer<'_, DuffF32>>::new(&mesh).unwrap();
    let t80 = Tet80Tracer::new(&mesh).unwrap();
    for tracer in [&t20 as &dyn Tracer, &t80] {
        let frame = render(tracer, &camera, &lights, &opts).unwrap();
        assert_eq!(frame.triangle, reference.triangle, "{}", tracer.name());
        assert_eq!(frame.stats.shadow_rays, reference.stats.shadow_rays);
        assert_eq!(frame.stats.shadow_failures, 0, "{}", tracer.name());
        let differ = frame
            .color
            .iter()
            .zip(&reference.color)
            .filter(|(a, b)| (**a - **b).abs().max_element() > 1e-4)
            .count();
        assert_eq!(
            differ,
            0,
            "{}: {differ} pixels shaded differently",
            tracer.name()
        );
        // Its own shadow walk stops on entering the light's tet, short of
        // where the same ray leaves the mesh.
        let cam = locate(&mesh, camera.position, 0).unwrap();
        let light_tet = locate(&mesh, lights[0].position, cam).unwrap();
        let ray = Ray::new(camera.position, lights[0].position - camera.position);
        let stopped = tracer.trace_until(&ray, Start::Tet(cam), &[light_tet]);
        let through = tracer.trace(&ray, Start::Tet(cam));
        assert!(
            matches!(stopped, TraceOutcome::Miss { .. })
                && stopped.tets_visited() < through.tets_visited(),
            "{}: {stopped:?} vs {through:?}",
            tracer.name()
        );
    }
}
