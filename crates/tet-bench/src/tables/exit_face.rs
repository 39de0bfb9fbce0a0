//! Exit-face search (Maria et al. 2017, Table 5): the cost of one
//! exit-face decision per method, and whole walks on the same grid
//! (measured by [`crate::timing::exitface`], single thread).

use std::fmt::Write as _;

use anyhow::Result;

use crate::timing::exitface::{self, ExitFaceSizes, ExitFaceTable};

/// The exit-face table, at the quick or full sizes.
pub fn measure(quick: bool) -> Result<ExitFaceTable> {
    let sizes = if quick {
        ExitFaceSizes::QUICK
    } else {
        ExitFaceSizes::FULL
    };
    eprintln!(
        "exit-face search: {} tets × {} lines, {} walks (single thread)",
        sizes.tets, sizes.rays_per_tet, sizes.walk_rays
    );
    exitface::run(sizes)
}

/// The table.
pub fn markdown(m: &mut String, x: &ExitFaceTable) {
    let z = &x.sizes;
    let _ = writeln!(m, "\n## Exit-face search (Maria et al. 2017, Table 5)\n");
    let _ = writeln!(
        m,
        "One thread. {} random tets of a jittered Kuhn grid ({} tets) × {} random lines through each (paper: 10,000 tets × 16,384 rays); a stab is one exit-face decision as a walk makes it after entering the tet (entry face and per-ray setup carried, not timed); best of {}. Decisions are checked against the exit face computed in f64. Paper ns = its CPU ms ÷ 163.84 M stabs (other CPU, other code: compare the ratios).\n",
        z.tets, x.grid_tets, z.rays_per_tet, z.repetitions
    );
    let _ = writeln!(
        m,
        "| decision | used by | ns per exit face | × Plücker | paper ns | paper × Ours | wrong | operations per tet |"
    );
    let _ = writeln!(m, "|---|---|---:|---:|---:|---:|---:|---|");
    let plucker = x
        .stabs
        .iter()
        .find(|r| r.used_by == "tet80")
        .map_or(f64::NAN, |r| r.ns_per_stab);
    let paper_ours = x
        .stabs
        .iter()
        .find(|r| r.used_by == "tet80")
        .and_then(|r| r.paper_ns_per_stab);
    for r in &x.stabs {
        let (pns, pratio) = match (r.paper_ns_per_stab, paper_ours) {
            (Some(p), Some(o)) => (format!("{p:.1}"), format!("{:.2}", p / o)),
            _ => ("–".into(), "–".into()),
        };
        let _ = writeln!(
            m,
            "| {} | {} | {:.2} | {:.2} | {pns} | {pratio} | {} | {} |",
            r.method,
            r.used_by,
            r.ns_per_stab,
            r.ns_per_stab / plucker,
            r.wrong,
            r.operations
        );
    }
    let _ = writeln!(
        m,
        "\nWhole walks on the same grid: {} random rays from random interior points walked to their first constrained face (5 % of faces constrained), one thread, best of {} (the criterion bench `tet-trace-cpu/benches/exit_face.rs` as a timed harness).\n",
        z.walk_rays, z.repetitions
    );
    let _ = writeln!(m, "| tracer | record bytes | tets visited | ns per tet |");
    let _ = writeln!(m, "|---|---:|---:|---:|");
    for w in &x.walks {
        let _ = writeln!(
            m,
            "| {} | {} | {} | {:.2} |",
            w.tracer, w.record_bytes, w.tets_visited, w.ns_per_tet
        );
    }
}
