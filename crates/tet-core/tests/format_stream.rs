//! Streaming writer and section reader of the mesh format: a file written a
//! slice at a time is byte for byte the one `to_bytes`/`save` write; any
//! range of any section reads back as the mesh's; out-of-order writes,
//! unfinished writers, short and corrupt files give typed errors.

use std::path::Path;

use glam::Vec3;
use proptest::prelude::*;
use tet_core::TetMesh;
use tet_core::format::{
    FormatError, HEADER_LEN, OptionalSections, SectionReader, StreamWriter, load_with_scene,
    to_bytes, to_bytes_with_scene,
};
use tet_core::scene::{Camera, PointLight, SceneInfo};
use tet_core::synthetic::{GridSpec, kuhn_grid, with_attributes};

/// A grid mesh with the attributes `which` (bit 0 normals, 1 uvs, 2 materials).
fn mesh_with(cells: [u32; 3], which: u8, seed: u64) -> TetMesh {
    let m = kuhn_grid(&GridSpec {
        cells,
        jitter: 0.1,
        constrained_fraction: 0.4,
        seed,
        ..Default::default()
    });
    with_attributes(m, which, seed)
}

fn scene() -> SceneInfo {
    SceneInfo {
        camera: Some(Camera {
            position: Vec3::new(3.0, 4.0, 5.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            vfov_deg: 40.0,
        }),
        lights: vec![PointLight {
            position: Vec3::new(1.0, 9.0, 2.0),
            color: Vec3::ONE,
            intensity: 2.0,
        }],
    }
}

/// Appends `items` in chunks: the sizes `chunks` (0 = an empty append)
/// over and over while they make progress, then the rest at once.
fn in_chunks<T>(items: &[T], chunks: &[usize], mut f: impl FnMut(&[T]) -> Result<(), FormatError>) {
    let mut at = 0;
    if chunks.iter().any(|&c| c > 0) {
        for &c in chunks.iter().cycle() {
            if at + c > items.len() {
                break;
            }
            f(&items[at..at + c]).unwrap();
            at += c;
        }
    } else {
        for _ in chunks {
            f(&[]).unwrap();
        }
    }
    f(&items[at..]).unwrap();
}

/// Streams `m` (and `scene`) into `path`, every section in chunks.
fn stream(path: &Path, m: &TetMesh, scene: &SceneInfo, chunks: &[usize]) -> u64 {
    let mut w =
        StreamWriter::create(path, m.triangle_count, OptionalSections::of(&m.attributes)).unwrap();
    in_chunks(&m.points, chunks, |s| w.append_points(s));
    in_chunks(&m.tets, chunks, |s| w.append_tets(s));
    in_chunks(&m.neighbors, chunks, |s| w.append_neighbors(s));
    in_chunks(&m.constrained, chunks, |s| w.append_constrained(s));
    let a = &m.attributes;
    if let Some(n) = &a.normals {
        in_chunks(n, chunks, |s| w.append_normals(s));
    }
    if let Some(u) = &a.uvs {
        in_chunks(u, chunks, |s| w.append_uvs(s));
    }
    if let Some(mat) = &a.materials {
        in_chunks(mat, chunks, |s| w.append_materials(s));
    }
    assert_eq!(w.points_written(), m.points.len() as u64);
    assert_eq!(w.tets_written(), m.tets.len() as u64);
    assert_eq!(w.constrained_written(), m.constrained.len() as u64);
    w.finish_with_scene(scene).unwrap()
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Any chunking of any mesh (attributes or not, scene block or not)
    /// gives the bytes of `to_bytes`, and every range of every section
    /// reads back as the mesh's.
    #[test]
    fn streamed_files_equal_saved_ones_and_read_back_by_range(
        cells in [1u32..3, 1u32..3, 1u32..3],
        which in 0u8..8,
        seed in any::<u64>(),
        with_scene in any::<bool>(),
        chunks in prop::collection::vec(0usize..40, 1..4),
        cut in 0.0f64..1.0,
    ) {
        let m = mesh_with(cells, which, seed);
        let sc = if with_scene { scene() } else { SceneInfo::default() };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.tmesh");
        let len = stream(&path, &m, &sc, &chunks);
        let bytes = std::fs::read(&path).unwrap();
        prop_assert_eq!(len, bytes.len() as u64);
        prop_assert!(bytes == to_bytes_with_scene(&m, &sc), "streamed bytes differ");
        prop_assert_eq!(files_in(dir.path()), vec!["m.tmesh".to_string()]);
        let (back, back_scene) = load_with_scene(&path).unwrap();
        prop_assert_eq!(&back, &m);
        prop_assert_eq!(&back_scene, &sc);

        let mut r = SectionReader::open(&path).unwrap();
        r.verify_payload().unwrap();
        prop_assert_eq!(r.point_count(), m.points.len() as u64);
        prop_assert_eq!(r.tet_count(), m.tets.len() as u64);
        prop_assert_eq!(r.constrained_count(), m.constrained.len() as u64);
        prop_assert_eq!(r.triangle_count(), m.triangle_count);
        prop_assert_eq!(r.optional(), OptionalSections::of(&m.attributes));
        prop_assert_eq!(r.file_length(), len);
        prop_assert_eq!(r.read_scene().unwrap(), sc);
        let range = |n: usize| {
            let a = (n as f64 * cut) as usize;
            (a as u64..n as u64, a..n)
        };
        let (fr, sl) = range(m.points.len());
        prop_assert_eq!(&r.read_points(fr).unwrap()[..], &m.points[sl]);
        let (fr, sl) = range(m.tets.len());
        prop_assert_eq!(&r.read_tets(fr.clone()).unwrap()[..], &m.tets[sl.clone()]);
        prop_assert_eq!(&r.read_neighbors(fr).unwrap()[..], &m.neighbors[sl]);
        let (fr, sl) = range(m.constrained.len());
        prop_assert_eq!(&r.read_constrained(fr).unwrap()[..], &m.constrained[sl]);
        let a = &m.attributes;
        let (fr, sl) = range(m.points.len());
        match &a.normals {
            Some(n) => prop_assert_eq!(&r.read_normals(fr.clone()).unwrap()[..], &n[sl.clone()]),
            None => {
                let empty = r.read_normals(0..0).unwrap();
                prop_assert!(empty.is_empty());
                let absent = matches!(
                    r.read_normals(0..1),
                    Err(FormatError::SectionRange { count: 0, .. })
                );
                prop_assert!(absent, "reading absent normals");
            }
        }
        if let Some(u) = &a.uvs {
            prop_assert_eq!(&r.read_uvs(fr).unwrap()[..], &u[sl]);
        }
        if let Some(mat) = &a.materials {
            let (fr, sl) = range(mat.len());
            prop_assert_eq!(&r.read_materials(fr).unwrap()[..], &mat[sl]);
        }
    }
}

#[test]
fn an_empty_mesh_streams_to_the_bare_header() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("e.tmesh");
    let m = TetMesh::default();
    let w = StreamWriter::create(&path, 0, OptionalSections::default()).unwrap();
    assert_eq!(w.finish().unwrap(), HEADER_LEN as u64);
    assert_eq!(std::fs::read(&path).unwrap(), to_bytes(&m));
}

