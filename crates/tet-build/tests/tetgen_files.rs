//! TetGen files and VTK export: round trips through a Kuhn-grid mesh with
//! constrained faces, and errors that name file and line.

use tet_build::tetgen_files::{FilesError, TetgenFiles, from_tet_mesh, read, to_tet_mesh, write};
use tet_build::vtk::to_vtu_string;
use tet_core::synthetic::{GridSpec, kuhn_grid};

fn grid_mesh() -> tet_core::TetMesh {
    let spec = GridSpec {
        constrained_fraction: 0.3,
        ..GridSpec::default()
    };
    let m = kuhn_grid(&spec);
    m.validate().unwrap();
    m
}

#[test]
fn node_ele_face_neigh_round_trip() {
    let mesh = grid_mesh();
    assert!(
        !mesh.constrained.is_empty(),
        "the test needs constrained faces"
    );
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path().join("grid");
    let files = from_tet_mesh(&mesh);
    write(&base, &files).unwrap();
    for ext in ["node", "ele", "face", "neigh"] {
        assert!(dir.path().join(format!("grid.{ext}")).exists(), "{ext}");
    }
    let back = read(&base).unwrap();
    assert_eq!(back, files);
    let again = to_tet_mesh(&back, &base, Some(mesh.triangle_count)).unwrap();
    assert_eq!(again.points, mesh.points);
    assert_eq!(again.tets, mesh.tets);
    assert_eq!(again.neighbors, mesh.neighbors);
    // The constrained-face table may be ordered differently: compare as sets.
    let mut a = again.constrained.clone();
    let mut b = mesh.constrained.clone();
    a.sort_by_key(|c| c.triangle);
    b.sort_by_key(|c| c.triangle);
    assert_eq!(a, b);
    // Neighbours written: across constrained faces too, the real tet.
    let n = files.neighbors.as_ref().unwrap();
    for (t, row) in n.iter().enumerate() {
        for (k, &got) in row.iter().enumerate() {
            let expect = mesh.across(t as u32, k).map_or(-1, |s| s.tet as i32);
            assert_eq!(got, expect);
        }
    }
}

#[test]
fn one_based_files_and_reversed_tets_are_accepted() {
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path().join("two");
    std::fs::write(
        dir.path().join("two.node"),
        "# comment\n5 3 0 1\n1 0 0 0 0\n2 1 0 0 0\n3 0 1 0 0\n4 0.2 0.2 1 0\n5 0.2 0.2 -1 0\n",
    )
    .unwrap();
    // Tet 1 negatively oriented in our convention (v0 and v1 swapped).
    std::fs::write(dir.path().join("two.ele"), "2 4 0\n1 2 1 3 4\n2 2 1 3 5\n").unwrap();
    std::fs::write(
        dir.path().join("two.face"),
        "1 1\n1 1 2 3 8 # marker 8 = triangle 7\n",
    )
    .unwrap();
    let f = read(&base).unwrap();
    assert_eq!(f.tets, vec![[1, 0, 2, 3], [1, 0, 2, 4]]);
    let m = to_tet_mesh(&f, &base, None).unwrap();
    assert_eq!(m.triangle_count, 8);
    assert_eq!(m.constrained.len(), 1);
    assert_eq!(m.constrained[0].triangle, 7);
    assert_eq!(m.constrained[0].vertices, [0, 1, 2]);
    // Triangle (0,1,2) has normal +z: the tet with apex z = 1 is in front.
    let front = m.constrained[0].front.tet as usize;
    assert!(m.tets[front].contains(&3));
}

#[test]
fn errors_name_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path().join("bad");
    std::fs::write(
        dir.path().join("bad.node"),
        "3 3 0 0\n0 0 0 0\n1 1 0 x\n2 0 1 0\n",
    )
    .unwrap();
    std::fs::write(dir.path().join("bad.ele"), "0 4 0\n").unwrap();
    match read(&base) {
        Err(FilesError::Parse {
            path,
            line,
            message,
        }) => {
            assert!(path.ends_with("bad.node"));
            assert_eq!(line, 3);
            assert!(message.contains("\"x\""), "{message}");
        }
        other => panic!("{other:?}"),
    }
    std::fs::write(
        dir.path().join("bad.node"),
        "3 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n",
    )
    .unwrap();
    std::fs::write(dir.path().join("bad.ele"), "1 4 0\n\n# c\n0 0 1 2 3\n").unwrap();
    match read(&base) {
        Err(FilesError::Parse {
            path,
            line,
            message,
        }) => {
            assert!(path.ends_with("bad.ele"));
            assert_eq!(line, 4);
            assert!(message.contains("out of range"), "{message}");
        }
        other => panic!("{other:?}"),
    }
    // A huge header count with no records: a parse error, not an allocation.
    std::fs::write(dir.path().join("bad.ele"), "4000000000000 4 0\n0 0 1 2 0\n").unwrap();
    match read(&base) {
        Err(FilesError::Parse {
            line: 0, message, ..
        }) => {
            assert!(
                message.contains("expected 4000000000000 records, found 1"),
                "{message}"
            )
        }
        other => panic!("{other:?}"),
    }
    std::fs::remove_file(dir.path().join("bad.ele")).unwrap();
    assert!(matches!(read(&base), Err(FilesError::Io { .. })));
    // A flat tet is refused when converting.
    let flat = TetgenFiles {
        points: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]],
        tets: vec![[0, 1, 2, 3]],
        ..TetgenFiles::default()
    };
    assert!(matches!(
        to_tet_mesh(&flat, &base, None),
        Err(FilesError::RoundingFlattens { tet: 0, .. })
    ));
    // A tet that is positive in f64 but flat once rounded to f32.
    let thin = TetgenFiles {
        points: vec![
            [0.0; 3],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.3, 0.3, 1e-12],
        ],
        tets: vec![[0, 1, 2, 3]],
        ..TetgenFiles::default()
    };
    let r = to_tet_mesh(&thin, &base, None);
    // 1e-12 survives f32 (it is a normal f32), so this one must succeed…
    assert!(r.is_ok(), "{r:?}");
    let thinner = TetgenFiles {
        points: vec![
            [0.0; 3],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.3, 0.3, 1e-60],
        ],
        tets: vec![[0, 1, 2, 3]],
        ..TetgenFiles::default()
    };
    // …while 1e-60 rounds to 0 in f32 and flattens the tet.
    assert!(matches!(
        to_tet_mesh(&thinner, &base, None),
        Err(FilesError::RoundingFlattens { tet: 0, .. })
    ));
}

