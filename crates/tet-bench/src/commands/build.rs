//! `tet-bench build`: build a scene's mesh (in core, or in parts under
//! `--memory-limit`) and write it to a mesh file; `--predict-memory`
//! predicts TetGen's peak memory instead.

use anyhow::{Context, Result, bail};
use serde::Serialize;

use std::path::Path;

use tet_core::TetMesh;
use tet_core::scene::SceneInfo;

use super::text::print_build;
use crate::cli::BuildArgs;
use crate::load::build_flags::Walls;
use crate::load::{BuildSummary, MESH_EXTENSION, load};
use crate::outofcore::options::MergeMode;
use crate::outofcore::{Limited, MemoryReport, predict, tet20_speed};
use crate::output::{outln, print_json};
use crate::timing::RenderDoc;

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
    /// With `--tet20`: tet20 on the written mesh, read back from the file
    /// (else `null`).
    pub tet20: Option<RenderDoc>,
}

/// The scene's own camera and lights, stored with the mesh so that
/// `render FILE` sees what `render SCENE` sees.
fn stored_scene(scene: Option<&tet_build::scene::Scene>) -> SceneInfo {
    SceneInfo {
        camera: scene.and_then(|s| s.camera),
        lights: scene.map(|s| s.lights.clone()).unwrap_or_default(),
    }
}

/// Saves a mesh built in memory and describes it.
fn save(
    mesh: &TetMesh,
    stored: &SceneInfo,
    output: &Path,
    name: String,
    build: Option<BuildSummary>,
    memory: Option<MemoryReport>,
) -> Result<BuildDoc> {
    tet_core::format::save_with_scene(output, mesh, stored)
        .with_context(|| format!("cannot write {}", output.display()))?;
    Ok(BuildDoc {
        name,
        output: output.display().to_string(),
        points: mesh.points.len(),
        tets: mesh.tets.len(),
        constrained_faces: mesh.constrained.len(),
        file_bytes: std::fs::metadata(output).map_or(0, |m| m.len()),
        build,
        memory,
        tet20: None,
    })
}

