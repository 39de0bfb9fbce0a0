//! Out of core under a memory limit (Erkoç et al. 2021, Tables 2–3):
//! each scene built in parts under the builder's own share plus ½ and ⅓
//! of its in-core TetGen peak,
//! with build time, parts, peaks, tet quality and tet20 speed (full mode,
//! first scene of each geometry only).
//!
//! Each limited build runs as `tet-bench build SCENE --memory-limit L
//! --json` in a process of its own, as a user runs it: the limit bounds
//! that process and its TetGen workers together, and this harness, which
//! holds other meshes, would not fit under it. The merged mesh is read
//! back from the file it wrote.

use std::fmt::Write as _;

use super::doc::{Quality, TablesDoc};
use crate::methods::method::Method;

#[cfg(feature = "tetgen")]
pub use measuring::{build_in_own_process, measure};

/// The measurement: limited builds in processes of their own (they run
/// TetGen, so only with the `tetgen` feature).
#[cfg(feature = "tetgen")]
mod measuring {
    use crate::methods::method::Method;
    use crate::tables::doc::{OutOfCoreRow, Quality, TABLE_FLAGS};
    use std::path::Path;
    use std::process::Command;

    use anyhow::{Context, Result, bail};
    use tet_build::outofcore::admission::builder_bytes;
    use tet_core::TetMesh;
    use tet_trace_cpu::render::RenderOptions;

    use crate::load::{Loaded, with_mesh};
    use crate::outofcore::{MemoryReport, predict};
    use crate::output::error_chain;
    use crate::timing::time_method;

    /// Tet quality of a mesh (aspect and radius-edge ratios).
    fn quality(mesh: &TetMesh) -> Option<Quality> {
        let q = tet_build::quality::mesh_quality(mesh)?;
        Some(Quality {
            aspect_min: q.aspect_ratio.min,
            aspect_max: q.aspect_ratio.max,
            aspect_mean: q.aspect_ratio.mean,
            radius_edge_min: q.radius_edge.min,
            radius_edge_max: q.radius_edge.max,
            radius_edge_mean: q.radius_edge.mean,
        })
    }

    /// Out-of-core builds of a scene under the builder's own share plus ½ and
    /// ⅓ of its in-core TetGen peak, and tet20 on each merged mesh.
    pub fn measure(
        spec: &str,
        loaded: &Loaded,
        opts: &RenderOptions,
        frames: crate::timing::Frames,
        pool: &rayon::ThreadPool,
    ) -> Vec<OutOfCoreRow> {
        let (Some(scene), Some(build)) = (&loaded.scene, &loaded.build) else {
            return Vec::new();
        };
        let peak_bytes = match build.worker_peak_kib {
            Some(k) => k * 1024,
            None => match predict(scene, TABLE_FLAGS.no_box) {
                Ok(p) => p.predicted_peak_bytes,
                Err(_) => return Vec::new(),
            },
        };
        let mut rows = Vec::new();
        let threads = pool.current_num_threads();
        let in_core_quality = quality(&loaded.mesh);
        for fraction in [0.5, 1.0 / 3.0] {
            // The builder's own share beside a fraction of TetGen's peak: the
            // limit is on the builder and its workers together.
            let limit =
                builder_bytes(scene.triangles.len()) + (peak_bytes as f64 * fraction) as u64;
            eprintln!(
                "  {}: out-of-core build under {:.1} MiB",
                loaded.name,
                limit as f64 / (1024.0 * 1024.0)
            );
            let mut row = OutOfCoreRow {
                fraction,
                in_core_peak_kib: build.worker_peak_kib,
                in_core_s: build.total_s,
                in_core_tets: loaded.mesh.tets.len(),
                memory: None,
                tets: 0,
                tet20: None,
                in_core_quality,
                quality: None,
                error: None,
            };
            let file = std::env::temp_dir().join(format!(
                "tet-bench-out-of-core-{}-{}.tmesh",
                std::process::id(),
                rows.len()
            ));
            let result =
                build_in_own_process(spec, limit, threads, &file).and_then(|(mesh, memory)| {
                    let merged = with_mesh(scene.clone(), mesh, None);
                    let tet20 = time_method(&merged, Method::Tet20, opts, frames, pool)?.0;
                    Ok((merged.mesh.tets.len(), memory, tet20, quality(&merged.mesh)))
                });
            let _ = std::fs::remove_file(&file);
            match result {
                Ok((tets, memory, tet20, q)) => {
                    row.tets = tets;
                    row.memory = Some(memory);
                    row.tet20 = Some(tet20);
                    row.quality = q;
                }
                Err(e) => row.error = Some(error_chain(&e)),
            }
            rows.push(row);
        }
        rows
    }

    /// `tet-bench build SPEC -o FILE --memory-limit LIMIT --threads THREADS
    /// --json`, with `build`'s default flags (the tables' own): the merged
    /// mesh, read back, and the build's memory report.
    pub fn build_in_own_process(
        spec: &str,
        limit: u64,
        threads: usize,
        file: &Path,
    ) -> Result<(TetMesh, MemoryReport)> {
        let exe = std::env::current_exe().context("cannot find this executable")?;
        let out = Command::new(&exe)
            .arg("build")
            .arg(spec)
            .arg("-o")
            .arg(file)
            .args(["--memory-limit", &limit.to_string()])
            .args(["--threads", &threads.to_string()])
            .arg("--json")
            .output()
            .with_context(|| format!("cannot run {}", exe.display()))?;
        if !out.status.success() {
            let stderr = String::from_utf8_lossy(&out.stderr);
            bail!(
                "{}",
                stderr.trim().lines().last().unwrap_or("the build failed")
            );
        }
        let doc: serde_json::Value =
            serde_json::from_slice(&out.stdout).context("the build's --json output")?;
        let memory: MemoryReport =
            serde_json::from_value(doc["memory"].clone()).context("the build's memory report")?;
        let mesh = tet_core::format::load(file)
            .with_context(|| format!("cannot read back {}", file.display()))?;
        Ok((mesh, memory))
    }
}

