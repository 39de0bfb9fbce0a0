//! On-disk format of a built [`TetMesh`] (every compact layout is derived
//! from it at load time).
//!
//! # Layout, byte by byte (version 1)
//!
//! All integers and floats are little-endian. The file is a fixed 176-byte
//! header followed by the sections, each starting at an 8-byte-aligned offset
//! and padded with zero bytes up to the next one.
//!
//! | offset | size | field | meaning |
//! |-------:|-----:|-------|---------|
//! | 0   | 8 | `magic`             | the bytes `TETMESH\0` |
//! | 8   | 4 | `version`           | `1` ([`VERSION`]) |
//! | 12  | 4 | `flags`             | bit 0: normals present, bit 1: uvs, bit 2: materials, bit 3: scene block; other bits 0 |
//! | 16  | 8 | `file_length`       | total file size in bytes, header included |
//! | 24  | 4 | `triangle_count`    | [`TetMesh::triangle_count`] |
//! | 28  | 4 | `reserved`          | 0 |
//! | 32  | 8 | `point_count`       | number of points (≤ 2³²−1) |
//! | 40  | 8 | `tet_count`         | number of tets (< 2³¹−1) |
//! | 48  | 8 | `constrained_count` | number of constrained faces (< 2³¹−1) |
//! | 56  | 112 | section table     | 7 × (`offset: u64`, `length: u64`), in this order: points, tets, neighbors, constrained, normals, uvs, materials |
//! | 168 | 4 | `payload_crc`       | CRC-32 (IEEE, as `crc32fast`) of bytes `176..file_length` |
//! | 172 | 4 | `header_crc`        | CRC-32 of bytes `0..172` |
//!
//! Sections (element type, bytes per element, element count):
//!
//! | section | element | bytes | count |
//! |---------|---------|------:|-------|
//! | points      | `[f32; 3]` x, y, z                                   | 12 | `point_count` |
//! | tets        | `[u32; 4]` vertex ids                                | 16 | `tet_count` |
//! | neighbors   | `[u32; 4]` [`crate::Link`] per face                  | 16 | `tet_count` |
//! | constrained | `triangle: u32, vertices: [u32; 3], front: (tet u32, face u32), back: (tet u32, face u32)` ([`crate::ConstrainedFace`]) | 32 | `constrained_count` |
//! | normals     | `[f32; 3]`                                           | 12 | `point_count` (if flag bit 0) |
//! | uvs         | `[f32; 2]`                                           | 8  | `point_count` (if flag bit 1) |
//! | materials   | `u32`                                                | 4  | `triangle_count` (if flag bit 2) |
//!
//! The **scene block** (flag bit 3; see [`SceneInfo`]) has no table entry:
//! it starts at the first 8-byte boundary after the last present section and
//! runs to `file_length`, as 48-byte records of twelve 4-byte words — word 0
//! the kind, words 1–11 `f32`s, unused words 0:
//!
//! | kind | record | words 1–11 |
//! |-----:|--------|------------|
//! | 1 | camera (at most one) | position xyz, target xyz, up xyz, vertical FOV in degrees, 0 |
//! | 2 | point light | position xyz, colour rgb, intensity, 0, 0, 0, 0 |
//!
//! A file without the flag is byte for byte what earlier writers produced;
//! a reader older than the flag rejects a file with it by naming the unknown
//! flag bit, never by misreading it.
//!
//! An absent optional section has offset 0 and length 0. A present section
//! has `length = count × bytes`, an offset that is a multiple of 8, not below
//! the end of the previous present section (or the header), and ends within
//! `file_length`. [`to_bytes`] writes the sections back to back in table
//! order with minimal padding.
//!
//! # Loading
//!
//! [`load`] / [`from_bytes`] check, in order: the magic, the version, that the
//! whole header is present (a short file names the header field it cuts),
//! reserved bits and flags, `file_length` against the real length, the counts
//! against their limits, and every section's offset and length against the
//! counts and the file length — so every allocation is bounded by the real
//! file size and no unchecked header field ever sizes one; then the header
//! CRC. Only then are the sections read, each straight into a typed `Vec`
//! (`bytemuck::cast_slice_mut` on the `Vec`'s own storage: one `read` or
//! `memcpy` per section, no intermediate buffer, no per-element parsing —
//! a little-endian host needs no conversion; a big-endian one swaps each
//! 4-byte word in place), the payload CRC compared, and
//! [`TetMesh::validate`] run. Errors are [`FormatError`]s naming the file and
//! the field or section at fault.
//!
//! [`save`] writes to a temporary file in the target's directory, syncs it
//! and renames it over the target, so a reader never sees a partial file.
//!
//! # Streaming
//!
//! A mesh larger than memory is written and read a piece at a time:
//!
//! * [`StreamWriter`] appends element slices to the sections in table order
//!   (points, tets, neighbors, constrained, then the optional ones),
//!   hashing the payload as it goes; [`StreamWriter::finish`] writes the
//!   header last (counts and section table from what was written) and
//!   renames the temporary file into place. A writer dropped unfinished
//!   removes its temporary file and leaves the target untouched. For the
//!   same mesh the file is byte for byte what [`save`] writes ([`save`] is a
//!   [`StreamWriter`] given whole sections).
//! * [`SectionReader`] opens a file with the header checks of [`load`]
//!   (against the real file length), then reads any range of one section
//!   without reading the rest; [`SectionReader::verify_payload`] checks the
//!   payload CRC in one streaming pass of bounded memory. Element *values*
//!   (vertex ids, links) are not checked: a caller indexing with them checks
//!   them ([`load`] runs [`TetMesh::validate`] on the whole mesh instead).

