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

pub mod ffi;
pub mod worker;

use std::ffi::{CString, OsString};
use std::path::PathBuf;
use std::time::{Duration, Instant};

use thiserror::Error;

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
}

impl Default for TetgenOptions {
    fn default() -> Self {
        TetgenOptions {
            quality: None,
            max_steiner: None,
            coplanar_tolerance: None,
            preserve_surface: true,
            keep_convex_hull: true,
            neighbors: false,
            face_tets: false,
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
        if let Some(q) = self.quality {
            s.push_str(&format!("q{q}"));
        }
        if let Some(n) = self.max_steiner {
            s.push_str(&format!("S{n}"));
        }
        if let Some(t) = self.coplanar_tolerance {
            s.push_str(&format!("T{t:e}"));
        }
        s.push_str("zQ");
        s
    }

    fn check(&self) -> Result<(), TetgenError> {
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
/// [`worker::serve_stdio`], e.g. the `tet-build-worker` binary, or the
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

/// A failure to tetrahedralize, with TetGen's meaning where TetGen reported it.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum TetgenError {
    /// The PLC has no points or no triangles.
    #[error("empty input: {points} points, {triangles} triangles")]
    EmptyInput {
        /// Number of points.
        points: usize,
        /// Number of triangles.
        triangles: usize,
    },
    /// More elements than TetGen's 32-bit indices hold.
    #[error("input too large: {what} = {count}")]
    TooLarge {
        /// What was counted.
        what: &'static str,
        /// How many.
        count: usize,
    },
    /// `markers` does not have one entry per triangle.
    #[error("{markers} markers for {triangles} triangles")]
    MarkerCount {
        /// Number of markers.
        markers: usize,
        /// Number of triangles.
        triangles: usize,
    },
    /// A point coordinate is NaN or infinite.
    #[error("point {point} has a non-finite coordinate {coords:?}")]
    NonFinitePoint {
        /// Point index.
        point: u32,
        /// Its coordinates.
        coords: [f64; 3],
    },
    /// A triangle names a point that does not exist.
    #[error("triangle {triangle}: vertex {vertex} is out of range ({points} points)")]
    VertexOutOfRange {
        /// Triangle index.
        triangle: u32,
        /// Offending vertex id.
        vertex: u32,
        /// Number of points.
        points: usize,
    },
    /// A triangle repeats a vertex id.
    #[error("triangle {triangle} repeats vertex {vertex}")]
    RepeatedVertex {
        /// Triangle index.
        triangle: u32,
        /// The repeated vertex.
        vertex: u32,
    },
    /// A triangle's three points are collinear (exact test).
    #[error("triangle {triangle} {vertices:?} is degenerate (collinear points)")]
    DegenerateTriangle {
        /// Triangle index.
        triangle: u32,
        /// Its vertices.
        vertices: [u32; 3],
    },
    /// Two triangles have the same three vertices.
    #[error("triangles {first} and {second} are the same facet {vertices:?}")]
    DuplicateTriangle {
        /// First triangle index.
        first: u32,
        /// Second triangle index.
        second: u32,
        /// Sorted vertex ids.
        vertices: [u32; 3],
    },
    /// An option value is invalid.
    #[error("invalid TetGen option: {0}")]
    BadOption(String),
    /// TetGen rejected the switch string.
    #[error("TetGen rejected the switches {0:?}")]
    BadSwitches(String),
    /// All input points are coplanar: no tetrahedron exists.
    #[error("input is flat: all points are coplanar")]
    FlatInput,
    /// TetGen code 1.
    #[error("TetGen ran out of memory (code 1)")]
    OutOfMemory,
    /// TetGen code 2: an internal inconsistency (TetGen asks for a bug report).
    #[error("TetGen internal error (code 2)")]
    Internal,
    /// TetGen code 3: input facets intersect each other.
    #[error("TetGen detected a self-intersection of the input (code 3)")]
    SelfIntersection,
    /// TetGen code 4: a feature smaller than the tolerance (`-T`).
    #[error(
        "TetGen detected a very small input feature (code 4); try a smaller coplanar tolerance"
    )]
    SmallFeature,
    /// TetGen code 5: two facets are (nearly) coincident.
    #[error("TetGen detected two very close input facets (code 5)")]
    CloseFacets,
    /// TetGen code 10: an input error (e.g. an invalid PLC).
    #[error("TetGen detected an input error (code 10)")]
    InputError,
    /// Another code from `terminatetetgen`, or an unexpected C++ exception (-4).
    #[error("TetGen stopped with code {0}")]
    Other(i32),
    /// The worker exceeded its time limit and was killed.
    #[error("TetGen worker exceeded its time limit of {seconds:.1} s and was killed")]
    Timeout {
        /// The limit.
        seconds: f64,
    },
    /// The worker died without a reply (crash, abort, signal).
    #[error("TetGen worker died: {status}; stderr tail: {stderr}")]
    WorkerDied {
        /// Exit status in words.
        status: String,
        /// Last lines of its stderr.
        stderr: String,
    },
    /// The worker could not be started or talked to.
    #[error("TetGen worker I/O: {0}")]
    WorkerIo(String),
    /// The worker's reply (or a request) is malformed.
    #[error("TetGen worker protocol: {0}")]
    Protocol(String),
}

