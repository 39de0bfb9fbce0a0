//! The fixed 176-byte header: parsing with every check of
//! [`super::load`], and encoding.

use std::path::Path;

use super::error::FormatError;
use super::spec::{
    ELEMENT_BYTES, FLAG_MATERIALS, FLAG_NORMALS, FLAG_SCALARS, FLAG_SCENE, FLAG_UVS, HEADER_CRC_AT,
    HEADER_FIELDS, HEADER_LEN, KNOWN_FLAGS, MAGIC, MAX_SCENE_RECORDS, PAYLOAD_CRC_AT,
    SCALAR_NAME_SLOT, SCENE_RECORD_BYTES, SECTION_NAMES, VERSION,
};
use super::words::padding;
use crate::link::MAX_TETS;

/// Parsed and checked header.
#[derive(Clone, Copy, Debug)]
pub(super) struct Header {
    pub(super) flags: u32,
    pub(super) file_length: u64,
    pub(super) triangle_count: u32,
    /// (offset, length) per section; length 0 when absent.
    pub(super) sections: [(u64, u64); 7],
    pub(super) counts: [u64; 7],
    /// Time steps of the scalar block (0 when absent).
    pub(super) scalar_steps: u32,
    /// (offset, length) of the scalar block (name slot included); length 0
    /// when absent.
    pub(super) scalars: (u64, u64),
    /// (offset, length) of the scene block; length 0 when absent.
    pub(super) scene: (u64, u64),
    pub(super) payload_crc: u32,
}

pub(super) fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().expect("4 bytes"))
}

pub(super) fn u64_at(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().expect("8 bytes"))
}

/// Checks the header (`head` holds the file's first bytes, at most
/// [`HEADER_LEN`]) against the real file length `actual`.
pub(super) fn parse_header(head: &[u8], actual: u64, path: &Path) -> Result<Header, FormatError> {
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
    let scalar_steps = u32_at(head, 28);
    if flags & FLAG_SCALARS == 0 && scalar_steps != 0 {
        return Err(bad(
            "scalar_steps",
            format!("{scalar_steps:#x} without the scalar flag {FLAG_SCALARS:#x}, expected 0"),
        ));
    }
    if flags & FLAG_SCALARS != 0 && scalar_steps == 0 {
        return Err(bad(
            "scalar_steps",
            format!("0 with the scalar flag {FLAG_SCALARS:#x}: a field has at least one step"),
        ));
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
    let mut scalars = (0, 0);
    if present(FLAG_SCALARS) {
        let offset = end + padding(end);
        // steps < 2^32 and points < 2^32: the product fits in u128 and is
        // checked against the file before anything is allocated.
        let values = u128::from(scalar_steps) * u128::from(point_count) * 4;
        let length = u128::from(SCALAR_NAME_SLOT) + values;
        let block_end = u128::from(offset) + length;
        if block_end > u128::from(file_length) {
            return Err(FormatError::Truncated {
                path: p(),
                field: "scalars",
                needed: u64::try_from(block_end).unwrap_or(u64::MAX),
                actual,
            });
        }
        scalars = (offset, length as u64);
        end = block_end as u64;
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
        scalar_steps,
        scalars,
        scene,
        payload_crc: u32_at(head, PAYLOAD_CRC_AT),
    })
}

/// What the header records (see the module docs).
pub(super) struct HeaderFields {
    pub(super) flags: u32,
    pub(super) file_length: u64,
    pub(super) triangle_count: u32,
    /// Time steps of the scalar block (0 without one).
    pub(super) scalar_steps: u32,
    /// Points, tets, constrained faces.
    pub(super) counts: [u64; 3],
    /// (offset, length) per section, in table order.
    pub(super) table: [(u64, u64); 7],
    pub(super) payload_crc: u32,
}

/// The 176 header bytes, header CRC included.
pub(super) fn header_bytes(h: &HeaderFields) -> [u8; HEADER_LEN] {
    let mut head = [0u8; HEADER_LEN];
    head[0..8].copy_from_slice(&MAGIC);
    head[8..12].copy_from_slice(&VERSION.to_le_bytes());
    head[12..16].copy_from_slice(&h.flags.to_le_bytes());
    head[16..24].copy_from_slice(&h.file_length.to_le_bytes());
    head[24..28].copy_from_slice(&h.triangle_count.to_le_bytes());
    head[28..32].copy_from_slice(&h.scalar_steps.to_le_bytes());
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
