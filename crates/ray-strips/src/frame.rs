//! The structure's own frame: scenes far outside unit size are stored
//! scaled by a power of two, so that the watertight test's products stay
//! within `f32`.
//!
//! The test multiplies ray-space coordinates twice (edge functions, of the
//! order of the scene size squared) and then by a distance (the hit
//! distance, size cubed): a scene of size 10¹⁵ overflows, one of size
//! 10⁻¹⁵ underflows into subnormals. Scaling the vertices and the ray
//! origin by the same power of two `s` changes no rounding (every product
//! scales exactly), so the structure traverses the scaled scene with the
//! unchanged direction and the range `[s·t_min, s·t_max]`, and divides the
//! hit distance by `s`; barycentrics are unchanged.

use glam::Vec3;

/// Scenes whose largest coordinate magnitude lies in `[2⁻¹⁶, 2¹⁷)` are
/// stored as they are.
const UNSCALED: std::ops::Range<f32> = 1.0 / 65536.0..131072.0;

/// The power of two that brings the largest coordinate magnitude of
/// `positions` into `[1, 2)`, or 1 when it already lies in [`UNSCALED`], is
/// not a finite positive number, or when scaling would round a coordinate
/// (one that falls into the subnormals).
pub(crate) fn unit_scale(positions: &[Vec3]) -> f32 {
    let m = positions
        .iter()
        .map(|p| p.abs().max_element())
        .fold(0.0f32, f32::max);
    if UNSCALED.contains(&m) || !(m.is_finite() && m > 0.0) {
        return 1.0;
    }
    let e = m.log2().floor() as i32;
    let s = 2.0f32.powi(-e.clamp(-126, 126));
    let exact = positions.iter().all(|&p| (p * s) / s == p);
    if exact { s } else { 1.0 }
}
