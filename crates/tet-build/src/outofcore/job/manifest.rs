//! `job.json`: the self-describing plan of a job ([`JobManifest`]); its
//! schema is in the README ("Building on a cluster").
//!
//! Coordinates that must come back bit-exactly (cut planes, seam
//! rectangles, the enclosing box) are JSON *strings* holding the shortest
//! decimal that parses back to the same `f32` ([`ExactF32`]): a JSON
//! number would go through `f64` in most readers. Camera and lights are
//! plain numbers.

use std::path::{Path, PathBuf};

use glam::Vec3;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use tet_core::scene::{Camera, PointLight, SceneInfo};

use super::error::JobError;
use crate::outofcore::plane::SplitPlane;
use crate::outofcore::tree::CutTree;

/// The `schema` field of every job description.
pub const JOB_SCHEMA: &str = "tet-job";
/// The version of `job.json` written and read.
pub const JOB_VERSION: u32 = 1;
/// The job description's file name in the job directory.
pub const JOB_FILE: &str = "job.json";

/// An `f32` written as its shortest round-trip decimal string.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExactF32(pub f32);

impl Serialize for ExactF32 {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&format!("{:?}", self.0))
    }
}

impl<'de> Deserialize<'de> for ExactF32 {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<ExactF32, D::Error> {
        let s = String::deserialize(d)?;
        match s.parse::<f32>() {
            Ok(v) if v.is_finite() => Ok(ExactF32(v)),
            _ => Err(serde::de::Error::custom(format!(
                "{s:?} is not a finite f32"
            ))),
        }
    }
}

fn exact3(v: Vec3) -> [ExactF32; 3] {
    v.to_array().map(ExactF32)
}

fn vec3(v: &[ExactF32; 3]) -> Vec3 {
    Vec3::new(v[0].0, v[1].0, v[2].0)
}

/// The scene the job was planned from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneRecord {
    /// Scene name.
    pub name: String,
    /// Digest of its vertices' bits and triangles ([`super::plan::scene_digest`]).
    pub digest: String,
    /// Vertices.
    pub vertices: usize,
    /// Triangles (the ids the mesh's constrained faces carry are below it).
    pub triangles: u32,
}

/// How every part is built.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BuildRecord {
    /// TetGen `-q` bound, if any.
    pub quality: Option<f64>,
    /// TetGen `-S` cap, if any.
    pub max_steiner: Option<u64>,
    /// TetGen `-q<ratio>/<degrees>` sliver bound, if any (absent in files
    /// written before it existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_dihedral: Option<f64>,
    /// TetGen `-O` optimisation, when not TetGen's default (absent in
    /// files written before it existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub optimization: Option<crate::tetgen::Optimization>,
    /// TetGen `-o/` dihedral bound of the optimisation, when not its
    /// default (absent in files written before it existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_dihedral: Option<f64>,
    /// Seconds one part's TetGen worker may run.
    pub time_limit_s: f64,
    /// Hilbert-sort each part on its own before writing it.
    pub sort_parts: bool,
    /// The scene's self-intersections were resolved before the split.
    pub resolve: bool,
    /// The per-part limit the plan keeps every prediction under, bytes
    /// (`null`: planned by part count only).
    pub limit_bytes: Option<u64>,
    /// Enclosing box, lower corner.
    pub box_min: [ExactF32; 3],
    /// Enclosing box, upper corner.
    pub box_max: [ExactF32; 3],
}

/// A node of the recursive split: a leaf (its part index) or a plane.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum TreeNode {
    /// One part, by index.
    Leaf(usize),
    /// A cut: the half `x[axis] ≤ value` (`below`) and `≥ value` (`above`).
    Split {
        /// 0, 1, 2 for x, y, z.
        axis: usize,
        /// The plane's offset.
        value: ExactF32,
        /// The lower half.
        below: Box<TreeNode>,
        /// The upper half.
        above: Box<TreeNode>,
    },
}

