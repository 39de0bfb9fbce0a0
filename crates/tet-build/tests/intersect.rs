//! Self-intersection detection on hand-built pairs, against a brute-force
//! O(n²) pass on random soups, and (ignored) on the shared meshes.

use std::path::Path;

use glam::Vec3;
use proptest::prelude::*;
use tet_build::intersect::{
    IntersectionKind, classify_pair, find_self_intersections, find_self_intersections_brute_force,
};
use tet_build::scene::Scene;

fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

/// Run the pair through the full detector (two triangles, separate vertices).
fn detect(a: [Vec3; 3], b: [Vec3; 3]) -> Option<IntersectionKind> {
    let verts: Vec<Vec3> = a.iter().chain(&b).copied().collect();
    let r = find_self_intersections(&verts, &[[0, 1, 2], [3, 4, 5]]);
    let direct = classify_pair(a, b);
    let reversed = classify_pair(b, a);
    assert_eq!(direct, reversed, "classification must be symmetric");
    match r.pairs.as_slice() {
        [] => assert_eq!(direct, None),
        [p] => {
            assert_eq!((p.first, p.second), (0, 1));
            assert_eq!(Some(p.kind), direct);
        }
        _ => unreachable!(),
    }
    direct
}

const A: [Vec3; 3] = [
    Vec3::new(0.0, 0.0, 0.0),
    Vec3::new(2.0, 0.0, 0.0),
    Vec3::new(0.0, 2.0, 0.0),
];

#[test]
fn crossing() {
    let b = [v(0.5, 0.5, -1.0), v(0.5, 0.5, 1.0), v(3.0, 3.0, 0.5)];
    assert_eq!(detect(A, b), Some(IntersectionKind::Transversal));
}

#[test]
fn separated() {
    let b = [v(5.0, 5.0, -1.0), v(5.0, 5.0, 1.0), v(6.0, 6.0, 0.5)];
    assert_eq!(detect(A, b), None);
}

#[test]
fn touching_at_a_shared_vertex() {
    // Shares A's corner (0,0,0), rises out of the plane.
    let b = [v(0.0, 0.0, 0.0), v(-1.0, 0.0, 1.0), v(0.0, -1.0, 1.0)];
    assert_eq!(detect(A, b), None);
    // Shares the corner and lies in the plane, in a disjoint wedge.
    let b = [v(0.0, 0.0, 0.0), v(-1.0, 0.0, 0.0), v(0.0, -1.0, 0.0)];
    assert_eq!(detect(A, b), None);
    // Shares the corner but its opposite edge pierces A.
    let b = [v(0.0, 0.0, 0.0), v(0.5, 0.5, -1.0), v(0.5, 0.5, 1.0)];
    assert_eq!(detect(A, b), Some(IntersectionKind::Transversal));
    // Shares the corner, coplanar, wedges overlap.
    let b = [v(0.0, 0.0, 0.0), v(1.0, 1.0, 0.0), v(-1.0, 1.0, 0.0)];
    assert_eq!(detect(A, b), Some(IntersectionKind::Coplanar));
    // Shares the corner, coplanar, one edge runs along A's edge (overlap on a segment).
    let b = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, -1.0, 0.0)];
    assert_eq!(detect(A, b), Some(IntersectionKind::Coplanar));
}

#[test]
fn touching_at_an_unshared_point_is_reported() {
    // B's corner lies inside A without being a vertex of A.
    let b = [v(0.5, 0.5, 0.0), v(0.5, 0.5, 1.0), v(1.0, 0.0, 1.0)];
    assert_eq!(detect(A, b), Some(IntersectionKind::Transversal));
}

#[test]
fn sharing_an_edge() {
    // Non-coplanar hinge.
    let b = [v(2.0, 0.0, 0.0), v(0.0, 0.0, 0.0), v(1.0, -1.0, 1.0)];
    assert_eq!(detect(A, b), None);
    // Coplanar, opposite sides (a proper planar neighbour).
    let b = [v(2.0, 0.0, 0.0), v(0.0, 0.0, 0.0), v(1.0, -1.0, 0.0)];
    assert_eq!(detect(A, b), None);
    // Coplanar, same side: folded over.
    let b = [v(2.0, 0.0, 0.0), v(0.0, 0.0, 0.0), v(1.0, 0.5, 0.0)];
    assert_eq!(detect(A, b), Some(IntersectionKind::Coplanar));
}

