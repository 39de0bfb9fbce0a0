//! Planning a job ([`plan_job`]): the scene cut exactly as the
//! single-process builders cut it ([`crate::outofcore::tree`] or
//! [`crate::outofcore::seam`]), every part's PLC written to its own input
//! file, and `job.json` written last (so a job directory with a
//! `job.json` has all its inputs).

use std::path::Path;

use tet_core::scene::SceneInfo;

use super::digest::{Xxh64, format_digest};
use super::error::JobError;
use super::manifest::{
    BuildRecord, ExactF32, FailedInput, JOB_FILE, JOB_SCHEMA, JOB_VERSION, JobManifest, MergePlan,
    PartRecord, Partition, SceneRecord, SeamRecord, TreeNode,
};
use super::part_input::{PartInput, encode};
use super::records::write_atomic;
use super::replan::known_failures;
use crate::bbox::EnclosingBox;
use crate::clean::clean_scene;
use crate::outofcore::error::SeamError;
use crate::outofcore::merge::PartInputs;
use crate::outofcore::parts::{PartPlc, SeamOptions, SeamReport};
use crate::outofcore::seam::slab_part_inputs;
use crate::outofcore::split::{SlabPlan, SplitOptions, plan_slabs};
use crate::outofcore::tree::{plan_tree_with_moves, tree_part_inputs_once};
use crate::scene::Scene;

/// How to cut the scene.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Planner {
    /// The paper's recursive tree; parallel slabs when no tree fits.
    #[default]
    Auto,
    /// The recursive tree only.
    Tree,
    /// Parallel slabs only.
    Slabs,
}

/// What [`plan_job`] is asked.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanOptions {
    /// Enclosing box, TetGen switches, resolution (isolation and
    /// parallelism are the part runner's business and ignored here).
    pub seam: SeamOptions,
    /// Every part's predicted TetGen peak stays under this (bytes).
    pub limit_bytes: Option<u64>,
    /// At least this many parts: a tree is split down to depth
    /// `⌈log2 parts⌉` at least; slabs are planned under lower limits until
    /// there are as many.
    pub parts: usize,
    /// How to cut.
    pub planner: Planner,
    /// Cut the tree's parts further, within the limit, toward the part
    /// size of the default walled build
    /// ([`SplitOptions::shaped_for_rays`]), so that the merged mesh takes
    /// as few tets per ray as that build; `false`: cut for the limit alone
    /// (fewer, larger parts: fewer tasks to schedule, a mesh slower to
    /// trace).
    pub shaped_for_rays: bool,
    /// Hilbert-sort each part before writing its result.
    pub sort_parts: bool,
    /// Seconds a part's TetGen worker may run.
    pub time_limit_s: f64,
    /// Camera and lights stored with the merged mesh.
    pub scene_info: SceneInfo,
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions {
            seam: SeamOptions::default(),
            limit_bytes: None,
            parts: 1,
            planner: Planner::Auto,
            shaped_for_rays: true,
            sort_parts: true,
            time_limit_s: 600.0,
            scene_info: SceneInfo::default(),
        }
    }
}

/// Digest of a scene's geometry: vertex count, vertices' bits, triangles.
pub fn scene_digest(scene: &Scene) -> String {
    let mut h = Xxh64::new();
    h.update(&(scene.vertices.len() as u64).to_le_bytes());
    for v in &scene.vertices {
        for c in v.to_array() {
            h.update(&c.to_bits().to_le_bytes());
        }
    }
    for t in &scene.triangles {
        for i in t {
            h.update(&i.to_le_bytes());
        }
    }
    format_digest(h.finish())
}

/// Depth a tree must reach to have at least `parts` leaves.
fn min_depth(parts: usize) -> usize {
    parts.max(1).next_power_of_two().trailing_zeros() as usize
}

/// Slabs under `limit`, at least `parts` of them: the limit is lowered
/// below the largest slab's prediction until there are enough (`None`
/// when no plan fits).
fn slabs_for(
    vertices: &[glam::Vec3],
    triangles: &[[u32; 3]],
    bounds: (glam::Vec3, glam::Vec3),
    limit: u64,
    parts: usize,
) -> Option<SlabPlan> {
    let mut split = SplitOptions {
        limit_bytes: limit,
        ..SplitOptions::default()
    };
    for _ in 0..64 {
        let plan = plan_slabs(vertices, triangles, bounds, &split)?;
        if plan.values.len() + 1 >= parts {
            return Some(plan);
        }
        let largest = plan.predicted_bytes.iter().copied().max()?;
        split.limit_bytes = largest - largest / 8;
    }
    None
}

