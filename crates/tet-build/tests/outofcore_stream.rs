//! The streaming merge of part files against an
//! independent reference, without TetGen: two Kuhn grids side by side are
//! the two halves of one Kuhn grid (Kuhn's subdivision is conforming across
//! cells), so merging their files across the seam x = 2 must give that
//! grid — with constrained planes inside the parts and on the seam itself.
//! Broken part files give typed errors and leave no mesh file.

#![cfg(feature = "tetgen")]

mod common;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::Vec3;
use tet_build::outofcore::split::SplitPlane;
use tet_build::outofcore::stream::{StreamError, merge_part_files};
use tet_core::format::{FormatError, load_with_scene, save, to_bytes};
use tet_core::scene::{Camera, SceneInfo};
use tet_core::synthetic::{GridSpec, constrain_faces, kuhn_grid};
use tet_core::{TetMesh, face_key};

use common::{bits, canonical};

/// An unjittered Kuhn grid of `cells` unit cells from `offset`, with the
/// faces on the planes x = 1, 2, 3 and z = 1 constrained (wound towards
/// +x, +z; ids in the order met).
fn unlabelled(cells: [u32; 3], offset: Vec3) -> TetMesh {
    let g = kuhn_grid(&GridSpec {
        cells,
        jitter: 0.0,
        offset,
        ..GridSpec::default()
    });
    let on = |v: [Vec3; 3]| {
        let flat = |a: usize, x: f32| v.iter().all(|p| p[a] == x);
        [1.0, 2.0, 3.0].iter().any(|&x| flat(0, x)) || flat(2, 1.0)
    };
    constrain_faces(g, on, Some(Vec3::new(1.0, 0.0, 1.0)))
}

/// [`unlabelled`] with the scene triangle ids of the whole grid (`ids`, by
/// sorted vertex positions), as the parts of one scene number them.
fn grid(cells: [u32; 3], offset: Vec3, ids: &HashMap<[[u32; 3]; 3], u32>) -> TetMesh {
    let mut m = unlabelled(cells, offset);
    let labels: Vec<u32> = m
        .constrained
        .iter()
        .map(|f| ids[&position_key(&m, f.vertices)])
        .collect();
    for (f, id) in m.constrained.iter_mut().zip(labels) {
        f.triangle = id;
    }
    m.triangle_count = ids.len() as u32;
    m
}

fn position_key(m: &TetMesh, v: [u32; 3]) -> [[u32; 3]; 3] {
    let mut k = v.map(|i| bits(m.points[i as usize]));
    k.sort_unstable();
    k
}

/// Scene triangle ids of the whole grid's constrained faces, by position.
fn global_ids() -> HashMap<[[u32; 3]; 3], u32> {
    let whole = unlabelled([4, 2, 2], Vec3::ZERO);
    let mut keys: Vec<[[u32; 3]; 3]> = whole
        .constrained
        .iter()
        .map(|f| position_key(&whole, f.vertices))
        .collect();
    keys.sort_unstable();
    keys.into_iter()
        .enumerate()
        .map(|(i, k)| (k, i as u32))
        .collect()
}

fn scene() -> SceneInfo {
    SceneInfo {
        camera: Some(Camera {
            position: Vec3::new(2.0, 1.0, -5.0),
            target: Vec3::new(2.0, 1.0, 1.0),
            up: Vec3::Y,
            vfov_deg: 50.0,
        }),
        lights: Vec::new(),
    }
}

/// The seam between the halves: x = 2 over the grid's section.
fn seam() -> Vec<(SplitPlane, Vec3, Vec3)> {
    vec![(
        SplitPlane {
            axis: 0,
            value: 2.0,
        },
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(2.0, 2.0, 2.0),
    )]
}

/// Saves the halves as part files.
fn parts(dir: &Path, halves: &[TetMesh]) -> Vec<PathBuf> {
    halves
        .iter()
        .enumerate()
        .map(|(k, m)| {
            let p = dir.join(format!("part-{k}.tmesh"));
            save(&p, m).unwrap();
            p
        })
        .collect()
}

