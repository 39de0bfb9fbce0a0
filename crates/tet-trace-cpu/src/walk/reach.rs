//! Walks that end once they are past their ray's `t_max`: an
//! ambient-occlusion ray only asks whether something lies within its
//! length, yet the plain walk goes on until it meets a face or the mesh
//! boundary (measured on Torus Knots: 30.9 tets per AO ray, 21.9 with
//! this stop; `examples/ao_reach.rs`).
//!
//! **The rule.** The walk crosses faces in order along the ray. When
//! every vertex of the face it is about to leave through lies beyond the
//! plane `(p − o)·d = t_max·|d|²` (perpendicular to the ray at `t_max`),
//! the crossing point, a convex combination of them, lies beyond too,
//! and so does every face after it: no hit with `t ≤ t_max` is left, and
//! the walk ends as the miss it would have ended as (a hit beyond `t_max`
//! is reported as a miss already). A lane keeps one bit per vertex of its
//! current face ([`Reach::beyond`] of each), replaced with the new
//! vertex's bit at each step; all three set ends the walk.
//!
//! **Conservative in f32.** `(p − o)·d` is computed in f32 with a bound on
//! its rounding error, `γ·Σ|p_i − o_i|·|d_i|` with `γ = 8u` (`u = 2⁻²⁴`;
//! a dot product of three terms after a subtraction needs `5u`), and a
//! vertex counts as beyond only when the computed value less that bound
//! exceeds `t_max·|d|²·(1 + 2⁻¹⁶)` (the walk's own hit parameter is
//! computed in f64 from the same f32 points, so a crossing that far past
//! `t_max` is past it for the walk too). Where the products overflow the
//! comparison is false (NaN or infinity less infinity), where they
//! underflow their absolute error is far below the threshold, which is
//! a normal f32 ([`Reach::of`] refuses a bound otherwise): a vertex is
//! never counted beyond wrongly, and the stop never changes a verdict.
//!
//! **Bit for bit across walks.** The scalar walk and the SIMD lockstep
//! walk compute the same f32 operations in the same order (no fused
//! multiply-add: Rust never contracts, and the lanes use separate
//! multiplies and adds), so both stop at the same tet.

use glam::Vec3;

use crate::ray::Ray;

/// `γ` of the module docs: `8u`.
pub(crate) const GAMMA: f32 = 8.0 / (1u32 << 24) as f32;

/// The plane a bounded walk ends past (see the module docs): per lane,
/// the ray's origin and direction and the threshold.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Reach {
    pub(crate) origin: Vec3,
    pub(crate) dir: Vec3,
    /// `|d|` per axis.
    pub(crate) dir_abs: Vec3,
    /// `t_max·|d|²·(1 + 2⁻¹⁶)`.
    pub(crate) threshold: f32,
}

impl Reach {
    /// The bound of `ray`, or `None` when it has none worth the check
    /// (`t_max` infinite) or none computed safely (a threshold that is
    /// not a normal f32).
    pub(crate) fn of(ray: &Ray) -> Option<Reach> {
        let d = ray.direction.as_dvec3();
        let threshold = (ray.t_max as f64 * d.length_squared() * (1.0 + 1.0 / 65536.0)) as f32;
        (ray.t_max.is_finite() && threshold.is_normal() && threshold > 0.0).then(|| Reach {
            origin: ray.origin,
            dir: ray.direction,
            dir_abs: ray.direction.abs(),
            threshold,
        })
    }

    /// Whether `p` lies beyond the plane, by the conservative test of the
    /// module docs. The lockstep walk computes the same operations.
    #[inline(always)]
    pub(crate) fn beyond(&self, p: Vec3) -> bool {
        let (o, d, a) = (self.origin, self.dir, self.dir_abs);
        let (qx, qy, qz) = (p.x - o.x, p.y - o.y, p.z - o.z);
        let s = qx * d.x + qy * d.y + qz * d.z;
        let err = (qx.abs() * a.x + qy.abs() * a.y + qz.abs() * a.z) * GAMMA;
        s - err > self.threshold
    }

    /// The bits of the three points beyond the plane (bit `k`: `p[k]`).
    #[inline(always)]
    pub(crate) fn beyond_mask(&self, p: [Vec3; 3]) -> u8 {
        (self.beyond(p[0]) as u8) | (self.beyond(p[1]) as u8) << 1 | (self.beyond(p[2]) as u8) << 2
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against f64: a point counted beyond is beyond `t_max` along the
    /// ray in exact terms; points well beyond are counted; no bound
    /// without a finite `t_max`, or where the threshold is not normal.
    #[test]
    fn beyond_means_beyond_in_f64() {
        let mut rng = tet_core::synthetic::SplitMix64(11);
        let mut rand = || rng.range_f32(-1.0, 1.0);
        let mut counted = 0;
        for scale in [1e-12f32, 1e-3, 1.0, 1e3, 1e12] {
            for _ in 0..20_000 {
                let o = Vec3::new(rand(), rand(), rand()) * scale + Vec3::splat(3.0 * scale);
                let d = Vec3::new(rand(), rand(), rand());
                let ray = Ray {
                    origin: o,
                    direction: d,
                    t_min: 0.0,
                    t_max: (rand().abs() + 0.01) * scale,
                };
                let Some(r) = Reach::of(&ray) else {
                    assert!(d.as_dvec3().length_squared() < 1e-30 || scale < 1e-6);
                    continue;
                };
                let p = o + Vec3::new(rand(), rand(), rand()) * 2.0 * scale;
                let s = (p.as_dvec3() - o.as_dvec3()).dot(d.as_dvec3());
                let t = ray.t_max as f64 * d.as_dvec3().length_squared();
                if r.beyond(p) {
                    counted += 1;
                    assert!(s > t, "{p} counted beyond: {s} vs {t}");
                } else {
                    // Not counted only within the margin and the error bound.
                    let q = (p.as_dvec3() - o.as_dvec3()).abs();
                    let bound = q.dot(d.as_dvec3().abs()) * 1e-6;
                    assert!(s <= t * (1.0 + 2e-5) + bound, "{p} not counted: {s} vs {t}");
                }
            }
        }
        assert!(counted > 10_000, "{counted}");
        let mut ray = Ray::new(Vec3::ZERO, Vec3::X);
        assert_eq!(Reach::of(&ray), None);
        ray.t_max = 1e-40;
        assert_eq!(Reach::of(&ray), None, "threshold not normal");
    }
}
