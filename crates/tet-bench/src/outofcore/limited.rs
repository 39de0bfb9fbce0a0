//! `build --memory-limit`: the plan (in core, the paper's recursive tree or
//! parallel slabs, every part predicted under `limit / p` for `p` workers
//! at once), then the parts merged in memory ([`Limited::in_memory`]: the
//! caller holds the whole mesh, Hilbert-sorted as a whole) or streamed into
//! the mesh file ([`Limited::to_file`]: each part written to a part file as
//! its worker returns, Hilbert-sorted on its own, and the part files merged
//! a part at a time — `tet_build::outofcore::stream`).

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use tet_build::bbox::EnclosingBox;
use tet_build::outofcore::admission::{builder_bytes, worker_share};
use tet_build::outofcore::seam::{
    SeamOptions, SeamReport, SurfaceMode, build_slabs, build_slabs_to_file,
};
use tet_build::outofcore::split::{SlabPlan, SplitOptions, plan_slabs, plan_split_within};
use tet_build::outofcore::stream::{StreamOptions, StreamSummary};
use tet_build::outofcore::tree::{
    CutTree, TreePlan, build_tree_with_memory_limit, build_tree_with_memory_limit_to_file,
};
use tet_build::outofcore::tree_memory::TreeSampler;
use tet_core::TetMesh;
use tet_core::scene::SceneInfo;

use super::options::Planner;
use super::predict::predict;
use super::types::{Limited, MemoryReport, RelaxedPart, Written, mib};
use crate::load::build_flags::{BuildFlags, Walls};
use crate::load::{BuildSummary, CleaningSummary};

/// The split chosen.
enum Split {
    /// The paper's tree, every leaf predicted under `split.limit_bytes`.
    Tree(SplitOptions),
    /// Parallel slabs.
    Slabs(SlabPlan),
}

/// The plan of an out-of-core build.
struct Plan {
    /// When planning began (the build's clock).
    start: Instant,
    /// Predicted peak of the in-core TetGen run, bytes.
    predicted: u64,
    /// How the scene is split.
    split: Split,
    /// TetGen workers at once.
    parallel: usize,
    /// Options of every part's build.
    options: SeamOptions,
    /// Seconds spent cleaning the scene.
    clean_s: f64,
    /// Scene triangles after cleaning.
    scene_triangles: usize,
    /// Scene vertices after cleaning.
    scene_vertices: usize,
    /// What cleaning changed.
    cleaning: CleaningSummary,
}

/// What the split looked like, for the report.
struct Shape {
    /// `(axis, value)` of every plane, a tree's in preorder.
    cuts: Vec<(usize, f32)>,
    /// `tree` or `slabs`.
    planner: &'static str,
    /// Depth of the split.
    depth: usize,
    /// How many times planes were moved and the build retried.
    plane_moves: usize,
    /// The failures of TetGen on parts that retries moved walls for.
    part_failures: Vec<String>,
}

/// How the parts were merged, for the report.
struct Merged<'a> {
    /// `memory` or `stream`.
    mode: &'static str,
    /// The streaming merge's summary (streaming only).
    stream: Option<&'a StreamSummary>,
}

