//! The `mesh_file` and `xor_codecs` fuzz targets (issue 7), run on the stable
//! toolchain: each target's body (`fuzz/targets_common/<target>.rs`, shared
//! verbatim with the cargo-fuzz binaries through `include!`) over the
//! checked-in seed corpus `fuzz/seeds/<target>/` and over inputs generated
//! here (mutations of valid files, every truncation, huge header counts).
//!
//! A counting global allocator bounds the bytes each `mesh_file` input may
//! allocate by a multiple of its size, so "never over-allocates" is tested,
//! not assumed.
//!
//! Heavier runs (`#[ignore]`d; use `--release`):
//! * `million_executions`: each body over 10⁶ generated inputs (override with
//!   `TETRAYS_FUZZ_ITERS`), printing counts and time;
//! * `write_seed_corpus`: regenerates `fuzz/seeds/{mesh_file,xor_codecs}/`.

use std::time::Instant;

use glam::{Vec2, Vec3};
use tet_core::format;
use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};
use tet_core::{Attributes, TetMesh};

#[allow(dead_code)]
mod input {
    include!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/targets_common/input.rs"
    ));
}
#[allow(dead_code)]
mod mesh_file {
    include!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/targets_common/mesh_file.rs"
    ));
}
#[allow(dead_code)]
mod grid {
    include!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/targets_common/grid.rs"
    ));
}
#[allow(dead_code)]
mod xor_codecs {
    include!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/targets_common/xor_codecs.rs"
    ));
}

#[allow(dead_code)]
mod counting_alloc {
    include!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/targets_common/counting_alloc.rs"
    ));
}
use counting_alloc::peak_bytes;

#[global_allocator]
static ALLOCATOR: counting_alloc::Counting = counting_alloc::Counting;

/// The allocation budget of one `mesh_file` input: the loader reads each
/// section straight into its `Vec` and validation sorts the faces; the body
/// also writes and re-reads the mesh. All of it is proportional to the real
/// input size, never to a count read from the header.
fn mesh_file_budget(len: usize) -> usize {
    40 * len + (1 << 20)
}

fn check_mesh_file(data: &[u8]) {
    let ((), peak) = peak_bytes(|| mesh_file::check(data));
    assert!(
        peak <= mesh_file_budget(data.len()),
        "a {}-byte input allocated {peak} bytes at once",
        data.len()
    );
}

// ---------------------------------------------------------------------------
// Seed corpus.
// ---------------------------------------------------------------------------

#[allow(dead_code)]
mod corpus {
    include!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/targets_common/corpus.rs"
    ));
}
use corpus::{read_seeds, seed_dir};

/// Small valid meshes exercising every section of the format.
fn sample_meshes() -> Vec<(&'static str, TetMesh)> {
    let grid = |cells, fraction, shell, seed| {
        kuhn_grid(&GridSpec {
            cells,
            constrained_fraction: fraction,
            shell,
            seed,
            ..GridSpec::default()
        })
    };
    let mut with_attributes = grid([2, 1, 1], 0.3, None, 7);
    let n = with_attributes.points.len();
    with_attributes.attributes = Attributes {
        normals: Some((0..n).map(|i| Vec3::new(i as f32, 0.0, 1.0)).collect()),
        uvs: Some((0..n).map(|i| Vec2::new(0.5, i as f32)).collect()),
        materials: Some((0..with_attributes.triangle_count).collect()),
        scalars: None,
    };
    // A two-step scalar field (its own block after the sections).
    let mut with_scalars = grid([1, 2, 1], 0.2, None, 8);
    let n = with_scalars.points.len();
    with_scalars.attributes.scalars = Some(tet_core::ScalarField {
        name: "density".into(),
        steps: vec![
            (0..n).map(|i| i as f32 - 3.5).collect(),
            (0..n)
                .map(|i| if i % 2 == 0 { -0.0 } else { 1e-30 })
                .collect(),
        ],
    });
    vec![
        ("empty", TetMesh::default()),
        ("cube", grid([1, 1, 1], 0.0, None, 1)),
        ("cube_constrained", grid([1, 1, 1], 0.6, None, 2)),
        (
            "shell",
            grid([2, 2, 1], 0.0, Some(([0, 0, 0], [1, 1, 1])), 3),
        ),
        ("attributes", with_attributes),
        ("scalars", with_scalars),
    ]
}

