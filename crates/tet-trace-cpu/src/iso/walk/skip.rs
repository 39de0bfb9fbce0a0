//! Where a ray's walk may start: at the first region of tets straddling an
//! isovalue that its segment enters ([`super::super::regions`]), when that
//! lies well inside the volume.
//!
//! No crossing lies before the segment enters that region's box, so the
//! walk may begin at the tet holding the point there, entered through the
//! face the whole walk would have entered it by: the same 2-D edge test
//! ([`crate::walk::Projection::left`], antisymmetric, so exactly one face
//! of a tet the ray's line crosses is its entry and one its exit), with the
//! projection scaled as the walk's own. From there the walk is the whole
//! walk's, step for step: the same hits, bit for bit, fewer tets visited.
//! Where the point's tet is not found within a few steps of a neighbouring
//! ray's, or the ray's line (as the walk decides it) misses that tet, the
//! ray enters from the boundary as before.

use tet_core::FACE_VERTICES;

use super::super::regions::RegionHit;
use super::IsoWalk;
use crate::locate::locate_near;
use crate::ray::{Ray, TraceOutcome};
use crate::walk::projection::Projection;
use crate::walk::start::start_scale;
use crate::walk::{DuffF32, EntryHint, Start};

/// Steps of the point location from a neighbouring ray's start tet.
const LOCATE_STEPS: usize = 32;

/// Walk steps (tets) a start must save to be worth its point location.
const MIN_STEPS_SAVED: f32 = 4.0;

impl IsoWalk<'_> {
    /// Where a tile's ray starts: `None` when the regions cull it (a miss
    /// without a walk); else at its first region ([`IsoWalk::skip_to`]),
    /// or else in the viewpoint's tet `inside`, or through the boundary face
    /// its line enters by.
    pub(super) fn tile_start(
        &self,
        ray: &Ray,
        region: RegionHit,
        inside: Option<u32>,
        prev: &mut Option<u32>,
        hint: &mut EntryHint,
    ) -> Option<Result<Start, TraceOutcome>> {
        if region == RegionHit::None {
            return None;
        }
        Some(match (self.skip_to(ray, region, prev), inside) {
            (Some(s), _) => Ok(s),
            (None, Some(t)) => Ok(Start::Tet(t)),
            (None, None) => self.enter(ray, hint),
        })
    }

    /// The start of `ray`'s walk at its first region `region`, if that is
    /// worth it and found; `prev` carries the last start tet between the
    /// rays of a tile (the point location's source).
    fn skip_to(&self, ray: &Ray, region: RegionHit, prev: &mut Option<u32>) -> Option<Start> {
        let RegionHit::At { t, near } = region else {
            return None;
        };
        let regions = self.regions.as_ref()?;
        // From where the ray enters the mesh's bounds (or starts).
        let (lo, hi) = regions.bounds();
        let (enter, _) = super::super::marching::slab(ray.origin, ray.direction.recip(), lo, hi);
        let from = enter.max(ray.t_min).max(0.0);
        let saved = (t - from) * ray.direction.length() / regions.step_length();
        // NaN (a degenerate ray or bounds) starts from the boundary too.
        if saved.is_nan() || saved < MIN_STEPS_SAVED {
            return None;
        }
        let mesh = &self.mesh;
        let p = ray.origin + ray.direction * t;
        let tet = locate_near(mesh, p, prev.unwrap_or(near), LOCATE_STEPS)?;
        *prev = Some(tet);
        let proj = DuffF32::setup_scaled(ray, start_scale(mesh, ray, Start::Tet(tet)));
        let v = mesh.tets[tet as usize];
        let q = v.map(|i| proj.project(mesh.points[i as usize]));
        // The face whose inward winding (a, c, b) turns counter-clockwise
        // around the ray: the one its line enters by.
        let face = FACE_VERTICES.iter().position(|&[a, b, c]| {
            proj.left(q[a], v[a], q[c], v[c])
                && proj.left(q[c], v[c], q[b], v[b])
                && proj.left(q[b], v[b], q[a], v[a])
        })?;
        Some(Start::Entry {
            tet,
            face: face as u8,
        })
    }
}
