//! Maria et al.'s Algorithm 2 (Tet80 start tet in three side products)
//! against an independent f64 exit-face test, against the engine's
//! four-face start test, and whole Tet80 walks from interior points and
//! from vertices / edges / faces against the brute-force reference.

use glam::DVec3;
use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};
use tet_core::{FACE_VERTICES, TetMesh};
use tet_trace_cpu::reference::{
    Aim, closest_hit, grazes_an_edge, random_direction, random_point_inside, random_ray,
    ray_from_feature,
};
use tet_trace_cpu::tet80::Tet80Tracer;
use tet_trace_cpu::walk::start_exit_face;
use tet_trace_cpu::{DuffF64, Ray, Start, TraceOutcome, Tracer, locate};

fn mesh(seed: u64) -> TetMesh {
    kuhn_grid(&GridSpec {
        cells: [4, 4, 4],
        jitter: 0.12,
        constrained_fraction: 0.15,
        shell: seed.is_multiple_of(2).then_some(([1; 3], [3; 3])),
        seed,
        ..Default::default()
    })
}

/// The face of tet `t` through which the line leaves it, from the f64 edge
/// functions `d · (qa × qb)` of each outward face (all positive for the exit
/// face), with the margin of the decision (smallest edge function of the
/// winner relative to the scale, and largest of the others); `None` when the
/// margin is below `tol` (the line passes within rounding of an edge).
fn exit_face_f64(m: &TetMesh, ray: &Ray, t: u32, tol: f64) -> Option<usize> {
    let o = ray.origin.as_dvec3();
    let d = ray.direction.as_dvec3().normalize();
    let q: Vec<DVec3> = m.tet_points(t).iter().map(|p| p.as_dvec3() - o).collect();
    let scale = q.iter().map(|x| x.length_squared()).fold(0.0, f64::max);
    let mins: Vec<f64> = FACE_VERTICES
        .iter()
        .map(|s| {
            let e = |a: usize, b: usize| d.dot(q[a].cross(q[b])) / scale;
            e(s[0], s[1]).min(e(s[1], s[2])).min(e(s[2], s[0]))
        })
        .collect();
    let best = (0..4).max_by(|&a, &b| mins[a].total_cmp(&mins[b]))?;
    let others_max = (0..4)
        .filter(|&k| k != best)
        .map(|k| mins[k])
        .fold(f64::MIN, f64::max);
    (mins[best] > tol && others_max < -tol).then_some(best)
}

#[test]
fn algorithm2_finds_the_exit_face_from_interior_points() {
    let (mut compared, mut skipped) = (0, 0);
    for seed in 0..4 {
        let m = mesh(seed);
        let t80 = Tet80Tracer::new(&m).unwrap();
        let mut rng = SplitMix64(seed + 100);
        for i in 0..3000 {
            let (o, t) = random_point_inside(&m, &mut rng);
            if !t80.strictly_inside(t, o) {
                continue;
            }
            // Random directions, and rays aimed exactly at vertices, edge
            // midpoints and face centroids of other tets.
            let ray = match i % 4 {
                0 => Ray::new(o, random_direction(&mut rng)),
                k => {
                    let aim = [Aim::Vertex, Aim::EdgeMidpoint, Aim::FaceCentroid][k - 1];
                    let (r, _) = random_ray(&m, &mut rng, aim);
                    let d = r.origin + r.direction - o;
                    if d.length_squared() == 0.0 {
                        continue;
                    }
                    Ray::new(o, d)
                }
            };
            let got = t80.algorithm2_exit_face(&ray, t);
            let Some(want) = exit_face_f64(&m, &ray, t, 1e-6) else {
                skipped += 1;
                continue;
            };
            assert_eq!(got, want, "seed {seed}, ray {ray:?} in tet {t}");
            // The engine's four-face test agrees (in f64).
            assert_eq!(start_exit_face::<DuffF64>(&m, &ray, t), Some((t, want)));
            compared += 1;
        }
    }
    assert!(
        compared > 10000 && skipped < compared / 50,
        "{compared} {skipped}"
    );
}