impl TetgenError {
    /// Maps a shim status code to an error.
    pub fn from_code(code: i32, switches: &str) -> TetgenError {
        match code {
            ffi::BAD_SWITCHES => TetgenError::BadSwitches(switches.to_string()),
            ffi::FLAT_INPUT => TetgenError::FlatInput,
            1 => TetgenError::OutOfMemory,
            2 => TetgenError::Internal,
            3 => TetgenError::SelfIntersection,
            4 => TetgenError::SmallFeature,
            5 => TetgenError::CloseFacets,
            10 => TetgenError::InputError,
            c => TetgenError::Other(c),
        }
    }

    /// The status code this error travels as between worker and host (inverse
    /// of [`TetgenError::from_code`] for TetGen's own failures).
    fn code(&self) -> Option<i32> {
        Some(match self {
            TetgenError::BadSwitches(_) => ffi::BAD_SWITCHES,
            TetgenError::FlatInput => ffi::FLAT_INPUT,
            TetgenError::OutOfMemory => 1,
            TetgenError::Internal => 2,
            TetgenError::SelfIntersection => 3,
            TetgenError::SmallFeature => 4,
            TetgenError::CloseFacets => 5,
            TetgenError::InputError => 10,
            TetgenError::Other(c) => *c,
            _ => return None,
        })
    }
}

