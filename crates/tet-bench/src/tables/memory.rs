//! Bytes per layout (Aman et al., seed 000 Table 4): hot and cold bytes of
//! every layout per scene (measured with the construction table, by
//! [`crate::layouts::info`]), beside the paper's Torus Knots numbers.

use std::fmt::Write as _;

use super::doc::{TablesDoc, is_torus_knots};

/// Seed 000 Table 4, Torus Knots, MB per layout (their Tet80 column is the
/// tet records only, so it compares with our hot bytes).
const PAPER_TABLE4_TORUS_KNOTS_MB: [(&str, f64); 4] = [
    ("tet32", 12.3),
    ("tet20", 9.2),
    ("tet16", 8.2),
    ("tet80", 20.6),
];

/// Bytes as MB (10⁶ bytes), two decimals.
fn mb(b: usize) -> String {
    format!("{:.2}", b as f64 / 1e6)
}

/// The table.
pub fn markdown(m: &mut String, doc: &TablesDoc) {
    let _ = writeln!(m, "\n## Bytes per layout (seed 000 Table 4)\n");
    let _ = writeln!(
        m,
        "Hot = tet records + point positions read by the walk; cold = constrained-face table, attributes, anchors. MB = 10⁶ bytes.\n"
    );
    let _ = writeln!(
        m,
        "Paper: seed 000 Table 4 on Torus Knots (xor layouts: total; Tet80: records only, compare with hot).\n"
    );
    let _ = writeln!(
        m,
        "| scene | layout | hot MB | cold MB | total MB | hot B/tet | paper MB |"
    );
    let _ = writeln!(m, "|---|---|---:|---:|---:|---:|---:|");
    for sc in &doc.scenes {
        if let Some(i) = &sc.info {
            for l in &i.layouts {
                let paper = PAPER_TABLE4_TORUS_KNOTS_MB
                    .iter()
                    .find(|(n, _)| *n == l.name)
                    .filter(|_| is_torus_knots(&sc.spec))
                    .map_or("–".to_string(), |(_, v)| format!("{v:.1}"));
                let _ = writeln!(
                    m,
                    "| {} | {} | {} | {} | {} | {:.1} | {} |",
                    i.name,
                    l.name,
                    mb(l.hot_bytes),
                    mb(l.cold_bytes),
                    mb(l.total_bytes),
                    l.hot_bytes_per_tet,
                    paper
                );
            }
        }
    }
}