/// A small mesh with a scene block (camera and two lights).
fn scene_seed() -> Vec<u8> {
    let mesh = kuhn_grid(&GridSpec {
        cells: [1, 1, 1],
        constrained_fraction: 0.5,
        seed: 4,
        ..GridSpec::default()
    });
    let light = |x: f32| tet_core::scene::PointLight {
        position: Vec3::new(x, 2.0, 3.0),
        color: Vec3::ONE,
        intensity: 0.5,
    };
    let scene = tet_core::scene::SceneInfo {
        camera: Some(tet_core::scene::Camera::default()),
        lights: vec![light(1.0), light(-1.0)],
    };
    format::to_bytes_with_scene(&mesh, &scene)
}

/// Seed inputs of `xor_codecs`: one per placement and grid shape, plus the
/// all-zero and empty inputs.
fn xor_seeds() -> Vec<(String, Vec<u8>)> {
    let mut out = vec![("empty".to_string(), Vec::new())];
    let mut rng = SplitMix64(0x5eed);
    for i in 0..8u8 {
        let mut bytes: Vec<u8> = (0..96).map(|_| rng.next_u64() as u8).collect();
        // cells, jitter, fraction, shell flag, placement.
        bytes[0..4].copy_from_slice(&u32::from(i % 3).to_le_bytes());
        bytes[14] = i; // shell on odd seeds
        bytes[15] = i % 6;
        out.push((format!("grid{i}"), bytes));
    }
    out
}

#[test]
#[ignore = "rewrites fuzz/seeds/{mesh_file,xor_codecs}/; run when the format changes"]
fn write_seed_corpus() {
    for (target, seeds) in [
        (
            "mesh_file",
            sample_meshes()
                .into_iter()
                .map(|(name, m)| (format!("{name}.tmeshbin"), format::to_bytes(&m)))
                .chain([("scene.tmeshbin".to_string(), scene_seed())])
                .collect::<Vec<_>>(),
        ),
        ("xor_codecs", xor_seeds()),
    ] {
        let dir = seed_dir(target);
        std::fs::create_dir_all(&dir).unwrap();
        for (name, bytes) in seeds {
            std::fs::write(dir.join(name), bytes).unwrap();
        }
    }
}

#[test]
fn mesh_file_seed_corpus() {
    let seeds = read_seeds("mesh_file");
    assert!(seeds.len() >= 5, "seed corpus missing: {seeds:?}");
    let mut loaded = 0;
    for (name, bytes) in &seeds {
        check_mesh_file(bytes);
        // Seeds written by the current writer must load; regression inputs
        // (named `crash-*`/`regress-*`) need only not crash.
        if !name.starts_with("regress") && !name.starts_with("crash") {
            assert!(mesh_file::check_bytes(bytes), "seed {name} does not load");
            loaded += 1;
        }
    }
    assert!(loaded >= 5);
}

#[test]
fn mesh_file_generated_valid_files_load_and_round_trip() {
    for (name, mesh) in sample_meshes() {
        let bytes = format::to_bytes(&mesh);
        assert!(mesh_file::check_bytes(&bytes), "{name}");
        assert_eq!(format::from_bytes(&bytes).unwrap(), mesh, "{name}");
        check_mesh_file(&bytes);
    }
}

#[test]
fn mesh_file_every_truncation_is_a_typed_error() {
    for (name, mesh) in sample_meshes() {
        let bytes = format::to_bytes(&mesh);
        for len in 0..bytes.len() {
            let cut = &bytes[..len];
            let (result, peak) = peak_bytes(|| format::from_bytes(cut));
            assert!(result.is_err(), "{name}: prefix of {len} bytes loaded");
            assert!(
                peak <= mesh_file_budget(len),
                "{name}: prefix {len}: {peak} bytes"
            );
            check_mesh_file(cut);
        }
    }
}

