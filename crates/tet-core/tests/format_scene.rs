//! The optional scene block (camera + point lights) of the mesh format:
//! exact round trips, files without it unchanged, and every malformed block
//! rejected with a typed error naming the record.

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::format::{
    FLAG_SCENE, FormatError, HEADER_LEN, SCENE_RECORD_BYTES, from_bytes, from_bytes_with_scene,
    load_with_scene, save_with_scene, to_bytes, to_bytes_with_scene,
};
use tet_core::scene::{Camera, PointLight, SceneInfo};
use tet_core::synthetic::{GridSpec, kuhn_grid};

fn mesh() -> TetMesh {
    kuhn_grid(&GridSpec {
        cells: [2, 1, 1],
        constrained_fraction: 0.4,
        seed: 11,
        ..Default::default()
    })
}

fn scene() -> SceneInfo {
    SceneInfo {
        camera: Some(Camera {
            position: Vec3::new(9.483198, 9.588511, 14.769205),
            target: Vec3::new(0.0, -0.0, 1e-30),
            up: Vec3::Y,
            vfov_deg: 45.0,
        }),
        lights: vec![
            PointLight {
                position: Vec3::new(6.0, 10.0, 8.0),
                color: Vec3::ONE,
                intensity: 1.0,
            },
            PointLight {
                position: Vec3::new(-1e20, 3.5, f32::MIN_POSITIVE),
                color: Vec3::new(0.25, 0.0, 2.0),
                intensity: 0.0,
            },
        ],
    }
}

/// Recomputes both CRCs so a patched file is rejected for the patch.
fn fix_crcs(b: &mut [u8]) {
    let payload = crc32fast::hash(&b[HEADER_LEN..]);
    b[168..172].copy_from_slice(&payload.to_le_bytes());
    let header = crc32fast::hash(&b[..172]);
    b[172..176].copy_from_slice(&header.to_le_bytes());
}

fn flags(b: &[u8]) -> u32 {
    u32::from_le_bytes(b[12..16].try_into().unwrap())
}

#[test]
fn scene_round_trips_bit_for_bit() {
    let (m, s) = (mesh(), scene());
    let bytes = to_bytes_with_scene(&m, &s);
    assert_ne!(flags(&bytes) & FLAG_SCENE, 0);
    let (m2, s2) = from_bytes_with_scene(&bytes).unwrap();
    assert_eq!(m2, m);
    assert_eq!(s2, s);
    // -0.0 and tiny values survive as bits, not just as equal floats.
    assert_eq!(s2.camera.unwrap().target.y.to_bits(), (-0.0f32).to_bits());
    // The plain reader accepts the file and returns the same mesh.
    assert_eq!(from_bytes(&bytes).unwrap(), m);
    // Lights only, camera only.
    for s in [
        SceneInfo {
            camera: None,
            lights: scene().lights,
        },
        SceneInfo {
            camera: scene().camera,
            lights: Vec::new(),
        },
    ] {
        assert_eq!(
            from_bytes_with_scene(&to_bytes_with_scene(&m, &s))
                .unwrap()
                .1,
            s
        );
    }
}

#[test]
fn empty_scene_writes_the_plain_file() {
    let m = mesh();
    let plain = to_bytes(&m);
    assert_eq!(to_bytes_with_scene(&m, &SceneInfo::default()), plain);
    assert_eq!(flags(&plain) & FLAG_SCENE, 0);
    let (_, s) = from_bytes_with_scene(&plain).unwrap();
    assert!(s.is_empty());
    // The block adds exactly one record per camera/light.
    let with = to_bytes_with_scene(&m, &scene());
    assert_eq!(
        with.len() as u64,
        plain.len() as u64 + 3 * SCENE_RECORD_BYTES
    );
}

#[test]
fn save_and_load_with_scene() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.tmesh");
    save_with_scene(&path, &mesh(), &scene()).unwrap();
    let (m, s) = load_with_scene(&path).unwrap();
    assert_eq!(m, mesh());
    assert_eq!(s, scene());
}

/// Index of the first byte of scene record `r` in `b`.
fn record_at(b: &[u8], records: usize, r: usize) -> usize {
    b.len() - (records - r) * SCENE_RECORD_BYTES as usize
}

