//! Entry through the boundary (tight box) vs a camera inside the mesh
//! (wide box), tet20: what starting rays outside the mesh costs or saves.

use std::fmt::Write as _;

use anyhow::Result;
use tet_trace_cpu::render::RenderOptions;

use super::doc::TablesDoc;
use super::plan::{MeshCache, Planned};
use super::variant::{Paired, speedup_cell, tet20_on_variant};
use crate::load::Loaded;
use crate::load::build_flags::BuildFlags;
use crate::timing::Frames;

/// tet20 on the scene built with `--wide-box` (the camera inside the mesh).
pub fn measure(
    planned: &Planned,
    baseline: &Loaded,
    cache: &mut MeshCache,
    opts: &RenderOptions,
    frames: Frames,
    pool: &rayon::ThreadPool,
) -> Result<Paired> {
    let variant = |flags| BuildFlags {
        wide_box: true,
        ..flags
    };
    tet20_on_variant(
        planned,
        baseline,
        cache,
        variant,
        "wide-box mesh (camera inside)",
        (opts, frames, pool),
    )
}

/// The table.
pub fn markdown(m: &mut String, doc: &TablesDoc) {
    let _ = writeln!(
        m,
        "\n## Entry through the boundary (tight box) vs camera inside the mesh (wide box), tet20\n"
    );
    let _ = writeln!(
        m,
        "Tight: the enclosing box holds the scene only (0.2 % margin) and primary rays from the camera outside enter through the mesh boundary (rays that miss it visit no tet). Wide (`--wide-box`): the box also holds the camera and lights (10 % margin), as in the papers' meshes, and every ray walks from the camera's tet. The two meshes timed in alternating rounds, the best frame of each. Speed-up: tight ÷ wide from the best frames, then its range over the rounds; † marks a speed-up below 1 (the wide box, the papers' choice, faster): read it against that range, which is the machine's noise where it spans 1.\n"
    );
    let _ = writeln!(
        m,
        "| scene | tight Mrays/s | tight tets/ray | wide Mrays/s | wide tets/ray | speed-up |"
    );
    let _ = writeln!(m, "|---|---:|---:|---:|---:|---:|");
    for sc in &doc.scenes {
        if let (Some(a), Some(b)) = (&sc.tight_box_tet20, &sc.wide_box_tet20) {
            let _ = writeln!(
                m,
                "| {} | {:.2} | {:.1} | {:.2} | {:.1} | {} |",
                a.scene,
                a.mrays_per_s,
                a.tets_per_ray,
                b.mrays_per_s,
                b.tets_per_ray,
                speedup_cell(a.mrays_per_s / b.mrays_per_s, &sc.tight_box_round_speedups)
            );
        }
    }
}