impl TreeNode {
    /// The node of `tree`, leaves numbered depth-first below first from `next`.
    pub fn from_cut_tree(tree: &CutTree, next: &mut usize) -> TreeNode {
        match tree {
            CutTree::Leaf => {
                *next += 1;
                TreeNode::Leaf(*next - 1)
            }
            CutTree::Split {
                plane,
                below,
                above,
            } => TreeNode::Split {
                axis: plane.axis,
                value: ExactF32(plane.value),
                below: Box::new(TreeNode::from_cut_tree(below, next)),
                above: Box::new(TreeNode::from_cut_tree(above, next)),
            },
        }
    }

    /// The planes as a [`CutTree`].
    pub fn cut_tree(&self) -> CutTree {
        match self {
            TreeNode::Leaf(_) => CutTree::Leaf,
            TreeNode::Split {
                axis,
                value,
                below,
                above,
            } => CutTree::split(*axis, value.0, below.cut_tree(), above.cut_tree()),
        }
    }

    /// The leaves' part indices, depth-first below first.
    pub fn leaves(&self) -> Vec<usize> {
        match self {
            TreeNode::Leaf(k) => vec![*k],
            TreeNode::Split { below, above, .. } => {
                let mut v = below.leaves();
                v.extend(above.leaves());
                v
            }
        }
    }
}

/// How the scene was cut into parts.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "planner", rename_all = "lowercase", deny_unknown_fields)]
pub enum Partition {
    /// The paper's recursive tree (Erkoç et al. 2021).
    Tree {
        /// The tree; leaves carry part indices.
        tree: TreeNode,
        /// Planes moved off degenerate configurations while planning.
        plane_moves: usize,
    },
    /// Parallel slabs along one axis.
    Slabs {
        /// 0, 1, 2 for x, y, z.
        axis: usize,
        /// The planes' offsets, increasing.
        values: Vec<ExactF32>,
    },
}

/// One part of the plan.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PartRecord {
    /// The part's index (its position in `parts`).
    pub index: usize,
    /// Its input file, in the job directory.
    pub input: String,
    /// The input file's digest (its checksum, `xxh64:…`).
    pub input_digest: String,
    /// The input file's bytes.
    pub input_bytes: u64,
    /// Its result file (a mesh file), in the job directory.
    pub result: String,
    /// TetGen input points.
    pub points: usize,
    /// TetGen input facets.
    pub triangles: usize,
    /// Points on no scene facet (wall corners, trace points).
    pub wall_points: usize,
    /// Facets that are seam-only or box faces.
    pub wall_triangles: usize,
    /// The memory model's prediction of the part's TetGen peak, bytes (with margin).
    pub predicted_peak_bytes: u64,
    /// Built with its surface relaxed (`SeamOptions::surface_relaxed_parts`), as its input
    /// file says: the planner's last resort for a part TetGen failed on
    /// wherever its walls stood. Absent (false) in older plans.
    #[serde(default)]
    pub surface_relaxed: bool,
}

/// A seam between parts: plane and rectangle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeamRecord {
    /// 0, 1, 2 for x, y, z.
    pub axis: usize,
    /// The plane's offset.
    pub value: ExactF32,
    /// Lower corner of the rectangle.
    pub lo: [ExactF32; 3],
    /// Upper corner.
    pub hi: [ExactF32; 3],
}

impl SeamRecord {
    /// The record of a seam as the builders report it.
    pub fn new(seam: &(SplitPlane, Vec3, Vec3)) -> SeamRecord {
        SeamRecord {
            axis: seam.0.axis,
            value: ExactF32(seam.0.value),
            lo: exact3(seam.1),
            hi: exact3(seam.2),
        }
    }

    /// The seam as the streamed merge takes it.
    pub fn seam(&self) -> (SplitPlane, Vec3, Vec3) {
        (
            SplitPlane {
                axis: self.axis,
                value: self.value.0,
            },
            vec3(&self.lo),
            vec3(&self.hi),
        )
    }
}

