//! Where the camera is when the scene does not say ([`framing_camera`]),
//! and the `--eye`, `--target`, `--up`, `--fov` overrides ([`ViewArgs`],
//! [`apply_view`]).
//!
//! The default camera stands outside the scene, as in every viewer: on the
//! +z side of the centre of the scene's bounding box, looking at it, far
//! enough for the bounding sphere to fit the vertical field of view with a
//! margin. Its
//! primary rays enter the mesh through its boundary
//! (`tet_trace_cpu::Viewpoint`), so a closed object is seen from outside.

use clap::Args;
use glam::Vec3;
use tet_core::TetMesh;
use tet_core::scene::Camera;

/// The view: each flag given replaces that part of the scene's camera (or
/// of the default camera, which frames the whole scene from outside on
/// its +z side). Checked before anything is traced: finite coordinates,
/// an eye away from the target, an up direction not along the line of
/// sight, and a field of view strictly between 0 and 180 degrees.
#[derive(Debug, Clone, Copy, Default, Args)]
pub struct ViewArgs {
    /// Camera position `X,Y,Z`, replacing the scene's camera position (without
    /// a scene camera: outside the scene on its +z side, framing it).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub eye: Option<glam::Vec3>,
    /// Point `X,Y,Z` the camera looks at (default: the scene camera's target,
    /// or the centre of the scene).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub target: Option<glam::Vec3>,
    /// Up direction `X,Y,Z` of the image, across the line of sight (default:
    /// the scene camera's, or +y).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub up: Option<glam::Vec3>,
    /// Vertical field of view in degrees, between 0 and 180 (default: the
    /// scene camera's, or 60).
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    pub fov: Option<f32>,
}

/// Parses `X,Y,Z` (three finite numbers separated by commas).
pub fn parse_vec3(s: &str) -> Result<glam::Vec3, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [x, y, z] = parts.as_slice() else {
        return Err(format!(
            "`{s}` is not a point: give three numbers separated by commas, e.g. 0,1.5,-4"
        ));
    };
    let mut v = [0.0f32; 3];
    for (out, text) in v.iter_mut().zip([x, y, z]) {
        *out = text
            .parse::<f32>()
            .map_err(|_| format!("`{text}` in `{s}` is not a number"))?;
        if !out.is_finite() {
            return Err(format!("`{text}` in `{s}` is not finite"));
        }
    }
    Ok(glam::Vec3::from_array(v))
}

/// Vertical field of view of the default camera, degrees.
pub const DEFAULT_VFOV_DEG: f32 = 60.0;

/// How much wider than the bounding sphere the default view is (1.1: the
/// sphere fills 91 % of the image height).
const FRAMING_MARGIN: f32 = 1.1;

/// A view given on the command line that no camera can have.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ViewError {
    /// The eye and the target are the same point.
    #[error("--eye and --target are the same point ({0}): the camera needs a direction to look in")]
    EyeAtTarget(Vec3),
    /// The up direction is zero or along the line of sight.
    #[error(
        "--up {up} is parallel to the line of sight {direction} (or zero): give an up direction across it"
    )]
    UpAlongView {
        /// The up direction.
        up: Vec3,
        /// Target minus eye.
        direction: Vec3,
    },
    /// The field of view is not strictly between 0 and 180 degrees.
    #[error("--fov {0} must lie strictly between 0 and 180 degrees")]
    Fov(f32),
    /// A coordinate is not finite (a scene's camera, or a flag).
    #[error("the camera's {0} is not finite")]
    NotFinite(&'static str),
}

/// A camera framing the box `min..max` from outside: on its +z side,
/// looking at its centre, at the distance where the bounding sphere fits
/// the vertical field of view with a margin. An empty box (no points)
/// gives the default camera.
pub fn framing_camera_of(min: Vec3, max: Vec3) -> Camera {
    if !(min.is_finite() && max.is_finite()) || min.cmpgt(max).any() {
        return Camera::default();
    }
    let center = (min + max) * 0.5;
    let radius = ((max - min).length() * 0.5).max(1e-6 * center.abs().max_element().max(1.0));
    let half_fov = (DEFAULT_VFOV_DEG * 0.5).to_radians();
    let distance = FRAMING_MARGIN * radius / half_fov.sin();
    Camera {
        position: center + Vec3::Z * distance,
        target: center,
        up: Vec3::Y,
        vfov_deg: DEFAULT_VFOV_DEG,
    }
}

