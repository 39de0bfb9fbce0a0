//! On-disk format: exact round trips, and every kind of bad file gives the
//! typed error naming the field at fault (never a panic or a huge allocation).

use std::path::Path;

use glam::Vec3;
use proptest::prelude::*;
use tet_core::format::{
    FormatError, HEADER_FIELDS, HEADER_LEN, IN_MEMORY, MAGIC, VERSION, from_bytes, load, save,
    to_bytes,
};
use tet_core::synthetic::{GridSpec, kuhn_grid, with_attributes};
use tet_core::{MeshError, TetMesh};

fn small_mesh() -> TetMesh {
    let m = kuhn_grid(&GridSpec {
        cells: [1, 1, 2],
        constrained_fraction: 0.3,
        seed: 5,
        ..Default::default()
    });
    assert!(m.triangle_count > 0);
    with_attributes(m, 7, 3)
}

fn field(name: &str) -> (usize, usize) {
    let (_, off, size) = HEADER_FIELDS.iter().find(|f| f.0 == name).unwrap();
    (*off, *size)
}

fn put_u64(b: &mut [u8], name: &str, v: u64) {
    let (off, size) = field(name);
    assert_eq!(size, 8);
    b[off..off + 8].copy_from_slice(&v.to_le_bytes());
}

fn put_u32(b: &mut [u8], name: &str, v: u32) {
    let (off, size) = field(name);
    assert_eq!(size, 4);
    b[off..off + 4].copy_from_slice(&v.to_le_bytes());
}

fn get_u64(b: &[u8], name: &str) -> u64 {
    let (off, _) = field(name);
    u64::from_le_bytes(b[off..off + 8].try_into().unwrap())
}

/// Recomputes both CRCs (payload over 176.., header over 0..172) so a patched
/// file is rejected for the patched field, not for its checksum.
fn fix_crcs(b: &mut [u8]) {
    let payload = crc32fast::hash(&b[HEADER_LEN..]);
    b[168..172].copy_from_slice(&payload.to_le_bytes());
    let header = crc32fast::hash(&b[..172]);
    b[172..176].copy_from_slice(&header.to_le_bytes());
}

prop_compose! {
    fn grid_mesh()(
        cells in [1u32..4, 1u32..4, 1u32..4],
        jitter in 0.0f32..0.15,
        fraction in prop_oneof![Just(0.0), 0.0f64..0.6],
        shell in any::<bool>(),
        seed in any::<u64>(),
        attrs in 0u8..8,
    ) -> TetMesh {
        let m = kuhn_grid(&GridSpec {
            cells,
            jitter,
            constrained_fraction: fraction,
            shell: shell.then_some(([0, 0, 0], cells)),
            scale: 0.37,
            offset: Vec3::new(-2.0, 1e4, 0.5),
            seed,
        });
        with_attributes(m, attrs, seed)
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    #[test]
    fn bytes_round_trip_exactly(m in grid_mesh()) {
        let b = to_bytes(&m);
        prop_assert_eq!(b.len() % 8, 0);
        prop_assert_eq!(get_u64(&b, "file_length"), b.len() as u64);
        let back = from_bytes(&b).unwrap();
        prop_assert_eq!(&back, &m);
        // Bit-exact floats (PartialEq would accept -0.0 == 0.0).
        let bits = |x: &TetMesh| x.points.iter().flat_map(|p| p.to_array()).map(f32::to_bits).collect::<Vec<_>>();
        prop_assert_eq!(bits(&back), bits(&m));
        prop_assert_eq!(to_bytes(&back), b);
    }

    #[test]
    fn any_single_byte_flip_is_rejected(m in grid_mesh(), pos in any::<prop::sample::Index>(), x in 1u8..=255) {
        let mut b = to_bytes(&m);
        let i = pos.index(b.len());
        b[i] ^= x;
        prop_assert!(from_bytes(&b).is_err(), "flip at {} accepted", i);
    }
}

#[test]
fn file_round_trip_is_exact_and_atomic() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("mesh.tet");
    let m = small_mesh();
    save(&path, &m).unwrap();
    assert_eq!(load(&path).unwrap(), m);
    assert_eq!(std::fs::read(&path).unwrap(), to_bytes(&m));
    // Overwrite with another mesh: replaced whole, no temporary left behind.
    let m2 = kuhn_grid(&GridSpec::default());
    save(&path, &m2).unwrap();
    assert_eq!(load(&path).unwrap(), m2);
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("mesh.tet")]);
}

#[test]
fn io_errors_name_the_path() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nope.tet");
    let e = load(&missing).unwrap_err();
    assert!(matches!(&e, FormatError::Io { path, .. } if path == &missing));
    assert!(e.to_string().contains("nope.tet"));
    let e = save(dir.path().join("no/such/dir/m.tet"), &small_mesh()).unwrap_err();
    assert!(matches!(e, FormatError::Io { .. }));
    // A bad file on disk names its path too.
    let bad = dir.path().join("bad.tet");
    std::fs::write(&bad, b"TETMESH").unwrap();
    let e = load(&bad).unwrap_err();
    assert!(
        matches!(&e, FormatError::Truncated { path, field: "magic", .. } if path == &bad),
        "{e}"
    );
    assert!(e.to_string().contains("bad.tet"));
}

