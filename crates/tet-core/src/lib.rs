//! # tet-core
//!
//! The data model of a constrained Delaunay tetrahedralization (CDT) used as a
//! ray-tracing acceleration structure: a ray walks from tetrahedron to
//! neighbour until it crosses a *constrained face*, i.e. a face lying on a
//! scene triangle.
//!
//! * [`TetMesh`] is the canonical, validated mesh every other crate builds on.
//! * [`Link`] is the 32-bit neighbour reference shared by every layout: a
//!   neighbour tet, the mesh boundary, or (flag bit set) an index into the
//!   cold constrained-face table.
//! * [`synthetic`] generates valid meshes without an external mesher (for tests,
//!   fuzzing and benchmarks).
//! * [`fields`]: an optional per-point scalar field with one or more time
//!   steps ([`Attributes::scalars`]), the data isosurfaces are traced in
//!   (Wald et al. 2007); stored in the mesh file's scalar block.
//!
//! Conventions (used by every layout and kernel):
//! * tet `t` has vertices `tets[t] = [v0, v1, v2, v3]`, positively oriented:
//!   `orient3d(v0, v1, v2, v3) > 0`, i.e. `((v1-v0) × (v2-v0)) · (v3-v0) > 0`;
//! * face `k` of a tet is the face opposite vertex `k`, and neighbour `k` is the
//!   tet across face `k`;
//! * [`FACE_VERTICES`]`[k]` lists face `k`'s vertex slots in the order whose
//!   right-hand normal points out of the tet.
//!
//! # Example: one mesh, every layout, exact bytes
//!
//! ```
//! use tet_core::format;
//! use tet_core::layout::{Tet16Mesh, Tet20Mesh};
//! use tet_core::memory::MemoryReport;
//! use tet_core::synthetic::{GridSpec, kuhn_grid};
//!
//! // A valid mesh without an external mesher: 4×4×4 cubes, 6 tets each.
//! let mesh = kuhn_grid(&GridSpec { cells: [4, 4, 4], ..GridSpec::default() });
//! assert_eq!(mesh.tets.len(), 6 * 64);
//!
//! // The compact layouts encode it losslessly...
//! let tet20 = Tet20Mesh::from_mesh(&mesh).unwrap();
//! assert_eq!(tet20.to_mesh().unwrap().tets.len(), mesh.tets.len());
//! // ...and report their exact size, hot (walked) and cold (read on a hit).
//! assert_eq!(tet20.memory().tets, 20 * mesh.tets.len());
//! let report = MemoryReport::for_mesh(&mesh);
//! assert_eq!(report.get("tet16"), Some(&Tet16Mesh::from_mesh(&mesh).unwrap().memory()));
//!
//! // The on-disk format round-trips bit for bit, checked on load.
//! let bytes = format::to_bytes(&mesh);
//! assert_eq!(format::from_bytes(&bytes).unwrap(), mesh);
//! ```

#![deny(missing_docs)]

pub mod error;
pub mod fields;
pub mod format;
pub mod hilbert;
pub mod input_triangles;
pub mod layout;
pub mod link;
pub mod memory;
pub mod mesh;
pub mod predicates;
pub mod regions;
pub mod reorder;
pub mod scene;
pub mod synthetic;
mod validate;

pub use error::MeshError;
pub use fields::ScalarField;
pub use input_triangles::InputTriangles;
pub use link::{Link, LinkKind, MAX_TETS};
pub use mesh::{Attributes, ConstrainedFace, FACE_VERTICES, FaceSide, NO_TET, TetMesh, face_key};
