//! Resolving self-intersections: hand-built cases, random integer soups
//! (where exact contacts are common) and, ignored, the shared meshes.
//!
//! Every result is checked independently of the module: no pair meets
//! (the grid detector and the brute-force O(n²) pass), input vertices are
//! unchanged and first, every piece lies in its parent and is wound like
//! it, and the pieces cover every input triangle (area sums where no
//! coplanar overlap is involved, point samples everywhere).

use std::path::Path;
use std::time::Instant;

use glam::{DVec3, Vec3};
use proptest::prelude::*;
use tet_build::clean::clean;
use tet_build::intersect::{
    IntersectionKind, find_self_intersections, find_self_intersections_brute_force,
};
use tet_build::resolve::{ResolveError, ResolveOptions, Resolved, SNAP_ULPS, resolve};

fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

fn dv(p: Vec3) -> DVec3 {
    p.as_dvec3()
}

fn corners(vertices: &[Vec3], t: [u32; 3]) -> [DVec3; 3] {
    t.map(|i| dv(vertices[i as usize]))
}

fn normal(t: [DVec3; 3]) -> DVec3 {
    (t[1] - t[0]).cross(t[2] - t[0])
}

fn area(t: [DVec3; 3]) -> f64 {
    normal(t).length() * 0.5
}

/// Distance from `p` to the closed triangle `t` (non-degenerate).
fn distance_to_triangle(p: DVec3, t: [DVec3; 3]) -> f64 {
    let n = normal(t).normalize();
    let q = p - n * n.dot(p - t[0]);
    let inside = (0..3).all(|i| {
        let (a, b) = (t[i], t[(i + 1) % 3]);
        (b - a).cross(q - a).dot(n) >= 0.0
    });
    if inside {
        return (p - q).length();
    }
    (0..3)
        .map(|i| {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            let d = b - a;
            let s = ((p - a).dot(d) / d.length_squared()).clamp(0.0, 1.0);
            (p - (a + d * s)).length()
        })
        .fold(f64::INFINITY, f64::min)
}

/// A bound on how far a piece's corner may lie from where it belongs. Each
/// round rounds new points to `f32` (half a spacing per coordinate, the
/// spacing at the largest coordinate `m` being at most `2^-23 m`), may snap
/// a point onto a vertex up to `SNAP_ULPS` spacings away, and may route a
/// boundary through a point as far from it; a later round's points lie in
/// pieces that are already that far off. Euclidean: `sqrt(3)` times the
/// per-coordinate bound.
fn rounding_bound(vertices: &[Vec3], rounds: u32) -> f64 {
    let m = vertices
        .iter()
        .map(|p| p.abs().max_element())
        .fold(0.0f32, f32::max) as f64;
    let spacing = 2f64.powi(-23) * m.max(1e-30);
    rounds.max(1) as f64 * 3f64.sqrt() * (0.5 + 2.0 * SNAP_ULPS) * spacing * 1.01
}

