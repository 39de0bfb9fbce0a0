//! The `job_files` fuzz target, run on the stable toolchain: its body
//! (`fuzz/targets_common/job_files.rs`, shared verbatim with the cargo-fuzz
//! binary through `include!`) over the checked-in seed corpus
//! `fuzz/seeds/job_files/` — a real job's `job.json`, part input and run
//! records — and over mutations of it generated here: corrupted and
//! truncated job files are typed errors, never a panic, and what is read
//! back is what the writers write.
//!
//! `write_seed_corpus` (`#[ignore]`d) regenerates the seeds from a job
//! planned here.
#![cfg(feature = "tetgen")]

use tet_build::outofcore::job::{PlanOptions, plan_job};
use tet_build::outofcore::memory_model::knot_grid;
use tet_core::synthetic::SplitMix64;

#[allow(dead_code)]
mod job_files {
    include!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/targets_common/job_files.rs"
    ));
}
#[allow(dead_code)]
mod corpus {
    include!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/targets_common/corpus.rs"
    ));
}
#[allow(dead_code)]
mod counting_alloc {
    include!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/targets_common/counting_alloc.rs"
    ));
}
use corpus::{read_seeds, seed_dir};

#[global_allocator]
static ALLOCATOR: counting_alloc::Counting = counting_alloc::Counting;

/// Runs the body on `data`, checking that it never holds more than a
/// small multiple of the input at once (a count in a header must not size
/// an allocation).
fn bounded(data: &[u8]) -> bool {
    let (accepted, peak) = counting_alloc::peak_bytes(|| job_files::check(data));
    assert!(
        peak <= 64 * data.len() + (1 << 20),
        "a {}-byte job file allocated {peak} bytes at once",
        data.len()
    );
    accepted
}

/// A job planned from a small scene: its `job.json`, part 0's input and
/// one record of each kind, as fuzz inputs.
fn seeds() -> Vec<(String, Vec<u8>)> {
    let dir = tempfile::tempdir().unwrap();
    let job = plan_job(
        &knot_grid(1, 40, 6),
        &PlanOptions {
            parts: 2,
            ..PlanOptions::default()
        },
        dir.path(),
    )
    .unwrap();
    let read = |p: std::path::PathBuf| std::fs::read(p).unwrap();
    let paths = job.part_paths(dir.path(), 0);
    let done = format!(
        r#"{{"part":0,"input_digest":"{}","result_digest":"xxh64:0123456789abcdef","result_bytes":1234,"points":10,"tets":20,"constrained":5,"predicted_peak_bytes":1048576,"tetgen_peak_kib":900,"process_peak_kib":null,"seconds":0.25,"host":"node-1"}}"#,
        job.parts[0].input_digest
    );
    let error = r#"{"part":1,"kind":"input","message":"part 1: checksum","input_digest":"xxh64:0000000000000000","host":"node-2"}"#;
    let running = r#"{"part":1,"host":"node-2","pid":4242,"process_start":123456,"started_unix_s":1764000000,"slurm_task":"77_1"}"#;
    vec![
        (
            "job_json".into(),
            job_files::join(0, &read(dir.path().join("job.json"))),
        ),
        ("part_input".into(), job_files::join(1, &read(paths.input))),
        ("done_record".into(), job_files::join(2, done.as_bytes())),
        ("error_record".into(), job_files::join(2, error.as_bytes())),
        (
            "running_record".into(),
            job_files::join(2, running.as_bytes()),
        ),
    ]
}

#[test]
#[ignore = "rewrites fuzz/seeds/job_files/"]
fn write_seed_corpus() {
    let dir = seed_dir("job_files");
    std::fs::create_dir_all(&dir).unwrap();
    for (name, bytes) in seeds() {
        std::fs::write(dir.join(name), bytes).unwrap();
    }
}

#[test]
fn every_seed_is_accepted_and_reads_back() {
    for (name, bytes) in read_seeds("job_files").iter().chain(&seeds()) {
        assert!(bounded(bytes), "{name}: a valid job file was refused");
    }
}

/// One to three mutations of `file`: flip a byte, overwrite a byte with an
/// extreme value, delete or duplicate a range, truncate.
fn mutate(rng: &mut SplitMix64, file: &[u8]) -> Vec<u8> {
    let mut b = file.to_vec();
    for _ in 0..1 + rng.next_u64() % 3 {
        if b.is_empty() {
            break;
        }
        let at = (rng.next_u64() % b.len() as u64) as usize;
        match rng.next_u64() % 5 {
            0 => b[at] ^= 1 << (rng.next_u64() % 8),
            1 => b[at] = [0, 0xff, b'9', b'"', b'-'][(rng.next_u64() % 5) as usize],
            2 => {
                let end = (at + 1 + (rng.next_u64() % 16) as usize).min(b.len());
                b.drain(at..end);
            }
            3 => {
                let end = (at + 1 + (rng.next_u64() % 16) as usize).min(b.len());
                let copy = b[at..end].to_vec();
                b.splice(at..at, copy);
            }
            _ => b.truncate(at),
        }
    }
    b
}

#[test]
fn corrupted_and_truncated_job_files_are_typed_errors() {
    let seeds = seeds();
    let mut rng = SplitMix64(19);
    let mut accepted = 0;
    for i in 0..3000 {
        let (kind, file) = job_files::split(&seeds[i % seeds.len()].1);
        // The kind byte stays: each mutation hits the file's own reader.
        let b = job_files::join(kind, &mutate(&mut rng, file));
        accepted += bounded(&b) as usize;
    }
    // Some mutations keep a file valid (a changed digit of a JSON number);
    // a part input's checksum refuses every change.
    assert!(accepted > 0 && accepted < 3000, "{accepted}");
}

#[test]
fn a_part_input_with_any_byte_changed_is_refused() {
    let seeds = seeds();
    let (kind, file) = job_files::split(&seeds[1].1);
    assert_eq!(kind, 1);
    for at in (0..file.len()).step_by(7) {
        let mut b = file.to_vec();
        b[at] ^= 0x10;
        assert!(!bounded(&job_files::join(1, &b)), "byte {at} changed");
    }
    for len in [0, 7, 39, 40, file.len() - 9, file.len() - 1] {
        assert!(!bounded(&job_files::join(1, &file[..len])), "cut at {len}");
    }
}
