// Body of the `vtk_files` fuzz target: arbitrary bytes given to the VTK
// readers of `tet_build::vtk` (legacy `.vtk` and XML `.vtu`).
//
// Input layout: byte 0 picks the reader (0 mod 3: legacy, 1: XML, 2: by
// content as `read_vtk` does); the rest is the file.
//
// Property: the reader returns a typed `VtkError` naming the file, or a
// mesh that validates and survives every writer (legacy ASCII/BINARY,
// `.vtu` ASCII/base64/appended) and its reader unchanged — the legacy
// writers only when the field's name is one word, as legacy names must
// be. Never a panic.

use std::path::Path;

use tet_build::vtk::{self, VtkEncoding};
use tet_core::TetMesh;

/// The path the readers are given (errors must name it).
pub const PATH: &str = "fuzz-input.vtk";

/// Splits fuzz bytes into the reader selector and the file.
pub fn split(data: &[u8]) -> (u8, &[u8]) {
    data.split_first().map_or((0, &[][..]), |(s, r)| (*s, r))
}

/// Joins a selector and a file into one fuzz input (the inverse of [`split`]).
pub fn join(selector: u8, file: &[u8]) -> Vec<u8> {
    let mut out = vec![selector];
    out.extend_from_slice(file);
    out
}

/// Runs the property on `data`; returns whether a mesh was read.
pub fn check(data: &[u8]) -> bool {
    let (selector, file) = split(data);
    let path = Path::new(PATH);
    let read = match selector % 3 {
        0 => vtk::from_legacy_bytes(file, path),
        1 => vtk::from_vtu_bytes(file, path),
        _ => vtk::from_vtk_bytes(file, path),
    };
    match read {
        Ok(mesh) => {
            check_mesh(&mesh);
            true
        }
        Err(e) => {
            let msg = e.to_string();
            assert!(msg.starts_with(PATH), "error does not name the file: {msg}");
            false
        }
    }
}

fn check_mesh(mesh: &TetMesh) {
    if let Err(e) = mesh.validate() {
        panic!("a VTK reader returned an invalid mesh: {e}");
    }
    let path = Path::new(PATH);
    let one_word = mesh
        .attributes
        .scalars
        .as_ref()
        .is_none_or(|f| !f.name.is_empty() && !f.name.chars().any(char::is_whitespace));
    for enc in [VtkEncoding::Ascii, VtkEncoding::Binary, VtkEncoding::Appended] {
        let back = vtk::from_vtu_bytes(&vtk::to_vtu_bytes(mesh, enc), path)
            .unwrap_or_else(|e| panic!("our .vtu ({enc:?}) does not read back: {e}"));
        assert!(back == *mesh, ".vtu ({enc:?}) round trip differs");
        if one_word && enc != VtkEncoding::Appended {
            let back = vtk::from_legacy_bytes(&vtk::to_legacy_bytes(mesh, enc), path)
                .unwrap_or_else(|e| panic!("our .vtk ({enc:?}) does not read back: {e}"));
            assert!(back == *mesh, "legacy ({enc:?}) round trip differs");
        }
    }
}
