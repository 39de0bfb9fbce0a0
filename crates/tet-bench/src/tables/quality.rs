//! Build trade: the surface-preserving `-pY` build against the quality
//! bound `-pYq5` (tets, build time, tet20 speed).

use std::fmt::Write as _;

use anyhow::Result;
use tet_trace_cpu::render::RenderOptions;

use super::doc::{QualityTrade, TABLE_FLAGS, TablesDoc};
use super::plan::{MeshCache, Planned};
use crate::cli::{BuildFlags, Method};
use crate::load::BuildSummary;
use crate::timing::time_method;

/// The scene built with `-q5` (at most 2 M Steiner points) and tet20 on it.
pub fn measure(
    planned: &Planned,
    cache: &mut MeshCache,
    opts: &RenderOptions,
    frames: u32,
    pool: &rayon::ThreadPool,
) -> Result<QualityTrade> {
    eprintln!("  {}: quality-refined build (-q5)", planned.spec);
    let flags = BuildFlags {
        quality: Some(5.0),
        max_steiner: Some(2_000_000),
        ..TABLE_FLAGS
    };
    let refined = cache.load(planned, &flags, false)?.0;
    Ok(QualityTrade {
        tets: refined.mesh.tets.len(),
        build: refined.build.clone(),
        tet20: time_method(&refined, Method::Tet20, opts, frames, pool)?.0,
    })
}

/// The table (full mode only).
pub fn markdown(m: &mut String, doc: &TablesDoc) {
    if doc.scenes.iter().any(|sc| sc.quality5.is_some()) {
        let _ = writeln!(
            m,
            "\n## Build trade: surface-preserving `-pY` vs quality `-pYq5`\n"
        );
        let _ = writeln!(
            m,
            "| scene | tets -pY | tets -q5 | build s -pY | build s -q5 | tet20 Mrays/s -pY | tet20 Mrays/s -q5 |"
        );
        let _ = writeln!(m, "|---|---:|---:|---:|---:|---:|---:|");
        for sc in &doc.scenes {
            let (Some(q), Some(i)) = (&sc.quality5, &sc.info) else {
                continue;
            };
            let base = sc.renders.iter().find(|r| r.method == Method::Tet20);
            let secs = |b: &Option<BuildSummary>| b.as_ref().map_or(f64::NAN, |b| b.total_s);
            let _ = writeln!(
                m,
                "| {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} |",
                i.name,
                i.tets,
                q.tets,
                secs(&i.build),
                secs(&q.build),
                base.map_or(f64::NAN, |r| r.mrays_per_s),
                q.tet20.mrays_per_s
            );
        }
    }
}