use std::fs::File;
use std::io::{self, BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use bytemuck::Pod;
use crc32fast::Hasher;
use glam::{Vec2, Vec3};
use thiserror::Error;

use crate::error::MeshError;
use crate::link::{Link, MAX_TETS};
use crate::mesh::{Attributes, ConstrainedFace, TetMesh};
use crate::scene::{Camera, PointLight, SceneInfo, SceneInfoError};

mod section_reader;
mod stream_writer;

pub use section_reader::SectionReader;
pub use stream_writer::{OptionalSections, StreamWriter};

/// The first eight bytes of every file.
pub const MAGIC: [u8; 8] = *b"TETMESH\0";
/// The format version this code reads and writes.
pub const VERSION: u32 = 1;
/// Size of the fixed header in bytes.
pub const HEADER_LEN: usize = 176;
/// Flag bit: a normals section is present.
pub const FLAG_NORMALS: u32 = 1;
/// Flag bit: a uvs section is present.
pub const FLAG_UVS: u32 = 2;
/// Flag bit: a materials section is present.
pub const FLAG_MATERIALS: u32 = 4;
/// Flag bit: a scene block (camera and lights) ends the file.
pub const FLAG_SCENE: u32 = 8;
const KNOWN_FLAGS: u32 = FLAG_NORMALS | FLAG_UVS | FLAG_MATERIALS | FLAG_SCENE;
/// Bytes per scene-block record.
pub const SCENE_RECORD_BYTES: u64 = 48;
/// Most records a scene block may hold (one camera and the lights).
pub const MAX_SCENE_RECORDS: u64 = 1 << 16;
const SCENE_CAMERA: u32 = 1;
const SCENE_LIGHT: u32 = 2;

/// Path used in errors from [`from_bytes`].
pub const IN_MEMORY: &str = "<in-memory>";

/// Header fields: (name, offset, size). Used to name the field a short file cuts.
pub const HEADER_FIELDS: [(&str, usize, usize); 23] = [
    ("magic", 0, 8),
    ("version", 8, 4),
    ("flags", 12, 4),
    ("file_length", 16, 8),
    ("triangle_count", 24, 4),
    ("reserved", 28, 4),
    ("point_count", 32, 8),
    ("tet_count", 40, 8),
    ("constrained_count", 48, 8),
    ("points offset", 56, 8),
    ("points length", 64, 8),
    ("tets offset", 72, 8),
    ("tets length", 80, 8),
    ("neighbors offset", 88, 8),
    ("neighbors length", 96, 8),
    ("constrained offset", 104, 8),
    ("constrained length", 112, 8),
    ("normals offset", 120, 8),
    ("normals length", 128, 8),
    ("uvs offset", 136, 8),
    ("uvs length", 144, 8),
    ("materials offset", 152, 8),
    ("materials length", 160, 8),
];
const PAYLOAD_CRC_AT: usize = 168;
const HEADER_CRC_AT: usize = 172;

/// Section names in table order.
pub const SECTION_NAMES: [&str; 7] = [
    "points",
    "tets",
    "neighbors",
    "constrained",
    "normals",
    "uvs",
    "materials",
];
const ELEMENT_BYTES: [u64; 7] = [12, 16, 16, 32, 12, 8, 4];

/// Why a file could not be loaded or saved. Every variant names the file
/// ([`IN_MEMORY`] for [`from_bytes`]).
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
    /// A [`StreamWriter`] was asked to write a section out of table order,
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
    /// A [`SectionReader`] was asked for elements the section does not
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

/// Parsed and checked header.
#[derive(Clone, Copy, Debug)]
struct Header {
    flags: u32,
    file_length: u64,
    triangle_count: u32,
    /// (offset, length) per section; length 0 when absent.
    sections: [(u64, u64); 7],
    counts: [u64; 7],
    /// (offset, length) of the scene block; length 0 when absent.
    scene: (u64, u64),
    payload_crc: u32,
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().expect("4 bytes"))
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().expect("8 bytes"))
}