fn patched(edit: impl FnOnce(&mut Vec<u8>)) -> Result<(TetMesh, SceneInfo), FormatError> {
    let mut b = to_bytes_with_scene(&mesh(), &scene());
    edit(&mut b);
    fix_crcs(&mut b);
    from_bytes_with_scene(&b)
}

fn put_word(b: &mut [u8], record: usize, word: usize, v: u32) {
    let at = record_at(b, 3, record) + 4 * word;
    b[at..at + 4].copy_from_slice(&v.to_le_bytes());
}

fn expect_bad_scene(r: Result<(TetMesh, SceneInfo), FormatError>, record: usize, needle: &str) {
    match r {
        Err(FormatError::BadScene {
            record: got,
            detail,
            ..
        }) => {
            assert_eq!(got, record, "{detail}");
            assert!(detail.contains(needle), "{detail:?} lacks {needle:?}");
        }
        other => panic!("expected BadScene in record {record} ({needle}), got {other:?}"),
    }
}

#[test]
fn malformed_records_are_named() {
    expect_bad_scene(patched(|b| put_word(b, 1, 0, 7)), 1, "unknown kind 7");
    expect_bad_scene(patched(|b| put_word(b, 2, 0, 1)), 2, "second camera");
    expect_bad_scene(patched(|b| put_word(b, 1, 11, 1)), 1, "unused word 11");
    expect_bad_scene(patched(|b| put_word(b, 0, 11, 1)), 0, "unused word 11");
    expect_bad_scene(
        patched(|b| put_word(b, 0, 2, f32::NAN.to_bits())),
        0,
        "non-finite",
    );
    // Up parallel to the view direction.
    expect_bad_scene(
        patched(|b| {
            let dir = Vec3::new(-9.483198, -9.588511, -14.769205);
            for (k, c) in [dir.x, dir.y, dir.z].into_iter().enumerate() {
                put_word(b, 0, 7 + k, c.to_bits());
            }
            put_word(b, 0, 4, 0);
            put_word(b, 0, 5, 0);
            put_word(b, 0, 6, 0);
        }),
        0,
        "up vector",
    );
    expect_bad_scene(
        patched(|b| put_word(b, 0, 10, 180f32.to_bits())),
        0,
        "field of view",
    );
    expect_bad_scene(
        patched(|b| put_word(b, 2, 7, (-1f32).to_bits())),
        2,
        "negative",
    );
    expect_bad_scene(
        patched(|b| put_word(b, 1, 2, f32::INFINITY.to_bits())),
        1,
        "non-finite",
    );
}

#[test]
fn block_size_and_checksum_are_checked() {
    let good = to_bytes_with_scene(&mesh(), &scene());
    // A block that is not a whole number of records.
    let mut b = good.clone();
    b.truncate(b.len() - 4);
    let len = b.len() as u64;
    b[16..24].copy_from_slice(&len.to_le_bytes());
    fix_crcs(&mut b);
    match from_bytes_with_scene(&b) {
        Err(FormatError::BadField { field, detail, .. }) => {
            assert_eq!(field, "file_length");
            assert!(detail.contains("scene block"), "{detail}");
        }
        other => panic!("{other:?}"),
    }
    // The flag without a block.
    let mut b = to_bytes(&mesh());
    let f = flags(&b) | FLAG_SCENE;
    b[12..16].copy_from_slice(&f.to_le_bytes());
    fix_crcs(&mut b);
    assert!(matches!(
        from_bytes_with_scene(&b),
        Err(FormatError::BadField {
            field: "file_length",
            ..
        })
    ));
    // A flipped bit in the block is caught by the payload checksum.
    let mut b = good.clone();
    let at = record_at(&b, 3, 1) + 5;
    b[at] ^= 0x04;
    assert!(matches!(
        from_bytes_with_scene(&b),
        Err(FormatError::ChecksumMismatch {
            part: "payload",
            ..
        })
    ));
    // Cutting the file anywhere in the block is a typed error, never a panic.
    for cut in (good.len() - 3 * SCENE_RECORD_BYTES as usize)..good.len() {
        assert!(from_bytes_with_scene(&good[..cut]).is_err(), "cut at {cut}");
    }
}
