//! The scalar-field block of the mesh file: exact round trips (with and
//! without a field, one or several steps, whole-file and streamed writes),
//! the byte layout against a file built by hand from the documented table,
//! files without the block (as every earlier writer produced them), and
//! corrupted or truncated files giving typed errors.

use glam::Vec3;
use tet_core::fields::{SCALAR_NAME_BYTES, ScalarField};
use tet_core::format::{
    FLAG_SCALARS, FormatError, HEADER_LEN, OptionalSections, SectionReader, StreamWriter,
    from_bytes, load, save, to_bytes, write_to,
};
use tet_core::synthetic::{GridSpec, kuhn_grid, with_attributes};
use tet_core::{Link, MeshError, TetMesh};

fn one_tet() -> TetMesh {
    let points = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
    TetMesh::assemble(points, vec![[0, 1, 2, 3]], &[], 0).unwrap()
}

fn field_mesh(steps: usize) -> TetMesh {
    let m = kuhn_grid(&GridSpec {
        cells: [2, 1, 2],
        constrained_fraction: 0.3,
        seed: 9,
        ..Default::default()
    });
    let mut m = with_attributes(m, 7, 2);
    let n = m.points.len();
    m.attributes.scalars = Some(ScalarField {
        name: "pressure".into(),
        steps: (0..steps)
            .map(|s| {
                (0..n)
                    .map(|i| match i % 4 {
                        0 => -0.0,
                        1 => 1e-30,
                        _ => (s * 100 + i) as f32 * 0.25,
                    })
                    .collect()
            })
            .collect(),
    });
    m
}

fn fix_crcs(b: &mut [u8]) {
    let payload = crc32fast::hash(&b[HEADER_LEN..]);
    b[168..172].copy_from_slice(&payload.to_le_bytes());
    let header = crc32fast::hash(&b[..172]);
    b[172..176].copy_from_slice(&header.to_le_bytes());
}

fn bits(m: &TetMesh) -> Vec<Vec<u32>> {
    let f = m.attributes.scalars.as_ref().unwrap();
    f.steps
        .iter()
        .map(|s| s.iter().map(|v| v.to_bits()).collect())
        .collect()
}

#[test]
fn round_trips_with_and_without_a_field() {
    let dir = tempfile::tempdir().unwrap();
    for steps in [1, 3] {
        let m = field_mesh(steps);
        m.validate().unwrap();
        let b = to_bytes(&m);
        let back = from_bytes(&b).unwrap();
        assert_eq!(back, m);
        assert_eq!(bits(&back), bits(&m), "-0.0 and 1e-30 survive bit for bit");
        let path = dir.path().join(format!("f{steps}.tetmesh"));
        save(&path, &m).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b, "save and to_bytes agree");
        assert_eq!(load(&path).unwrap(), m);
    }
    let mut plain = field_mesh(1);
    plain.attributes.scalars = None;
    let b = to_bytes(&plain);
    assert_eq!(
        u32::from_le_bytes(b[12..16].try_into().unwrap()) & FLAG_SCALARS,
        0
    );
    assert_eq!(u32::from_le_bytes(b[28..32].try_into().unwrap()), 0);
    let back = from_bytes(&b).unwrap();
    assert_eq!(back.attributes.scalars, None);
    assert_eq!(back, plain);
}

