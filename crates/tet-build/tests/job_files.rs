//! The job's files on their own (no TetGen run): a part's input file
//! against its documented byte layout, every corruption a typed error, and
//! `job.json` round trips with its schema, version and consistency checks.

#![cfg(feature = "tetgen")]

use std::path::Path;

use glam::Vec3;
use tet_build::outofcore::job::digest::{Xxh64, digest, xxh64};
use tet_build::outofcore::job::manifest::{ExactF32, JobManifest, Partition};
use tet_build::outofcore::job::part_input::{PartInput, SEAM_FACET, decode, encode};
use tet_build::outofcore::job::{
    InputFault, JobError, PlanOptions, Planner, part_index, plan_job, scene_digest,
};
use tet_build::outofcore::memory_model::knot_grid;

fn sample() -> PartInput {
    PartInput {
        part: 3,
        triangle_count: 10,
        facets: vec![
            (
                [Vec3::new(0.0, 0.0, 0.0), Vec3::X, Vec3::new(0.1, 1.0, -2.5)],
                7,
            ),
            ([Vec3::Y, Vec3::Z, Vec3::ONE], SEAM_FACET),
        ],
        box_faces: vec![[
            Vec3::splat(-3.0),
            Vec3::splat(3.0),
            Vec3::new(3.0, -3.0, 0.5),
        ]],
        surface_relaxed: true,
    }
}

/// The layout of the module docs, written out field by field.
fn by_hand(p: &PartInput) -> Vec<u8> {
    let mut b = b"TETPART\0".to_vec();
    for w in [1u32, p.part, p.triangle_count, u32::from(p.surface_relaxed)] {
        b.extend(w.to_le_bytes());
    }
    b.extend((p.facets.len() as u64).to_le_bytes());
    b.extend((p.box_faces.len() as u64).to_le_bytes());
    let tri = |b: &mut Vec<u8>, t: &[Vec3; 3]| {
        for v in t {
            for c in [v.x, v.y, v.z] {
                b.extend(c.to_le_bytes());
            }
        }
    };
    for (t, id) in &p.facets {
        tri(&mut b, t);
        b.extend(id.to_le_bytes());
    }
    for t in &p.box_faces {
        tri(&mut b, t);
    }
    let sum = xxh64(&b);
    b.extend(sum.to_le_bytes());
    b
}

/// Rewrites the trailing checksum, so that a check after it is reached.
fn reseal(b: &mut [u8]) {
    let n = b.len() - 8;
    let sum = xxh64(&b[..n]);
    b[n..].copy_from_slice(&sum.to_le_bytes());
}

#[test]
fn part_input_round_trips_in_its_documented_layout() {
    let p = sample();
    let (bytes, sum) = encode(&p);
    assert_eq!(bytes, by_hand(&p));
    assert_eq!(bytes.len(), 40 + 2 * 40 + 36 + 8);
    let (back, back_sum) = decode(&bytes).unwrap();
    assert_eq!(back, p);
    assert_eq!(back_sum, sum);
    assert_eq!(sum, xxh64(&bytes[..bytes.len() - 8]));
}

#[test]
fn corrupt_part_inputs_give_typed_errors() {
    let good = encode(&sample()).0;
    // Every truncation: too short for a header, or sizes that do not add up.
    for len in 0..good.len() {
        match decode(&good[..len]) {
            Err(InputFault::Short { len: l, min: 48 }) => assert!(len < 48 && l == len as u64),
            Err(InputFault::Length { len: l, .. }) => assert!(len >= 48 && l == len as u64),
            other => panic!("{len} bytes: {other:?}"),
        }
    }
    // A flipped byte anywhere after the header words that are checked first.
    for at in 40..good.len() - 8 {
        let mut b = good.clone();
        b[at] ^= 0x10;
        assert!(
            matches!(decode(&b), Err(InputFault::Checksum { .. })),
            "byte {at}"
        );
    }
    let mut b = good.clone();
    b[0] = b'X';
    assert!(matches!(decode(&b), Err(InputFault::Magic { .. })));
    let mut b = good.clone();
    b[8] = 2;
    assert!(matches!(
        decode(&b),
        Err(InputFault::Version {
            found: 2,
            expected: 1
        })
    ));
    let mut b = good.clone();
    b[20] = 2;
    assert!(matches!(decode(&b), Err(InputFault::Flags(2))));
    // A facet count that would ask for 2^64 bytes: refused by length,
    // nothing allocated.
    let mut b = good.clone();
    b[24..32].copy_from_slice(&u64::MAX.to_le_bytes());
    assert!(matches!(decode(&b), Err(InputFault::Length { .. })));
    // Sealed files with bad content.
    let mut b = good.clone();
    b[40 + 36..40 + 40].copy_from_slice(&10u32.to_le_bytes());
    reseal(&mut b);
    assert_eq!(
        decode(&b).unwrap_err(),
        InputFault::Triangle {
            facet: 0,
            triangle: 10,
            count: 10
        }
    );
    let mut b = good.clone();
    b[40 + 40 + 4..40 + 40 + 8].copy_from_slice(&f32::NAN.to_le_bytes());
    reseal(&mut b);
    assert_eq!(
        decode(&b).unwrap_err(),
        InputFault::NonFinite {
            what: "facet",
            index: 1
        }
    );
    let mut b = good.clone();
    let at = 40 + 80;
    b[at..at + 4].copy_from_slice(&f32::INFINITY.to_le_bytes());
    reseal(&mut b);
    assert_eq!(
        decode(&b).unwrap_err(),
        InputFault::NonFinite {
            what: "box face",
            index: 0
        }
    );
}