/// Checks the header (`head` holds the file's first bytes, at most
/// [`HEADER_LEN`]) against the real file length `actual`.
fn parse_header(head: &[u8], actual: u64, path: &Path) -> Result<Header, FormatError> {
    let p = || path.to_path_buf();
    let truncated_at = |len: usize| {
        let (field, off, size) = HEADER_FIELDS
            .iter()
            .copied()
            .chain([
                ("payload_crc", PAYLOAD_CRC_AT, 4),
                ("header_crc", HEADER_CRC_AT, 4),
            ])
            .find(|&(_, off, size)| off + size > len)
            .expect("len < HEADER_LEN");
        FormatError::Truncated {
            path: p(),
            field,
            needed: (off + size) as u64,
            actual,
        }
    };
    if head.len() < 8 {
        return Err(truncated_at(head.len()));
    }
    let found: [u8; 8] = head[..8].try_into().expect("8 bytes");
    if found != MAGIC {
        return Err(FormatError::BadMagic { path: p(), found });
    }
    if head.len() < 12 {
        return Err(truncated_at(head.len()));
    }
    let version = u32_at(head, 8);
    if version != VERSION {
        return Err(FormatError::UnsupportedVersion {
            path: p(),
            found: version,
        });
    }
    if head.len() < HEADER_LEN {
        return Err(truncated_at(head.len()));
    }
    let bad = |field: &'static str, detail: String| FormatError::BadField {
        path: p(),
        field,
        detail,
    };
    let flags = u32_at(head, 12);
    if flags & !KNOWN_FLAGS != 0 {
        return Err(bad(
            "flags",
            format!("unknown bits {:#x}", flags & !KNOWN_FLAGS),
        ));
    }
    let reserved = u32_at(head, 28);
    if reserved != 0 {
        return Err(bad("reserved", format!("{reserved:#x}, expected 0")));
    }
    let file_length = u64_at(head, 16);
    if actual < file_length {
        return Err(FormatError::Truncated {
            path: p(),
            field: "payload (file_length)",
            needed: file_length,
            actual,
        });
    }
    if actual > file_length {
        return Err(FormatError::SizeMismatch {
            path: p(),
            field: "file_length",
            expected: actual,
            found: file_length,
        });
    }
    let triangle_count = u32_at(head, 24);
    let point_count = u64_at(head, 32);
    let tet_count = u64_at(head, 40);
    let constrained_count = u64_at(head, 48);
    for (field, count, limit) in [
        ("point_count", point_count, u64::from(u32::MAX)),
        ("tet_count", tet_count, u64::from(MAX_TETS) - 1),
        (
            "constrained_count",
            constrained_count,
            u64::from(MAX_TETS) - 1,
        ),
    ] {
        if count > limit {
            return Err(bad(field, format!("{count} exceeds the limit {limit}")));
        }
    }
    let present = |bit: u32| flags & bit != 0;
    let counts = [
        point_count,
        tet_count,
        tet_count,
        constrained_count,
        if present(FLAG_NORMALS) {
            point_count
        } else {
            0
        },
        if present(FLAG_UVS) { point_count } else { 0 },
        if present(FLAG_MATERIALS) {
            u64::from(triangle_count)
        } else {
            0
        },
    ];
    let is_present = [
        true,
        true,
        true,
        true,
        present(FLAG_NORMALS),
        present(FLAG_UVS),
        present(FLAG_MATERIALS),
    ];
    let mut sections = [(0u64, 0u64); 7];
    let mut end = HEADER_LEN as u64;
    for i in 0..7 {
        let (off_name, _, _) = HEADER_FIELDS[9 + 2 * i];
        let (len_name, _, _) = HEADER_FIELDS[10 + 2 * i];
        let offset = u64_at(head, 56 + 16 * i);
        let length = u64_at(head, 64 + 16 * i);
        if !is_present[i] {
            if offset != 0 || length != 0 {
                return Err(bad(
                    off_name,
                    format!(
                        "section {} is absent (flags {flags:#x}) but has offset {offset}, length {length}",
                        SECTION_NAMES[i]
                    ),
                ));
            }
            continue;
        }
        // counts are bounded by 2^32, element sizes by 32: no overflow.
        let expected = counts[i] * ELEMENT_BYTES[i];
        if length != expected {
            return Err(FormatError::SizeMismatch {
                path: p(),
                field: len_name,
                expected,
                found: length,
            });
        }
        if !offset.is_multiple_of(8) {
            return Err(bad(off_name, format!("{offset} is not a multiple of 8")));
        }
        if offset < end {
            return Err(bad(
                off_name,
                format!("{offset} overlaps the header or the previous section (ends at {end})"),
            ));
        }
        let section_end = offset.saturating_add(length);
        if section_end > file_length {
            return Err(FormatError::Truncated {
                path: p(),
                field: SECTION_NAMES[i],
                needed: section_end,
                actual,
            });
        }
        sections[i] = (offset, length);
        end = section_end;
    }
    let mut scene = (0, 0);
    if present(FLAG_SCENE) {
        let offset = end + padding(end);
        let length = file_length.saturating_sub(offset);
        let records = length / SCENE_RECORD_BYTES;
        if length == 0 || !length.is_multiple_of(SCENE_RECORD_BYTES) || records > MAX_SCENE_RECORDS
        {
            return Err(bad(
                "file_length",
                format!(
                    "the scene block (flag {FLAG_SCENE:#x}) from offset {offset} to the end is \
                     {length} bytes: not 1..={MAX_SCENE_RECORDS} records of {SCENE_RECORD_BYTES}"
                ),
            ));
        }
        scene = (offset, length);
    }
    let stored = u32_at(head, HEADER_CRC_AT);
    let computed = crc32fast::hash(&head[..HEADER_CRC_AT]);
    if stored != computed {
        return Err(FormatError::ChecksumMismatch {
            path: p(),
            part: "header",
            stored,
            computed,
        });
    }
    Ok(Header {
        flags,
        file_length,
        triangle_count,
        sections,
        counts,
        scene,
        payload_crc: u32_at(head, PAYLOAD_CRC_AT),
    })
}

