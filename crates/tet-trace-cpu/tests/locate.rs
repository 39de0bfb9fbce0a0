//! Point location against an exact, independent containment test.

use glam::{DVec3, Vec3};
use proptest::prelude::*;
use tet_core::predicates::orient3d;
use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};
use tet_core::{FACE_VERTICES, TetMesh};
use tet_trace_cpu::locate::{LocateError, locate, scan};

/// Closed-tet containment straight from the exact predicate.
fn contains(mesh: &TetMesh, t: u32, p: Vec3) -> bool {
    let v: Vec<DVec3> = mesh.tet_points(t).iter().map(|x| x.as_dvec3()).collect();
    FACE_VERTICES
        .iter()
        .all(|s| orient3d(v[s[0]], v[s[1]], v[s[2]], p.as_dvec3()) <= 0.0)
}

fn mesh(seed: u64, shell: bool) -> TetMesh {
    kuhn_grid(&GridSpec {
        cells: [4, 4, 4],
        jitter: 0.12,
        constrained_fraction: 0.2,
        shell: shell.then_some(([1; 3], [3; 3])),
        seed,
        ..Default::default()
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, .. ProptestConfig::default() })]

    #[test]
    fn finds_vertices_edges_faces_and_interiors(seed in any::<u64>(), shell in any::<bool>()) {
        let m = mesh(seed, shell);
        let mut rng = SplitMix64(seed);
        for i in 0..60 {
            let t = (rng.next_u64() % m.tets.len() as u64) as u32;
            let p = m.tet_points(t);
            let r = rng.next_u64();
            let q = match i % 4 {
                0 => p[(r % 4) as usize],
                1 => (p[(r % 4) as usize] + p[((r % 4 + 1 + r / 4 % 3) % 4) as usize]) * 0.5,
                2 => {
                    let s = FACE_VERTICES[(r % 4) as usize];
                    (p[s[0]] + p[s[1]] + p[s[2]]) / 3.0
                }
                _ => (p[0] + p[1] + p[2] + p[3]) * 0.25,
            };
            let source = (rng.next_u64() % m.tets.len() as u64) as u32;
            let found = locate(&m, q, source).unwrap();
            prop_assert!(contains(&m, found, q), "tet {found} does not contain {q:?}");
        }
    }
}

#[test]
fn walks_into_a_region_cut_off_by_a_shell() {
    let m = mesh(9, true);
    // Source outside the shell (near the corner), target at its centre.
    let source = scan(&m, Vec3::splat(0.3)).unwrap();
    let centre = Vec3::splat(2.0);
    let found = locate(&m, centre, source).unwrap();
    assert!(contains(&m, found, centre));
}

#[test]
fn outside_and_bad_input_are_typed_errors() {
    let m = mesh(4, false);
    assert_eq!(
        locate(&m, Vec3::new(5.0, 1.0, 1.0), 0),
        Err(LocateError::OutsideMesh {
            point: Vec3::new(5.0, 1.0, 1.0)
        })
    );
    assert!(matches!(
        locate(&m, Vec3::new(f32::NAN, 0.0, 0.0), 0),
        Err(LocateError::NonFinite { .. })
    ));
    assert!(matches!(
        locate(&m, Vec3::ONE, m.tets.len() as u32),
        Err(LocateError::BadSource { .. })
    ));
    assert_eq!(
        locate(&TetMesh::default(), Vec3::ONE, 0),
        Err(LocateError::EmptyMesh)
    );
}