/// Cuts `scene` into parts (see [`PlanOptions`]), writes every part's
/// input file and `job.json` into `dir` (made if missing) and returns the
/// plan. Results of an earlier plan in `dir` stay; a part whose input is
/// unchanged keeps its result (its digest still matches). Where parts of
/// an earlier plan of the same scene in `dir` failed in a way moving their
/// walls may cure, the tree planner moves the walls of every part whose
/// input failed ([`super::replan`]).
pub fn plan_job(scene: &Scene, options: &PlanOptions, dir: &Path) -> Result<JobManifest, JobError> {
    let digest = scene_digest(scene);
    let failed_inputs = known_failures(dir, &digest)?;
    let (cleaned, _) = clean_scene(scene).map_err(|e| JobError::Plan(SeamError::from(e)))?;
    if cleaned.triangles.is_empty() {
        return Err(JobError::Plan(SeamError::EmptyScene));
    }
    let b = EnclosingBox::new(cleaned.bounds(), options.seam.enclosing_box)
        .map_err(|e| JobError::Plan(SeamError::from(e)))?;
    // The cleaned copy is made again only if slabs are planned: it is not
    // held while the tree's parts are made.
    drop(cleaned);
    let limit = options.limit_bytes.unwrap_or(u64::MAX);
    // Cut as the local builds cut: under the limit and, unless told
    // otherwise, toward the part size that shapes the merged mesh for rays
    // (the walls of the default build), so that a job's mesh is traced as
    // fast as theirs.
    let split = SplitOptions {
        min_depth: min_depth(options.parts),
        ..SplitOptions::under_limit(limit, options.shaped_for_rays)
    };
    let seam = &options.seam;
    let prepared = std::cell::OnceCell::new();
    std::fs::create_dir_all(dir).map_err(JobError::io(dir))?;
    let tree = match options.planner {
        Planner::Slabs => None,
        _ => {
            // Each attempt writes its inputs as it makes them: a part whose
            // facets cannot be made, or whose input is known to fail,
            // fails the attempt so that the planner moves its walls (an
            // error of the files ends the planning, `Ok(Err)`).
            match plan_tree_with_moves(scene, &split, seam, |t, relaxed| {
                let (inputs, report) = tree_part_inputs_once(scene, &prepared, t, seam)?;
                match write_inputs(&inputs, relaxed, &failed_inputs, dir) {
                    Ok(parts) => Ok(Ok((inputs, report, parts))),
                    Err(JobError::Plan(e)) => Err(e),
                    Err(e) => Ok(Err(e)),
                }
            }) {
                Ok((written, plan)) => {
                    let (inputs, report, parts) = written?;
                    let mut next = 0;
                    let node = TreeNode::from_cut_tree(&plan.cuts, &mut next);
                    let partition = Partition::Tree {
                        tree: node,
                        plane_moves: plan.plane_moves,
                    };
                    Some((inputs, report, parts, partition))
                }
                Err(SeamError::LimitTooSmall { .. }) if options.planner == Planner::Auto => None,
                Err(SeamError::LimitTooSmall { limit_bytes }) => {
                    return Err(JobError::LimitTooSmall { limit_bytes });
                }
                Err(e) => return Err(JobError::Plan(e)),
            }
        }
    };
    let (inputs, report, parts, partition) = match tree {
        Some(t) => t,
        None => {
            let (cleaned, _) =
                clean_scene(scene).map_err(|e| JobError::Plan(SeamError::from(e)))?;
            let plan = slabs_for(
                &cleaned.vertices,
                &cleaned.triangles,
                (b.min, b.max),
                limit,
                options.parts,
            )
            .ok_or(JobError::LimitTooSmall { limit_bytes: limit })?;
            drop(cleaned);
            let (inputs, report) =
                slab_part_inputs(scene, plan.axis, &plan.values, seam).map_err(JobError::Plan)?;
            let partition = Partition::Slabs {
                axis: plan.axis,
                values: plan.values.iter().map(|&v| ExactF32(v)).collect(),
            };
            // Slab plans do not move planes: no known failures to avoid.
            let parts = write_inputs(&inputs, &[], &[], dir)?;
            (inputs, report, parts, partition)
        }
    };
    let (camera, lights) = MergePlan::scene_records(&options.scene_info);
    let manifest = JobManifest {
        schema: JOB_SCHEMA.into(),
        version: JOB_VERSION,
        scene: SceneRecord {
            name: scene.name.clone(),
            digest,
            vertices: scene.vertices.len(),
            triangles: inputs.triangle_count,
        },
        build: BuildRecord {
            quality: seam.tetgen.quality,
            max_steiner: seam.tetgen.max_steiner,
            min_dihedral: seam.tetgen.min_dihedral,
            optimization: seam.tetgen.optimization,
            max_dihedral: seam.tetgen.max_dihedral,
            time_limit_s: options.time_limit_s,
            sort_parts: options.sort_parts,
            resolve: seam.resolve.is_some(),
            limit_bytes: options.limit_bytes,
            box_min: b.min.to_array().map(ExactF32),
            box_max: b.max.to_array().map(ExactF32),
        },
        partition,
        merge: merge_plan(&report, parts.len(), camera, lights),
        parts,
        failed_inputs,
    };
    write_atomic(&dir.join(JOB_FILE), manifest.to_json().as_bytes())?;
    Ok(manifest)
}

