//! The traversal speed of a built mesh (the trade between memory, build
//! time and render time of a build under a memory limit): `build --tet20` traces the mesh
//! file it wrote with tet20, so an out-of-core build and an in-core build
//! of the same scene report comparable Mrays/s.

use std::path::Path;

use anyhow::{Context, Result};
use tet_trace_cpu::render::RenderOptions;

use crate::load::build_flags::BuildFlags;
use crate::methods::method::Method;
use crate::timing::{RenderDoc, pool, time_method};

/// Image width of the measurement.
pub const WIDTH: u32 = 640;
/// Image height of the measurement.
pub const HEIGHT: u32 = 480;
/// Timed frames (the best one counts), after one warm-up frame.
pub const FRAMES: u32 = 3;

/// tet20 on the mesh file `path` (read back with every check of
/// `format::load`, so a streamed file is validated as a whole here), with
/// its stored camera and lights, on all cores.
/// (`flags` are those of the build; a mesh file ignores them.)
pub fn tet20_speed(path: &Path, flags: &BuildFlags, quiet: bool) -> Result<RenderDoc> {
    let spec = path.to_string_lossy();
    let loaded = crate::load::load(&spec, flags, quiet)
        .with_context(|| format!("cannot read back {}", path.display()))?;
    crate::load::require_tets(&loaded)?;
    let opts = RenderOptions {
        width: WIDTH,
        height: HEIGHT,
        ..RenderOptions::default()
    };
    Ok(time_method(&loaded, Method::Tet20, &opts, FRAMES, &pool(None)?)?.0)
}