/// Checks a PLC before TetGen sees it (see the module docs).
pub fn check_input(input: &TetgenInput) -> Result<(), TetgenError> {
    let np = input.points.len();
    let nt = input.triangles.len();
    if np == 0 || nt == 0 {
        return Err(TetgenError::EmptyInput {
            points: np,
            triangles: nt,
        });
    }
    // TetGen indexes with C int; its pools need headroom.
    const LIMIT: usize = (i32::MAX / 4) as usize;
    if np > LIMIT {
        return Err(TetgenError::TooLarge {
            what: "points",
            count: np,
        });
    }
    if nt > LIMIT {
        return Err(TetgenError::TooLarge {
            what: "triangles",
            count: nt,
        });
    }
    if input.markers.len() != nt {
        return Err(TetgenError::MarkerCount {
            markers: input.markers.len(),
            triangles: nt,
        });
    }
    for (i, p) in input.points.iter().enumerate() {
        if !p.iter().all(|c| c.is_finite()) {
            return Err(TetgenError::NonFinitePoint {
                point: i as u32,
                coords: *p,
            });
        }
    }
    let mut keys: Vec<([u32; 3], u32)> = Vec::with_capacity(nt);
    for (t, tri) in input.triangles.iter().enumerate() {
        let t = t as u32;
        for (k, &v) in tri.iter().enumerate() {
            if v as usize >= np {
                return Err(TetgenError::VertexOutOfRange {
                    triangle: t,
                    vertex: v,
                    points: np,
                });
            }
            if tri[..k].contains(&v) {
                return Err(TetgenError::RepeatedVertex {
                    triangle: t,
                    vertex: v,
                });
            }
        }
        let [a, b, c] = tri.map(|v| input.points[v as usize]);
        if collinear(a, b, c) {
            return Err(TetgenError::DegenerateTriangle {
                triangle: t,
                vertices: *tri,
            });
        }
        let mut key = *tri;
        key.sort_unstable();
        keys.push((key, t));
    }
    // All points coplanar: no tetrahedron exists (TetGen itself only
    // detects an axis-aligned plane). Triangle 0 is not degenerate here.
    let [a, b, c] = input.triangles[0].map(|v| glam::DVec3::from_array(input.points[v as usize]));
    if input
        .points
        .iter()
        .all(|&p| tet_core::predicates::orient3d(a, b, c, glam::DVec3::from_array(p)) == 0.0)
    {
        return Err(TetgenError::FlatInput);
    }
    keys.sort_unstable();
    for w in keys.windows(2) {
        if w[0].0 == w[1].0 {
            return Err(TetgenError::DuplicateTriangle {
                first: w[0].1,
                second: w[1].1,
                vertices: w[0].0,
            });
        }
    }
    Ok(())
}

