//! VTK files: our meshes round-trip exactly through every format and
//! encoding; small hand-written files parse to hand-built meshes; malformed
//! files give typed errors naming the line or cell; truncation never panics.

use std::path::Path;

use glam::Vec3;
use tet_build::vtk::{
    VtkEncoding, VtkError, from_legacy_bytes, from_vtk_bytes, from_vtu_bytes, read_vtk,
    to_legacy_bytes, to_vtu_bytes, write_vtk,
};
use tet_core::synthetic::{GridSpec, kuhn_grid};
use tet_core::{ScalarField, TetMesh};

const ENCODINGS: [VtkEncoding; 3] = [
    VtkEncoding::Ascii,
    VtkEncoding::Binary,
    VtkEncoding::Appended,
];

fn mesh_with_field(steps: usize) -> TetMesh {
    let mut m = kuhn_grid(&GridSpec {
        cells: [2, 3, 2],
        jitter: 0.12,
        constrained_fraction: 0.3,
        seed: 11,
        ..GridSpec::default()
    });
    m.triangle_count += 2; // ids that name no face must survive too
    let n = m.points.len();
    if steps > 0 {
        m.attributes.scalars = Some(ScalarField {
            name: "density".into(),
            steps: (0..steps)
                .map(|s| {
                    (0..n)
                        .map(|i| (i as f32 * 0.37 - s as f32).sin() * 1e3 + 1e-30)
                        .collect()
                })
                .collect(),
        });
    }
    m.validate().unwrap();
    m
}

fn path() -> &'static Path {
    Path::new("test.vtk")
}

#[test]
fn our_meshes_round_trip_exactly() {
    for steps in [0, 1, 3] {
        let m = mesh_with_field(steps);
        assert!(!m.constrained.is_empty());
        for enc in ENCODINGS {
            let legacy = from_legacy_bytes(&to_legacy_bytes(&m, enc), path())
                .unwrap_or_else(|e| panic!("legacy {enc:?}: {e}"));
            assert_eq!(legacy, m, "legacy {enc:?}, {steps} steps");
            let vtu = from_vtu_bytes(&to_vtu_bytes(&m, enc), path())
                .unwrap_or_else(|e| panic!("vtu {enc:?}: {e}"));
            assert_eq!(vtu, m, "vtu {enc:?}, {steps} steps");
        }
    }
    // Through files, the format picked by extension and by content.
    let dir = tempfile::tempdir().unwrap();
    let m = mesh_with_field(2);
    for (name, enc) in [
        ("a.vtk", VtkEncoding::Binary),
        ("b.vtu", VtkEncoding::Appended),
    ] {
        let p = dir.path().join(name);
        write_vtk(&p, &m, enc).unwrap();
        assert_eq!(read_vtk(&p).unwrap(), m);
    }
}

/// Two tets sharing face (0, 1, 2); the second is listed inverted.
const LEGACY: &str = "# vtk DataFile Version 3.0
hand written
ASCII

DATASET UNSTRUCTURED_GRID
POINTS 5 double
0 0 0  1 0 0  0 1 0
0.2 0.2 1
0.2 0.2 -1
CELLS 2 10
4 0 1 2 3
4 0 1 2 4
CELL_TYPES 2
10
10
POINT_DATA 5
SCALARS temperature float
LOOKUP_TABLE default
0 1 2 3 -4.5
SCALARS pressure float 1
LOOKUP_TABLE default
5 6 7 8 9
VECTORS velocity float
1 0 0 1 0 0 1 0 0 1 0 0 1 0 0
";

fn expected_bipyramid(steps: Vec<Vec<f32>>, name: &str) -> TetMesh {
    let points = vec![
        Vec3::ZERO,
        Vec3::X,
        Vec3::Y,
        Vec3::new(0.2, 0.2, 1.0),
        Vec3::new(0.2, 0.2, -1.0),
    ];
    // The second tet, oriented by hand: swap its first two vertices.
    let mut m = TetMesh::assemble(points, vec![[0, 1, 2, 3], [1, 0, 2, 4]], &[], 0).unwrap();
    m.attributes.scalars = Some(ScalarField {
        name: name.into(),
        steps,
    });
    m.validate().unwrap();
    m
}

