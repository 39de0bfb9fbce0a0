//! cargo-fuzz target `tetgen_files`: a thin wrapper around the shared body in
//! `fuzz/targets_common/tetgen_files.rs` (also run on stable by the corpus tests).
#![no_main]

use libfuzzer_sys::fuzz_target;

#[allow(dead_code)]
mod input {
    include!("../targets_common/input.rs");
}
#[allow(dead_code)]
mod tetgen_files {
    include!("../targets_common/tetgen_files.rs");
}

fuzz_target!(|data: &[u8]| {
    tetgen_files::check(data);
});
