//! Helpers shared by the kernel test binaries.

use tet_core::TetMesh;
use tet_core::synthetic::{GridSpec, kuhn_grid};

/// A validated jittered Kuhn grid of `cells³` cells with a `fraction` of
/// random constrained faces, or (with `shell`) a closed shell one cell in.
pub fn grid(cells: u32, jitter: f32, fraction: f64, shell: bool, seed: u64) -> TetMesh {
    let m = kuhn_grid(&GridSpec {
        cells: [cells; 3],
        jitter,
        constrained_fraction: fraction,
        shell: shell.then_some(([1; 3], [cells - 1; 3])),
        seed,
        ..Default::default()
    });
    m.validate().unwrap();
    m
}