#[test]
fn truncation_at_every_byte_is_reported() {
    let b = to_bytes(&small_mesh());
    for len in 0..b.len() {
        match from_bytes(&b[..len]) {
            Err(FormatError::Truncated { actual, needed, .. }) => {
                assert_eq!(actual, len as u64);
                assert!(needed > actual);
            }
            other => panic!("length {len}: {other:?}"),
        }
    }
    // Also through a real file (streaming reader).
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.tet");
    for len in [0, 7, 100, HEADER_LEN, HEADER_LEN + 1, b.len() - 1] {
        std::fs::write(&path, &b[..len]).unwrap();
        assert!(
            matches!(load(&path), Err(FormatError::Truncated { .. })),
            "{len}"
        );
    }
}

#[test]
fn truncation_inside_the_header_names_the_field() {
    let b = to_bytes(&small_mesh());
    let mut fields: Vec<(&str, usize, usize)> = HEADER_FIELDS.to_vec();
    fields.push(("payload_crc", 168, 4));
    fields.push(("header_crc", 172, 4));
    for (name, off, size) in fields {
        for len in [off, off + size - 1] {
            match from_bytes(&b[..len]) {
                Err(FormatError::Truncated { field, path, .. }) => {
                    assert_eq!(field, name, "cut at {len}");
                    assert_eq!(path, Path::new(IN_MEMORY));
                }
                other => panic!("cut at {len}: {other:?}"),
            }
        }
    }
}

#[test]
fn wrong_magic_and_version() {
    let mut b = to_bytes(&small_mesh());
    b[0] = b'X';
    fix_crcs(&mut b);
    assert!(matches!(from_bytes(&b), Err(FormatError::BadMagic { found, .. }) if found[0] == b'X'));
    let mut b = to_bytes(&small_mesh());
    put_u32(&mut b, "version", VERSION + 1);
    fix_crcs(&mut b);
    assert!(matches!(
        from_bytes(&b),
        Err(FormatError::UnsupportedVersion { found, .. }) if found == VERSION + 1
    ));
    assert_eq!(&b[..8], &MAGIC);
}

#[test]
fn out_of_range_indices_with_valid_checksums_are_mesh_errors() {
    let mut m = small_mesh();
    m.tets[1][2] = 999;
    match from_bytes(&to_bytes(&m)) {
        Err(FormatError::InvalidMesh {
            source:
                MeshError::VertexOutOfBounds {
                    tet: 1,
                    slot: 2,
                    vertex: 999,
                    ..
                },
            ..
        }) => {}
        other => panic!("{other:?}"),
    }
    let mut m = small_mesh();
    m.neighbors[0][0] = tet_core::Link::tet(12345);
    assert!(matches!(
        from_bytes(&to_bytes(&m)),
        Err(FormatError::InvalidMesh {
            source: MeshError::NeighborOutOfBounds {
                tet: 0,
                face: 0,
                neighbor: 12345,
                ..
            },
            ..
        })
    ));
    let mut m = small_mesh();
    m.constrained[0].front.tet = 777;
    m.constrained[0].back.tet = 778;
    assert!(matches!(
        from_bytes(&to_bytes(&m)),
        Err(FormatError::InvalidMesh {
            source: MeshError::ConstrainedBackReference { index: 0, .. }
                | MeshError::ConstrainedOutOfBounds { .. },
            ..
        })
    ));
    // An attribute of the wrong length is caught by the section table.
    let mut m = small_mesh();
    m.attributes.uvs.as_mut().unwrap().pop();
    assert!(matches!(
        from_bytes(&to_bytes(&m)),
        Err(FormatError::SizeMismatch {
            field: "uvs length",
            ..
        })
    ));
}

#[test]
fn checksum_mismatches() {
    let good = to_bytes(&small_mesh());
    let mut b = good.clone();
    b[HEADER_LEN + 5] ^= 0x10; // a point coordinate
    assert!(matches!(
        from_bytes(&b),
        Err(FormatError::ChecksumMismatch {
            part: "payload",
            ..
        })
    ));
    let mut b = good.clone();
    *b.last_mut().unwrap() ^= 1; // last section or padding
    assert!(matches!(
        from_bytes(&b),
        Err(FormatError::ChecksumMismatch {
            part: "payload",
            ..
        })
    ));
    let mut b = good.clone();
    b[173] ^= 0xFF; // the header CRC itself
    assert!(matches!(
        from_bytes(&b),
        Err(FormatError::ChecksumMismatch { part: "header", .. })
    ));
    // Without a materials section nothing else checks triangle_count: only
    // the header CRC catches a change to it.
    let m = with_attributes(
        kuhn_grid(&GridSpec {
            constrained_fraction: 0.3,
            ..Default::default()
        }),
        3,
        1,
    );
    let mut b = to_bytes(&m);
    put_u32(&mut b, "triangle_count", m.triangle_count + 1000);
    let payload_crc = crc32fast::hash(&b[HEADER_LEN..]);
    b[168..172].copy_from_slice(&payload_crc.to_le_bytes());
    assert!(matches!(
        from_bytes(&b),
        Err(FormatError::ChecksumMismatch { part: "header", .. })
    ));
}