/// Checks everything the module promises about `out` for this input.
fn check(vertices: &[Vec3], triangles: &[[u32; 3]], out: &Resolved) {
    let n = vertices.len();
    assert!(out.vertices.len() >= n);
    for (a, b) in vertices.iter().zip(&out.vertices) {
        assert_eq!(
            a.to_array().map(f32::to_bits),
            b.to_array().map(f32::to_bits)
        );
    }
    assert_eq!(out.report.added_points, out.vertices.len() - n);
    assert_eq!(out.triangles.len(), out.parent.len());
    for (t, &p) in out.triangles.iter().zip(&out.parent) {
        assert!((p as usize) < triangles.len(), "parent {p} out of range");
        assert!(t.iter().all(|&i| (i as usize) < out.vertices.len()));
    }
    // Every added point is used.
    let mut used = vec![false; out.vertices.len()];
    out.triangles
        .iter()
        .flatten()
        .for_each(|&i| used[i as usize] = true);
    assert!(used[n..].iter().all(|&u| u), "an added point is unused");
    // No two vertices share a position.
    let mut keys: Vec<[u32; 3]> = out
        .vertices
        .iter()
        .map(|p| (*p + Vec3::ZERO).to_array().map(f32::to_bits))
        .collect();
    keys.sort_unstable();
    let before = keys.len();
    keys.dedup();
    assert_eq!(keys.len(), before, "two output vertices share a position");

    // Free of self-intersections, by both detectors.
    let grid = find_self_intersections(&out.vertices, &out.triangles);
    assert!(
        grid.is_clean(),
        "pairs remain: {:?}",
        &grid.pairs[..grid.pairs.len().min(8)]
    );
    assert!(
        grid.degenerate.is_empty(),
        "degenerate pieces {:?}",
        grid.degenerate
    );
    let brute = find_self_intersections_brute_force(&out.vertices, &out.triangles);
    assert!(
        brute.is_empty(),
        "brute force finds {:?}",
        &brute[..brute.len().min(8)]
    );

    let tol = rounding_bound(&out.vertices, out.report.rounds);
    // Each piece in its parent, wound like it.
    for (t, &p) in out.triangles.iter().zip(&out.parent) {
        let piece = corners(&out.vertices, *t);
        let parent = corners(vertices, triangles[p as usize]);
        for q in piece {
            let d = distance_to_triangle(q, parent);
            assert!(
                d <= tol,
                "piece {t:?} corner {q} is {d} from parent {p} (bound {tol})"
            );
        }
        // A piece flat to within the rounding bound (its height over its
        // longest edge at most `tol`: three points collinear before
        // rounding) has no winding to check: its normal is rounding noise
        // and may stand at right angles to its parent's, where neither
        // winding agrees (found by this test: a crossing point exactly on a
        // parent's edge, rounded just off it).
        let longest = (0..3)
            .map(|i| (piece[(i + 1) % 3] - piece[i]).length())
            .fold(0.0, f64::max);
        let flat = normal(piece).length() <= tol * longest;
        assert!(
            flat || normal(piece).dot(normal(parent)) > 0.0,
            "piece {t:?} {piece:?} of {p} {parent:?} is wound against it: normals {} {}",
            normal(piece),
            normal(parent)
        );
    }
    // Areas: a parent's pieces never overlap each other, so they cover at
    // most its area; when nothing was merged and it overlaps nothing
    // coplanar, they cover it exactly once (up to the rounding of their
    // corners). Merged pieces (coplanar or, after snapping, identical) are
    // covered by another parent: the samples below check that.
    let coplanar: Vec<bool> = {
        let mut c = vec![false; triangles.len()];
        for pair in find_self_intersections_brute_force(vertices, triangles) {
            if pair.kind != IntersectionKind::Transversal {
                c[pair.first as usize] = true;
                c[pair.second as usize] = true;
            }
        }
        c
    };
    let mut sums = vec![0.0f64; triangles.len()];
    let mut slack = vec![0.0f64; triangles.len()];
    for (t, &p) in out.triangles.iter().zip(&out.parent) {
        let piece = corners(&out.vertices, *t);
        sums[p as usize] += area(piece);
        let perimeter: f64 = (0..3)
            .map(|i| (piece[(i + 1) % 3] - piece[i]).length())
            .sum();
        slack[p as usize] += 2.0 * tol * perimeter;
    }
    for (i, tri) in triangles.iter().enumerate() {
        let a = area(corners(vertices, *tri));
        let bound = slack[i] + 1e-12 * a;
        assert!(
            sums[i] <= a + bound,
            "triangle {i}: pieces cover {} of {a}",
            sums[i]
        );
        if !coplanar[i] && out.report.merged_pieces == 0 {
            assert!(
                (sums[i] - a).abs() <= bound,
                "triangle {i}: pieces cover {} of {a}",
                sums[i]
            );
        }
    }
    // Coverage by samples: every point of every input triangle is near some
    // piece (of any parent: coplanar overlaps are kept once).
    for tri in triangles {
        let t = corners(vertices, *tri);
        for (i, j) in [
            (1, 1),
            (2, 1),
            (1, 2),
            (4, 1),
            (1, 4),
            (3, 3),
            (0, 0),
            (6, 0),
            (0, 6),
            (3, 0),
        ] {
            let (a, b) = (i as f64 / 7.0, j as f64 / 7.0);
            let q = t[0] + (t[1] - t[0]) * a + (t[2] - t[0]) * b;
            let nearest = out
                .triangles
                .iter()
                .map(|&p| distance_to_triangle(q, corners(&out.vertices, p)))
                .fold(f64::INFINITY, f64::min);
            assert!(
                nearest <= tol,
                "point {q} of triangle {tri:?} is {nearest} from the nearest piece (bound {tol})"
            );
        }
    }
}