/// Every face is chosen, from both fake entries: the rule is exercised in
/// full (not only the faces around one vertex).
#[test]
fn algorithm2_reaches_all_four_faces() {
    let m = mesh(1);
    let t80 = Tet80Tracer::new(&m).unwrap();
    let mut rng = SplitMix64(5);
    let mut seen = [0u32; 4];
    for _ in 0..2000 {
        let (o, t) = random_point_inside(&m, &mut rng);
        let ray = Ray::new(o, random_direction(&mut rng));
        seen[t80.algorithm2_exit_face(&ray, t)] += 1;
    }
    assert!(seen.iter().all(|&c| c > 200), "{seen:?}");
}

#[test]
fn tet80_walks_from_interior_points_and_features_match_the_reference() {
    // Per origin kind: interior point, vertex, edge midpoint, face centroid.
    let (mut compared, mut wrong) = ([0u32; 4], [0u32; 4]);
    for seed in 0..4 {
        let m = mesh(seed);
        let t80 = Tet80Tracer::new(&m).unwrap();
        let mut rng = SplitMix64(seed + 7);
        for i in 0..1500 {
            let (ray, start) = match i % 4 {
                0 => random_ray(&m, &mut rng, Aim::Random),
                k => {
                    let aim = [Aim::Vertex, Aim::EdgeMidpoint, Aim::FaceCentroid][k - 1];
                    let r = ray_from_feature(&m, &mut rng, aim);
                    let s = locate(&m, r.origin, 0).unwrap();
                    // On a vertex the origin is never "strictly inside", so
                    // the start falls back to the search around it (edge
                    // midpoints and centroids round off their plane in f32,
                    // into either path).
                    if k == 1 {
                        assert!(!t80.strictly_inside(s, r.origin));
                    }
                    (r, s)
                }
            };
            if grazes_an_edge(&m, &ray, 1e-3) {
                continue;
            }
            let want = closest_hit(&m, &ray);
            if want.is_some_and(|h| h.t < 1e-3 || h.t_gap < 1e-3) {
                continue;
            }
            let got = t80.trace(&ray, Start::Tet(start));
            compared[i % 4] += 1;
            let ok = match (got, want) {
                (TraceOutcome::Hit(h), Some(w)) => h.face == w.face,
                (TraceOutcome::Miss { .. }, None) => true,
                _ => false,
            };
            wrong[i % 4] += !ok as u32;
        }
    }
    // Tet80 is not watertight (Maria et al. report no failures in f32); on
    // rays clear of every triangle edge it matches the reference from
    // interior points (Algorithm 2) and from edge midpoints and face
    // centroids. From a vertex, the Plücker walk meets side products that
    // are exactly zero (an edge through the origin) and is occasionally
    // wrong or hits the step cap (reported, never a hang). That walk is
    // unchanged by Algorithm 2 (the start falls back to the search around
    // the vertex, as before); this test only reports its rate (5 of 69 with
    // these seeds).
    assert!(
        compared[0] > 1000 && compared[2] > 300 && compared[3] > 1000,
        "{compared:?}"
    );
    assert_eq!(
        [wrong[0], wrong[2], wrong[3]],
        [0; 3],
        "{wrong:?} of {compared:?}"
    );
    eprintln!(
        "tet80 from vertices: {} wrong of {} compared",
        wrong[1], compared[1]
    );
}

#[test]
fn batch_with_a_shared_origin_equals_single_traces() {
    let m = mesh(2);
    let t80 = Tet80Tracer::new(&m).unwrap();
    let mut rng = SplitMix64(9);
    // A shared interior origin (Algorithm 2 path) and a shared vertex origin
    // (fallback path).
    let (inside, t_in) = random_point_inside(&m, &mut rng);
    let vertex = m.points[(2 * 5 + 2) * 5 + 2];
    for o in [inside, vertex] {
        let s = if o == inside {
            t_in
        } else {
            locate(&m, o, 0).unwrap()
        };
        let rays: Vec<Ray> = (0..200)
            .map(|_| Ray::new(o, random_direction(&mut rng)))
            .collect();
        let mut out = vec![TraceOutcome::Miss { tets_visited: 0 }; rays.len()];
        t80.trace_batch(&rays, Start::Tet(s), &mut out);
        for (r, o) in rays.iter().zip(&out) {
            assert_eq!(*o, t80.trace(r, Start::Tet(s)));
        }
    }
}
