//! The `obj_and_scene` and `tetgen_files` fuzz targets, run on the
//! stable toolchain: each target's body (`fuzz/targets_common/<target>.rs`,
//! shared verbatim with the cargo-fuzz binaries through `include!`) over the
//! checked-in seed corpus `fuzz/seeds/<target>/` and over token-level
//! mutations of it generated here.
//!
//! A counting global allocator bounds what one input may allocate.
//!
//! Heavier runs (`#[ignore]`d; use `--release`):
//! * `million_executions`: each body over 10⁶ generated inputs (override with
//!   `TETRAYS_FUZZ_ITERS`), printing counts and time;
//! * `write_seed_corpus`: regenerates `fuzz/seeds/{obj_and_scene,tetgen_files}/`.

use std::time::Instant;

use tet_build::tetgen_files;
use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};

#[allow(dead_code)]
mod input {
    include!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/targets_common/input.rs"
    ));
}
#[allow(dead_code)]
mod obj_and_scene {
    include!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/targets_common/obj_and_scene.rs"
    ));
}
#[allow(dead_code)]
mod tetgen_files_target {
    include!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/targets_common/tetgen_files.rs"
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

/// What one text input may allocate at most: parsers keep a few copies of
/// the text and its tokens, never an amount a count in the text asks for.
fn budget(len: usize) -> usize {
    256 * len + (4 << 20)
}

fn bounded<R>(what: &str, data: &[u8], f: impl FnOnce() -> R) -> R {
    let (r, peak) = peak_bytes(f);
    assert!(
        peak <= budget(data.len()),
        "{what}: a {}-byte input allocated {peak} bytes at once: {:?}",
        data.len(),
        String::from_utf8_lossy(data)
    );
    r
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

/// A scenes.json in the shape of the real one, over the fixture meshes.
const SCENES_JSON: &str = r#"{
  "title": "generated fuzz seed",
  "meshes": {
    "tet": { "file": "tet.obj", "pre_transform": null },
    "quad": { "file": "quad.obj",
              "pre_transform": { "scale": [2, 2, 2], "rotation_deg": [0, 90, 0], "translation": [0, 1, 0] } }
  },
  "scenes": [
    { "name": "Two Tets",
      "camera": { "orbit_x_rad": 0.5, "orbit_y_rad": 1.0, "distance": 20.0, "target": [0, 0, 0],
                  "position": [9.48, 9.58, 14.76] },
      "lights": [ { "position": [6, 10, 8], "color": [1, 1, 1], "intensity": 1.0, "type": "point" } ],
      "objects": [
        { "name": "a", "mesh": "tet", "translation": [-5, 0, 0], "rotation_deg": [0, 0, 0], "scale": [1, 1, 1] },
        { "name": "b", "mesh": "tet", "file": "tet.obj", "translation": [5, 0, 0], "rotation_deg": [10, 20, 30], "scale": [1, -1, 1] },
        { "name": "placeholder", "mesh": null }
      ] },
    { "name": "Quad",
      "camera": { "orbit_x_rad": 0.0, "orbit_y_rad": 0.0, "distance": 5.0, "target": [0, 0, 0] },
      "objects": [
        { "name": "q", "mesh": "quad", "translation": [0, 0, 0], "rotation_deg": [0, 0, 0], "scale": [1, 1, 1] }
      ] },
    { "name": "Missing",
      "camera": { "orbit_x_rad": 0.0, "orbit_y_rad": 0.0, "distance": 5.0, "target": [0, 0, 0] },
      "objects": [ { "name": "m", "paper_mesh_file": "gone.obj", "mesh": null,
                     "translation": [0, 0, 0], "rotation_deg": [0, 0, 0], "scale": [1, 1, 1] } ] }
  ]
}
"#;

fn obj_seeds() -> Vec<(String, Vec<u8>)> {
    let texts: [(&str, &str); 7] = [
        ("tet.obj", obj_and_scene::TET_OBJ),
        ("quad_crlf.obj", obj_and_scene::QUAD_OBJ),
        (
            "negative_indices.obj",
            "o a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\no b\nv 0 0 1\nvn 0 0 1\nf 1//1 2//1 -1//1\n",
        ),
        (
            "polygon_groups.obj",
            "mtllib none.mtl\ng g1\nusemtl m\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\nf 1 2 3 4\ns 1\nf 1 2 5\nf 2 3 5\nl 1 2\np 3\n",
        ),
        ("non_finite.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"),
        ("out_of_range.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\n"),
        ("scenes.json", SCENES_JSON),
    ];
    texts
        .iter()
        .map(|(n, t)| (n.to_string(), t.as_bytes().to_vec()))
        .collect()
}

/// The four TetGen texts our writer produces for `mesh`, joined.
fn tetgen_input_of(mesh: &tet_core::TetMesh, with_face: bool, with_neigh: bool) -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path().join("m");
    let mut files = tetgen_files::from_tet_mesh(mesh);
    if !with_neigh {
        files.neighbors = None;
    }
    if !with_face {
        files.faces.clear();
        files.face_markers = None;
    }
    tetgen_files::write(&base, &files).unwrap();
    let read = |ext: &str| std::fs::read_to_string(dir.path().join(format!("m.{ext}"))).ok();
    let (face, neigh) = (read("face"), read("neigh"));
    tetgen_files_target::join(
        &read("node").unwrap(),
        &read("ele").unwrap(),
        face.as_deref().filter(|_| with_face),
        neigh.as_deref().filter(|_| with_neigh),
    )
}

