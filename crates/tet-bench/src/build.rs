//! `tet-bench build`: build a scene's mesh and write it to a mesh file.

use anyhow::{Context, Result, bail};
use serde::Serialize;

use crate::cli::BuildArgs;
use crate::load::{BuildSummary, MESH_EXTENSION, load};
use crate::outofcore::{MemoryReport, predict, print_memory};

/// The `build` document.
#[derive(Debug, Serialize)]
pub struct BuildDoc {
    /// Scene name.
    pub name: String,
    /// Output path.
    pub output: String,
    /// Points.
    pub points: usize,
    /// Tets.
    pub tets: usize,
    /// Constrained faces.
    pub constrained_faces: usize,
    /// Bytes written.
    pub file_bytes: u64,
    /// Construction report.
    pub build: Option<BuildSummary>,
    /// With `--memory-limit`: the prediction, parts and peaks (else `null`).
    pub memory: Option<MemoryReport>,
}

/// Prints a construction report.
pub fn print_build(b: &BuildSummary) {
    println!(
        "  build: TetGen `{}`; {} scene triangles, {} Steiner points",
        b.switches, b.scene_triangles, b.steiner_points
    );
    println!(
        "  times: clean {:.3} s, TetGen {:.3} s, assemble+validate {:.3} s, reorder {:.3} s, total {:.3} s; TetGen peak {}",
        b.clean_s,
        b.tetgen_s,
        b.assemble_s,
        b.reorder_s,
        b.total_s,
        b.worker_peak_kib
            .map_or("n/a".into(), |k| format!("{:.1} MB", k as f64 / 1024.0))
    );
    let c = &b.cleaning;
    println!(
        "  cleaning: {} vertices merged, {} repeated-vertex, {} zero-area, {} duplicate triangles dropped, {} unused vertices removed",
        c.merged_vertices,
        c.repeated_vertex_triangles,
        c.zero_area_triangles,
        c.duplicate_triangles,
        c.unused_vertices
    );
}

/// `tet-bench build`.
pub fn run(args: &BuildArgs, json: bool) -> Result<()> {
    if args.predict_memory {
        return run_predict(args, json);
    }
    let Some(output) = &args.output else {
        bail!("give the output mesh file with -o FILE.{MESH_EXTENSION}");
    };
    if output.extension().is_none_or(|e| e != MESH_EXTENSION) {
        bail!(
            "the output file must end in .{MESH_EXTENSION} (got {})",
            output.display()
        );
    }
    let (loaded, memory) = match args.memory_limit {
        None => (load(&args.scene, &args.build, json)?, None),
        Some(limit) => {
            if args.scene.ends_with(&format!(".{MESH_EXTENSION}")) {
                bail!(
                    "--memory-limit builds a scene; `{}` is already a mesh file",
                    args.scene
                );
            }
            let scene = tet_build::scene::Scene::load(&args.scene)
                .with_context(|| format!("cannot load scene `{}`", args.scene))?;
            let (mesh, build, memory) = crate::outofcore::build_limited(
                &scene,
                &args.build,
                limit,
                args.threads
                    .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
                json,
                &[],
            )?;
            (
                crate::load::with_mesh(scene, mesh, Some(build)),
                Some(memory),
            )
        }
    };
    // The scene's own camera and lights travel with the mesh, so that
    // `render FILE` sees what `render SCENE` sees.
    let stored = tet_core::scene::SceneInfo {
        camera: loaded.scene.as_ref().and_then(|s| s.camera),
        lights: loaded
            .scene
            .as_ref()
            .map(|s| s.lights.clone())
            .unwrap_or_default(),
    };
    tet_core::format::save_with_scene(output, &loaded.mesh, &stored)
        .with_context(|| format!("cannot write {}", output.display()))?;
    let file_bytes = std::fs::metadata(output).map(|m| m.len()).unwrap_or(0);
    let doc = BuildDoc {
        name: loaded.name.clone(),
        output: output.display().to_string(),
        points: loaded.mesh.points.len(),
        tets: loaded.mesh.tets.len(),
        constrained_faces: loaded.mesh.constrained.len(),
        file_bytes,
        build: loaded.build.clone(),
        memory,
    };
    if json {
        println!("{}", serde_json::to_string_pretty(&doc)?);
    } else {
        println!(
            "{}: {} points, {} tets, {} constrained faces -> {} ({} bytes)",
            doc.name, doc.points, doc.tets, doc.constrained_faces, doc.output, doc.file_bytes
        );
        if let Some(b) = &doc.build {
            print_build(b);
        }
        if let Some(m) = &doc.memory {
            print_memory(m);
        }
    }
    Ok(())
}

/// `build --predict-memory`: the memory model's prediction, no build.
fn run_predict(args: &BuildArgs, json: bool) -> Result<()> {
    if args.scene.ends_with(&format!(".{MESH_EXTENSION}")) {
        bail!(
            "--predict-memory predicts a TetGen run on a scene; `{}` is a mesh file",
            args.scene
        );
    }
    let scene = tet_build::scene::Scene::load(&args.scene)
        .with_context(|| format!("cannot load scene `{}`", args.scene))?;
    let p = predict(&scene, args.build.no_box)?;
    if json {
        println!("{}", serde_json::to_string_pretty(&p)?);
    } else {
        println!(
            "{}: TetGen input {} points + {} triangles; predicted peak memory {:.1} MiB ({} bytes) = {:.3} × ({:.2} MB + {:.0} B × {})",
            p.name,
            p.points,
            p.triangles,
            p.predicted_peak_bytes as f64 / (1024.0 * 1024.0),
            p.predicted_peak_bytes,
            p.model.margin,
            p.model.base_bytes / 1e6,
            p.model.bytes_per_element,
            p.points + p.triangles
        );
    }
    Ok(())
}