fn run(vertices: &[Vec3], triangles: &[[u32; 3]]) -> Resolved {
    let out = resolve(vertices, triangles, &ResolveOptions::default()).unwrap();
    check(vertices, triangles, &out);
    out
}

#[test]
fn a_clean_scene_comes_back_identical() {
    // A tetrahedron: its faces share edges only.
    let vertices = vec![
        v(0.0, 0.0, 0.0),
        v(1.0, 0.0, 0.0),
        v(0.0, 1.0, 0.0),
        v(0.0, 0.0, 1.0),
    ];
    let triangles = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let out = run(&vertices, &triangles);
    assert_eq!(out.vertices, vertices);
    assert_eq!(out.triangles, triangles);
    assert_eq!(out.parent, vec![0, 1, 2, 3]);
    assert_eq!(out.report, Default::default());
}

#[test]
fn triangles_sharing_an_edge_are_left_alone() {
    // Two triangles on a common edge, folded (not coplanar) and flat.
    for z in [1.0, 0.0] {
        let vertices = vec![
            v(0.0, 0.0, 0.0),
            v(2.0, 0.0, 0.0),
            v(1.0, 2.0, 0.0),
            v(1.0, -2.0, z),
        ];
        let triangles = vec![[0, 1, 2], [1, 0, 3]];
        let out = run(&vertices, &triangles);
        assert_eq!(out.triangles, triangles);
        assert_eq!(out.report.rounds, 0);
    }
}

#[test]
fn two_triangles_crossing_in_an_x() {
    // B stands through A's interior and out across A's edge 1-2.
    let vertices = vec![
        v(0.0, 0.0, 0.0),
        v(4.0, 0.0, 0.0),
        v(0.0, 4.0, 0.0),
        v(1.0, 1.0, -1.0),
        v(1.0, 1.0, 1.0),
        v(4.0, 4.0, 0.5),
    ];
    let triangles = vec![[0, 1, 2], [3, 4, 5]];
    let out = run(&vertices, &triangles);
    assert_eq!(out.report.pairs, 1);
    assert_eq!(out.report.split_triangles, 2);
    assert_eq!(out.report.merged_pieces, 0);
    // The planes z = 0 and x = y meet in A and B from (1, 1, 0), where B's
    // edge 3-4 pierces A, to (2, 2, 0), where A's edge 1-2 enters B: both
    // points added, and both triangles cut along the segment between them.
    assert_eq!(out.report.added_points, 2);
    let find = |p: Vec3| out.vertices.iter().position(|q| *q == p).expect("point") as u32;
    let (p, q) = (find(v(1.0, 1.0, 0.0)), find(v(2.0, 2.0, 0.0)));
    for parent in 0..2 {
        assert!(
            out.triangles
                .iter()
                .zip(&out.parent)
                .any(|(t, &o)| o == parent && t.contains(&p) && t.contains(&q)),
            "triangle {parent} is not cut along the segment"
        );
    }
}

#[test]
fn a_t_junction_splits_the_edge_it_touches() {
    // B's corner 3 lies on A's edge 0-1 (and B rises out of A's plane);
    // A's neighbour C across edge 0-1 must get the point too.
    let vertices = vec![
        v(0.0, 0.0, 0.0),
        v(4.0, 0.0, 0.0),
        v(0.0, 4.0, 0.0),
        v(2.0, 0.0, 0.0),
        v(2.0, 1.0, 3.0),
        v(3.0, 1.0, 3.0),
        v(2.0, -4.0, 0.0),
    ];
    let triangles = vec![[0, 1, 2], [3, 4, 5], [1, 0, 6]];
    let out = run(&vertices, &triangles);
    assert_eq!(out.report.pairs, 2);
    assert_eq!(out.report.added_points, 0);
    // Vertex 3 is a corner of pieces of A and of C.
    for parent in [0, 2] {
        assert!(
            out.triangles
                .iter()
                .zip(&out.parent)
                .any(|(t, &p)| p == parent && t.contains(&3)),
            "no piece of {parent} uses vertex 3"
        );
    }
}

