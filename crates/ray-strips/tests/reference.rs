//! Hits against an f64 brute-force reference on random meshes and rays;
//! packets and occlusion against single-ray `intersect`.

mod common;

use common::Reference;
use glam::Vec3;
use proptest::prelude::*;
use ray_strips::{BuildOptions, Hit, Ray, RayStrips};

const EPS: f64 = 1e-4;

/// A random mesh: a noisy height field (long strips), a random triangle
/// soup over few vertices (short strips, duplicates, non-manifold edges)
/// or both.
fn mesh() -> impl Strategy<Value = (Vec<Vec3>, Vec<[u32; 3]>)> {
    let field = (2u32..12, 2u32..12, any::<u64>()).prop_map(|(w, h, seed)| {
        let mut s = seed | 1;
        let heights: Vec<f32> = (0..(w + 1) * (h + 1))
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                (s % 1000) as f32 / 500.0 - 1.0
            })
            .collect();
        let (v, f) = common::grid(w, h, &heights);
        // Centre it around the origin at a scale that is not a power of two.
        let shift = Vec3::new(w as f32 / 2.0, h as f32 / 2.0, 0.0);
        (v.iter().map(|p| (*p - shift) * 0.37).collect(), f)
    });
    let soup = (4usize..20)
        .prop_flat_map(|n| {
            (
                prop::collection::vec((-2.0f32..2.0, -2.0f32..2.0, -2.0f32..2.0), n),
                prop::collection::vec((0..n as u32, 0..n as u32, 0..n as u32), 1..40),
            )
        })
        .prop_map(|(v, f)| {
            (
                v.into_iter().map(|(x, y, z)| Vec3::new(x, y, z)).collect(),
                f.into_iter().map(|(a, b, c)| [a, b, c]).collect(),
            )
        });
    prop_oneof![field, soup]
}

fn unit() -> impl Strategy<Value = Vec3> {
    (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0)
        .prop_filter("non-zero", |(x, y, z)| x * x + y * y + z * z > 1e-3)
        .prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// Random rays: origins around the mesh aimed at random points near it.
fn rays() -> impl Strategy<Value = Vec<Ray>> {
    prop::collection::vec(
        (
            unit(),
            -2.0f32..2.0,
            -2.0f32..2.0,
            -1.0f32..1.0,
            0.5f32..4.0,
            0.0f32..0.3,
            prop::bool::ANY,
        ),
        16..48,
    )
    .prop_map(|rs| {
        rs.into_iter()
            .map(|(from, x, y, z, dist, t_min, bounded)| {
                let target = Vec3::new(x, y, z);
                let origin = target + from * dist;
                let mut ray = Ray::new(origin, (target - origin) * 0.7);
                ray.t_min = t_min;
                if bounded {
                    ray.t_max = 1.2;
                }
                ray
            })
            .collect()
    })
}

/// Coherent 2×2 groups: a camera at `eye` looking at the origin.
fn camera_rays(eye: Vec3, n: usize) -> Vec<Ray> {
    let forward = (-eye).normalize();
    let right = forward.cross(Vec3::Z).normalize_or(Vec3::X);
    let up = right.cross(forward);
    let mut rays = Vec::new();
    for by in 0..n {
        for bx in 0..n {
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let px = (2 * bx + dx) as f32 / (2 * n) as f32 - 0.5;
                let py = (2 * by + dy) as f32 / (2 * n) as f32 - 0.5;
                rays.push(Ray::new(eye, forward + 1.2 * (px * right + py * up)));
            }
        }
    }
    rays
}

fn bits(h: &Option<Hit>) -> Option<(u32, u32, u32, u32)> {
    h.map(|h| (h.triangle, h.t.to_bits(), h.u.to_bits(), h.v.to_bits()))
}

fn check_against_reference(positions: &[Vec3], triangles: &[[u32; 3]], rs: &RayStrips, ray: &Ray) {
    let got = rs.intersect(ray);
    match common::reference(
        positions,
        triangles,
        ray.origin,
        ray.direction,
        ray.t_min,
        ray.t_max,
        EPS,
    ) {
        Reference::Ambiguous => {}
        Reference::Miss => assert_eq!(got, None, "reference misses {ray:?}"),
        Reference::Hit(r) => {
            let h = got.unwrap_or_else(|| panic!("reference hits {r:?} with {ray:?}"));
            assert_eq!(h.triangle as usize, r.triangle, "{ray:?}");
            assert!(
                (f64::from(h.t) - r.t).abs() <= EPS * r.t.abs().max(1e-3),
                "t {} vs {}",
                h.t,
                r.t
            );
            assert!((f64::from(h.u) - r.u).abs() <= EPS, "u {} vs {}", h.u, r.u);
            assert!((f64::from(h.v) - r.v).abs() <= EPS, "v {} vs {}", h.v, r.v);
        }
    }
}

