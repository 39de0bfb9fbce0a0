//! The format's constants: magic, version, flags, header fields and
//! section table (see the module docs of [`crate::format`]).

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
/// Flag bit: a scalar-field block (name and time steps) follows the
/// sections; the header word `scalar_steps` holds its step count.
pub const FLAG_SCALARS: u32 = 16;
pub(super) const KNOWN_FLAGS: u32 =
    FLAG_NORMALS | FLAG_UVS | FLAG_MATERIALS | FLAG_SCENE | FLAG_SCALARS;
/// Bytes of the scalar block's name slot (UTF-8, NUL-padded).
pub const SCALAR_NAME_SLOT: u64 = crate::fields::SCALAR_NAME_BYTES as u64;
/// Bytes per scene-block record.
pub const SCENE_RECORD_BYTES: u64 = 48;
/// Most records a scene block may hold (one camera and the lights).
pub const MAX_SCENE_RECORDS: u64 = 1 << 16;
/// Header fields: (name, offset, size). Used to name the field a short file cuts.
pub const HEADER_FIELDS: [(&str, usize, usize); 23] = [
    ("magic", 0, 8),
    ("version", 8, 4),
    ("flags", 12, 4),
    ("file_length", 16, 8),
    ("triangle_count", 24, 4),
    ("scalar_steps", 28, 4),
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
pub(super) const PAYLOAD_CRC_AT: usize = 168;
pub(super) const HEADER_CRC_AT: usize = 172;

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
pub(super) const ELEMENT_BYTES: [u64; 7] = [12, 16, 16, 32, 12, 8, 4];

#[cfg(test)]
mod tests {
    use glam::{Vec2, Vec3};

    use super::*;
    use crate::mesh::ConstrainedFace;

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
}
