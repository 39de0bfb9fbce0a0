//! # tet-build
//!
//! From a triangle scene to a constrained Delaunay tetrahedralization
//! ([`tet_core::TetMesh`]). TetGen (AGPL-3.0) is linked only with the default
//! `tetgen` feature; everything else here is permissively licensed.
//!
//! ```
//! use glam::Vec3;
//! use tet_build::pipeline::{BuildOptions, build};
//! use tet_build::scene::Scene;
//!
//! // A tetrahedron: four corners, four outward (counter-clockwise) triangles.
//! let vertices = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
//! let triangles = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
//! let scene = Scene { vertices, triangles, ..Scene::default() };
//! let (mesh, _report) = build(&scene, &BuildOptions::default())?;
//! assert_eq!(mesh.constrained.len(), 4); // every triangle is a constrained face
//! println!("{} tets, {} points", mesh.tets.len(), mesh.points.len());
//! # Ok::<(), tet_build::pipeline::BuildError>(())
//! ```
//!
//! Modules, bottom up (each uses only modules above it in this list):
//!
//! * [`scene`]: triangle scenes (OBJ files, `scenes.json`); [`procedural`]:
//!   scenes made in code, among them [`flat`] (flat-faced solids),
//!   [`city`] and [`pipes`] (stand-ins for the paper's Rungholt and Exhaust
//!   Pipe); [`source`]: a scene named by a spec string.
//! * [`clean`], [`intersect`], [`bbox`], [`quality`]: cleaning, exact
//!   self-intersection search, the enclosing box, tet quality;
//!   [`resolve`]: self-intersecting triangles split along their
//!   intersections so that they meet only in shared vertices and edges.
//! * [`tetgen`]: TetGen in process or in a worker process;
//!   [`tetgen_files`], [`vtk`]: TetGen's and ParaView's (VTK) file formats,
//!   VTK with per-point scalar fields.
//! * [`volume`]: tetrahedral volumes with scalar fields for isosurface
//!   tracing (Wald et al. 2007): split grids, analytic fields, named
//!   stand-ins for the paper's data sets.
//! * [`pipeline`]: the in-core build, stage by stage.
//! * [`outofcore`]: the build under a memory limit, part by part (Erkoç et
//!   al. 2021).

#![deny(missing_docs)]

pub mod bbox;
pub mod city;
pub mod clean;
pub mod flat;
pub mod intersect;
#[cfg(feature = "tetgen")]
pub mod outofcore;
pub mod pipeline;
pub mod pipes;
pub mod procedural;
pub mod quality;
/// Making a self-intersecting triangle soup meet only in shared vertices and edges.
pub mod resolve;
pub mod scene;
pub mod source;
pub mod tetgen_files;
pub mod tetgen_options;
pub mod volume;
pub mod vtk;

#[cfg(feature = "tetgen")]
pub mod tetgen;
