//! `tet-bench convert`: a tet mesh (and its scalar field, constrained
//! faces and triangle ids) between our mesh file, VTK and TetGen's files,
//! so a CDT or a volume opens in ParaView and a mesh from TetGen, TetWild
//! or a simulation reaches every command.

use std::path::Path;

use anyhow::{Context, Result};
use serde::Serialize;
use tet_build::tetgen_files;
use tet_build::volume::{VolumeOptions, load_volume};
use tet_build::vtk::{VtkEncoding, write_pvd, write_vtk};

use crate::cli::ConvertArgs;
use crate::output::{outln, print_json};

/// What `convert` wrote (JSON).
#[derive(Serialize)]
struct Converted<'a> {
    /// Input as given.
    input: &'a str,
    /// Output path.
    output: String,
    /// Output format.
    format: &'static str,
    /// Points.
    points: usize,
    /// Tets.
    tets: usize,
    /// Constrained faces.
    constrained_faces: usize,
    /// Time steps of the scalar field (0 without one).
    scalar_steps: usize,
}

/// The output format of `path`, by extension.
fn format_of(path: &Path) -> &'static str {
    match path.extension().and_then(|e| e.to_str()) {
        Some("vtk") => "vtk",
        Some("vtu") => "vtu",
        Some("pvd") => "pvd",
        Some("node") => "tetgen",
        _ => "tmesh",
    }
}

/// `tet-bench convert`.
pub fn run(args: &ConvertArgs, json: bool) -> Result<()> {
    let mesh = load_volume(&args.input, &VolumeOptions::default())
        .with_context(|| format!("cannot read {}", args.input))?;
    let out = &args.output;
    let format = format_of(out);
    match format {
        "vtk" | "vtu" => write_vtk(out, &mesh, VtkEncoding::Binary)?,
        "pvd" => write_pvd(out, &mesh, VtkEncoding::Binary)?,
        "tetgen" => {
            tetgen_files::write(&out.with_extension(""), &tetgen_files::from_tet_mesh(&mesh))?
        }
        _ => tet_core::format::save(out, &mesh)?,
    }
    let doc = Converted {
        input: &args.input,
        output: out.display().to_string(),
        format,
        points: mesh.points.len(),
        tets: mesh.tets.len(),
        constrained_faces: mesh.constrained.len(),
        scalar_steps: mesh
            .attributes
            .scalars
            .as_ref()
            .map_or(0, |f| f.step_count()),
    };
    if json {
        print_json(&doc)?;
    } else {
        outln!(
            "{} -> {} ({}): {} points, {} tets, {} constrained faces, {} scalar steps",
            doc.input,
            doc.output,
            doc.format,
            doc.points,
            doc.tets,
            doc.constrained_faces,
            doc.scalar_steps
        )?;
    }
    Ok(())
}
