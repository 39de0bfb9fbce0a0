//! The SVG figures of a `tables` run, drawn from the measured
//! [`TablesDoc`] with [`super::plots`]:
//!
//! * `speed_vs_accuracy.svg` — Mrays/s (render) against failures per 1024²
//!   rays (accuracy), one circle per method and scene: Maria et al.'s
//!   (Maria et al. 2017) trade between speed and robustness in one picture;
//! * `figure8_sorted_vs_unsorted.svg` — Aman et al. (2022) Figure 8:
//!   tet20 Mrays/s on the Hilbert-sorted and the unsorted (TetGen order)
//!   mesh, per scene;
//! * `mrays_per_method.svg` — Mrays/s per method, grouped by scene;
//! * `bytes_per_triangle_vs_mrays.svg` — bytes per scene triangle against
//!   Mrays/s, one mark per structure (Tet20, Tet16, Tet32, Ray-Strips,
//!   obvhs) and scene, large models included: the memory–speed trade of
//!   the compact tet layouts and of Ray-Strips (Lauterbach et al. 2007) in one picture.

use anyhow::Result;

use super::doc::TablesDoc;
use super::plots::{BarGroup, Point, bars_svg, scatter_svg};
use crate::methods::method::Method;

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
            "Speed vs accuracy (Maria et al. 2017, Table 4 against render speed)",
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
            let sorted = sc.sorted_tet20.as_ref()?;
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
            "Hilbert-sorted vs unsorted mesh (Aman et al. 2022, Figure 8)",
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
            "Render speed per method (Aman et al. 2022, Table 1)",
            "Mrays/s",
            &groups,
        )?,
    ));
    out.push((
        "bytes_per_triangle_vs_mrays.svg",
        scatter_svg(
            "Memory against speed per structure (Aman et al. 2022, Table 4; Lauterbach et al. 2007, Tables 1 and 3)",
            "bytes per scene triangle (structure and vertices)",
            "Mrays/s (primary rays)",
            &bytes_vs_speed(doc),
        )?,
    ));
    Ok(out)
}

/// One point per structure and scene: its bytes per triangle (the memory
/// table's, Ray-Strips' and the BVH's) and its render speed.
fn bytes_vs_speed(doc: &TablesDoc) -> Vec<Point> {
    let mut points = Vec::new();
    let mut push = |structure: &str, scene: &str, bytes_per_triangle: f64, mrays: f64| {
        points.push(Point {
            series: structure.to_string(),
            label: format!("{structure} ({scene})"),
            x: bytes_per_triangle,
            y: mrays,
        });
    };
    for sc in &doc.scenes {
        let mrays = |m: Method| {
            sc.renders
                .iter()
                .find(|r| r.method == m)
                .map(|r| (r.scene.clone(), r.mrays_per_s))
        };
        for (layout, method) in [
            ("tet20", Method::Tet20),
            ("tet16", Method::Tet16),
            ("tet32", Method::Tet32),
            ("ray-strips", Method::Strips),
        ] {
            let bytes = sc
                .info
                .as_ref()
                .and_then(|i| i.layouts.iter().find(|l| l.name == layout));
            if let (Some(b), Some((scene, m))) = (bytes, mrays(method)) {
                push(method.name(), &scene, b.total_bytes_per_triangle, m);
            }
        }
        if let (Some(s), Some((scene, m))) = (&sc.ray_strips, mrays(Method::Obvhs)) {
            let bytes = (s.bvh_hierarchy_bytes + s.bvh_geometry_bytes) as f64;
            push(
                Method::Obvhs.name(),
                &scene,
                bytes / s.triangles.max(1) as f64,
                m,
            );
        }
    }
    for row in &doc.large_models {
        for s in &row.structures {
            push(
                &s.structure,
                &row.scene,
                s.bytes_per_triangle,
                s.render.mrays_per_s,
            );
        }
    }
    points
}
