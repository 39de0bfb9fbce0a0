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
use crate::timing::{Frames, RenderDoc, time_method};

/// Rounds of the alternating measurement (each of `frames` frames).
const ROUNDS: usize = 3;

/// tet20 on the default mesh and on the variant, timed alternately.
pub struct Paired {
    /// The default mesh (`baseline`).
    pub baseline: RenderDoc,
    /// The mesh built with the variant's flags.
    pub variant: RenderDoc,
    /// Each round's speed-up of the default mesh over the variant (the
    /// variant's best frame time over the default's, in that round): the
    /// spread that tells a real difference from the machine's noise.
    pub round_speedups: Vec<f64>,
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
    (opts, frames, pool): (&RenderOptions, Frames, &rayon::ThreadPool),
) -> Result<Paired> {
    eprintln!("  {}: {what}", planned.spec);
    let mesh = cache.load(planned, &variant(TABLE_FLAGS), false)?.0;
    let time = |loaded: &Loaded| time_method(loaded, Method::Tet20, opts, frames, pool);
    let faster = |a: RenderDoc, b: RenderDoc| if b.best_ms < a.best_ms { b } else { a };
    let (mut base, mut var) = (time(baseline)?.0, time(&mesh)?.0);
    let mut round_speedups = vec![var.best_ms / base.best_ms];
    for _ in 1..ROUNDS {
        let (b, v) = (time(baseline)?.0, time(&mesh)?.0);
        round_speedups.push(v.best_ms / b.best_ms);
        base = faster(base, b);
        var = faster(var, v);
    }
    Ok(Paired {
        baseline: base,
        variant: var,
        round_speedups,
    })
}

/// A speed-up as the tables print it, `1.05×`, followed by its range over
/// the rounds, `(0.98–1.09×)`, when there was more than one, and by `†`
/// when it is below 1, the opposite of what the paper found (the legend
/// under the table says so).
pub fn speedup_cell(best: f64, rounds: &[f64]) -> String {
    let mut s = format!("{best:.2}×");
    if rounds.len() > 1 {
        let lo = rounds.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = rounds.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        s.push_str(&format!(" ({lo:.2}–{hi:.2}×)"));
    }
    if best < 1.0 {
        s.push_str(" †");
    }
    s
}

#[cfg(test)]
mod tests {
    use super::speedup_cell;

    #[test]
    fn a_speedup_shows_its_spread_and_marks_a_contradiction() {
        assert_eq!(speedup_cell(1.25, &[1.25]), "1.25×");
        assert_eq!(
            speedup_cell(1.05, &[0.98, 1.09, 1.05]),
            "1.05× (0.98–1.09×)"
        );
        assert_eq!(
            speedup_cell(0.83, &[0.95, 0.80, 0.9]),
            "0.83× (0.80–0.95×) †"
        );
        assert_eq!(speedup_cell(0.9, &[]), "0.90× †");
    }
}