fn tetgen_seeds() -> Vec<(String, Vec<u8>)> {
    let grid = |cells, fraction, seed| {
        kuhn_grid(&GridSpec {
            cells,
            constrained_fraction: fraction,
            seed,
            ..GridSpec::default()
        })
    };
    let mut out = vec![
        (
            "cube_all_files".to_string(),
            tetgen_input_of(&grid([1, 1, 1], 0.5, 1), true, true),
        ),
        (
            "cube_node_ele".to_string(),
            tetgen_input_of(&grid([1, 1, 1], 0.0, 2), false, false),
        ),
        (
            "grid_faces".to_string(),
            tetgen_input_of(&grid([2, 1, 1], 0.3, 3), true, false),
        ),
    ];
    // Hand-written: 1-based, comments, attributes and markers, one tet
    // given with negative orientation.
    out.push((
        "one_based_comments".to_string(),
        tetgen_files_target::join(
            "# nodes\n5 3 1 1\n1 0 0 0 7.5 1\n2 1 0 0 7.5 1\n3 0 1 0 7.5 0\n4 0 0 1 7.5 0\n5 0 0 -1 0 0 # below\n",
            "2 4 1\n1 1 2 3 4 1\n2 1 3 2 5 2\n",
            Some("2 1\n1 1 2 3 1\n2 1 2 4 0\n"),
            Some("2 4\n1 -1 -1 -1 2\n2 -1 -1 -1 1\n"),
        ),
    ));
    out.push((
        "flat_tet".to_string(),
        tetgen_files_target::join(
            "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 1 1 0\n",
            "1 4 0\n0 0 1 2 3\n",
            None,
            None,
        ),
    ));
    out
}

#[test]
#[ignore = "rewrites fuzz/seeds/{obj_and_scene,tetgen_files}/"]
fn write_seed_corpus() {
    for (target, seeds) in [
        ("obj_and_scene", obj_seeds()),
        ("tetgen_files", tetgen_seeds()),
    ] {
        let dir = seed_dir(target);
        std::fs::create_dir_all(&dir).unwrap();
        for (name, bytes) in seeds {
            std::fs::write(dir.join(name), bytes).unwrap();
        }
    }
}

#[test]
fn obj_and_scene_seed_corpus() {
    let seeds = read_seeds("obj_and_scene");
    assert!(seeds.len() >= 6, "seed corpus missing: {seeds:?}");
    let mut objs_ok = 0;
    let mut scenes_loaded = 0;
    for (_, bytes) in &seeds {
        bounded("obj_and_scene", bytes, || obj_and_scene::check(bytes));
        objs_ok += obj_and_scene::check_obj(bytes) as usize;
        scenes_loaded += obj_and_scene::check_scenes_json(bytes);
    }
    // tet, quad, negative indices, polygons parse; out-of-range and NaN don't.
    assert_eq!(objs_ok, 4);
    // "Two Tets" and "Quad" load; "Missing" is a typed error.
    assert_eq!(scenes_loaded, 2);
}

#[test]
fn obj_and_scene_seeds_match_the_generator() {
    for (name, bytes) in obj_seeds() {
        let on_disk = std::fs::read(seed_dir("obj_and_scene").join(&name)).unwrap();
        assert_eq!(on_disk, bytes, "{name}: rerun write_seed_corpus");
    }
}

#[test]
fn tetgen_files_seed_corpus() {
    let seeds = read_seeds("tetgen_files");
    assert!(seeds.len() >= 5, "seed corpus missing: {seeds:?}");
    let mut built = Vec::new();
    for (name, bytes) in &seeds {
        if bounded("tetgen_files", bytes, || tetgen_files_target::check(bytes)) {
            built.push(name.as_str());
        }
    }
    assert_eq!(
        built,
        [
            "cube_all_files",
            "cube_node_ele",
            "grid_faces",
            "one_based_comments"
        ]
    );
}

/// Found by the fuzzer: a header count sized an allocation before any
/// record was read, aborting the process on `99999999999999 4 0` (fixed in
/// `tetgen_files.rs`). The reproducers are seeds named `regress-*`.
#[test]
fn tetgen_files_huge_counts_are_typed_errors() {
    let inputs: Vec<_> = read_seeds("tetgen_files")
        .into_iter()
        .filter(|(n, _)| n.starts_with("regress-"))
        .collect();
    assert!(inputs.len() >= 3);
    for (name, bytes) in &inputs {
        assert!(
            !bounded(name, bytes, || tetgen_files_target::check(bytes)),
            "{name}: a file with a huge record count built a mesh"
        );
    }
}