#[test]
fn an_edge_through_another_triangles_vertex() {
    // B's edge 3-4 passes exactly through A's corner 1 (no new point).
    let vertices = vec![
        v(0.0, 0.0, 0.0),
        v(2.0, 0.0, 0.0),
        v(0.0, 2.0, 0.0),
        v(2.0, -1.0, -1.0),
        v(2.0, 1.0, 1.0),
        v(-1.0, 1.0, 1.0),
    ];
    let triangles = vec![[0, 1, 2], [3, 4, 5]];
    let out = run(&vertices, &triangles);
    assert!(out.report.pairs == 1);
    assert!(
        out.triangles
            .iter()
            .zip(&out.parent)
            .any(|(t, &p)| p == 1 && t.contains(&1)),
        "B's pieces must meet A's corner"
    );
}

#[test]
fn coplanar_triangles_overlapping_partly() {
    let vertices = vec![
        v(0.0, 0.0, 0.0),
        v(4.0, 0.0, 0.0),
        v(0.0, 4.0, 0.0),
        v(1.0, 1.0, 0.0),
        v(5.0, 1.0, 0.0),
        v(1.0, 5.0, 0.0),
    ];
    let triangles = vec![[0, 1, 2], [3, 4, 5]];
    let out = run(&vertices, &triangles);
    assert!(out.report.merged_pieces > 0);
    // The union's area: both minus the overlap (a right triangle with legs 2).
    let total: f64 = out
        .triangles
        .iter()
        .map(|&t| area(corners(&out.vertices, t)))
        .sum();
    assert!((total - (8.0 + 8.0 - 2.0)).abs() < 1e-5, "{total}");
    // The overlap stays with the lower index.
    let overlap_centre = DVec3::new(1.5, 1.5, 0.0);
    let owner: Vec<u32> = out
        .triangles
        .iter()
        .zip(&out.parent)
        .filter(|(t, _)| distance_to_triangle(overlap_centre, corners(&out.vertices, **t)) == 0.0)
        .map(|(_, &p)| p)
        .collect();
    assert!(
        !owner.is_empty() && owner.iter().all(|&p| p == 0),
        "{owner:?}"
    );
}

#[test]
fn a_duplicate_facet_with_opposite_winding_is_kept_once() {
    let vertices = vec![v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)];
    let triangles = vec![[0, 1, 2], [0, 2, 1]];
    let out = run(&vertices, &triangles);
    assert_eq!(out.triangles, vec![[0, 1, 2]]);
    assert_eq!(out.parent, vec![0]);
    assert_eq!(out.report.merged_pieces, 1);
    assert_eq!(out.report.split_triangles, 1);
}

/// A closed octahedron around `c` with "radius" `r`, outward.
fn octahedron(vertices: &mut Vec<Vec3>, triangles: &mut Vec<[u32; 3]>, c: Vec3, r: f32) {
    let b = vertices.len() as u32;
    for d in [
        Vec3::X,
        Vec3::NEG_X,
        Vec3::Y,
        Vec3::NEG_Y,
        Vec3::Z,
        Vec3::NEG_Z,
    ] {
        vertices.push(c + d * r);
    }
    let (px, nx, py, ny, pz, nz) = (b, b + 1, b + 2, b + 3, b + 4, b + 5);
    for (x, y) in [(px, py), (py, nx), (nx, ny), (ny, px)] {
        triangles.push([x, y, pz]);
        triangles.push([y, x, nz]);
    }
}

/// A closed axis-aligned cube `[lo, hi]`, outward, two triangles a face.
fn cube(vertices: &mut Vec<Vec3>, triangles: &mut Vec<[u32; 3]>, lo: Vec3, hi: Vec3) {
    let b = vertices.len() as u32;
    for i in 0..8 {
        vertices.push(Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        ));
    }
    for q in [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ] {
        let q = q.map(|i| b + i);
        triangles.push([q[0], q[1], q[2]]);
        triangles.push([q[0], q[2], q[3]]);
    }
}

