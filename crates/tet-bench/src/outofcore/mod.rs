//! Building under a memory limit (Erkoç et al. 2021): `build --predict-memory`,
//! `build --memory-limit`, and the out-of-core table of `tables`; the
//! options of such builds and of their jobs (`--memory-limit`,
//! `--planner`, `--merge`, `submit --mem-per-part`) are [`options`].
//!
//! The prediction is `tet_build`'s memory model
//! ([`tet_build::outofcore::memory_model::predict_peak_memory`], TetGen's
//! peak resident memory as a linear function of points + triangles of its
//! input, with a safety margin) on the cleaned scene plus the enclosing
//! box's 8 corners and 12 triangles.
//!
//! **The limit is on the whole process tree**: this process and its
//! TetGen workers together. A model of the builder's own memory (the
//! scene, its cleaned and clipped parts:
//! [`tet_build::outofcore::admission::builder_bytes`]) is set aside first;
//! each of `p` workers at once then gets a `p`-th of the rest, less this
//! process's share of its result
//! ([`tet_build::outofcore::admission::worker_share`]). While
//! the parts run, a worker starts only when this process's resident
//! memory *now* and the running parts' commitments leave room for it
//! ([`tet_build::outofcore::admission`]), and the process tree's resident
//! memory is sampled for the report (`tree_peak_kib`,
//! [`tet_build::outofcore::tree_memory`]). The in-core build is taken
//! when the whole scene's prediction fits the same share with one worker.
//!
//! Over the limit, the scene is split
//! recursively by the paper's planes until every part's prediction fits
//! its share
//! ([`tet_build::outofcore::tree::build_tree_with_memory_limit`]), each
//! part is tetrahedralized by its own TetGen worker with exact seams and
//! the parts are merged; when no tree fits, parallel slabs are tried
//! ([`tet_build::outofcore::split::plan_slabs`]); `--planner tree|slabs`
//! forces one. The tree's planes usually cut far fewer scene triangles
//! than slabs do (the README's results give the numbers).
//!
//! **Merging.** `build` streams by default ([`MergeMode::Stream`](options::MergeMode::Stream),
//! [`Limited::to_file`]): each part goes to a part file as soon as its
//! worker returns and the part files are merged into the output a part at
//! a time, so the process never holds the whole mesh — what a build under
//! a limit is for. The price is locality: each part is
//! Hilbert-sorted on its own and the parts follow each other in the tree's
//! leaf order, instead of one curve through the whole mesh.
//! `--merge memory` ([`Limited::in_memory`]) merges in memory and sorts the
//! whole mesh, which no limit on the process can bound: only the workers'
//! predictions are held to their shares then. The `tables` harness runs
//! the default (streamed) build in a process of its own and reads the file
//! back. `build --tet20` reads the written file back
//! and traces it, so the trade (memory, build time, render speed) of both
//! merges and of the in-core build is measured the same way
//! ([`tet20_speed`]).

#[cfg(not(feature = "tetgen"))]
use {crate::load::BuildSummary, anyhow::Result, tet_core::TetMesh};

#[cfg(feature = "tetgen")]
mod limited;
pub mod options;
mod predict;
mod trace_speed;
mod types;

pub use predict::predict;
pub use trace_speed::tet20_speed;
pub use types::{Limited, MemoryReport};

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
