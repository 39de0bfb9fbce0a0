//! `tet-bench build`: build a scene's mesh and write it to a mesh file.

use anyhow::{Context, Result, bail};
use serde::Serialize;

use crate::cli::BuildArgs;
use crate::load::{BuildSummary, MESH_EXTENSION, load};

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
    if args.output.extension().is_none_or(|e| e != MESH_EXTENSION) {
        bail!(
            "the output file must end in .{MESH_EXTENSION} (got {})",
            args.output.display()
        );
    }
    let loaded = load(&args.scene, &args.build, json)?;
    tet_core::format::save(&args.output, &loaded.mesh)
        .with_context(|| format!("cannot write {}", args.output.display()))?;
    let file_bytes = std::fs::metadata(&args.output)
        .map(|m| m.len())
        .unwrap_or(0);
    let doc = BuildDoc {
        name: loaded.name.clone(),
        output: args.output.display().to_string(),
        points: loaded.mesh.points.len(),
        tets: loaded.mesh.tets.len(),
        constrained_faces: loaded.mesh.constrained.len(),
        file_bytes,
        build: loaded.build.clone(),
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
    }
    Ok(())
}
