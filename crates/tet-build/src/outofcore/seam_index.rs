//! Which points and faces lie on a seam: the exact test shared by the seam
//! quality report ([`super::report`]) and the streaming merge
//! ([`super::stream`]).
//!
//! A seam is a split plane's section of its part's box: plane
//! `x[axis] = value` and a rectangle (lower and upper corner, both with the
//! plane's coordinate), as listed in [`super::seam::SeamReport::seams`].
//! Seam points carry the plane's coordinate bit for bit, so membership is
//! exact: the coordinate equals the plane's and the other two lie within
//! the rectangle (boundary included).

use std::collections::HashMap;

use glam::Vec3;

use super::plane::SplitPlane;

/// The seams, indexed by plane.
#[derive(Clone, Debug, Default)]
pub struct SeamIndex {
    /// `(axis, bits of the plane value with −0 folded into +0)` → rectangles.
    planes: HashMap<(usize, u32), Vec<(Vec3, Vec3)>>,
}

impl SeamIndex {
    /// Indexes `seams` (plane, rectangle lower corner, upper corner).
    pub fn new(seams: &[(SplitPlane, Vec3, Vec3)]) -> SeamIndex {
        let mut planes: HashMap<(usize, u32), Vec<(Vec3, Vec3)>> = HashMap::new();
        for (plane, lo, hi) in seams {
            planes
                .entry((plane.axis, (plane.value + 0.0).to_bits()))
                .or_default()
                .push((*lo, *hi));
        }
        SeamIndex { planes }
    }

    /// True when there are no seams.
    pub fn is_empty(&self) -> bool {
        self.planes.is_empty()
    }

    /// Rectangles of the seams on plane `x[axis] = value`.
    fn rectangles(&self, axis: usize, value: f32) -> &[(Vec3, Vec3)] {
        self.planes
            .get(&(axis, (value + 0.0).to_bits()))
            .map_or(&[], Vec::as_slice)
    }

    /// Does `p` lie on a seam?
    pub fn contains_point(&self, p: Vec3) -> bool {
        (0..3).any(|k| {
            self.rectangles(k, p[k])
                .iter()
                .any(|(lo, hi)| inside(p, *lo, *hi))
        })
    }

    /// Does the face `f` lie in one seam (all three points on the same
    /// plane and inside one of its rectangles)?
    pub fn contains_face(&self, f: [Vec3; 3]) -> bool {
        (0..3).any(|k| {
            let v = f[0][k];
            f[1][k] == v
                && f[2][k] == v
                && self
                    .rectangles(k, v)
                    .iter()
                    .any(|(lo, hi)| f.iter().all(|&p| inside(p, *lo, *hi)))
        })
    }
}

/// `p` within the box `lo..=hi` (on the plane's own axis both are equal to
/// the plane's value, which `p` has).
fn inside(p: Vec3, lo: Vec3, hi: Vec3) -> bool {
    (0..3).all(|a| p[a] >= lo[a] && p[a] <= hi[a])
}
