//! Rays in, hits out: the two value types of the public interface.

use glam::Vec3;

/// A ray `p(t) = origin + t * direction`, restricted to `t_min ≤ t ≤ t_max`.
///
/// The direction need not be normalised; `t` is measured in units of its
/// length. A ray whose origin or direction is not finite, or whose direction
/// is zero, hits nothing; direction components smaller than
/// `f32::MIN_POSITIVE` (subnormal) are taken as zero.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Where the ray starts.
    pub origin: Vec3,
    /// Where it goes (any non-zero length).
    pub direction: Vec3,
    /// Smallest accepted hit distance (inclusive).
    pub t_min: f32,
    /// Largest accepted hit distance (inclusive).
    pub t_max: f32,
}

impl Ray {
    /// A ray over `[0, ∞]`.
    pub fn new(origin: Vec3, direction: Vec3) -> Self {
        Self {
            origin,
            direction,
            t_min: 0.0,
            t_max: f32::INFINITY,
        }
    }

    /// Whether the ray can hit anything at all: finite origin and
    /// direction, a non-zero direction and a non-empty `[t_min, t_max]`.
    pub(crate) fn is_traceable(&self) -> bool {
        self.origin.is_finite()
            && self.direction.is_finite()
            && self.direction != Vec3::ZERO
            && self.t_min <= self.t_max
    }
}

/// The closest intersection of a ray with the mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Index of the hit triangle in the *input* triangle slice given to
    /// [`crate::RayStrips::build`].
    pub triangle: u32,
    /// Distance along the ray, in units of the direction's length.
    pub t: f32,
    /// Barycentric weight of the input triangle's second vertex.
    pub u: f32,
    /// Barycentric weight of the input triangle's third vertex, so that the
    /// hit point is `(1 - u - v) * v0 + u * v1 + v * v2` in input order.
    pub v: f32,
}
