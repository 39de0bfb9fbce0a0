//! The error type of the GPU path.

use thiserror::Error;

/// Everything that can go wrong on the GPU path; each variant names what
/// failed.
#[derive(Debug, Error)]
pub enum GpuError {
    /// No adapter (GPU or software) could be obtained.
    #[error("no wgpu adapter available: {reason}")]
    NoAdapter {
        /// What wgpu reported.
        reason: String,
    },
    /// The adapter refused to create a device.
    #[error("could not create a wgpu device on {adapter}: {reason}")]
    Device {
        /// Adapter name.
        adapter: String,
        /// What wgpu reported.
        reason: String,
    },
    /// A buffer exceeds one of the device limits.
    #[error(
        "{buffer}: {bytes} bytes exceed the device limit {limit} = {value} bytes \
         (tet records are split over at most 4 bindings, other arrays not at all)"
    )]
    TooLarge {
        /// Which buffer ("tet20 records", "points", ...).
        buffer: &'static str,
        /// Its size in bytes.
        bytes: u64,
        /// Name of the wgpu limit (`max_storage_buffer_binding_size`, ...).
        limit: &'static str,
        /// The limit's value.
        value: u64,
    },
    /// The mesh could not be encoded in the layout.
    #[error(transparent)]
    Layout(#[from] tet_core::layout::LayoutError),
    /// More elements than the kernel's 32-bit indices can address.
    #[error("{what}: {count} exceeds the GPU kernel's limit of {limit}")]
    TooMany {
        /// What was counted.
        what: &'static str,
        /// How many there are.
        count: usize,
        /// The largest supported count.
        limit: usize,
    },
    /// `rays` and `starts` of a batch differ in length.
    #[error("batch has {rays} rays but {starts} starts")]
    LengthMismatch {
        /// Number of rays.
        rays: usize,
        /// Number of starts.
        starts: usize,
    },
    /// Invalid camera set-up (start tet out of range, empty image, ...).
    #[error("camera: {detail}")]
    Camera {
        /// What is wrong.
        detail: String,
    },
    /// The mesh has no constrained faces: a BVH over its scene triangles
    /// would be empty.
    #[error("the mesh has no constrained faces (no scene triangles to build a BVH over)")]
    EmptyScene,
    /// wgpu reported a validation or out-of-memory error.
    #[error("wgpu error during {during}: {message}")]
    Wgpu {
        /// The operation.
        during: &'static str,
        /// wgpu's message.
        message: String,
    },
}
