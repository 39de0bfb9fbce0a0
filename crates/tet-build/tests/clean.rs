//! Cleaning against hand-built cases and an integer-arithmetic brute force.

use glam::Vec3;
use proptest::prelude::*;
use tet_build::clean::{CleanError, DuplicatePair, REMOVED, clean, clean_scene};
use tet_build::procedural;

#[test]
fn hand_built_soup() {
    let v = vec![
        Vec3::new(0.0, 0.0, 0.0),                   // 0
        Vec3::new(1.0, 0.0, 0.0),                   // 1
        Vec3::new(0.0, 1.0, 0.0),                   // 2
        Vec3::new(-0.0, 0.0, 0.0),                  // 3 = 0 (negative zero)
        Vec3::new(1.0, 1.0, 1.0),                   // 4
        Vec3::new(2.0, 2.0, 2.0),                   // 5
        Vec3::new(2.0, 2.0, 2.0 + 1.0 / 1048576.0), // 6 nearly collinear with 0,4
        Vec3::new(9.0, 9.0, 9.0),                   // 7 unused
        Vec3::new(1.0, 0.0, 0.0),                   // 8 = 1
    ];
    let t = vec![
        [0, 1, 2], // 0 kept
        [3, 8, 2], // 1 = triangle 0 after merging, same winding
        [2, 1, 0], // 2 = triangle 0, reversed
        [0, 4, 5], // 3 exactly collinear
        [0, 4, 6], // 4 kept (not collinear)
        [0, 3, 4], // 5 repeats vertex 0 after merging
        [1, 1, 2], // 6 repeats vertex 1
    ];
    let c = clean(&v, &t).unwrap();
    let r = &c.report;
    assert_eq!(r.merged_vertices, vec![(3, 0), (8, 1)]);
    assert_eq!(r.repeated_vertex_triangles, vec![5, 6]);
    assert_eq!(r.zero_area_triangles, vec![3]);
    assert_eq!(
        r.duplicate_triangles,
        vec![
            DuplicatePair {
                kept: 0,
                dropped: 1,
                same_winding: true
            },
            DuplicatePair {
                kept: 0,
                dropped: 2,
                same_winding: false
            },
        ]
    );
    // 5 was only used by the collinear triangle; 7 by nothing.
    assert_eq!(r.unused_vertices, vec![5, 7]);
    assert_eq!(r.dropped_triangles(), 5);
    assert_eq!(c.triangle_source, vec![0, 4]);
    assert_eq!(c.vertex_source, vec![0, 1, 2, 4, 6]);
    assert_eq!(c.vertices, vec![v[0], v[1], v[2], v[4], v[6]]);
    assert_eq!(c.triangles, vec![[0, 1, 2], [0, 3, 4]]);
    assert_eq!(c.vertex_map, vec![0, 1, 2, 0, 3, REMOVED, 4, REMOVED, 1]);
    // Cleaning again does nothing.
    let again = clean(&c.vertices, &c.triangles).unwrap();
    assert!(again.report.is_noop());
}

#[test]
fn typed_errors() {
    let v = vec![Vec3::ZERO, Vec3::X, Vec3::new(0.0, f32::NAN, 0.0)];
    match clean(&v, &[[0, 1, 2]]) {
        Err(CleanError::NonFiniteVertex { vertex: 2, .. }) => {}
        other => panic!("{other:?}"),
    }
    let v = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
    match clean(&v, &[[0, 1, 2], [0, 1, 3]]) {
        Err(CleanError::IndexOutOfRange {
            triangle: 1,
            corner: 2,
            vertex: 3,
            count: 3,
        }) => {}
        other => panic!("{other:?}"),
    }
    let e = clean(&[Vec3::new(f32::INFINITY, 0.0, 0.0)], &[]).unwrap_err();
    assert!(e.to_string().contains("vertex 0"));
}

