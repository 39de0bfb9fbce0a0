//! Our VTK writer read back by an independent reader (the `vtkio` crate):
//! a `.vtu` in each XML encoding and a legacy `.vtk` in each legacy
//! encoding give back the mesh's points, its tets (as VTK_TETRA cells) and
//! its point scalars.
//!
//! Not covered: `.vtu` with raw appended data ([`VtkEncoding::Appended`]).
//! Raw bytes inside `<AppendedData>` are valid VTK (ParaView writes and
//! reads them) but not well-formed XML, and `vtkio`'s XML parser rejects
//! them (`EndEventMismatch` at `AppendedData`), as XML-based readers such
//! as meshio do; our own reader's round trip covers that encoding
//! (`tests/vtk.rs`).
//!
//! Legacy files are read with their dataset-level field data (the
//! `FIELD FieldData 1` block right after `DATASET`, which carries our
//! triangle count) cut out: the VTK file format allows that block there
//! and VTK's own writers put it there, but `vtkio`'s legacy parser (0.6, 0.7)
//! accepts no field data before `POINTS`. Everything else of the file,
//! byte for byte, is what `vtkio` reads.

use tet_build::vtk::{VtkEncoding, write_vtk};
use tet_core::synthetic::{GridSpec, kuhn_grid};
use tet_core::{ScalarField, TetMesh};
use vtkio::Vtk;
use vtkio::model::{Attribute, CellType, DataSet, IOBuffer, Piece};

fn mesh() -> TetMesh {
    let mut m = kuhn_grid(&GridSpec {
        cells: [2, 3, 2],
        jitter: 0.12,
        seed: 7,
        ..GridSpec::default()
    });
    let n = m.points.len();
    m.attributes.scalars = Some(ScalarField {
        name: "density".into(),
        steps: vec![
            (0..n)
                .map(|i| (i as f32 * 0.37).sin() * 1e3 + 0.25)
                .collect(),
        ],
    });
    m.validate().unwrap();
    m
}

/// Every number of a buffer as f64 (the reader keeps the file's type).
fn numbers(b: &IOBuffer) -> Vec<f64> {
    match b {
        IOBuffer::F32(v) => v.iter().map(|&x| x as f64).collect(),
        IOBuffer::F64(v) => v.clone(),
        IOBuffer::I32(v) => v.iter().map(|&x| x as f64).collect(),
        IOBuffer::I64(v) => v.iter().map(|&x| x as f64).collect(),
        IOBuffer::U32(v) => v.iter().map(|&x| x as f64).collect(),
        IOBuffer::U64(v) => v.iter().map(|&x| x as f64).collect(),
        IOBuffer::U8(v) => v.iter().map(|&x| x as f64).collect(),
        IOBuffer::I8(v) => v.iter().map(|&x| x as f64).collect(),
        IOBuffer::U16(v) => v.iter().map(|&x| x as f64).collect(),
        IOBuffer::I16(v) => v.iter().map(|&x| x as f64).collect(),
        other => panic!("unexpected buffer {other:?}"),
    }
}

/// A legacy file without its dataset-level `FIELD` block (see the module
/// docs): the bytes from `FIELD FieldData` up to `POINTS` removed.
fn without_field_data(bytes: &[u8]) -> Vec<u8> {
    let find = |pat: &[u8], from: usize| {
        bytes[from..]
            .windows(pat.len())
            .position(|w| w == pat)
            .map(|i| i + from)
            .expect("block present")
    };
    let i = find(b"FIELD FieldData", 0);
    let j = find(b"POINTS", i);
    [&bytes[..i], &bytes[j..]].concat()
}

/// Checks what `vtkio` read from `path` against `m`.
fn check(vtk: Vtk, m: &TetMesh, what: &str) {
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("{what}: not an unstructured grid");
    };
    assert_eq!(pieces.len(), 1, "{what}");
    let Piece::Inline(p) = &pieces[0] else {
        panic!("{what}: piece not inline");
    };
    let pts = numbers(&p.points);
    let want: Vec<f64> = m
        .points
        .iter()
        .flat_map(|q| q.to_array())
        .map(|x| x as f64)
        .collect();
    assert_eq!(pts, want, "{what}: points");
    let (n, verts) = p.cells.cell_verts.clone().into_legacy();
    assert_eq!(n as usize, m.tets.len(), "{what}: cell count");
    let mut got = Vec::new();
    let mut i = 0;
    while i < verts.len() {
        let k = verts[i] as usize;
        got.push(verts[i + 1..i + 1 + k].to_vec());
        i += 1 + k;
    }
    let want: Vec<Vec<u32>> = m.tets.iter().map(|t| t.to_vec()).collect();
    assert_eq!(got, want, "{what}: connectivity");
    assert!(
        p.cells.types.iter().all(|&t| t == CellType::Tetra),
        "{what}"
    );
    let field = m.attributes.scalars.as_ref().unwrap();
    let data = p
        .data
        .point
        .iter()
        .find_map(|a| match a {
            Attribute::DataArray(d) if d.name == field.name => Some(numbers(&d.data)),
            _ => None,
        })
        .unwrap_or_else(|| panic!("{what}: no point array {}", field.name));
    let want: Vec<f64> = field.steps[0].iter().map(|&x| x as f64).collect();
    assert_eq!(data, want, "{what}: point scalars");
}

#[test]
fn vtkio_reads_our_vtu_and_legacy_files() {
    let m = mesh();
    let dir = tempfile::tempdir().unwrap();
    for (ext, encodings) in [
        ("vtu", &[VtkEncoding::Ascii, VtkEncoding::Binary][..]),
        ("vtk", &[VtkEncoding::Ascii, VtkEncoding::Binary][..]),
    ] {
        for &enc in encodings {
            let path = dir.path().join(format!("m_{enc:?}.{ext}"));
            write_vtk(&path, &m, enc).unwrap();
            let what = format!("{ext} {enc:?}");
            let vtk = if ext == "vtu" {
                Vtk::import(&path)
            } else {
                Vtk::parse_legacy_be(&without_field_data(&std::fs::read(&path).unwrap())[..])
            };
            let vtk = vtk.unwrap_or_else(|e| panic!("{what}: {e:?}"));
            check(vtk, &m, &what);
        }
    }
}
