//! The build pipeline: a triangle scene to a validated constrained Delaunay
//! tetrahedralization ([`TetMesh`]), as a short driver ([`build`]) over one
//! module per stage, each with its own input and output types:
//!
//! 1. `prepare`: clean the scene (merge equal vertices, drop degenerate
//!    and duplicate triangles);
//! 2. `resolve`: where triangles cross, touch in their interiors or
//!    overlap, split them along the intersections ([`crate::resolve`]);
//!    pieces keep their input triangle's id (off with
//!    [`BuildOptions::resolve`] = `None`: such a scene then fails with
//!    [`BuildError::SelfIntersections`]);
//! 3. `prepare`: add the optional enclosing box and mark TetGen's facets;
//! 4. `rounding`: TetGen `-pY`, then the exact f32 rounding check, with
//!    snapping and re-runs where rounding flattens tets;
//! 5. `faces`: every scene triangle is exactly one TetGen face;
//! 6. `assemble`: neighbour links and the constrained-face table
//!    ([`Assembly`]), then normals and uvs;
//! 7. `reorder`: optional Hilbert order ([`Reorder`]), tet-core's sort run
//!    in parallel;
//! 8. `validate`: tet-core's validator ([`Validation`]); the pipeline
//!    never returns a mesh that fails [`TetMesh::validate`].
//!
//! Options and the report are in [`options`], errors in [`error`]; the
//! stage modules are private, each documents its stage.

#![cfg(feature = "tetgen")]

mod assemble;
pub mod error;
mod faces;
mod frame;
pub mod options;
mod prepare;
mod reorder;
mod resolve;
pub(crate) mod rounding;
mod validate;

use std::time::Instant;

use tet_core::TetMesh;

pub use error::BuildError;
pub use options::{
    Assembly, BuildOptions, BuildReport, Progress, ProgressFn, Reorder, Stage, StageTimes,
    Validation,
};
pub(crate) use resolve::resolve_cleaned;

use crate::scene::Scene;
use crate::tetgen::worker::peak_memory_kib;

