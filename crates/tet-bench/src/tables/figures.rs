//! The SVG figures of a `tables` run, drawn from the measured
//! [`TablesDoc`] with [`crate::plots`]:
//!
//! * `speed_vs_accuracy.svg` — Mrays/s (render) against failures per 1024²
//!   rays (accuracy), one circle per method and scene: Maria et al.'s
//!   (seed 001) trade between speed and robustness in one picture;
//! * `figure8_sorted_vs_unsorted.svg` — Aman et al. (seed 000) Figure 8:
//!   tet20 Mrays/s on the Hilbert-sorted and the unsorted (TetGen order)
//!   mesh, per scene;
//! * `mrays_per_method.svg` — Mrays/s per method, grouped by scene.

use anyhow::Result;

use super::doc::TablesDoc;
use crate::cli::Method;
use crate::plots::{BarGroup, Point, bars_svg, scatter_svg};

/// The figures of a `tables` run: `(file name, SVG)`.
pub fn figures(doc: &TablesDoc) -> Result<Vec<(&'static str, String)>> {
    let mut out = Vec::new();
    // Speed vs accuracy.
    let mut points = Vec::new();
    for sc in &doc.scenes {
        let Some(a) = &sc.accuracy else { continue };
        for x in &a.methods {
            let Some(r) = sc.renders.iter().find(|r| r.tracer == x.method) else {
                continue;
            };
            points.push(Point {
                series: r.method.name().to_string(),
                label: format!("{} ({})", r.method.name(), r.scene),
                x: x.failures_per_1024_squared,
                y: r.mrays_per_s,
            });
        }
    }
    out.push((
        "speed_vs_accuracy.svg",
        scatter_svg(
            "Speed vs accuracy (seed 001 Table 4 against render speed)",
            "failures per 1024² rays (f32, against the f64 reference)",
            "Mrays/s (primary rays)",
            &points,
        )?,
    ));
    // Figure 8.
    let groups: Vec<BarGroup> = doc
        .scenes
        .iter()
        .filter_map(|sc| {
            let sorted = sc.renders.iter().find(|r| r.method == Method::Tet20)?;
            let unsorted = sc.unsorted_tet20.as_ref()?;
            Some(BarGroup {
                name: sorted.scene.clone(),
                bars: vec![
                    ("tet20, Hilbert-sorted".into(), sorted.mrays_per_s),
                    ("tet20, unsorted".into(), unsorted.mrays_per_s),
                ],
            })
        })
        .collect();
    out.push((
        "figure8_sorted_vs_unsorted.svg",
        bars_svg(
            "Hilbert-sorted vs unsorted mesh (seed 000 Figure 8)",
            "Mrays/s",
            &groups,
        )?,
    ));
    // Mrays/s per method per scene.
    let groups: Vec<BarGroup> = doc
        .scenes
        .iter()
        .filter(|sc| !sc.renders.is_empty())
        .map(|sc| BarGroup {
            name: sc.renders[0].scene.clone(),
            bars: sc
                .renders
                .iter()
                .map(|r| (r.method.name().to_string(), r.mrays_per_s))
                .collect(),
        })
        .collect();
    out.push((
        "mrays_per_method.svg",
        bars_svg(
            "Render speed per method (seed 000 Table 1)",
            "Mrays/s",
            &groups,
        )?,
    ));
    Ok(out)
}
