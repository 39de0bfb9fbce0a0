//! The enclosing box: 8 corners and 12 triangles around the whole scene, so
//! that the space around the objects is tetrahedralized too (rays starting
//! anywhere inside it find a tet).
//!
//! This box is part of the *mesh boundary*, not of the scene: its triangles
//! are appended after the scene triangles and reported as a
//! [`BoundaryRange`] so the builder can treat them as boundary faces (not
//! constrained scene faces). It is distinct from the visible box objects of
//! the "in a Box" scenes. neptun uses the fixed box `[-50, 50]³`
//! ([`BoxSpec::NEPTUN`]); [`BoxSpec::Relative`] sizes it from the scene.

use glam::Vec3;
use thiserror::Error;

use crate::procedural::BOX_TRIANGLES;

/// How to size the enclosing box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BoxSpec {
    /// Scene bounds grown on every side by `margin` × the largest scene
    /// extent, and at least by `1e-4` × the largest coordinate magnitude
    /// (a few hundred f32 steps, so the box stays strictly outside the
    /// scene far from the origin). Both are relative: a scene and its
    /// scaled copy get scaled boxes.
    Relative {
        /// Relative margin (e.g. 0.1).
        margin: f32,
    },
    /// A fixed box, which must strictly contain the scene.
    Fixed {
        /// Lower corner.
        min: Vec3,
        /// Upper corner.
        max: Vec3,
    },
}

impl BoxSpec {
    /// neptun's fixed box `[-50, 50]³`.
    pub const NEPTUN: BoxSpec = BoxSpec::Fixed {
        min: Vec3::splat(-50.0),
        max: Vec3::splat(50.0),
    };
}

impl Default for BoxSpec {
    fn default() -> Self {
        BoxSpec::Relative { margin: 0.1 }
    }
}

/// The box could not be built.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum BoxError {
    /// The scene has no triangles, so there are no bounds to enclose.
    #[error("cannot build an enclosing box around an empty scene")]
    EmptyScene,
    /// A fixed box does not strictly contain the scene bounds.
    #[error(
        "fixed box {box_min:?}..{box_max:?} does not strictly contain the scene bounds {scene_min:?}..{scene_max:?}"
    )]
    DoesNotContain {
        /// Box lower corner.
        box_min: Vec3,
        /// Box upper corner.
        box_max: Vec3,
        /// Scene lower corner.
        scene_min: Vec3,
        /// Scene upper corner.
        scene_max: Vec3,
    },
    /// Margin is negative, zero or not finite.
    #[error("invalid relative margin {0}")]
    BadMargin(f32),
    /// A corner of the box is not finite: grown around the scene, it
    /// overflows f32 (or a fixed box was given with infinite corners).
    #[error(
        "the enclosing box {min:?}..{max:?} is not finite: it overflows f32, whose largest value is {limit:e}",
        limit = f32::MAX
    )]
    Overflows {
        /// Box lower corner.
        min: Vec3,
        /// Box upper corner.
        max: Vec3,
    },
}

/// An enclosing box: corners and outward triangles (local indices 0..8;
/// corner `i` takes max x when bit 0 is set, max y for bit 1, max z for bit 2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnclosingBox {
    /// Lower corner.
    pub min: Vec3,
    /// Upper corner.
    pub max: Vec3,
    /// The 8 corners.
    pub corners: [Vec3; 8],
    /// 12 triangles, right-hand normals pointing out of the box.
    pub triangles: [[u32; 3]; 12],
}

/// Where the box landed after [`EnclosingBox::append_to`]: triangles
/// `first_triangle..first_triangle + 12` and vertices
/// `first_vertex..first_vertex + 8` are boundary, not scene geometry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BoundaryRange {
    /// First boundary vertex.
    pub first_vertex: u32,
    /// First boundary triangle.
    pub first_triangle: u32,
}

impl BoundaryRange {
    /// True when triangle `t` belongs to the enclosing box.
    pub fn is_boundary_triangle(&self, t: u32) -> bool {
        t >= self.first_triangle && t < self.first_triangle + 12
    }
}

impl EnclosingBox {
    /// Build the box around scene bounds `(scene_min, scene_max)`.
    pub fn new(bounds: Option<(Vec3, Vec3)>, spec: BoxSpec) -> Result<EnclosingBox, BoxError> {
        let (smin, smax) = bounds.ok_or(BoxError::EmptyScene)?;
        let (min, max) = match spec {
            BoxSpec::Relative { margin } => {
                if !(margin.is_finite() && margin > 0.0) {
                    return Err(BoxError::BadMargin(margin));
                }
                let extent = (smax - smin).max_element();
                let scale = smin.abs().max(smax.abs()).max_element();
                let pad = (margin * extent).max(scale * 1e-4);
                (smin - Vec3::splat(pad), smax + Vec3::splat(pad))
            }
            BoxSpec::Fixed { min, max } => {
                if !(min.cmplt(smin).all() && max.cmpgt(smax).all()) {
                    return Err(BoxError::DoesNotContain {
                        box_min: min,
                        box_max: max,
                        scene_min: smin,
                        scene_max: smax,
                    });
                }
                (min, max)
            }
        };
        if !(min.is_finite() && max.is_finite()) {
            return Err(BoxError::Overflows { min, max });
        }
        let corners = std::array::from_fn(|i| {
            Vec3::new(
                if i & 1 != 0 { max.x } else { min.x },
                if i & 2 != 0 { max.y } else { min.y },
                if i & 4 != 0 { max.z } else { min.z },
            )
        });
        Ok(EnclosingBox {
            min,
            max,
            corners,
            triangles: BOX_TRIANGLES,
        })
    }

