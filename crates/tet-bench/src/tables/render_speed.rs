//! Render time per method (Aman et al. 2022, Table 1, right half):
//! every CPU method on every scene, with the ratio to the BVH measured in
//! the same run beside the paper's published ratio for that scene and,
//! on Torus Knots, the paper authors' own code's ratio measured on a
//! 2-core machine (absolute times are machine-bound, ratios travel).

use std::fmt::Write as _;

use anyhow::Result;
use tet_trace_cpu::render::RenderOptions;

use super::doc::{TablesDoc, is_torus_knots};
use super::paper::paper_scene;
use crate::load::Loaded;
use crate::methods::cpu_methods;
use crate::methods::method::Method;
use crate::timing::{Frames, RenderDoc, time_method};

/// neptun (the authors' C++ code) on a 2-core machine, Torus Knots,
/// 1920×1440 primary rays, 2 threads, Mrays/s, measured once for this
/// project: the paper-ratio column divides these by neptun's BVH.
const NEPTUN_TORUS_KNOTS_MRAYS: [(Method, f64); 7] = [
    (Method::Tet20, 5.23),
    (Method::Tet16, 4.84),
    (Method::Tet32, 2.31),
    (Method::Tet80, 1.65),
    (Method::Sctp, 2.79),
    (Method::Obvhs, 4.92),
    (Method::Embree, 11.3),
];

/// neptun's BVH on the same run, Mrays/s (the denominator of its ratios).
const NEPTUN_BVH_MRAYS: f64 = 4.92;

/// One timed render per CPU method.
pub fn measure(
    spec: &str,
    loaded: &Loaded,
    opts: &RenderOptions,
    frames: Frames,
    pool: &rayon::ThreadPool,
) -> Result<Vec<RenderDoc>> {
    let mut renders = Vec::new();
    for m in cpu_methods() {
        eprintln!("  {spec}: rendering with {}", m.name());
        renders.push(time_method(loaded, m, opts, frames, pool)?.0);
    }
    Ok(renders)
}

/// The table.
pub fn markdown(m: &mut String, doc: &TablesDoc) {
    let _ = writeln!(
        m,
        "\n## Render time per method (Aman et al. 2022, Table 1, right half)\n"
    );
    let _ = writeln!(
        m,
        "Ratio = method Mrays/s ÷ BVH (obvhs) Mrays/s in the same run. Paper ratio: Aman et al. (2022) Table 1, BVH ms ÷ method ms on the paper's scene. neptun ratio: the same ratio in the authors' own C++ renderer (neptun, github.com/aytekaman/neptun), measured on Torus Knots on a 2-core machine (1920×1440, 2 threads; its BVH 4.92 Mrays/s), – on other scenes. tets/ray: mean tets a primary ray visits (tet walks only); BVH nodes/ray: mean nodes whose box a ray tests (obvhs only); failures: primary rays whose walk failed (step cap, lost, invalid), not wrong answers (the robustness table counts those).\n"
    );
    let _ = writeln!(
        m,
        "| scene | method | best ms | median ms | Mrays/s | tets/ray | BVH nodes/ray | ratio to BVH | paper ratio | neptun ratio | failures |"
    );
    let _ = writeln!(m, "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for sc in &doc.scenes {
        let bvh = sc
            .renders
            .iter()
            .find(|r| r.method == Method::Obvhs)
            .map_or(f64::NAN, |r| r.mrays_per_s);
        for r in &sc.renders {
            let paper = paper_scene(&sc.spec)
                .and_then(|p| p.ratio_to_bvh(r.method))
                .map_or("–".to_string(), |v| format!("{v:.2}"));
            let neptun = NEPTUN_TORUS_KNOTS_MRAYS
                .iter()
                .find(|(pm, _)| *pm == r.method)
                .filter(|_| is_torus_knots(&sc.spec))
                .map_or("–".to_string(), |(_, v)| {
                    format!("{:.2}", v / NEPTUN_BVH_MRAYS)
                });
            let tets = if r.method.walks_tets() {
                format!("{:.1}", r.tets_per_ray)
            } else {
                "–".to_string()
            };
            let nodes = r
                .nodes_per_ray
                .map_or("–".to_string(), |n| format!("{n:.1}"));
            let _ = writeln!(
                m,
                "| {} | {} | {:.1} | {:.1} | {:.2} | {tets} | {nodes} | {:.2} | {paper} | {neptun} | {} |",
                r.scene,
                r.tracer,
                r.best_ms,
                r.median_ms,
                r.mrays_per_s,
                r.mrays_per_s / bvh,
                r.failures
            );
        }
    }
}