#[test]
fn stream_writer_writes_the_same_bytes_step_by_step() {
    let dir = tempfile::tempdir().unwrap();
    let m = field_mesh(2);
    let path = dir.path().join("s.tetmesh");
    let a = &m.attributes;
    let mut w = StreamWriter::create(&path, m.triangle_count, OptionalSections::of(a)).unwrap();
    w.append_points(&m.points).unwrap();
    w.append_tets(&m.tets).unwrap();
    w.append_neighbors(&m.neighbors).unwrap();
    w.append_constrained(&m.constrained).unwrap();
    w.append_normals(a.normals.as_ref().unwrap()).unwrap();
    w.append_uvs(a.uvs.as_ref().unwrap()).unwrap();
    w.append_materials(a.materials.as_ref().unwrap()).unwrap();
    let f = a.scalars.as_ref().unwrap();
    // A step of the wrong length or name is refused, naming the section.
    assert!(matches!(
        w.append_scalar_step(&f.name, &f.steps[0][1..]),
        Err(FormatError::SectionOrder {
            section: "scalars",
            ..
        })
    ));
    w.append_scalar_step(&f.name, &f.steps[0]).unwrap();
    assert!(matches!(
        w.append_scalar_step("other", &f.steps[1]),
        Err(FormatError::SectionOrder {
            section: "scalars",
            ..
        })
    ));
    w.append_scalar_step(&f.name, &f.steps[1]).unwrap();
    w.finish().unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), to_bytes(&m));

    let mut r = SectionReader::open(&path).unwrap();
    assert!(r.optional().scalars);
    assert_eq!(r.scalar_steps(), 2);
    assert_eq!(r.read_scalar_name().unwrap().as_deref(), Some("pressure"));
    assert_eq!(r.read_scalars(1, 2..5).unwrap(), f.steps[1][2..5].to_vec());
    assert!(matches!(
        r.read_scalars(2, 0..1),
        Err(FormatError::SectionRange { count: 2, .. })
    ));
    r.verify_payload().unwrap();

    // A file announced with a field but given no step is refused.
    let path2 = dir.path().join("none.tetmesh");
    let optional = OptionalSections {
        scalars: true,
        ..Default::default()
    };
    let w = StreamWriter::create(&path2, 0, optional).unwrap();
    assert!(matches!(
        w.finish(),
        Err(FormatError::BadField {
            field: "scalar_steps",
            ..
        })
    ));
    assert!(!path2.exists());
}

/// The bytes of `one_tet` built by hand from the table in the format docs,
/// with an optional two-step field named "t".
fn hand_built(with_field: bool) -> Vec<u8> {
    let mut b = vec![0u8; HEADER_LEN];
    let u32_at =
        |b: &mut Vec<u8>, at: usize, v: u32| b[at..at + 4].copy_from_slice(&v.to_le_bytes());
    let u64_at =
        |b: &mut Vec<u8>, at: usize, v: u64| b[at..at + 8].copy_from_slice(&v.to_le_bytes());
    b[0..8].copy_from_slice(b"TETMESH\0");
    u32_at(&mut b, 8, 1);
    u32_at(&mut b, 12, if with_field { 16 } else { 0 });
    u32_at(&mut b, 28, if with_field { 2 } else { 0 });
    u64_at(&mut b, 32, 4);
    u64_at(&mut b, 40, 1);
    // points at 176 (48 bytes), tets at 224, neighbors at 240, constrained
    // (empty) at 256.
    for (i, (off, len)) in [(176u64, 48u64), (224, 16), (240, 16), (256, 0)]
        .into_iter()
        .enumerate()
    {
        u64_at(&mut b, 56 + 16 * i, off);
        u64_at(&mut b, 64 + 16 * i, len);
    }
    for p in [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]] {
        for x in p {
            b.extend_from_slice(&x.to_le_bytes());
        }
    }
    for v in [0u32, 1, 2, 3] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for _ in 0..4 {
        b.extend_from_slice(&Link::BOUNDARY.0.to_le_bytes());
    }
    if with_field {
        let mut slot = [0u8; 64];
        slot[0] = b't';
        b.extend_from_slice(&slot);
        for v in [1.0f32, 2.0, 3.0, 4.0, -1.0, -2.0, -3.0, -4.5] {
            b.extend_from_slice(&v.to_le_bytes());
        }
    }
    let len = b.len() as u64;
    u64_at(&mut b, 16, len);
    fix_crcs(&mut b);
    b
}

#[test]
fn byte_layout_matches_a_hand_built_file() {
    // Without the block: the file every earlier (version 1) writer produced.
    let old = hand_built(false);
    assert_eq!(old.len(), 256);
    let m = one_tet();
    assert_eq!(from_bytes(&old).unwrap(), m);
    assert_eq!(to_bytes(&m), old);

    let new = hand_built(true);
    assert_eq!(new.len(), 256 + 64 + 32);
    let mut m = one_tet();
    m.attributes.scalars = Some(ScalarField {
        name: "t".into(),
        steps: vec![vec![1.0, 2.0, 3.0, 4.0], vec![-1.0, -2.0, -3.0, -4.5]],
    });
    assert_eq!(from_bytes(&new).unwrap(), m);
    assert_eq!(to_bytes(&m), new);
}