#[test]
fn hand_written_legacy_file() {
    let m = from_legacy_bytes(LEGACY.as_bytes(), path()).unwrap();
    let expected = expected_bipyramid(
        vec![
            vec![0.0, 1.0, 2.0, 3.0, -4.5],
            vec![5.0, 6.0, 7.0, 8.0, 9.0],
        ],
        "temperature",
    );
    assert_eq!(m, expected);
    // The version 5.1 cell layout.
    let v51 = LEGACY
        .replace("# vtk DataFile Version 3.0", "# vtk DataFile Version 5.1")
        .replace(
            "CELLS 2 10\n4 0 1 2 3\n4 0 1 2 4\n",
            "CELLS 3 8\nOFFSETS vtktypeint64\n0 4 8\nCONNECTIVITY vtktypeint64\n0 1 2 3\n0 1 2 4\n",
        );
    assert_eq!(from_legacy_bytes(v51.as_bytes(), path()).unwrap(), expected);
    assert_eq!(from_vtk_bytes(v51.as_bytes(), path()).unwrap(), expected);
}

const VTU: &str = r#"<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">
  <UnstructuredGrid>
    <Piece NumberOfPoints="5" NumberOfCells="2">
      <PointData Scalars="t">
        <DataArray type="Float64" Name="t_t0000" format="ascii">0 1 2 3 -4.5</DataArray>
        <DataArray type="Float32" Name="t_t0001" format="ascii">5 6 7 8 9</DataArray>
      </PointData>
      <Points>
        <DataArray type="Float32" NumberOfComponents="3" format="ascii">
          0 0 0 1 0 0 0 1 0 0.2 0.2 1 0.2 0.2 -1
        </DataArray>
      </Points>
      <Cells>
        <DataArray type="Int32" Name="connectivity" format="ascii">0 1 2 3 0 1 2 4</DataArray>
        <DataArray type="Int32" Name="offsets" format="ascii">4 8</DataArray>
        <DataArray type="UInt8" Name="types" format="ascii">10 10</DataArray>
      </Cells>
    </Piece>
  </UnstructuredGrid>
</VTKFile>
"#;

#[test]
fn hand_written_vtu_file() {
    let m = from_vtu_bytes(VTU.as_bytes(), path()).unwrap();
    let expected = expected_bipyramid(
        vec![
            vec![0.0, 1.0, 2.0, 3.0, -4.5],
            vec![5.0, 6.0, 7.0, 8.0, 9.0],
        ],
        "t",
    );
    assert_eq!(m, expected);
    // base64 inline data: header UInt32 byte count then the values, as one
    // stream (VTK) or two padded blocks (meshio); both decode.
    let offsets: Vec<u8> = [8u32, 4, 8].iter().flat_map(|v| v.to_le_bytes()).collect();
    let b64 = base64(&offsets);
    let split = format!("{}{}", base64(&8u32.to_le_bytes()), base64(&offsets[4..]));
    for text in [b64, split] {
        let v = VTU.replace(
            r#"<DataArray type="Int32" Name="offsets" format="ascii">4 8</DataArray>"#,
            &format!(
                r#"<DataArray type="Int32" Name="offsets" format="binary">{text}</DataArray>"#
            ),
        );
        assert_eq!(from_vtu_bytes(v.as_bytes(), path()).unwrap(), expected);
    }
}

/// An independent base64 encoder for the test.
fn base64(bytes: &[u8]) -> String {
    let a = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in bytes.chunks(3) {
        let n = c
            .iter()
            .enumerate()
            .fold(0u32, |n, (i, &b)| n | u32::from(b) << (16 - 8 * i));
        for k in 0..4 {
            s.push(if k <= c.len() {
                a[(n >> (18 - 6 * k) & 63) as usize] as char
            } else {
                '='
            });
        }
    }
    s
}

fn legacy_err(text: &str) -> VtkError {
    from_legacy_bytes(text.as_bytes(), path()).unwrap_err()
}

