//! What a trace reports: the bytes of the mesh on the GPU, the statistics of
//! a batch or frame, and a camera frame.

use std::time::Instant;

use tet_trace_cpu::TraceOutcome;

/// Bytes of the mesh arrays resident on the GPU.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GpuMemory {
    /// Layout name.
    pub layout: &'static str,
    /// Tet records (20 bytes each for Tet20).
    pub tets: u64,
    /// Points (12 bytes each).
    pub points: u64,
    /// Constrained-face records (24 bytes each).
    pub constrained: u64,
}

impl GpuMemory {
    /// Sum of all arrays.
    pub fn total(&self) -> u64 {
        self.tets + self.points + self.constrained
    }
}

/// Statistics of one batch or frame, with the fields of the CPU renderer's
/// `FrameStats` (so `tet-bench` can report GPU methods the same way).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DispatchStats {
    /// Method name (`"gpu-tet20"`, ..., `"gpu-bvh"`).
    pub method: String,
    /// Adapter, from [`GpuContext::device_name`](crate::GpuContext::device_name).
    pub device: String,
    /// Summed GPU time of the kernel dispatches (timestamp queries), ms;
    /// `None` when the adapter has no timestamp queries.
    pub gpu_ms: Option<f64>,
    /// Wall time from the first submit to the last result on the host
    /// (includes uploads of per-ray data and read-back, and the host-side
    /// starts; excludes the host re-walks of lost walks, which are in
    /// [`DispatchStats::host_rewalk_ms`]), ms.
    pub wall_ms: f64,
    /// Number of dispatches.
    pub dispatches: u32,
    /// Rays traced.
    pub rays: u64,
    /// Rays that hit a constrained face.
    pub hits: u64,
    /// Rays that failed (step cap, lost, invalid).
    pub failures: u64,
    /// Tets visited by all rays (for a re-walked ray, both walks' tets);
    /// for the BVH ([`GpuBvh`](crate::GpuBvh), method `"gpu-bvh"`), the
    /// BVH boxes tested, the root's included.
    pub tets_visited: u64,
    /// Rays whose GPU walk lost its way (reached the default step cap, or
    /// found no start: `Failure::StepCap`, `Failure::Lost`) and that the
    /// host walked again with the exact walk
    /// ([`tet_trace_cpu::exact::ExactTracer`]), as the CPU tracers do (see
    /// the crate docs, "Walks that lost their way").
    pub host_rewalks: u64,
    /// Host (CPU) time of those exact re-walks, ms: kept apart from
    /// [`DispatchStats::gpu_ms`] and [`DispatchStats::wall_ms`] so that the
    /// GPU timings measure the GPU walk alone.
    pub host_rewalk_ms: f64,
}

impl DispatchStats {
    /// The time to report: GPU time when measured, wall time otherwise (ms).
    pub fn ms(&self) -> f64 {
        self.gpu_ms.unwrap_or(self.wall_ms)
    }

    /// Million rays per second over [`DispatchStats::ms`].
    pub fn mrays_per_s(&self) -> f64 {
        self.rays as f64 / (self.ms() * 1e3)
    }

    /// Wall time plus the host re-walks: the time the caller waited, ms.
    pub fn total_ms(&self) -> f64 {
        self.wall_ms + self.host_rewalk_ms
    }

    /// Adds the dispatches, GPU time and host re-walks of `other` (a
    /// nested batch, e.g. the camera rays re-traced through the batch path).
    pub(crate) fn absorb(&mut self, other: &DispatchStats) {
        self.dispatches += other.dispatches;
        if let (Some(a), Some(b)) = (self.gpu_ms, other.gpu_ms) {
            self.gpu_ms = Some(a + b);
        }
        self.host_rewalks += other.host_rewalks;
        self.host_rewalk_ms += other.host_rewalk_ms;
    }

    pub(crate) fn count(&mut self, outcomes: &[TraceOutcome]) {
        self.rays += outcomes.len() as u64;
        for o in outcomes {
            self.hits += o.hit().is_some() as u64;
            self.failures += o.is_failure() as u64;
            self.tets_visited += o.tets_visited() as u64;
        }
    }
}

/// A camera frame traced on the GPU.
#[derive(Clone, Debug, PartialEq)]
pub struct GpuFrame {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Outcome per pixel, row-major from the top.
    pub outcomes: Vec<TraceOutcome>,
    /// Statistics of the whole frame (re-traced rays and host re-walks of
    /// lost walks included).
    pub stats: DispatchStats,
    /// Rays whose origin lay on the start tet's boundary so that the GPU
    /// start failed; they were re-traced through
    /// [`GpuTracer::trace_batch`](crate::GpuTracer::trace_batch).
    pub retraced: u64,
}

impl GpuFrame {
    /// The frame of `outcomes`, with the wall time since `t0` and the
    /// outcomes counted into `stats`.
    pub(crate) fn done(
        width: u32,
        height: u32,
        outcomes: Vec<TraceOutcome>,
        mut stats: DispatchStats,
        t0: Instant,
        retraced: u64,
    ) -> GpuFrame {
        stats.wall_ms = (t0.elapsed().as_secs_f64() * 1e3 - stats.host_rewalk_ms).max(0.0);
        stats.count(&outcomes);
        GpuFrame {
            width,
            height,
            outcomes,
            stats,
            retraced,
        }
    }

    /// Hit triangle per pixel (`u32::MAX` for none), as in the CPU `Frame`.
    pub fn triangles(&self) -> Vec<u32> {
        self.outcomes
            .iter()
            .map(|o| o.hit().map_or(u32::MAX, |h| h.triangle))
            .collect()
    }
}
