//! The first failing rays of each method, kept with the accuracy counts
//! (JSON `failed_rays[]` of every method of an accuracy case) so that a
//! rare failure seen over 10⁸ rays can be reproduced and studied without
//! running the 10⁸ rays again: the ray, where it started, what the method
//! returned and what the f64 reference found.

use serde::Serialize;
use tet_trace_cpu::{Ray, Start, TraceOutcome};

/// Failing rays kept per method and case.
pub const KEPT: usize = 8;

/// One failing ray.
#[derive(Clone, Debug, Serialize)]
pub struct FailedRay {
    /// The verdict: `Leak`, `WrongTriangle`, `FalseMiss`, `FalseHit`,
    /// `StepCap`, `Lost`, `Invalid` or `Nan`.
    pub verdict: String,
    /// Ray origin, as traced (f32).
    pub origin: [f32; 3],
    /// Ray direction, as traced (f32).
    pub direction: [f32; 3],
    /// Ray interval start.
    pub t_min: f32,
    /// Ray interval end.
    pub t_max: f32,
    /// How the walk started: `tet T`, `face F into tet T`, `entry …`, or
    /// `camera` (the camera's own start).
    pub start: String,
    /// What the method returned (its outcome, as Rust prints it).
    pub outcome: String,
    /// The reference's nearest hit, or `null` for a miss.
    pub reference: Option<ReferenceHit>,
}

/// The f64 reference's nearest hit on a failing ray.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ReferenceHit {
    /// Scene triangle.
    pub triangle: u32,
    /// Ray parameter.
    pub t: f64,
    /// Within the grazing tolerance of an edge of the triangle.
    pub near_edge: bool,
    /// Every line near the ray crosses the surface around the edges and
    /// vertices the hit grazes (a miss there is a leak).
    pub closed: bool,
}

impl FailedRay {
    /// The record of `ray` (started from `start`) judged `verdict`.
    pub fn new(
        verdict: String,
        ray: &Ray,
        start: Option<&Start>,
        outcome: &TraceOutcome,
        reference: Option<ReferenceHit>,
    ) -> FailedRay {
        FailedRay {
            verdict,
            origin: ray.origin.to_array(),
            direction: ray.direction.to_array(),
            t_min: ray.t_min,
            t_max: ray.t_max,
            start: start.map_or_else(|| "camera".into(), |s| format!("{s:?}")),
            outcome: format!("{outcome:?}"),
            reference,
        }
    }
}
