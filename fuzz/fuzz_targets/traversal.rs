//! cargo-fuzz target `traversal`: a thin wrapper around the shared body in
//! `fuzz/targets_common/traversal.rs`.
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
mod traversal {
    include!("../targets_common/traversal.rs");
}

fuzz_target!(|data: &[u8]| {
    traversal::check(data);
});
