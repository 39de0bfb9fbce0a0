//! The `traversal` fuzz target's body (fuzz/targets_common/traversal.rs) on
//! stable: over the checked-in seed corpus and over every regression the
//! fuzzer found. Each input is a small mesh plus rays; every kernel must end
//! within its step cap with a well-formed outcome (see the target's docs).

#[allow(dead_code)]
mod input {
    include!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/targets_common/input.rs"
    ));
}
#[allow(dead_code)]
mod grid {
    include!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/targets_common/grid.rs"
    ));
}
#[allow(dead_code)]
mod traversal {
    include!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/targets_common/traversal.rs"
    ));
}

#[allow(dead_code)]
mod corpus {
    include!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/targets_common/corpus.rs"
    ));
}
use corpus::read_seeds;

#[test]
fn traversal_seed_corpus() {
    let seeds = read_seeds("traversal");
    assert!(seeds.len() >= 10);
    for (name, bytes) in seeds {
        assert!(traversal::check(&bytes) > 0, "{name}: traced no ray");
    }
}

/// Rays whose direction mixes subnormal or huge components with ordinary
/// ones used to produce hits with infinite `t` or barycentrics; they are now
/// reported as failures (`Failure::Lost`) or answered correctly.
#[test]
fn traversal_regressions() {
    let found = read_seeds("../regressions/traversal");
    assert!(found.len() >= 5);
    for (name, bytes) in found {
        assert!(traversal::check(&bytes) > 0, "{name}: traced no ray");
    }
}
