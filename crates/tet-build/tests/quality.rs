//! Quality metrics against hand-computed values.

use glam::DVec3;
use tet_build::quality::{Stats, aspect_ratio, mesh_quality, radius_edge_ratio};
use tet_core::TetMesh;

fn regular(scale: f64) -> [DVec3; 4] {
    // Alternate corners of a cube: all six edges have length scale·sqrt(8).
    [
        DVec3::new(1.0, 1.0, 1.0),
        DVec3::new(1.0, -1.0, -1.0),
        DVec3::new(-1.0, 1.0, -1.0),
        DVec3::new(-1.0, -1.0, 1.0),
    ]
    .map(|p| p * scale)
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * b.abs().max(1.0)
}

#[test]
fn regular_tet_has_the_textbook_ratios() {
    for s in [1.0, 0.001, 250.0] {
        let p = regular(s);
        assert!(
            close(aspect_ratio(p), (1.5f64).sqrt()),
            "{}",
            aspect_ratio(p)
        );
        assert!(close(radius_edge_ratio(p), 6f64.sqrt() / 4.0));
    }
}

#[test]
fn corner_tet_by_hand() {
    // Unit corner tet: edges 1,1,1 and sqrt2 ×3; volume 1/6; largest face is
    // the equilateral one with area sqrt(3)/2, so the smallest height is
    // 3V/A = (1/2)/(sqrt3/2) = 1/sqrt3 and the aspect ratio sqrt2·sqrt3.
    // Circumcentre (1/2,1/2,1/2): radius sqrt3/2, shortest edge 1.
    let p = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
    assert!(close(aspect_ratio(p), 6f64.sqrt()));
    assert!(close(radius_edge_ratio(p), 3f64.sqrt() / 2.0));
}

#[test]
fn flat_tet_is_infinitely_bad() {
    let p = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)];
    assert_eq!(aspect_ratio(p), f64::INFINITY);
    assert_eq!(radius_edge_ratio(p), f64::INFINITY);
}

#[test]
fn mesh_statistics_combine_tets() {
    // Two tets sharing face (0,1,2): the unit corner tet above it and a
    // mirrored one below (same shape): all stats equal the corner tet's.
    let points = vec![
        glam::Vec3::ZERO,
        glam::Vec3::X,
        glam::Vec3::Y,
        glam::Vec3::Z,
        glam::Vec3::NEG_Z,
    ];
    let mesh = TetMesh::assemble(points, vec![[0, 1, 2, 3], [1, 0, 2, 4]], &[], 0).unwrap();
    mesh.validate().unwrap();
    let q = mesh_quality(&mesh).unwrap();
    assert_eq!(q.tets, 2);
    assert!(close(q.aspect_ratio.min, 6f64.sqrt()) && close(q.aspect_ratio.max, 6f64.sqrt()));
    assert!(close(q.radius_edge.mean, 3f64.sqrt() / 2.0));
    let s = Stats::of([1.0, 2.0, 6.0]).unwrap();
    assert_eq!((s.min, s.max, s.mean), (1.0, 6.0, 3.0));
    assert!(Stats::of([]).is_none());
    assert!(mesh_quality(&TetMesh::default()).is_none());
}
