//! cargo-fuzz target `job_files`: a thin wrapper around the shared body in
//! `fuzz/targets_common/job_files.rs` (also run on stable by the corpus
//! tests). Needs the fuzz crate's `job` feature, on by default (the
//! out-of-core job module lives behind tet-build's `tetgen` feature).
#![no_main]

use libfuzzer_sys::fuzz_target;

#[allow(dead_code)]
mod job_files {
    include!("../targets_common/job_files.rs");
}

fuzz_target!(|data: &[u8]| {
    job_files::check(data);
});
