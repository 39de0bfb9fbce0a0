//! tet20 on a variant of a scene's mesh (the same scene rebuilt with other
//! build flags) beside the default mesh: the measurement shared by the
//! tables that compare a build choice against the default one (Hilbert
//! sorting, the enclosing box).
//!
//! The two meshes are timed in alternating rounds (default, variant,
//! default, …) and each keeps its best round, so that a ratio compares
//! frames taken under the same load: a baseline timed minutes earlier, in
//! the render table, made a 2-core machine's noise look like a slow-down.

use anyhow::Result;
use tet_trace_cpu::render::RenderOptions;

use super::doc::TABLE_FLAGS;
use super::plan::{MeshCache, Planned};
use crate::load::Loaded;
use crate::load::build_flags::BuildFlags;
use crate::methods::method::Method;
use crate::timing::{RenderDoc, time_method};

/// Rounds of the alternating measurement (each of `frames` frames).
const ROUNDS: usize = 3;

/// tet20 on the default mesh and on the variant, timed alternately.
pub struct Paired {
    /// The default mesh (`baseline`).
    pub baseline: RenderDoc,
    /// The mesh built with the variant's flags.
    pub variant: RenderDoc,
}

/// Times tet20 on `baseline` (the scene's default mesh) and on `planned`'s
/// scene built with `variant` (a change of the tables' default flags), in
/// [`ROUNDS`] alternating rounds; `what` names the variant in the progress
/// line.
pub fn tet20_on_variant(
    planned: &Planned,
    baseline: &Loaded,
    cache: &mut MeshCache,
    variant: impl FnOnce(BuildFlags) -> BuildFlags,
    what: &str,
    (opts, frames, pool): (&RenderOptions, u32, &rayon::ThreadPool),
) -> Result<Paired> {
    eprintln!("  {}: {what}", planned.spec);
    let mesh = cache.load(planned, &variant(TABLE_FLAGS), false)?.0;
    let time = |loaded: &Loaded| time_method(loaded, Method::Tet20, opts, frames, pool);
    let faster = |a: RenderDoc, b: RenderDoc| if b.best_ms < a.best_ms { b } else { a };
    let (mut base, mut var) = (time(baseline)?.0, time(&mesh)?.0);
    for _ in 1..ROUNDS {
        base = faster(base, time(baseline)?.0);
        var = faster(var, time(&mesh)?.0);
    }
    Ok(Paired {
        baseline: base,
        variant: var,
    })
}
