//! The `vtk_files` fuzz target, run on the stable toolchain: its body
//! (`fuzz/targets_common/vtk_files.rs`, shared verbatim with the cargo-fuzz
//! binary through `include!`) over the checked-in seed corpus
//! `fuzz/seeds/vtk_files/` and over token-level mutations of it, with a
//! counting global allocator bounding what one input may allocate.
//!
//! `write_seed_corpus` (`#[ignore]`d) regenerates the seeds;
//! `TETRAYS_FUZZ_ITERS` sets the number of mutations (default 1500).

use tet_build::vtk::{VtkEncoding, to_legacy_bytes, to_vtu_bytes};
use tet_core::ScalarField;
use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};

#[allow(dead_code)]
mod vtk_files {
    include!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/targets_common/vtk_files.rs"
    ));
}
#[allow(dead_code)]
mod counting_alloc {
    include!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/targets_common/counting_alloc.rs"
    ));
}
#[allow(dead_code)]
mod corpus {
    include!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/targets_common/corpus.rs"
    ));
}
use corpus::{read_seeds, seed_dir};
use counting_alloc::peak_bytes;

#[global_allocator]
static ALLOCATOR: counting_alloc::Counting = counting_alloc::Counting;

/// What one input may allocate at most: a few copies of the file and of
/// its values as `f64`, never what a count in the file asks for.
fn budget(len: usize) -> usize {
    256 * len + (4 << 20)
}

fn bounded(data: &[u8]) -> bool {
    let (r, peak) = peak_bytes(|| vtk_files::check(data));
    assert!(
        peak <= budget(data.len()),
        "a {}-byte input allocated {peak} bytes at once: {:?}",
        data.len(),
        String::from_utf8_lossy(data)
    );
    r
}

const LEGACY: &str = "# vtk DataFile Version 3.0\nhand written\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 5 double\n0 0 0 1 0 0 0 1 0\n0.2 0.2 1\n0.2 0.2 -1\nCELLS 2 10\n4 0 1 2 3\n4 0 1 2 4\nCELL_TYPES 2\n10\n10\nPOINT_DATA 5\nSCALARS temperature float\nLOOKUP_TABLE default\n0 1 2 3 -4.5\n";

const VTU: &str = r#"<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">
<UnstructuredGrid><Piece NumberOfPoints="5" NumberOfCells="2">
<PointData><DataArray type="Float64" Name="t" format="ascii">0 1 2 3 -4.5</DataArray></PointData>
<Points><DataArray type="Float32" NumberOfComponents="3" format="ascii">0 0 0 1 0 0 0 1 0 0.2 0.2 1 0.2 0.2 -1</DataArray></Points>
<Cells>
<DataArray type="Int32" Name="connectivity" format="ascii">0 1 2 3 0 1 2 4</DataArray>
<DataArray type="Int32" Name="offsets" format="ascii">4 8</DataArray>
<DataArray type="UInt8" Name="types" format="ascii">10 10</DataArray>
</Cells></Piece></UnstructuredGrid></VTKFile>
"#;

