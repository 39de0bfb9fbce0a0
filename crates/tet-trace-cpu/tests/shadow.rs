//! Shadow rays that end at the light's tet (Aman et al. 2022, §6) against an
//! independent f64 brute force (the segment from the hit point to the light
//! against every scene triangle), on random scenes, and on hand-built cases:
//! lights on vertices, edges and faces of constrained planes, and lights
//! inside a closed shell.

use glam::{DVec3, Vec3};
use tet_core::predicates::orient3d;
use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};
use tet_core::{FACE_VERTICES, TetMesh};
use tet_trace_cpu::reference::{Aim, edge_distance, random_point_inside, random_ray};
use tet_trace_cpu::sctp::SctpTracer;
use tet_trace_cpu::secondary::{
    LightTarget, MeshWalker, ShadowTracer, hit_point, trace_shadow, visible_from,
};
use tet_trace_cpu::tet16::Tet16Tracer;
use tet_trace_cpu::tet20::Tet20Tracer;
use tet_trace_cpu::tet32::Tet32Tracer;
use tet_trace_cpu::tet80::Tet80Tracer;
use tet_trace_cpu::{DuffF32, DuffF64, Hit, Ray, Start, TraceOutcome, Tracer, locate};

/// Brute-force visibility of `l` from `p` (on constrained face `own`):
/// `Some(true)` when no scene triangle meets the open segment `(p, l)`,
/// `Some(false)` when one crosses it clearly inside, `None` when the answer
/// depends on rounding (the segment passes within `tol` of a triangle edge,
/// or a crossing lies within `tol` of either end without the light lying
/// exactly on that triangle's plane). A triangle meeting the segment only
/// at the light (light on the triangle) does not occlude: the documented rule.
fn brute_visible(mesh: &TetMesh, p: Vec3, own: u32, l: Vec3) -> Option<bool> {
    let tol = 1e-5;
    let (o, d) = (p.as_dvec3(), (l - p).as_dvec3());
    let len = d.length();
    let mut visible = true;
    for (i, cf) in mesh.constrained.iter().enumerate() {
        if i as u32 == own {
            continue;
        }
        let v = cf.vertices.map(|k| mesh.points[k as usize].as_dvec3());
        let n = (v[1] - v[0]).cross(v[2] - v[0]);
        let den = n.dot(d);
        let light_on_plane = orient3d(v[0], v[1], v[2], l.as_dvec3()) == 0.0;
        if den == 0.0 {
            if (n.dot(v[0] - o) / n.length()).abs() < tol {
                return None; // the segment runs in the triangle's plane
            }
            continue;
        }
        let t = n.dot(v[0] - o) / den;
        if t < -tol / len || t > 1.0 + tol / len {
            continue;
        }
        let x = o + d * t;
        if edge_distance(x, v) < tol {
            if light_on_plane && (x - l.as_dvec3()).length() < tol {
                continue; // the light sits on (an edge of) this triangle
            }
            return None;
        }
        let inside = inside_triangle(x, v, n);
        if !inside {
            continue;
        }
        if light_on_plane {
            continue; // touches the segment only at the light
        }
        if t * len < tol || (1.0 - t) * len < tol {
            return None;
        }
        visible = false;
    }
    Some(visible)
}

fn inside_triangle(x: DVec3, v: [DVec3; 3], n: DVec3) -> bool {
    (0..3).all(|k| (v[(k + 1) % 3] - v[k]).cross(x - v[k]).dot(n) >= 0.0)
}