#[test]
fn two_grid_halves_merge_into_the_whole_grid() {
    let ids = global_ids();
    let whole = grid([4, 2, 2], Vec3::ZERO, &ids);
    whole.validate().unwrap();
    let below = grid([2, 2, 2], Vec3::ZERO, &ids);
    let mut above = grid([2, 2, 2], Vec3::new(2.0, 0.0, 0.0), &ids);
    // Part order and point order within a part do not matter.
    tet_core::reorder::hilbert_reorder(&mut above).unwrap();
    let on_seam = |m: &TetMesh| {
        m.constrained
            .iter()
            .filter(|f| f.vertices.iter().all(|&v| m.points[v as usize].x == 2.0))
            .count()
    };
    assert_eq!(on_seam(&below), 8, "the seam carries scene faces");
    assert_eq!(on_seam(&above), 8);
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("merged.tmesh");
    for order in [[0, 1], [1, 0]] {
        let halves = [&below, &above];
        let files = parts(dir.path(), &order.map(|i| halves[i].clone()));
        let s = merge_part_files(&files, &seam(), &out, &scene()).unwrap();
        let (merged, stored) = load_with_scene(&out).unwrap();
        assert_eq!(stored, scene());
        assert_eq!(canonical(&merged), canonical(&whole), "order {order:?}");
        assert_eq!(
            (s.points, s.tets, s.constrained),
            (
                whole.points.len() as u64,
                whole.tets.len() as u64,
                whole.constrained.len() as u64
            )
        );
        assert_eq!(s.file_bytes, std::fs::metadata(&out).unwrap().len());
        // 3 × 3 lattice points on the seam, 8 seam faces of which all
        // carry scene triangles here.
        assert_eq!(s.seam_points, 9);
        assert_eq!((s.seam_faces, s.seam_constrained), (0, 8));
        assert!(s.max_resident_bytes > 0 && s.max_resident_bytes < s.all_parts_bytes + (1 << 20));
    }
    // Without scene faces on the seam, its faces become tet–tet links.
    let plain = |offset| {
        let g = kuhn_grid(&GridSpec {
            cells: [2, 2, 2],
            jitter: 0.0,
            offset,
            ..GridSpec::default()
        });
        constrain_faces(g, |v| v.iter().all(|p| p.z == 1.0), Some(Vec3::Z))
    };
    let files = parts(dir.path(), &[plain(Vec3::ZERO), plain(Vec3::X * 2.0)]);
    let s = merge_part_files(&files, &seam(), &out, &SceneInfo::default()).unwrap();
    assert_eq!((s.seam_faces, s.seam_constrained), (8, 0));
    let merged = tet_core::format::load(&out).unwrap();
    let reference = constrain_faces(
        kuhn_grid(&GridSpec {
            cells: [4, 2, 2],
            jitter: 0.0,
            ..GridSpec::default()
        }),
        |v| v.iter().all(|p| p.z == 1.0),
        Some(Vec3::Z),
    );
    // Ids differ (each part numbers its own): compare without them.
    let strip = |m: &TetMesh| {
        let mut m = m.clone();
        m.constrained.iter_mut().for_each(|f| f.triangle = 0);
        canonical(&m)
    };
    assert_eq!(strip(&merged), strip(&reference));
}

#[test]
fn broken_part_files_give_typed_errors_and_no_mesh_file() {
    let ids = global_ids();
    let below = grid([2, 2, 2], Vec3::ZERO, &ids);
    let above = grid([2, 2, 2], Vec3::new(2.0, 0.0, 0.0), &ids);
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("merged.tmesh");
    let files = parts(dir.path(), &[below.clone(), above.clone()]);
    let merge = |files: &[PathBuf]| merge_part_files(files, &seam(), &out, &SceneInfo::default());

    // A flipped payload byte in a part.
    let mut bytes = to_bytes(&above);
    bytes[200] ^= 4;
    std::fs::write(&files[1], &bytes).unwrap();
    match merge(&files) {
        Err(StreamError::Format(FormatError::ChecksumMismatch { path, part, .. })) => {
            assert_eq!((path, part), (files[1].clone(), "payload"));
        }
        other => panic!("{other:?}"),
    }
    // A tet vertex past the part's points (valid checksums).
    let mut bad = above.clone();
    bad.tets[5][2] = 999;
    save(&files[1], &bad).unwrap();
    match merge(&files) {
        Err(StreamError::OutOfBounds {
            part: 1,
            element: "tet vertex",
            index: 22,
            value: 999,
            ..
        }) => {}
        other => panic!("{other:?}"),
    }
    // Parts numbering different scene triangle sets.
    let mut bad = above.clone();
    bad.triangle_count += 1;
    save(&files[1], &bad).unwrap();
    assert!(matches!(
        merge(&files),
        Err(StreamError::TriangleCount { part: 1, .. })
    ));
    // A finer grid on the other side: its seam faces match none.
    let finer = kuhn_grid(&GridSpec {
        cells: [4, 4, 4],
        jitter: 0.0,
        scale: 0.5,
        offset: Vec3::new(2.0, 0.0, 0.0),
        ..GridSpec::default()
    });
    let finer = TetMesh::assemble(finer.points, finer.tets, &[], below.triangle_count).unwrap();
    save(&files[1], &finer).unwrap();
    match merge(&files) {
        Err(StreamError::SeamFace {
            detail, vertices, ..
        }) => {
            assert!(detail.contains("other side"), "{detail}");
            assert_eq!(vertices, face_key(vertices));
        }
        other => panic!("{other:?}"),
    }
    assert!(!out.exists(), "no mesh file after a failed merge");
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 2, "only the part files: {left:?}");
}
