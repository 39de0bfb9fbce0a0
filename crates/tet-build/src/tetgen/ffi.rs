//! Raw bindings to our C ABI shim (`cpp/tet_shim.{h,cpp}`), compiled together
//! with TetGen by `build.rs`. Only [`super`] calls these; everything unsafe
//! about TetGen stays in this file and in `super::in_process`.

use std::ffi::{c_char, c_void};

/// Mirror of `TetShimView` in `cpp/tet_shim.h`: read-only pointers into
/// TetGen's output, valid until [`tetshim_free`] is called on the handle.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct TetShimView {
    /// Number of output points.
    pub npoints: i32,
    /// `3 * npoints` coordinates.
    pub points: *const f64,
    /// Number of tets.
    pub ntets: i32,
    /// `4 * ntets` 0-based vertex ids.
    pub tets: *const i32,
    /// `4 * ntets` neighbours (k-th opposite corner k, -1 = none), or null.
    pub neighbors: *const i32,
    /// Number of output faces (subfaces of the PLC).
    pub nfaces: i32,
    /// `3 * nfaces` 0-based vertex ids.
    pub faces: *const i32,
    /// `nfaces` facet markers, or null.
    pub face_markers: *const i32,
    /// `2 * nfaces` tets on the two sides of each face (`-1` = none), or
    /// null (TetGen's `adjtetlist`, only with `-nn`).
    pub face_tets: *const i32,
}

impl Default for TetShimView {
    fn default() -> Self {
        TetShimView {
            npoints: 0,
            points: std::ptr::null(),
            ntets: 0,
            tets: std::ptr::null(),
            neighbors: std::ptr::null(),
            nfaces: 0,
            faces: std::ptr::null(),
            face_markers: std::ptr::null(),
            face_tets: std::ptr::null(),
        }
    }
}

/// `TETSHIM_OK`.
pub const OK: i32 = 0;
/// `TETSHIM_BAD_SWITCHES`: TetGen rejected the switch string.
pub const BAD_SWITCHES: i32 = -1;
/// `TETSHIM_BAD_INPUT`: negative counts or out-of-range vertex ids.
pub const BAD_INPUT: i32 = -2;
/// `TETSHIM_FLAT_INPUT`: the input's bounding box has zero extent along an axis.
pub const FLAT_INPUT: i32 = -3;
/// `TETSHIM_UNKNOWN_EXCEPTION`: a C++ exception other than TetGen's int codes.
pub const UNKNOWN_EXCEPTION: i32 = -4;

unsafe extern "C" {
    /// Runs TetGen on a PLC of triangles (one facet per triangle, marker per
    /// facet) with the shim's driver (`library_driver` = 0: `-S` caps the
    /// refinement's Steiner points alone) or TetGen's own (1). Returns 0
    /// and fills `handle`/`view`, or an error code.
    pub fn tetshim_tetrahedralize(
        points: *const f64,
        npoints: i32,
        triangles: *const i32,
        markers: *const i32,
        ntriangles: i32,
        switches: *const c_char,
        library_driver: i32,
        handle: *mut *mut c_void,
        view: *mut TetShimView,
    ) -> i32;

    /// Frees TetGen's output (null is accepted).
    pub fn tetshim_free(handle: *mut c_void);

    /// Sends C stdout to stderr; returns a duplicate of the original stdout fd or -1.
    pub fn tetshim_redirect_stdout() -> i32;
}
