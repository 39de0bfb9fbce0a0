//! A volume named by a spec string, for command lines: a VTK file
//! (`.vtk`, `.vtu`, or a `.pvd` time series), TetGen files (`base.node` / `base.ele`, with point
//! attributes as the field), a mesh file in the tet-core format (any other
//! existing file, e.g. `.tmesh`), or one of the synthetic volumes
//! ([`super::synthetic_volume_names`]).

use std::path::Path;

use tet_core::TetMesh;

use super::VolumeError;
use super::named::{VolumeOptions, synthetic_volume};
use crate::{tetgen_files, vtk};

/// Loads the volume `spec` names (see the module docs). `options` applies
/// to synthetic volumes only. A file may carry no scalar field
/// (`mesh.attributes.scalars` is then `None`).
pub fn load_volume(spec: &str, options: &VolumeOptions) -> Result<TetMesh, VolumeError> {
    let lower = spec.to_ascii_lowercase();
    let path = Path::new(spec);
    if lower.ends_with(".vtk") || lower.ends_with(".vtu") || lower.ends_with(".pvd") {
        return Ok(vtk::read_vtk(path)?);
    }
    if lower.ends_with(".node") || lower.ends_with(".ele") {
        let base = path.with_extension("");
        let files = tetgen_files::read(&base)?;
        return Ok(tetgen_files::to_tet_mesh(&files, &base, None)?);
    }
    if path.is_file() {
        return Ok(tet_core::format::load(path)?);
    }
    synthetic_volume(spec, options)
}