/// Face indices that overflow inside `tobj` (huge, or relative ones reaching
/// before the first element; found by the fuzzer): `parse_obj_bytes` checks
/// indices before tobj sees them, so each is a typed error, not a panic.
#[test]
fn obj_index_overflow_regressions() {
    let inputs = read_seeds("../regressions/obj_and_scene");
    assert!(inputs.len() >= 2);
    for (name, bytes) in &inputs {
        assert!(
            !obj_and_scene::check_obj(bytes),
            "{name}: out-of-range index parsed"
        );
    }
    for bytes in [
        &b"vn 0 0 1\nf 1//2147483648\n"[..],
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//-3\n",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -9223372036854775808\n",
    ] {
        assert!(!obj_and_scene::check_obj(bytes));
    }
}

/// Tokens that break naive parsers: huge and negative counts and indices,
/// non-numbers, non-finite values, comment and record markers.
const TOKENS: [&str; 26] = [
    "0",
    "1",
    "-1",
    "2",
    "3",
    "4",
    "5",
    "4294967295",
    "4294967296",
    "-2147483648",
    "9223372036854775807",
    "99999999999999999999",
    "18446744073709551615",
    "nan",
    "inf",
    "-inf",
    "1e39",
    "-0",
    "1e-45",
    "#",
    "f",
    "v",
    "1/1/1",
    "-3/-1/-1",
    "\u{0}",
    "\"scenes\"",
];

/// One to three token-level mutations of `text`: replace a token, delete
/// or duplicate a line, insert a token, truncate.
fn mutate_text(rng: &mut SplitMix64, text: &[u8]) -> Vec<u8> {
    let mut b = text.to_vec();
    for _ in 0..1 + rng.next_u64() % 3 {
        let pos = (rng.next_u64() % (b.len() as u64 + 1)) as usize;
        let token = TOKENS[(rng.next_u64() % TOKENS.len() as u64) as usize].as_bytes();
        let is_space = |c: u8| c.is_ascii_whitespace() || c == 0;
        match rng.next_u64() % 6 {
            0 | 1 => {
                // Replace the token around `pos`.
                let mut s = pos.min(b.len());
                while s > 0 && !is_space(b[s - 1]) {
                    s -= 1;
                }
                let mut e = pos.min(b.len());
                while e < b.len() && !is_space(b[e]) {
                    e += 1;
                }
                b.splice(s..e, token.iter().copied());
            }
            2 => {
                b.splice(pos..pos, token.iter().chain(b" ").copied());
            }
            3 | 4 => {
                // Delete (3) or duplicate (4) the line around `pos`.
                let s = b[..pos]
                    .iter()
                    .rposition(|&c| c == b'\n')
                    .map_or(0, |i| i + 1);
                let e = b[pos..]
                    .iter()
                    .position(|&c| c == b'\n')
                    .map_or(b.len(), |i| pos + i + 1);
                if rng.next_u64().is_multiple_of(2) {
                    b.drain(s..e);
                } else {
                    let line: Vec<u8> = b[s..e].to_vec();
                    b.splice(e..e, line);
                }
            }
            _ => b.truncate(pos),
        }
    }
    b
}

#[test]
fn obj_and_scene_mutations() {
    let seeds: Vec<Vec<u8>> = obj_seeds().into_iter().map(|(_, b)| b).collect();
    let mut rng = SplitMix64(11);
    for i in 0..1500 {
        let b = mutate_text(&mut rng, &seeds[i % seeds.len()]);
        bounded("obj_and_scene", &b, || obj_and_scene::check(&b));
    }
}

#[test]
fn tetgen_files_mutations() {
    let seeds: Vec<Vec<u8>> = tetgen_seeds().into_iter().map(|(_, b)| b).collect();
    let mut rng = SplitMix64(12);
    let mut built = 0;
    for i in 0..800 {
        let b = mutate_text(&mut rng, &seeds[i % seeds.len()]);
        built += bounded("tetgen_files", &b, || tetgen_files_target::check(&b)) as usize;
    }
    // Some mutations keep the files valid (e.g. a changed coordinate).
    assert!(built > 0);
}

#[test]
#[ignore = "long: ~10^6 executions per target; run with --release"]
fn million_executions() {
    let iters: usize = std::env::var("TETRAYS_FUZZ_ITERS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);
    for (name, seeds, body) in [
        (
            "obj_and_scene",
            obj_seeds(),
            (|b: &[u8]| {
                obj_and_scene::check(b);
            }) as fn(&[u8]),
        ),
        (
            "tetgen_files",
            tetgen_seeds(),
            (|b: &[u8]| {
                tetgen_files_target::check(b);
            }) as fn(&[u8]),
        ),
    ] {
        let seeds: Vec<Vec<u8>> = seeds.into_iter().map(|(_, b)| b).collect();
        let mut rng = SplitMix64(0xC0FFEE);
        let start = Instant::now();
        for i in 0..iters {
            let b = mutate_text(&mut rng, &seeds[i % seeds.len()]);
            body(&b);
        }
        println!(
            "{name}: {iters} inputs, 0 crashes, {:.1} s",
            start.elapsed().as_secs_f64()
        );
    }
}
