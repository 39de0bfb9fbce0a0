//! Construction (Aman et al., seed 000 Table 1, left half): triangles,
//! points, tets, TetGen and total build time, BVH build time, regions.

use std::fmt::Write as _;
use std::time::Instant;

use anyhow::Result;

use super::doc::TablesDoc;
use crate::bvh::BvhTracer;
use crate::layouts::{Info, info};
use crate::load::Loaded;

/// The scene's counts and layout bytes, and the seconds to build its BVH.
pub fn measure(loaded: &Loaded) -> Result<(Info, f64)> {
    let info = info(loaded, false)?;
    let bvh_start = Instant::now();
    drop(BvhTracer::new(&loaded.mesh));
    Ok((info, bvh_start.elapsed().as_secs_f64()))
}

/// The table.
pub fn markdown(m: &mut String, doc: &TablesDoc) {
    let _ = writeln!(m, "\n## Construction (seed 000 Table 1, left half)\n");
    let _ = writeln!(
        m,
        "| scene | triangles | points | tets | TetGen s | total build s | BVH build s | regions |"
    );
    let _ = writeln!(m, "|---|---:|---:|---:|---:|---:|---:|---:|");
    for sc in &doc.scenes {
        if let Some(i) = &sc.info {
            let (tg, tot) = i
                .build
                .as_ref()
                .map_or((f64::NAN, f64::NAN), |b| (b.tetgen_s, b.total_s));
            let shared = if sc.mesh_reused {
                " (mesh shared)"
            } else if !sc.shares_mesh_with.is_empty() {
                " (built once for its group)"
            } else {
                ""
            };
            let _ = writeln!(
                m,
                "| {}{shared} | {} | {} | {} | {:.2} | {:.2} | {:.3} | {} |",
                i.name,
                i.triangles,
                i.points,
                i.tets,
                tg,
                tot,
                sc.bvh_build_s.unwrap_or(f64::NAN),
                i.regions.count
            );
        }
    }
}