/// A sequential byte source positioned just after the header.
trait Source {
    fn read_exact_into(&mut self, buf: &mut [u8]) -> io::Result<()>;
}

impl Source for &[u8] {
    fn read_exact_into(&mut self, buf: &mut [u8]) -> io::Result<()> {
        Read::read_exact(self, buf)
    }
}

struct FileSource(BufReader<File>);

impl Source for FileSource {
    fn read_exact_into(&mut self, buf: &mut [u8]) -> io::Result<()> {
        self.0.read_exact(buf)
    }
}

/// Reads the payload section by section into typed vectors, hashing every
/// byte (padding included) in file order.
struct PayloadReader<'a, S: Source> {
    src: S,
    pos: u64,
    crc: Hasher,
    path: &'a Path,
}

impl<S: Source> PayloadReader<'_, S> {
    fn io(&self, source: io::Error) -> FormatError {
        FormatError::Io {
            path: self.path.to_path_buf(),
            source,
        }
    }

    /// Consumes (and hashes) bytes up to absolute offset `to`.
    fn skip_to(&mut self, to: u64) -> Result<(), FormatError> {
        let mut buf = [0u8; 4096];
        while self.pos < to {
            let n = (to - self.pos).min(buf.len() as u64) as usize;
            self.src
                .read_exact_into(&mut buf[..n])
                .map_err(|e| self.io(e))?;
            self.crc.update(&buf[..n]);
            self.pos += n as u64;
        }
        Ok(())
    }

    /// Reads `count` elements at absolute offset `offset` straight into a
    /// `Vec<T>`. `count × size_of::<T>()` was checked against the file length.
    fn section<T: Pod>(&mut self, (offset, length): (u64, u64)) -> Result<Vec<T>, FormatError> {
        self.skip_to(offset)?;
        let count = (length / size_of::<T>() as u64) as usize;
        let mut v = vec![T::zeroed(); count];
        let bytes: &mut [u8] = bytemuck::cast_slice_mut(&mut v);
        self.src.read_exact_into(bytes).map_err(|e| self.io(e))?;
        self.crc.update(bytes);
        self.pos += length;
        from_le_words(bytes);
        Ok(v)
    }
}

