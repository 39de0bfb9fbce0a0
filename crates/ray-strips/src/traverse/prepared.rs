//! A ray prepared once for traversal: reciprocal direction for the box and
//! plane distances, and the shear of Woop et al.'s watertight test.

use glam::Vec3A;

use crate::layout::BvhNode;
use crate::ray::Ray;

/// Relative slack applied to every computed box or plane distance so that
/// culling is conservative: `(c − o) · (1/d)` is within three roundings of
/// the exact value (Ize, "Robust BVH ray traversal"), and the slack is
/// twice that. A ray aimed exactly at a vertex or edge on a box face is
/// therefore never culled by rounding.
pub(crate) const SLACK: f32 = 3.0 * f32::EPSILON;

/// `x` moved towards −∞ by the slack.
#[inline(always)]
pub(crate) fn down(x: f32) -> f32 {
    x - x.abs() * SLACK
}

/// `x` moved towards +∞ by the slack.
#[inline(always)]
pub(crate) fn up(x: f32) -> f32 {
    x + x.abs() * SLACK
}

/// `max` for values that are not NaN (one instruction, unlike `f32::max`).
#[inline(always)]
pub(crate) fn fmax(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// `min` for values that are not NaN.
#[inline(always)]
pub(crate) fn fmin(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

/// A traceable ray with its precomputed values.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Prepared {
    /// Origin.
    pub org: [f32; 3],
    /// Direction.
    pub dir: [f32; 3],
    /// `1 / dir` per axis (unused on axes where `dir` is zero).
    pub inv: [f32; 3],
    /// Lower end of the accepted range.
    pub t_min: f32,
    /// Woop's axis permutation: `kz` is the largest direction component.
    pub k: [usize; 3],
    /// Woop's shear constants `Sx, Sy, Sz`.
    pub shear: [f32; 3],
    /// `org` as a vector (box tests).
    pub org_a: Vec3A,
    /// `inv` as a vector (box tests).
    pub inv_a: Vec3A,
    /// Whether some direction component is zero (slab tests then need the
    /// careful path).
    pub parallel: bool,
}

impl Prepared {
    /// `None` for rays that cannot hit anything.
    pub fn new(ray: &Ray) -> Option<Self> {
        if !ray.is_traceable() {
            return None;
        }
        // Subnormal components count as zero, so that `1 / d` is finite
        // for every non-zero component and slab distances are never NaN.
        let dir = ray
            .direction
            .to_array()
            .map(|d| if d.abs() < f32::MIN_POSITIVE { 0.0 } else { d });
        if dir == [0.0; 3] {
            return None;
        }
        let kz = glam::Vec3::from(dir).abs().max_position();
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if dir[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        // One vector division for all reciprocals; Woop's shear constants
        // `d_kx / d_kz` and `d_ky / d_kz` as products with `1 / d_kz` (any
        // per-ray constants give a watertight test, as long as every
        // vertex is transformed with the same ones).
        let inv = glam::Vec3::ONE / glam::Vec3::from(dir);
        let inv_kz = inv[kz];
        Some(Self {
            org: ray.origin.to_array(),
            dir,
            inv: inv.to_array(),
            // The `w` lanes meet the node's words (small integers, i.e.
            // subnormal floats): 1 keeps that lane's results normal, which
            // some processors compute much faster.
            org_a: Vec3A::from_vec4(ray.origin.extend(1.0)),
            inv_a: Vec3A::from_vec4(inv.extend(1.0)),
            t_min: ray.t_min,
            k: [kx, ky, kz],
            shear: [dir[kx] * inv_kz, dir[ky] * inv_kz, inv_kz],
            parallel: dir.contains(&0.0),
        })
    }

    /// Whether traversal visits a node's first child first on `axis`
    /// (direction `≥ 0`, so `-0.0` and `0.0` agree).
    #[inline(always)]
    pub fn forward(&self, axis: usize) -> bool {
        self.dir[axis] >= 0.0
    }

    /// Conservative `[t_near, t_far]` of the box within `[t_min, t_max]`,
    /// `None` when empty.
    #[inline(always)]
    pub fn box_interval(&self, node: &BvhNode, t_max: f32) -> Option<(f32, f32)> {
        self.interval(node.min(), node.max(), t_max)
    }

    /// Conservative `[t_near, t_far]` of the box `[min, max]` (`xyz`
    /// lanes) within `[t_min, t_max]`, `None` when empty.
    #[inline(always)]
    pub fn interval(&self, min: Vec3A, max: Vec3A, t_max: f32) -> Option<(f32, f32)> {
        if !self.parallel {
            // No direction component is zero: every slab distance is a
            // number (the same IEEE operations per lane as a scalar loop),
            // and `down`/`up` are monotonic, so the slack is applied once
            // to the combined ends.
            let t0 = (min - self.org_a) * self.inv_a;
            let t1 = (max - self.org_a) * self.inv_a;
            let tn = t0.min(t1).max_element();
            let tf = t0.max(t1).min_element();
            let tn = fmax(self.t_min, down(tn));
            let tf = fmin(t_max, up(tf));
            return (tn <= tf).then_some((tn, tf));
        }
        let mut tn = self.t_min;
        let mut tf = t_max;
        for a in 0..3 {
            if self.dir[a] == 0.0 {
                if self.org[a] < min[a] || self.org[a] > max[a] {
                    return None;
                }
            } else {
                let t0 = (min[a] - self.org[a]) * self.inv[a];
                let t1 = (max[a] - self.org[a]) * self.inv[a];
                tn = tn.max(down(t0.min(t1)));
                tf = tf.min(up(t0.max(t1)));
            }
        }
        (tn <= tf).then_some((tn, tf))
    }
}

/// The closest hit found so far.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Best {
    /// Its distance (the ray's `t_max` while nothing is hit).
    pub t: f32,
    /// Per-triangle word of the hit triangle (`u32::MAX`: none).
    pub word: u32,
    /// Barycentric weights in input order of vertices 1 and 2.
    pub u: f32,
    /// See `u`.
    pub v: f32,
}

impl Best {
    /// Nothing hit yet within `[.., t_max]`.
    pub fn new(t_max: f32) -> Self {
        Self {
            t: t_max,
            word: u32::MAX,
            u: 0.0,
            v: 0.0,
        }
    }
}