#[test]
fn coplanar_overlapping_without_shared_vertices() {
    let b = [v(0.5, 0.5, 0.0), v(3.0, 0.5, 0.0), v(0.5, 3.0, 0.0)];
    assert_eq!(detect(A, b), Some(IntersectionKind::Coplanar));
    // B strictly inside A.
    let b = [v(0.2, 0.2, 0.0), v(0.6, 0.2, 0.0), v(0.2, 0.6, 0.0)];
    assert_eq!(detect(A, b), Some(IntersectionKind::Coplanar));
    // Coplanar, disjoint.
    let b = [v(3.0, 3.0, 0.0), v(4.0, 3.0, 0.0), v(3.0, 4.0, 0.0)];
    assert_eq!(detect(A, b), None);
}

#[test]
fn duplicate_positions() {
    let b = [A[2], A[0], A[1]];
    assert_eq!(detect(A, b), Some(IntersectionKind::Duplicate));
}

#[test]
fn near_parallel_1e_7_apart() {
    let b = [v(0.1, 0.1, 1e-7), v(1.9, 0.05, 1e-7), v(0.05, 1.9, 1e-7)];
    assert_eq!(detect(A, b), None);
    // Tilted so one corner dips 1e-7 below the plane: a genuine crossing.
    let b = [v(0.1, 0.1, -1e-7), v(1.5, 0.1, 1e-7), v(0.1, 1.5, 1e-7)];
    assert_eq!(detect(A, b), Some(IntersectionKind::Transversal));
}

#[test]
fn degenerate_triangles_are_listed_not_tested() {
    let verts = vec![
        v(0.0, 0.0, 0.0),
        v(1.0, 1.0, 1.0),
        v(2.0, 2.0, 2.0),
        v(0.0, 1.0, 0.0),
    ];
    let r = find_self_intersections(&verts, &[[0, 1, 2], [0, 1, 3]]);
    assert_eq!(r.degenerate, vec![0]);
    assert!(r.pairs.is_empty());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    /// Grid broad phase finds exactly the brute-force pairs, on soups with
    /// many exact degeneracies (small integer coordinates).
    #[test]
    fn grid_matches_brute_force(
        coords in prop::collection::vec(prop::array::uniform3(-3i32..4), 4..30),
        raw in prop::collection::vec(prop::array::uniform3(0u32..1000), 1..40),
    ) {
        let n = coords.len() as u32;
        let tris: Vec<[u32; 3]> = raw.iter().map(|t| t.map(|i| i % n)).collect();
        let verts: Vec<Vec3> = coords.iter().map(|c| Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32) * 0.5).collect();
        let grid = find_self_intersections(&verts, &tris);
        let brute = find_self_intersections_brute_force(&verts, &tris);
        prop_assert_eq!(grid.pairs, brute);
    }
}

/// `file` in the scenes' directory, loaded, if it is there: `TET_SHARED_SCENES`
/// when set (a copy of the whole data set, the files the repository leaves
/// out included; see `scenes/README.md`), else the repository's `scenes/`.
fn shared_scene(file: &str) -> Option<Scene> {
    let dir = std::env::var_os("TET_SHARED_SCENES")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes"));
    let p = dir.join(file);
    if !p.exists() {
        eprintln!("skipping: {} not present", p.display());
        return None;
    }
    Some(Scene::load(p.to_str().unwrap()).unwrap())
}

#[test]
#[ignore = "shared meshes; run in release"]
fn teapot_self_intersects() {
    let Some(s) = shared_scene("teapot.obj") else {
        return;
    };
    let t = std::time::Instant::now();
    let r = find_self_intersections(&s.vertices, &s.triangles);
    let count = |k| r.pairs.iter().filter(|p| p.kind == k).count();
    eprintln!(
        "teapot: {} triangles, {} pairs ({} transversal, {} coplanar, {} duplicate), {} degenerate, {} candidates, {:?}",
        s.triangles.len(),
        r.pairs.len(),
        count(IntersectionKind::Transversal),
        count(IntersectionKind::Coplanar),
        count(IntersectionKind::Duplicate),
        r.degenerate.len(),
        r.candidates,
        t.elapsed()
    );
    // How many of them the float reference also sees as proper crossings
    // (the rest are contacts such as a vertex lying on another part's face).
    let tri = |t: u32| s.triangles[t as usize].map(|i| s.vertices[i as usize]);
    let float_agree = r
        .pairs
        .iter()
        .filter(|p| float_reference(tri(p.first), tri(p.second)))
        .count();
    eprintln!(
        "teapot: float reference confirms {float_agree} of {}",
        r.pairs.len()
    );
    assert!(!r.pairs.is_empty(), "the teapot is known to self-intersect");
}

