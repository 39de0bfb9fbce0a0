//! # tet-trace-cpu
//!
//! CPU ray traversal through a constrained tetrahedralization: a ray walks
//! from the tet containing its origin, neighbour by neighbour, until it
//! crosses a constrained face (a scene triangle).
//!
//! * [`ray`]: [`Ray`], [`Hit`], [`TraceOutcome`] (hit / miss / reported failure);
//! * [`mod@locate`]: exact point location (seed 000 §4.2);
//! * [`entry`]: rays from a viewpoint outside the mesh enter through its boundary;
//! * [`walk`]: the watertight traversal engine and its projections;
//! * [`scaled`]: the scaled basis of Eq. 1–3, specialised per direction case;
//! * kernels, one per method: [`sctp`], [`tet32`], [`tet20`], [`tet16`], [`tet80`];
//! * [`mod@reference`]: f64 brute-force closest hit and ray generators for tests;
//! * [`render`]: pinhole renderer, Lambert shading, PNG, heat maps, stats;
//! * [`secondary`]: shadow, reflection and refraction rays (seed 000 §6).

#![deny(missing_docs)]

pub mod area_light;
pub mod entry;
pub mod kernel;
pub mod locate;
pub mod lockstep;
pub mod ray;
pub mod reference;
pub mod render;
pub mod scaled;
pub mod sctp;
mod sctp_lockstep;
pub mod secondary;
pub mod tet16;
pub mod tet20;
pub mod tet32;
pub mod tet80;
pub mod walk;

pub use entry::{Viewpoint, ViewpointError};
pub use kernel::{Tracer, WalkTracer};
pub use locate::{LocateError, locate};
pub use ray::{Failure, Hit, Ray, TraceOutcome};
pub use walk::{DuffF32, DuffF64, OriginF32, Projection, Start, Starts, TripleF32};
