//! cargo-fuzz target `mesh_file`: a thin wrapper around the shared body in
//! `fuzz/targets_common/mesh_file.rs` (also run on stable by the corpus tests).
#![no_main]

use libfuzzer_sys::fuzz_target;

#[allow(dead_code)]
mod input {
    include!("../targets_common/input.rs");
}
#[allow(dead_code)]
mod mesh_file {
    include!("../targets_common/mesh_file.rs");
}

fuzz_target!(|data: &[u8]| {
    mesh_file::check(data);
});