#[test]
#[ignore = "shared meshes; run in release"]
fn bunny_and_large_meshes_report() {
    for file in [
        "stanford-bunny.obj",
        "armadillo_stanford_100k.obj",
        "nefertiti.obj",
        "fandisk.obj",
        "beast.obj",
        "spot.obj",
        "neptune_aimatshape_30k.obj",
        "teapot.obj",
        "torus_knot.obj",
        "box.obj",
    ] {
        let Some(s) = shared_scene(file) else {
            continue;
        };
        let t = std::time::Instant::now();
        let r = find_self_intersections(&s.vertices, &s.triangles);
        let el = t.elapsed();
        eprintln!(
            "{file}: {} triangles, {} pairs, {} degenerate, {} candidates, {:?}; first pairs {:?}",
            s.triangles.len(),
            r.pairs.len(),
            r.degenerate.len(),
            r.candidates,
            el,
            &r.pairs[..r.pairs.len().min(5)]
        );
        assert!(el.as_secs_f64() < 10.0, "{file} took {el:?}");
        let c = tet_build::clean::clean(&s.vertices, &s.triangles).unwrap();
        let rep = &c.report;
        eprintln!(
            "{file}: clean merged {} vertices, dropped {} repeated-vertex, {} zero-area, {} duplicate triangles, {} unused vertices",
            rep.merged_vertices.len(),
            rep.repeated_vertex_triangles.len(),
            rep.zero_area_triangles.len(),
            rep.duplicate_triangles.len(),
            rep.unused_vertices.len()
        );
    }
}

/// Independent floating-point reference for triangles in general position:
/// they intersect iff an edge of one passes through the interior of the
/// other (parametric plane crossing + barycentric coordinates in f64).
fn float_reference(a: [Vec3; 3], b: [Vec3; 3]) -> bool {
    fn edge_hits(p: glam::DVec3, q: glam::DVec3, t: [glam::DVec3; 3]) -> bool {
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        let (dp, dq) = (n.dot(p - t[0]), n.dot(q - t[0]));
        if dp * dq > 0.0 || dp == dq {
            return false;
        }
        let x = p + (q - p) * (dp / (dp - dq));
        // Barycentric coordinates of x.
        let (v0, v1, v2) = (t[1] - t[0], t[2] - t[0], x - t[0]);
        let (d00, d01, d11, d20, d21) =
            (v0.dot(v0), v0.dot(v1), v1.dot(v1), v2.dot(v0), v2.dot(v1));
        let den = d00 * d11 - d01 * d01;
        let v = (d11 * d20 - d01 * d21) / den;
        let w = (d00 * d21 - d01 * d20) / den;
        v >= 0.0 && w >= 0.0 && v + w <= 1.0
    }
    let a = a.map(|p| p.as_dvec3());
    let b = b.map(|p| p.as_dvec3());
    (0..3).any(|i| edge_hits(a[i], a[(i + 1) % 3], b))
        || (0..3).any(|i| edge_hits(b[i], b[(i + 1) % 3], a))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]
    /// Random float triangles (general position): exact narrow phase agrees
    /// with the independent float reference.
    #[test]
    fn narrow_phase_matches_float_reference(c in prop::array::uniform18(-1.0f32..1.0)) {
        let a = [v(c[0], c[1], c[2]), v(c[3], c[4], c[5]), v(c[6], c[7], c[8])];
        let b = [v(c[9], c[10], c[11]), v(c[12], c[13], c[14]), v(c[15], c[16], c[17])];
        let exact = classify_pair(a, b);
        prop_assert_eq!(exact.is_some(), float_reference(a, b));
        if let Some(k) = exact {
            prop_assert_eq!(k, IntersectionKind::Transversal);
        }
    }
}

/// Many small triangles plus large ones spanning the whole scene (each large
/// triangle sits in many grid cells): still exactly the brute-force pairs.
#[test]
fn large_and_small_triangles_mix() {
    let mut verts = Vec::new();
    let mut tris = Vec::new();
    // 400 small, disjoint triangles on a 20×20 lattice in z = 0.
    for i in 0..20 {
        for j in 0..20 {
            let b = verts.len() as u32;
            let (x, y) = (i as f32, j as f32);
            verts.extend([v(x, y, 0.0), v(x + 0.5, y, 0.0), v(x, y + 0.5, 0.0)]);
            tris.push([b, b + 1, b + 2]);
        }
    }
    // 100 large slanted triangles spanning everything, crossing the plane z = 0.
    for k in 0..100 {
        let b = verts.len() as u32;
        let y = k as f32 * 0.2 + 0.05;
        verts.extend([v(-1.0, y, -1.0), v(21.0, y, -1.0), v(10.0, y + 0.2, 1.0)]);
        tris.push([b, b + 1, b + 2]);
    }
    let grid = find_self_intersections(&verts, &tris);
    let brute = find_self_intersections_brute_force(&verts, &tris);
    assert!(!brute.is_empty());
    assert_eq!(grid.pairs, brute);
}
