//! On-disk format of a built [`TetMesh`](crate::TetMesh) (every compact layout is derived
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
//! | 12  | 4 | `flags`             | bit 0: normals present, bit 1: uvs, bit 2: materials, bit 3: scene block, bit 4: scalar block; other bits 0 |
//! | 16  | 8 | `file_length`       | total file size in bytes, header included |
//! | 24  | 4 | `triangle_count`    | [`TetMesh::triangle_count`](crate::TetMesh::triangle_count) |
//! | 28  | 4 | `scalar_steps`      | time steps of the scalar block (≥ 1) with flag bit 4; 0 without it (the word was a reserved 0 before the block existed) |
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
//! The **scalar block** (flag bit 4; a [`ScalarField`](crate::fields::ScalarField)
//! in [`crate::Attributes::scalars`]) has no table entry either: it starts
//! at the first 8-byte boundary after the last present section and is
//!
//! | part | bytes | content |
//! |------|------:|---------|
//! | name   | 64 ([`SCALAR_NAME_SLOT`]) | the field's name, UTF-8, padded with NUL bytes (plain bytes, not words) |
//! | values | `scalar_steps × point_count × 4` | `f32`, step by step, one per point in point order |
//!
//! padded with zeros to the next 8-byte boundary. Its size follows from the
//! header alone (`scalar_steps`, `point_count`), so it is checked against
//! `file_length` before anything is allocated; the payload CRC covers it.
//! Why no table entry: the table is part of the fixed 176-byte header, and
//! a new entry would change the header's size and every offset after it
//! (a version 2); the block, sized by a header word that version 1 kept
//! reserved at 0, leaves files without a field byte for byte as before (a
//! version-1 file loads unchanged), and a reader older than the block
//! rejects a file with it by naming the unknown flag bit, never by
//! misreading it.
//!
//! The **scene block** (flag bit 3; see [`SceneInfo`](crate::scene::SceneInfo)) has no table entry:
//! it starts at the first 8-byte boundary after the last present section (or
//! after the scalar block when there is one) and runs to `file_length`, as 48-byte records of twelve 4-byte words — word 0
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
//! [`TetMesh::validate`](crate::TetMesh::validate) run. Errors are [`FormatError`]s naming the file and
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
//!   (points, tets, neighbors, constrained, then the optional ones, then
//!   the scalar field a step at a time: [`StreamWriter::append_scalar_step`]),
//!   hashing the payload as it goes; [`StreamWriter::finish`] writes the
//!   header last (counts and section table from what was written) and
//!   renames the temporary file into place. A writer dropped unfinished
//!   removes its temporary file and leaves the target untouched. For the
//!   same mesh the file is byte for byte what [`save`] writes ([`save`] is a
//!   [`StreamWriter`] given whole sections).
//! * [`SectionReader`] opens a file with the header checks of [`load`]
//!   (against the real file length), then reads any range of one section
//!   without reading the rest; [`SectionReader::verify_payload`] checks the
//!   payload CRC in one streaming pass of bounded memory;
//!   [`SectionReader::read_scalars`] reads a range of one time step. Element *values*
//!   (vertex ids, links) are not checked: a caller indexing with them checks
//!   them ([`load`] runs [`TetMesh::validate`](crate::TetMesh::validate) on the whole mesh instead).

//!
//! # Modules
//!
//! * `spec`: the constants (magic, version, flags, header fields);
//! * `header`: the 176-byte header (parse with every check, encode);
//! * `error`: [`FormatError`];
//! * `words`: byte order and padding of the payload;
//! * `scene_block`: the camera and light records; `scalar_block`: the
//!   scalar field's name slot;
//! * `read` / `write`: whole meshes ([`load`], [`save`], …);
//! * [`StreamWriter`] / [`SectionReader`]: a piece at a time.

mod error;
mod header;
mod read;
mod scalar_block;
mod scene_block;
mod section_reader;
mod spec;
mod stream_writer;
mod words;
mod write;

pub use error::{FormatError, IN_MEMORY};
pub use read::{from_bytes, from_bytes_with_scene, load, load_with_scene};
pub use section_reader::SectionReader;
pub use spec::{
    FLAG_MATERIALS, FLAG_NORMALS, FLAG_SCALARS, FLAG_SCENE, FLAG_UVS, HEADER_FIELDS, HEADER_LEN,
    MAGIC, MAX_SCENE_RECORDS, SCALAR_NAME_SLOT, SCENE_RECORD_BYTES, SECTION_NAMES, VERSION,
};
pub use stream_writer::{OptionalSections, StreamWriter};
pub use write::{
    save, save_with_scene, to_bytes, to_bytes_with_scene, write_to, write_to_with_scene,
};