#[test]
fn a_tetrahedron_pierced_by_a_thin_triangle() {
    let mut vertices = vec![
        v(0.0, 0.0, 0.0),
        v(2.0, 0.0, 0.0),
        v(0.0, 2.0, 0.0),
        v(0.0, 0.0, 2.0),
    ];
    let mut triangles = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    // A needle through the solid: from below the base to beyond face 1-2-3.
    vertices.extend([v(0.3, 0.4, -1.0), v(0.31, 0.4, -1.0), v(0.5, 0.5, 3.0)]);
    triangles.push([4, 5, 6]);
    let out = run(&vertices, &triangles);
    assert_eq!(out.report.pairs, 2);
}

#[test]
fn interpenetrating_octahedra() {
    let (mut vertices, mut triangles) = (Vec::new(), Vec::new());
    octahedron(&mut vertices, &mut triangles, Vec3::ZERO, 1.0);
    octahedron(&mut vertices, &mut triangles, v(0.5, 0.3, 0.2), 1.0);
    let out = run(&vertices, &triangles);
    assert!(out.report.pairs > 0);
}

#[test]
fn interpenetrating_cubes_with_shared_planes() {
    // Faces in common planes (coplanar overlaps) and edges crossing edges.
    let (mut vertices, mut triangles) = (Vec::new(), Vec::new());
    cube(&mut vertices, &mut triangles, Vec3::ZERO, Vec3::splat(2.0));
    cube(
        &mut vertices,
        &mut triangles,
        v(1.0, 1.0, 0.0),
        v(3.0, 3.0, 2.0),
    );
    let out = run(&vertices, &triangles);
    assert!(out.report.merged_pieces > 0);
}

#[test]
fn three_triangles_through_one_line_and_a_triple_point() {
    // Three mutually crossing triangles: their segments cross in each
    // triangle at the point where the three planes meet.
    let vertices = vec![
        v(-2.0, -2.0, 0.0),
        v(3.0, -2.0, 0.0),
        v(-2.0, 3.0, 0.0),
        v(0.0, -2.0, -2.0),
        v(0.0, 3.0, -2.0),
        v(0.0, -2.0, 3.0),
        v(-2.0, 0.0, -2.0),
        v(-2.0, 0.0, 3.0),
        v(3.0, 0.0, -2.0),
    ];
    let triangles = vec![[0, 1, 2], [3, 4, 5], [6, 7, 8]];
    let out = run(&vertices, &triangles);
    assert_eq!(out.report.pairs, 3);
    // The origin, where the planes meet, is a vertex of pieces of all three.
    let origin = out
        .vertices
        .iter()
        .position(|p| *p == Vec3::ZERO)
        .expect("triple point");
    for parent in 0..3 {
        assert!(
            out.triangles
                .iter()
                .zip(&out.parent)
                .any(|(t, &p)| p == parent && t.contains(&(origin as u32))),
            "no piece of {parent} meets the triple point"
        );
    }
}

#[test]
fn an_edge_lying_inside_another_triangle() {
    // B stands on A: B's bottom edge 3-4 lies in A's plane, inside A.
    // A gets that edge as a constraint; B is left as it is.
    let vertices = vec![
        v(0.0, 0.0, 0.0),
        v(4.0, 0.0, 0.0),
        v(0.0, 4.0, 0.0),
        v(1.0, 1.0, 0.0),
        v(2.0, 1.0, 0.0),
        v(1.5, 1.0, 2.0),
    ];
    let triangles = vec![[0, 1, 2], [3, 4, 5]];
    let out = run(&vertices, &triangles);
    assert_eq!(out.report.added_points, 0);
    assert!(out.triangles.contains(&[3, 4, 5]));
    assert!(
        out.triangles
            .iter()
            .zip(&out.parent)
            .any(|(t, &p)| p == 0 && t.contains(&3) && t.contains(&4)),
        "A's pieces have no edge 3-4"
    );
}