fn seeds() -> Vec<(String, Vec<u8>)> {
    let mut m = kuhn_grid(&GridSpec {
        cells: [1, 1, 2],
        constrained_fraction: 0.3,
        seed: 4,
        ..GridSpec::default()
    });
    let n = m.points.len();
    m.attributes.scalars = Some(ScalarField {
        name: "rho".into(),
        steps: vec![(0..n).map(|i| i as f32 * 0.5).collect(), vec![-1.0; n]],
    });
    let mut out = Vec::new();
    for (tag, enc) in [
        ("ascii", VtkEncoding::Ascii),
        ("binary", VtkEncoding::Binary),
        ("appended", VtkEncoding::Appended),
    ] {
        if enc != VtkEncoding::Appended {
            out.push((
                format!("ours_{tag}.vtk"),
                vtk_files::join(0, &to_legacy_bytes(&m, enc)),
            ));
        }
        out.push((
            format!("ours_{tag}.vtu"),
            vtk_files::join(1, &to_vtu_bytes(&m, enc)),
        ));
    }
    out.push(("hand.vtk".into(), vtk_files::join(2, LEGACY.as_bytes())));
    out.push(("hand.vtu".into(), vtk_files::join(2, VTU.as_bytes())));
    out.push((
        "hexahedron.vtk".into(),
        vtk_files::join(0, LEGACY.replace("10\n10\n", "10\n12\n").as_bytes()),
    ));
    out.push((
        "huge_count.vtk".into(),
        vtk_files::join(
            0,
            LEGACY
                .replace("POINTS 5", "POINTS 99999999999999")
                .as_bytes(),
        ),
    ));
    out.push((
        "huge_block.vtu".into(),
        vtk_files::join(
            1,
            VTU.replace(r#"format="ascii">4 8<"#, r#"format="binary">/////w==<"#)
                .as_bytes(),
        ),
    ));
    out
}

#[test]
#[ignore = "rewrites fuzz/seeds/vtk_files/"]
fn write_seed_corpus() {
    let dir = seed_dir("vtk_files");
    std::fs::create_dir_all(&dir).unwrap();
    for (name, bytes) in seeds() {
        std::fs::write(dir.join(name), bytes).unwrap();
    }
}

#[test]
fn seeds_match_the_generator() {
    for (name, bytes) in seeds() {
        let on_disk = std::fs::read(seed_dir("vtk_files").join(&name)).unwrap();
        assert_eq!(on_disk, bytes, "{name}: rerun write_seed_corpus");
    }
}

#[test]
fn seed_corpus() {
    let mut read = Vec::new();
    for (name, bytes) in read_seeds("vtk_files") {
        if bounded(&bytes) {
            read.push(name);
        }
    }
    assert_eq!(
        read,
        [
            "hand.vtk",
            "hand.vtu",
            "ours_appended.vtu",
            "ours_ascii.vtk",
            "ours_ascii.vtu",
            "ours_binary.vtk",
            "ours_binary.vtu"
        ]
    );
}

const TOKENS: [&str; 16] = [
    "0",
    "1",
    "-1",
    "4",
    "10",
    "5",
    "4294967295",
    "99999999999999999999",
    "nan",
    "inf",
    "1e39",
    "-0",
    "float",
    "SCALARS x float 1",
    "</DataArray>",
    "format=\"binary\"",
];

/// One to three token-level mutations: replace or insert a token, delete or
/// duplicate a line, truncate, flip a byte.
fn mutate(rng: &mut SplitMix64, data: &[u8]) -> Vec<u8> {
    let mut b = data.to_vec();
    for _ in 0..1 + rng.next_u64() % 3 {
        // Keep the selector byte.
        let pos = 1 + (rng.next_u64() % b.len() as u64) as usize;
        let pos = pos.min(b.len());
        let token = TOKENS[(rng.next_u64() % TOKENS.len() as u64) as usize].as_bytes();
        match rng.next_u64() % 6 {
            0 | 1 => {
                let mut s = pos;
                while s > 1 && !b[s - 1].is_ascii_whitespace() {
                    s -= 1;
                }
                let mut e = pos;
                while e < b.len() && !b[e].is_ascii_whitespace() {
                    e += 1;
                }
                b.splice(s..e, token.iter().copied());
            }
            2 => {
                b.splice(pos..pos, token.iter().chain(b" ").copied());
            }
            3 => {
                let s = b[..pos]
                    .iter()
                    .rposition(|&c| c == b'\n')
                    .map_or(1, |i| i + 1);
                let e = b[pos..]
                    .iter()
                    .position(|&c| c == b'\n')
                    .map_or(b.len(), |i| pos + i + 1);
                if rng.next_u64().is_multiple_of(2) {
                    b.drain(s..e);
                } else {
                    let line = b[s..e].to_vec();
                    b.splice(e..e, line);
                }
            }
            4 => b.truncate(pos),
            _ => {
                if pos < b.len() {
                    b[pos] ^= 1 << (rng.next_u64() % 8);
                }
            }
        }
    }
    b
}

#[test]
fn mutations() {
    let seeds: Vec<Vec<u8>> = seeds().into_iter().map(|(_, b)| b).collect();
    let mut rng = SplitMix64(21);
    let mut read = 0;
    let iters = std::env::var("TETRAYS_FUZZ_ITERS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1500);
    for i in 0..iters {
        let b = mutate(&mut rng, &seeds[i % seeds.len()]);
        read += bounded(&b) as usize;
    }
    // Some mutations keep the file readable (e.g. a changed value).
    assert!(read > 0);
    println!("{read} of {iters} mutated inputs read");
}
