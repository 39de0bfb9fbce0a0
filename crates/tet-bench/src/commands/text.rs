//! Console text shared by the commands (`build` and `info` both print a
//! construction report).

use anyhow::Result;

use crate::load::BuildSummary;
use crate::output::outln;

/// Prints a construction report.
pub fn print_build(b: &BuildSummary) -> Result<()> {
    outln!(
        "  build: TetGen `{}`; {} scene triangles, {} Steiner points",
        b.switches,
        b.scene_triangles,
        b.steiner_points
    )?;
    outln!(
        "  times: clean {:.3} s, resolve {:.3} s, TetGen {:.3} s, assemble+validate {:.3} s, reorder {:.3} s, total {:.3} s; TetGen peak {}",
        b.clean_s,
        b.resolve_s,
        b.tetgen_s,
        b.assemble_s,
        b.reorder_s,
        b.total_s,
        b.worker_peak_kib
            .map_or("n/a".into(), |k| format!("{:.1} MB", k as f64 / 1024.0))
    )?;
    let c = &b.cleaning;
    outln!(
        "  cleaning: {} vertices merged, {} repeated-vertex, {} zero-area, {} duplicate triangles dropped, {} unused vertices removed",
        c.merged_vertices,
        c.repeated_vertex_triangles,
        c.zero_area_triangles,
        c.duplicate_triangles,
        c.unused_vertices
    )?;
    let r = &b.resolve;
    if r.pairs > 0 {
        outln!(
            "  resolved: {} intersecting pairs; {} triangles split, {} points added, {} overlapping pieces merged, {} rounds",
            r.pairs,
            r.split_triangles,
            r.added_points,
            r.merged_pieces,
            r.rounds
        )?;
    }
    Ok(())
}