    /// Append the corners and triangles to a vertex/triangle list.
    pub fn append_to(
        &self,
        vertices: &mut Vec<Vec3>,
        triangles: &mut Vec<[u32; 3]>,
    ) -> BoundaryRange {
        let range = BoundaryRange {
            first_vertex: vertices.len() as u32,
            first_triangle: triangles.len() as u32,
        };
        vertices.extend_from_slice(&self.corners);
        triangles.extend(
            self.triangles
                .iter()
                .map(|t| t.map(|v| v + range.first_vertex)),
        );
        range
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::intersect::find_self_intersections;
    use crate::procedural;

    fn signed_volume(v: &[Vec3], t: &[[u32; 3]]) -> f64 {
        t.iter()
            .map(|&[a, b, c]| {
                let (a, b, c) = (
                    v[a as usize].as_dvec3(),
                    v[b as usize].as_dvec3(),
                    v[c as usize].as_dvec3(),
                );
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    #[test]
    fn relative_box_around_cube() {
        let b = EnclosingBox::new(
            Some((Vec3::splat(-1.0), Vec3::splat(1.0))),
            BoxSpec::Relative { margin: 0.1 },
        )
        .unwrap();
        // Extent 2, margin 0.1 → pad 0.2 on every side.
        assert_eq!(b.min, Vec3::splat(-1.2));
        assert_eq!(b.max, Vec3::splat(1.2));
        let vol = signed_volume(&b.corners, &b.triangles);
        let side = 2.4f32 as f64; // f32 rounding of ±1.2
        assert!((vol - side.powi(3)).abs() < 1e-5, "outward winding: {vol}");
        // Every corner appears, every corner is a box corner.
        for (i, c) in b.corners.iter().enumerate() {
            assert_eq!(c.x, if i & 1 != 0 { 1.2 } else { -1.2 });
        }
    }

    #[test]
    fn fixed_box_and_errors() {
        let s = procedural::by_name("torus-knots-box").unwrap();
        let b = EnclosingBox::new(s.bounds(), BoxSpec::NEPTUN).unwrap();
        assert_eq!(b.corners[7], Vec3::splat(50.0));
        let small = BoxSpec::Fixed {
            min: Vec3::splat(-20.0),
            max: Vec3::splat(20.0),
        };
        assert!(matches!(
            EnclosingBox::new(s.bounds(), small),
            Err(BoxError::DoesNotContain { .. })
        ));
        assert_eq!(
            EnclosingBox::new(None, BoxSpec::default()),
            Err(BoxError::EmptyScene)
        );
        assert!(matches!(
            EnclosingBox::new(s.bounds(), BoxSpec::Relative { margin: -1.0 }),
            Err(BoxError::BadMargin(_))
        ));
    }

    #[test]
    fn relative_boxes_scale_with_the_scene_and_overflow_is_an_error() {
        // A scene and its copy scaled by 2⁻¹⁰⁰ get boxes scaled by 2⁻¹⁰⁰:
        // the pad is relative (no absolute floor that would dwarf a tiny scene).
        let s = 2f32.powi(-100);
        let (lo, hi) = (Vec3::new(-1.0, 0.0, 2.0), Vec3::new(1.0, 0.5, 3.0));
        let unit = EnclosingBox::new(Some((lo, hi)), BoxSpec::default()).unwrap();
        let tiny = EnclosingBox::new(Some((lo * s, hi * s)), BoxSpec::default()).unwrap();
        assert_eq!((tiny.min, tiny.max), (unit.min * s, unit.max * s));
        // Far from the origin the box keeps a margin of many f32 steps.
        let far = EnclosingBox::new(
            Some((Vec3::splat(1e5), Vec3::splat(1e5 + 0.01))),
            BoxSpec::default(),
        )
        .unwrap();
        assert!(far.min.x <= 1e5 - 10.0 && far.max.x >= 1e5 + 10.0);
        let huge = (Vec3::splat(-3e38), Vec3::splat(3e38));
        assert!(matches!(
            EnclosingBox::new(Some(huge), BoxSpec::default()),
            Err(BoxError::Overflows { .. })
        ));
    }

    #[test]
    fn appended_box_is_separate_boundary() {
        let s = procedural::by_name("torus-knots-box").unwrap();
        let b = EnclosingBox::new(s.bounds(), BoxSpec::Relative { margin: 0.05 }).unwrap();
        // Strictly outside the visible box [-21,21]×[-11,11]×[-21,21].
        assert!(b.min.cmplt(Vec3::new(-21.0, -11.0, -21.0)).all());
        assert!(b.max.cmpgt(Vec3::new(21.0, 11.0, 21.0)).all());
        let (mut v, mut t) = (s.vertices.clone(), s.triangles.clone());
        let r = b.append_to(&mut v, &mut t);
        assert_eq!(r.first_triangle as usize, s.triangles.len());
        assert_eq!(r.first_vertex as usize, s.vertices.len());
        assert!(r.is_boundary_triangle(r.first_triangle + 11));
        assert!(!r.is_boundary_triangle(r.first_triangle - 1));
        assert!(!r.is_boundary_triangle(r.first_triangle + 12));
        assert_eq!(t.len(), s.triangles.len() + 12);
        // Only the last 12 triangles, around the outside: no intersections.
        let tris = &t[r.first_triangle as usize..];
        assert!(signed_volume(&v, tris) > 0.0);
        // The box alone plus the visible box: nothing intersects.
        let mut vv = v[..24].to_vec();
        let mut tt = s.triangles[..12].to_vec();
        b.append_to(&mut vv, &mut tt);
        assert!(find_self_intersections(&vv, &tt).pairs.is_empty());
    }
}
