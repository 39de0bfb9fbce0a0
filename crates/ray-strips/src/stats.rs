//! What a built structure costs (bytes) and what it consists of (counts).

/// Exact heap bytes of the arrays traversal reads, split as the paper's
/// Table 1 splits them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Bytes {
    /// Global vertex list (12 bytes per referenced vertex), strip vertex
    /// indices (4 bytes each) and per-triangle words (input triangle id and
    /// vertex permutation, [`Stats::triangle_word_bits`] bits per triangle,
    /// packed into whole words per strip).
    pub geometry: usize,
    /// Strip hierarchies: one header word per strip plus its
    /// `⌊n/2⌋ − 1` nodes (two `f32` split coordinates and one flag byte each,
    /// flag bytes packed four to a word).
    pub hierarchy: usize,
    /// High-level BVH nodes (32 bytes each).
    pub top_level: usize,
    /// `geometry + hierarchy + top_level`.
    pub total: usize,
}

/// Counts describing a built structure.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stats {
    /// Triangles stored (input triangles minus skipped ones).
    pub triangles: usize,
    /// Input triangles skipped because two of their vertex indices are
    /// equal (they have no area and can never be hit).
    pub skipped_triangles: usize,
    /// Vertices referenced by stored triangles.
    pub vertices: usize,
    /// Number of triangle strips.
    pub strips: usize,
    /// Swap slots: copies of a neighbouring triangle that let a strip
    /// turn; they take a triangle's place in the strip and its hierarchy
    /// but are never tested.
    pub swap_slots: usize,
    /// `triangles / strips` (0 for an empty mesh), swap slots not counted.
    pub mean_strip_triangles: f64,
    /// Longest strip, in triangles and swap slots.
    pub max_strip_triangles: usize,
    /// Leaves of the SAH stage (groups of at most `chunk_triangles`).
    pub chunks: usize,
    /// Nodes of the high-level BVH (inner nodes and one leaf per strip).
    pub top_level_nodes: usize,
    /// Strip-hierarchy nodes over all strips.
    pub hierarchy_nodes: usize,
    /// Width of a per-triangle word ([`crate::layout::triangle_word_bits`]
    /// of the input triangle count).
    pub triangle_word_bits: u32,
}