#[test]
fn malformed_legacy_files_name_the_line_or_cell() {
    let check_line = |text: String, want: usize, needle: &str| match legacy_err(&text) {
        VtkError::Parse {
            line,
            message,
            path,
        } => {
            assert_eq!(path, Path::new("test.vtk"));
            assert_eq!(line, want, "{message}");
            assert!(message.contains(needle), "{message}");
        }
        other => panic!("expected a parse error, got {other}"),
    };
    check_line(
        LEGACY.replace("CELL_TYPES 2", "CELL_TYPES 3"),
        13,
        "CELL_TYPES has 3",
    );
    check_line(
        LEGACY.replace("0 1 2 3 -4.5", "0 1 nan 3 -4.5"),
        19,
        "not finite",
    );
    check_line(
        LEGACY.replace("0 1 2 3 -4.5", "0 1 x 3 -4.5"),
        19,
        "cannot parse",
    );
    check_line(
        LEGACY.replace("POINTS 5 double", "POINTS 5 quad"),
        6,
        "unknown data type",
    );
    check_line(
        LEGACY.replace("DATASET UNSTRUCTURED_GRID", "DATASET POLYDATA"),
        5,
        "POLYDATA",
    );
    check_line(LEGACY.replace("VECTORS", "VECTORZ"), 23, "unknown keyword");
    // One value too many: the reader runs into the next keyword.
    check_line(
        LEGACY.replace("CELLS 2 10", "CELLS 2 11"),
        13,
        "CELLS: cannot parse",
    );
    check_line(LEGACY.trim_end().to_string(), 24, "truncated");
    check_line(
        LEGACY.split("CELL_TYPES").next().unwrap().to_string(),
        13,
        "no CELL_TYPES",
    );
    let check_cell = |text: String, want: usize, needle: &str| match legacy_err(&text) {
        VtkError::Cell { cell, message, .. } => {
            assert_eq!(cell, want, "{message}");
            assert!(message.contains(needle), "{message}");
        }
        other => panic!("expected a cell error, got {other}"),
    };
    check_cell(LEGACY.replace("4 0 1 2 4", "4 0 1 2 5"), 1, "out of range");
    check_cell(LEGACY.replace("10\n10\n", "10\n12\n"), 1, "type 12");
    // A triangle without our constrained-face marker.
    check_cell(
        LEGACY
            .replace(
                "CELLS 2 10\n4 0 1 2 3\n4 0 1 2 4",
                "CELLS 2 9\n4 0 1 2 3\n3 0 1 2",
            )
            .replace("10\n10\n", "10\n5\n"),
        1,
        "marker",
    );
    // A flat tet.
    check_cell(LEGACY.replace("0.2 0.2 -1", "0.5 0.5 0"), 1, "flat");
    // A face shared by three tets is a mesh error.
    let three = LEGACY
        .replace("POINTS 5 double", "POINTS 6 double")
        .replace("0.2 0.2 -1\n", "0.2 0.2 -1\n0.3 0.1 2\n")
        .replace(
            "CELLS 2 10\n4 0 1 2 3\n4 0 1 2 4",
            "CELLS 3 15\n4 0 1 2 3\n4 0 1 2 4\n4 0 1 2 5",
        )
        .replace("CELL_TYPES 2\n10\n10", "CELL_TYPES 3\n10\n10\n10")
        .split("POINT_DATA")
        .next()
        .unwrap()
        .to_string();
    assert!(
        matches!(legacy_err(&three), VtkError::Mesh { .. }),
        "{}",
        legacy_err(&three)
    );
}

#[test]
fn malformed_vtu_files_are_typed_errors() {
    let err = |text: String| from_vtu_bytes(text.as_bytes(), path()).unwrap_err();
    let parse_at = |text: String, want: usize, needle: &str| match err(text) {
        VtkError::Parse { line, message, .. } => {
            assert_eq!(line, want, "{message}");
            assert!(message.contains(needle), "{message}");
        }
        other => panic!("expected a parse error, got {other}"),
    };
    parse_at(
        VTU.replace("0 1 2 3 -4.5", "0 1 2 3"),
        6,
        "4 values, expected 5",
    );
    parse_at(VTU.replace("5 6 7 8 9", "5 6 inf 8 9"), 7, "not finite");
    parse_at(
        VTU.replace("NumberOfCells=\"2\"", "NumberOfCells=\"3\""),
        16,
        "expected 3",
    );
    parse_at(VTU.replace("</Piece>", ""), 20, "XML");
    parse_at(
        VTU.replace(
            "byte_order=\"LittleEndian\"",
            "compressor=\"vtkZLibDataCompressor\"",
        ),
        2,
        "compressed",
    );
    assert!(matches!(
        err(VTU.replace("0 1 2 3 0 1 2 4", "0 1 2 3 0 1 2 9")),
        VtkError::Cell { cell: 1, .. }
    ));
    assert!(matches!(
        err(VTU.replace("10 10", "10 42")),
        VtkError::Cell { cell: 1, .. }
    ));
}

