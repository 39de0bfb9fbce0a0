//! # tet-trace-cpu
//!
//! CPU ray traversal through a constrained tetrahedralization: a ray walks
//! from the tet containing its origin, neighbour by neighbour, until it
//! crosses a constrained face (a scene triangle).
//!
//! * [`ray`]: [`Ray`], [`Hit`], [`TraceOutcome`] (hit / miss / reported failure);
//! * [`mod@locate`]: exact point location (Aman et al. 2022, §4.2);
//! * [`boundary_entry`]: rays from a viewpoint outside the mesh enter through its boundary;
//! * [`walk`]: the watertight traversal engine and its projections;
//! * [`lockstep`]: the SIMD lockstep batch walks, and [`batch`]: which
//!   batch walk each projection takes;
//! * [`scaled`]: the scaled basis of Eq. 1–3, specialised per direction case;
//! * kernels, one per method: [`sctp`], [`tet32`], [`tet20`], [`tet16`], [`tet80`];
//! * [`exact`]: the exact reference walk (exact predicates, symbolic
//!   perturbation), the yardstick of the accuracy measurement;
//! * [`mod@reference`]: f64 brute-force closest hit and ray generators for tests;
//! * [`render`]: pinhole renderer, Lambert shading, PNG, heat maps, stats;
//! * [`secondary`]: shadow, reflection and refraction rays (Aman et al. 2022, §6).
//!
//! # Example
//!
//! A mesh (here a procedural grid with a closed box of constrained faces
//! inside), the Tet20 kernel, and one ray from inside the mesh:
//!
//! ```
//! use glam::Vec3;
//! use tet_core::synthetic::{GridSpec, kuhn_grid};
//! use tet_trace_cpu::{DuffF32, Ray, Start, TraceOutcome, Tracer, locate, tet20::Tet20Tracer};
//!
//! let shell = Some(([1; 3], [3; 3]));
//! let mesh = kuhn_grid(&GridSpec { cells: [4; 3], shell, ..Default::default() });
//! let tracer = Tet20Tracer::<DuffF32>::new(&mesh).unwrap();
//! let origin = Vec3::new(0.5, 0.5, 0.5); // outside the box, inside the mesh
//! let start = Start::Tet(locate(&mesh, origin, 0).unwrap());
//! let ray = Ray::new(origin, Vec3::splat(2.0) - origin); // toward the box centre
//! let TraceOutcome::Hit(hit) = tracer.trace(&ray, start) else { panic!("no hit") };
//! assert!(hit.t > 0.0 && hit.tets_visited > 0);
//! ```
//!
//! # Adding a layout
//!
//! A layout is its layout file, its kernel file and one registry line:
//!
//! 1. **The layout file** (`tet-core`, a module of `tet_core::layout`):
//!    the record, `#[repr(C)]` and [`bytemuck::Pod`] in 32-bit words, and
//!    its encoding from a mesh and back (`tet_core::layout::LayoutRecord`),
//!    so that `tet_core::layout::LayoutMesh` of it exists.
//! 2. **The kernel file** (here, `src/tetNN.rs`, like [`tet20`]):
//!    `impl WalkRecord for TetNN` ([`kernel::WalkRecord`]: the kernel's
//!    name, `VX`, the scalar exit link the scalar walks read, and
//!    `type Exit`); the exit rule as a zero-sized type `TetNNExit`
//!    implementing [`lockstep::ExitRule`] (the words of a record it
//!    reads, and the same exit link in SIMD lanes, which the lockstep walk
//!    gathers; [`lockstep::ByLane`] instead makes the lockstep walk give
//!    its batches to the scalar interleaved walk); and the tracer,
//!    `pub type TetNNTracer<'m, P = DuffF32> = WalkTracer<'m, TetNNMesh, P>`.
//!    [`WalkTracer::new`] then encodes a mesh in it, and every walk runs
//!    over it: single rays, shadow rays, the interleaved batches and the
//!    lockstep batches ([`lockstep::trace`] with [`lockstep::Planar`]) at
//!    every width.
//! 3. **One registry line**: `pub mod tetNN;` below (and, to run it from
//!    the command line, its arm in `tet-bench`'s method registry).
//!
//! Nothing else names the layouts: no enum of rules, no dispatch table.
//! To test it, add its tracer to the kernels of `tests/lockstep.rs` (every
//! lockstep width against the scalar walk, bit for bit) and
//! `tests/kernels.rs`.

#![deny(missing_docs)]

pub mod area_light;
pub mod batch;
pub mod boundary_entry;
pub mod exact;
pub mod iso;
pub mod kernel;
pub mod locate;
pub mod lockstep;
mod lost;
pub mod ray;
pub mod reference;
pub mod render;
pub mod scaled;
pub mod sctp;
pub mod secondary;
mod shadow_batch;
pub mod tet16;
pub mod tet20;
pub mod tet32;
pub mod tet80;
pub mod tracer;
pub mod walk;

pub use batch::BatchWalk;
pub use boundary_entry::{Viewpoint, ViewpointError};
pub use kernel::{Tracer, WalkTracer};
pub use locate::{LocateError, locate};
pub use ray::{Failure, Hit, Ray, TraceOutcome};
pub use walk::{DuffF32, DuffF64, OriginF32, Projection, Start, Starts, TripleF32};