/// The file stores little-endian 4-byte words; every element type here is
/// made of 4-byte words, so on a big-endian host each word is swapped.
#[cfg(target_endian = "big")]
fn from_le_words(bytes: &mut [u8]) {
    for w in bytes.chunks_exact_mut(4) {
        w.reverse();
    }
}

#[cfg(target_endian = "little")]
fn from_le_words(_bytes: &mut [u8]) {}

fn decode<S: Source>(
    src: S,
    header: Header,
    path: &Path,
) -> Result<(TetMesh, SceneInfo), FormatError> {
    let mut r = PayloadReader {
        src,
        pos: HEADER_LEN as u64,
        crc: Hasher::new(),
        path,
    };
    let s = header.sections;
    let points: Vec<Vec3> = r.section(s[0])?;
    let tets: Vec<[u32; 4]> = r.section(s[1])?;
    let neighbors: Vec<[Link; 4]> = r.section(s[2])?;
    let constrained: Vec<ConstrainedFace> = r.section(s[3])?;
    let present = |bit| header.flags & bit != 0;
    let normals: Option<Vec<Vec3>> = if present(FLAG_NORMALS) {
        Some(r.section(s[4])?)
    } else {
        None
    };
    let uvs: Option<Vec<Vec2>> = if present(FLAG_UVS) {
        Some(r.section(s[5])?)
    } else {
        None
    };
    let materials: Option<Vec<u32>> = if present(FLAG_MATERIALS) {
        Some(r.section(s[6])?)
    } else {
        None
    };
    let scene_records: Vec<[u32; 12]> = if present(FLAG_SCENE) {
        r.section(header.scene)?
    } else {
        Vec::new()
    };
    r.skip_to(header.file_length)?;
    let computed = r.crc.finalize();
    if computed != header.payload_crc {
        return Err(FormatError::ChecksumMismatch {
            path: path.to_path_buf(),
            part: "payload",
            stored: header.payload_crc,
            computed,
        });
    }
    debug_assert_eq!(points.len() as u64, header.counts[0]);
    let mesh = TetMesh {
        points,
        tets,
        neighbors,
        constrained,
        triangle_count: header.triangle_count,
        attributes: Attributes {
            normals,
            uvs,
            materials,
        },
    };
    let scene = decode_scene(&scene_records, path)?;
    mesh.validate().map_err(|source| FormatError::InvalidMesh {
        path: path.to_path_buf(),
        source,
    })?;
    Ok((mesh, scene))
}