#[test]
fn truncated_files_are_errors_never_panics() {
    let m = mesh_with_field(2);
    for enc in ENCODINGS {
        for bytes in [to_legacy_bytes(&m, enc), to_vtu_bytes(&m, enc)] {
            // Every cut through the first part, then a stride.
            let cuts = (0..bytes.len().min(600)).chain((600..bytes.len()).step_by(97));
            for len in cuts {
                // A legacy file cut just before a field step is a valid
                // file with fewer steps; a .vtu only loses trailing space.
                let rest = &bytes[len..];
                let legitimate = rest.iter().all(u8::is_ascii_whitespace)
                    || (len > 0
                        && bytes[len - 1] == b'\n'
                        && (rest.starts_with(b"POINT_DATA")
                            || rest.starts_with(b"SCALARS density")));
                if legitimate {
                    continue;
                }
                assert!(
                    from_vtk_bytes(&bytes[..len], path()).is_err(),
                    "{enc:?}: a file cut at {len} of {} bytes parsed",
                    bytes.len()
                );
            }
        }
    }
}

#[test]
fn pvd_time_series_round_trip_and_mismatches() {
    use tet_build::vtk::{read_pvd, write_pvd};
    let dir = tempfile::tempdir().unwrap();
    let m = mesh_with_field(3);
    let pvd = dir.path().join("series.pvd");
    write_pvd(&pvd, &m, VtkEncoding::Binary).unwrap();
    for k in 0..3 {
        assert!(dir.path().join(format!("series_t{k:04}.vtu")).is_file());
    }
    assert_eq!(read_pvd(&pvd).unwrap(), m);
    assert_eq!(read_vtk(&pvd).unwrap(), m);
    // Steps follow `timestep`, not the order of the lines.
    let text = std::fs::read_to_string(&pvd).unwrap();
    let reversed = text
        .replace("timestep=\"0\"", "timestep=\"9\"")
        .replace("timestep=\"2\"", "timestep=\"-1\"");
    std::fs::write(&pvd, &reversed).unwrap();
    let r = read_pvd(&pvd).unwrap();
    let f = m.attributes.scalars.as_ref().unwrap();
    assert_eq!(
        r.attributes.scalars.unwrap().steps,
        [f.steps[2].clone(), f.steps[1].clone(), f.steps[0].clone()]
    );
    // A step holding another mesh is an error naming the DataSet's line.
    let other = mesh_with_field(0);
    let mut moved = other.clone();
    moved.points[0].x += 0.01;
    moved.attributes.scalars = Some(ScalarField::single(
        "density",
        vec![0.0; moved.points.len()],
    ));
    std::fs::write(
        dir.path().join("series_t0001.vtu"),
        to_vtu_bytes(&moved, VtkEncoding::Ascii),
    )
    .unwrap();
    std::fs::write(&pvd, &text).unwrap();
    match read_pvd(&pvd) {
        Err(VtkError::Parse { line, message, .. }) => {
            assert_eq!(line, 5, "{message}");
            assert!(message.contains("another mesh"), "{message}");
        }
        other => panic!("{other:?}"),
    }
    // A missing step file is an I/O error naming that file.
    write_pvd(&pvd, &m, VtkEncoding::Ascii).unwrap();
    std::fs::remove_file(dir.path().join("series_t0002.vtu")).unwrap();
    match read_pvd(&pvd) {
        Err(VtkError::Io { path, .. }) => assert!(path.ends_with("series_t0002.vtu")),
        other => panic!("{other:?}"),
    }
}
