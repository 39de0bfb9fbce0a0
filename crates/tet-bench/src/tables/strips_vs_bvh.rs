//! Ray-Strips (Lauterbach et al. 2007, Tables 1, 3, 4 and 5) per
//! scene: the structure's bytes split as Table 1 splits them beside the
//! BVH baseline's, single rays (Table 3, from the render table's
//! `strips` and `obvhs` rows of the same run) and 2×2 packets (Table 4) as
//! ratios to the BVH, and the construction statistics (Table 5), with the
//! paper's Bunny figures beside ours on the Stanford bunny.

use std::fmt::Write as _;
use std::time::Instant;

use anyhow::Result;
use tet_trace_cpu::render::RenderOptions;

use super::doc::{StripsRow, TablesDoc};
use crate::load::Loaded;
use crate::methods::bvh::BvhTracer;
use crate::methods::method::Method;
use crate::methods::strips::StripsTracer;
use crate::timing::{Frames, time_method};

/// The paper's Bunny row (67 k triangles): Table 1 MB (Ray-Strips total,
/// geometry, hierarchy; BVH hierarchy; indexed-list + BVH total;
/// optimised + BVH total), Tables 3–4 fps (Ray-Strips, BVH), Table 5.
struct PaperBunny;

impl PaperBunny {
    /// Table 1: Ray-Strips total, MB.
    const TOTAL_MB: f64 = 1.5;
    /// Table 1: Ray-Strips geometry, MB.
    const GEOMETRY_MB: f64 = 1.2;
    /// Table 1: Ray-Strips hierarchy, MB.
    const HIERARCHY_MB: f64 = 0.3;
    /// Table 1: the BVH's hierarchy, MB.
    const BVH_HIERARCHY_MB: f64 = 4.2;
    /// Table 1: BVH + optimised triangles, total MB.
    const OPTIMISED_TOTAL_MB: f64 = 7.4;
    /// Table 3: single rays, fps (Ray-Strips, BVH).
    const SINGLE_FPS: (f64, f64) = (2.39, 4.52);
    /// Table 4: 2×2 packets, fps (Ray-Strips, BVH).
    const PACKET_FPS: (f64, f64) = (7.04, 10.42);
    /// Table 5: build s (Ray-Strips, BVH).
    const BUILD_S: (f64, f64) = (0.4, 0.03);
    /// Table 5: strips.
    const STRIPS: usize = 4260;
    /// Table 5: triangles per strip.
    const MEAN_STRIP: f64 = 19.29;
}

/// True for the scene the paper's Bunny row belongs to.
fn is_bunny(spec: &str) -> bool {
    spec.to_ascii_lowercase().contains("bunny")
}

/// Builds Ray-Strips and the BVH over the scene's triangles and renders
/// the packet variant.
pub fn measure(
    spec: &str,
    loaded: &Loaded,
    opts: &RenderOptions,
    frames: Frames,
    pool: &rayon::ThreadPool,
) -> Result<StripsRow> {
    let mesh = &loaded.mesh;
    let strips = StripsTracer::new(mesh, false)?;
    let t = Instant::now();
    let bvh = BvhTracer::new(mesh);
    let bvh_build_s = t.elapsed().as_secs_f64();
    let (bvh_hierarchy_bytes, bvh_geometry_bytes) = bvh.bytes();
    let (s, b) = (strips.strips().stats(), strips.strips().bytes());
    eprintln!("  {spec}: rendering with strips-packets");
    let packets = time_method(loaded, Method::StripsPackets, opts, frames, pool)?.0;
    Ok(StripsRow {
        triangles: s.triangles,
        strips: s.strips,
        mean_strip_triangles: s.mean_strip_triangles,
        chunks: s.chunks,
        build_s: strips.build_s(),
        bvh_build_s,
        geometry_bytes: b.geometry,
        hierarchy_bytes: b.hierarchy,
        top_level_bytes: b.top_level,
        total_bytes: b.total,
        bvh_hierarchy_bytes,
        bvh_geometry_bytes,
        packets,
    })
}

/// MB (10⁶ bytes), two decimals.
fn mb(b: usize) -> String {
    format!("{:.2}", b as f64 / 1e6)
}

/// The paper's value on the bunny, else a dash.
fn paper(spec: &str, v: String) -> String {
    if is_bunny(spec) { v } else { "–".into() }
}

