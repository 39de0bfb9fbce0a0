//! cargo-fuzz target `vtk_files`: a thin wrapper around the shared body in
//! `fuzz/targets_common/vtk_files.rs` (also run on stable by
//! crates/tet-build/tests/fuzz_vtk.rs).
#![no_main]

use libfuzzer_sys::fuzz_target;

#[allow(dead_code)]
mod vtk_files {
    include!("../targets_common/vtk_files.rs");
}

fuzz_target!(|data: &[u8]| {
    vtk_files::check(data);
});