/// Pseudo-random byte strings and mutations of a valid file never panic:
/// a typed error, or (for the valid file) the input back.
#[test]
fn mutated_part_inputs_never_panic() {
    let good = encode(&sample()).0;
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for _ in 0..3000 {
        let mut b = good.clone();
        for _ in 0..1 + next() % 4 {
            let at = (next() % b.len() as u64) as usize;
            b[at] = next() as u8;
        }
        if next() % 3 == 0 {
            reseal(&mut b);
        }
        let cut = (next() % (b.len() as u64 + 1)) as usize;
        let b = if next() % 4 == 0 { &b[..cut] } else { &b[..] };
        if let Ok((p, _)) = decode(b) {
            // Whatever decodes encodes back to the same bytes.
            assert_eq!(encode(&p).0, b);
        }
    }
}

#[test]
fn exact_floats_survive_json() {
    for v in [
        0.1f32,
        -0.0,
        1.0e-45,
        f32::MIN_POSITIVE,
        16_777_216.0,
        3.402_823_5e38,
        -1.175_494_2e-38,
        0.300_000_04,
    ] {
        let text = serde_json::to_string(&ExactF32(v)).unwrap();
        let back: ExactF32 = serde_json::from_str(&text).unwrap();
        assert_eq!(back.0.to_bits(), v.to_bits(), "{v:?} as {text}");
    }
    for bad in ["\"NaN\"", "\"inf\"", "\"x\"", "0.5"] {
        assert!(serde_json::from_str::<ExactF32>(bad).is_err(), "{bad}");
    }
}

fn plan_small(dir: &Path, parts: usize) -> JobManifest {
    let scene = knot_grid(1, 60, 6);
    let options = PlanOptions {
        parts,
        ..PlanOptions::default()
    };
    plan_job(&scene, &options, dir).unwrap()
}

#[test]
fn job_json_round_trips_and_describes_its_parts() {
    let dir = tempfile::tempdir().unwrap();
    let job = plan_small(dir.path(), 3);
    assert!(job.parts.len() >= 3, "{} parts", job.parts.len());
    assert_eq!(JobManifest::load(dir.path()).unwrap(), job);
    assert_eq!(job.scene.digest, scene_digest(&knot_grid(1, 60, 6)));
    assert_ne!(job.scene.digest, scene_digest(&knot_grid(1, 60, 8)));
    let Partition::Tree { tree, .. } = &job.partition else {
        panic!("the default planner cuts a tree here: {:?}", job.partition);
    };
    assert_eq!(tree.leaves(), job.merge.order);
    assert_eq!(job.merge.seams.len(), job.parts.len() - 1);
    for (k, p) in job.parts.iter().enumerate() {
        // Each part's file is there, is the digest the plan names, and
        // holds that part's facets only.
        let bytes = std::fs::read(dir.path().join(&p.input)).unwrap();
        assert_eq!(bytes.len() as u64, p.input_bytes);
        let (input, sum) = decode(&bytes).unwrap();
        assert_eq!(format!("xxh64:{sum:016x}"), p.input_digest);
        assert_eq!(input.part as usize, k);
        assert_eq!(input.facets.len() + input.box_faces.len(), p.triangles);
        assert!(p.predicted_peak_bytes > 0);
        // No part carries the whole scene.
        let mut ids: Vec<u32> = input
            .facets
            .iter()
            .map(|f| f.1)
            .filter(|&id| id != SEAM_FACET)
            .collect();
        ids.sort_unstable();
        ids.dedup();
        assert!(
            !ids.is_empty() && ids.len() < 720,
            "part {k}: {} of 720",
            ids.len()
        );
    }
    // Planning the same scene again writes the same inputs (digests are
    // reproducible, so finished parts stay valid).
    let again = plan_small(dir.path(), 3);
    assert_eq!(again, job);
    assert_eq!(
        digest(&std::fs::read(dir.path().join("job.json")).unwrap()),
        digest(job.to_json().as_bytes())
    );
    // Slabs on request.
    let slabs = plan_job(
        &knot_grid(1, 60, 6),
        &PlanOptions {
            parts: 3,
            planner: Planner::Slabs,
            ..PlanOptions::default()
        },
        &dir.path().join("slabs"),
    )
    .unwrap();
    match &slabs.partition {
        Partition::Slabs { values, .. } => assert_eq!(values.len() + 1, slabs.parts.len()),
        other => panic!("{other:?}"),
    }
}