fn check_packets(rs: &RayStrips, rays: &[Ray]) {
    let mut out = vec![None; rays.len()];
    rs.intersect_packet(rays, &mut out);
    for (ray, p) in rays.iter().zip(&out) {
        let single = rs.intersect(ray);
        assert_eq!(bits(p), bits(&single), "packet vs single for {ray:?}");
        assert_eq!(rs.occluded(ray), single.is_some(), "occluded for {ray:?}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn hits_match_the_f64_reference(
        (positions, triangles) in mesh(),
        rays in rays(),
        chunk in prop_oneof![Just(1usize), Just(4), Just(16), Just(256)],
        strips_per_leaf in 1usize..4,
        strip_swaps in any::<bool>(),
    ) {
        let rs = RayStrips::build(&positions, &triangles, &BuildOptions { chunk_triangles: chunk, strips_per_leaf, strip_swaps })
            .unwrap();
        for ray in &rays {
            check_against_reference(&positions, &triangles, &rs, ray);
        }
        check_packets(&rs, &rays);
    }

    #[test]
    fn packets_equal_single_rays_bit_for_bit(
        (positions, triangles) in mesh(),
        eye in unit(),
        dist in 1.5f32..6.0,
        chunk in prop_oneof![Just(2usize), Just(32), Just(256)],
        strips_per_leaf in 1usize..4,
        strip_swaps in any::<bool>(),
    ) {
        let rs = RayStrips::build(&positions, &triangles, &BuildOptions { chunk_triangles: chunk, strips_per_leaf, strip_swaps })
            .unwrap();
        let rays = camera_rays(eye.normalize() * dist, 6);
        check_packets(&rs, &rays);
        // Odd lengths and mixed groups.
        check_packets(&rs, &rays[1..rays.len() - 2]);
        for ray in rays.iter().step_by(7) {
            check_against_reference(&positions, &triangles, &rs, ray);
        }
    }
}

#[test]
fn a_camera_over_a_sphere_agrees_with_the_reference() {
    let (positions, triangles) = common::icosphere(3, Vec3::new(0.1, 0.2, -0.3), 1.3);
    let rs = RayStrips::build(&positions, &triangles, &BuildOptions::default()).unwrap();
    let rays = camera_rays(Vec3::new(2.5, -3.0, 1.5), 16);
    let mut hits = 0;
    for ray in &rays {
        check_against_reference(&positions, &triangles, &rs, ray);
        hits += usize::from(rs.intersect(ray).is_some());
    }
    assert!(hits > rays.len() / 8, "the sphere fills part of the view");
    check_packets(&rs, &rays);
}

#[test]
fn scaled_and_displaced_meshes_agree_with_the_reference() {
    // Scales whose products overflow or underflow f32 unless the
    // structure works in its own frame, and a scene far from the origin;
    // chunks of several strips per leaf, so that the quantized strip boxes
    // decide which strips a ray enters.
    for (scale, offset) in [
        (1e-15f32, Vec3::ZERO),
        (1e15, Vec3::ZERO),
        (1e-30, Vec3::ZERO),
        (1e30, Vec3::ZERO),
        (1e37, Vec3::ZERO),
        (1.0, Vec3::new(1e4, -2e4, 5e3)),
    ] {
        let (unit, triangles) = common::torus(32, 12, 1.0, 0.35, Vec3::ZERO);
        let positions: Vec<Vec3> = unit.iter().map(|&p| p * scale + offset).collect();
        for strips_per_leaf in [1, 16] {
            let options = BuildOptions {
                strips_per_leaf,
                ..BuildOptions::default()
            };
            let rs = RayStrips::build(&positions, &triangles, &options).unwrap();
            let mut hits = 0;
            for ray in camera_rays(Vec3::new(0.4, 2.2, 1.3) * 1.4, 12) {
                let ray = Ray::new(ray.origin * scale + offset, ray.direction);
                check_against_reference(&positions, &triangles, &rs, &ray);
                if let Some(h) = rs.intersect(&ray) {
                    hits += 1;
                    // The distance in the caller's frame, to f32 precision.
                    let p = common::point(
                        &positions,
                        triangles[h.triangle as usize],
                        f64::from(h.u),
                        f64::from(h.v),
                    );
                    let along = ray.origin.as_dvec3() + f64::from(h.t) * ray.direction.as_dvec3();
                    assert!(
                        (p - along).length() <= 1e-4 * (p.length() + f64::from(scale)),
                        "scale {scale}: hit point {p} vs {along}"
                    );
                }
            }
            assert!(
                hits > 50,
                "scale {scale}: the torus is in view ({hits} hits)"
            );
        }
    }
}
