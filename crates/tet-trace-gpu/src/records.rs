//! The records shared with the shaders (`#[repr(C)]`, the WGSL structs'
//! layouts), the outcome codes and start modes, and the mapping of a result
//! record to the CPU's [`TraceOutcome`].

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use tet_core::scene::Camera;
use tet_trace_cpu::{Failure, Hit, TraceOutcome};

use crate::error::GpuError;

// Outcome codes and start modes shared with the shader.
pub(crate) const ST_HIT: u32 = 0;
pub(crate) const ST_MISS: u32 = 1;
pub(crate) const ST_STEP_CAP: u32 = 2;
pub(crate) const ST_INVALID: u32 = 3;
pub(crate) const ST_LOST: u32 = 4;
pub(crate) const START_EXIT: u32 = 0;
pub(crate) const START_ENTER: u32 = 1;
pub(crate) const START_DONE: u32 = 2;

/// Uniform parameters (layout of the shader's `Params`, 144 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub(crate) struct Params {
    pub(crate) ray_count: u32,
    pub(crate) first_ray: u32,
    pub(crate) step_cap: u32,
    pub(crate) camera_mode: u32,
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) point_count: u32,
    pub(crate) cam_tet: u32,
    pub(crate) cam_ids: [u32; 4],
    pub(crate) cam_links: [u32; 4],
    pub(crate) camera: CameraRec,
}
const _: () = assert!(size_of::<Params>() == 144);

/// The camera of a frame whose rays the GPU makes (`Camera` in
/// `camera.wgsl`, shared by the tet walks and the BVH kernel): the eye, the
/// view frame and the lens, in f32.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub(crate) struct CameraRec {
    pub(crate) eye: [f32; 4],
    pub(crate) forward: [f32; 4],
    pub(crate) right: [f32; 4],
    pub(crate) up: [f32; 4],
    /// `half_h`, aspect, pixel offset (0 or 0.5), unused.
    pub(crate) lens: [f32; 4],
}
const _: () = assert!(size_of::<CameraRec>() == 80);

impl CameraRec {
    /// The record of `camera` for a `width × height` image; fails with
    /// [`GpuError::Camera`] on an empty or too large image (more than
    /// `u32::MAX` pixels) or a degenerate camera.
    pub(crate) fn new(
        camera: &Camera,
        width: u32,
        height: u32,
        pixel_centers: bool,
    ) -> Result<CameraRec, GpuError> {
        let pixels = width as u64 * height as u64;
        if width == 0 || height == 0 || pixels > u32::MAX as u64 {
            return Err(GpuError::Camera {
                detail: format!("image size {width}x{height} is empty or too large"),
            });
        }
        let forward = (camera.target - camera.position).normalize();
        let right = -camera.up.cross(forward).normalize();
        let up = -forward.cross(right);
        if !(camera.position.is_finite() && forward.is_finite() && right.is_finite()) {
            return Err(GpuError::Camera {
                detail: format!("degenerate camera {camera:?}"),
            });
        }
        let half_h = (camera.vfov_deg.to_radians() * 0.5).tan();
        let aspect = width as f32 / height as f32;
        let offset = if pixel_centers { 0.5 } else { 0.0 };
        let v4 = |v: Vec3| v.extend(0.0).to_array();
        Ok(CameraRec {
            eye: v4(camera.position),
            forward: v4(forward),
            right: v4(right),
            up: v4(up),
            lens: [half_h, aspect, offset, 0.0],
        })
    }
}

/// One batch ray: origin + `t_min`, direction + `t_max`, projection basis.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub(crate) struct RayRec {
    pub(crate) o: [f32; 4],
    pub(crate) d: [f32; 4],
    pub(crate) u: [f32; 4],
    pub(crate) v: [f32; 4],
}

/// Where a batch ray's walk starts (computed on the host, see crate docs).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub(crate) struct StartRec {
    pub(crate) mode: u32,
    pub(crate) ids: [u32; 3],
    pub(crate) tet: u32,
    pub(crate) link: u32,
    pub(crate) visited: u32,
    pub(crate) next: u32,
}

/// One result record as written by the shader (40 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub(crate) struct HitRec {
    pub(crate) status: u32,
    pub(crate) triangle: u32,
    pub(crate) face: u32,
    pub(crate) t: f32,
    pub(crate) bary: [f32; 3],
    pub(crate) tet: u32,
    pub(crate) far_tet: u32,
    pub(crate) visited: u32,
}
const _: () = assert!(size_of::<HitRec>() == 40);

impl HitRec {
    pub(crate) fn outcome(&self) -> TraceOutcome {
        let failed = |failure| TraceOutcome::Failed {
            failure,
            tets_visited: self.visited,
        };
        match self.status {
            ST_HIT => TraceOutcome::Hit(Hit {
                triangle: self.triangle,
                face: self.face,
                t: self.t,
                barycentrics: self.bary,
                tet: self.tet,
                far_tet: self.far_tet,
                tets_visited: self.visited,
            }),
            ST_MISS => TraceOutcome::Miss {
                tets_visited: self.visited,
            },
            ST_STEP_CAP => failed(Failure::StepCap),
            ST_INVALID => failed(Failure::InvalidRay),
            _ => failed(Failure::Lost),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tet_core::NO_TET;

    #[test]
    fn hit_records_map_to_cpu_outcomes() {
        let rec = |status| HitRec {
            status,
            triangle: 7,
            face: 3,
            t: 2.5,
            bary: [0.25, 0.25, 0.5],
            tet: 11,
            far_tet: NO_TET,
            visited: 9,
        };
        match rec(ST_HIT).outcome() {
            TraceOutcome::Hit(h) => {
                assert_eq!((h.triangle, h.face, h.tet, h.tets_visited), (7, 3, 11, 9));
                assert_eq!((h.t, h.barycentrics), (2.5, [0.25, 0.25, 0.5]));
                assert!(!h.has_far_side());
            }
            o => panic!("{o:?}"),
        }
        assert_eq!(
            rec(ST_MISS).outcome(),
            TraceOutcome::Miss { tets_visited: 9 }
        );
        for (st, f) in [
            (ST_STEP_CAP, Failure::StepCap),
            (ST_INVALID, Failure::InvalidRay),
            (ST_LOST, Failure::Lost),
            (99, Failure::Lost),
        ] {
            assert_eq!(
                rec(st).outcome(),
                TraceOutcome::Failed {
                    failure: f,
                    tets_visited: 9
                }
            );
        }
    }
}
