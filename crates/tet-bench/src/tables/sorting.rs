//! Hilbert-sorted vs unsorted mesh (Aman et al. 2022, Figure 8):
//! tet20 on the mesh in TetGen's order against the sorted one.

use std::fmt::Write as _;

use anyhow::Result;
use tet_trace_cpu::render::RenderOptions;

use super::doc::TablesDoc;
use super::plan::{MeshCache, Planned};
use super::variant::{Paired, speedup_cell, tet20_on_variant};
use crate::load::Loaded;
use crate::load::build_flags::BuildFlags;
use crate::timing::Frames;

/// tet20 on the scene built without Hilbert sorting.
pub fn measure(
    planned: &Planned,
    baseline: &Loaded,
    cache: &mut MeshCache,
    opts: &RenderOptions,
    frames: Frames,
    pool: &rayon::ThreadPool,
) -> Result<Paired> {
    let variant = |flags| BuildFlags {
        no_sort: true,
        ..flags
    };
    tet20_on_variant(
        planned,
        baseline,
        cache,
        variant,
        "unsorted mesh for Figure 8",
        (opts, frames, pool),
    )
}

/// The table.
pub fn markdown(m: &mut String, doc: &TablesDoc) {
    let _ = writeln!(
        m,
        "\n## Hilbert-sorted vs unsorted (Aman et al. 2022, Figure 8), tet20\n"
    );
    let _ = writeln!(
        m,
        "The two meshes timed in alternating rounds, the best frame of each (so the sorted figure may differ from the render table's). Speed-up: sorted ÷ unsorted from the best frames, then its range over the rounds (each round's best frames); † marks a speed-up below 1, the opposite of the paper's finding: read it against that range, which is the machine's noise where it spans 1.\n"
    );
    let _ = writeln!(
        m,
        "| scene | sorted Mrays/s | unsorted Mrays/s | speed-up |"
    );
    let _ = writeln!(m, "|---|---:|---:|---:|");
    for sc in &doc.scenes {
        if let (Some(a), Some(b)) = (&sc.sorted_tet20, &sc.unsorted_tet20) {
            let _ = writeln!(
                m,
                "| {} | {:.2} | {:.2} | {} |",
                a.scene,
                a.mrays_per_s,
                b.mrays_per_s,
                speedup_cell(a.mrays_per_s / b.mrays_per_s, &sc.sorting_round_speedups)
            );
        }
    }
}