/// Builds the constrained Delaunay tetrahedralization of `scene` (see the module docs).
pub fn build(scene: &Scene, options: &BuildOptions) -> Result<(TetMesh, BuildReport), BuildError> {
    let start = Instant::now();
    let mut tetgen_options = options.tetgen.clone();
    if options.assembly == Assembly::TetgenNeighbors {
        tetgen_options.face_tets = true;
    }
    let mut report = BuildReport {
        switches: tetgen_options.switches(),
        ..BuildReport::default()
    };
    let progress = |stage: Stage| {
        if let Some(p) = &options.progress {
            p(&Progress {
                stage,
                elapsed: start.elapsed(),
            });
        }
    };

    // 1. Load and clean.
    progress(Stage::Clean);
    let t = Instant::now();
    let cleaned = prepare::clean(scene)?;
    report.times.clean = t.elapsed();
    report.clean = cleaned.map.report.clone();

    // 2. Resolve self-intersections (without it, a self-intersecting scene
    // fails in TetGen and comes back as `BuildError::SelfIntersections`).
    let cleaned = match &options.resolve {
        Some(resolve_options) => {
            progress(Stage::Resolve);
            let t = Instant::now();
            let (resolved, resolve_report) = resolve::resolve_scene(cleaned, resolve_options)?;
            report.times.resolve = t.elapsed();
            report.resolve = resolve_report;
            resolved
        }
        None => cleaned,
    };

    // 3. Enclosing box and TetGen's PLC.
    if options.enclosing_box.is_some() {
        progress(Stage::EnclosingBox);
    }
    let t = Instant::now();
    let plc = prepare::plc(&cleaned.scene, options.enclosing_box)?;
    report.scene_triangles = plc.scene_triangles;
    report.boundary_triangles = plc.boundary_triangles;
    if options.enclosing_box.is_some() {
        report.times.enclosing_box = t.elapsed();
    }
    let fixed_points = plc.input.points.len();

    // 4. TetGen and f32 rounding.
    let rounded = rounding::tetrahedralize_rounded(
        scene,
        plc.input,
        &plc.frame,
        &tetgen_options,
        options,
        &progress,
    )?;
    let stats = &rounded.stats;
    report.tetgen_rounds = stats.rounds;
    report.rounding_failures = stats.failures.clone();
    report.snapped_points = stats.snapped;
    report.times.tetgen = stats.tetgen;
    report.times.tetgen_inside = stats.tetgen_inside;
    report.times.rounding = stats.rounding;
    report.worker_peak_memory_kib = stats.worker_peak_kib;
    report.steiner_points = rounded.points.len() - fixed_points;

    // 5. Constrained faces.
    progress(Stage::ConstrainedFaces);
    let t = Instant::now();
    let faces = faces::match_scene_faces(
        &rounded.out.faces,
        &rounded.out.face_markers,
        &rounded.input.triangles,
        plc.scene_triangles,
        &cleaned.map.triangle_source,
    )?;
    report.times.constrained_faces = t.elapsed();

    // 6. Assembly and attributes.
    progress(Stage::Assemble);
    let t = Instant::now();
    let triangle_count = scene.triangles.len() as u32;
    let mut mesh = assemble::assemble(rounded, &faces, options.assembly, triangle_count)?;
    report.times.assemble = t.elapsed();
    assemble::attach_attributes(&mut mesh, &cleaned, scene);

    // 7. Reorder.
    if options.reorder == Reorder::Hilbert {
        progress(Stage::Reorder);
        let t = Instant::now();
        let reordering = reorder::hilbert_reorder(&mut mesh)
            .expect("an assembled mesh has one link row per tet");
        report.reordering = Some(reordering);
        report.times.reorder = t.elapsed();
    }

    // 8. Validate.
    progress(Stage::Validate);
    let t = Instant::now();
    validate::validate(&mesh, options.validation)?;
    report.times.validate = t.elapsed();

    report.points = mesh.points.len();
    report.tets = mesh.tets.len();
    report.constrained_faces = mesh.constrained.len();
    report.times.total = start.elapsed();
    report.peak_memory_kib = match (peak_memory_kib(), report.worker_peak_memory_kib) {
        (Some(a), Some(b)) => Some(a.max(b)),
        (a, b) => a.or(b),
    };
    Ok((mesh, report))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    /// Post-TetGen stage costs on "Torus Knots in a Box", best of 10 (run in
    /// release: `cargo test --release -p tet-build --lib -- --ignored
    /// --nocapture stage_timing`; `TET_STAGE_OBJ=path.obj` times that scene,
    /// `TET_STAGE_REPS` sets the repetitions).
    #[test]
    #[ignore = "measurement, not a check: prints stage timings; run in release with --nocapture"]
    fn stage_timing() {
        let reps: usize = std::env::var("TET_STAGE_REPS")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(10);
        let best = |f: &mut dyn FnMut() -> Duration| (0..reps).map(|_| f()).min().unwrap();
        let scene = match std::env::var("TET_STAGE_OBJ") {
            Ok(path) => Scene::load_obj(std::path::Path::new(&path)).unwrap(),
            Err(_) => crate::procedural::by_name("torus-knots-box").unwrap(),
        };
        let (mesh, _) = build(&scene, &BuildOptions::default()).unwrap();
        println!("{}: {} tets", scene.name, mesh.tets.len());
        println!("rayon threads: {}", rayon::current_num_threads());
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        let time = |f: &mut dyn FnMut(&mut TetMesh)| {
            best(&mut || {
                let mut m = mesh.clone();
                let s = Instant::now();
                f(&mut m);
                s.elapsed()
            })
        };
        let parallel = time(&mut |m| {
            reorder::hilbert_reorder(m).unwrap();
        });
        let sequential = time(&mut |m| {
            tet_core::reorder::hilbert_reorder(m).unwrap();
        });
        println!(
            "hilbert reorder: parallel {:.1} ms, tet_core {:.1} ms",
            ms(parallel),
            ms(sequential)
        );
        let construction = time(&mut |m| validate::check_construction(m).unwrap());
        let construction_seq = time(&mut |m| m.validate_construction().unwrap());
        let full = time(&mut |m| m.validate().unwrap());
        println!(
            "construction check: parallel {:.1} ms, tet_core {:.1} ms; validate {:.1} ms",
            ms(construction),
            ms(construction_seq),
            ms(full)
        );
    }
}