impl Limited<'_> {
    /// Builds in memory: the mesh, Hilbert-sorted as a whole unless
    /// `flags.no_sort`.
    pub fn in_memory(&self) -> Result<(TetMesh, BuildSummary, MemoryReport)> {
        let sampler = TreeSampler::start_own();
        let Some(mut plan) = self.plan()? else {
            let (mesh, build, mut report) = self.in_core()?;
            report.tree_peak_kib = sampler.finish();
            return Ok((mesh, build, report));
        };
        // This process gathers the whole mesh: the parts' results are not
        // given back while the others run, so no gate on them can hold the
        // limit; the workers' predictions still fit their shares.
        plan.options.tree_limit_bytes = None;
        let spinner = crate::load::spinner(self.quiet);
        spinner.set_message(self.progress(&plan));
        let tetgen_start = Instant::now();
        let (mut mesh, report, shape) = self.run(
            &plan,
            |split, options| build_tree_with_memory_limit(self.scene, split, options),
            |axis, values, options| build_slabs(self.scene, axis, values, options),
        )?;
        let tetgen_s = tetgen_start.elapsed().as_secs_f64();
        let reorder_start = Instant::now();
        if !self.flags.no_sort {
            spinner.set_message(format!("{}: Hilbert reordering", self.scene.name));
            tet_core::reorder::hilbert_reorder(&mut mesh)?;
        }
        let reorder_s = reorder_start.elapsed().as_secs_f64();
        spinner.finish_and_clear();
        let merged = Merged {
            mode: "memory",
            stream: None,
        };
        let (build, mut memory) = self.reports(
            &plan,
            report,
            &shape,
            mesh.points.len(),
            (tetgen_s, reorder_s),
            &merged,
        );
        memory.tree_peak_kib = sampler.finish();
        Ok((mesh, build, memory))
    }

    /// Builds into the mesh file `output` with the scene block `stored`:
    /// in core (then saved) when the prediction fits, else with the
    /// streaming merge (the whole mesh is never in memory; each part is
    /// Hilbert-sorted on its own unless `flags.no_sort`, parts in leaf
    /// order).
    pub fn to_file(
        &self,
        output: &Path,
        stored: &SceneInfo,
    ) -> Result<(Written, BuildSummary, MemoryReport)> {
        let sampler = TreeSampler::start_own();
        let Some(plan) = self.plan()? else {
            let (mesh, build, mut report) = self.in_core()?;
            tet_core::format::save_with_scene(output, &mesh, stored)
                .with_context(|| format!("cannot write {}", output.display()))?;
            report.tree_peak_kib = sampler.finish();
            let written = Written {
                points: mesh.points.len(),
                tets: mesh.tets.len(),
                constrained: mesh.constrained.len(),
                file_bytes: std::fs::metadata(output).map_or(0, |m| m.len()),
            };
            return Ok((written, build, report));
        };
        let stream = StreamOptions {
            output: output.to_path_buf(),
            scene: stored.clone(),
            sort_parts: !self.flags.no_sort,
            work_dir: None,
        };
        let spinner = crate::load::spinner(self.quiet);
        spinner.set_message(self.progress(&plan));
        let tetgen_start = Instant::now();
        let (summary, report, shape) = self.run(
            &plan,
            |split, options| {
                build_tree_with_memory_limit_to_file(self.scene, split, options, &stream)
            },
            |axis, values, options| build_slabs_to_file(self.scene, axis, values, options, &stream),
        )?;
        let tetgen_s = tetgen_start.elapsed().as_secs_f64();
        spinner.finish_and_clear();
        let merged = Merged {
            mode: "stream",
            stream: Some(&summary),
        };
        let (build, mut memory) = self.reports(
            &plan,
            report,
            &shape,
            summary.points as usize,
            (tetgen_s, 0.0),
            &merged,
        );
        memory.tree_peak_kib = sampler.finish();
        let written = Written {
            points: summary.points as usize,
            tets: summary.tets as usize,
            constrained: summary.constrained as usize,
            file_bytes: summary.file_bytes,
        };
        Ok((written, build, memory))
    }

    /// The in-core build when the whole scene's prediction fits.
    fn in_core(&self) -> Result<(TetMesh, BuildSummary, MemoryReport)> {
        let start = Instant::now();
        let own = builder_bytes(self.scene.triangles.len());
        let predicted = predict(self.scene, self.flags.no_box)?.predicted_peak_bytes;
        // The limit chooses the parts: where the scene fits, one piece.
        let one_piece = BuildFlags {
            walls: Some(Walls::None),
            ..*self.flags
        };
        let (mesh, build) =
            crate::load::build_scene_in(self.scene, &one_piece, self.quiet, self.extra)?;
        let report = MemoryReport {
            limit_bytes: self.limit_bytes,
            predicted_in_core_bytes: predicted,
            out_of_core: false,
            parts: 1,
            parallel_parts: 1,
            axis: None,
            planes: Vec::new(),
            plane_axes: Vec::new(),
            planner: "in-core".to_string(),
            depth: 0,
            triangles_cut: 0,
            part_points: Vec::new(),
            part_triangles: Vec::new(),
            part_tets: vec![mesh.tets.len()],
            part_predicted_bytes: vec![predicted],
            part_peak_kib: vec![build.worker_peak_kib],
            max_part_peak_kib: build.worker_peak_kib,
            part_split_pieces: vec![0],
            plane_moves: 0,
            part_failures: Vec::new(),
            surface_relaxed: Vec::new(),
            parts_reused: 0,
            total_s: start.elapsed().as_secs_f64(),
            merge: "in-core".to_string(),
            merge_s: None,
            merge_max_resident_bytes: None,
            merge_all_parts_bytes: None,
            part_file_bytes: None,
            process_peak_kib: tet_build::tetgen::worker::peak_memory_kib(),
            own_bytes: own,
            tree_peak_kib: None,
        };
        Ok((mesh, build, report))
    }

    /// The spinner's message while the parts are built.
    fn progress(&self, plan: &Plan) -> String {
        let what = match &plan.split {
            Split::Tree(_) => "a split tree".to_string(),
            Split::Slabs(s) => format!("{} slabs", s.values.len() + 1),
        };
        format!(
            "{}: building {what} ({} at a time)",
            self.scene.name, plan.parallel
        )
    }

    /// The split, or `None` when the whole scene's prediction fits.
    ///
    /// The limit bounds the whole process tree: this process's own memory
    /// (a model of it, [`builder_bytes`], so that the same command plans
    /// the same parts on every run) is set aside first, and each of `p`
    /// workers at once gets a `p`-th of the rest, less this process's share
    /// of its result ([`worker_share`]).
    fn plan(&self) -> Result<Option<Plan>> {
        let (scene, flags, limit_bytes) = (self.scene, self.flags, self.limit_bytes);
        let start = Instant::now();
        let predicted = predict(scene, flags.no_box)?.predicted_peak_bytes;
        let own = builder_bytes(scene.triangles.len());
        if own >= limit_bytes {
            bail!(
                "--memory-limit {:.1} MiB leaves nothing for TetGen: this process sets {:.1} MiB aside for itself (the scene `{}` and its parts); raise --memory-limit",
                mib(limit_bytes),
                mib(own),
                scene.name
            );
        }
        if predicted <= worker_share(limit_bytes, scene.triangles.len(), 1) {
            return Ok(None);
        }
        if flags.no_box {
            bail!(
                "`{}` needs an out-of-core build (predicted {:.1} MiB > what the limit {:.1} MiB leaves a worker beside this process), which cuts the enclosing box into parts: drop --no-box",
                scene.name,
                mib(predicted),
                mib(limit_bytes)
            );
        }
        let clean_start = Instant::now();
        let (cleaned, cm) = tet_build::clean::clean_scene(scene)
            .map_err(|e| anyhow::anyhow!("cannot clean `{}`: {e}", scene.name))?;
        let clean_s = clean_start.elapsed().as_secs_f64();
        let one_piece = crate::load::seam_options(scene, flags, self.extra)?;
        let b = EnclosingBox::new(cleaned.bounds(), one_piece.enclosing_box)
            .with_context(|| format!("cannot build the enclosing box of `{}`", scene.name))?;
        let (split, parallel) = self.choose(&cleaned, (b.min, b.max), scene.triangles.len())?;
        let options = SeamOptions {
            parallel_parts: parallel,
            tree_limit_bytes: Some(limit_bytes),
            ..one_piece
        };
        Ok(Some(Plan {
            start,
            predicted,
            split,
            parallel,
            options,
            clean_s,
            scene_triangles: cleaned.triangles.len(),
            scene_vertices: cleaned.vertices.len(),
            cleaning: CleaningSummary {
                merged_vertices: cm.report.merged_vertices.len(),
                repeated_vertex_triangles: cm.report.repeated_vertex_triangles.len(),
                zero_area_triangles: cm.report.zero_area_triangles.len(),
                duplicate_triangles: cm.report.duplicate_triangles.len(),
                unused_vertices: cm.report.unused_vertices.len(),
            },
        }))
    }

    /// The split and the workers at once for a scene of `triangles`
    /// triangles: the paper's tree when one fits, else slabs (or what
    /// `self.planner` forces).
    fn choose(
        &self,
        cleaned: &tet_build::scene::Scene,
        bounds: (glam::Vec3, glam::Vec3),
        triangles: usize,
    ) -> Result<(Split, usize)> {
        let (scene, limit_bytes) = (self.scene, self.limit_bytes);
        let own = builder_bytes(triangles);
        // Each leaf under its share and, as the default build is walled
        // (`--walls auto`), cut toward the part size of that build where
        // the share is larger: a mesh shaped for rays (the job planner
        // cuts the same way). `--walls none`: for the limit alone.
        let shaped = self.flags.walls() == Walls::Auto;
        let share =
            |p: usize| SplitOptions::under_limit(worker_share(limit_bytes, triangles, p), shaped);
        let max_parallel = self.max_parallel.max(1);
        // The paper's recursive tree (planes through the mean of the axis
        // of largest variance, moved to cut fewer triangles) first: on
        // Torus Knots in a Box it cut 10-12 triangles where slabs cut
        // 8-28 340 and was as fast or faster (tet-build's
        // tests/outofcore.rs `trade_torus_knots`). With `p` parts at once
        // every leaf must be predicted under its share: the most parallel
        // `p` with at least `p` leaves is taken.
        let tree = (self.planner != Planner::Slabs)
            .then(|| {
                (1..=max_parallel).rev().find_map(|p| {
                    let opts = share(p);
                    // A share too small gives up at its first part that
                    // does not fit, not after planning the whole tree.
                    plan_split_within(&cleaned.vertices, &cleaned.triangles, bounds, &opts)
                        .filter(|plan| plan.parts() >= p)
                        .map(|_| (Split::Tree(opts), p))
                })
            })
            .flatten();
        match (tree, self.planner) {
            (Some(t), _) => Ok(t),
            (None, Planner::Tree) => bail!(
                "no recursive split of `{}` keeps every part's predicted TetGen peak under {:.1} MiB (the limit {:.1} MiB less this process's own {:.1} MiB and its share of each part): raise --memory-limit or try --planner slabs",
                scene.name,
                mib(share(1).limit_bytes),
                mib(limit_bytes),
                mib(own)
            ),
            (None, _) => {
                // Slabs: one worker at a time, slabs predicted under the
                // share; with `p` at once under a `p`-th of it (more slabs,
                // more cut triangles and seam tets). The most parallel plan
                // with at least `p` slabs and at most twice as many as the
                // one-at-a-time plan.
                let slabs =
                    |p: usize| plan_slabs(&cleaned.vertices, &cleaned.triangles, bounds, &share(p));
                let Some(base) = slabs(1) else {
                    bail!(
                        "no split of `{}` keeps every part's predicted TetGen peak under {:.1} MiB (the limit {:.1} MiB less this process's own {:.1} MiB and its share of the part; an empty part alone is predicted {:.1} MiB, and every part carries its seams and box): raise --memory-limit",
                        scene.name,
                        mib(share(1).limit_bytes),
                        mib(limit_bytes),
                        mib(own),
                        mib(SplitOptions::default().model.predict(0, 0))
                    );
                };
                let base_parts = base.values.len() + 1;
                let (plan, p) = (2..=max_parallel)
                    .rev()
                    .find_map(|p| {
                        slabs(p)
                            .filter(|plan| {
                                let parts = plan.values.len() + 1;
                                parts >= p && parts <= 2 * base_parts
                            })
                            .map(|plan| (plan, p))
                    })
                    .unwrap_or((base, 1));
                Ok((Split::Slabs(plan), p))
            }
        }
    }

    /// Builds the planned split with `tree` or `slabs` (in memory or to a
    /// file).
    fn run<T>(
        &self,
        plan: &Plan,
        tree: impl FnOnce(
            &SplitOptions,
            &SeamOptions,
        )
            -> Result<(T, SeamReport, TreePlan), tet_build::outofcore::seam::SeamError>,
        slabs: impl FnOnce(
            usize,
            &[f32],
            &SeamOptions,
        ) -> Result<(T, SeamReport), tet_build::outofcore::seam::SeamError>,
    ) -> Result<(T, SeamReport, Shape)> {
        let failed = || format!("out-of-core build of `{}` failed", self.scene.name);
        match &plan.split {
            Split::Tree(split) => {
                let (out, report, built) = tree(split, &plan.options).with_context(failed)?;
                let mut cuts = Vec::new();
                let mut stack = vec![&built.cuts];
                while let Some(node) = stack.pop() {
                    if let CutTree::Split {
                        plane,
                        below,
                        above,
                    } = node
                    {
                        cuts.push((plane.axis, plane.value));
                        stack.push(above);
                        stack.push(below);
                    }
                }
                let shape = Shape {
                    cuts,
                    planner: "tree",
                    depth: built.plan.depth(),
                    plane_moves: built.plane_moves,
                    part_failures: built.part_failures,
                };
                Ok((out, report, shape))
            }
            Split::Slabs(s) => {
                let (out, report) = slabs(s.axis, &s.values, &plan.options).with_context(failed)?;
                let shape = Shape {
                    cuts: s.values.iter().map(|&v| (s.axis, v)).collect(),
                    planner: "slabs",
                    depth: (s.values.len() + 1).next_power_of_two().trailing_zeros() as usize,
                    plane_moves: 0,
                    part_failures: Vec::new(),
                };
                Ok((out, report, shape))
            }
        }
    }

    /// The construction and memory reports of an out-of-core build.
    fn reports(
        &self,
        plan: &Plan,
        report: SeamReport,
        shape: &Shape,
        points: usize,
        (tetgen_s, reorder_s): (f64, f64),
        merged: &Merged,
    ) -> (BuildSummary, MemoryReport) {
        let total_s = plan.start.elapsed().as_secs_f64();
        let peaks = report.part_peak_kib.clone();
        let max_peak = peaks.iter().flatten().copied().max();
        let summary = BuildSummary {
            switches: format!("{} (per part)", plan.options.tetgen.switches()),
            scene_triangles: plan.scene_triangles,
            steiner_points: points.saturating_sub(plan.scene_vertices + 8),
            clean_s: plan.clean_s,
            resolve_s: 0.0,
            tetgen_s,
            assemble_s: 0.0,
            reorder_s,
            total_s,
            worker_peak_kib: max_peak,
            cleaning: plan.cleaning.clone(),
            resolve: report.resolve.clone().unwrap_or_default(),
        };
        let s = merged.stream;
        let memory = MemoryReport {
            limit_bytes: self.limit_bytes,
            predicted_in_core_bytes: plan.predicted,
            out_of_core: true,
            parts: report.part_tets.len(),
            parallel_parts: plan.parallel,
            axis: shape.cuts.first().map(|c| c.0),
            planes: shape.cuts.iter().map(|c| c.1).collect(),
            plane_axes: shape.cuts.iter().map(|c| c.0).collect(),
            planner: shape.planner.to_string(),
            depth: shape.depth,
            plane_moves: shape.plane_moves,
            part_failures: shape.part_failures.clone(),
            surface_relaxed: report
                .part_surface
                .iter()
                .enumerate()
                .filter(|(_, m)| **m != SurfaceMode::Preserved)
                .map(|(part, m)| RelaxedPart {
                    part,
                    mode: m.name().to_string(),
                })
                .collect(),
            parts_reused: report.parts_reused,
            triangles_cut: report.triangles_cut,
            part_points: report.part_points,
            part_triangles: report.part_triangles,
            part_tets: report.part_tets,
            part_predicted_bytes: report.part_predicted_bytes,
            part_peak_kib: peaks,
            max_part_peak_kib: max_peak,
            part_split_pieces: report.part_split_pieces,
            total_s,
            merge: merged.mode.to_string(),
            merge_s: s.map(|s| s.merge_s),
            merge_max_resident_bytes: s.map(|s| s.max_resident_bytes),
            merge_all_parts_bytes: s.map(|s| s.all_parts_bytes),
            part_file_bytes: s.map(|s| s.part_file_bytes),
            process_peak_kib: tet_build::tetgen::worker::peak_memory_kib(),
            own_bytes: builder_bytes(self.scene.triangles.len()),
            tree_peak_kib: None,
        };
        (summary, memory)
    }
}