fn merge_plan(
    report: &SeamReport,
    parts: usize,
    camera: Option<super::manifest::CameraRecord>,
    lights: Vec<super::manifest::LightRecord>,
) -> MergePlan {
    MergePlan {
        seams: report.seams.iter().map(SeamRecord::new).collect(),
        order: (0..parts).collect(),
        camera,
        lights,
    }
}

/// Writes every part's input file, one part's facets at a time (those
/// `relaxed` names with their surface relaxed); the parts' plan records.
/// A part whose facets fail in a way moving its walls may cure
/// ([`SeamError::part_to_retry`]), or whose input is one of `failed`
/// ([`SeamError::FailedBefore`]), is not written; the others are, and
/// then all such parts are returned together ([`SeamError::parts_failed`]
/// in [`JobError::Plan`]), so that the planner moves all their walls at
/// once.
fn write_inputs(
    inputs: &PartInputs,
    relaxed: &[usize],
    failed: &[FailedInput],
    dir: &Path,
) -> Result<Vec<PartRecord>, JobError> {
    let mut records = Vec::with_capacity(inputs.parts.len());
    let mut again = Vec::new();
    for k in 0..inputs.parts.len() {
        let list = match inputs.parts.facets(k) {
            Ok(list) => list,
            Err(e) if e.part_to_retry().is_some() => {
                again.push(e);
                continue;
            }
            Err(e) => return Err(JobError::Plan(e)),
        };
        let plc = PartPlc::new(&list.facets, &list.box_faces);
        let input = PartInput::of_part(inputs, k, &list, relaxed);
        drop(list);
        let (bytes, sum) = encode(&input);
        let digest = format_digest(sum);
        if let Some(f) = failed.iter().find(|f| f.input_digest == digest) {
            again.push(SeamError::FailedBefore {
                part: k,
                input_digest: digest,
                message: f.message.clone(),
            });
            continue;
        }
        let name = format!("part-{k}.input");
        write_atomic(&dir.join(&name), &bytes)?;
        records.push(PartRecord {
            index: k,
            input: name,
            input_digest: digest,
            input_bytes: bytes.len() as u64,
            result: format!("part-{k}.tmesh"),
            points: plc.input.points.len(),
            triangles: plc.input.triangles.len(),
            wall_points: plc.wall_points,
            wall_triangles: plc.wall_triangles,
            predicted_peak_bytes: plc.predicted_peak_bytes(),
            surface_relaxed: input.surface_relaxed,
        });
    }
    match SeamError::parts_failed(again) {
        Some(e) => Err(JobError::Plan(e)),
        None => Ok(records),
    }
}
