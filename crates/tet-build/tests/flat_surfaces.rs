//! Flat surfaces: rays that lie in the plane of constrained faces (and of
//! the tet faces around them) must end, with an answer the f64 geometry
//! allows. The solids are generated here ([`tet_build::flat`]): a gear
//! whose caps are strips of long thin triangles, prisms with fan caps, a
//! staircase, a box with grid and fan faces, a tilted gear whose planes
//! are flat only up to f32 rounding, and the "Flat Parts" scene, where
//! every part stands on one shared plane. The rays lie in every flat plane
//! of each solid: from its vertices along its edges and through the
//! vertices of coplanar faces, from points on its edges and faces in
//! random in-plane directions, from outside the solid towards its
//! vertices and edges, and along camera rows at each cap height.
//!
//! The reference is brute force in f64, independent of the walk: a hit
//! must lie on the triangle it names, and no walk may pass a *robust*
//! crossing (the line crosses a triangle's interior, away from its edges,
//! at an angle) without reporting it or something nearer. A ray in a
//! plane touches the plane's triangles along segments; whether it counts
//! as above or below them is the walk's tie rule, so any hit on them, or
//! none, is allowed. That verdict applies to the rays lying exactly in
//! their plane (axis-aligned planes, and the level camera rows); in a plane
//! f32 cannot hold (the tilted gear's, a wall at an angle) the rounded ray
//! runs at a tiny angle to it. Every walk (Tet20, Tet16, Tet32 in f32,
//! Tet20 in f64, the consistent Tet80; single rays and the lockstep batch)
//! must end on every ray with no failure of any kind, the batch as the
//! single ray. (In the tilted planes an f32 walk meets tets thinner than
//! its rounding, circles, and is walked again by the exact walk: that
//! fallback is tested here.)

#![cfg(feature = "tetgen")]

use glam::{DVec3, Vec3};
use tet_build::flat;
use tet_build::pipeline::{BuildOptions, build};
use tet_build::scene::{MeshData, Scene};
use tet_core::TetMesh;
use tet_core::input_triangles::plane_barycentrics;
use tet_core::synthetic::SplitMix64;
use tet_trace_cpu::reference::{edge_distance, line_triangle};
use tet_trace_cpu::tet16::Tet16Tracer;
use tet_trace_cpu::tet20::Tet20Tracer;
use tet_trace_cpu::tet32::Tet32Tracer;
use tet_trace_cpu::tet80::Tet80ConsistentTracer;
use tet_trace_cpu::walk::BoundaryEntry;
use tet_trace_cpu::{DuffF32, DuffF64, Ray, Start, Starts, TraceOutcome, Tracer, locate};

fn solid(name: &str, mesh: MeshData) -> Scene {
    Scene {
        name: name.into(),
        vertices: mesh.positions,
        triangles: mesh.triangles,
        ..Scene::default()
    }
}

/// The planes holding two or more constrained faces: `(unit normal,
/// offset)` in f64, faces grouped when their normals agree to 1e-6 and
/// their offsets to 1e-6 of the scene's size.
fn flat_planes(mesh: &TetMesh, size: f64) -> Vec<(DVec3, f64, Vec<u32>)> {
    let mut planes: Vec<(DVec3, f64, Vec<u32>)> = Vec::new();
    for (i, cf) in mesh.constrained.iter().enumerate() {
        let v = cf.vertices.map(|k| mesh.points[k as usize].as_dvec3());
        let n = (v[1] - v[0]).cross(v[2] - v[0]);
        if n.length() == 0.0 {
            continue;
        }
        let n = n.normalize();
        let found = planes.iter_mut().find(|(m, off, _)| {
            let same = m.dot(n).abs() > 1.0 - 1e-6;
            same && (m.dot(v[0]) - off).abs() <= 1e-6 * size
        });
        match found {
            Some(p) => p.2.push(i as u32),
            None => planes.push((n, n.dot(v[0]), vec![i as u32])),
        }
    }
    planes.retain(|p| p.2.len() >= 2);
    planes
}

/// A random unit direction in the plane of normal `n` (f64, rounded to f32:
/// exactly in the plane when the plane is axis-aligned).
fn in_plane(rng: &mut SplitMix64, n: DVec3) -> Vec3 {
    loop {
        let r = DVec3::new(
            rng.next_f64() - 0.5,
            rng.next_f64() - 0.5,
            rng.next_f64() - 0.5,
        );
        let d = r - n * r.dot(n);
        if d.length() > 0.1 {
            return d.normalize().as_vec3();
        }
    }
}

