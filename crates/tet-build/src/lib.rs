//! # tet-build
//!
//! From a triangle scene to a constrained Delaunay tetrahedralization
//! ([`tet_core::TetMesh`]). TetGen (AGPL-3.0) is linked only with the default
//! `tetgen` feature; everything else here is permissively licensed.

pub mod bbox;
pub mod clean;
pub mod intersect;
#[cfg(feature = "tetgen")]
pub mod outofcore;
pub mod pipeline;
pub mod procedural;
pub mod quality;
pub mod scene;
pub mod tetgen_files;
pub mod vtk;

#[cfg(feature = "tetgen")]
pub mod tetgen;
