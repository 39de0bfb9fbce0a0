//! Scene-level descriptions shared by the builder, the tracers and the bench:
//! a pinhole camera and point lights. Plain data; ray generation lives in the
//! trace crates.

use glam::Vec3;

/// A pinhole camera (conventions of the repository's `scenes/scenes.json`:
/// look-at, world up +y, image plane at distance 1, vertical field of view `vfov_deg`,
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

/// What a mesh file may carry besides the mesh: the scene's camera and point
/// lights, so a mesh built from a scene renders from the scene's viewpoint
/// and lights without the scene description at hand.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneInfo {
    /// The scene's camera, if it has one.
    pub camera: Option<Camera>,
    /// The scene's point lights.
    pub lights: Vec<PointLight>,
}

/// Why a camera or light cannot be used.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SceneInfoError {
    /// A coordinate, colour or angle is NaN or infinite.
    #[error("{what}: non-finite value")]
    NonFinite {
        /// `"camera"` or `"light N"`.
        what: String,
    },
    /// The camera looks at its own position.
    #[error("camera: position equals target")]
    DegenerateView,
    /// The up vector is zero or parallel to the view direction.
    #[error("camera: up vector is zero or parallel to the view direction")]
    DegenerateUp,
    /// The field of view is not in (0°, 180°).
    #[error("camera: vertical field of view {0}° is not in (0, 180)")]
    FieldOfView(f32),
    /// A light has a negative colour component or intensity.
    #[error("light {0}: negative colour or intensity")]
    NegativeLight(usize),
}

impl SceneInfo {
    /// True when there is nothing to store.
    pub fn is_empty(&self) -> bool {
        self.camera.is_none() && self.lights.is_empty()
    }

    /// Checks that the camera defines a view and the lights are finite and
    /// non-negative.
    pub fn validate(&self) -> Result<(), SceneInfoError> {
        if let Some(c) = &self.camera {
            let all = [c.position, c.target, c.up];
            if !all.iter().all(|v| v.is_finite()) || !c.vfov_deg.is_finite() {
                return Err(SceneInfoError::NonFinite {
                    what: "camera".into(),
                });
            }
            let view = c.target - c.position;
            if view == Vec3::ZERO {
                return Err(SceneInfoError::DegenerateView);
            }
            if view.cross(c.up) == Vec3::ZERO {
                return Err(SceneInfoError::DegenerateUp);
            }
            if !(c.vfov_deg > 0.0 && c.vfov_deg < 180.0) {
                return Err(SceneInfoError::FieldOfView(c.vfov_deg));
            }
        }
        for (i, l) in self.lights.iter().enumerate() {
            if !l.position.is_finite() || !l.color.is_finite() || !l.intensity.is_finite() {
                return Err(SceneInfoError::NonFinite {
                    what: format!("light {i}"),
                });
            }
            if l.color.min_element() < 0.0 || l.intensity < 0.0 {
                return Err(SceneInfoError::NegativeLight(i));
            }
        }
        Ok(())
    }
}
