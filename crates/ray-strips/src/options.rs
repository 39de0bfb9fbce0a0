//! Build options.

/// How [`crate::RayStrips::build`] partitions the mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BuildOptions {
    /// The SAH stage of the high-level BVH stops splitting at groups
    /// ("chunks", paper §4.2) of at most this many triangles; each chunk is
    /// then stripified and every strip becomes one BVH leaf with its own
    /// strip hierarchy. Larger chunks allow longer strips (less memory) at
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
    /// `chunk_triangles: 128`, one strip per leaf as in the paper, no
    /// swaps; chosen with the crate's `measure` example on a 70 k-triangle
    /// bumpy sphere and the Stanford bunny: chunks of 16–128 trace fastest
    /// (within the noise of the shared measuring machine), and 128 is the
    /// most compact of them (bunny 26.8 B/triangle against 28.4 at 64;
    /// 256 saves another 0.9 B/triangle but traced 10–40 % slower).
    /// `strips_per_leaf: 4` brings the bunny to 21.5 B/triangle (1.49 MB);
    /// its speed ranged from equal to 30 % slower over the runs.
    fn default() -> Self {
        Self {
            chunk_triangles: 128,
            strips_per_leaf: 1,
            strip_swaps: false,
        }
    }
}
