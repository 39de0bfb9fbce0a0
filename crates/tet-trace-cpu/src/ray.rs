//! Rays, hit records and trace outcomes shared by every kernel.

use glam::Vec3;
use tet_core::NO_TET;

/// Default cap on the number of tets one walk may visit before it is
/// reported as a [`Failure::StepCap`] (a would-be infinite walk never hangs).
pub const DEFAULT_STEP_CAP: u32 = 1 << 20;

/// A ray `origin + t * direction`, `t ∈ [t_min, t_max]`.
///
/// `direction` need not be normalised; `t` is measured in units of it.
/// Constrained faces crossed at `t < t_min` are walked through (used by
/// secondary rays); a first hit at `t > t_max` is reported as a miss (shadow
/// rays use `t_max` = distance to the light).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Start point.
    pub origin: Vec3,
    /// Direction (any non-zero length).
    pub direction: Vec3,
    /// Smallest accepted hit parameter.
    pub t_min: f32,
    /// Largest accepted hit parameter.
    pub t_max: f32,
}

impl Ray {
    /// A ray accepting every hit with `t ≥ 0`.
    pub fn new(origin: Vec3, direction: Vec3) -> Ray {
        Ray {
            origin,
            direction,
            t_min: 0.0,
            t_max: f32::INFINITY,
        }
    }

    /// Point at parameter `t`.
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.direction * t
    }

    /// True when origin and direction are finite and the direction non-zero
    /// (of any size: a scene at 1e-30 has directions whose squared length
    /// underflows f32).
    pub fn is_valid(&self) -> bool {
        self.origin.is_finite()
            && self.direction.is_finite()
            && self.direction != Vec3::ZERO
            && !self.t_min.is_nan()
            && !self.t_max.is_nan()
    }
}

/// The first constrained face a ray crosses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Scene triangle id ([`tet_core::ConstrainedFace::triangle`]).
    pub triangle: u32,
    /// Index of the constrained face in [`tet_core::TetMesh::constrained`].
    pub face: u32,
    /// Ray parameter of the hit point.
    pub t: f32,
    /// Barycentric weights of the hit point w.r.t.
    /// [`tet_core::ConstrainedFace::vertices`] (sum 1).
    pub barycentrics: [f32; 3],
    /// Tet the ray was in when it reached the face.
    pub tet: u32,
    /// Tet on the other side of the face ([`NO_TET`] on the mesh boundary).
    pub far_tet: u32,
    /// Number of tets the walk visited (the start tet included).
    pub tets_visited: u32,
}

impl Hit {
    /// True when a tet exists beyond the hit face.
    pub fn has_far_side(&self) -> bool {
        self.far_tet != NO_TET
    }
}

/// Why a walk gave up.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Failure {
    /// More than the step cap tets were visited (a loop or a huge mesh).
    StepCap,
    /// The ray has a NaN/infinite component or a zero direction.
    InvalidRay,
    /// No tet around the origin has an exit face for this ray: the start tet
    /// does not contain the origin, or the projection degenerated.
    Lost,
}

/// Result of tracing one ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TraceOutcome {
    /// The ray crossed a constrained face with `t ∈ [t_min, t_max]`.
    Hit(Hit),
    /// The ray left the mesh through its boundary, or its first hit lies
    /// beyond `t_max`.
    Miss {
        /// Tets visited.
        tets_visited: u32,
    },
    /// The walk failed (reported, never a hang or a silent wrong answer).
    Failed {
        /// Why.
        failure: Failure,
        /// Tets visited before giving up.
        tets_visited: u32,
    },
}

impl TraceOutcome {
    /// True when the walk lost its way: it stopped at its step cap, or
    /// found no start tet holding the ray's line ([`Failure::Lost`]). The
    /// tracers then walk the ray again with the exact walk (at the default
    /// step cap, which no line's walk reaches).
    pub fn lost_its_way(&self) -> bool {
        matches!(
            self,
            TraceOutcome::Failed {
                failure: Failure::StepCap | Failure::Lost,
                ..
            }
        )
    }

    /// This outcome with `spent` more tets visited: the outcome of a walk
    /// redone after another walk spent `spent` tets on the same ray.
    pub fn with_tets_added(self, spent: u32) -> TraceOutcome {
        match self {
            TraceOutcome::Hit(mut h) => {
                h.tets_visited = h.tets_visited.saturating_add(spent);
                TraceOutcome::Hit(h)
            }
            TraceOutcome::Miss { tets_visited } => TraceOutcome::Miss {
                tets_visited: tets_visited.saturating_add(spent),
            },
            TraceOutcome::Failed {
                failure,
                tets_visited,
            } => TraceOutcome::Failed {
                failure,
                tets_visited: tets_visited.saturating_add(spent),
            },
        }
    }

    /// The hit, if any.
    pub fn hit(&self) -> Option<&Hit> {
        match self {
            TraceOutcome::Hit(h) => Some(h),
            _ => None,
        }
    }

    /// Tets visited by the walk.
    pub fn tets_visited(&self) -> u32 {
        match *self {
            TraceOutcome::Hit(h) => h.tets_visited,
            TraceOutcome::Miss { tets_visited } => tets_visited,
            TraceOutcome::Failed { tets_visited, .. } => tets_visited,
        }
    }

    /// True for [`TraceOutcome::Failed`].
    pub fn is_failure(&self) -> bool {
        matches!(self, TraceOutcome::Failed { .. })
    }
}
