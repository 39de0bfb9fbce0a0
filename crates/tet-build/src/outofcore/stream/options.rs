//! What a streamed build is asked ([`StreamOptions`]) and reports
//! ([`StreamSummary`]).

use std::path::PathBuf;

use tet_core::scene::SceneInfo;

/// Where and how [`build_tree_to_file`](crate::outofcore::tree::build_tree_to_file) and
/// [`crate::outofcore::seam::build_slabs_to_file`] write the merged mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct StreamOptions {
    /// The mesh file (replaced atomically when the merge is done).
    pub output: PathBuf,
    /// Camera and lights stored with the mesh (the file's scene block).
    pub scene: SceneInfo,
    /// Hilbert-sort each part on its own before writing it.
    pub sort_parts: bool,
    /// Directory in which the part files' directory is made (and removed
    /// afterwards); `None`: the output's directory.
    pub work_dir: Option<PathBuf>,
}

impl StreamOptions {
    /// Writes `output`, parts sorted, no scene block, part files next to it.
    pub fn new(output: impl Into<PathBuf>) -> StreamOptions {
        StreamOptions {
            output: output.into(),
            scene: SceneInfo::default(),
            sort_parts: true,
            work_dir: None,
        }
    }
}

/// What the streaming merge wrote and held.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StreamSummary {
    /// Points of the merged mesh.
    pub points: u64,
    /// Tets.
    pub tets: u64,
    /// Constrained faces.
    pub constrained: u64,
    /// Bytes of the mesh file.
    pub file_bytes: u64,
    /// Bytes of all part files together.
    pub part_file_bytes: u64,
    /// Points on seams (deduplicated through the seam map).
    pub seam_points: usize,
    /// Seam-only faces linked across seams.
    pub seam_faces: usize,
    /// Scene faces lying on a cut plane, merged from their two parts.
    pub seam_constrained: usize,
    /// Largest number of bytes the merge held at once: one part's arrays
    /// (or chunks of them) plus the seam maps, by vector and hash-table
    /// capacity (see the module docs).
    pub max_resident_bytes: u64,
    /// Bytes of every part's arrays together (points and their global ids,
    /// tets, neighbours, constrained faces): what a merge holding all parts
    /// would need before any map of its own.
    pub all_parts_bytes: u64,
    /// Seconds of the merge (after the last part was written).
    pub merge_s: f64,
}