#[test]
fn huge_counts_and_offsets_fail_before_allocating() {
    let good = to_bytes(&small_mesh());
    let patched = |f: &dyn Fn(&mut Vec<u8>)| {
        let mut b = good.clone();
        f(&mut b);
        fix_crcs(&mut b);
        from_bytes(&b)
    };
    // Count far beyond the limits.
    assert!(matches!(
        patched(&|b| put_u64(b, "tet_count", u64::MAX)),
        Err(FormatError::BadField {
            field: "tet_count",
            ..
        })
    ));
    assert!(matches!(
        patched(&|b| put_u64(b, "point_count", 1 << 40)),
        Err(FormatError::BadField {
            field: "point_count",
            ..
        })
    ));
    // Count within limits but not matching the section length.
    assert!(matches!(
        patched(&|b| put_u64(b, "point_count", u32::MAX as u64)),
        Err(FormatError::SizeMismatch {
            field: "points length",
            ..
        })
    ));
    // Count and length agree, but the file is far too short: ~51 GB claimed.
    assert!(matches!(
        patched(&|b| {
            put_u64(b, "point_count", u32::MAX as u64);
            put_u64(b, "points length", u32::MAX as u64 * 12);
            put_u64(b, "normals length", u32::MAX as u64 * 12);
            put_u64(b, "uvs length", u32::MAX as u64 * 8);
        }),
        Err(FormatError::Truncated {
            field: "points",
            ..
        })
    ));
    assert!(matches!(
        patched(&|b| {
            put_u64(b, "constrained_count", (1 << 31) - 2);
            put_u64(b, "constrained length", ((1 << 31) - 2) * 32);
        }),
        Err(FormatError::Truncated {
            field: "constrained",
            ..
        })
    ));
    // Offsets that overflow or point past the end.
    assert!(matches!(
        patched(&|b| put_u64(b, "materials offset", u64::MAX - 7)),
        Err(FormatError::Truncated {
            field: "materials",
            ..
        })
    ));
    // file_length claims more than there is, or less.
    assert!(matches!(
        patched(&|b| put_u64(b, "file_length", u64::MAX)),
        Err(FormatError::Truncated { .. })
    ));
    let mut longer = good.clone();
    longer.extend_from_slice(&[0; 8]);
    fix_crcs(&mut longer);
    assert!(matches!(
        from_bytes(&longer),
        Err(FormatError::SizeMismatch {
            field: "file_length",
            ..
        })
    ));
}

#[test]
fn malformed_section_table_and_flags() {
    let good = to_bytes(&small_mesh());
    let patched = |f: &dyn Fn(&mut Vec<u8>)| {
        let mut b = good.clone();
        f(&mut b);
        fix_crcs(&mut b);
        from_bytes(&b)
    };
    let points_offset = get_u64(&good, "points offset");
    assert_eq!(points_offset, HEADER_LEN as u64);
    assert!(matches!(
        patched(&|b| put_u64(b, "points offset", points_offset + 4)),
        Err(FormatError::BadField {
            field: "points offset",
            ..
        })
    ));
    assert!(matches!(
        patched(&|b| put_u64(b, "tets offset", points_offset)),
        Err(FormatError::BadField {
            field: "tets offset",
            ..
        })
    ));
    assert!(matches!(
        patched(&|b| put_u64(b, "points offset", 0)),
        Err(FormatError::BadField {
            field: "points offset",
            ..
        })
    ));
    assert!(matches!(
        patched(&|b| put_u32(b, "flags", 1 << 7)),
        Err(FormatError::BadField { field: "flags", .. })
    ));
    assert!(matches!(
        patched(&|b| put_u32(b, "scalar_steps", 1)),
        Err(FormatError::BadField {
            field: "scalar_steps",
            ..
        })
    ));
    // Clearing a flag leaves a section the header says is absent.
    assert!(matches!(
        patched(&|b| put_u32(b, "flags", 0b011)),
        Err(FormatError::BadField {
            field: "materials offset",
            ..
        })
    ));
}

#[test]
fn absent_attributes_stay_absent_and_empty_mesh_round_trips() {
    for which in 0..8 {
        let m = with_attributes(
            kuhn_grid(&GridSpec {
                constrained_fraction: 0.2,
                ..Default::default()
            }),
            which,
            1,
        );
        let back = from_bytes(&to_bytes(&m)).unwrap();
        assert_eq!(back.attributes.normals.is_some(), which & 1 != 0);
        assert_eq!(back.attributes.uvs.is_some(), which & 2 != 0);
        assert_eq!(back.attributes.materials.is_some(), which & 4 != 0);
        assert_eq!(back, m);
    }
    let empty = TetMesh::default();
    assert_eq!(from_bytes(&to_bytes(&empty)).unwrap(), empty);
}
