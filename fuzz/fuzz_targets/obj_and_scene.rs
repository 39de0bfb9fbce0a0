//! cargo-fuzz target `obj_and_scene`: a thin wrapper around the shared body in
//! `fuzz/targets_common/obj_and_scene.rs` (also run on stable by the corpus tests).
#![no_main]

use libfuzzer_sys::fuzz_target;

#[allow(dead_code)]
mod input {
    include!("../targets_common/input.rs");
}
#[allow(dead_code)]
mod obj_and_scene {
    include!("../targets_common/obj_and_scene.rs");
}

fuzz_target!(|data: &[u8]| {
    obj_and_scene::check(data);
});
