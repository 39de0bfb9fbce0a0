//! Scene-level descriptions shared by the builder, the tracers and the bench:
//! a pinhole camera and point lights. Plain data; ray generation lives in the
//! trace crates.

use glam::Vec3;

/// A pinhole camera (conventions of `../shared/scenes/scenes.json`: look-at,
/// world up +y, image plane at distance 1, vertical field of view `vfov_deg`,
/// pixel `(i, j)` maps to `2i/W - 1`, `1 - 2j/H` without a half-pixel offset
/// unless the renderer is asked for pixel centres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub position: Vec3,
    /// Point looked at.
    pub target: Vec3,
    /// World up vector.
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub vfov_deg: f32,
}

impl Default for Camera {
    fn default() -> Self {
        Camera {
            position: Vec3::new(0.0, 0.0, 10.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            vfov_deg: 45.0,
        }
    }
}

/// A point light (no distance falloff, as in the papers' renderer).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    /// Position.
    pub position: Vec3,
    /// Linear RGB colour.
    pub color: Vec3,
    /// Intensity multiplier.
    pub intensity: f32,
}
