//! TetGen run in this process, through the C ABI shim ([`super::ffi`]).

use std::ffi::CString;
use std::time::Instant;

use super::error::TetgenError;
use super::ffi;
use super::types::{TetgenInput, TetgenOptions, TetgenOutput};

/// Which TetGen driver runs the stages (`-S` is counted differently).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Driver {
    /// The shim's: `-S` caps the quality refinement's Steiner points alone.
    Shim,
    /// TetGen's own `tetrahedralize()`: `-S` counts the boundary
    /// recovery's Steiner points too (kept to compare the two).
    #[cfg_attr(not(test), allow(dead_code))]
    Library,
}

/// Runs TetGen in this process (input already checked).
pub(crate) fn run_in_process(
    input: &TetgenInput,
    options: &TetgenOptions,
) -> Result<TetgenOutput, TetgenError> {
    run_with_driver(input, options, Driver::Shim)
}

/// [`run_in_process`] with the given driver.
pub(crate) fn run_with_driver(
    input: &TetgenInput,
    options: &TetgenOptions,
    driver: Driver,
) -> Result<TetgenOutput, TetgenError> {
    let switches = options.switches();
    let c_switches =
        CString::new(switches.clone()).map_err(|_| TetgenError::BadSwitches(switches.clone()))?;
    let points: Vec<f64> = input.points.iter().flatten().copied().collect();
    let triangles: Vec<i32> = input
        .triangles
        .iter()
        .flatten()
        .map(|&v| v as i32)
        .collect();
    let mut handle: *mut std::ffi::c_void = std::ptr::null_mut();
    let mut view = ffi::TetShimView::default();
    // TetGen's predicates keep global state set per run (exactinit: error
    // bounds and static filters scaled to the input's bounding box), so two
    // runs in one process must never overlap.
    let _serial = TETGEN_LOCK
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    let start = Instant::now();
    // SAFETY: the pointers reference live buffers of the lengths passed
    // (3 × points, 3 × triangles, 1 × markers — check_input guarantees
    // markers.len() == triangles.len() and that counts fit in i32); the shim
    // catches every C++ exception and only writes `handle` and `view`.
    let code = unsafe {
        ffi::tetshim_tetrahedralize(
            points.as_ptr(),
            input.points.len() as i32,
            triangles.as_ptr(),
            input.markers.as_ptr(),
            input.triangles.len() as i32,
            c_switches.as_ptr(),
            i32::from(driver == Driver::Library),
            &mut handle,
            &mut view,
        )
    };
    let seconds = start.elapsed().as_secs_f64();
    if code != ffi::OK {
        return Err(TetgenError::from_code(code, &switches));
    }
    let guard = Handle(handle);
    // SAFETY: on success the view's pointers reference TetGen's output arrays
    // of the stated lengths (null when a count is 0 or the list was not
    // requested), owned by `guard` and alive until it is dropped below.
    let out = unsafe { copy_view(&view) };
    drop(guard);
    let mut out = out?;
    out.seconds = seconds;
    Ok(out)
}

/// Serializes in-process TetGen runs (see [`run_in_process`]).
static TETGEN_LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Frees TetGen's output when dropped.
struct Handle(*mut std::ffi::c_void);

impl Drop for Handle {
    fn drop(&mut self) {
        // SAFETY: the handle came from tetshim_tetrahedralize and is freed once.
        unsafe { ffi::tetshim_free(self.0) }
    }
}

