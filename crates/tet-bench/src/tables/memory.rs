//! Bytes per layout (Aman et al. 2022, Table 4): hot and cold bytes of
//! every layout per scene (measured with the construction table, by
//! [`crate::methods::layouts::info`]), beside the paper's numbers for that scene
//! (their meshes are larger: compare bytes per tet, or the ratios between
//! layouts).

use std::fmt::Write as _;

use super::doc::TablesDoc;
use super::paper::paper_scene;

/// Bytes as MB (10⁶ bytes), two decimals.
fn mb(b: usize) -> String {
    format!("{:.2}", b as f64 / 1e6)
}

/// The table.
pub fn markdown(m: &mut String, doc: &TablesDoc) {
    let _ = writeln!(m, "\n## Bytes per layout (Aman et al. 2022, Table 4)\n");
    let _ = writeln!(
        m,
        "Hot = tet records + point positions read by the walk; cold = constrained-face table, attributes, anchors; `ray-strips` (Lauterbach et al. 2007) is the whole Ray-Strips structure over the same triangles, all hot. MB = 10⁶ bytes.\n"
    );
    let _ = writeln!(
        m,
        "Paper: Aman et al. (2022) Table 4 on the paper's (larger) mesh of the scene (xor layouts: total; Tet80: records only, compare with hot).\n"
    );
    let _ = writeln!(
        m,
        "| scene | layout | hot MB | cold MB | total MB | hot B/tet | total B/triangle | paper MB |"
    );
    let _ = writeln!(m, "|---|---|---:|---:|---:|---:|---:|---:|");
    for sc in &doc.scenes {
        if let Some(i) = &sc.info {
            for l in &i.layouts {
                let paper = paper_scene(&sc.spec)
                    .and_then(|p| p.layout_mb(l.name))
                    .map_or("–".to_string(), |v| format!("{v:.1}"));
                let _ = writeln!(
                    m,
                    "| {} | {} | {} | {} | {} | {:.1} | {:.1} | {} |",
                    i.name,
                    l.name,
                    mb(l.hot_bytes),
                    mb(l.cold_bytes),
                    mb(l.total_bytes),
                    l.hot_bytes_per_tet,
                    l.total_bytes_per_triangle,
                    paper
                );
            }
        }
    }
}
