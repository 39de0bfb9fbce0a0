//! Build options.

/// How [`crate::RayStrips::build`] partitions the mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BuildOptions {
    /// The SAH stage of the high-level BVH stops splitting at groups
    /// ("chunks", paper §4.2) of at most this many triangles; each chunk is
    /// then stripified, and its strips, each with its own strip hierarchy,
    /// go into BVH leaves of up to [`BuildOptions::strips_per_leaf`]. Larger chunks allow longer strips (less memory) at
    /// the cost of a less SAH-shaped lower hierarchy. Must be at least 1.
    pub chunk_triangles: usize,
    /// High-level BVH leaves hold up to this many strips of one chunk
    /// (consecutive blocks sharing the leaf's box as the root box of their
    /// hierarchies). The paper gives every strip its own leaf (`1`); larger
    /// values save about 64 bytes per strip of top-level nodes at the cost
    /// of looser root boxes. Must be at least 1.
    pub strips_per_leaf: usize,
    /// Let strips turn through swap slots (see the stripifier's docs).
    pub strip_swaps: bool,
}

impl Default for BuildOptions {
    /// `chunk_triangles: 28`, `strips_per_leaf: 16` (every strip of a
    /// chunk in the chunk's one leaf: a 28-triangle chunk has about 5
    /// strips, rarely more than 8), no swaps. Chosen as the fastest setting
    /// within the paper's memory budget (1.5 MB for the bunny, Table 1:
    /// 21.6 bytes per triangle). Bytes from [`crate::RayStrips::bytes`];
    /// instructions per primary ray counted with valgrind (callgrind,
    /// tracing only: `--toggle-collect='*trace_all*'`) over 128² rays of
    /// the crate's `bench` example (`RES=128 RUNS=1`; single rays; the
    /// bunny framed by the `measure` example's camera, and 27 torus knots
    /// seen as in the "Torus Knots" scene):
    ///
    /// | chunk | strips/leaf | bunny strips | mean strip | bunny bytes/triangle | bunny MB | bunny instr./ray | knots instr./ray |
    /// |---|---|---|---|---|---|---|---|
    /// | 1 (plain BVH) | 1 | 69451 | 1.00 | 90.02 | 6.25 | 1379 | 5328 |
    /// | 16 | 1 | 15514 | 4.48 | 32.51 | 2.26 | 1377 | 5408 |
    /// | 36 | 1 | 11855 | 5.86 | 28.75 | 2.00 | 1504 | 5851 |
    /// | 128 | 1 | 8599 | 8.08 | 25.51 | 1.77 | 1894 | 7463 |
    /// | 64 | 16 | 10198 | 6.81 | 19.16 | 1.33 | 1809 | 7510 |
    /// | 36 | 16 | 11855 | 5.86 | 20.35 | 1.41 | 1583 | 6479 |
    /// | 32 | 16 | 12378 | 5.61 | 20.71 | 1.44 | 1541 | 6335 |
    /// | **28** | **16** | **12997** | **5.34** | **21.22** | **1.47** | **1505** | **6128** |
    /// | 24 | 16 | 13521 | 5.14 | 21.68 | 1.51 | 1476 | 5899 |
    ///
    /// Small chunks keep strips short and compact, which the strip
    /// hierarchy's one-axis splits cull well; the bytes then come from
    /// putting a chunk's strips into one leaf (two top-level nodes per
    /// chunk instead of per strip), where each strip keeps its own box in
    /// its header at no cost (see [`crate::layout`]), so that a leaf of
    /// several strips culls almost as well as one leaf per strip. One strip
    /// per leaf as in the paper needs strips of about 19 triangles to fit
    /// the budget (Stripe's 19.3 on the bunny, Table 5); with this crate's
    /// greedy stripifier `chunk_triangles: 128, strips_per_leaf: 1` is both
    /// larger (1.77 MB) and slower than the default.
    ///
    /// Against the obvhs BVH2 of `tet-bench` (`tet-bench render SCENE
    /// --method strips|obvhs --threads 2 --frames 10`, 1920 × 1440, best
    /// frame, runs alternated on a 2-core machine), see the README's
    /// Ray-Strips section for the measured ratios.
    fn default() -> Self {
        Self {
            chunk_triangles: 28,
            strips_per_leaf: 16,
            strip_swaps: false,
        }
    }
}