/// A camera as stored with the merged mesh.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraRecord {
    /// Eye.
    pub position: [f32; 3],
    /// Point looked at.
    pub target: [f32; 3],
    /// Up vector.
    pub up: [f32; 3],
    /// Vertical field of view, degrees.
    pub vfov_deg: f32,
}

/// A point light as stored with the merged mesh.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightRecord {
    /// Position.
    pub position: [f32; 3],
    /// Linear RGB colour.
    pub color: [f32; 3],
    /// Intensity.
    pub intensity: f32,
}

/// How the finished parts become one mesh.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MergePlan {
    /// The seams (their faces are matched across parts).
    pub seams: Vec<SeamRecord>,
    /// Parts in the order their elements follow each other in the mesh.
    pub order: Vec<usize>,
    /// The camera stored with the mesh.
    pub camera: Option<CameraRecord>,
    /// The lights stored with the mesh.
    pub lights: Vec<LightRecord>,
}

impl MergePlan {
    /// The scene block of the merged mesh.
    pub fn scene_info(&self) -> SceneInfo {
        let v = Vec3::from_array;
        SceneInfo {
            camera: self.camera.as_ref().map(|c| Camera {
                position: v(c.position),
                target: v(c.target),
                up: v(c.up),
                vfov_deg: c.vfov_deg,
            }),
            lights: self
                .lights
                .iter()
                .map(|l| PointLight {
                    position: v(l.position),
                    color: v(l.color),
                    intensity: l.intensity,
                })
                .collect(),
        }
    }

    /// The records of a scene block.
    pub fn scene_records(info: &SceneInfo) -> (Option<CameraRecord>, Vec<LightRecord>) {
        let camera = info.camera.map(|c| CameraRecord {
            position: c.position.to_array(),
            target: c.target.to_array(),
            up: c.up.to_array(),
            vfov_deg: c.vfov_deg,
        });
        let lights = info
            .lights
            .iter()
            .map(|l| LightRecord {
                position: l.position.to_array(),
                color: l.color.to_array(),
                intensity: l.intensity,
            })
            .collect();
        (camera, lights)
    }
}

/// `job.json`: everything a part, the merge and a scheduler need.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JobManifest {
    /// Always [`JOB_SCHEMA`].
    pub schema: String,
    /// [`JOB_VERSION`].
    pub version: u32,
    /// The scene.
    pub scene: SceneRecord,
    /// How parts are built.
    pub build: BuildRecord,
    /// How the scene was cut.
    pub partition: Partition,
    /// One entry per part, index order.
    pub parts: Vec<PartRecord>,
    /// How the results are merged.
    pub merge: MergePlan,
    /// Part inputs that failed in earlier runs of the job in a way moving
    /// their walls may cure: the plan moved the walls of every part whose
    /// input was one of them, and keeps them so that planning again does
    /// not go back to an input known to fail. Empty (and absent from the
    /// file) when none failed.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub failed_inputs: Vec<FailedInput>,
}

/// A part input that failed ([`JobManifest::failed_inputs`]).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FailedInput {
    /// The input's digest.
    pub input_digest: String,
    /// The part it was in the plan it failed in.
    pub part: usize,
    /// How it failed, in words.
    pub message: String,
}

impl JobManifest {
    /// The largest predicted part peak, bytes.
    pub fn max_predicted_bytes(&self) -> u64 {
        self.parts
            .iter()
            .map(|p| p.predicted_peak_bytes)
            .max()
            .unwrap_or(0)
    }

