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
    /// `chunk_triangles: 36`, `strips_per_leaf: 16` (every strip of a
    /// chunk in the chunk's one leaf: a 36-triangle chunk has about 4
    /// strips, rarely more than 8), no swaps. Chosen as the fastest setting
    /// within the paper's memory budget (1.5 MB for the bunny, Table 1:
    /// 21.6 bytes per triangle). Bytes from [`crate::RayStrips::bytes`];
    /// instructions per primary ray counted with valgrind (callgrind,
    /// tracing only) over 128² rays of the crate's `bench` example
    /// (single rays; the bunny framed by the `measure` example's camera,
    /// and 27 torus knots seen as in the "Torus Knots" scene):
    ///
    /// | chunk | strips/leaf | bunny strips | mean strip | bunny bytes/triangle | bunny MB | bunny instr./ray | knots instr./ray |
    /// |---|---|---|---|---|---|---|---|
    /// | 1 (plain BVH) | 1 | 69451 | 1.00 | 90.02 | 6.25 | 1333 | 4947 |
    /// | 16 | 1 | 15514 | 4.48 | 33.64 | 2.34 | 1340 | 5049 |
    /// | 64 | 1 | 10198 | 6.81 | 28.35 | 1.97 | 1572 | 5997 |
    /// | 128 | 1 | 8599 | 8.08 | 26.79 | 1.86 | 1805 | 7011 |
    /// | 256 | 1 | 7637 | 9.09 | 25.86 | 1.80 | 2202 | 8638 |
    /// | 128 | 4 | 8599 | 8.08 | 21.51 | 1.49 | 2319 | 10479 |
    /// | 64 | 5 | 10198 | 6.81 | 21.55 | 1.50 | 2088 | 9461 |
    /// | 40 | 16 | 11580 | 6.00 | 21.33 | 1.48 | 2031 | 8984 |
    /// | **36** | **16** | **11855** | **5.86** | **21.57** | **1.50** | **1963** | **8568** |
    /// | 32 | 16 | 12378 | 5.61 | 21.92 | 1.52 | 1865 | 8103 |
    ///
    /// Small chunks keep strips short and compact, which the strip
    /// hierarchy's one-axis splits cull well; the bytes then come from
    /// putting a chunk's strips into one leaf (two top-level nodes per
    /// chunk instead of per strip). One strip per leaf as in the paper
    /// needs strips of about 19 triangles to fit the budget (Stripe's 19.3
    /// on the bunny, Table 5); with this crate's greedy stripifier
    /// `chunk_triangles: 128, strips_per_leaf: 1` takes 8 % fewer instructions
    /// than the default on the bunny (18 % on the knots) but is 24 % larger.
    ///
    /// Against the obvhs BVH2 of `tet-bench` (`tet-bench render SCENE
    /// --method strips|obvhs --threads 2 --frames 5`, 1920 × 1440, best
    /// frame, runs alternated on a shared, loaded 2-core machine): the
    /// default reached 0.58 of the BVH's rays per second on the bunny and
    /// 0.49 on Torus Knots (`chunk_triangles: 128, strips_per_leaf: 1`:
    /// 0.63 and 0.55), in line with the paper, where Ray-Strips took about
    /// twice its BVH's time (Table 3).
    fn default() -> Self {
        Self {
            chunk_triangles: 36,
            strips_per_leaf: 16,
            strip_swaps: false,
        }
    }
}
