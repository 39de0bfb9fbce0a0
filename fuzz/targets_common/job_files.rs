// Body of the `job_files` fuzz target: the files of an out-of-core job
// directory that a part's run, the merge and `job status` read back —
// `job.json` (`JobManifest::from_json`), a part's input file
// (`part_input::decode`) and the run records (`part-K.done.json`,
// `part-K.error.json`, `part-K.running.json`).
//
// Input layout: byte 0 chooses the file (0: `job.json`, 1: a part input,
// 2: a run record), the rest is the file's bytes.
//
// Property: each reader returns a typed error or a value that the writer
// gives back unchanged — a manifest survives `to_json` + `from_json`, and
// every part's paths and its partition tree can be formed from it; a
// decoded part input re-encodes to the very bytes and digest read; a
// record survives serialisation. Never a panic.

use std::path::Path;

use tet_build::outofcore::job::part_input::{decode, encode};
use tet_build::outofcore::job::{DoneRecord, ErrorRecord, JobManifest, RunningRecord};

/// The file a fuzz input is, and its bytes.
pub fn split(data: &[u8]) -> (u8, &[u8]) {
    data.split_first().map_or((0, &[][..]), |(k, r)| (*k % 3, r))
}

/// One fuzz input: the kind byte, then the file.
pub fn join(kind: u8, file: &[u8]) -> Vec<u8> {
    let mut out = vec![kind];
    out.extend_from_slice(file);
    out
}

/// Runs one input; true when the file was accepted.
pub fn check(data: &[u8]) -> bool {
    let (kind, file) = split(data);
    match kind {
        0 => check_manifest(file),
        1 => check_part_input(file),
        _ => check_record(file),
    }
}

fn check_manifest(file: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(file) else {
        return false;
    };
    let path = Path::new("job/job.json");
    let Ok(m) = JobManifest::from_json(text, path) else {
        return false;
    };
    let again = JobManifest::from_json(&m.to_json(), path).expect("a written manifest reads back");
    assert_eq!(again, m, "job.json round trip");
    for k in 0..m.parts.len() {
        let paths = m.part_paths(Path::new("job"), k);
        assert!(paths.input.starts_with("job") && paths.result.starts_with("job"));
    }
    if let tet_build::outofcore::job::manifest::Partition::Tree { tree, .. } = &m.partition {
        let _ = tree.cut_tree();
    }
    true
}

fn check_part_input(file: &[u8]) -> bool {
    let Ok((input, digest)) = decode(file) else {
        return false;
    };
    let (bytes, again) = encode(&input);
    assert_eq!(again, digest, "part input digest");
    assert!(bytes == file, "a decoded part input re-encodes to other bytes");
    true
}

fn check_record(file: &[u8]) -> bool {
    fn round_trip<T>(file: &[u8]) -> bool
    where
        T: serde::Serialize + for<'de> serde::Deserialize<'de> + PartialEq + std::fmt::Debug,
    {
        let Ok(r) = serde_json::from_slice::<T>(file) else {
            return false;
        };
        let text = serde_json::to_string(&r).expect("a record serializes");
        assert_eq!(serde_json::from_str::<T>(&text).expect("reads back"), r);
        true
    }
    // Every kind is tried: a file is one of them at most (unknown fields
    // are refused), and none may panic.
    let done = round_trip::<DoneRecord>(file);
    let error = round_trip::<ErrorRecord>(file);
    let running = round_trip::<RunningRecord>(file);
    done || error || running
}
