//! What goes into and comes out of TetGen: [`TetgenInput`],
//! [`TetgenOptions`], where it runs ([`Isolation`], [`WorkerCommand`]) and
//! [`TetgenOutput`].

use std::ffi::OsString;
use std::path::PathBuf;
use std::time::Duration;

use super::error::TetgenError;

/// A triangle-only PLC for TetGen, in f64 (f32 scene coordinates convert exactly).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TetgenInput {
    /// Input points. Output points keep these indices; Steiner points follow.
    pub points: Vec<[f64; 3]>,
    /// Triangles (indices into `points`), each one facet.
    pub triangles: Vec<[u32; 3]>,
    /// One facet marker per triangle (`triangles.len()` entries). Use
    /// distinct markers (e.g. triangle index + 1) to keep each triangle its
    /// own facet; equal markers let TetGen merge coplanar neighbours.
    pub markers: Vec<i32>,
}

impl TetgenInput {
    /// A PLC whose triangle `i` has marker `i + 1`.
    pub fn with_index_markers(points: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>) -> TetgenInput {
        let markers = (1..=triangles.len() as i32).collect();
        TetgenInput {
            points,
            triangles,
            markers,
        }
    }
}

pub use crate::tetgen_options::{NO_RATIO, Optimization, TetgenOptions};

impl TetgenOptions {
    pub(crate) fn check(&self) -> Result<(), TetgenError> {
        if let Some(o) = self.optimization
            && (o.level > 9 || o.scheme > 7)
        {
            return Err(TetgenError::BadOption(format!(
                "optimisation level {} (0 to 9) / scheme {} (0 to 7)",
                o.level, o.scheme
            )));
        }
        if let Some(a) = self.min_dihedral
            && !(a.is_finite() && (0.0..70.0).contains(&a))
        {
            return Err(TetgenError::BadOption(format!(
                "minimum dihedral angle {a} (degrees, from 0 to 70)"
            )));
        }
        if let Some(a) = self.max_dihedral
            && !(a.is_finite() && a > 0.0 && a < 180.0)
        {
            return Err(TetgenError::BadOption(format!(
                "maximum dihedral angle {a} (degrees, between 0 and 180)"
            )));
        }
        if let Some(q) = self.quality
            && !(q.is_finite() && q > 0.0)
        {
            return Err(TetgenError::BadOption(format!("quality ratio {q}")));
        }
        if let Some(t) = self.coplanar_tolerance
            && !(t.is_finite() && t > 0.0)
        {
            return Err(TetgenError::BadOption(format!("coplanar tolerance {t}")));
        }
        Ok(())
    }
}

/// How to run a worker process: a program (and arguments) that calls
/// [`worker::serve_stdio`](super::worker::serve_stdio), e.g. the `tet-build-worker` binary, or the
/// bench binary re-executing itself with a hidden subcommand.
#[derive(Clone, Debug, PartialEq)]
pub struct WorkerCommand {
    /// Program to start.
    pub program: PathBuf,
    /// Its arguments.
    pub args: Vec<OsString>,
    /// Wall-clock limit; the worker is killed when it is exceeded.
    pub timeout: Option<Duration>,
}

/// Where TetGen runs.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Isolation {
    /// In this process: fastest; C++ exceptions are caught, but a crash in
    /// TetGen ends the process and there is no time limit.
    #[default]
    InProcess,
    /// In a child process, killed at the time limit.
    Worker(WorkerCommand),
}

/// TetGen's output.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TetgenOutput {
    /// Points: the input points first (same indices), then Steiner points.
    pub points: Vec<[f64; 3]>,
    /// Tets (vertex ids), in TetGen's orientation convention (not ours:
    /// callers orient them, see `pipeline`).
    pub tets: Vec<[u32; 4]>,
    /// Neighbour `k` of each tet (opposite corner `k`), `-1` = none; only with `-n`.
    pub neighbors: Option<Vec<[i32; 4]>>,
    /// Subfaces: faces lying on input facets (and hull faces with `-c`).
    pub faces: Vec<[u32; 3]>,
    /// Facet marker of each face (`0` for hull faces not on a facet).
    pub face_markers: Vec<i32>,
    /// TetGen's `adjtetlist` (only with `-nn`, [`TetgenOptions::face_tets`]):
    /// the tets on the two sides of each face, `-1` = none, *as TetGen
    /// reports them*. For a face on the convex hull TetGen 1.5 may report
    /// the unset index of its internal hull tet instead of the real tet
    /// (seen as large negative or out-of-range values), so check that a
    /// listed tet has the face before using it.
    pub face_tets: Option<Vec<[i32; 2]>>,
    /// Peak resident memory (VmHWM, KiB) of the worker process, when isolated.
    pub worker_peak_kib: Option<u64>,
    /// Seconds spent inside TetGen (measured where it ran).
    pub seconds: f64,
}
