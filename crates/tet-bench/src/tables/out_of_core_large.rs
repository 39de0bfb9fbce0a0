//! Out of core where it matters (Erkoç et al. 2021: the scenes that
//! do not fit): `fan-sphere:N`, a closed bumpy sphere whose poles are fans
//! of about √N long thin triangles (the mesh whose cuts once failed), built
//! in parts under its builder's own share plus a sixteenth of its
//! predicted in-core TetGen peak, in a process of its own as a user runs
//! it. Per size: parts, build time, the process tree's peak against the
//! limit, and tet20's speed, tets per ray and failures on the merged mesh
//! against the f64 reference.

use std::fmt::Write as _;

#[cfg(not(feature = "tetgen"))]
use super::doc::LargeOutOfCoreRow;
use super::doc::TablesDoc;

/// The limit's share of the predicted in-core TetGen peak, beside the
/// builder's own share.
pub const IN_CORE_SHARE: u64 = 16;

#[cfg(feature = "tetgen")]
pub use measuring::measure_all;

/// The measurement: builds in processes of their own (they run TetGen,
/// so only with the `tetgen` feature).
#[cfg(feature = "tetgen")]
mod measuring {
    use anyhow::{Context, Result};
    use tet_build::outofcore::admission::builder_bytes;
    use tet_build::scene::Scene;
    use tet_trace_cpu::render::RenderOptions;

    use crate::accuracy::{RayPlan, run_case};
    use crate::load::with_mesh;
    use crate::methods::method::{Method, Precision};
    use crate::outofcore::predict;
    use crate::tables::doc::{LargeOutOfCoreRow, TABLE_FLAGS};
    use crate::tables::out_of_core::build_in_own_process;
    use crate::tables::out_of_core_large::IN_CORE_SHARE;
    use crate::timing::time_method;

    /// One row per size (a failed size is a row with its error).
    pub fn measure_all(
        sizes: &[u64],
        opts: &RenderOptions,
        frames: crate::timing::Frames,
        pool: &rayon::ThreadPool,
    ) -> Vec<LargeOutOfCoreRow> {
        sizes
            .iter()
            .map(|&n| {
                let spec = format!("fan-sphere:{n}");
                let mut row = LargeOutOfCoreRow {
                    scene: spec.clone(),
                    triangles: 0,
                    predicted_in_core_bytes: 0,
                    limit_bytes: 0,
                    memory: None,
                    tets: 0,
                    tet20: None,
                    accuracy: None,
                    error: None,
                };
                if let Err(e) = measure_one(&spec, &mut row, opts, frames, pool) {
                    eprintln!("  {spec}: {e:#}");
                    row.error = Some(format!("{e:#}"));
                }
                row
            })
            .collect()
    }

    /// Builds `spec` under its limit, then times and checks tet20 on the
    /// merged mesh, filling `row` as it goes.
    fn measure_one(
        spec: &str,
        row: &mut LargeOutOfCoreRow,
        opts: &RenderOptions,
        frames: crate::timing::Frames,
        pool: &rayon::ThreadPool,
    ) -> Result<()> {
        let scene = Scene::load(spec).with_context(|| format!("cannot make `{spec}`"))?;
        row.triangles = scene.triangles.len();
        row.predicted_in_core_bytes = predict(&scene, TABLE_FLAGS.no_box)?.predicted_peak_bytes;
        row.limit_bytes =
            builder_bytes(scene.triangles.len()) + row.predicted_in_core_bytes / IN_CORE_SHARE;
        eprintln!(
            "large out of core: {spec} under {:.1} MiB",
            row.limit_bytes as f64 / (1024.0 * 1024.0)
        );
        let file = std::env::temp_dir().join(format!(
            "tet-bench-large-out-of-core-{}.tmesh",
            std::process::id()
        ));
        let threads = pool.current_num_threads();
        let built = build_in_own_process(spec, row.limit_bytes, threads, &file);
        let _ = std::fs::remove_file(&file);
        let (mesh, memory) = built?;
        row.memory = Some(memory);
        row.tets = mesh.tets.len();
        let merged = with_mesh(scene, mesh, None);
        row.tet20 = Some(time_method(&merged, Method::Tet20, opts, frames, pool)?.0);
        let plan = RayPlan {
            side: 256,
            random: 20_000,
            seed: 1,
            min_time_s: 0.0,
            adversarial: 0,
        };
        let case = run_case("merged", &merged, &[Method::Tet20], Precision::F32, plan)?;
        row.accuracy = case.methods.into_iter().next();
        Ok(())
    }
}

