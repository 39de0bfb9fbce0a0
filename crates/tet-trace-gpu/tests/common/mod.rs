//! Helpers shared by the GPU tests: the adapter (or a skip message, or a
//! failure under `TET_GPU_REQUIRED=1`), the grazing tolerance and the
//! random rays.

#![allow(dead_code)]

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::scene::Camera;
use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};
use tet_trace_cpu::reference::{Aim, random_ray};
use tet_trace_cpu::{Ray, Start};
use tet_trace_gpu::{GpuContext, GpuOptions, REQUIRE_ADAPTER_ENV};

/// Distance to a constrained-face edge below which a ray counts as grazing
/// (meshes have unit cells; scaled with the mesh where a test scales it).
pub const GRAZE: f64 = 1e-4;

/// Whether `TET_GPU_REQUIRED` turns a missing adapter into a failure.
pub fn required() -> bool {
    std::env::var(REQUIRE_ADAPTER_ENV).is_ok_and(|v| !v.is_empty() && v != "0")
}

/// The adapter, or `None` (with a printed skip message) when there is none.
pub fn gpu_with(opts: &GpuOptions) -> Option<GpuContext> {
    match GpuContext::with_options(opts) {
        Ok(c) => {
            eprintln!("adapter: {}", c.device_name());
            Some(c)
        }
        Err(e) => {
            assert!(
                !required(),
                "{REQUIRE_ADAPTER_ENV} is set but no GPU adapter is available: {e}"
            );
            eprintln!(
                "SKIPPED: no wgpu adapter ({e}). Install a Vulkan driver (lavapipe: \
                 apt-get install -y mesa-vulkan-drivers) or set {REQUIRE_ADAPTER_ENV}=1 \
                 to make this a failure."
            );
            None
        }
    }
}

/// The adapter with the default options.
pub fn gpu() -> Option<GpuContext> {
    gpu_with(&GpuOptions::default())
}

/// Random rays from interior points toward random directions, vertices,
/// edge midpoints and face centroids, with the tet holding each origin.
pub fn random_rays(mesh: &TetMesh, n: usize, seed: u64) -> (Vec<Ray>, Vec<Start>) {
    let mut rng = SplitMix64(seed);
    let aims = [
        Aim::Random,
        Aim::Vertex,
        Aim::EdgeMidpoint,
        Aim::FaceCentroid,
    ];
    (0..n)
        .map(|i| {
            let (r, t) = random_ray(mesh, &mut rng, aims[i % 4]);
            (r, Start::Tet(t))
        })
        .unzip()
}

/// The camera tests' scene: a jittered 6³ grid with a closed shell around
/// cells 2..4 and 2 % of the other faces constrained, and a camera inside
/// the grid looking at the shell.
pub fn shell_in_view() -> (TetMesh, Camera) {
    let mesh = kuhn_grid(&GridSpec {
        cells: [6, 6, 6],
        jitter: 0.1,
        constrained_fraction: 0.02,
        shell: Some(([2, 2, 2], [4, 4, 4])),
        seed: 17,
        ..Default::default()
    });
    let camera = Camera {
        position: Vec3::new(0.55, 4.3, 0.8),
        target: Vec3::new(3.0, 3.0, 3.0),
        up: Vec3::Y,
        vfov_deg: 45.0,
    };
    (mesh, camera)
}