/// The default camera of a scene or mesh without a camera: framing the
/// scene's surface (the vertices of the constrained faces, so that a scene
/// and the mesh file built from it get the same view, whatever enclosing
/// box was added), or every point of a mesh without constrained faces.
pub fn framing_camera(mesh: &TetMesh) -> Camera {
    if mesh.constrained.is_empty() {
        let (min, max) = mesh.point_bounds();
        return framing_camera_of(min, max);
    }
    let (min, max) = mesh
        .constrained
        .iter()
        .flat_map(|cf| cf.vertices)
        .map(|v| mesh.points[v as usize])
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), p| {
            (a.min(p), b.max(p))
        });
    framing_camera_of(min, max)
}

/// `camera` with the parts given in `view` replaced, checked.
pub fn apply_view(camera: Camera, view: &ViewArgs) -> Result<Camera, ViewError> {
    let cam = Camera {
        position: view.eye.unwrap_or(camera.position),
        target: view.target.unwrap_or(camera.target),
        up: view.up.unwrap_or(camera.up),
        vfov_deg: view.fov.unwrap_or(camera.vfov_deg),
    };
    check(&cam)?;
    Ok(cam)
}

/// Checks that `cam` describes a view: finite, eye away from the target,
/// up across the line of sight, field of view in (0°, 180°).
pub fn check(cam: &Camera) -> Result<(), ViewError> {
    for (name, v) in [
        ("eye", cam.position),
        ("target", cam.target),
        ("up direction", cam.up),
    ] {
        if !v.is_finite() {
            return Err(ViewError::NotFinite(name));
        }
    }
    if !(cam.vfov_deg > 0.0 && cam.vfov_deg < 180.0) {
        return Err(ViewError::Fov(cam.vfov_deg));
    }
    let direction = cam.target - cam.position;
    if direction == Vec3::ZERO {
        return Err(ViewError::EyeAtTarget(cam.position));
    }
    // Parallel (or zero) when the sine of their angle is below ~1e-4.
    let cross = direction.normalize().cross(cam.up.normalize_or_zero());
    if cross.length() < 1e-4 {
        return Err(ViewError::UpAlongView {
            up: cam.up,
            direction,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_camera_sees_the_whole_box_from_outside() {
        let (min, max) = (Vec3::new(-1.0, -2.0, 3.0), Vec3::new(5.0, 2.0, 4.0));
        let cam = framing_camera_of(min, max);
        let center = (min + max) * 0.5;
        assert_eq!(cam.target, center);
        assert!(cam.position.z > max.z, "outside, on the +z side: {cam:?}");
        // Every corner lies inside the vertical and horizontal (square
        // image) field of view.
        let forward = (cam.target - cam.position).normalize();
        let half = (cam.vfov_deg * 0.5).to_radians();
        for i in 0..8 {
            let corner = Vec3::new(
                if i & 1 == 0 { min.x } else { max.x },
                if i & 2 == 0 { min.y } else { max.y },
                if i & 4 == 0 { min.z } else { max.z },
            );
            let to = (corner - cam.position).normalize();
            assert!(
                to.dot(forward).acos() < half,
                "corner {corner} outside the view"
            );
        }
        assert_eq!(
            framing_camera_of(Vec3::INFINITY, Vec3::NEG_INFINITY),
            Camera::default()
        );
    }

    #[test]
    fn views_are_checked() {
        let cam = framing_camera_of(Vec3::ZERO, Vec3::ONE);
        let ok = ViewArgs {
            eye: Some(Vec3::new(0.0, 0.0, -5.0)),
            ..ViewArgs::default()
        };
        let moved = apply_view(cam, &ok).unwrap();
        assert_eq!(moved.position, Vec3::new(0.0, 0.0, -5.0));
        assert_eq!(moved.target, cam.target);
        let at_target = ViewArgs {
            eye: Some(cam.target),
            ..ViewArgs::default()
        };
        assert_eq!(
            apply_view(cam, &at_target),
            Err(ViewError::EyeAtTarget(cam.target))
        );
        let up_along = ViewArgs {
            up: Some(cam.target - cam.position),
            ..ViewArgs::default()
        };
        assert!(matches!(
            apply_view(cam, &up_along),
            Err(ViewError::UpAlongView { .. })
        ));
        for fov in [0.0, -10.0, 180.0, 200.0, f32::NAN] {
            let v = ViewArgs {
                fov: Some(fov),
                ..ViewArgs::default()
            };
            assert!(
                matches!(apply_view(cam, &v), Err(ViewError::Fov(_))),
                "{fov}"
            );
        }
    }

    #[test]
    fn points_parse_as_three_finite_numbers() {
        assert_eq!(
            parse_vec3("1,-2.5, 3e2"),
            Ok(glam::Vec3::new(1.0, -2.5, 300.0))
        );
        for bad in ["", "1,2", "1,2,3,4", "1,x,3", "1,inf,3", "NaN,0,0", "1;2;3"] {
            assert!(parse_vec3(bad).is_err(), "{bad}");
        }
    }
}
