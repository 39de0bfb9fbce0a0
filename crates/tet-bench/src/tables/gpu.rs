//! GPU methods (Aman et al. 2022, Table 3): the tet walks as wgpu
//! compute shaders, when built with `--features gpu` and an adapter is
//! present.

use std::fmt::Write as _;

use tet_trace_cpu::render::RenderOptions;

use super::doc::TablesDoc;
use super::paper::paper_scene;
use crate::load::Loaded;
use crate::methods::method::Method;
use crate::output::error_chain;
use crate::timing::RenderDoc;
use crate::timing::gpu::time_gpu;

/// The GPU methods' rows, or why there are none.
pub fn measure(
    loaded: &Loaded,
    opts: &RenderOptions,
    frames: u32,
) -> (Vec<RenderDoc>, Option<String>) {
    if !cfg!(feature = "gpu") {
        return (Vec::new(), Some("built without the `gpu` feature".into()));
    }
    let mut rows = Vec::new();
    for m in [
        Method::GpuTet20,
        Method::GpuTet16,
        Method::GpuTet32,
        Method::GpuTet80,
    ] {
        eprintln!("  {}: rendering with {}", loaded.name, m.name());
        match time_gpu(loaded, m, opts.width, opts.height, frames) {
            Ok(doc) => rows.push(doc),
            Err(e) => return (rows, Some(error_chain(&e))),
        }
    }
    (rows, None)
}

/// The table.
pub fn markdown(m: &mut String, doc: &TablesDoc) {
    let _ = writeln!(m, "\n## GPU (Aman et al. 2022, Table 3)\n");
    let _ = writeln!(
        m,
        "| scene | method (device) | best ms | Mrays/s | tets/ray | GPU bytes (tets + points) | failures | paper ms |"
    );
    let _ = writeln!(m, "|---|---|---:|---:|---:|---:|---:|---:|");
    for sc in &doc.scenes {
        for r in &sc.gpu_renders {
            let paper = paper_scene(&sc.spec)
                .and_then(|p| p.gpu_ms(r.method))
                .map_or("–".to_string(), |v| format!("{v:.2}"));
            let _ = writeln!(
                m,
                "| {} | {} | {:.2} | {:.2} | {:.1} | {} | {} | {paper} |",
                r.scene,
                r.tracer,
                r.best_ms,
                r.mrays_per_s,
                r.tets_per_ray,
                r.hot_bytes,
                r.failures
            );
        }
        if let Some(note) = &sc.gpu_note {
            let _ = writeln!(m, "| {} | no GPU rows: {note} | | | | | | |", sc.spec);
        }
    }
}
