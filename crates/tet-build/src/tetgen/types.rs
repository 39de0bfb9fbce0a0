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

/// TetGen switches we expose (the switch string is always ours, never the caller's).
#[derive(Clone, Debug, PartialEq)]
pub struct TetgenOptions {
    /// `-q<ratio>`: refine until every tet's radius-edge ratio is at most
    /// `ratio` (TetGen's default 2.0 when `Some(2.0)`). Multiplies tets 5–9×.
    pub quality: Option<f64>,
    /// `-q<ratio>/<degrees>`: also refine tets whose smallest dihedral
    /// angle is below `degrees` (slivers). Without [`Self::quality`] the
    /// ratio bound is [`NO_RATIO`] (no radius-edge refinement).
    pub min_dihedral: Option<f64>,
    /// `-S<n>`: at most `n` Steiner points. Caps `-q` refinement, which
    /// otherwise may not terminate between near-parallel facets.
    pub max_steiner: Option<u64>,
    /// `-T<tol>`: coplanarity tolerance (TetGen's default 1e-8).
    pub coplanar_tolerance: Option<f64>,
    /// `-Y`: keep the input surface mesh (no Steiner points on facets). On by default.
    pub preserve_surface: bool,
    /// `-c`: keep the convex hull (otherwise TetGen removes tets outside the
    /// closed boundary it can find, which empties open scenes).
    pub keep_convex_hull: bool,
    /// `-n`: also output tet neighbours.
    pub neighbors: bool,
    /// `-nn`: also output, for every output face, the tets on its two sides
    /// ([`TetgenOutput::face_tets`]); implies [`TetgenOptions::neighbors`].
    pub face_tets: bool,
    /// `-O<level>/<scheme>`: TetGen's mesh optimisation after the build
    /// (flips, smoothing and vertex insertion/deletion by scheme bits 1, 2
    /// and 4; up to `2^level − 1` passes). `None` keeps TetGen's default
    /// (level 2, scheme 7), which runs on every `-p` build.
    pub optimization: Option<Optimization>,
    /// `-o/<degrees>`: the dihedral angle above which the optimisation
    /// works on a tet (TetGen's default 165°). Smaller values remove more
    /// slivers and cost more time.
    pub max_dihedral: Option<f64>,
}

/// The radius-edge bound written with [`TetgenOptions::min_dihedral`]
/// alone: large enough that no tet is refined for its ratio.
pub const NO_RATIO: f64 = 1000.0;

/// TetGen's mesh optimisation setting (`-O<level>/<scheme>`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Optimization {
    /// 0 (off) to 9: up to `2^level − 1` optimisation passes.
    pub level: u8,
    /// Bit set: 1 edge/face flips, 2 vertex smoothing, 4 vertex insertion
    /// and deletion (0 to 7).
    pub scheme: u8,
}

impl Default for TetgenOptions {
    fn default() -> Self {
        TetgenOptions {
            quality: None,
            min_dihedral: None,
            max_steiner: None,
            coplanar_tolerance: None,
            preserve_surface: true,
            keep_convex_hull: true,
            neighbors: false,
            face_tets: false,
            optimization: None,
            max_dihedral: None,
        }
    }
}

impl TetgenOptions {
    /// The TetGen switch string, e.g. `pYczQ`.
    pub fn switches(&self) -> String {
        let mut s = String::from("p");
        if self.preserve_surface {
            s.push('Y');
        }
        if self.keep_convex_hull {
            s.push('c');
        }
        if self.face_tets {
            s.push_str("nn");
        } else if self.neighbors {
            s.push('n');
        }
        match (self.quality, self.min_dihedral) {
            (Some(q), None) => s.push_str(&format!("q{q}")),
            (q, Some(a)) => s.push_str(&format!("q{}/{a}", q.unwrap_or(NO_RATIO))),
            (None, None) => {}
        }
        if let Some(n) = self.max_steiner {
            s.push_str(&format!("S{n}"));
        }
        if let Some(o) = self.optimization {
            s.push_str(&format!("O{}/{}", o.level, o.scheme));
        }
        if let Some(a) = self.max_dihedral {
            s.push_str(&format!("o/{a}"));
        }
        if let Some(t) = self.coplanar_tolerance {
            s.push_str(&format!("T{t:e}"));
        }
        s.push_str("zQ");
        s
    }

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