/// Parses and checks the scene block's records.
fn decode_scene(records: &[[u32; 12]], path: &Path) -> Result<SceneInfo, FormatError> {
    let bad = |record: usize, detail: String| FormatError::BadScene {
        path: path.to_path_buf(),
        record,
        detail,
    };
    let mut scene = SceneInfo::default();
    for (i, rec) in records.iter().enumerate() {
        let f = |k: usize| f32::from_bits(rec[k]);
        let v = |k: usize| Vec3::new(f(k), f(k + 1), f(k + 2));
        let (used, single) = match rec[0] {
            SCENE_CAMERA => {
                if scene.camera.is_some() {
                    return Err(bad(i, "a second camera".into()));
                }
                let camera = Camera {
                    position: v(1),
                    target: v(4),
                    up: v(7),
                    vfov_deg: f(10),
                };
                scene.camera = Some(camera);
                (
                    11,
                    SceneInfo {
                        camera: Some(camera),
                        lights: Vec::new(),
                    },
                )
            }
            SCENE_LIGHT => {
                let light = PointLight {
                    position: v(1),
                    color: v(4),
                    intensity: f(7),
                };
                scene.lights.push(light);
                (
                    8,
                    SceneInfo {
                        camera: None,
                        lights: vec![light],
                    },
                )
            }
            kind => return Err(bad(i, format!("unknown kind {kind}"))),
        };
        if let Some(k) = (used..12).find(|&k| rec[k] != 0) {
            return Err(bad(
                i,
                format!("unused word {k} is {:#x}, expected 0", rec[k]),
            ));
        }
        // The record is checked alone, so a light error names "light 0":
        // the record index above is the position that matters.
        single
            .validate()
            .map_err(|e: SceneInfoError| bad(i, e.to_string().replace("light 0", "light")))?;
    }
    Ok(scene)
}

/// Encodes `scene` as scene-block records (camera first, then lights).
fn scene_records(scene: &SceneInfo) -> Vec<[u32; 12]> {
    let mut out = Vec::with_capacity(scene.lights.len() + 1);
    let put = |kind: u32, words: &[f32]| {
        let mut rec = [0u32; 12];
        rec[0] = kind;
        for (k, w) in words.iter().enumerate() {
            rec[1 + k] = w.to_bits();
        }
        rec
    };
    if let Some(c) = &scene.camera {
        let (p, t, u) = (c.position, c.target, c.up);
        out.push(put(
            SCENE_CAMERA,
            &[p.x, p.y, p.z, t.x, t.y, t.z, u.x, u.y, u.z, c.vfov_deg],
        ));
    }
    for l in &scene.lights {
        let (p, c) = (l.position, l.color);
        out.push(put(
            SCENE_LIGHT,
            &[p.x, p.y, p.z, c.x, c.y, c.z, l.intensity],
        ));
    }
    out
}

/// Decodes a mesh from an in-memory file image (checks as in [`load`];
/// errors name [`IN_MEMORY`] as the path). A scene block, if any, is checked
/// and dropped; [`from_bytes_with_scene`] returns it.
pub fn from_bytes(bytes: &[u8]) -> Result<TetMesh, FormatError> {
    from_bytes_with_scene(bytes).map(|(mesh, _)| mesh)
}

/// [`from_bytes`], also returning the scene block (empty when absent).
pub fn from_bytes_with_scene(bytes: &[u8]) -> Result<(TetMesh, SceneInfo), FormatError> {
    let path = Path::new(IN_MEMORY);
    let head = &bytes[..bytes.len().min(HEADER_LEN)];
    let header = parse_header(head, bytes.len() as u64, path)?;
    decode(&bytes[HEADER_LEN..], header, path)
}

/// Loads a mesh saved by [`save`]: header checks against the real file size,
/// sections read straight into typed vectors, CRCs, then [`TetMesh::validate`].
/// A scene block, if any, is checked and dropped; [`load_with_scene`]
/// returns it.
pub fn load(path: impl AsRef<Path>) -> Result<TetMesh, FormatError> {
    load_with_scene(path).map(|(mesh, _)| mesh)
}

/// [`load`], also returning the scene block (empty when absent).
pub fn load_with_scene(path: impl AsRef<Path>) -> Result<(TetMesh, SceneInfo), FormatError> {
    let path = path.as_ref();
    let (file, header) = SectionReader::open(path)?.into_parts();
    decode(
        FileSource(BufReader::with_capacity(1 << 16, file)),
        header,
        path,
    )
}

fn padding(len: u64) -> u64 {
    (8 - len % 8) % 8
}

/// The sections of `mesh` in table order (`None` when absent), as raw bytes.
fn section_bytes(mesh: &TetMesh) -> [Option<&[u8]>; 7] {
    let a = &mesh.attributes;
    [
        Some(bytemuck::cast_slice(&mesh.points)),
        Some(bytemuck::cast_slice(&mesh.tets)),
        Some(bytemuck::cast_slice(&mesh.neighbors)),
        Some(bytemuck::cast_slice(&mesh.constrained)),
        a.normals.as_deref().map(bytemuck::cast_slice),
        a.uvs.as_deref().map(bytemuck::cast_slice),
        a.materials.as_deref().map(bytemuck::cast_slice),
    ]
}