/// The table (or why there is none).
pub fn markdown(m: &mut String, doc: &TablesDoc) {
    let _ = writeln!(
        m,
        "\n## Out of core under a memory limit (Erkoç et al. 2021, Tables 2–3)\n"
    );
    if let Some(note) = &doc.out_of_core_note {
        let _ = writeln!(m, "Out-of-core table {note}.");
        return;
    }
    let _ = writeln!(
        m,
        "Limits are on the whole process tree: the builder's own share (`build --predict-memory` prints it) plus ½ and ⅓ of the in-core TetGen worker's measured peak. Each limited build runs as `tet-bench build SCENE --memory-limit L` in a process of its own, which sets its share aside, splits the scene recursively (the planes of Erkoç et al. 2021, or slabs when no tree fits) until the parts' *predicted* peaks fit what is left, starts parallel workers only while they fit together, and streams the merged mesh (exact seams, each part Hilbert-sorted) to a file read back for tet20. Parts are given as count, workers at once, planner and depth. Part peaks are the workers' measured `VmHWM`; tree peak is the builder and its workers together (resident memory sampled every 2 ms), what the limit bounds; aspect ratio = longest edge ÷ smallest height (Erkoç et al. 2021, Table 3); tets per ray of tet20 on the table's camera, beside the in-core mesh's (the seams' cost to every ray).\n"
    );
    let _ = writeln!(
        m,
        "Paper (Erkoç et al. 2021, Table 2, two parts, Xeon E5-2620): time 11.5× TetGen's (Armadillo), 6.9× (Armadillo in a box), 3.1×, 2.5×, 1.7× (larger scenes cut between objects) at 0.54–0.60× its memory; Table 3, mean aspect ratio TetGen → theirs: torus knot 7.52 → 22.20, Neptune 8.72 → 12.92, Armadillo 7.31 → 12.84.\n"
    );
    let _ = writeln!(
        m,
        "| scene | limit | limit MiB | parts (at once) | triangles cut | build s | × in-core | max part peak MiB | tree peak MiB | tets | aspect mean / max | tet20 Mrays/s | tets per ray (× in-core) |"
    );
    let _ = writeln!(
        m,
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    let aspect = |q: &Option<Quality>| {
        q.as_ref().map_or("–".into(), |q| {
            format!("{:.2} / {:.0}", q.aspect_mean, q.aspect_max)
        })
    };
    let mib = |k: Option<u64>| k.map_or("–".into(), |k| format!("{:.1}", k as f64 / 1024.0));
    for sc in &doc.scenes {
        let Some(first) = sc.out_of_core.first() else {
            continue;
        };
        let name = sc
            .info
            .as_ref()
            .map_or(sc.spec.as_str(), |i| i.name.as_str());
        let in_core = sc.renders.iter().find(|r| r.method == Method::Tet20);
        let tet20 = in_core.map_or(f64::NAN, |r| r.mrays_per_s);
        let in_core_tpr = in_core.map_or(f64::NAN, |r| r.tets_per_ray);
        let _ = writeln!(
            m,
            "| {name} | in core | – | 1 | 0 | {:.2} | 1.00 | {} | – | {} | {} | {:.2} | {:.1} (1.00) |",
            first.in_core_s,
            mib(first.in_core_peak_kib),
            first.in_core_tets,
            aspect(&first.in_core_quality),
            tet20,
            in_core_tpr
        );
        for r in &sc.out_of_core {
            let label = if r.fraction > 0.4 { "½" } else { "⅓" };
            match (&r.memory, &r.error) {
                (Some(mem), _) => {
                    let _ = writeln!(
                        m,
                        "| {name} | {label} | {:.1} | {} ({} at once, {} depth {}) | {} | {:.2} | {:.2} | {} | {} | {} | {} | {:.2} | {:.1} ({:.2}) |",
                        mem.limit_bytes as f64 / (1024.0 * 1024.0),
                        mem.parts,
                        mem.parallel_parts,
                        mem.planner,
                        mem.depth,
                        mem.triangles_cut,
                        mem.total_s,
                        mem.total_s / r.in_core_s,
                        mib(mem.max_part_peak_kib),
                        mib(mem.tree_peak_kib),
                        r.tets,
                        aspect(&r.quality),
                        r.tet20.as_ref().map_or(f64::NAN, |t| t.mrays_per_s),
                        r.tet20.as_ref().map_or(f64::NAN, |t| t.tets_per_ray),
                        r.tet20.as_ref().map_or(f64::NAN, |t| t.tets_per_ray) / in_core_tpr
                    );
                }
                (None, e) => {
                    let _ = writeln!(
                        m,
                        "| {name} | {label} | failed: {} | | | | | | | | | | |",
                        e.as_deref().unwrap_or("")
                    );
                }
            }
        }
    }
}