#[test]
fn a_point_on_a_non_manifold_edge_splits_every_triangle_on_it() {
    // Three fins on the edge 0-1, and a fourth triangle piercing that edge.
    let vertices = vec![
        v(0.0, 0.0, 0.0),
        v(4.0, 0.0, 0.0),
        v(2.0, 3.0, 0.0),
        v(2.0, -2.0, 2.0),
        v(2.0, -2.0, -2.0),
        v(1.0, 0.0, -1.0),
        v(1.0, 0.0, 1.0),
        v(1.0, 1.0, 0.0),
    ];
    let triangles = vec![[0, 1, 2], [1, 0, 3], [0, 1, 4], [5, 6, 7]];
    let out = run(&vertices, &triangles);
    let point = out
        .vertices
        .iter()
        .position(|p| *p == v(1.0, 0.0, 0.0))
        .expect("the edge point") as u32;
    for parent in 0..3 {
        assert!(
            out.triangles
                .iter()
                .zip(&out.parent)
                .any(|(t, &p)| p == parent && t.contains(&point)),
            "fin {parent} is not split at the edge point"
        );
    }
}

#[test]
fn bad_input_is_a_typed_error() {
    let ok = vec![v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)];
    let opts = ResolveOptions::default();
    assert!(matches!(
        resolve(&ok, &[[0, 1, 3]], &opts),
        Err(ResolveError::IndexOutOfRange {
            triangle: 0,
            corner: 2,
            vertex: 3,
            ..
        })
    ));
    let mut nan = ok.clone();
    nan[1].y = f32::NAN;
    assert!(matches!(
        resolve(&nan, &[[0, 1, 2]], &opts),
        Err(ResolveError::NonFiniteVertex { vertex: 1, .. })
    ));
    let mut huge = ok.clone();
    huge[2].z = 1e30;
    assert!(matches!(
        resolve(&huge, &[[0, 1, 2]], &opts),
        Err(ResolveError::CoordinateTooLarge { vertex: 2, .. })
    ));
    let line = vec![v(0.0, 0.0, 0.0), v(1.0, 1.0, 1.0), v(2.0, 2.0, 2.0)];
    assert!(matches!(
        resolve(&line, &[[0, 1, 2]], &opts),
        Err(ResolveError::DegenerateTriangle { triangle: 0 })
    ));
}

#[test]
fn zero_rounds_allowed_names_the_crossing_pair() {
    let vertices = vec![
        v(0.0, 0.0, 0.0),
        v(4.0, 0.0, 0.0),
        v(0.0, 4.0, 0.0),
        v(1.0, 1.0, -1.0),
        v(1.0, 1.0, 1.0),
        v(2.0, 1.5, 0.5),
    ];
    let triangles = vec![[0, 1, 2], [3, 4, 5]];
    let err = resolve(&vertices, &triangles, &ResolveOptions { max_rounds: 0 }).unwrap_err();
    assert_eq!(
        err,
        ResolveError::NotConverged {
            rounds: 0,
            pairs: vec![(0, 1)],
            total: 1
        }
    );
}

/// A cleaned random soup of `tris` triangles with corners in `-4..=4`.
fn soup(raw: &[[(i8, i8, i8); 3]]) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for t in raw {
        let b = vertices.len() as u32;
        for &(x, y, z) in t {
            vertices.push(v(x as f32, y as f32, z as f32));
        }
        triangles.push([b, b + 1, b + 2]);
    }
    let c = clean(&vertices, &triangles).unwrap();
    (c.vertices, c.triangles)
}

