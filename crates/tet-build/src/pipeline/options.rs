//! What a build is asked to do and what it reports: [`BuildOptions`]
//! (stage choices: [`Assembly`], [`Reorder`], [`Validation`]; progress
//! callback), [`BuildReport`] with [`StageTimes`].

use std::sync::Arc;
use std::time::Duration;

use tet_core::reorder::Reordering;

use crate::bbox::BoxSpec;
use crate::clean::CleanReport;
use crate::resolve::{ResolveOptions, ResolveReport};
use crate::tetgen::{Isolation, TetgenOptions};

/// Progress callback, called at the start of every stage.
pub type ProgressFn = Arc<dyn Fn(&Progress) + Send + Sync>;

/// A stage of [`build`](super::build).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Cleaning the scene.
    Clean,
    /// Resolving self-intersections ([`BuildOptions::resolve`]).
    Resolve,
    /// Adding the enclosing box.
    EnclosingBox,
    /// Running TetGen (round 1, 2, … when rounding forces a re-run).
    Tetgen {
        /// 1-based round.
        round: u32,
    },
    /// Checking tets after rounding points to f32.
    Rounding,
    /// Matching TetGen's faces to scene triangles.
    ConstrainedFaces,
    /// Building neighbours and the constrained-face table.
    Assemble,
    /// Hilbert reordering ([`Reorder::Hilbert`] only).
    Reorder,
    /// Validating the mesh.
    Validate,
}

/// How [`build`](super::build) turns TetGen's tets into neighbour links and the
/// constrained-face table. Both give the same [`TetMesh`](tet_core::TetMesh).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Assembly {
    /// Read TetGen's own adjacency (`-nn`): the neighbour of each tet face
    /// and the two tets of each constrained face. Linear time, no sorting.
    #[default]
    TetgenNeighbors,
    /// [`TetMesh::assemble`](tet_core::TetMesh::assemble): neighbours found by sorting all face keys
    /// (the reference; ignores TetGen's adjacency).
    SortFaceKeys,
}

/// Memory order of the mesh [`build`](super::build) returns.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Reorder {
    /// TetGen's order (points: scene vertices, box corners, Steiner points).
    #[default]
    None,
    /// Points by the Hilbert key of their position, tets by that of their
    /// centroid, constrained faces by tet: the same permutations as
    /// [`tet_core::reorder::hilbert_reorder`] (Aman et al. §5), computed in
    /// parallel. The permutations are returned in [`BuildReport::reordering`].
    Hilbert,
}

/// How [`build`](super::build) checks the finished mesh. Either way, a mesh that would
/// fail [`TetMesh::validate`](tet_core::TetMesh::validate) is never returned.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Validation {
    /// Every invariant of [`TetMesh::validate`](tet_core::TetMesh::validate) except tet orientation (and
    /// the distinct-vertices check it implies), which the rounding stage has
    /// decided exactly on the final f32 coordinates of every tet (a build
    /// with a non-positive tet fails there). Linear time: links, the
    /// constrained-face table and face manifoldness (each face key in at
    /// most one linked pair or unlinked face) without a global sort.
    #[default]
    Construction,
    /// [`TetMesh::validate`](tet_core::TetMesh::validate), which also re-checks orientation (slower:
    /// sorts every face key, single-threaded).
    Full,
}

/// What [`build`](super::build) reports to the progress callback.
#[derive(Clone, Debug, PartialEq)]
pub struct Progress {
    /// The stage starting now.
    pub stage: Stage,
    /// Time since the build started.
    pub elapsed: Duration,
}

