//! Object transforms and the orbit camera of `scenes.json`.
//!
//! Conventions (the `conventions` block of the repository's
//! `scenes/scenes.json`, transcribed from the authors' renderer neptun):
//!
//! * `world = T(translation) · R · S(scale) · local`, with
//!   `R = Ry(rotation_deg.y) · Rx(rotation_deg.x) · Rz(rotation_deg.z)`
//!   (glm's `eulerAngleYXZ(yaw = y, pitch = x, roll = z)`), angles in degrees;
//! * a mesh's `pre_transform` is applied to local vertices *before* the object
//!   transform: `world = M_object · M_pre · local`;
//! * a transform with a negative determinant (an odd number of negative scale
//!   factors, e.g. the box objects' `(-2.1, -1.1, -2.1)`) mirrors the mesh: the
//!   triangles keep their index order, so their geometric (right-hand) normals
//!   now point to the other side of the surface (the box faces inward). Vertex
//!   normals follow the same flip: they are transformed by the inverse
//!   transpose and multiplied by the sign of the determinant, so they always
//!   agree with the geometric normal of the transformed triangles. (neptun
//!   itself keeps the inverse-transpose normal without the sign, which points
//!   away from the winding; a renderer that wants that behaviour negates the
//!   normals of objects whose [`Transform::flips_winding`] is true.)
//! * orbit camera: `dir = (cos oy · cos ox, sin ox, sin oy · cos ox)`,
//!   `position = target + distance · dir`, look at `target`, world up `+y`,
//!   vertical field of view 45°.
//!
//! All arithmetic is done in f64 and rounded to f32 once at the end.

use glam::{DMat3, DMat4, DVec3, Vec3};
use tet_core::scene::Camera;

/// Translation, rotation (degrees, YXZ order) and per-axis scale of an object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Translation `T`.
    pub translation: DVec3,
    /// Rotation angles in degrees about x, y, z, applied as `Ry · Rx · Rz`.
    pub rotation_deg: DVec3,
    /// Per-axis scale `S` (negative values mirror).
    pub scale: DVec3,
}

impl Default for Transform {
    fn default() -> Self {
        Transform::IDENTITY
    }
}

impl Transform {
    /// The identity transform.
    pub const IDENTITY: Transform = Transform {
        translation: DVec3::ZERO,
        rotation_deg: DVec3::ZERO,
        scale: DVec3::ONE,
    };

    /// A pure translation.
    pub fn translate(t: DVec3) -> Transform {
        Transform {
            translation: t,
            ..Transform::IDENTITY
        }
    }

    /// The rotation matrix `Ry(y) · Rx(x) · Rz(z)` (angles in degrees).
    pub fn rotation_matrix(&self) -> DMat3 {
        let r = self.rotation_deg;
        DMat3::from_rotation_y(r.y.to_radians())
            * DMat3::from_rotation_x(r.x.to_radians())
            * DMat3::from_rotation_z(r.z.to_radians())
    }

    /// The affine matrix `T · R · S`.
    pub fn matrix(&self) -> DMat4 {
        let rs = self.rotation_matrix() * DMat3::from_diagonal(self.scale);
        let mut m = DMat4::from_mat3(rs);
        m.w_axis = self.translation.extend(1.0);
        m
    }

    /// True when the transform mirrors (negative determinant): triangle
    /// winding then faces the other side of the surface.
    pub fn flips_winding(&self) -> bool {
        self.scale.x * self.scale.y * self.scale.z < 0.0
    }
}

/// A composed affine map (point matrix plus normal matrix), ready to apply.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Affine {
    /// Point matrix.
    pub matrix: DMat4,
    /// Normal matrix: inverse transpose of the linear part, times the sign of
    /// its determinant (see the module docs).
    pub normal_matrix: DMat3,
    /// Whether the linear part has a negative determinant.
    pub mirrors: bool,
}

impl Affine {
    /// `outer · inner` (apply `inner` first), e.g. object ∘ pre-transform.
    pub fn compose(outer: &Transform, inner: Option<&Transform>) -> Affine {
        let m = match inner {
            Some(i) => outer.matrix() * i.matrix(),
            None => outer.matrix(),
        };
        Affine::from_matrix(m)
    }

    /// Build from an affine matrix.
    pub fn from_matrix(matrix: DMat4) -> Affine {
        let lin = DMat3::from_mat4(matrix);
        let det = lin.determinant();
        let sign = if det < 0.0 { -1.0 } else { 1.0 };
        Affine {
            matrix,
            normal_matrix: lin.inverse().transpose() * sign,
            mirrors: det < 0.0,
        }
    }

    /// Transform a point (computed in f64, rounded once to f32).
    pub fn point(&self, p: Vec3) -> Vec3 {
        self.matrix.transform_point3(p.as_dvec3()).as_vec3()
    }

    /// Transform a normal and renormalise (zero stays zero).
    pub fn normal(&self, n: Vec3) -> Vec3 {
        (self.normal_matrix * n.as_dvec3())
            .normalize_or_zero()
            .as_vec3()
    }
}

/// The orbit camera of `scenes.json`: angles in radians, vertical FOV 45°.
pub fn orbit_camera(orbit_x_rad: f64, orbit_y_rad: f64, distance: f64, target: DVec3) -> Camera {
    let (sx, cx) = orbit_x_rad.sin_cos();
    let (sy, cy) = orbit_y_rad.sin_cos();
    let dir = DVec3::new(cy * cx, sx, sy * cx);
    Camera {
        position: (target + distance * dir).as_vec3(),
        target: target.as_vec3(),
        up: Vec3::Y,
        vfov_deg: 45.0,
    }
}

/// Camera basis of the neptun renderer: `(forward, right, cam_up)` with
/// `forward = normalize(target - position)`, `right = -normalize(up × forward)`,
/// `cam_up = -(forward × right)`.
pub fn camera_basis(camera: &Camera) -> (Vec3, Vec3, Vec3) {
    let forward = (camera.target - camera.position).normalize();
    let right = -camera.up.cross(forward).normalize();
    let cam_up = -forward.cross(right);
    (forward, right, cam_up)
}
