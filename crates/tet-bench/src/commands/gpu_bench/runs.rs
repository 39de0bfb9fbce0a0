//! From timed dispatches to a row: the fastest and median kernel times,
//! which clock measured them, and the hits against the CPU walk's.

use tet_trace_gpu::DispatchStats;

use super::compare::hits;
use super::doc::{Differences, GpuBytes, Row, Seen};

/// What one method did on one batch of rays, to become a [`Row`].
pub struct Measured<'a> {
    /// Scene name.
    pub scene: &'a str,
    /// Method name (`gpu-tet20`, `gpu-bvh`).
    pub method: &'a str,
    /// `primary`, `shadow` or `bounce`.
    pub kind: &'static str,
    /// The timed dispatches (at least one).
    pub runs: &'a [DispatchStats],
    /// What the GPU found per ray (the warm-up dispatch's outcomes).
    pub gpu: &'a [Seen],
    /// What the CPU walk found on the same rays.
    pub cpu: &'a [Seen],
    /// The CPU walk's name.
    pub reference: &'a str,
    /// The rays that differ.
    pub differences: Differences,
    /// Tets visited per ray (`None` for the BVH).
    pub tets_per_ray: Option<f64>,
    /// BVH boxes tested per ray (`None` for the walks).
    pub nodes_per_ray: Option<f64>,
    /// Bytes on the GPU.
    pub gpu_bytes: GpuBytes,
    /// Encoding and upload, or BVH build, ms.
    pub setup_ms: f64,
    /// The paper's kernel ms, where it has one.
    pub paper_ms: Option<f64>,
}

impl Measured<'_> {
    /// The row: the fastest dispatch by kernel time (timestamps, else wall
    /// time), the median, and the counts.
    pub fn row(self) -> Row {
        let mut ms: Vec<f64> = self.runs.iter().map(DispatchStats::ms).collect();
        ms.sort_by(f64::total_cmp);
        let best = self
            .runs
            .iter()
            .min_by(|a, b| a.ms().total_cmp(&b.ms()))
            .cloned()
            .unwrap_or_default();
        let kernel_ms = best.ms();
        let rays = self.gpu.len() as u64;
        let mrays_per_s = if kernel_ms > 0.0 {
            rays as f64 / (kernel_ms * 1e3)
        } else {
            0.0
        };
        Row {
            scene: self.scene.to_string(),
            method: self.method.to_string(),
            kind: self.kind,
            rays,
            kernel_ms,
            median_ms: ms.get(ms.len() / 2).copied().unwrap_or(0.0),
            mrays_per_s,
            grays_per_s: mrays_per_s / 1e3,
            timing: if best.gpu_ms.is_some() {
                "timestamp"
            } else {
                "wall"
            },
            dispatches: self.runs.len() as u32,
            wall_ms: best.wall_ms,
            outside_kernel_ms: (best.wall_ms - kernel_ms).max(0.0),
            host_rewalks: best.host_rewalks,
            hits: hits(self.gpu),
            cpu_hits: hits(self.cpu),
            reference: self.reference.to_string(),
            differences: self.differences,
            failures: self
                .gpu
                .iter()
                .filter(|s| matches!(s, Seen::Failed))
                .count() as u64,
            tets_per_ray: self.tets_per_ray,
            nodes_per_ray: self.nodes_per_ray,
            gpu_bytes: self.gpu_bytes,
            setup_ms: self.setup_ms,
            paper_ms: self.paper_ms,
            ratio_to_paper: self.paper_ms.map(|p| kernel_ms / p),
        }
    }
}