/// Options of [`build`](super::build).
#[derive(Clone)]
pub struct BuildOptions {
    /// TetGen switches (default `-pYc`: surface preserving, no quality refinement).
    pub tetgen: TetgenOptions,
    /// Where TetGen runs.
    pub isolation: Isolation,
    /// Split triangles that cross, touch in their interiors or overlap
    /// ([`crate::resolve`]) before TetGen; `None` refuses such a scene with
    /// [`BuildError::SelfIntersections`](super::BuildError::SelfIntersections)
    /// instead. A clean scene builds the same either way.
    pub resolve: Option<ResolveOptions>,
    /// Enclosing box around the scene (its faces become the mesh boundary).
    pub enclosing_box: Option<BoxSpec>,
    /// How many extra TetGen runs may be spent repairing f32 rounding.
    pub max_rounding_rounds: u32,
    /// Called at the start of each stage.
    pub progress: Option<ProgressFn>,
    /// How neighbours and constrained faces are built.
    pub assembly: Assembly,
    /// Memory order of the result.
    pub reorder: Reorder,
    /// How the result is checked.
    pub validation: Validation,
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions {
            tetgen: TetgenOptions::default(),
            isolation: Isolation::InProcess,
            resolve: Some(ResolveOptions::default()),
            enclosing_box: None,
            max_rounding_rounds: 4,
            progress: None,
            assembly: Assembly::default(),
            reorder: Reorder::default(),
            validation: Validation::default(),
        }
    }
}

impl std::fmt::Debug for BuildOptions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BuildOptions")
            .field("tetgen", &self.tetgen)
            .field("isolation", &self.isolation)
            .field("resolve", &self.resolve)
            .field("enclosing_box", &self.enclosing_box)
            .field("max_rounding_rounds", &self.max_rounding_rounds)
            .field("progress", &self.progress.as_ref().map(|_| "callback"))
            .field("assembly", &self.assembly)
            .field("reorder", &self.reorder)
            .field("validation", &self.validation)
            .finish()
    }
}

/// Wall-clock time of each stage.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StageTimes {
    /// Cleaning.
    pub clean: Duration,
    /// Resolving self-intersections (the exact check alone on a clean scene).
    pub resolve: Duration,
    /// Enclosing box.
    pub enclosing_box: Duration,
    /// TetGen, all rounds, as seen by the caller (includes the worker's
    /// start-up and pipe transfer when isolated).
    pub tetgen: Duration,
    /// TetGen, all rounds, as measured around the TetGen call itself.
    pub tetgen_inside: Duration,
    /// f32 rounding checks.
    pub rounding: Duration,
    /// Matching faces to triangles (constrained-face extraction and coverage check).
    pub constrained_faces: Duration,
    /// Neighbours and constrained-face table ([`Assembly`]).
    pub assemble: Duration,
    /// Hilbert reordering ([`Reorder::Hilbert`]).
    pub reorder: Duration,
    /// Validation ([`Validation`]).
    pub validate: Duration,
    /// The whole build.
    pub total: Duration,
}

/// What [`build`](super::build) did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BuildReport {
    /// Cleaning actions.
    pub clean: CleanReport,
    /// What resolving self-intersections did (all zero for a clean scene
    /// or with [`BuildOptions::resolve`] off).
    pub resolve: ResolveReport,
    /// Scene triangles after cleaning and resolving (= constrained faces).
    pub scene_triangles: usize,
    /// Box triangles added (0 or 12).
    pub boundary_triangles: usize,
    /// Points of the mesh.
    pub points: usize,
    /// Points TetGen added (all rounds) beyond the scene and box vertices.
    pub steiner_points: usize,
    /// Tets.
    pub tets: usize,
    /// Constrained faces.
    pub constrained_faces: usize,
    /// TetGen runs (1 unless rounding forced re-runs).
    pub tetgen_rounds: u32,
    /// Tets found flat or inverted after rounding, per TetGen round (before snapping).
    pub rounding_failures: Vec<usize>,
    /// Steiner points moved to a neighbouring f32 value to keep tets positive.
    pub snapped_points: usize,
    /// TetGen switch string.
    pub switches: String,
    /// Stage times.
    pub times: StageTimes,
    /// Peak resident memory (VmHWM, KiB) of this process since it started
    /// (not only this build), or of the worker when that is larger.
    pub peak_memory_kib: Option<u64>,
    /// The isolated worker's peak resident memory (KiB), when isolated.
    pub worker_peak_memory_kib: Option<u64>,
    /// The permutations applied by [`Reorder::Hilbert`] (`order[new] = old`,
    /// old = TetGen's order); `None` without reordering.
    pub reordering: Option<Reordering>,
}