#[test]
fn sections_out_of_order_or_absent_are_refused_and_nothing_is_left() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("o.tmesh");
    let m = mesh_with([1, 1, 1], 0, 1);
    let mut w = StreamWriter::create(&path, m.triangle_count, OptionalSections::default()).unwrap();
    w.append_points(&m.points).unwrap();
    w.append_neighbors(&m.neighbors).unwrap();
    match w.append_tets(&m.tets) {
        Err(FormatError::SectionOrder {
            section: "tets",
            detail,
            ..
        }) => assert!(detail.contains("neighbors"), "{detail}"),
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        w.append_normals(&m.points),
        Err(FormatError::SectionOrder {
            section: "normals",
            ..
        })
    ));
    // An unfinished writer leaves nothing behind.
    drop(w);
    assert!(files_in(dir.path()).is_empty());
}

#[test]
fn inconsistent_counts_fail_at_finish_and_keep_the_old_target() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("c.tmesh");
    std::fs::write(&path, b"old").unwrap();
    let m = mesh_with([1, 1, 1], 1, 2);
    let opt = OptionalSections::of(&m.attributes);
    // One neighbour record short.
    let mut w = StreamWriter::create(&path, m.triangle_count, opt).unwrap();
    w.append_points(&m.points).unwrap();
    w.append_tets(&m.tets).unwrap();
    w.append_neighbors(&m.neighbors[1..]).unwrap();
    w.append_constrained(&m.constrained).unwrap();
    w.append_normals(m.attributes.normals.as_ref().unwrap())
        .unwrap();
    match w.finish() {
        Err(FormatError::SizeMismatch {
            field: "neighbors length",
            expected,
            found,
            ..
        }) => assert_eq!(expected, found + 16),
        other => panic!("{other:?}"),
    }
    // Normals declared but missing.
    let mut w = StreamWriter::create(&path, m.triangle_count, opt).unwrap();
    w.append_points(&m.points).unwrap();
    assert!(matches!(
        w.finish(),
        Err(FormatError::SizeMismatch {
            field: "normals length",
            found: 0,
            ..
        })
    ));
    assert_eq!(std::fs::read(&path).unwrap(), b"old");
    assert_eq!(files_in(dir.path()), vec!["c.tmesh".to_string()]);
    // A directory that does not exist.
    assert!(matches!(
        StreamWriter::create(dir.path().join("no/such/x.tmesh"), 0, opt),
        Err(FormatError::Io { .. })
    ));
}