#[test]
fn vtu_lists_tets_then_constrained_faces() {
    let mesh = grid_mesh();
    let s = to_vtu_string(&mesh);
    let nt = mesh.tets.len();
    let nc = mesh.constrained.len();
    assert!(s.contains(&format!(
        "NumberOfPoints=\"{}\" NumberOfCells=\"{}\"",
        mesh.points.len(),
        nt + nc
    )));
    // Parse the types array back and count.
    let types = s
        .split("Name=\"types\" format=\"ascii\">\n")
        .nth(1)
        .unwrap();
    let types: Vec<u8> = types
        .split("</DataArray>")
        .next()
        .unwrap()
        .split_whitespace()
        .map(|x| x.parse().unwrap())
        .collect();
    assert_eq!(types.len(), nt + nc);
    assert!(types[..nt].iter().all(|&t| t == 10) && types[nt..].iter().all(|&t| t == 5));
    let offsets = s
        .split("Name=\"offsets\" format=\"ascii\">\n")
        .nth(1)
        .unwrap();
    let last: usize = offsets
        .split("</DataArray>")
        .next()
        .unwrap()
        .split_whitespace()
        .last()
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(last, 4 * nt + 3 * nc);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.vtu");
    tet_build::vtk::write_vtu(&path, &mesh).unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), s);
    // No temporary file is left behind.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

/// `.node` point attributes are the scalar field: read from a hand-written
/// file, kept through `to_tet_mesh`, `from_tet_mesh`, `write` and `read`.
#[test]
fn node_attributes_are_the_scalar_field() {
    use tet_build::tetgen_files::{ATTRIBUTE_FIELD, from_tet_mesh, read, to_tet_mesh, write};
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path().join("a");
    std::fs::write(
        dir.path().join("a.node"),
        "4 3 2 1\n0 0 0 0 1.5 -0.0 7\n1 1 0 0 2.5 1e-30 7\n2 0 1 0 3.5 -2 0\n3 0 0 1 4.5 8 0\n",
    )
    .unwrap();
    std::fs::write(dir.path().join("a.ele"), "1 4 0\n0 0 1 2 3\n").unwrap();
    let files = read(&base).unwrap();
    assert_eq!(
        files.point_attributes,
        [vec![1.5, 2.5, 3.5, 4.5], vec![-0.0, 1e-30, -2.0, 8.0]]
    );
    let mesh = to_tet_mesh(&files, &base, None).unwrap();
    let field = mesh.attributes.scalars.as_ref().unwrap();
    assert_eq!(field.name, ATTRIBUTE_FIELD);
    assert_eq!(
        field.steps,
        [vec![1.5f32, 2.5, 3.5, 4.5], vec![-0.0, 1e-30, -2.0, 8.0]]
    );
    assert!(field.steps[1][0].is_sign_negative());
    let out = dir.path().join("b");
    write(&out, &from_tet_mesh(&mesh)).unwrap();
    let again = to_tet_mesh(&read(&out).unwrap(), &out, None).unwrap();
    assert_eq!(again, mesh);
    // A missing attribute value, a non-finite one, an f32 overflow, a
    // column of the wrong length are typed errors.
    std::fs::write(dir.path().join("a.node"), "1 3 2 0\n0 0 0 0 1\n").unwrap();
    assert!(matches!(
        read(&base),
        Err(FilesError::Parse { line: 2, .. })
    ));
    std::fs::write(dir.path().join("a.node"), "1 3 1 0\n0 0 0 0 nan\n").unwrap();
    assert!(matches!(
        read(&base),
        Err(FilesError::Parse { line: 2, .. })
    ));
    let mut big = files.clone();
    big.point_attributes[0][2] = 1e39;
    assert!(matches!(
        to_tet_mesh(&big, &base, None),
        Err(FilesError::Mesh(tet_core::MeshError::ScalarNotFinite {
            step: 0,
            point: 2,
            ..
        }))
    ));
    big.point_attributes[1].pop();
    assert!(matches!(
        write(&out, &big),
        Err(FilesError::Mesh(tet_core::MeshError::ScalarLength {
            step: 1,
            ..
        }))
    ));
}