/// Rays lying in the flat planes of `mesh` (see the module docs), at most
/// `per_plane` from each plane, each with whether it lies in its plane
/// exactly: an axis-aligned plane holds its f32 rays exactly; in any other
/// plane the f32 rounding of the direction tilts the ray out of it.
fn in_plane_rays(mesh: &TetMesh, size: f64, per_plane: usize, seed: u64) -> Vec<(Ray, bool)> {
    let mut rng = SplitMix64(seed);
    let pick = |rng: &mut SplitMix64, m: usize| (rng.next_u64() % m as u64) as usize;
    let mut out = Vec::new();
    let pt = |k: u32| mesh.points[k as usize];
    for (n, _, faces) in flat_planes(mesh, size) {
        let exact = n.abs().max_element() == 1.0;
        for k in 0..per_plane {
            let f = mesh.constrained[faces[pick(&mut rng, faces.len())] as usize].vertices;
            let g = mesh.constrained[faces[pick(&mut rng, faces.len())] as usize].vertices;
            let (i, j) = (pick(&mut rng, 3), pick(&mut rng, 3));
            let s = (pick(&mut rng, 1023) + 1) as f32 / 1024.0;
            let on_edge = pt(f[i]) + (pt(f[(i + 1) % 3]) - pt(f[i])) * s;
            let (a, b) = (
                pick(&mut rng, 1000) as f32 / 1000.0,
                pick(&mut rng, 1000) as f32 / 1000.0,
            );
            let (a, b) = if a + b > 1.0 {
                (1.0 - a, 1.0 - b)
            } else {
                (a, b)
            };
            let on_face = pt(f[0]) + (pt(f[1]) - pt(f[0])) * a + (pt(f[2]) - pt(f[0])) * b;
            let (origin, dir) = match k % 6 {
                // Along an edge, from its vertex, both ways.
                0 => (pt(f[i]), pt(f[(i + 1) % 3]) - pt(f[i])),
                1 => (pt(f[(i + 1) % 3]), pt(f[i]) - pt(f[(i + 1) % 3])),
                // Through a vertex of another face of the plane.
                2 => (pt(f[i]), pt(g[j]) - pt(f[i])),
                3 => (on_edge, in_plane(&mut rng, n)),
                4 => (on_face, in_plane(&mut rng, n)),
                // From outside the solid, towards a vertex or an edge point.
                _ => {
                    let d = in_plane(&mut rng, n);
                    let target = if pick(&mut rng, 2) == 0 {
                        pt(g[j])
                    } else {
                        on_edge
                    };
                    (target - d * (0.3 * size) as f32, d)
                }
            };
            if dir != Vec3::ZERO && dir.is_finite() {
                out.push((Ray::new(origin, dir), exact));
            }
        }
    }
    out
}

/// Camera rows at each height in `heights`: eyes around the scene at that
/// height, looking level across it (`y` up), a fan of directions each.
fn camera_rows(centre: Vec3, radius: f32, heights: &[f32]) -> Vec<Ray> {
    let mut out = Vec::new();
    for &h in heights {
        for e in 0..8 {
            let a = std::f32::consts::TAU * e as f32 / 8.0 + 0.1;
            let eye = Vec3::new(centre.x + radius * a.cos(), h, centre.z + radius * a.sin());
            let ahead = Vec3::new(centre.x - eye.x, 0.0, centre.z - eye.z).normalize();
            let side = Vec3::new(-ahead.z, 0.0, ahead.x);
            for p in 0..64 {
                let x = (p as f32 + 0.5) / 32.0 - 1.0;
                out.push(Ray::new(eye, ahead + side * (0.6 * x)));
            }
        }
    }
    out
}

