//! cargo-fuzz target `xor_codecs`: a thin wrapper around the shared body in
//! `fuzz/targets_common/xor_codecs.rs` (also run on stable by the corpus tests).
#![no_main]

use libfuzzer_sys::fuzz_target;

#[allow(dead_code)]
mod input {
    include!("../targets_common/input.rs");
}
#[allow(dead_code)]
mod grid {
    include!("../targets_common/grid.rs");
}
#[allow(dead_code)]
mod xor_codecs {
    include!("../targets_common/xor_codecs.rs");
}

fuzz_target!(|data: &[u8]| {
    xor_codecs::check(data);
});