    /// Parses and checks `job.json`'s text (`path` names it in errors).
    pub fn from_json(text: &str, path: &Path) -> Result<JobManifest, JobError> {
        let bad = |detail: String| JobError::Manifest {
            path: path.to_path_buf(),
            detail,
        };
        // Schema and version first, so that another version is named as such
        // rather than as a field error.
        let head: serde_json::Value =
            serde_json::from_str(text).map_err(|e| bad(format!("not JSON: {e}")))?;
        match head.get("schema") {
            Some(serde_json::Value::String(s)) if s == JOB_SCHEMA => {}
            Some(s) => return Err(bad(format!("schema {s}, expected {JOB_SCHEMA:?}"))),
            None => return Err(bad("no schema field: not a job description".into())),
        }
        match head.get("version") {
            Some(v) if v.as_u64() == Some(u64::from(JOB_VERSION)) => {}
            Some(v) => {
                return Err(bad(format!(
                    "version {v}, this reader knows version {JOB_VERSION}"
                )));
            }
            None => return Err(bad("no version field".into())),
        }
        let m: JobManifest = serde_json::from_value(head).map_err(|e| bad(e.to_string()))?;
        m.check().map_err(bad)?;
        Ok(m)
    }

    /// The consistency checks of [`JobManifest::from_json`].
    fn check(&self) -> Result<(), String> {
        let n = self.parts.len();
        if n == 0 {
            return Err("parts: empty".into());
        }
        for (i, p) in self.parts.iter().enumerate() {
            if p.index != i {
                return Err(format!("parts[{i}].index is {}", p.index));
            }
            for (field, name) in [("input", &p.input), ("result", &p.result)] {
                if !plain_file_name(name) {
                    return Err(format!(
                        "parts[{i}].{field} {name:?} is not a plain file name"
                    ));
                }
            }
        }
        let mut order = self.merge.order.clone();
        order.sort_unstable();
        if order != (0..n).collect::<Vec<_>>() {
            return Err(format!("merge.order is not a permutation of 0..{n}"));
        }
        match &self.partition {
            Partition::Tree { tree, .. } => {
                if tree.leaves() != self.merge.order {
                    return Err("partition.tree's leaves are not merge.order".into());
                }
            }
            Partition::Slabs { axis, values } => {
                if *axis > 2 || values.len() + 1 != n {
                    return Err(format!(
                        "partition: {} slab planes on axis {axis} for {n} parts",
                        values.len()
                    ));
                }
            }
        }
        for (i, s) in self.merge.seams.iter().enumerate() {
            if s.axis > 2 {
                return Err(format!("merge.seams[{i}].axis is {}", s.axis));
            }
        }
        Ok(())
    }

    /// Reads `dir/job.json`.
    pub fn load(dir: &Path) -> Result<JobManifest, JobError> {
        let path = dir.join(JOB_FILE);
        let text = std::fs::read_to_string(&path).map_err(JobError::io(&path))?;
        JobManifest::from_json(&text, &path)
    }

    /// The JSON text written to `job.json`.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a job description serializes") + "\n"
    }

    /// Path of part `k`'s input, result, done, error and running files in
    /// `dir`.
    pub fn part_paths(&self, dir: &Path, k: usize) -> PartPaths {
        let p = &self.parts[k];
        PartPaths {
            input: dir.join(&p.input),
            result: dir.join(&p.result),
            done: dir.join(format!("part-{k}.done.json")),
            error: dir.join(format!("part-{k}.error.json")),
            running: dir.join(format!("part-{k}.running.json")),
        }
    }
}

/// The files of one part.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PartPaths {
    /// Its input (facets).
    pub input: PathBuf,
    /// Its result (a mesh file).
    pub result: PathBuf,
    /// `part-K.done.json`: digests and measured peaks of a finished run.
    pub done: PathBuf,
    /// `part-K.error.json`: why the last run failed.
    pub error: PathBuf,
    /// `part-K.running.json`: a run in progress (removed when it ends).
    pub running: PathBuf,
}

/// A file name without directories (the job directory can move).
fn plain_file_name(name: &str) -> bool {
    !name.is_empty() && name != "." && name != ".." && !name.contains(['/', '\\', '\0'])
}