/// The f64 verdict on one outcome (see the module docs); `Err` says why not.
fn judge(mesh: &TetMesh, ray: &Ray, out: &TraceOutcome, tol: f64) -> Result<(), String> {
    let (o, d) = (ray.origin.as_dvec3(), ray.direction.as_dvec3());
    let dl = d.length();
    let slack = tol / dl;
    // The nearest robust crossing.
    let robust = mesh
        .constrained
        .iter()
        .filter_map(|cf| {
            let v = cf.vertices.map(|k| mesh.points[k as usize].as_dvec3());
            let n = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
            if n.dot(d).abs() < 1e-3 * dl {
                return None;
            }
            line_triangle(o, d, v)?;
            let t = n.dot(v[0] - o) / n.dot(d);
            let p = o + d * t;
            (t >= ray.t_min as f64 + slack && edge_distance(p, v) > tol).then_some(t)
        })
        .min_by(f64::total_cmp);
    match out {
        TraceOutcome::Hit(h) => {
            let v = mesh.constrained[h.face as usize]
                .vertices
                .map(|k| mesh.points[k as usize].as_dvec3());
            let p = o + d * h.t as f64;
            let (b, n) = plane_barycentrics(v, p);
            let off = if b.iter().all(|&x| x >= 0.0) {
                n.normalize().dot(p - v[0]).abs()
            } else {
                edge_distance(p, v)
            };
            if off > tol {
                return Err(format!(
                    "hit at t = {} is {off} off its face {}",
                    h.t, h.face
                ));
            }
            match robust {
                Some(t) if (h.t as f64) > t + slack => {
                    Err(format!("hit at t = {} passed a crossing at t = {t}", h.t))
                }
                _ => Ok(()),
            }
        }
        TraceOutcome::Miss { .. } => match robust {
            Some(t) => Err(format!("missed a crossing at t = {t}")),
            None => Ok(()),
        },
        TraceOutcome::Failed { .. } => Err(format!("failed: {out:?}")),
    }
}

