//! Construction (Aman et al. 2022, Table 1, left half): triangles,
//! points, tets, the self-intersections resolved and the time it took,
//! TetGen and total build time, BVH build time, regions; beside the
//! paper's triangles and Tet-mesh-20 build time for that scene.

use std::fmt::Write as _;
use std::time::Instant;

use anyhow::Result;

use super::doc::TablesDoc;
use super::paper::paper_scene;
use crate::load::Loaded;
use crate::methods::bvh::BvhTracer;
use crate::methods::layouts::{Info, info};

/// The scene's counts and layout bytes, and the seconds to build its BVH.
pub fn measure(loaded: &Loaded) -> Result<(Info, f64)> {
    let info = info(loaded, false)?;
    let bvh_start = Instant::now();
    drop(BvhTracer::new(&loaded.mesh));
    Ok((info, bvh_start.elapsed().as_secs_f64()))
}

/// The table.
pub fn markdown(m: &mut String, doc: &TablesDoc) {
    let _ = writeln!(
        m,
        "\n## Construction (Aman et al. 2022, Table 1, left half)\n"
    );
    let _ = writeln!(
        m,
        "| scene | triangles | points | tets | pairs resolved | resolve s | TetGen s | total build s | BVH build s | regions | paper triangles | paper build s | paper BVH s |"
    );
    let _ = writeln!(
        m,
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for sc in &doc.scenes {
        if let Some(i) = &sc.info {
            let (tg, tot) = i
                .build
                .as_ref()
                .map_or((f64::NAN, f64::NAN), |b| (b.tetgen_s, b.total_s));
            let (pairs, resolve_s) = i.build.as_ref().map_or(("–".into(), "–".into()), |b| {
                (b.resolve.pairs.to_string(), format!("{:.3}", b.resolve_s))
            });
            let paper = paper_scene(&sc.spec).map_or("– | – | –".to_string(), |p| {
                format!("{} | {:.2} | {:.3}", p.triangles, p.build_s, p.bvh_build_s)
            });
            let shared = if sc.mesh_reused {
                " (mesh shared)"
            } else if !sc.shares_mesh_with.is_empty() {
                " (built once for its group)"
            } else {
                ""
            };
            let _ = writeln!(
                m,
                "| {}{shared} | {} | {} | {} | {pairs} | {resolve_s} | {:.2} | {:.2} | {:.3} | {} | {paper} |",
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
