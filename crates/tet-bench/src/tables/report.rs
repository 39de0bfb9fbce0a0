//! The report writers of `tables`: the Markdown report (the run's setup,
//! then each table's own section in a fixed order), the CSV of render and
//! accuracy rows, and the files. They take the measured [`TablesDoc`] and
//! never measure.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result};

use super::doc::TablesDoc;
use super::{
    construction, entry, exit_face, gpu, isosurfaces, large_models, memory, out_of_core,
    out_of_core_large, quality, render_speed, robustness, secondary, sorting, speed_accuracy,
    strips_vs_bvh, zoom,
};

/// The Markdown report (`tables.md`, and stdout without `--json`).
pub fn markdown(doc: &TablesDoc) -> String {
    let s = &doc.setup;
    let mut m = String::new();
    let _ = writeln!(m, "# Reproduction tables\n");
    let _ = writeln!(
        m,
        "Machine: {} logical CPUs, {} worker threads, {}; images {}×{}, best of {} frames; compile-time features: {}; {} mode; total {:.0} s.\n",
        s.cpus,
        s.threads,
        s.platform,
        s.width,
        s.height,
        s.frames,
        if s.target_features.is_empty() {
            "baseline (no target-cpu=native)".to_string()
        } else {
            s.target_features.join(", ")
        },
        if s.quick { "quick" } else { "full" },
        doc.total_s
    );
    for sc in doc.scenes.iter().filter(|sc| sc.error.is_some()) {
        let _ = writeln!(
            m,
            "* `{}` failed: {}",
            sc.spec,
            sc.error.as_deref().unwrap_or("")
        );
    }
    for sc in &doc.scenes {
        for e in &sc.partial_errors {
            let _ = writeln!(m, "* `{}`, {e} (row left out)", sc.spec);
        }
    }

    construction::markdown(&mut m, doc);
    render_speed::markdown(&mut m, doc);
    secondary::markdown(&mut m, doc);
    memory::markdown(&mut m, doc);
    strips_vs_bvh::markdown(&mut m, doc);
    sorting::markdown(&mut m, doc);
    entry::markdown(&mut m, doc);
    zoom::markdown(&mut m, doc);
    quality::markdown(&mut m, doc);
    gpu::markdown(&mut m, doc);
    robustness::markdown(&mut m, doc);
    if let Some(x) = &doc.speed_accuracy {
        speed_accuracy::markdown(&mut m, x);
    }
    if let Some(x) = &doc.exit_face {
        exit_face::markdown(&mut m, x);
    }
    isosurfaces::markdown(&mut m, doc);
    large_models::markdown(&mut m, doc);
    out_of_core::markdown(&mut m, doc);
    out_of_core_large::markdown(&mut m, doc);
    if !doc.figures.is_empty() {
        let _ = writeln!(m, "\n## Figures\n");
        for f in &doc.figures {
            let _ = writeln!(m, "* `{f}`");
        }
    }
    m
}

/// Writes `bytes` to `path` through a temporary file renamed into place.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let tmp = path.with_extension("tmp");
    std::fs::write(&tmp, bytes).with_context(|| format!("cannot write {}", tmp.display()))?;
    std::fs::rename(&tmp, path).with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}

/// Writes `tables.md`, `tables.json` and `tables.csv` into `dir`.
pub fn write_outputs(dir: &Path, doc: &TablesDoc, markdown: &str) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    write_atomic(&dir.join("tables.md"), markdown.as_bytes())?;
    write_atomic(
        &dir.join("tables.json"),
        serde_json::to_string_pretty(doc)?.as_bytes(),
    )?;
    write_atomic(&dir.join("tables.csv"), csv(doc).as_bytes())?;
    Ok(())
}

/// One CSV row per (scene, method): render and accuracy columns.
fn csv(doc: &TablesDoc) -> String {
    let mut s = String::from(
        "scene,method,tracer,width,height,threads,best_ms,median_ms,mrays_per_s,tets_per_ray,hot_bytes,setup_s,failures_per_1024_squared,nodes_per_ray\n",
    );
    for sc in &doc.scenes {
        for r in &sc.renders {
            let fails = sc
                .accuracy
                .as_ref()
                .and_then(|a| a.methods.iter().find(|m| m.method == r.tracer))
                .map_or(String::new(), |m| {
                    format!("{:.3}", m.failures_per_1024_squared)
                });
            // Tets per ray only for tet walks; bytes where measured.
            let tets = if r.method.walks_tets() {
                format!("{:.2}", r.tets_per_ray)
            } else {
                String::new()
            };
            let bytes = if r.hot_bytes > 0 {
                r.hot_bytes.to_string()
            } else {
                String::new()
            };
            let _ = writeln!(
                s,
                "{},{},{},{},{},{},{:.3},{:.3},{:.4},{tets},{bytes},{:.4},{},{}",
                r.scene,
                r.method.name(),
                r.tracer,
                r.width,
                r.height,
                r.threads,
                r.best_ms,
                r.median_ms,
                r.mrays_per_s,
                r.setup_s,
                fails,
                r.nodes_per_ray.map_or(String::new(), |n| format!("{n:.2}"))
            );
        }
    }
    s
}
