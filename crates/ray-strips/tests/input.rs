//! Bad and awkward input: typed errors naming the element, no panics on
//! degenerate, duplicate or non-manifold triangles, empty meshes.

mod common;

use glam::Vec3;
use ray_strips::{BuildError, BuildOptions, Ray, RayStrips};

fn quad() -> Vec<Vec3> {
    vec![
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ]
}

#[test]
fn an_index_out_of_range_names_the_triangle() {
    let err =
        RayStrips::build(&quad(), &[[0, 1, 2], [0, 2, 4]], &BuildOptions::default()).unwrap_err();
    assert_eq!(
        err,
        BuildError::IndexOutOfRange {
            triangle: 1,
            index: 4,
            vertex_count: 4
        }
    );
    assert!(err.to_string().contains("triangle 1"));
}

#[test]
fn a_non_finite_coordinate_names_the_vertex() {
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let mut v = quad();
        v[2].y = bad;
        let err = RayStrips::build(&v, &[[0, 1, 2]], &BuildOptions::default()).unwrap_err();
        assert!(
            matches!(err, BuildError::NonFiniteVertex { vertex: 2, .. }),
            "{err:?}"
        );
        assert!(err.to_string().contains("vertex 2"));
    }
}

#[test]
fn zero_chunk_size_is_an_error() {
    let err = RayStrips::build(
        &quad(),
        &[[0, 1, 2]],
        &BuildOptions {
            chunk_triangles: 0,
            ..BuildOptions::default()
        },
    )
    .unwrap_err();
    assert_eq!(err, BuildError::ZeroChunkTriangles);
}

#[test]
fn an_empty_mesh_hits_nothing() {
    for (v, t) in [
        (vec![], vec![]),
        (quad(), vec![]),
        (quad(), vec![[0, 0, 1], [2, 2, 2]]),
    ] {
        let rs = RayStrips::build(&v, &t, &BuildOptions::default()).unwrap();
        let ray = Ray::new(Vec3::new(0.5, 0.5, 1.0), Vec3::NEG_Z);
        assert_eq!(rs.intersect(&ray), None);
        assert!(!rs.occluded(&ray));
        let mut out = [None; 5];
        rs.intersect_packet(&[ray; 5], &mut out);
        assert_eq!(out, [None; 5]);
        assert_eq!(rs.stats().strips, 0);
        assert_eq!(rs.stats().skipped_triangles, t.len());
    }
}

#[test]
fn degenerate_duplicate_and_non_manifold_triangles_are_handled() {
    let mut v = quad();
    v.push(Vec3::new(0.5, 0.5, 1.0)); // 4: fin apex
    v.push(Vec3::new(2.0, 0.0, 0.0)); // 5: collinear with 0 and 1
    let t = vec![
        [0, 1, 2],
        [0, 2, 3],
        [0, 2, 3], // duplicate
        [2, 0, 3], // same triangle, other order
        [0, 2, 4], // third triangle on edge 0–2: non-manifold
        [1, 1, 3], // repeated index: skipped
        [0, 1, 5], // collinear: kept, never hit
    ];
    let rs = RayStrips::build(&v, &t, &BuildOptions::default()).unwrap();
    assert_eq!(rs.stats().skipped_triangles, 1);
    assert_eq!(rs.stats().triangles, 6);
    // Straight down through the second half of the quad: the three copies
    // tie; the smallest input index wins.
    let h = rs
        .intersect(&Ray::new(Vec3::new(0.2, 0.7, 2.0), Vec3::NEG_Z))
        .unwrap();
    assert_eq!(h.triangle, 1);
    assert!((h.t - 2.0).abs() < 1e-6);
    // Barycentrics in input order of triangle 1 = (0, 2, 3):
    // p = (1−u−v)·(0,0) + u·(1,1) + v·(0,1) = (0.2, 0.7) ⇒ u = 0.2, v = 0.5.
    assert!(
        (h.u - 0.2).abs() < 1e-6 && (h.v - 0.5).abs() < 1e-6,
        "{h:?}"
    );
    // Along the collinear triangle's line: no hit on it, no panic.
    let along = Ray::new(Vec3::new(3.0, 0.0, 0.0), Vec3::NEG_X);
    let _ = rs.intersect(&along);
    assert_eq!(
        rs.intersect(&Ray::new(Vec3::new(1.5, 0.0, 1.0), Vec3::NEG_Z)),
        None,
        "the zero-area triangle (0, 1, 5) is never hit"
    );
}

#[test]
fn untraceable_rays_hit_nothing() {
    let rs = RayStrips::build(&quad(), &[[0, 1, 2]], &BuildOptions::default()).unwrap();
    for ray in [
        Ray::new(Vec3::new(0.7, 0.2, 1.0), Vec3::ZERO),
        Ray::new(Vec3::new(f32::NAN, 0.2, 1.0), Vec3::NEG_Z),
        Ray::new(
            Vec3::new(0.7, 0.2, 1.0),
            Vec3::new(0.0, f32::INFINITY, -1.0),
        ),
        Ray {
            t_min: 2.0,
            t_max: 1.0,
            ..Ray::new(Vec3::new(0.7, 0.2, 1.0), Vec3::NEG_Z)
        },
    ] {
        assert_eq!(rs.intersect(&ray), None);
        assert!(!rs.occluded(&ray));
    }
    let ok = Ray::new(Vec3::new(0.7, 0.2, 1.0), Vec3::NEG_Z);
    assert!(rs.intersect(&ok).is_some());
    // t range is inclusive at both ends.
    let exact = Ray {
        t_min: 1.0,
        t_max: 1.0,
        ..ok
    };
    assert_eq!(rs.intersect(&exact).map(|h| h.t), Some(1.0));
}

#[test]
fn the_structure_is_send_and_sync() {
    fn check<T: Send + Sync>() {}
    check::<RayStrips>();
}

#[test]
fn subnormal_direction_components_count_as_zero() {
    let rs = RayStrips::build(&quad(), &[[0, 1, 2], [0, 2, 3]], &BuildOptions::default()).unwrap();
    // Straight down through the shared diagonal's end at a box face, with a
    // subnormal sideways component: still a hit, no NaN.
    let tiny = f32::MIN_POSITIVE / 4.0;
    let ray = Ray::new(Vec3::new(1.0, 1.0, 1.0), Vec3::new(tiny, -tiny, -1.0));
    let h = rs.intersect(&ray).expect("hit at the corner");
    assert_eq!(h.t, 1.0);
    // Only subnormal components: nothing.
    assert_eq!(rs.intersect(&Ray::new(Vec3::ONE, Vec3::splat(-tiny))), None);
}