#[test]
fn scene_cleaning_merges_box_corners_and_keeps_ranges() {
    let s = procedural::by_name("torus-knots-box").unwrap();
    let (c, cm) = clean_scene(&s).unwrap();
    // The box's 24 (corner, normal) vertices collapse to 8 corners; knots are clean.
    assert_eq!(cm.report.merged_vertices.len(), 16);
    // Each box corner carries three face normals: all 16 merges conflict.
    assert_eq!(cm.report.attribute_conflicts, cm.report.merged_vertices);
    assert!(
        clean_scene(&procedural::by_name("torus-knots").unwrap())
            .unwrap()
            .1
            .report
            .is_noop()
    );
    assert_eq!(c.vertices.len(), 8 + 27 * 1440);
    assert_eq!(c.triangles.len(), 77_772);
    assert_eq!(c.objects[0].triangle_count, 12);
    assert_eq!(c.objects[0].vertex_count, 8);
    assert_eq!(c.objects[1].first_triangle, 12);
    assert_eq!(c.normals.as_ref().unwrap().len(), c.vertices.len());
    // No vertex moved.
    for (o, &i) in cm.vertex_source.iter().enumerate() {
        assert_eq!(c.vertices[o], s.vertices[i as usize]);
    }
}

/// Reference results: (repeated-vertex, zero-area, duplicate pairs, kept).
type Reference = (Vec<u32>, Vec<u32>, Vec<(u32, u32)>, Vec<u32>);

/// Independent reference in integer arithmetic on small integer coordinates.
fn reference(v: &[[i32; 3]], t: &[[u32; 3]]) -> Reference {
    let canon = |i: u32| (0..v.len()).find(|&j| v[j] == v[i as usize]).unwrap() as u32;
    let (mut repeated, mut zero, mut dups, mut kept) = (vec![], vec![], vec![], vec![]);
    let mut seen: Vec<([u32; 3], u32)> = vec![];
    for (k, tri) in t.iter().enumerate() {
        let m = tri.map(canon);
        if m[0] == m[1] || m[1] == m[2] || m[0] == m[2] {
            repeated.push(k as u32);
            continue;
        }
        let p = m.map(|i| v[i as usize].map(i64::from));
        let e1 = [p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]];
        let e2 = [p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]];
        let cr = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        if cr == [0, 0, 0] {
            zero.push(k as u32);
            continue;
        }
        let mut s = m;
        s.sort();
        if let Some(&(_, first)) = seen.iter().find(|(x, _)| *x == s) {
            dups.push((first, k as u32));
        } else {
            seen.push((s, k as u32));
            kept.push(k as u32);
        }
    }
    (repeated, zero, dups, kept)
}

proptest! {
    #[test]
    fn matches_integer_reference(
        coords in prop::collection::vec(prop::array::uniform3(-2i32..3), 3..14),
        raw in prop::collection::vec(prop::array::uniform3(0u32..1000), 0..30),
    ) {
        let n = coords.len() as u32;
        let tris: Vec<[u32; 3]> = raw.iter().map(|t| t.map(|i| i % n)).collect();
        let verts: Vec<Vec3> = coords.iter().map(|c| Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32)).collect();
        let c = clean(&verts, &tris).unwrap();
        let (repeated, zero, dups, kept) = reference(&coords, &tris);
        prop_assert_eq!(&c.report.repeated_vertex_triangles, &repeated);
        prop_assert_eq!(&c.report.zero_area_triangles, &zero);
        let got: Vec<(u32, u32)> = c.report.duplicate_triangles.iter().map(|d| (d.kept, d.dropped)).collect();
        prop_assert_eq!(got, dups);
        prop_assert_eq!(&c.triangle_source, &kept);
        // Output triangles reproduce the input positions exactly, winding kept.
        for (o, &src) in c.triangle_source.iter().enumerate() {
            let a = c.triangles[o].map(|i| c.vertices[i as usize]);
            let b = tris[src as usize].map(|i| verts[i as usize]);
            prop_assert_eq!(a, b);
        }
        // Output vertices are distinct and all used.
        let mut used = vec![false; c.vertices.len()];
        for t in &c.triangles { for &i in t { used[i as usize] = true; } }
        prop_assert!(used.iter().all(|&u| u));
        for i in 0..c.vertices.len() {
            for j in i + 1..c.vertices.len() {
                prop_assert_ne!(c.vertices[i], c.vertices[j]);
            }
        }
    }
}
