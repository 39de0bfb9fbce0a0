//! Camera approaching the surface (Aman et al. 2022, Table 5): tet20
//! against the BVH on the Armadillo Zoom series (scenes whose name holds
//! "Zoom"; their renders come from the render-speed table).

use std::fmt::Write as _;

use super::doc::{SceneResult, TablesDoc};
use crate::methods::method::Method;

/// Aman et al. (2022) Table 5 (Armadillo Zoom 0–5): Tet20 tets per pixel, BVH nodes
/// per pixel, Tet20 ms, BVH ms.
const PAPER_ZOOM: [(f64, f64, f64, f64); 6] = [
    (48.54, 27.23, 140.3, 87.4),
    (52.32, 32.90, 151.0, 109.4),
    (55.11, 38.53, 168.3, 123.9),
    (59.13, 46.67, 179.4, 146.8),
    (60.13, 57.88, 182.3, 175.9),
    (43.62, 65.27, 126.6, 193.9),
];

/// The table (only when a scene of the run is a zoom scene).
pub fn markdown(m: &mut String, doc: &TablesDoc) {
    let zoom: Vec<&SceneResult> = doc
        .scenes
        .iter()
        .filter(|sc| sc.spec.contains("Zoom") && !sc.renders.is_empty())
        .collect();
    if !zoom.is_empty() {
        let _ = writeln!(
            m,
            "\n## Camera approaching the surface (Aman et al. 2022, Table 5)\n"
        );
        let _ = writeln!(
            m,
            "Paper (Armadillo Zoom 0–5): Tet20 48.5–60.1 tets per pixel, 140–183 ms; BVH 87–194 ms (Tet20 faster from Zoom 4 on).\n"
        );
        let _ = writeln!(
            m,
            "| scene | tet20 tets/ray | BVH nodes/ray | tet20 ms | BVH ms | tet20 / BVH time | paper tets | paper nodes | paper time ratio |"
        );
        let _ = writeln!(m, "|---|---:|---:|---:|---:|---:|---:|---:|---:|");
        for sc in zoom {
            let t = sc.renders.iter().find(|r| r.method == Method::Tet20);
            let b = sc.renders.iter().find(|r| r.method == Method::Obvhs);
            let paper = sc
                .spec
                .rsplit_once("Zoom ")
                .and_then(|(_, n)| n.trim().parse::<usize>().ok())
                .and_then(|i| PAPER_ZOOM.get(i));
            let (pt, pn, pr) = paper.map_or(("–".into(), "–".into(), "–".into()), |p| {
                (
                    format!("{:.1}", p.0),
                    format!("{:.1}", p.1),
                    format!("{:.2}", p.2 / p.3),
                )
            });
            if let (Some(t), Some(b)) = (t, b) {
                let _ = writeln!(
                    m,
                    "| {} | {:.1} | {} | {:.1} | {:.1} | {:.2} | {pt} | {pn} | {pr} |",
                    t.scene,
                    t.tets_per_ray,
                    b.nodes_per_ray.map_or("–".into(), |n| format!("{n:.1}")),
                    t.best_ms,
                    b.best_ms,
                    t.best_ms / b.best_ms
                );
            }
        }
    }
}