#[test]
fn corrupted_blocks_give_typed_errors() {
    let good = hand_built(true);
    let value_at = 256 + 64; // step 0, point 0
    // Any truncation is an error, never a panic.
    for len in 0..good.len() {
        assert!(from_bytes(&good[..len]).is_err(), "truncated at {len}");
    }
    // A flipped value byte breaks the payload CRC.
    let mut b = good.clone();
    b[value_at + 4 * 5] ^= 0x40;
    assert!(matches!(
        from_bytes(&b),
        Err(FormatError::ChecksumMismatch {
            part: "payload",
            ..
        })
    ));
    // A NaN with valid CRCs names the step and the point.
    let mut b = good.clone();
    b[value_at + 4 * 6..value_at + 4 * 7].copy_from_slice(&f32::NAN.to_le_bytes());
    fix_crcs(&mut b);
    assert!(matches!(
        from_bytes(&b),
        Err(FormatError::InvalidMesh {
            source: MeshError::ScalarNotFinite {
                step: 1,
                point: 2,
                ..
            },
            ..
        })
    ));
    // A huge step count fails on the header, before anything is allocated.
    let mut b = good.clone();
    b[28..32].copy_from_slice(&u32::MAX.to_le_bytes());
    fix_crcs(&mut b);
    assert!(matches!(
        from_bytes(&b),
        Err(FormatError::Truncated {
            field: "scalars",
            ..
        })
    ));
    // The flag without steps, steps without the flag.
    let mut b = good.clone();
    b[28..32].copy_from_slice(&0u32.to_le_bytes());
    fix_crcs(&mut b);
    assert!(matches!(
        from_bytes(&b),
        Err(FormatError::BadField {
            field: "scalar_steps",
            ..
        })
    ));
    let mut b = hand_built(false);
    b[28..32].copy_from_slice(&1u32.to_le_bytes());
    fix_crcs(&mut b);
    assert!(matches!(
        from_bytes(&b),
        Err(FormatError::BadField {
            field: "scalar_steps",
            ..
        })
    ));
    // A name slot with bytes after its NUL, or not UTF-8.
    for (at, byte) in [(256 + 10, b'x'), (256, 0xff)] {
        let mut b = good.clone();
        b[at] = byte;
        fix_crcs(&mut b);
        assert!(
            matches!(
                from_bytes(&b),
                Err(FormatError::BadField {
                    field: "scalars name",
                    ..
                })
            ),
            "byte {at}"
        );
    }
    // One step fewer than the header says: the block runs past the file.
    let mut b = good.clone();
    b[28..32].copy_from_slice(&3u32.to_le_bytes());
    fix_crcs(&mut b);
    assert!(matches!(
        from_bytes(&b),
        Err(FormatError::Truncated {
            field: "scalars",
            ..
        })
    ));
}

#[test]
fn unwritable_fields_are_refused_not_written_wrong() {
    let mut m = one_tet();
    m.attributes.scalars = Some(ScalarField::single(
        "n".repeat(SCALAR_NAME_BYTES + 1),
        vec![0.0; 4],
    ));
    let err = write_to(&m, &mut Vec::new()).unwrap_err();
    assert_eq!(err.kind(), std::io::ErrorKind::InvalidInput);
    m.attributes.scalars = Some(ScalarField::single("n", vec![0.0; 3]));
    assert!(write_to(&m, &mut Vec::new()).is_err());
    assert!(matches!(
        m.validate(),
        Err(MeshError::ScalarLength {
            step: 0,
            actual: 3,
            expected: 4
        })
    ));
    let dir = tempfile::tempdir().unwrap();
    assert!(matches!(
        save(dir.path().join("x"), &m),
        Err(FormatError::SectionOrder {
            section: "scalars",
            ..
        })
    ));
}

#[test]
fn memory_counts_the_field_only_when_present() {
    let mut m = one_tet();
    let before = m.attributes.bytes();
    m.attributes.scalars = Some(ScalarField {
        name: "abc".into(),
        steps: vec![vec![0.0; 4]; 3],
    });
    assert_eq!(m.attributes.bytes(), before + 3 * 4 * 4 + 3);
    let report = tet_core::memory::MemoryReport::for_mesh(&m);
    assert_eq!(report.get("tet20").unwrap().attributes, 3 * 4 * 4 + 3);
}