/// Header values that make naive loaders allocate or index wildly.
const INTERESTING_U64: [u64; 12] = [
    0,
    1,
    7,
    176,
    0x7FFF_FFFE,
    0x7FFF_FFFF,
    0x8000_0000,
    0xFFFF_FFFF,
    0x1_0000_0000,
    u64::MAX / 32,
    u64::MAX - 7,
    u64::MAX,
];

#[test]
fn mesh_file_huge_header_fields_are_refused_within_budget() {
    for (name, mesh) in sample_meshes() {
        let bytes = format::to_bytes(&mesh);
        // Every 8-byte header field from file_length on (counts and the
        // section table), with consistent CRCs so the value is really used.
        for at in (16..168).step_by(8) {
            for value in INTERESTING_U64 {
                let mut b = bytes.clone();
                b[at..at + 8].copy_from_slice(&value.to_le_bytes());
                check_mesh_file(&b);
                let patched = mesh_file::with_consistent_header(&b).unwrap();
                let (_, peak) = peak_bytes(|| format::from_bytes(&patched));
                assert!(
                    peak <= mesh_file_budget(patched.len()),
                    "{name}: field at {at} = {value}: {peak} bytes"
                );
            }
        }
    }
}

/// One random mutation of `seed`: bit flips, interesting words, truncation,
/// extension or splicing.
fn mutate(rng: &mut SplitMix64, seed: &[u8]) -> Vec<u8> {
    let mut b = seed.to_vec();
    let n = 1 + rng.next_u64() % 4;
    for _ in 0..n {
        let pick = |rng: &mut SplitMix64, len: usize| (rng.next_u64() % len.max(1) as u64) as usize;
        match rng.next_u64() % 7 {
            0 if !b.is_empty() => {
                let i = pick(rng, b.len());
                b[i] ^= 1 << (rng.next_u64() % 8);
            }
            1 if !b.is_empty() => {
                let i = pick(rng, b.len());
                b[i] = [0u8, 1, 0x7F, 0x80, 0xFF][pick(rng, 5)];
            }
            2 if b.len() >= 8 => {
                let i = pick(rng, b.len() - 7) & !3;
                let v = INTERESTING_U64[pick(rng, INTERESTING_U64.len())];
                b[i..i + 8].copy_from_slice(&v.to_le_bytes());
            }
            3 if b.len() >= 4 => {
                // A 32-bit word of the payload: link values, vertex ids, floats.
                let i = pick(rng, b.len() - 3) & !3;
                let v: u32 = [
                    0,
                    1,
                    0x7FFF_FFFF,
                    0x8000_0000,
                    0xFFFF_FFFF,
                    0x7FC0_0000,
                    0x7F80_0000,
                    rng.next_u64() as u32,
                ][pick(rng, 8)];
                b[i..i + 4].copy_from_slice(&v.to_le_bytes());
            }
            4 => {
                let len = pick(rng, b.len() + 1);
                b.truncate(len);
            }
            5 => {
                let extra = 1 + pick(rng, 64);
                b.extend((0..extra).map(|_| rng.next_u64() as u8));
            }
            _ if b.len() >= 16 => {
                // Copy one 8-byte-aligned block over another.
                let from = pick(rng, b.len() - 7) & !7;
                let to = pick(rng, b.len() - 7) & !7;
                let block: [u8; 8] = b[from..from + 8].try_into().unwrap();
                b[to..to + 8].copy_from_slice(&block);
            }
            _ => {}
        }
    }
    b
}

fn mesh_file_mutations(iterations: usize, seed: u64) -> (usize, usize) {
    let files: Vec<Vec<u8>> = sample_meshes()
        .into_iter()
        .map(|(_, m)| format::to_bytes(&m))
        .chain(read_seeds("mesh_file").into_iter().map(|(_, b)| b))
        .collect();
    let mut rng = SplitMix64(seed);
    let mut loaded = 0;
    for i in 0..iterations {
        let b = mutate(&mut rng, &files[i % files.len()]);
        if let Some(p) = mesh_file::with_consistent_header(&b) {
            loaded += mesh_file::check_bytes(&p) as usize;
        }
        mesh_file::check_bytes(&b);
    }
    (iterations, loaded)
}

