//! Why a file could not be loaded or saved.

use std::io;
use std::path::PathBuf;

use thiserror::Error;

use super::spec::{MAGIC, VERSION};
use crate::error::MeshError;

/// Path used in errors from [`super::from_bytes`].
pub const IN_MEMORY: &str = "<in-memory>";

/// Why a file could not be loaded or saved. Every variant names the file
/// ([`IN_MEMORY`] for [`super::from_bytes`]).
#[derive(Debug, Error)]
pub enum FormatError {
    /// The operating system refused a read or write.
    #[error("{path}: I/O error: {source}", path = .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: io::Error,
    },
    /// The file ends before the named field or section does.
    #[error("{path}: truncated in {field}: needs {needed} bytes, file has {actual}", path = .path.display())]
    Truncated {
        /// The file.
        path: PathBuf,
        /// The header field or section cut short.
        field: &'static str,
        /// Bytes needed to hold it.
        needed: u64,
        /// Bytes in the file.
        actual: u64,
    },
    /// The file does not start with [`MAGIC`].
    #[error("{path}: bad magic {found:02x?}, expected {MAGIC:02x?} (\"TETMESH\\0\")", path = .path.display())]
    BadMagic {
        /// The file.
        path: PathBuf,
        /// The first eight bytes found.
        found: [u8; 8],
    },
    /// The version is not [`VERSION`].
    #[error("{path}: unsupported version {found} (this reader supports {VERSION})", path = .path.display())]
    UnsupportedVersion {
        /// The file.
        path: PathBuf,
        /// Version found.
        found: u32,
    },
    /// A header field has a value this version does not allow.
    #[error("{path}: header field {field}: {detail}", path = .path.display())]
    BadField {
        /// The file.
        path: PathBuf,
        /// The field.
        field: &'static str,
        /// What is wrong.
        detail: String,
    },
    /// A size recorded in the header disagrees with the counts or the file.
    #[error("{path}: {field} is {found} bytes, expected {expected}", path = .path.display())]
    SizeMismatch {
        /// The file.
        path: PathBuf,
        /// The header field or section.
        field: &'static str,
        /// Expected size.
        expected: u64,
        /// Size recorded (or found).
        found: u64,
    },
    /// A stored CRC-32 does not match the bytes.
    #[error("{path}: {part} checksum mismatch: stored {stored:#010x}, computed {computed:#010x}", path = .path.display())]
    ChecksumMismatch {
        /// The file.
        path: PathBuf,
        /// `"header"` or `"payload"`.
        part: &'static str,
        /// The CRC stored in the header.
        stored: u32,
        /// The CRC of the bytes read.
        computed: u32,
    },
    /// A scene-block record is malformed or describes an unusable camera or
    /// light.
    #[error("{path}: scene block record {record}: {detail}", path = .path.display())]
    BadScene {
        /// The file.
        path: PathBuf,
        /// Record index within the block.
        record: usize,
        /// What is wrong.
        detail: String,
    },
    /// A [`StreamWriter`](super::StreamWriter) was asked to write a section out of table order,
    /// or one the file does not have.
    #[error("{path}: cannot write section {section}: {detail}", path = .path.display())]
    SectionOrder {
        /// The file being written.
        path: PathBuf,
        /// The section.
        section: &'static str,
        /// Why not.
        detail: String,
    },
    /// A [`SectionReader`](super::SectionReader) was asked for elements the section does not
    /// have (or for a section the file does not have: `count` 0).
    #[error("{path}: elements {start}..{end} of section {section} requested, it has {count}", path = .path.display())]
    SectionRange {
        /// The file.
        path: PathBuf,
        /// The section.
        section: &'static str,
        /// First element requested.
        start: u64,
        /// One past the last element requested.
        end: u64,
        /// Elements in the section.
        count: u64,
    },
    /// The file is well formed but the mesh breaks an invariant.
    #[error("{path}: invalid mesh: {source}", path = .path.display())]
    InvalidMesh {
        /// The file.
        path: PathBuf,
        /// The violated invariant.
        source: MeshError,
    },
}
