//! VTK files: a [`TetMesh`] with its scalar field to and from the legacy
//! format (`.vtk`, ASCII or BINARY) and the XML unstructured-grid format
//! (`.vtu`, ASCII, base64 "binary" or appended raw data), so volumes made
//! elsewhere (ParaView, meshio, simulation codes) can be traced and ours
//! inspected.
//!
//! # What a file holds
//!
//! * **Cells**: tetrahedra (VTK type 10), then our constrained faces as
//!   triangles (type 5). Cell data `kind` tells them apart (0 = tet, 1 =
//!   constrained face) and `triangle` gives a face's scene triangle (-1 for
//!   tets); field data `triangle_count` is [`TetMesh::triangle_count`]. In
//!   ParaView, Threshold on `kind` shows either part.
//! * **Point data**: the scalar field ([`tet_core::Attributes::scalars`]),
//!   one `Float32` array per time step: named after the field when it has
//!   one step, `name_t0000`, `name_t0001`, … when it has several.
//!
//! # Reading
//!
//! [`read_vtk`] picks the format from the content (a legacy file starts with
//! `# vtk DataFile Version`). The result is a validated mesh:
//!
//! * every cell must be a tetrahedron, or a triangle marked `kind = 1`
//!   (our constrained faces, scene triangle from the `triangle` array,
//!   which must be present); any other cell is an error naming the cell;
//! * points are rounded to `f32`; each tet is oriented positively by the
//!   exact orientation of the file's coordinates, and a tet that is flat, or
//!   flat or inverted after rounding, is an error naming the cell;
//! * neighbours are linked ([`TetMesh::assemble`]) and the mesh validated;
//! * **scalar field**: every one-component point-data array is one time
//!   step, in file order (several arrays mean several steps). The field is
//!   named after the first array; when the arrays are exactly `name_t0000`,
//!   `name_t0001`, … the suffix is dropped (so our files round-trip).
//!   Values are rounded to `f32` and must be finite. Arrays with several
//!   components (vectors, …) are read past.
//! * **time series as files**: a ParaView collection (`.pvd`) lists one
//!   file per time step; [`read_pvd`] joins them (same mesh in every file)
//!   into one field with all their steps, [`write_pvd`] writes one `.vtu`
//!   per step. [`read_vtk`] reads a `.pvd` too.
//!
//! Malformed files give [`VtkError`]s naming the file and the line (legacy;
//! for XML the line of the element) or the cell at fault: unknown keywords
//! or types, counts that disagree, indices out of range, non-finite values,
//! truncated data. No count read from a file sizes an allocation beyond
//! what the file's length can hold. A legacy file has no end marker, so it
//! must end with a line break and hold `POINTS`, `CELLS` and `CELL_TYPES`;
//! a legacy file cut exactly before a `POINT_DATA` or `SCALARS` line still
//! reads (with fewer field steps), as it is a valid file.
//!
//! Normals, texture coordinates and materials are not stored in VTK files
//! and are dropped on export. Legacy array names are single words: spaces
//! in a field's name become `_`.

use std::fs;
use std::io;
use std::path::{Path, PathBuf};

use tet_core::{MeshError, TetMesh};
use thiserror::Error;

mod base64;
mod legacy;
mod model;
mod series;
mod xml;

pub use legacy::{from_legacy_bytes, to_legacy_bytes};
pub use model::{KIND_ARRAY, TRIANGLE_ARRAY, TRIANGLE_COUNT_FIELD};
pub use series::{read_pvd, write_pvd};
pub use xml::{from_vtu_bytes, to_vtu_bytes};

/// VTK cell type of a tetrahedron.
pub const VTK_TETRA: u8 = 10;
/// VTK cell type of a triangle.
pub const VTK_TRIANGLE: u8 = 5;

/// How data arrays are written.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum VtkEncoding {
    /// Text (exact: `f32` values as shortest round-trip decimals).
    #[default]
    Ascii,
    /// Legacy: `BINARY` (big-endian); XML: inline base64 (`format="binary"`).
    Binary,
    /// XML: raw appended data (`format="appended"`); legacy: as [`VtkEncoding::Binary`].
    Appended,
}