#[test]
fn section_reader_checks_the_header_ranges_and_payload() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r.tmesh");
    let m = mesh_with([2, 1, 1], 4, 3);
    let good = to_bytes(&m);
    std::fs::write(&path, &good).unwrap();
    let mut r = SectionReader::open(&path).unwrap();
    let n = m.tets.len() as u64;
    match r.read_tets(n - 1..n + 1) {
        Err(FormatError::SectionRange {
            section: "tets",
            start,
            end,
            count,
            path: p,
        }) => {
            assert_eq!((start, end, count), (n - 1, n + 1, n));
            assert_eq!(p, path);
        }
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        r.read_points(std::ops::Range { start: 3, end: 2 }),
        Err(FormatError::SectionRange { .. })
    ));
    // Short files: the header's field, or the section cut.
    for len in [0, 7, 100, HEADER_LEN + 1, good.len() - 1] {
        std::fs::write(&path, &good[..len]).unwrap();
        assert!(
            matches!(
                SectionReader::open(&path),
                Err(FormatError::Truncated { .. })
            ),
            "{len}"
        );
    }
    // A flipped payload byte: the header still opens, sections still read,
    // the streaming CRC pass names the payload.
    let mut bad = good.clone();
    bad[HEADER_LEN + 3] ^= 0x40;
    std::fs::write(&path, &bad).unwrap();
    let mut r = SectionReader::open(&path).unwrap();
    assert_eq!(r.read_tets(0..1).unwrap()[..], m.tets[..1]);
    assert!(matches!(
        r.verify_payload(),
        Err(FormatError::ChecksumMismatch {
            part: "payload",
            ..
        })
    ));
    // A flipped header byte fails the open.
    let mut bad = good.clone();
    bad[40] ^= 1;
    std::fs::write(&path, &bad).unwrap();
    assert!(SectionReader::open(&path).is_err());
    assert!(matches!(
        SectionReader::open(dir.path().join("missing.tmesh")),
        Err(FormatError::Io { .. })
    ));
}
