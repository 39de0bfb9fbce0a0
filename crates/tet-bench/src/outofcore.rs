//! Building under a memory limit (Erkoç et al., seed 003): `build --predict-memory`,
//! `build --memory-limit`, and the out-of-core table of `tables`.
//!
//! The prediction is `tet_build`'s memory model
//! ([`tet_build::outofcore::memory_model::predict_peak_memory`], TetGen's
//! peak resident memory as a linear function of points + triangles of its
//! input, with a safety margin) on the cleaned scene plus the enclosing
//! box's 8 corners and 12 triangles. Over the limit, the scene is split
//! recursively by the paper's planes until every part's prediction fits
//! the limit divided by the parts run at once
//! ([`tet_build::outofcore::tree::build_tree_with_memory_limit`]), each
//! part is tetrahedralized by its own TetGen worker with exact seams and
//! the parts are merged; when no tree fits, parallel slabs are tried
//! ([`tet_build::outofcore::split::plan_slabs`]); `--planner tree|slabs`
//! forces one. The tree's planes usually cut far fewer scene triangles
//! than slabs do (the README's results give the numbers).
//!
//! **Merging.** `build` streams by default ([`MergeMode::Stream`](crate::cli::MergeMode::Stream),
//! [`Limited::to_file`]): each part goes to a part file as soon as its
//! worker returns and the part files are merged into the output a part at
//! a time, so the process never holds the whole mesh — what a build under
//! a limit is for. The price is locality: each part is
//! Hilbert-sorted on its own and the parts follow each other in the tree's
//! leaf order, instead of one curve through the whole mesh.
//! `--merge memory` ([`Limited::in_memory`]) merges in memory and sorts the
//! whole mesh; the `tables` harness uses it (it traces the mesh right
//! away, so holds it anyway). `build --tet20` reads the written file back
//! and traces it, so the trade (memory, build time, render speed) of both
//! merges and of the in-core build is measured the same way
//! ([`tet20_speed`]).

use anyhow::Result;
use tet_build::scene::Scene;
use tet_core::TetMesh;

use crate::cli::{BuildFlags, Planner};
use crate::load::BuildSummary;

#[cfg(feature = "tetgen")]
mod limited;
mod predict;
mod trace_speed;
mod types;

pub use predict::predict;
pub use trace_speed::tet20_speed;
pub use types::{Limited, MemoryReport};

/// Builds `scene` so that every TetGen run's predicted peak fits
/// `limit_bytes`, the parts merged in memory ([`Limited::in_memory`] with
/// the default planner: the paper's tree, slabs when no tree fits).
pub fn build_limited(
    scene: &Scene,
    flags: &BuildFlags,
    limit_bytes: u64,
    max_parallel: usize,
    quiet: bool,
    extra: &[glam::Vec3],
) -> Result<(TetMesh, BuildSummary, MemoryReport)> {
    Limited {
        scene,
        flags,
        limit_bytes,
        max_parallel,
        quiet,
        extra,
        planner: Planner::Auto,
    }
    .in_memory()
}

/// Without TetGen, scenes cannot be built.
#[cfg(not(feature = "tetgen"))]
impl Limited<'_> {
    /// The error of every build without TetGen.
    fn no_tetgen<T>(&self) -> Result<T> {
        anyhow::bail!(
            "`{}` is a scene, but this tet-bench was built without the `tetgen` feature",
            self.scene.name
        )
    }

    /// Fails: no TetGen.
    pub fn in_memory(&self) -> Result<(TetMesh, BuildSummary, MemoryReport)> {
        self.no_tetgen()
    }

    /// Fails: no TetGen.
    pub fn to_file(
        &self,
        _: &std::path::Path,
        _: &tet_core::scene::SceneInfo,
    ) -> Result<(types::Written, BuildSummary, MemoryReport)> {
        self.no_tetgen()
    }
}
