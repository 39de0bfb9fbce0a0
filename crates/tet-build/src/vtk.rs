//! Export of a [`TetMesh`] as a VTK XML unstructured grid (`.vtu`, ASCII)
//! for ParaView: the tets (VTK type 10) followed by the constrained faces
//! as triangles (VTK type 5), told apart by the cell-data arrays
//! `kind` (0 = tet, 1 = constrained face) and `triangle` (source scene
//! triangle of a constrained face, -1 for tets). Filter on `kind` in
//! ParaView (Threshold) to see either part. The write is atomic.

use std::fmt::Write as _;
use std::path::Path;

use tet_core::TetMesh;

pub use crate::tetgen_files::FilesError as VtkError;

/// VTK cell type of a tetrahedron.
pub const VTK_TETRA: u8 = 10;
/// VTK cell type of a triangle.
pub const VTK_TRIANGLE: u8 = 5;

/// The `.vtu` document for `mesh`.
pub fn to_vtu_string(mesh: &TetMesh) -> String {
    let nt = mesh.tets.len();
    let nc = mesh.constrained.len();
    let mut s = String::with_capacity(64 * (mesh.points.len() + nt + nc) + 1024);
    s.push_str("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n");
    let _ = writeln!(
        s,
        "<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
        mesh.points.len(),
        nt + nc
    );
    s.push_str(
        "<Points>\n<DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">\n",
    );
    for p in &mesh.points {
        let _ = writeln!(s, "{:?} {:?} {:?}", p.x, p.y, p.z);
    }
    s.push_str("</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for t in &mesh.tets {
        let _ = writeln!(s, "{} {} {} {}", t[0], t[1], t[2], t[3]);
    }
    for c in &mesh.constrained {
        let _ = writeln!(s, "{} {} {}", c.vertices[0], c.vertices[1], c.vertices[2]);
    }
    s.push_str("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for i in 1..=nt {
        let _ = writeln!(s, "{}", 4 * i);
    }
    for i in 1..=nc {
        let _ = writeln!(s, "{}", 4 * nt + 3 * i);
    }
    s.push_str("</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    for _ in 0..nt {
        let _ = writeln!(s, "{VTK_TETRA}");
    }
    for _ in 0..nc {
        let _ = writeln!(s, "{VTK_TRIANGLE}");
    }
    s.push_str("</DataArray>\n</Cells>\n<CellData Scalars=\"kind\">\n<DataArray type=\"UInt8\" Name=\"kind\" format=\"ascii\">\n");
    for _ in 0..nt {
        s.push_str("0\n");
    }
    for _ in 0..nc {
        s.push_str("1\n");
    }
    s.push_str("</DataArray>\n<DataArray type=\"Int64\" Name=\"triangle\" format=\"ascii\">\n");
    for _ in 0..nt {
        s.push_str("-1\n");
    }
    for c in &mesh.constrained {
        let _ = writeln!(s, "{}", c.triangle);
    }
    s.push_str("</DataArray>\n</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    s
}

/// Writes `mesh` to `path` as `.vtu` (atomically: temporary file + rename).
pub fn write_vtu(path: &Path, mesh: &TetMesh) -> Result<(), VtkError> {
    crate::tetgen_files::atomic_write(path, to_vtu_string(mesh).as_bytes())
}
