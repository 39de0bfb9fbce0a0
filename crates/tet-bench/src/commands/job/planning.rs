//! `build SCENE --plan JOB_DIR`: the job's plan written to a directory.

use std::path::Path;

use anyhow::{Context, Result, bail};
use serde::Serialize;
use tet_build::outofcore::job::manifest::Partition;
use tet_build::outofcore::job::{PlanOptions, Planner, plan_job};
use tet_build::outofcore::seam::SeamOptions;
use tet_core::scene::SceneInfo;

use crate::cli::BuildArgs;
use crate::load::MESH_EXTENSION;
use crate::load::build_flags::Walls;
use crate::outofcore::options::Planner as PlannerOption;
use crate::output::{outln, print_json};

/// The `build --plan` document.
#[derive(Debug, Serialize)]
pub struct PlanDoc {
    /// The job directory.
    pub job_dir: String,
    /// Scene name.
    pub scene: String,
    /// Digest of the scene's geometry.
    pub scene_digest: String,
    /// `tree` or `slabs`.
    pub planner: String,
    /// Parts.
    pub parts: usize,
    /// The per-part limit every prediction fits, bytes (`null`: by count only).
    pub limit_bytes: Option<u64>,
    /// Predicted TetGen peak of each part, bytes.
    pub part_predicted_bytes: Vec<u64>,
    /// Bytes of each part's input file.
    pub part_input_bytes: Vec<u64>,
    /// Part inputs known to fail from earlier runs of the job in this
    /// directory (`job.json`'s `failed_inputs`): the plan moved the walls
    /// of the parts that had them.
    pub failed_inputs: usize,
}

/// `tet-bench build SCENE --plan JOB_DIR`.
pub fn plan(args: &BuildArgs, dir: &Path, json: bool) -> Result<()> {
    if args.scene.ends_with(&format!(".{MESH_EXTENSION}")) {
        bail!(
            "--plan plans the build of a scene; `{}` is already a mesh file",
            args.scene
        );
    }
    let flags = &args.build;
    if flags.no_box {
        bail!("a job cuts the enclosing box into parts: drop --no-box");
    }
    let scene = tet_build::scene::Scene::load(&args.scene)
        .with_context(|| format!("cannot load scene `{}`", args.scene))?;
    let options = PlanOptions {
        seam: SeamOptions {
            enclosing_box: crate::load::enclosing_box(&scene, &[], flags.wide_box),
            tetgen: flags.tetgen_options(scene.vertices.len()),
            resolve: (!flags.no_resolve).then(Default::default),
            ..SeamOptions::default()
        },
        limit_bytes: args.memory_limit,
        parts: args.parts.unwrap_or(1),
        planner: match args.planner {
            PlannerOption::Auto => Planner::Auto,
            PlannerOption::Tree => Planner::Tree,
            PlannerOption::Slabs => Planner::Slabs,
        },
        // As the default build: walled unless `--walls none` (or a
        // quality bound, whose builds are one piece).
        shaped_for_rays: flags.walls() == Walls::Auto,
        sort_parts: !flags.no_sort,
        time_limit_s: flags.time_limit,
        scene_info: SceneInfo {
            camera: scene.camera,
            lights: scene.lights.clone(),
        },
    };
    let job = plan_job(&scene, &options, dir)
        .with_context(|| format!("cannot plan `{}` into {}", scene.name, dir.display()))?;
    let doc = PlanDoc {
        job_dir: dir.display().to_string(),
        scene: job.scene.name.clone(),
        scene_digest: job.scene.digest.clone(),
        planner: match job.partition {
            Partition::Tree { .. } => "tree",
            Partition::Slabs { .. } => "slabs",
        }
        .into(),
        parts: job.parts.len(),
        limit_bytes: job.build.limit_bytes,
        part_predicted_bytes: job.parts.iter().map(|p| p.predicted_peak_bytes).collect(),
        part_input_bytes: job.parts.iter().map(|p| p.input_bytes).collect(),
        failed_inputs: job.failed_inputs.len(),
    };
    if json {
        return print_json(&doc);
    }
    let mib = |b: u64| b as f64 / (1024.0 * 1024.0);
    outln!(
        "{}: {} parts ({}), largest predicted TetGen peak {:.1} MiB -> {}",
        doc.scene,
        doc.parts,
        doc.planner,
        mib(job.max_predicted_bytes()),
        doc.job_dir
    )?;
    if doc.failed_inputs > 0 {
        outln!(
            "  walls moved around {} part input(s) that failed in earlier runs; parts whose input is unchanged keep their results",
            doc.failed_inputs
        )?;
    }
    let n = doc.parts;
    outln!(
        "  build each part: tet-bench build-part {} --index K   (K = 0..{}; or a Slurm array / Kubernetes Indexed Job)",
        doc.job_dir,
        n - 1
    )?;
    outln!(
        "  then merge:      tet-bench merge {} -o OUT.tmesh   (or: tet-bench submit {} --engine slurm)",
        doc.job_dir,
        doc.job_dir
    )?;
    Ok(())
}