/// The soup on which the proptest below found a piece flat within
/// rounding whose normal stood at right angles to its parent's (see
/// `check`): resolved and checked every run.
#[test]
fn a_crossing_point_on_a_parents_edge_resolves() {
    let raw = [
        [(2, -1, -1), (-2, -1, 3), (3, 2, -2)],
        [(0, -2, 1), (-2, -2, -1), (3, 2, 2)],
        [(1, -1, 0), (-2, 0, 3), (0, 0, 0)],
        [(0, -1, 0), (0, 0, 0), (0, 0, 0)],
        [(0, 0, 0); 3],
        [(0, 0, 0); 3],
    ];
    let (vertices, triangles) = soup(&raw);
    let vertices: Vec<Vec3> = vertices.iter().map(|&p| p * 0.1).collect();
    let out = resolve(&vertices, &triangles, &ResolveOptions::default()).unwrap();
    check(&vertices, &triangles, &out);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn random_integer_soups_resolve(
        raw in prop::collection::vec(prop::array::uniform3((-4i8..=4, -4i8..=4, -4i8..=4)), 2..=8)
    ) {
        let (vertices, triangles) = soup(&raw);
        match resolve(&vertices, &triangles, &ResolveOptions::default()) {
            Ok(out) => check(&vertices, &triangles, &out),
            Err(e) => panic!("{e} on {vertices:?} {triangles:?}"),
        }
    }

    #[test]
    fn dense_decimal_soups_resolve(
        raw in prop::collection::vec(prop::array::uniform3((-3i8..=3, -3i8..=3, -3i8..=3)), 6..=14)
    ) {
        // Many triangles on a coarse grid of tenths: planes, lines and
        // points that coincide in decimal almost coincide in f32, the
        // hardest case for rounding.
        let (vertices, triangles) = soup(&raw);
        let vertices: Vec<Vec3> = vertices.iter().map(|p| *p * 0.1).collect();
        match resolve(&vertices, &triangles, &ResolveOptions::default()) {
            Ok(out) => check(&vertices, &triangles, &out),
            Err(e) => panic!("{e} on {vertices:?} {triangles:?}"),
        }
    }

    #[test]
    fn random_fractional_soups_resolve(
        raw in prop::collection::vec(prop::array::uniform3((-40i8..=40, -40i8..=40, -40i8..=40)), 2..=6)
    ) {
        // Coordinates in tenths: the intersection points are inexact in
        // binary, so every new point is rounded.
        let (vertices, triangles) = soup(&raw);
        let vertices: Vec<Vec3> = vertices.iter().map(|p| *p * 0.1).collect();
        match resolve(&vertices, &triangles, &ResolveOptions::default()) {
            Ok(out) => check(&vertices, &triangles, &out),
            Err(e) => panic!("{e} on {vertices:?} {triangles:?}"),
        }
    }
}

/// `name` in the scenes' directory, if it is there: `TET_SHARED_SCENES`
/// when set (a copy of the whole data set, the files the repository leaves
/// out included; see `scenes/README.md`), else the repository's `scenes/`.
fn shared(name: &str) -> Option<std::path::PathBuf> {
    let dir = std::env::var_os("TET_SHARED_SCENES")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes"));
    let p = dir.join(name);
    p.exists().then_some(p)
}

/// Resolves a real scene, checks the result and prints the numbers
/// (`cargo test --release -p tet-build --test resolve -- --ignored --nocapture`).
fn real_scene(name: &str, scene: tet_build::scene::Scene) {
    let (cleaned, _) = tet_build::clean::clean_scene(&scene).unwrap();
    let (vertices, triangles) = (cleaned.vertices, cleaned.triangles);
    let start = Instant::now();
    let check_only = find_self_intersections(&vertices, &triangles);
    let detect = start.elapsed();
    let start = Instant::now();
    let out = resolve(&vertices, &triangles, &ResolveOptions::default()).unwrap();
    let time = start.elapsed();
    let r = &out.report;
    println!(
        "{name}: {} triangles, {} pairs -> {} pieces ({} split, {} points added, {} merged), {} rounds, \
         resolve {:.1} ms (detection alone {:.1} ms, {} candidate pairs), {} threads",
        triangles.len(),
        r.pairs,
        out.triangles.len(),
        r.split_triangles,
        r.added_points,
        r.merged_pieces,
        r.rounds,
        time.as_secs_f64() * 1e3,
        detect.as_secs_f64() * 1e3,
        check_only.candidates,
        rayon::current_num_threads(),
    );
    assert_eq!(r.pairs, check_only.pairs.len());
    assert!(find_self_intersections(&out.vertices, &out.triangles).is_clean());
    assert_eq!(&out.vertices[..vertices.len()], &vertices[..]);
}

#[test]
#[ignore = "measurement: resolves the scene meshes in scenes/ (those present) and prints timings; run in release with --nocapture"]
fn real_meshes() {
    for name in ["neptune_aimatshape_30k.obj", "teapot.obj", "beast.obj"] {
        let Some(path) = shared(name) else {
            eprintln!("skipping {name}: not found");
            continue;
        };
        real_scene(name, tet_build::scene::Scene::load_obj(&path).unwrap());
    }
    // Mix needs the Neptune mesh, which the repository leaves out.
    if let (Some(path), Some(_)) = (shared("scenes.json"), shared("neptune_aimatshape_30k.obj")) {
        let mix = tet_build::scene::scenes_json::load_scene(&path, "Mix").unwrap();
        real_scene("Mix", mix);
    }
}