/// The tables.
pub fn markdown(m: &mut String, doc: &TablesDoc) {
    let rows: Vec<_> = doc
        .scenes
        .iter()
        .filter_map(|sc| Some((sc, sc.ray_strips.as_ref()?)))
        .collect();
    if rows.is_empty() {
        return;
    }
    let _ = writeln!(
        m,
        "\n## Ray-Strips (Lauterbach et al. 2007, Tables 1, 3, 4, 5)\n"
    );
    let _ = writeln!(
        m,
        "Ray-Strips (`ray-strips` crate, default options) and the obvhs BVH over the same triangles (the mesh's constrained faces). MB = 10⁶ bytes; the BVH's geometry is its precomputed intersection triangles and face ids (the paper's \"optimized\" representation). Paper columns: the paper's Bunny (67 k triangles) on the Stanford bunny only.\n"
    );
    let _ = writeln!(
        m,
        "| scene | triangles | Ray-Strips MB (geometry + hierarchy + top = total) | B/triangle | BVH MB (hierarchy + geometry = total) | B/triangle | paper Ray-Strips MB | paper BVH + optimised MB |"
    );
    let _ = writeln!(m, "|---|---:|---|---:|---|---:|---:|---:|");
    for (sc, r) in &rows {
        let bvh_total = r.bvh_hierarchy_bytes + r.bvh_geometry_bytes;
        let n = r.triangles.max(1) as f64;
        let _ = writeln!(
            m,
            "| {} | {} | {} + {} + {} = {} | {:.1} | {} + {} = {} | {:.1} | {} | {} |",
            sc.spec,
            r.triangles,
            mb(r.geometry_bytes),
            mb(r.hierarchy_bytes),
            mb(r.top_level_bytes),
            mb(r.total_bytes),
            r.total_bytes as f64 / n,
            mb(r.bvh_hierarchy_bytes),
            mb(r.bvh_geometry_bytes),
            mb(bvh_total),
            bvh_total as f64 / n,
            paper(
                &sc.spec,
                format!(
                    "{} + {} = {}",
                    PaperBunny::GEOMETRY_MB,
                    PaperBunny::HIERARCHY_MB,
                    PaperBunny::TOTAL_MB
                )
            ),
            paper(
                &sc.spec,
                format!(
                    "{} (hierarchy {})",
                    PaperBunny::OPTIMISED_TOTAL_MB,
                    PaperBunny::BVH_HIERARCHY_MB
                )
            ),
        );
    }
    let _ = writeln!(
        m,
        "\nSpeed: Mrays/s of the render table's views (same run, same threads); ratio = Ray-Strips ÷ obvhs single rays. obvhs has no packet traversal, so both Ray-Strips rows are divided by its single rays (the paper divides packets by BVH packets). Paper: 512², one core.\n"
    );
    let _ = writeln!(
        m,
        "| scene | strips Mrays/s | strips-packets Mrays/s | obvhs Mrays/s | single ratio | packet ratio | paper single ratio | paper packet ratio |"
    );
    let _ = writeln!(m, "|---|---:|---:|---:|---:|---:|---:|---:|");
    for (sc, r) in &rows {
        let speed = |method: Method| {
            sc.renders
                .iter()
                .find(|x| x.method == method)
                .map_or(f64::NAN, |x| x.mrays_per_s)
        };
        let (single, bvh) = (speed(Method::Strips), speed(Method::Obvhs));
        let packets = r.packets.mrays_per_s;
        let ratio = |(a, b): (f64, f64)| format!("{:.2}", a / b);
        let _ = writeln!(
            m,
            "| {} | {single:.2} | {packets:.2} | {bvh:.2} | {:.2} | {:.2} | {} | {} |",
            sc.spec,
            single / bvh,
            packets / bvh,
            paper(&sc.spec, ratio(PaperBunny::SINGLE_FPS)),
            paper(&sc.spec, ratio(PaperBunny::PACKET_FPS)),
        );
    }
    let _ = writeln!(
        m,
        "\nConstruction (one build each, all threads available to the builder).\n"
    );
    let _ = writeln!(
        m,
        "| scene | Ray-Strips s | BVH s | strips | triangles per strip | chunks | paper s (Ray-Strips / BVH) | paper strips | paper triangles per strip |"
    );
    let _ = writeln!(m, "|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for (sc, r) in &rows {
        let _ = writeln!(
            m,
            "| {} | {:.3} | {:.3} | {} | {:.2} | {} | {} | {} | {} |",
            sc.spec,
            r.build_s,
            r.bvh_build_s,
            r.strips,
            r.mean_strip_triangles,
            r.chunks,
            paper(
                &sc.spec,
                format!("{} / {}", PaperBunny::BUILD_S.0, PaperBunny::BUILD_S.1)
            ),
            paper(&sc.spec, PaperBunny::STRIPS.to_string()),
            paper(&sc.spec, PaperBunny::MEAN_STRIP.to_string()),
        );
    }
}
