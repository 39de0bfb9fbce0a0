//! The renderer against the brute-force reference, pixel by pixel.

use glam::Vec3;
use tet_core::scene::{Camera, PointLight};
use tet_core::synthetic::{GridSpec, kuhn_grid};
use tet_trace_cpu::DuffF32;
use tet_trace_cpu::reference::{closest_hit, grazes_an_edge};
use tet_trace_cpu::render::{PinholeCamera, RenderOptions, render};
use tet_trace_cpu::tet20::Tet20Tracer;

#[test]
fn frame_matches_reference_and_writes_png() {
    let camera = Camera {
        position: Vec3::new(0.6, 1.1, 5.4),
        target: Vec3::splat(3.0),
        up: Vec3::Y,
        vfov_deg: 45.0,
    };
    let frame = frame_matches_reference(&camera);
    let dir = std::env::temp_dir().join(format!("tet-trace-cpu-render-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("frame.png");
    frame.save_png(&path).unwrap();
    frame.save_heatmap(&dir.join("heat.png"), None).unwrap();
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()));
    let reader = decoder.read_info().unwrap();
    assert_eq!((reader.info().width, reader.info().height), (40, 30));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A camera outside the mesh (as behind a tight enclosing box): primary rays
/// enter through the boundary, those that miss the mesh visit no tet, and
/// every pixel matches the brute force; the light outside the mesh too.
#[test]
fn camera_outside_the_mesh_enters_through_the_boundary() {
    let camera = Camera {
        position: Vec3::new(7.0, 6.0, 9.0),
        target: Vec3::splat(3.0),
        up: Vec3::Y,
        vfov_deg: 45.0,
    };
    let frame = frame_matches_reference(&camera);
    let untouched = frame.tets.iter().filter(|&&t| t == 0).count();
    assert!(
        untouched > 50,
        "rays around the mesh visit no tet: {untouched}"
    );
}

/// Renders a shell inside a 6³ grid from `camera` with Tet20 and checks
/// every pixel against the f64 brute force from the same camera model.
fn frame_matches_reference(camera: &Camera) -> tet_trace_cpu::render::Frame {
    let camera = *camera;
    let mesh = kuhn_grid(&GridSpec {
        cells: [6, 6, 6],
        jitter: 0.1,
        shell: Some(([2; 3], [4; 3])),
        seed: 5,
        ..Default::default()
    });
    let tracer = Tet20Tracer::<DuffF32>::new(&mesh).unwrap();
    let lights = [PointLight {
        position: Vec3::new(1.0, 5.5, 5.0),
        color: Vec3::ONE,
        intensity: 1.0,
    }];
    let opts = RenderOptions {
        width: 40,
        height: 30,
        shadows: true,
        ..Default::default()
    };
    let frame = render(&tracer, &camera, &lights, &opts).unwrap();
    assert_eq!(frame.stats.rays, 1200);
    assert_eq!(frame.stats.failures, 0);
    let hits = frame.triangle.iter().filter(|&&t| t != u32::MAX).count() as u64;
    assert_eq!(frame.stats.hits, hits);
    assert!(
        hits > 100 && hits < 1200,
        "the shell covers part of the view: {hits}"
    );
    assert_eq!(
        frame.stats.tets_visited,
        frame.tets.iter().map(|&t| t as u64).sum::<u64>()
    );

    // Independent: brute-force hit per pixel from the same camera model.
    let cam = PinholeCamera::new(&camera, 40, 30, false);
    let mut compared = 0;
    for j in 0..30 {
        for i in 0..40 {
            let ray = cam.ray(i, j);
            if grazes_an_edge(&mesh, &ray, 1e-3) {
                continue;
            }
            let want = closest_hit(&mesh, &ray).map_or(u32::MAX, |h| h.triangle);
            assert_eq!(
                frame.triangle[(j * 40 + i) as usize],
                want,
                "pixel ({i}, {j})"
            );
            compared += 1;
        }
    }
    assert!(compared > 1000);
    // Centre pixel direction follows the scenes.json convention (i = W/2 is
    // exactly forward, no half-pixel offset).
    let centre = cam.ray(20, 15).direction;
    assert!((centre - (camera.target - camera.position).normalize()).length() < 1e-6);
    frame
}

#[test]
fn camera_at_a_non_finite_position_is_an_error() {
    let mesh = kuhn_grid(&GridSpec::default());
    let tracer = Tet20Tracer::<DuffF32>::new(&mesh).unwrap();
    let camera = Camera {
        position: Vec3::new(f32::NAN, 1.0, 1.0),
        ..Default::default()
    };
    let opts = RenderOptions {
        width: 4,
        height: 4,
        ..Default::default()
    };
    assert!(render(&tracer, &camera, &[], &opts).is_err());
}

#[test]
fn vertex_normals_are_interpolated_and_face_normals_follow_winding() {
    use tet_trace_cpu::render::shading_normal;
    use tet_trace_cpu::secondary::face_normal;
    use tet_trace_cpu::{Ray, Start, Tracer, locate};
    let mut mesh = kuhn_grid(&GridSpec {
        cells: [3, 3, 3],
        jitter: 0.0,
        shell: Some(([1; 3], [2; 3])),
        ..Default::default()
    });
    let ray = Ray::new(Vec3::new(0.5, 1.4, 1.6), Vec3::X);
    let start = locate(&mesh, ray.origin, 0).unwrap();
    let hit = {
        let t = Tet20Tracer::<DuffF32>::new(&mesh).unwrap();
        *t.trace(&ray, Start::Tet(start)).hit().unwrap()
    };
    // Face normal from the winding: ±x on the plane x = 1, and it agrees
    // with the cross product of the face's own vertices.
    let cf = mesh.constrained[hit.face as usize];
    let v = cf.vertices.map(|i| mesh.points[i as usize]);
    let n = face_normal(&mesh, hit.face);
    assert!((n.x.abs() - 1.0).abs() < 1e-6);
    assert!(n.dot((v[1] - v[0]).cross(v[2] - v[0])) > 0.0);
    assert_eq!(shading_normal(&mesh, &hit), n);
    // Per-vertex normals: a constant field comes back unchanged; a field
    // equal to each vertex's y coordinate direction mixes by barycentrics.
    let normals: Vec<Vec3> = mesh
        .points
        .iter()
        .map(|p| Vec3::new(0.0, p.y, 1.0))
        .collect();
    mesh.attributes.normals = Some(normals);
    let expected = {
        let b = hit.barycentrics;
        let m: Vec3 = (0..3).map(|k| Vec3::new(0.0, v[k].y, 1.0) * b[k]).sum();
        m.normalize()
    };
    assert!((shading_normal(&mesh, &hit) - expected).length() < 1e-5);
}
