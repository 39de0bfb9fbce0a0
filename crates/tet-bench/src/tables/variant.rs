//! tet20 on a variant of a scene's mesh (the same scene rebuilt with other
//! build flags): the measurement shared by the tables that compare a build
//! choice against the default one (Hilbert sorting, the enclosing box).

use anyhow::Result;
use tet_trace_cpu::render::RenderOptions;

use super::doc::TABLE_FLAGS;
use super::plan::{MeshCache, Planned};
use crate::load::build_flags::BuildFlags;
use crate::methods::method::Method;
use crate::timing::{RenderDoc, time_method};

/// Times tet20 on `planned`'s scene built with `variant` (a change of the
/// tables' default flags); `what` names the variant in the progress line.
pub fn tet20_on_variant(
    planned: &Planned,
    cache: &mut MeshCache,
    variant: impl FnOnce(BuildFlags) -> BuildFlags,
    what: &str,
    (opts, frames, pool): (&RenderOptions, u32, &rayon::ThreadPool),
) -> Result<RenderDoc> {
    eprintln!("  {}: {what}", planned.spec);
    let mesh = cache.load(planned, &variant(TABLE_FLAGS), false)?.0;
    Ok(time_method(&mesh, Method::Tet20, opts, frames, pool)?.0)
}
