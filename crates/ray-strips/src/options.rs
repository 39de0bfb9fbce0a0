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
    /// swaps; chosen with the crate's `measure` example and instruction
    /// counts (valgrind) of 512² primary rays on the Stanford bunny:
    ///
    /// | chunk | strips/leaf | bytes/triangle | instructions/ray |
    /// |---|---|---|---|
    /// | 1 (plain BVH) | 1 | 90.0 | 1650 |
    /// | 16 | 1 | 33.6 | 1615 |
    /// | 64 | 1 | 28.4 | 1872 |
    /// | **128** | **1** | **26.8** | **2137** |
    /// | 256 | 1 | 25.9 | 2566 |
    /// | 64 | 4 | 22.1 | 2318 |
    /// | 128 | 4 | 21.5 | 2713 |
    ///
    /// 128 keeps most of the memory saving of larger chunks at a third more
    /// work per ray than a plain BVH (the paper's Ray-Strips took about
    /// twice the time of its BVH on the bunny, Table 3). With several strips
    /// per leaf (a deviation from the paper), `chunk_triangles: 64,
    /// strips_per_leaf: 4` is smaller (22.1 against 26.8 bytes per
    /// triangle on the bunny: within the paper's 1.5 MB) at 8 % more
    /// instructions per ray.
    fn default() -> Self {
        Self {
            chunk_triangles: 36,
            strips_per_leaf: 16,
            strip_swaps: false,
        }
    }
}