/// Exact collinearity: all three axis-aligned projections have zero signed area.
fn collinear(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> bool {
    let proj = |p: [f64; 3], i: usize, j: usize| robust::Coord { x: p[i], y: p[j] };
    [(0, 1), (1, 2), (2, 0)]
        .iter()
        .all(|&(i, j)| robust::orient2d(proj(a, i, j), proj(b, i, j), proj(c, i, j)) == 0.0)
}

/// Tetrahedralizes `input` where `isolation` says.
pub fn tetrahedralize(
    input: &TetgenInput,
    options: &TetgenOptions,
    isolation: &Isolation,
) -> Result<TetgenOutput, TetgenError> {
    check_input(input)?;
    options.check()?;
    match isolation {
        Isolation::InProcess => run_in_process(input, options),
        Isolation::Worker(cmd) => worker::run_worker(cmd, input, options),
    }
}

/// Runs TetGen in this process (input already checked).
pub(crate) fn run_in_process(
    input: &TetgenInput,
    options: &TetgenOptions,
) -> Result<TetgenOutput, TetgenError> {
    let switches = options.switches();
    let c_switches =
        CString::new(switches.clone()).map_err(|_| TetgenError::BadSwitches(switches.clone()))?;
    let points: Vec<f64> = input.points.iter().flatten().copied().collect();
    let triangles: Vec<i32> = input
        .triangles
        .iter()
        .flatten()
        .map(|&v| v as i32)
        .collect();
    let mut handle: *mut std::ffi::c_void = std::ptr::null_mut();
    let mut view = ffi::TetShimView::default();
    // TetGen's predicates keep global state set per run (exactinit: error
    // bounds and static filters scaled to the input's bounding box), so two
    // runs in one process must never overlap.
    let _serial = TETGEN_LOCK
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    let start = Instant::now();
    // SAFETY: the pointers reference live buffers of the lengths passed
    // (3 × points, 3 × triangles, 1 × markers — check_input guarantees
    // markers.len() == triangles.len() and that counts fit in i32); the shim
    // catches every C++ exception and only writes `handle` and `view`.
    let code = unsafe {
        ffi::tetshim_tetrahedralize(
            points.as_ptr(),
            input.points.len() as i32,
            triangles.as_ptr(),
            input.markers.as_ptr(),
            input.triangles.len() as i32,
            c_switches.as_ptr(),
            &mut handle,
            &mut view,
        )
    };
    let seconds = start.elapsed().as_secs_f64();
    if code != ffi::OK {
        return Err(TetgenError::from_code(code, &switches));
    }
    let guard = Handle(handle);
    // SAFETY: on success the view's pointers reference TetGen's output arrays
    // of the stated lengths (null when a count is 0 or the list was not
    // requested), owned by `guard` and alive until it is dropped below.
    let out = unsafe { copy_view(&view) };
    drop(guard);
    let mut out = out?;
    out.seconds = seconds;
    Ok(out)
}

/// Serializes in-process TetGen runs (see [`run_in_process`]).
static TETGEN_LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Frees TetGen's output when dropped.
struct Handle(*mut std::ffi::c_void);

impl Drop for Handle {
    fn drop(&mut self) {
        // SAFETY: the handle came from tetshim_tetrahedralize and is freed once.
        unsafe { ffi::tetshim_free(self.0) }
    }
}

/// Copies TetGen's output out of the shim's view.
///
/// # Safety
/// Every non-null pointer in `view` must reference an array of the length
/// the view states, alive for the duration of the call.
unsafe fn copy_view(view: &ffi::TetShimView) -> Result<TetgenOutput, TetgenError> {
    let count = |n: i32, what: &str| {
        usize::try_from(n).map_err(|_| TetgenError::Protocol(format!("negative {what} count {n}")))
    };
    let np = count(view.npoints, "point")?;
    let nt = count(view.ntets, "tet")?;
    let nf = count(view.nfaces, "face")?;
    // SAFETY (all slices below): guaranteed by the caller; null pointers are
    // only accepted with a zero length.
    let slice = |p: *const i32, n: usize| -> Result<&[i32], TetgenError> {
        if n == 0 {
            Ok(&[])
        } else if p.is_null() {
            Err(TetgenError::Protocol("null output list".into()))
        } else {
            Ok(unsafe { std::slice::from_raw_parts(p, n) })
        }
    };
    let pts: &[f64] = if np == 0 {
        &[]
    } else if view.points.is_null() {
        return Err(TetgenError::Protocol("null point list".into()));
    } else {
        unsafe { std::slice::from_raw_parts(view.points, 3 * np) }
    };
    let index = |v: i32| -> Result<u32, TetgenError> {
        if v >= 0 && (v as usize) < np {
            Ok(v as u32)
        } else {
            Err(TetgenError::Protocol(format!("vertex id {v} out of range")))
        }
    };
    let tets_raw = slice(view.tets, 4 * nt)?;
    let mut tets = Vec::with_capacity(nt);
    for c in tets_raw.chunks_exact(4) {
        tets.push([index(c[0])?, index(c[1])?, index(c[2])?, index(c[3])?]);
    }
    let neighbors = if view.neighbors.is_null() {
        None
    } else {
        let raw = slice(view.neighbors, 4 * nt)?;
        Some(
            raw.chunks_exact(4)
                .map(|c| [c[0], c[1], c[2], c[3]])
                .collect(),
        )
    };
    let faces_raw = slice(view.faces, 3 * nf)?;
    let mut faces = Vec::with_capacity(nf);
    for c in faces_raw.chunks_exact(3) {
        faces.push([index(c[0])?, index(c[1])?, index(c[2])?]);
    }
    let face_markers = if view.face_markers.is_null() {
        vec![0; nf]
    } else {
        slice(view.face_markers, nf)?.to_vec()
    };
    // Raw values: see `TetgenOutput::face_tets`.
    let face_tets = if view.face_tets.is_null() || nf == 0 {
        None
    } else {
        let raw = slice(view.face_tets, 2 * nf)?;
        Some(raw.chunks_exact(2).map(|c| [c[0], c[1]]).collect())
    };
    Ok(TetgenOutput {
        points: pts.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        tets,
        neighbors,
        faces,
        face_markers,
        face_tets,
        worker_peak_kib: None,
        seconds: 0.0,
    })
}
