//! Which rays a frame casts (`render --rays`) and the speed of each kind
//! (the render JSON's `rays_kind` and `by_kind`).

use clap::ValueEnum;
use serde::Serialize;
use tet_trace_cpu::render::{FrameStats, RenderOptions};

/// The rays of a frame: primary rays, and per primary hit one
/// ambient-occlusion ray, one shadow ray per point light in front of the
/// surface, or both (the secondary-ray workload of the Tray Racing
/// benchmark, with shadows).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum RayKinds {
    /// Primary rays only.
    #[default]
    Primary,
    /// Primary rays and one AO ray per hit.
    Ao,
    /// Primary rays and shadow rays to the point lights.
    Shadow,
    /// Primary, AO and shadow rays.
    Mixed,
}

impl RayKinds {
    /// The kinds a frame with `opts` casts.
    pub fn of(opts: &RenderOptions) -> Self {
        match (opts.ambient_occlusion, opts.shadows) {
            (false, false) => RayKinds::Primary,
            (true, false) => RayKinds::Ao,
            (false, true) => RayKinds::Shadow,
            (true, true) => RayKinds::Mixed,
        }
    }

    /// These kinds with shadow rays too (`render --shadows`).
    pub fn with_shadows(self, shadows: bool) -> Self {
        match (self, shadows) {
            (RayKinds::Primary, true) => RayKinds::Shadow,
            (RayKinds::Ao, true) => RayKinds::Mixed,
            (k, _) => k,
        }
    }

    /// Whether AO rays are cast.
    pub fn ao(self) -> bool {
        matches!(self, RayKinds::Ao | RayKinds::Mixed)
    }

    /// Whether shadow rays are cast.
    pub fn shadows(self) -> bool {
        matches!(self, RayKinds::Shadow | RayKinds::Mixed)
    }
}

/// Rays of one kind in a frame and their speed.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct KindDoc {
    /// Rays of this kind cast in the frame.
    pub rays: u64,
    /// Million rays per second of tracing this kind: its rays over the
    /// time the workers spent tracing them (summed over the workers,
    /// divided by their number); 0 when none were cast.
    pub mrays_per_s: f64,
    /// Mean tets visited per ray of this kind: tet walks' primary and AO
    /// rays; `null` where not counted (BVH methods, shadow rays).
    pub tets_per_ray: Option<f64>,
}

/// Each kind's rays and speed (`by_kind` of the render JSON).
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct ByKind {
    /// Primary rays.
    pub primary: KindDoc,
    /// Ambient-occlusion rays.
    pub ao: KindDoc,
    /// Shadow rays (point and area lights).
    pub shadow: KindDoc,
}

impl ByKind {
    /// The kinds of the frame `stats`, traced by `threads` workers.
    pub fn of(stats: &FrameStats, threads: usize) -> Self {
        let kind = |rays: u64, ms: f64, tets: u64| KindDoc {
            rays,
            mrays_per_s: FrameStats::kind_mrays_per_s(rays, ms, threads),
            tets_per_ray: (tets > 0).then(|| tets as f64 / rays.max(1) as f64),
        };
        ByKind {
            primary: kind(stats.rays, stats.primary_trace_ms, stats.tets_visited),
            ao: kind(stats.ao_rays, stats.ao_trace_ms, stats.ao_tets_visited),
            shadow: kind(stats.shadow_rays, stats.shadow_trace_ms, 0),
        }
    }
}
