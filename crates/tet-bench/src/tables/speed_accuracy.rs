//! Speed against accuracy: every CPU method in f32 and, where it has one,
//! f64, on the first scene as given and on its extreme cases (scaled,
//! translated, slivers: [`crate::accuracy::extremes`]) — Maria et al.'s robustness
//! (Maria et al. 2017, Table 4) beside the speed it costs.

use std::fmt::Write as _;

use anyhow::Result;

use super::doc::{SpeedAccuracy, TABLE_FLAGS};
use crate::accuracy::{CaseAccuracy, RayPlan, all_cases};
use crate::load::load;
use crate::methods::cpu_methods;
use crate::methods::method::Precision;
use crate::output::error_chain;

/// Runs the speed-against-accuracy cases on `spec`, each method timed for
/// at least `min_time_s`.
pub fn measure(spec: &str, quick: bool, min_time_s: f64) -> SpeedAccuracy {
    let flags = TABLE_FLAGS;
    let (side, rays) = if quick { (128, 5_000) } else { (512, 50_000) };
    let run = || -> Result<Vec<CaseAccuracy>> {
        let loaded = load(spec, &flags, true)?;
        let plan = RayPlan {
            side,
            random: rays,
            seed: 7,
            min_time_s,
            adversarial: 0,
        };
        all_cases(
            &loaded,
            &cpu_methods(),
            Precision::Both,
            plan,
            Some(&flags),
            true,
        )
    };
    match run() {
        Ok(cases) => SpeedAccuracy {
            scene: spec.to_string(),
            cases,
            error: None,
        },
        Err(e) => SpeedAccuracy {
            scene: spec.to_string(),
            cases: Vec::new(),
            error: Some(error_chain(&e)),
        },
    }
}

/// The table.
pub fn markdown(m: &mut String, x: &SpeedAccuracy) {
    let _ = writeln!(
        m,
        "\n## Speed vs accuracy: precision and extreme scenes ({})\n",
        x.scene
    );
    let _ = writeln!(
        m,
        "Per case, the same camera and random interior rays for every method; failures as above (per 1024² rays); Mrays/s: the best of passes over these same rays (all threads), repeated for at least `--min-time` seconds per method (0.5 s, or 0.2 s with `--quick`), so speeds compare within a case; half the rays are random interior rays (incoherent), so these speeds lie below the render table's camera rays and do not compare with it. Cases: the scene as given (with `--quick` the single torus knot), scaled by 1e-4, 1e4, 1e-30 and 1e30 (each rebuilt; at ×1e±30 sctp and tet80 in f32 are left out: their 3-D products leave f32's range), translated by 1e5, and a sliver-heavy jittered grid.\n"
    );
    if let Some(e) = &x.error {
        let _ = writeln!(m, "Not measured: {e}\n");
        return;
    }
    let _ = writeln!(
        m,
        "| case | method | precision | rays | leaks | wrong | false miss | false hit | cap | lost + NaN | failures per 1024² | Mrays/s |"
    );
    let _ = writeln!(
        m,
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for c in &x.cases {
        if let Some(why) = &c.skipped {
            let _ = writeln!(m, "| {} | skipped: {why} | | | | | | | | | | |", c.case);
            continue;
        }
        for r in &c.methods {
            let _ = writeln!(
                m,
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2} | {:.2} |",
                c.case,
                r.method,
                r.precision,
                r.rays,
                r.leaks,
                r.wrong_triangle,
                r.false_misses,
                r.false_hits,
                r.step_cap,
                r.lost + r.nans,
                r.failures_per_1024_squared,
                r.mrays_per_s
            );
        }
        for left in &c.left_out {
            let _ = writeln!(
                m,
                "| {} | {left}: left out (f32 products out of range) | | | | | | | | | | |",
                c.case
            );
        }
    }
}