/// Builds `scene`, traces the in-plane rays of its flat planes and `rows`
/// (camera rows, level: exactly in the horizontal planes) with every walk,
/// single and batched. Every walk must end (no failure of any kind) on
/// every ray, the batch must equal the single-ray walk, and on the rays
/// lying exactly in a plane the outcome must pass the f64 [`judge`].
/// Returns how many rays were judged.
fn check(scene: &Scene, rows: &[Ray], per_plane: usize, seed: u64) -> usize {
    let (mesh, _) = build(scene, &BuildOptions::default()).expect("the solid builds");
    let (lo, hi) = mesh.point_bounds();
    let size = (hi - lo).length() as f64;
    let magnitude = lo.abs().max(hi.abs()).max_element() as f64;
    let tol = 1e-5 * size + 1e-6 * magnitude;
    let mut rays = in_plane_rays(&mesh, size, per_plane, seed);
    assert!(
        rays.len() >= 4 * per_plane,
        "{}: flat planes found",
        scene.name
    );
    rays.extend(rows.iter().map(|r| (*r, true)));
    // Origins outside the mesh (its convex hull) enter through its
    // boundary, each walk deciding the entry face with its own projection
    // (`Starts::Outside`).
    let entry = BoundaryEntry::new(&mesh).expect("TetGen meshes the convex hull");
    let (inside, outside): (Vec<_>, Vec<_>) = rays
        .into_iter()
        .partition(|(r, _)| locate(&mesh, r.origin, 0).is_ok());
    let starts: Vec<Start> = inside
        .iter()
        .map(|(r, _)| Start::Tet(locate(&mesh, r.origin, 0).unwrap()))
        .collect();
    let tracers: Vec<Box<dyn Tracer + '_>> = vec![
        Box::new(Tet20Tracer::<DuffF32>::new(&mesh).unwrap()),
        Box::new(Tet16Tracer::<DuffF32>::new(&mesh).unwrap()),
        Box::new(Tet32Tracer::<DuffF32>::new(&mesh).unwrap()),
        Box::new(Tet80ConsistentTracer::consistent(&mesh).unwrap()),
        Box::new(Tet20Tracer::<DuffF64>::new(&mesh).unwrap()),
    ];
    let mut failures = Vec::new();
    let walks = (inside.len() + outside.len()) * tracers.len();
    for tracer in &tracers {
        for (set, starts) in [
            (&inside, Starts::Each(&starts)),
            (&outside, Starts::Outside(&entry)),
        ] {
            let rays: Vec<Ray> = set.iter().map(|(r, _)| *r).collect();
            // The batch path (the lockstep walk where the kernel has one)
            // must give every ray its single-ray outcome.
            let mut batch = vec![TraceOutcome::Miss { tets_visited: 0 }; rays.len()];
            tracer.trace_batch_from(&rays, starts, &mut batch);
            for (i, ((ray, exact), b)) in set.iter().zip(&batch).enumerate() {
                let single = match starts {
                    Starts::Each(s) => tracer.trace(ray, s[i]),
                    _ => {
                        let mut one = [TraceOutcome::Miss { tets_visited: 0 }];
                        tracer.trace_batch_from(std::slice::from_ref(ray), starts, &mut one);
                        one[0]
                    }
                };
                let verdict = match single {
                    TraceOutcome::Failed { .. } => Err(format!("failed: {single:?}")),
                    _ if *exact => judge(&mesh, ray, &single, tol),
                    _ => Ok(()),
                };
                if let Err(why) = verdict {
                    failures.push(format!("{} {ray:?}: {why}", tracer.name()));
                }
                if *b != single {
                    failures.push(format!(
                        "{} batch {b:?} != single {single:?} on {ray:?}",
                        tracer.name()
                    ));
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{}: {} of {} walks wrong, e.g.\n{}",
        scene.name,
        failures.len(),
        walks,
        failures[..failures.len().min(8)].join("\n")
    );
    inside.iter().chain(&outside).filter(|(_, e)| *e).count()
}

#[test]
fn gear_with_strip_caps() {
    let rows = camera_rows(Vec3::ZERO, 2.5, &[0.0, 0.3]);
    check(&solid("gear", flat::gear(12, 0.3, 0.3)), &rows, 300, 1);
}

#[test]
fn prisms_with_fan_caps() {
    let rows = camera_rows(Vec3::ZERO, 2.5, &[0.0, 0.5]);
    check(&solid("fan prism", flat::fan_prism(40, 0.5)), &rows, 300, 2);
    check(
        &solid("star prism", flat::star_prism(7, 0.5)),
        &rows,
        300,
        3,
    );
}

#[test]
fn stairs_and_subdivided_box() {
    let heights: Vec<f32> = (0..=6).map(|k| k as f32 * 0.25).collect();
    let rows = camera_rows(Vec3::new(1.2, 0.0, 0.5), 3.0, &heights);
    check(&solid("stairs", flat::stairs(6)), &rows, 200, 4);
    let rows = camera_rows(Vec3::splat(0.5), 2.0, &[0.0, 0.5, 1.0]);
    check(
        &solid("subdivided box", flat::subdivided_box(5)),
        &rows,
        200,
        5,
    );
}

#[test]
fn flat_parts_scene_with_tilted_and_shared_planes() {
    let scene = flat::flat_parts();
    let rows = camera_rows(
        Vec3::new(0.0, 0.0, 1.2),
        6.0,
        &flat::flat_parts_cap_heights(),
    );
    let n = check(&scene, &rows, 60, 6);
    assert!(n > 2000);
}

/// Far from the origin and at a tiny scale the same rays must still end
/// (the walk's scale and the tie rule's exact determinant at work).
#[test]
fn flat_solids_at_the_extremes() {
    for (scale, offset) in [(1e-4f32, Vec3::ZERO), (1.0, Vec3::new(3e4, -2e4, 1e4))] {
        let mut scene = solid("gear at an extreme", flat::gear(8, 0.3, 0.3));
        for v in &mut scene.vertices {
            *v = *v * scale + offset;
        }
        check(&scene, &[], 200, 7);
    }
}

/// The generators make closed, outward surfaces: every edge is shared by
/// exactly two triangles, in opposite directions, and the signed volume is
/// positive.
#[test]
fn flat_solids_are_closed_and_outward() {
    let solids = [
        flat::gear(5, 0.3, 0.3),
        flat::fan_prism(9, 0.5),
        flat::star_prism(5, 0.5),
        flat::stairs(4),
        flat::subdivided_box(3),
    ];
    for (i, m) in solids.iter().enumerate() {
        let mut edges = std::collections::HashMap::new();
        for t in &m.triangles {
            for k in 0..3 {
                *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        for (&(a, b), &c) in &edges {
            assert_eq!(c, 1, "solid {i}: edge {a}->{b} used {c} times");
            assert_eq!(
                edges.get(&(b, a)),
                Some(&1),
                "solid {i}: edge {a}->{b} open"
            );
        }
        let volume: f64 = m
            .triangles
            .iter()
            .map(|t| {
                let v = t.map(|k| m.positions[k as usize].as_dvec3());
                v[0].dot(v[1].cross(v[2])) / 6.0
            })
            .sum();
        assert!(volume > 0.0, "solid {i}: volume {volume}");
    }
}

/// The gear the issue was found on, as its OBJ had it: 12 teeth, caps at
/// `z = 0` and `z = 0.3`, built from f64 positions rounded to f32 (the
/// same solid as [`flat::gear`], differently placed and triangulated).
fn z_up_gear() -> MeshData {
    let n = 48;
    let at = |i: usize, r: f64, z: f64| {
        let a = std::f64::consts::TAU * i as f64 / n as f64;
        Vec3::new((r * a.cos()) as f32, (r * a.sin()) as f32, z as f32)
    };
    let rim = |i: usize| if i % 4 < 2 { 1.0 } else { 0.8 };
    let mut positions = Vec::new();
    for (r, z) in [(None, 0.0), (None, 0.3), (Some(0.3), 0.0), (Some(0.3), 0.3)] {
        positions.extend((0..n).map(|i| at(i, r.unwrap_or_else(|| rim(i)), z)));
    }
    let (r0, r1, b0, b1) = (0, n as u32, 2 * n as u32, 3 * n as u32);
    let mut triangles = Vec::new();
    for i in 0..n as u32 {
        let j = (i + 1) % n as u32;
        triangles.extend([
            [r0 + i, r0 + j, r1 + j],
            [r0 + i, r1 + j, r1 + i],
            [b0 + i, b1 + j, b0 + j],
            [b0 + i, b1 + i, b1 + j],
            [b1 + i, r1 + i, r1 + j],
            [b1 + i, r1 + j, b1 + j],
            [b0 + i, r0 + j, r0 + i],
            [b0 + i, b0 + j, r0 + j],
        ]);
    }
    MeshData {
        positions,
        triangles,
        ..MeshData::default()
    }
}

/// Rays of the gear found by `accuracy --adversarial`, each lying in the
/// plane of a tet face (not a scene face) within 1e-9 of its origin, where
/// the f32 projection moves the line off every tet around the origin. The
/// start then searched the tets next to them and took the one whose
/// centroid lay nearest along the ray: across the cap the first two rays
/// were about to hit (they then missed: a leak), or none (the third was
/// started from a guess and circled to the step cap). Every f32 walk must
/// now give the exact walk's answer: the cap at its `t` (the triangle may
/// be the one across the edge the line passes within rounding of), or the
/// miss.
#[test]
fn gear_rays_in_tet_face_planes_start_where_the_moved_line_is() {
    // In the box `tet-bench build gear` puts around it (0.2 % of its size
    // away), where the rays were found.
    let options = BuildOptions {
        enclosing_box: Some(tet_build::bbox::BoxSpec::Fixed {
            min: Vec3::new(-1.004, -1.004, -0.004),
            max: Vec3::new(1.004, 1.004, 0.304),
        }),
        ..BuildOptions::default()
    };
    let (mesh, _) = build(&solid("gear", z_up_gear()), &options).expect("the gear builds");
    let rays = [
        (
            [-0.6109181, -0.24095903, 0.022190982],
            [-0.24894017, -0.12659651, -0.9602094],
        ),
        (
            [0.7030131, 0.29119757, 0.012331617],
            [-0.79070354, -0.32752013, -0.51722187],
        ),
        (
            [-0.9765299, 0.90365607, -0.00320362],
            [0.55399686, 0.8324557, -0.010246247],
        ),
    ];
    let tracers: Vec<Box<dyn Tracer + '_>> = vec![
        Box::new(Tet20Tracer::<DuffF32>::new(&mesh).unwrap()),
        Box::new(Tet16Tracer::<DuffF32>::new(&mesh).unwrap()),
        Box::new(Tet32Tracer::<DuffF32>::new(&mesh).unwrap()),
        Box::new(Tet80ConsistentTracer::consistent(&mesh).unwrap()),
    ];
    let exact = tet_trace_cpu::exact::ExactTracer::new(&mesh);
    let mut wrong = Vec::new();
    for (o, d) in rays {
        let ray = Ray::new(Vec3::from(o), Vec3::from(d));
        let start = Start::Tet(locate(&mesh, ray.origin, 0).expect("inside the mesh"));
        let want = exact.trace(&ray, start);
        for tracer in &tracers {
            let got = tracer.trace(&ray, start);
            let same = match (want, got) {
                (TraceOutcome::Miss { .. }, TraceOutcome::Miss { .. }) => true,
                (TraceOutcome::Hit(a), TraceOutcome::Hit(b)) => (a.t - b.t).abs() <= 1e-6,
                _ => false,
            };
            if !same {
                wrong.push(format!(
                    "{} {ray:?}: {got:?}, exact {want:?}",
                    tracer.name()
                ));
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}