/// `tet-bench build`.
pub fn run(args: &BuildArgs, json: bool) -> Result<()> {
    if args.predict_memory {
        return run_predict(args, json);
    }
    if let Some(dir) = &args.plan {
        return super::job::plan(args, dir, json);
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
    if args.memory_limit.is_some() && args.build.walls.is_some_and(|w| w != Walls::None) {
        bail!(
            "--walls and --memory-limit both cut the scene into parts: give one (--memory-limit chooses the parts by memory)"
        );
    }
    let doc = match args.memory_limit {
        None => {
            let loaded = load(&args.scene, &args.build, json)?;
            let stored = stored_scene(loaded.scene.as_ref());
            save(
                &loaded.mesh,
                &stored,
                output,
                loaded.name.clone(),
                loaded.build,
                None,
            )?
        }
        Some(limit) => {
            if args.scene.ends_with(&format!(".{MESH_EXTENSION}")) {
                bail!(
                    "--memory-limit builds a scene; `{}` is already a mesh file",
                    args.scene
                );
            }
            let scene = tet_build::scene::Scene::load(&args.scene)
                .with_context(|| format!("cannot load scene `{}`", args.scene))?;
            let stored = stored_scene(Some(&scene));
            let limited = Limited {
                scene: &scene,
                flags: &args.build,
                limit_bytes: limit,
                max_parallel: args
                    .threads
                    .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
                quiet: json,
                extra: &[],
                planner: args.planner,
            };
            match args.merge {
                MergeMode::Memory => {
                    let (mesh, build, memory) = limited.in_memory()?;
                    save(
                        &mesh,
                        &stored,
                        output,
                        scene.name.clone(),
                        Some(build),
                        Some(memory),
                    )?
                }
                MergeMode::Stream => {
                    let (written, build, memory) = limited.to_file(output, &stored)?;
                    BuildDoc {
                        name: scene.name.clone(),
                        output: output.display().to_string(),
                        points: written.points,
                        tets: written.tets,
                        constrained_faces: written.constrained,
                        file_bytes: written.file_bytes,
                        build: Some(build),
                        memory: Some(memory),
                        tet20: None,
                    }
                }
            }
        }
    };
    let doc = BuildDoc {
        tet20: if args.tet20 {
            Some(tet20_speed(output, &args.build, json)?)
        } else {
            None
        },
        ..doc
    };
    if json {
        print_json(&doc)?;
    } else {
        outln!(
            "{}: {} points, {} tets, {} constrained faces -> {} ({} bytes)",
            doc.name,
            doc.points,
            doc.tets,
            doc.constrained_faces,
            doc.output,
            doc.file_bytes
        )?;
        if let Some(b) = &doc.build {
            print_build(b)?;
        }
        if let Some(m) = &doc.memory {
            print_memory(m)?;
        }
        if let Some(t) = &doc.tet20 {
            outln!(
                "  tet20 on the written mesh: {:.2} Mrays/s ({}x{}, best of {} frames, {} threads, {} failures)",
                t.mrays_per_s,
                t.width,
                t.height,
                t.frames,
                t.threads,
                t.failures
            )?;
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
        print_json(&p)?;
    } else {
        outln!(
            "{}: TetGen input {} points + {} triangles; predicted peak memory {:.1} MiB ({} bytes) = {:.3} × ({:.2} MB + {:.0} B × {}); a build under --memory-limit sets {:.1} MiB aside for its own process",
            p.name,
            p.points,
            p.triangles,
            p.predicted_peak_bytes as f64 / (1024.0 * 1024.0),
            p.predicted_peak_bytes,
            p.model.margin,
            p.model.base_bytes / 1e6,
            p.model.bytes_per_element,
            p.points + p.triangles,
            p.builder_bytes as f64 / (1024.0 * 1024.0)
        )?;
    }
    Ok(())
}

/// Prints a memory report.
fn print_memory(m: &MemoryReport) -> Result<()> {
    let mib = |bytes: u64| bytes as f64 / (1024.0 * 1024.0);
    let mb = mib;
    if !m.out_of_core {
        outln!(
            "  memory: predicted in-core peak {:.1} MiB fits the limit {:.1} MiB: built in core (measured peak {})",
            mb(m.predicted_in_core_bytes),
            mb(m.limit_bytes),
            m.max_part_peak_kib
                .map_or("n/a".into(), |k| format!("{:.1} MiB", k as f64 / 1024.0))
        )?;
        return Ok(());
    }
    // Slabs are cut along one axis; a tree's planes alternate.
    let axis = |a: usize| ["x", "y", "z"][a.min(2)];
    let cuts = if m.planner == "slabs" {
        format!("{} parts along {}", m.parts, axis(m.axis.unwrap_or(0)))
    } else {
        let mut axes: Vec<&str> = m.plane_axes.iter().map(|&a| axis(a)).collect();
        axes.sort_unstable();
        axes.dedup();
        format!(
            "{} parts ({} planner, {} planes along {})",
            m.parts,
            m.planner,
            m.plane_axes.len(),
            axes.join(", ")
        )
    };
    outln!(
        "  memory: predicted in-core peak {:.1} MiB > limit {:.1} MiB: {cuts} ({} at a time), {} scene triangles cut, {:.2} s",
        mb(m.predicted_in_core_bytes),
        mb(m.limit_bytes),
        m.parallel_parts,
        m.triangles_cut,
        m.total_s
    )?;
    for k in 0..m.parts {
        outln!(
            "    part {k}: {} points, {} triangles -> {} tets; peak predicted {:.1} MiB, measured {}",
            m.part_points.get(k).copied().unwrap_or(0),
            m.part_triangles.get(k).copied().unwrap_or(0),
            m.part_tets.get(k).copied().unwrap_or(0),
            mb(m.part_predicted_bytes.get(k).copied().unwrap_or(0)),
            m.part_peak_kib
                .get(k)
                .copied()
                .flatten()
                .map_or("n/a".into(), |k| format!("{:.1} MiB", k as f64 / 1024.0))
        )?;
    }
    let process = m
        .process_peak_kib
        .map_or("n/a".into(), |k| format!("{:.1} MiB", k as f64 / 1024.0));
    match (
        m.merge_s,
        m.merge_max_resident_bytes,
        m.merge_all_parts_bytes,
    ) {
        (Some(s), Some(held), Some(all)) => outln!(
            "  merge: streamed through {:.1} MiB of part files in {s:.2} s, holding at most {:.1} MiB (all parts: {:.1} MiB); this process's peak {process}",
            mb(m.part_file_bytes.unwrap_or(0)),
            mb(held),
            mb(all)
        )?,
        _ => outln!("  merge: {}; this process's peak {process}", m.merge)?,
    }
    Ok(())
}