/// Writes 4-byte words as little-endian (a plain copy on little-endian hosts).
fn write_le_words(w: &mut impl Write, bytes: &[u8]) -> io::Result<()> {
    if cfg!(target_endian = "little") {
        w.write_all(bytes)
    } else {
        for word in bytes.chunks_exact(4) {
            w.write_all(&[word[3], word[2], word[1], word[0]])?;
        }
        Ok(())
    }
}

/// Hashes 4-byte words as their little-endian encoding.
fn hash_le_words(h: &mut Hasher, bytes: &[u8]) {
    if cfg!(target_endian = "little") {
        h.update(bytes);
    } else {
        for word in bytes.chunks_exact(4) {
            h.update(&[word[3], word[2], word[1], word[0]]);
        }
    }
}

/// What the header records (see the module docs).
struct HeaderFields {
    flags: u32,
    file_length: u64,
    triangle_count: u32,
    /// Points, tets, constrained faces.
    counts: [u64; 3],
    /// (offset, length) per section, in table order.
    table: [(u64, u64); 7],
    payload_crc: u32,
}

/// The 176 header bytes, header CRC included.
fn header_bytes(h: &HeaderFields) -> [u8; HEADER_LEN] {
    let mut head = [0u8; HEADER_LEN];
    head[0..8].copy_from_slice(&MAGIC);
    head[8..12].copy_from_slice(&VERSION.to_le_bytes());
    head[12..16].copy_from_slice(&h.flags.to_le_bytes());
    head[16..24].copy_from_slice(&h.file_length.to_le_bytes());
    head[24..28].copy_from_slice(&h.triangle_count.to_le_bytes());
    for (i, count) in h.counts.iter().enumerate() {
        head[32 + 8 * i..40 + 8 * i].copy_from_slice(&count.to_le_bytes());
    }
    for (i, (off, len)) in h.table.iter().enumerate() {
        head[56 + 16 * i..64 + 16 * i].copy_from_slice(&off.to_le_bytes());
        head[64 + 16 * i..72 + 16 * i].copy_from_slice(&len.to_le_bytes());
    }
    head[PAYLOAD_CRC_AT..PAYLOAD_CRC_AT + 4].copy_from_slice(&h.payload_crc.to_le_bytes());
    let hcrc = crc32fast::hash(&head[..HEADER_CRC_AT]);
    head[HEADER_CRC_AT..HEADER_LEN].copy_from_slice(&hcrc.to_le_bytes());
    head
}

/// Serialises `mesh` into `w` (header first, then the sections).
///
/// The mesh is not validated: an invalid mesh is written as is and rejected
/// by [`load`] with [`FormatError::InvalidMesh`] (or a size mismatch when an
/// attribute array has the wrong length).
pub fn write_to(mesh: &TetMesh, w: &mut impl Write) -> io::Result<()> {
    write_to_with_scene(mesh, &SceneInfo::default(), w)
}

/// [`write_to`] followed by a scene block holding `scene` (none when it is
/// empty). The scene is not validated here either.
pub fn write_to_with_scene(
    mesh: &TetMesh,
    scene: &SceneInfo,
    w: &mut impl Write,
) -> io::Result<()> {
    let sections = section_bytes(mesh);
    let records = scene_records(scene);
    let mut flags = if records.is_empty() { 0 } else { FLAG_SCENE };
    for (bit, s) in [
        (FLAG_NORMALS, sections[4]),
        (FLAG_UVS, sections[5]),
        (FLAG_MATERIALS, sections[6]),
    ] {
        if s.is_some() {
            flags |= bit;
        }
    }
    let mut table = [(0u64, 0u64); 7];
    let mut crc = Hasher::new();
    let mut end = HEADER_LEN as u64;
    for (i, s) in sections.iter().enumerate() {
        if let Some(bytes) = s {
            let len = bytes.len() as u64;
            table[i] = (end, len);
            hash_le_words(&mut crc, bytes);
            crc.update(&[0u8; 8][..padding(len) as usize]);
            end += len + padding(len);
        }
    }
    let scene_bytes: &[u8] = bytemuck::cast_slice(&records);
    hash_le_words(&mut crc, scene_bytes);
    end += scene_bytes.len() as u64;
    let head = header_bytes(&HeaderFields {
        flags,
        file_length: end,
        triangle_count: mesh.triangle_count,
        counts: [
            mesh.points.len() as u64,
            mesh.tets.len() as u64,
            mesh.constrained.len() as u64,
        ],
        table,
        payload_crc: crc.finalize(),
    });
    w.write_all(&head)?;
    for bytes in sections.into_iter().flatten() {
        write_le_words(w, bytes)?;
        w.write_all(&[0u8; 8][..padding(bytes.len() as u64) as usize])?;
    }
    write_le_words(w, scene_bytes)
}