/// Copies TetGen's output out of the shim's view.
///
/// # Safety
/// Every non-null pointer in `view` must reference an array of the length
/// the view states, alive for the duration of the call.
unsafe fn copy_view(view: &ffi::TetShimView) -> Result<TetgenOutput, TetgenError> {
    let count = |n: i32, what: &str| {
        usize::try_from(n).map_err(|_| TetgenError::Protocol(format!("negative {what} count {n}")))
    };
    let np = count(view.npoints, "point")?;
    let nt = count(view.ntets, "tet")?;
    let nf = count(view.nfaces, "face")?;
    // SAFETY (all slices below): guaranteed by the caller; null pointers are
    // only accepted with a zero length.
    let slice = |p: *const i32, n: usize| -> Result<&[i32], TetgenError> {
        if n == 0 {
            Ok(&[])
        } else if p.is_null() {
            Err(TetgenError::Protocol("null output list".into()))
        } else {
            Ok(unsafe { std::slice::from_raw_parts(p, n) })
        }
    };
    let pts: &[f64] = if np == 0 {
        &[]
    } else if view.points.is_null() {
        return Err(TetgenError::Protocol("null point list".into()));
    } else {
        unsafe { std::slice::from_raw_parts(view.points, 3 * np) }
    };
    let index = |v: i32| -> Result<u32, TetgenError> {
        if v >= 0 && (v as usize) < np {
            Ok(v as u32)
        } else {
            Err(TetgenError::Protocol(format!("vertex id {v} out of range")))
        }
    };
    let tets_raw = slice(view.tets, 4 * nt)?;
    let mut tets = Vec::with_capacity(nt);
    for c in tets_raw.chunks_exact(4) {
        tets.push([index(c[0])?, index(c[1])?, index(c[2])?, index(c[3])?]);
    }
    let neighbors = if view.neighbors.is_null() {
        None
    } else {
        let raw = slice(view.neighbors, 4 * nt)?;
        Some(
            raw.chunks_exact(4)
                .map(|c| [c[0], c[1], c[2], c[3]])
                .collect(),
        )
    };
    let faces_raw = slice(view.faces, 3 * nf)?;
    let mut faces = Vec::with_capacity(nf);
    for c in faces_raw.chunks_exact(3) {
        faces.push([index(c[0])?, index(c[1])?, index(c[2])?]);
    }
    let face_markers = if view.face_markers.is_null() {
        vec![0; nf]
    } else {
        slice(view.face_markers, nf)?.to_vec()
    };
    // Raw values: see `TetgenOutput::face_tets`.
    let face_tets = if view.face_tets.is_null() || nf == 0 {
        None
    } else {
        let raw = slice(view.face_tets, 2 * nf)?;
        Some(raw.chunks_exact(2).map(|c| [c[0], c[1]]).collect())
    };
    Ok(TetgenOutput {
        points: pts.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        tets,
        neighbors,
        faces,
        face_markers,
        face_tets,
        worker_peak_kib: None,
        seconds: 0.0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bbox::{BoxSpec, EnclosingBox};
    use crate::tetgen_options::Optimization;

    /// The single torus knot in an enclosing box: TetGen's boundary
    /// recovery adds Steiner points to it (about a hundred).
    fn knot_in_a_box() -> TetgenInput {
        let scene = crate::procedural::by_name("torus-knot").unwrap();
        let (mut vertices, mut triangles) = (scene.vertices.clone(), scene.triangles.clone());
        EnclosingBox::new(scene.bounds(), BoxSpec::default())
            .unwrap()
            .append_to(&mut vertices, &mut triangles);
        let points = vertices.iter().map(|v| v.as_dvec3().to_array()).collect();
        TetgenInput::with_index_markers(points, triangles)
    }

    fn base() -> TetgenOptions {
        TetgenOptions {
            face_tets: true,
            ..TetgenOptions::default()
        }
    }

    #[test]
    fn the_shim_driver_builds_what_tetgens_own_builds() {
        let input = knot_in_a_box();
        let cases = [
            base(),
            TetgenOptions {
                min_dihedral: Some(2.0),
                ..base()
            },
            TetgenOptions {
                quality: Some(5.0),
                max_dihedral: Some(150.0),
                ..base()
            },
            TetgenOptions {
                preserve_surface: false,
                optimization: Some(Optimization {
                    level: 0,
                    scheme: 0,
                }),
                ..base()
            },
        ];
        for options in cases {
            let ours = run_with_driver(&input, &options, Driver::Shim).unwrap();
            let theirs = run_with_driver(&input, &options, Driver::Library).unwrap();
            let s = options.switches();
            assert_eq!(ours.points, theirs.points, "{s}");
            assert_eq!(ours.tets, theirs.tets, "{s}");
            assert_eq!(ours.neighbors, theirs.neighbors, "{s}");
            assert_eq!(ours.faces, theirs.faces, "{s}");
            assert_eq!(ours.face_markers, theirs.face_markers, "{s}");
            // TetGen leaves the outer side of a hull face uninitialised
            // (any value, changing from run to run): only the sides that
            // name a tet holding the face count.
            let sides = |o: &TetgenOutput| {
                let holds = |t: i32, f: &[u32; 3]| {
                    usize::try_from(t)
                        .ok()
                        .and_then(|t| o.tets.get(t))
                        .is_some_and(|tet| f.iter().all(|v| tet.contains(v)))
                };
                let sides = o.face_tets.as_ref().unwrap();
                (o.faces.iter().zip(sides))
                    .map(|(f, s)| s.map(|t| if holds(t, f) { t } else { -1 }))
                    .collect::<Vec<_>>()
            };
            assert_eq!(sides(&ours), sides(&theirs), "{s}");
        }
    }

    #[test]
    fn the_steiner_cap_counts_the_refinements_points_only() {
        let input = knot_in_a_box();
        let no_optimization = Some(Optimization {
            level: 0,
            scheme: 0,
        });
        let plain = TetgenOptions {
            optimization: no_optimization,
            ..base()
        };
        let recovered = run_in_process(&input, &plain).unwrap().points.len();
        let recovery = recovered - input.points.len();
        let cap = 20;
        assert!(recovery > cap, "the recovery added only {recovery} points");
        let refined = |max_steiner, driver| {
            let options = TetgenOptions {
                min_dihedral: Some(5.0),
                max_steiner,
                ..plain.clone()
            };
            run_with_driver(&input, &options, driver)
                .unwrap()
                .points
                .len()
        };
        let uncapped = refined(None, Driver::Shim);
        assert!(uncapped > recovered + cap, "{uncapped} points");
        // Ours: exactly `cap` refinement points on top of the recovery's.
        assert_eq!(refined(Some(cap as u64), Driver::Shim), recovered + cap);
        // TetGen's own driver counts the recovery's points against the
        // cap, which they already exceed: no refinement at all.
        assert_eq!(refined(Some(cap as u64), Driver::Library), recovered);
    }
}
