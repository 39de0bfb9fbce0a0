//! TetGen 1.5 (Si 2015) through our own C ABI shim, in process or in an
//! isolated worker process.
//!
//! * [`TetgenInput`] is a piecewise-linear complex made of triangles only:
//!   each triangle becomes one TetGen facet with its own marker, so TetGen
//!   never merges coplanar neighbours and every output subface names its
//!   source triangle (marker `0` is free for faces that are not scene
//!   triangles, e.g. an enclosing box).
//! * [`TetgenOptions`] builds the switch string. The default `-pYzQ` is the
//!   surface-preserving constrained Delaunay tetrahedralization the papers'
//!   construction times correspond to (Aman et al. §5, Maria et al. §6); `-q`
//!   (quality), `-S` (Steiner cap) and `-T` (coplanarity tolerance) are opt-in.
//! * The shim runs TetGen's stages with its own short driver (TetGen's
//!   `tetrahedralize()` reduced to our switches, same output), which
//!   changes one thing: `-S` caps the quality refinement's Steiner points
//!   alone. TetGen counts the points its boundary recovery added (2,735 on
//!   Torus Knots) against `-S`, so a cap below those refined nothing.
//! * [`Isolation`] chooses where TetGen runs. TetGen can abort (failed
//!   assertions, segmentation faults) or refine without end on some inputs;
//!   [`Isolation::Worker`] runs it in a child process (see [`worker`]) that
//!   is killed at a time limit, so no input can take the caller down.
//!   [`Isolation::InProcess`] is faster (no copy through a pipe) and catches
//!   every C++ exception, but a crash inside TetGen ends the process and
//!   there is no time limit. In-process runs are serialized by a global lock:
//!   TetGen's predicates keep per-run global state (`exactinit`), so
//!   concurrent runs in one process would corrupt each other; run several
//!   TetGen jobs in parallel through workers instead.
//!
//! Every input is checked in Rust before TetGen sees it ([`check_input`]):
//! non-finite coordinates, out-of-range or repeated vertex ids, degenerate
//! (exactly collinear) triangles and duplicated triangles are typed errors.
//! TetGen's own failure codes (`terminatetetgen`) become [`TetgenError`]
//! variants carrying their documented meaning.
//!
//! Modules, bottom up: [`ffi`] (the C ABI), [`error`], [`types`],
//! [`check`], `in_process` and [`worker`]; this module only chooses where
//! to run ([`tetrahedralize`]).

pub mod check;
pub mod error;
pub mod ffi;
mod in_process;
pub mod types;
pub mod worker;

pub use check::check_input;
pub use error::TetgenError;
pub use types::{Isolation, Optimization, TetgenInput, TetgenOptions, TetgenOutput, WorkerCommand};

/// Tetrahedralizes `input` where `isolation` says.
pub fn tetrahedralize(
    input: &TetgenInput,
    options: &TetgenOptions,
    isolation: &Isolation,
) -> Result<TetgenOutput, TetgenError> {
    check_input(input)?;
    options.check()?;
    match isolation {
        Isolation::InProcess => in_process::run_in_process(input, options),
        Isolation::Worker(cmd) => worker::run_worker(cmd, input, options),
    }
}