fn shadow_tracers(m: &TetMesh) -> Vec<(String, Box<dyn ShadowTracer + '_>)> {
    vec![
        ("mesh".into(), Box::new(MeshWalker::new(m))),
        (
            "tet20".into(),
            Box::new(Tet20Tracer::<DuffF32>::new(m).unwrap()),
        ),
        (
            "tet16".into(),
            Box::new(Tet16Tracer::<DuffF32>::new(m).unwrap()),
        ),
        (
            "tet32".into(),
            Box::new(Tet32Tracer::<DuffF32>::new(m).unwrap()),
        ),
        (
            "tet20/f64".into(),
            Box::new(Tet20Tracer::<DuffF64>::new(m).unwrap()),
        ),
        ("sctp".into(), Box::new(<SctpTracer<'_>>::new(m).unwrap())),
        ("tet80".into(), Box::new(Tet80Tracer::new(m).unwrap())),
    ]
}

/// A light position: inside a tet, on a vertex, an edge midpoint or a face
/// centroid of a random tet (often a constrained face), or on a constrained
/// face's centroid.
fn random_light(m: &TetMesh, rng: &mut SplitMix64) -> Vec3 {
    let t = (rng.next_u64() % m.tets.len() as u64) as u32;
    let p = m.tet_points(t);
    let r = rng.next_u64();
    match r % 5 {
        0 => random_point_inside(m, rng).0,
        1 => p[(r / 5 % 4) as usize],
        2 => (p[(r / 5 % 4) as usize] + p[((r / 5 % 4 + 1) % 4) as usize]) * 0.5,
        3 => {
            let s = FACE_VERTICES[(r / 5 % 4) as usize];
            (p[s[0]] + p[s[1]] + p[s[2]]) / 3.0
        }
        _ if !m.constrained.is_empty() => {
            let cf = m.constrained[(r / 5 % m.constrained.len() as u64) as usize];
            let v = cf.vertices.map(|k| m.points[k as usize]);
            (v[0] + v[1] + v[2]) / 3.0
        }
        _ => random_point_inside(m, rng).0,
    }
}

fn random_hits(m: &TetMesh, rng: &mut SplitMix64, n: usize) -> Vec<Hit> {
    let t = Tet20Tracer::<DuffF64>::new(m).unwrap();
    let mut out = Vec::new();
    while out.len() < n {
        let (ray, start) = random_ray(m, rng, Aim::Random);
        if let TraceOutcome::Hit(h) = t.trace(&ray, Start::Tet(start)) {
            out.push(h);
        }
    }
    out
}

#[test]
fn shadow_walks_agree_with_brute_force_visibility() {
    let mut compared = 0;
    let mut occluded = 0;
    for seed in 0..6u64 {
        let m = kuhn_grid(&GridSpec {
            cells: [4, 4, 4],
            jitter: 0.12,
            constrained_fraction: 0.12,
            shell: (seed % 2 == 1).then_some(([1; 3], [3; 3])),
            seed,
            ..Default::default()
        });
        let mut rng = SplitMix64(seed * 7 + 1);
        let hits = random_hits(&m, &mut rng, 40);
        let lights: Vec<LightTarget> = (0..12)
            .map(|_| LightTarget::locate(&m, random_light(&m, &mut rng), 0).unwrap())
            .collect();
        let tracers = shadow_tracers(&m);
        for hit in &hits {
            let p = hit_point(&m, hit);
            for light in &lights {
                let Some(want) = brute_visible(&m, p, hit.face, light.position) else {
                    continue;
                };
                compared += 1;
                occluded += !want as u32;
                for (name, t) in &tracers {
                    let out = trace_shadow(t.as_ref(), hit, light);
                    assert!(
                        !matches!(out, Some(TraceOutcome::Failed { .. })),
                        "{name}: {out:?}"
                    );
                    assert_eq!(
                        visible_from(t.as_ref(), hit, light),
                        want,
                        "{name}, seed {seed}: from {p:?} (face {}) to {:?} (star {:?})",
                        hit.face,
                        light.position,
                        light.tets()
                    );
                }
            }
        }
    }
    assert!(compared > 2000, "{compared}");
    assert!(
        occluded > compared / 10 && occluded < compared * 9 / 10,
        "{occluded} of {compared}"
    );
}

/// The unjittered 4³ grid with every tet face lying in one of the planes
/// `axis = value` marked constrained (each plane one scene triangle id per
/// face).
fn planes(list: &[(usize, f32)]) -> TetMesh {
    let g = kuhn_grid(&GridSpec {
        cells: [4, 4, 4],
        jitter: 0.0,
        ..Default::default()
    });
    let mut tris = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for tet in &g.tets {
        for s in FACE_VERTICES {
            let f = [tet[s[0]], tet[s[1]], tet[s[2]]];
            let on = list
                .iter()
                .any(|&(a, v)| f.iter().all(|&i| g.points[i as usize][a] == v));
            if on && seen.insert(tet_core::face_key(f)) {
                tris.push((f, tris.len() as u32));
            }
        }
    }
    let n = tris.len() as u32;
    let m = TetMesh::assemble(g.points, g.tets, &tris, n).unwrap();
    m.validate().unwrap();
    m
}

fn hit_of(t: &dyn Tracer, origin: Vec3, dir: Vec3) -> Hit {
    let ray = Ray::new(origin, dir);
    let s = locate(t.mesh(), origin, 0).unwrap();
    *t.trace(&ray, Start::Tet(s)).hit().expect("hit")
}

#[test]
fn lights_on_constrained_vertices_edges_and_faces_light_both_sides() {
    // Constrained planes z = 1, 2, 3 and x = 3; lights on the plane z = 2.
    // The face a hit point lies on never occludes (the shadow ray starts on
    // it, on the light's side), so each case has its occluders elsewhere.
    let m = planes(&[(2, 1.0), (2, 2.0), (2, 3.0), (0, 3.0)]);
    let t20 = Tet20Tracer::<DuffF32>::new(&m).unwrap();
    // On z = 1, in the slab 1 < z < 2 (below the lights' plane).
    let below = hit_of(&t20, Vec3::new(1.3, 2.6, 1.5), Vec3::new(0.05, 0.1, -1.0));
    // On z = 3, in the slab 2 < z < 3 (above the lights' plane).
    let above = hit_of(&t20, Vec3::new(1.7, 1.4, 2.5), Vec3::new(-0.1, 0.05, 1.0));
    // On x = 3 seen from x > 3, at z ≈ 3.5 and z ≈ 0.5: the planes z = 3,
    // resp. z = 1 (and z = 2) lie between them and the lights.
    let high = hit_of(&t20, Vec3::new(3.6, 2.1, 3.5), Vec3::new(-1.0, 0.02, 0.03));
    let low = hit_of(&t20, Vec3::new(3.6, 1.1, 0.5), Vec3::new(-1.0, 0.03, 0.02));
    assert!((hit_point(&m, &high).x - 3.0).abs() < 1e-6);
    for (light, star_len, want) in [
        // A vertex of the plane z = 2: its 24 Kuhn tets.
        (
            Vec3::new(2.0, 2.0, 2.0),
            24..=24,
            [true, true, false, false],
        ),
        // The midpoint of a grid edge (in the plane z = 2).
        (Vec3::new(1.5, 2.0, 2.0), 4..=6, [true, true, false, false]),
        // Inside one triangle of the plane: one tet on each side.
        (Vec3::new(1.3, 2.55, 2.0), 2..=2, [true, true, false, false]),
        // Control: inside a tet of the slab 1 < z < 2.
        (
            Vec3::new(1.3, 2.55, 1.75),
            1..=1,
            [true, false, false, false],
        ),
    ] {
        let target = LightTarget::locate(&m, light, 0).unwrap();
        assert!(
            star_len.contains(&target.tets().len()),
            "{light:?}: star {:?}",
            target.tets()
        );
        for (name, t) in shadow_tracers(&m) {
            for (hit, w) in [&below, &above, &high, &low].into_iter().zip(want) {
                assert_eq!(
                    visible_from(t.as_ref(), hit, &target),
                    w,
                    "{name}: light {light:?} from {:?}",
                    hit_point(&m, hit)
                );
                // The independent brute force agrees.
                assert_eq!(
                    brute_visible(&m, hit_point(&m, hit), hit.face, light),
                    Some(w)
                );
            }
        }
    }
}

#[test]
fn light_inside_a_closed_shell_is_occluded_from_everywhere_outside() {
    // A closed shell (lattice box 1..3) plus random faces everywhere.
    let m = kuhn_grid(&GridSpec {
        cells: [4, 4, 4],
        jitter: 0.1,
        constrained_fraction: 0.08,
        shell: Some(([1; 3], [3; 3])),
        seed: 3,
        ..Default::default()
    });
    let tracers = shadow_tracers(&m);
    let t64 = Tet20Tracer::<DuffF64>::new(&m).unwrap();
    let mut rng = SplitMix64(11);
    // Lights well inside the shell.
    let mut lights = Vec::new();
    while lights.len() < 3 {
        let (p, _) = random_point_inside(&m, &mut rng);
        if p.cmpge(Vec3::splat(1.3)).all() && p.cmple(Vec3::splat(2.7)).all() {
            lights.push(LightTarget::locate(&m, p, 0).unwrap());
        }
    }
    let mut outside = 0;
    for _ in 0..600 {
        let (ray, s) = random_ray(&m, &mut rng, Aim::Random);
        let Some(hit) = t64.trace(&ray, Start::Tet(s)).hit().copied() else {
            continue;
        };
        // Hit points clearly outside the shell's box (not on the shell).
        let p = hit_point(&m, &hit);
        if !(p.cmple(Vec3::splat(0.85)).any() || p.cmpge(Vec3::splat(3.15)).any()) {
            continue;
        }
        outside += 1;
        for light in &lights {
            assert_eq!(brute_visible(&m, p, hit.face, light.position), Some(false));
            for (name, t) in &tracers {
                assert!(
                    !visible_from(t.as_ref(), &hit, light),
                    "{name}: lit from outside at {p:?}"
                );
            }
        }
    }
    assert!(outside > 50, "{outside}");
}

#[test]
fn lights_outside_the_mesh_end_at_their_distance() {
    let m = planes(&[(2, 1.0), (2, 2.0)]);
    let t = Tet20Tracer::<DuffF32>::new(&m).unwrap();
    let hit = hit_of(&t, Vec3::new(1.3, 1.7, 1.6), Vec3::new(0.1, 0.2, -1.0));
    // Above the mesh (z > 4): the plate z = 2 occludes; below the floor
    // (z < 0): nothing beyond the floor.
    let above = LightTarget::locate_or_outside(&m, Vec3::new(2.1, 2.3, 6.0), 0).unwrap();
    assert!(above.tets().is_empty());
    assert!(!visible_from(&t, &hit, &above));
    let between = LightTarget::locate_or_outside(&m, Vec3::new(2.1, 2.3, 1.2), 0).unwrap();
    assert_eq!(between.tets().len(), 1);
    assert!(visible_from(&t, &hit, &between));
    // The walk stops in the light's tet: it visits fewer tets than the
    // distance-only rule, which walks on to the next face beyond the light.
    let full = trace_shadow(&t, &hit, &between).unwrap();
    let far = LightTarget::outside(between.position);
    let dist_only = trace_shadow(&t, &hit, &far).unwrap();
    assert!(matches!(full, TraceOutcome::Miss { .. }));
    assert!(matches!(dist_only, TraceOutcome::Miss { .. }));
    assert!(full.tets_visited() < dist_only.tets_visited());
}
