//! Tetrahedral volumes with a per-point scalar field, to trace isosurfaces
//! in (Wald et al. 2007): structured grids split into tets
//! ([`grid`]), analytic fields evaluated at the points ([`field`]), and
//! named synthetic stand-ins for the paper's data sets with their sizes
//! ([`named`]). The field of any [`TetMesh`] (a CDT, a VTK file) is set with
//! [`attach_field`] / [`attach_time_series`]. [`load_volume`] takes a
//! command line's spec: a file of any supported format or a synthetic
//! volume's name.
//!
//! Every mesh made here is valid ([`TetMesh::validate`]): positively
//! oriented tets, neighbours linked, no constrained faces, and the field in
//! [`tet_core::Attributes::scalars`].

use tet_core::{MeshError, ScalarField, TetMesh};
use thiserror::Error;

pub mod field;
pub mod grid;
pub mod named;
pub mod source;

pub use field::{AnalyticField, c60_vertices};
pub use grid::{GridVolume, Split, grid_mesh};
pub use named::{
    VolumeInfo, VolumeOptions, build_volume, synthetic_volume, synthetic_volume_info,
    synthetic_volume_names,
};
pub use source::load_volume;

/// Why a volume could not be made.
#[derive(Debug, Error)]
pub enum VolumeError {
    /// No synthetic volume has this name.
    #[error("unknown volume {name:?} (known: {known})")]
    UnknownName {
        /// The name asked for.
        name: String,
        /// The known names, comma-separated.
        known: String,
    },
    /// A grid or option value is out of range.
    #[error("{what}: {detail}")]
    BadParameter {
        /// The parameter.
        what: &'static str,
        /// What is wrong.
        detail: String,
    },
    /// A field value is NaN or infinite.
    #[error("field {name:?} step {step} point {point}: value {value} is not finite")]
    NonFiniteValue {
        /// The field's name.
        name: String,
        /// Time step.
        step: usize,
        /// Point index.
        point: usize,
        /// The value.
        value: f32,
    },
    /// The mesh (or the field on it) breaks an invariant.
    #[error("invalid volume mesh: {0}")]
    Mesh(#[from] MeshError),
    /// A VTK file could not be read.
    #[error(transparent)]
    Vtk(#[from] crate::vtk::VtkError),
    /// TetGen files could not be read or converted.
    #[error(transparent)]
    Tetgen(#[from] crate::tetgen_files::FilesError),
    /// A mesh file could not be loaded.
    #[error(transparent)]
    Format(#[from] tet_core::format::FormatError),
}

/// Sets `mesh`'s scalar field to one step of `f` evaluated at every point
/// (in parallel). A non-finite value is an error naming the point; the
/// mesh is left unchanged then. Replaces any field the mesh had.
pub fn attach_field(
    mesh: &mut TetMesh,
    name: &str,
    f: impl Fn(glam::Vec3) -> f32 + Sync,
) -> Result<(), VolumeError> {
    attach_time_series(mesh, name, 1, |p, _| f(p))
}

/// Sets `mesh`'s scalar field to `steps` steps, step `t` holding
/// `f(point, t)` at every point. Errors as [`attach_field`]; `steps` must
/// be at least 1.
pub fn attach_time_series(
    mesh: &mut TetMesh,
    name: &str,
    steps: usize,
    f: impl Fn(glam::Vec3, usize) -> f32 + Sync,
) -> Result<(), VolumeError> {
    use rayon::prelude::*;
    if steps == 0 {
        return Err(VolumeError::BadParameter {
            what: "steps",
            detail: "a field needs at least one time step".into(),
        });
    }
    tet_core::fields::check_name(name)?;
    let mut all = Vec::with_capacity(steps);
    for step in 0..steps {
        let values: Vec<f32> = mesh.points.par_iter().map(|&p| f(p, step)).collect();
        if let Some(point) = values.iter().position(|v| !v.is_finite()) {
            return Err(VolumeError::NonFiniteValue {
                name: name.to_string(),
                step,
                point,
                value: values[point],
            });
        }
        all.push(values);
    }
    mesh.attributes.scalars = Some(ScalarField {
        name: name.to_string(),
        steps: all,
    });
    Ok(())
}