#[test]
fn mesh_file_random_mutations() {
    let files: Vec<Vec<u8>> = sample_meshes()
        .into_iter()
        .map(|(_, m)| format::to_bytes(&m))
        .collect();
    let mut rng = SplitMix64(42);
    for i in 0..5000 {
        let b = mutate(&mut rng, &files[i % files.len()]);
        check_mesh_file(&b);
    }
    // Pure noise too.
    for len in [0, 7, 8, 12, 175, 176, 177, 600] {
        let b: Vec<u8> = (0..len).map(|_| rng.next_u64() as u8).collect();
        check_mesh_file(&b);
        let mut m = b.clone();
        if m.len() >= 12 {
            m[..8].copy_from_slice(&format::MAGIC);
            m[8..12].copy_from_slice(&format::VERSION.to_le_bytes());
        }
        check_mesh_file(&m);
    }
}

#[test]
fn xor_codecs_seed_corpus() {
    let seeds = read_seeds("xor_codecs");
    assert!(seeds.len() >= 5, "seed corpus missing: {seeds:?}");
    for (_, bytes) in &seeds {
        xor_codecs::check(bytes);
    }
}

#[test]
fn xor_codecs_generated_inputs() {
    let mut rng = SplitMix64(7);
    for len in 0..1000usize {
        let bytes: Vec<u8> = (0..len % 120).map(|_| rng.next_u64() as u8).collect();
        xor_codecs::check(&bytes);
    }
}

#[test]
fn xor_codecs_relabelling_preserves_the_mesh() {
    // The fuzz body's mesh generator is itself checked against an
    // independent property: relabelling keeps the multiset of tets (as point
    // sets) and of constrained triangles (as point triples).
    let original = kuhn_grid(&GridSpec {
        cells: [2, 2, 1],
        constrained_fraction: 0.4,
        ..GridSpec::default()
    });
    let r = grid::relabel(&original, 99, 5);
    assert_eq!(r.points.len(), original.points.len() + 5);
    let key = |m: &TetMesh, t: [u32; 4]| {
        let mut p: Vec<[u32; 3]> = t
            .iter()
            .map(|&v| m.points[v as usize].to_array().map(f32::to_bits))
            .collect();
        p.sort();
        p
    };
    let mut a: Vec<_> = original.tets.iter().map(|&t| key(&original, t)).collect();
    let mut b: Vec<_> = r.tets.iter().map(|&t| key(&r, t)).collect();
    a.sort();
    b.sort();
    assert_eq!(a, b);
    let tri = |m: &TetMesh| {
        let mut v: Vec<_> = m
            .constrained
            .iter()
            .map(|c| {
                (
                    c.triangle,
                    c.vertices
                        .map(|v| m.points[v as usize].to_array().map(f32::to_bits)),
                )
            })
            .collect();
        v.sort();
        v
    };
    assert_eq!(tri(&original), tri(&r));
    // And the relabelling really moved ids and slots.
    assert_ne!(original.tets, r.tets);
}

#[test]
#[ignore = "long: ~10^6 executions per target; run with --release"]
fn million_executions() {
    let iters: usize = std::env::var("TETRAYS_FUZZ_ITERS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);
    let start = Instant::now();
    let (n, loaded) = mesh_file_mutations(iters, 0xF00D);
    println!(
        "mesh_file: {n} inputs ({loaded} loaded after CRC patching), 0 crashes, {:.1} s",
        start.elapsed().as_secs_f64()
    );
    let start = Instant::now();
    let mut rng = SplitMix64(0xBEEF);
    let mut bytes = Vec::new();
    for i in 0..iters {
        bytes.clear();
        bytes.extend((0..(i % 128)).map(|_| rng.next_u64() as u8));
        xor_codecs::check(&bytes);
    }
    println!(
        "xor_codecs: {iters} inputs, 0 crashes, {:.1} s",
        start.elapsed().as_secs_f64()
    );
}