/// Why a VTK file could not be read or written. Every variant names the file.
#[derive(Debug, Error)]
pub enum VtkError {
    /// The file could not be read or written.
    #[error("{path}: {source}", path = .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: io::Error,
    },
    /// The file is malformed at this line (0: not tied to one line).
    #[error("{path}:{line}: {message}", path = .path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line number (for XML, of the element at fault).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A cell is not usable (not a tet or marked triangle, vertex out of
    /// range, flat).
    #[error("{path}: cell {cell}: {message}", path = .path.display())]
    Cell {
        /// The file.
        path: PathBuf,
        /// 0-based cell index.
        cell: usize,
        /// What is wrong.
        message: String,
    },
    /// The cells do not form a valid mesh (e.g. a face shared by three tets).
    #[error("{path}: invalid mesh: {source}", path = .path.display())]
    Mesh {
        /// The file.
        path: PathBuf,
        /// The violated invariant.
        source: MeshError,
    },
}

fn read_bytes(path: &Path) -> Result<Vec<u8>, VtkError> {
    fs::read(path).map_err(|source| VtkError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Reads a legacy `.vtk` file (see the module docs).
pub fn read_legacy(path: &Path) -> Result<TetMesh, VtkError> {
    from_legacy_bytes(&read_bytes(path)?, path)
}

/// Reads an XML `.vtu` file (see the module docs).
pub fn read_vtu(path: &Path) -> Result<TetMesh, VtkError> {
    from_vtu_bytes(&read_bytes(path)?, path)
}

/// Parses a file image of either format, told apart by its first bytes.
pub fn from_vtk_bytes(bytes: &[u8], path: &Path) -> Result<TetMesh, VtkError> {
    let start = bytes
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .unwrap_or(0);
    if bytes[start..].starts_with(b"#") {
        from_legacy_bytes(bytes, path)
    } else {
        from_vtu_bytes(bytes, path)
    }
}

/// Reads a VTK file of either format, or a `.pvd` collection (by its
/// extension; see the module docs).
pub fn read_vtk(path: &Path) -> Result<TetMesh, VtkError> {
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("pvd"))
    {
        return read_pvd(path);
    }
    from_vtk_bytes(&read_bytes(path)?, path)
}

/// The `.vtu` document of `mesh`, ASCII.
pub fn to_vtu_string(mesh: &TetMesh) -> String {
    String::from_utf8(to_vtu_bytes(mesh, VtkEncoding::Ascii)).expect("ASCII output is UTF-8")
}

/// Writes `mesh` to `path` as an ASCII `.vtu` (atomically: temporary file +
/// rename).
pub fn write_vtu(path: &Path, mesh: &TetMesh) -> Result<(), VtkError> {
    write_vtu_with(path, mesh, VtkEncoding::Ascii)
}

/// Writes `mesh` to `path` as `.vtu` with `encoding` (atomically).
pub fn write_vtu_with(path: &Path, mesh: &TetMesh, encoding: VtkEncoding) -> Result<(), VtkError> {
    atomic_write(path, &to_vtu_bytes(mesh, encoding))
}

/// Writes `mesh` to `path` as a legacy `.vtk` file with `encoding` (atomically).
pub fn write_legacy(path: &Path, mesh: &TetMesh, encoding: VtkEncoding) -> Result<(), VtkError> {
    atomic_write(path, &to_legacy_bytes(mesh, encoding))
}

/// Writes `mesh` in the format its extension names: `.vtk` legacy, anything
/// else `.vtu` (both with `encoding`).
pub fn write_vtk(path: &Path, mesh: &TetMesh, encoding: VtkEncoding) -> Result<(), VtkError> {
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("vtk"))
    {
        write_legacy(path, mesh, encoding)
    } else {
        write_vtu_with(path, mesh, encoding)
    }
}

fn atomic_write(path: &Path, bytes: &[u8]) -> Result<(), VtkError> {
    crate::tetgen_files::atomic_write(path, bytes).map_err(|e| match e {
        crate::tetgen_files::FilesError::Io { path, source } => VtkError::Io { path, source },
        other => VtkError::Io {
            path: path.to_path_buf(),
            source: io::Error::other(other.to_string()),
        },
    })
}
