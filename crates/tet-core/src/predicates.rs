//! Exact geometric predicates (Shewchuk's adaptive arithmetic via `robust`).
//!
//! Validation and construction decide orientation exactly; the traversal
//! kernels use their own floating-point tests, which are measured against
//! these.

use glam::{DVec3, Vec3};

/// Sign of `((b-a) × (c-a)) · (d-a)`, computed exactly from the f64 values.
///
/// Positive when `d` lies on the side of plane `abc` that the right-hand
/// normal of `(a, b, c)` points to; zero when the four points are coplanar.
pub fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    // robust::orient3d returns a positive value when d is *below* the plane
    // (Shewchuk's convention), so negate to match ours.
    -robust::orient3d(coord(a), coord(b), coord(c), coord(d))
}

/// [`orient3d`] on f32 points (converted exactly to f64).
pub fn orient3d_f32(a: Vec3, b: Vec3, c: Vec3, d: Vec3) -> f64 {
    orient3d(a.as_dvec3(), b.as_dvec3(), c.as_dvec3(), d.as_dvec3())
}

fn coord(p: DVec3) -> robust::Coord3D<f64> {
    robust::Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_tet_is_positive() {
        let o = DVec3::ZERO;
        assert!(orient3d(o, DVec3::X, DVec3::Y, DVec3::Z) > 0.0);
        assert!(orient3d(o, DVec3::Y, DVec3::X, DVec3::Z) < 0.0);
        assert_eq!(
            orient3d(o, DVec3::X, DVec3::Y, DVec3::new(3.0, 5.0, 0.0)),
            0.0
        );
    }

    #[test]
    fn exact_on_nearly_coplanar_points() {
        // d is 2^-60 above the plane z = 0 at a far-away location: a naive
        // f64 determinant rounds this to zero or the wrong sign.
        let a = DVec3::new(1e3, 1e3, 0.0);
        let b = DVec3::new(1e3 + 1.0, 1e3, 0.0);
        let c = DVec3::new(1e3, 1e3 + 1.0, 0.0);
        let d = DVec3::new(5e2, 7e2, 2f64.powi(-60));
        assert!(orient3d(a, b, c, d) > 0.0);
    }
}