/// Many random soups per configuration (`(scale, grid half-width, most
/// triangles)`), every result checked; fails on any error or failed check
/// and prints how many rounds the soups took
/// (`cargo test --release -p tet-build --test resolve -- --ignored --nocapture stress`;
/// `RESOLVE_STRESS_CASES` sets the cases per configuration).
#[test]
#[ignore = "stress: many random soups per configuration (minutes); run in release"]
fn stress_random_soups() {
    let cases: usize = std::env::var("RESOLVE_STRESS_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(2000);
    let configs: [(f32, i32, i32); 6] = [
        (1.0, 4, 8),
        (1.0, 2, 24),
        (0.1, 4, 8),
        (0.1, 10, 12),
        (0.1, 3, 20),
        (0.1, 5, 40),
    ];
    let mut seed = 12345u64;
    let mut failures = Vec::new();
    for (scale, range, most) in configs {
        let mut rnd = |n: i32| {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 33) % (2 * n as u64 + 1)) as i32 - n
        };
        let mut rounds = std::collections::BTreeMap::new();
        for case in 0..cases {
            let count = 2 + (rnd(1000).unsigned_abs() as i32 % (most - 1));
            let raw: Vec<[(i8, i8, i8); 3]> = (0..count)
                .map(|_| {
                    std::array::from_fn(|_| (rnd(range) as i8, rnd(range) as i8, rnd(range) as i8))
                })
                .collect();
            let (vertices, triangles) = soup(&raw);
            let vertices: Vec<Vec3> = vertices.iter().map(|p| *p * scale).collect();
            let what =
                format!("scale {scale} grid {range} case {case}: {vertices:?} {triangles:?}");
            match resolve(&vertices, &triangles, &ResolveOptions::default()) {
                Ok(out) => {
                    *rounds.entry(out.report.rounds).or_insert(0) += 1;
                    if std::panic::catch_unwind(|| check(&vertices, &triangles, &out)).is_err() {
                        failures.push(what);
                    }
                }
                Err(e) => failures.push(format!("{e}: {what}")),
            }
        }
        println!("scale {scale}, grid ±{range}, up to {most} triangles: rounds {rounds:?}");
    }
    assert!(
        failures.is_empty(),
        "{} failures, e.g. {}",
        failures.len(),
        failures[0]
    );
}

/// End to end on the shared meshes: TetGen accepts the resolved scene that
/// it refuses unresolved, and every piece comes back as a constrained face
/// (`cargo test --release -p tet-build --test resolve -- --ignored --nocapture tetgen`).
#[cfg(feature = "tetgen")]
#[test]
#[ignore = "needs the scene meshes in scenes/ and TetGen on them (minutes); run in release"]
fn resolved_meshes_tetrahedralize() {
    use tet_build::pipeline::{BuildOptions, build};
    use tet_build::scene::Scene;
    for name in ["teapot.obj", "neptune_aimatshape_30k.obj"] {
        let Some(path) = shared(name) else {
            eprintln!("skipping {name}: not found");
            continue;
        };
        let (cleaned, _) = tet_build::clean::clean_scene(&Scene::load_obj(&path).unwrap()).unwrap();
        let raw = Scene {
            vertices: cleaned.vertices.clone(),
            triangles: cleaned.triangles.clone(),
            ..Scene::default()
        };
        assert!(
            build(&raw, &BuildOptions::default()).is_err(),
            "{name} builds unresolved"
        );
        let out = resolve(
            &cleaned.vertices,
            &cleaned.triangles,
            &ResolveOptions::default(),
        )
        .unwrap();
        let scene = Scene {
            vertices: out.vertices,
            triangles: out.triangles,
            ..Scene::default()
        };
        let start = Instant::now();
        let (mesh, _) = build(&scene, &BuildOptions::default()).unwrap();
        println!(
            "{name}: {} pieces -> {} tets, {} constrained faces, {:.1} s",
            scene.triangles.len(),
            mesh.tets.len(),
            mesh.constrained.len(),
            start.elapsed().as_secs_f64()
        );
        assert_eq!(mesh.constrained.len(), scene.triangles.len());
    }
}