/// Serialises `mesh` into a new byte vector (see [`write_to`]).
pub fn to_bytes(mesh: &TetMesh) -> Vec<u8> {
    to_bytes_with_scene(mesh, &SceneInfo::default())
}

/// Serialises `mesh` and `scene` into a new byte vector (see
/// [`write_to_with_scene`]).
pub fn to_bytes_with_scene(mesh: &TetMesh, scene: &SceneInfo) -> Vec<u8> {
    let mut out = Vec::new();
    write_to_with_scene(mesh, scene, &mut out).expect("writing to a Vec cannot fail");
    out
}

/// Saves `mesh` to `path` atomically: the bytes go to a fresh temporary file
/// in the same directory, which is synced and then renamed over `path`.
/// On error the temporary file is removed and `path` is untouched.
pub fn save(path: impl AsRef<Path>, mesh: &TetMesh) -> Result<(), FormatError> {
    save_with_scene(path, mesh, &SceneInfo::default())
}

/// [`save`] with a scene block holding `scene` (none when it is empty), so
/// the file remembers the camera and lights of the scene it was built from.
///
/// The sections go through a [`StreamWriter`], which checks on the way that
/// attribute arrays have their section's length
/// ([`FormatError::SizeMismatch`]); nothing else is validated.
pub fn save_with_scene(
    path: impl AsRef<Path>,
    mesh: &TetMesh,
    scene: &SceneInfo,
) -> Result<(), FormatError> {
    let a = &mesh.attributes;
    let mut w = StreamWriter::create(
        path,
        mesh.triangle_count,
        OptionalSections::of(&mesh.attributes),
    )?;
    w.append_points(&mesh.points)?;
    w.append_tets(&mesh.tets)?;
    w.append_neighbors(&mesh.neighbors)?;
    w.append_constrained(&mesh.constrained)?;
    if let Some(n) = &a.normals {
        w.append_normals(n)?;
    }
    if let Some(u) = &a.uvs {
        w.append_uvs(u)?;
    }
    if let Some(m) = &a.materials {
        w.append_materials(m)?;
    }
    w.finish_with_scene(scene).map(|_| ())
}

/// A fresh temporary path in `path`'s directory, named after it (so that
/// renaming it over `path` is atomic: same file system).
fn temp_path(path: &Path) -> Result<PathBuf, FormatError> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path.file_name().ok_or_else(|| FormatError::Io {
        path: path.to_path_buf(),
        source: io::Error::new(io::ErrorKind::InvalidInput, "path has no file name"),
    })?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    Ok(dir.join(format!(
        ".{}.tmp-{}-{}",
        name.to_string_lossy(),
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_field_table_is_contiguous() {
        let mut at = 0;
        for (name, off, size) in HEADER_FIELDS {
            assert_eq!(off, at, "{name}");
            at += size;
        }
        assert_eq!(at, PAYLOAD_CRC_AT);
        assert_eq!(HEADER_CRC_AT + 4, HEADER_LEN);
        assert_eq!(ELEMENT_BYTES[3] as usize, size_of::<ConstrainedFace>());
        assert_eq!(size_of::<Vec3>(), 12);
        assert_eq!(size_of::<Vec2>(), 8);
    }

    #[test]
    fn empty_mesh_round_trips() {
        let m = TetMesh::default();
        let b = to_bytes(&m);
        assert_eq!(b.len(), HEADER_LEN);
        assert_eq!(from_bytes(&b).unwrap(), m);
    }
}