#[test]
fn broken_job_json_gives_typed_errors() {
    let dir = tempfile::tempdir().unwrap();
    let job = plan_small(dir.path(), 2);
    let path = dir.path().join("job.json");
    let text = job.to_json();
    let expect = |text: &str, needle: &str| {
        std::fs::write(&path, text).unwrap();
        match JobManifest::load(dir.path()) {
            Err(JobError::Manifest { path: p, detail }) => {
                assert_eq!(p, path);
                assert!(detail.contains(needle), "{needle:?} not in {detail:?}");
            }
            other => panic!("{other:?}"),
        }
    };
    expect(&text[..text.len() / 2], "not JSON");
    expect(&text.replace("\"version\": 1", "\"version\": 2"), "version");
    expect(&text.replace("\"tet-job\"", "\"other\""), "schema");
    expect(
        &text.replace("\"index\": 1", "\"index\": 7"),
        "parts[1].index",
    );
    expect(
        &text.replace("\"part-0.input\"", "\"../part-0.input\""),
        "plain file name",
    );
    expect(
        &text.replace("\"order\": [\n      0,", "\"order\": [\n      1,"),
        "order",
    );
    expect(
        &text.replacen("\"input_bytes\"", "\"extra\": 1, \"input_bytes\"", 1),
        "extra",
    );
    std::fs::remove_file(&path).unwrap();
    assert!(matches!(
        JobManifest::load(dir.path()),
        Err(JobError::Io { .. })
    ));
}

#[test]
fn the_part_index_comes_from_the_flag_or_the_engine() {
    let env = |pairs: &'static [(&'static str, &'static str)]| {
        move |name: &str| {
            pairs
                .iter()
                .find(|(k, _)| *k == name)
                .map(|(_, v)| v.to_string())
        }
    };
    assert_eq!(
        part_index(Some(4), env(&[("SLURM_ARRAY_TASK_ID", "2")])).unwrap(),
        4
    );
    assert_eq!(
        part_index(None, env(&[("SLURM_ARRAY_TASK_ID", "2")])).unwrap(),
        2
    );
    assert_eq!(
        part_index(None, env(&[("JOB_COMPLETION_INDEX", "5")])).unwrap(),
        5
    );
    assert_eq!(
        part_index(
            None,
            env(&[("JOB_COMPLETION_INDEX", "5"), ("SLURM_ARRAY_TASK_ID", "1")])
        )
        .unwrap(),
        1
    );
    assert!(matches!(part_index(None, env(&[])), Err(JobError::NoIndex)));
    assert!(matches!(
        part_index(None, env(&[("SLURM_ARRAY_TASK_ID", "x")])),
        Err(JobError::BadIndex {
            variable: "SLURM_ARRAY_TASK_ID",
            ..
        })
    ));
}

/// Values of the reference implementation (python-xxhash 3,
/// `xxhash.xxh64(data).hexdigest()`).
#[test]
fn digests_match_the_reference_xxh64() {
    let long: Vec<u8> = (0..3).flat_map(|_| 0..=255u8).chain(*b"xyz").collect();
    let cases: [(&[u8], u64); 5] = [
        (b"", 0xef46_db37_51d8_e999),
        (b"a", 0xd24e_c4f1_a98c_6e5b),
        (b"abc", 0x44bc_2cf5_ad77_0999),
        (&long, 0xe921_a1b4_5bd7_79f8),
        (&b"tetrays".repeat(13), 0xce8b_edd4_3d4f_fff9),
    ];
    for (data, expected) in cases {
        assert_eq!(xxh64(data), expected, "{} bytes", data.len());
        // Any split into updates gives the same hash.
        for cut in [1, 7, 31, 32, 33, 100] {
            let mut h = Xxh64::new();
            for piece in data.chunks(cut) {
                h.update(piece);
            }
            assert_eq!(
                h.finish(),
                expected,
                "{} bytes in pieces of {cut}",
                data.len()
            );
        }
    }
    assert_eq!(digest(b"abc"), "xxh64:44bc2cf5ad770999");
}