/// Without TetGen there is nothing to build: no rows.
#[cfg(not(feature = "tetgen"))]
pub fn measure_all(
    _: &[u64],
    _: &tet_trace_cpu::render::RenderOptions,
    _: crate::timing::Frames,
    _: &rayon::ThreadPool,
) -> Vec<LargeOutOfCoreRow> {
    Vec::new()
}

/// The table (or why there is none).
pub fn markdown(m: &mut String, doc: &TablesDoc) {
    let _ = writeln!(
        m,
        "\n## Out of core past one machine's share (Erkoç et al. 2021)\n"
    );
    if doc.large_out_of_core.is_empty() {
        let note = doc.large_out_of_core_note.as_deref().unwrap_or("no rows");
        let _ = writeln!(m, "Large out-of-core table {note}.");
        return;
    }
    let _ = writeln!(
        m,
        "`fan-sphere:N`: a closed bumpy sphere whose poles are fans of about √N long thin triangles, built with `tet-bench build SCENE --memory-limit L` in a process of its own, L = the builder's own share + 1/{IN_CORE_SHARE} of TetGen's predicted in-core peak. The builder holds the scene once: every part's triangles are taken from it when the part starts, and only the triangles the planes cut are clipped ahead. Tree peak: the builder and its workers together (sampled every 2 ms), what the limit bounds. Failures: tet20 (f32) against the f64 reference over the merged mesh's constrained faces, on its camera image (256²) and 20,000 random rays.\n"
    );
    let _ = writeln!(
        m,
        "| scene | triangles | in-core prediction MiB | limit MiB | parts (at once, planner) | build s | builder peak MiB | tree peak MiB | tets | tet20 Mrays/s | tets per ray | failures / rays |"
    );
    let _ = writeln!(
        m,
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    let mib = |b: u64| b as f64 / (1024.0 * 1024.0);
    for r in &doc.large_out_of_core {
        let (Some(mem), None) = (&r.memory, &r.error) else {
            let _ = writeln!(
                m,
                "| {} | {} | {:.0} | {:.1} | failed: {} | | | | | | | |",
                r.scene,
                r.triangles,
                mib(r.predicted_in_core_bytes),
                mib(r.limit_bytes),
                r.error.as_deref().unwrap_or("")
            );
            continue;
        };
        let kib = |k: Option<u64>| k.map_or("–".into(), |k| format!("{:.1}", k as f64 / 1024.0));
        let failures = r
            .accuracy
            .as_ref()
            .map_or("–".into(), |a| format!("{} / {}", a.failures, a.rays));
        let _ = writeln!(
            m,
            "| {} | {} | {:.0} | {:.1} | {} ({} at once, {}) | {:.1} | {} | {} | {} | {:.2} | {:.1} | {} |",
            r.scene,
            r.triangles,
            mib(r.predicted_in_core_bytes),
            mib(r.limit_bytes),
            mem.parts,
            mem.parallel_parts,
            mem.planner,
            mem.total_s,
            kib(mem.process_peak_kib),
            kib(mem.tree_peak_kib),
            r.tets,
            r.tet20.as_ref().map_or(f64::NAN, |t| t.mrays_per_s),
            r.tet20.as_ref().map_or(f64::NAN, |t| t.tets_per_ray),
            failures
        );
    }
}
