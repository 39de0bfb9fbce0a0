//! `gpu.md`: the document's tables in Markdown, written from the
//! [`GpuBenchDoc`] alone.

use std::fmt::Write as _;

use super::doc::{Differences, GpuBenchDoc, Row};

/// The whole report.
pub fn markdown(doc: &GpuBenchDoc) -> String {
    let mut m = String::new();
    let a = &doc.adapter;
    let _ = writeln!(m, "# GPU benchmark\n");
    let _ = writeln!(
        m,
        "Adapter: **{}** ({}, {}, driver {}); kernel times by {}.",
        a.name,
        a.device_type,
        a.backend,
        a.driver,
        if a.timestamps {
            "timestamp queries"
        } else {
            "wall clock (the adapter has no timestamp queries)"
        }
    );
    if a.software {
        let _ = writeln!(
            m,
            "\n**Software adapter**: these are CPU times of a Vulkan emulation, not GPU times."
        );
    }
    let s = &doc.setup;
    let _ = writeln!(
        m,
        "\n{}×{} camera rays, best of {} timed dispatches after a warm-up ({} for secondary rays); \
         meshes missing from `--meshes` built in the {} enclosing box; every hit checked \
         against the CPU walk of the same layout on the same rays. Run: {:.0} s.",
        s.width, s.height, s.frames, s.secondary_repeats, s.enclosing_box, doc.total_s
    );
    table3(&mut m, &doc.table3);
    bvh(&mut m, doc);
    secondary(&mut m, &doc.secondary);
    scenes(&mut m, doc);
    m
}

/// Aman et al. (2022) Table 3 beside ours.
fn table3(m: &mut String, rows: &[Row]) {
    let _ = writeln!(m, "\n## Aman et al. (2022), Table 3: kernel ms\n");
    let _ = writeln!(
        m,
        "The paper's figures are from a GTX 1060 on their meshes (Armadillo 346 k, Neptune \
         449 k, Mix 2.5 M triangles against 100 k, 59 k and 548 k here): compare ratios \
         between layouts, not absolute times.\n"
    );
    let _ = writeln!(
        m,
        "| scene | method | kernel ms | paper ms | ours ÷ paper | Mrays/s | tets/ray | hits | CPU hits | differences | GPU MB (tets + points + faces) | timing |"
    );
    let _ = writeln!(
        m,
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---|---:|---|"
    );
    for r in rows {
        let _ = writeln!(
            m,
            "| {} | {} | {:.3} | {} | {} | {:.1} | {} | {} | {} | {} | {:.1} | {} |",
            r.scene,
            r.method,
            r.kernel_ms,
            opt(r.paper_ms, 3),
            opt(r.ratio_to_paper, 2),
            r.mrays_per_s,
            opt(r.tets_per_ray, 1),
            r.hits,
            r.cpu_hits,
            differences(&r.differences),
            r.gpu_bytes.total as f64 / 1e6,
            r.timing
        );
    }
}

/// The GPU BVH on the same rays.
fn bvh(m: &mut String, doc: &GpuBenchDoc) {
    let _ = writeln!(m, "\n## GPU BVH on the same camera rays\n");
    if let Some(note) = &doc.bvh_note {
        let _ = writeln!(m, "{note}\n");
    }
    if doc.bvh.is_empty() {
        return;
    }
    let _ = writeln!(
        m,
        "| scene | kernel ms | Mrays/s | boxes/ray | hits | CPU tet20 hits | differences | build ms | GPU MB | gpu-tet20 speed ÷ BVH speed |"
    );
    let _ = writeln!(m, "|---|---:|---:|---:|---:|---:|---|---:|---:|---:|");
    for r in &doc.bvh {
        let tet20 = doc
            .table3
            .iter()
            .find(|t| t.scene == r.scene && t.method == "gpu-tet20")
            // Above 1: the walk is faster than the BVH.
            .map(|t| r.kernel_ms / t.kernel_ms);
        let _ = writeln!(
            m,
            "| {} | {:.3} | {:.1} | {} | {} | {} | {} | {:.0} | {:.1} | {} |",
            r.scene,
            r.kernel_ms,
            r.mrays_per_s,
            opt(r.nodes_per_ray, 1),
            r.hits,
            r.cpu_hits,
            differences(&r.differences),
            r.setup_ms,
            r.gpu_bytes.total as f64 / 1e6,
            opt(tet20, 2)
        );
    }
}

/// Secondary rays given by the CPU.
fn secondary(m: &mut String, rows: &[Row]) {
    let _ = writeln!(m, "\n## Secondary rays (from the CPU Tet20 walk's hits)\n");
    if rows.is_empty() {
        let _ = writeln!(m, "None: no primary ray hit.");
        return;
    }
    let _ = writeln!(
        m,
        "| scene | method | kind | rays | kernel ms | Mrays/s | Grays/s | outside the kernel ms | hits | CPU hits | differences |"
    );
    let _ = writeln!(m, "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---|");
    for r in rows {
        let _ = writeln!(
            m,
            "| {} | {} | {} | {} | {:.3} | {:.1} | {:.3} | {:.1} | {} | {} | {} |",
            r.scene,
            r.method,
            r.kind,
            r.rays,
            r.kernel_ms,
            r.mrays_per_s,
            r.grays_per_s,
            r.outside_kernel_ms,
            r.hits,
            r.cpu_hits,
            differences(&r.differences)
        );
    }
}

/// Where each scene's mesh came from, and the skipped scenes.
fn scenes(m: &mut String, doc: &GpuBenchDoc) {
    let _ = writeln!(m, "\n## Scenes\n");
    for s in &doc.scenes {
        match (&s.mesh, &s.skipped) {
            (_, Some(why)) => {
                let _ = writeln!(m, "* {} (`{}`): **skipped**: {why}", s.scene, s.spec);
            }
            (Some(mesh), None) => {
                let _ = writeln!(
                    m,
                    "* {} (`{}`): {} tets, mesh {}{}, camera {} the mesh",
                    s.scene,
                    s.spec,
                    mesh.tets,
                    mesh.source,
                    mesh.path
                        .as_ref()
                        .map_or(String::new(), |p| format!(" `{p}`")),
                    if s.camera_inside == Some(true) {
                        "inside"
                    } else {
                        "outside"
                    }
                );
            }
            (None, None) => {}
        }
    }
}

/// `none`, or how many rays differ and why.
fn differences(d: &Differences) -> String {
    if d.rays == 0 {
        return "none".into();
    }
    let mut parts = Vec::new();
    for (n, what) in [
        (d.near_edge, "near an edge"),
        (d.failed, "failed walk"),
        (d.unexplained, "**unexplained**"),
    ] {
        if n > 0 {
            parts.push(format!("{n} {what}"));
        }
    }
    parts.join(", ")
}

/// A number with `digits` decimals, or `–`.
fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("–".into(), |v| format!("{v:.digits$}"))
}
