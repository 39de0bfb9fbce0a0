//! The procedural stand-ins for the paper's scenes without a mesh here:
//! `city:N` (Rungholt: axis-aligned buildings on a street grid) and
//! `pipes:N` (Exhaust Pipe: long bent tubes side by side). At several
//! small sizes each must have about the triangles asked for, be made of
//! closed, outward-oriented objects (every edge used once each way, a
//! positive volume), have no degenerate or repeated triangle or vertex
//! (cleaning has nothing to do), and no two triangles may meet anywhere
//! but in shared vertices and edges (the crate's exact check). A small
//! instance of each builds into a CDT with nothing to resolve, and rays
//! traced through it (Tet20, f32) agree with brute force over the scene's
//! triangles.

use std::collections::HashMap;

use tet_build::clean::{clean, collinear};
use tet_build::intersect::find_self_intersections;
use tet_build::procedural::by_name;
use tet_build::scene::Scene;

/// The scene `name` (`city:20k`), which must exist.
fn scene(name: &str) -> Scene {
    by_name(name).unwrap_or_else(|| panic!("no procedural scene {name}"))
}

/// Why `scene` is not made of closed, outward-oriented objects without
/// degenerate triangles, or `None`.
fn closed_outward(scene: &Scene) -> Option<String> {
    for o in &scene.objects {
        let tris = &scene.triangles
            [o.first_triangle as usize..(o.first_triangle + o.triangle_count) as usize];
        let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
        for t in tris {
            let v = t.map(|k| scene.vertices[k as usize]);
            if collinear(v[0], v[1], v[2]) {
                return Some(format!("{}: degenerate triangle {t:?}", o.name));
            }
            for k in 0..3 {
                *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        for (&(a, b), &n) in &edges {
            if n != 1 || edges.get(&(b, a)) != Some(&1) {
                return Some(format!(
                    "{}: edge {a}->{b} used {n} times, {:?} times back",
                    o.name,
                    edges.get(&(b, a))
                ));
            }
        }
        let volume: f64 = tris
            .iter()
            .map(|t| {
                let v = t.map(|k| scene.vertices[k as usize].as_dvec3());
                v[0].dot(v[1].cross(v[2])) / 6.0
            })
            .sum();
        if volume <= 0.0 {
            return Some(format!("{}: volume {volume}", o.name));
        }
    }
    None
}

/// Every check on one scene but the CDT; panics with what failed.
fn check_valid(name: &str, asked: u64) -> Scene {
    let sc = scene(name);
    let n = sc.triangles.len() as f64;
    assert!(
        (n / asked as f64 - 1.0).abs() < 0.1,
        "{name}: {n} triangles, asked for {asked}"
    );
    assert!(sc.camera.is_some() && !sc.lights.is_empty(), "{name}");
    if let Some(why) = closed_outward(&sc) {
        panic!("{name}: {why}");
    }
    let cleaned = clean(&sc.vertices, &sc.triangles).expect("finite, in range");
    assert!(
        cleaned.report.is_noop(),
        "{name}: cleaning changed it: {:?}",
        cleaned.report
    );
    let report = find_self_intersections(&sc.vertices, &sc.triangles);
    assert!(
        report.is_clean() && report.degenerate.is_empty(),
        "{name}: {} intersecting pairs, e.g. {:?}",
        report.pairs.len(),
        &report.pairs[..report.pairs.len().min(4)]
    );
    sc
}

#[test]
fn city_is_a_closed_valid_surface_of_about_n_triangles() {
    for (name, n) in [("city:2k", 2_000), ("city:5k", 5_000), ("city:20k", 20_000)] {
        let sc = check_valid(name, n);
        eprintln!("{name}: {} triangles", sc.triangles.len());
    }
}

#[test]
fn pipes_are_closed_valid_tubes_of_about_n_triangles() {
    for (name, n) in [
        ("pipes:2k", 2_000),
        ("pipes:5k", 5_000),
        ("pipes:20k", 20_000),
    ] {
        let sc = check_valid(name, n);
        eprintln!("{name}: {} triangles", sc.triangles.len());
    }
}

/// The CDT checks need TetGen (the default feature).
#[cfg(feature = "tetgen")]
mod cdt {
    use tet_build::pipeline::{BuildOptions, build};
    use tet_build::scene::Scene;
    use tet_build::scene::transform::camera_basis;
    use tet_core::synthetic::SplitMix64;
    use tet_trace_cpu::reference::{Aim, random_ray, ray_triangle, segment_distance};
    use tet_trace_cpu::tet20::Tet20Tracer;
    use tet_trace_cpu::walk::BoundaryEntry;
    use tet_trace_cpu::{DuffF32, Ray, Start, Starts, TraceOutcome, Tracer};

    use super::scene;

    /// The f64 reference over the scene's triangles: the nearest hit's
    /// triangle and `t`, `None` for a miss, `Err(())` when too close to call
    /// (the hit point within `tol` of an edge of its triangle, or a second
    /// hit within `tol` along the ray).
    fn reference(scene: &Scene, ray: &Ray, tol: f64) -> Result<Option<(u32, f64)>, ()> {
        let mut hits: Vec<(f64, u32, [f64; 3])> = Vec::new();
        for (i, tri) in scene.triangles.iter().enumerate() {
            let v = tri.map(|k| scene.vertices[k as usize]);
            if let Some((t, b)) = ray_triangle(ray, v)
                && t >= ray.t_min as f64
            {
                hits.push((t, i as u32, b));
            }
        }
        hits.sort_by(|a, b| a.0.total_cmp(&b.0));
        let Some(&(t, tri, b)) = hits.first() else {
            return Ok(None);
        };
        let d = ray.direction.as_dvec3().length();
        if hits.get(1).is_some_and(|h| (h.0 - t) * d < tol) {
            return Err(());
        }
        let v = scene.triangles[tri as usize].map(|k| scene.vertices[k as usize].as_dvec3());
        let p = v[0] * b[0] + v[1] * b[1] + v[2] * b[2];
        if (0..3).any(|e| segment_distance(p, v[e], v[(e + 1) % 3]) < tol) {
            return Err(());
        }
        Ok(Some((tri, t)))
    }

    /// A `n × n` grid of the scene camera's primary rays.
    fn camera_rays(scene: &Scene, n: u32) -> Vec<Ray> {
        let cam = scene.camera.expect("the stand-ins have a camera");
        let (forward, right, up) = camera_basis(&cam);
        let h = (cam.vfov_deg.to_radians() / 2.0).tan();
        let mut rays = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let x = (2.0 * (i as f32 + 0.5) / n as f32 - 1.0) * h * 4.0 / 3.0;
                let y = (2.0 * (j as f32 + 0.5) / n as f32 - 1.0) * h;
                rays.push(Ray::new(cam.position, forward + right * x + up * y));
            }
        }
        rays
    }

    /// Builds `name` into a CDT (nothing to resolve, every triangle one
    /// constrained face) and checks Tet20 against [`reference`] on the
    /// camera's rays (entering through the mesh boundary) and on random rays
    /// from inside the mesh. Returns (rays checked, hits).
    fn check_cdt(name: &str) -> (usize, usize) {
        let scene = scene(name);
        let (mesh, report) = build(&scene, &BuildOptions::default()).expect("the stand-in builds");
        mesh.validate().unwrap();
        assert_eq!(report.resolve.pairs, 0, "{name}: nothing to resolve");
        assert_eq!(mesh.constrained.len(), scene.triangles.len(), "{name}");
        let (lo, hi) = mesh.point_bounds();
        let tol = 1e-6 * (hi - lo).as_dvec3().length();
        let tracer = Tet20Tracer::<DuffF32>::new(&mesh).unwrap();
        let entry = BoundaryEntry::new(&mesh).expect("TetGen meshes the convex hull");
        let camera = camera_rays(&scene, 48);
        let mut outcomes = vec![TraceOutcome::Miss { tets_visited: 0 }; camera.len()];
        tracer.trace_batch_from(&camera, Starts::Outside(&entry), &mut outcomes);
        let mut cases: Vec<(Ray, TraceOutcome)> = camera.into_iter().zip(outcomes).collect();
        let mut rng = SplitMix64(0x57A1D);
        for _ in 0..1500 {
            let (ray, tet) = random_ray(&mesh, &mut rng, Aim::Random);
            cases.push((ray, tracer.trace(&ray, Start::Tet(tet))));
        }
        let (mut checked, mut hits) = (0, 0);
        for (ray, outcome) in &cases {
            let Ok(expected) = reference(&scene, ray, tol) else {
                continue;
            };
            checked += 1;
            match (expected, outcome) {
                (None, TraceOutcome::Miss { .. }) => {}
                (Some((tri, t)), TraceOutcome::Hit(h)) => {
                    hits += 1;
                    assert_eq!(h.triangle, tri, "{name}: wrong triangle on {ray:?}");
                    let d = ray.direction.as_dvec3().length();
                    assert!(
                        (h.t as f64 - t).abs() * d < tol.max(1e-5 * t * d),
                        "{name}: t {} against {t} on {ray:?}",
                        h.t
                    );
                }
                (e, o) => panic!("{name}: expected {e:?}, got {o:?} on {ray:?}"),
            }
        }
        assert!(
            checked * 10 >= cases.len() * 9,
            "{name}: {checked} of {} checked",
            cases.len()
        );
        eprintln!(
            "{name}: {checked} of {} rays checked, {hits} hits",
            cases.len()
        );
        (checked, hits)
    }

    #[test]
    fn small_city_builds_and_traces_like_its_triangles() {
        let (checked, hits) = check_cdt("city:5k");
        assert!(hits * 3 >= checked, "{hits} of {checked} rays hit");
    }

    #[test]
    fn small_pipe_bundle_builds_and_traces_like_its_triangles() {
        let (checked, hits) = check_cdt("pipes:5k");
        assert!(hits * 5 >= checked, "{hits} of {checked} rays hit");
    }
}

/// Counts below the minimum are raised to it; the names are listed; the
/// full sizes are the paper's counts.
#[test]
fn counts_and_names() {
    for (name, at_least) in [("city:10", 1_000), ("pipes:1", 1_000)] {
        let n = scene(name).triangles.len() as f64;
        assert!((n / at_least as f64 - 1.0).abs() < 0.1, "{name}: {n}");
    }
    assert!(by_name("city:0").is_none() && by_name("pipes:x").is_none());
    let names: Vec<&str> = tet_build::procedural::SCENES
        .iter()
        .map(|p| p.name)
        .collect();
    for n in ["city", "city:N", "pipes", "pipes:N"] {
        assert!(names.contains(&n), "{n} not in SCENES");
    }
    // Aman et al. (2022), Table 2.
    assert_eq!(tet_build::city::RUNGHOLT_TRIANGLES, 3_580_928);
    assert_eq!(tet_build::pipes::EXHAUST_PIPE_TRIANGLES, 6_244_678);
}
