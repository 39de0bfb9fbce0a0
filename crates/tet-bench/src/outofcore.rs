//! Building under a memory limit (issue 8): `build --predict-memory`,
//! `build --memory-limit`, and the out-of-core table of `tables`.
//!
//! The prediction is `tet_build`'s memory model
//! ([`tet_build::outofcore::memory_model::predict_peak_memory`], TetGen's
//! peak resident memory as a linear function of points + triangles of its
//! input, with a safety margin) on the cleaned scene plus the enclosing
//! box's 8 corners and 12 triangles. Over the limit, the scene is split
//! recursively by the paper's planes until every part's prediction fits
//! the limit divided by the parts run at once
//! ([`tet_build::outofcore::tree::build_tree_with_memory_limit`]), each
//! part is tetrahedralized by its own TetGen worker with exact seams and
//! the parts are merged; when no tree fits, parallel slabs are tried
//! ([`tet_build::outofcore::split::plan_slabs`]). Measured on Torus Knots
//! in a Box, the tree cuts 12 triangles where slabs cut 14,012–28,340 and
//! builds in 0.62–0.67× the in-core time at ½–¼ of its peak.

use anyhow::Result;
use serde::Serialize;
use tet_build::scene::Scene;
use tet_core::TetMesh;

use crate::cli::BuildFlags;
use crate::load::BuildSummary;

/// Parses a memory size: a byte count, or a number with a unit `K`, `M`,
/// `G`, `T` (also `KB`/`KiB`, …, any case), all powers of 1024: `512M`,
/// `1.5G`, `2097152`.
pub fn parse_memory_limit(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let unit = unit.trim().to_ascii_lowercase();
    let scale: f64 = match unit.as_str() {
        "" | "b" => 1.0,
        "k" | "kb" | "kib" => 1024.0,
        "m" | "mb" | "mib" => 1024.0 * 1024.0,
        "g" | "gb" | "gib" => 1024.0 * 1024.0 * 1024.0,
        "t" | "tb" | "tib" => 1024.0 * 1024.0 * 1024.0 * 1024.0,
        _ => {
            return Err(format!(
                "unknown unit `{unit}` in `{s}`: give bytes or a number with K, M, G or T (powers of 1024), e.g. 512M or 1.5G"
            ));
        }
    };
    let value: f64 = num.parse().map_err(|_| {
        format!("`{s}` is not a memory size: give bytes or a number with K, M, G or T, e.g. 512M or 1.5G")
    })?;
    let bytes = value * scale;
    if !(bytes >= 1.0 && bytes < u64::MAX as f64) {
        return Err(format!(
            "memory limit `{s}` must be at least one byte and finite"
        ));
    }
    Ok(bytes.round() as u64)
}

/// Bytes as MiB.
fn mib(bytes: u64) -> f64 {
    bytes as f64 / (1024.0 * 1024.0)
}

/// `build --predict-memory` document.
#[derive(Clone, Debug, Serialize)]
pub struct Prediction {
    /// Scene name.
    pub name: String,
    /// Points given to TetGen (cleaned scene vertices + 8 box corners).
    pub points: usize,
    /// Triangles given to TetGen (cleaned scene triangles + 12 box triangles).
    pub triangles: usize,
    /// Predicted peak resident memory of the TetGen run, bytes (with margin).
    pub predicted_peak_bytes: u64,
    /// The model: `margin × (base_bytes + bytes_per_element × (points + triangles))`.
    pub model: ModelDoc,
}

/// The memory model's constants.
#[derive(Clone, Debug, Serialize)]
pub struct ModelDoc {
    /// Fixed part, bytes.
    pub base_bytes: f64,
    /// Bytes per input point or triangle.
    pub bytes_per_element: f64,
    /// Safety margin (multiplier).
    pub margin: f64,
}

/// What a build under `--memory-limit` did (field `memory` of the `build`
/// document, and rows of the out-of-core table).
#[derive(Clone, Debug, Serialize)]
pub struct MemoryReport {
    /// The limit, bytes.
    pub limit_bytes: u64,
    /// Predicted peak of the in-core TetGen run, bytes.
    pub predicted_in_core_bytes: u64,
    /// True when the scene was built in parts.
    pub out_of_core: bool,
    /// Parts (1 in core).
    pub parts: usize,
    /// Parts run at once (their predictions together fit the limit).
    pub parallel_parts: usize,
    /// Cut axis (0 = x, 1 = y, 2 = z) of the first plane, when cut (the
    /// only axis for slabs).
    pub axis: Option<usize>,
    /// Cut plane offsets (n parts: n - 1 planes; a tree's in preorder).
    pub planes: Vec<f32>,
    /// Axis of each plane of `planes`.
    pub plane_axes: Vec<usize>,
    /// Scene triangles cut by the planes.
    pub triangles_cut: usize,
    /// How the scene was split: `in-core`, `tree` (the paper's recursive
    /// perpendicular planes; `axis`/`planes` then empty) or `slabs`.
    pub planner: String,
    /// Depth of the split (0 in core; for slabs, log2 of the parts, rounded up).
    pub depth: usize,
    /// Input points of each part's TetGen run.
    pub part_points: Vec<usize>,
    /// Input triangles of each part's TetGen run.
    pub part_triangles: Vec<usize>,
    /// Tets of each part.
    pub part_tets: Vec<usize>,
    /// Predicted peak of each part, bytes.
    pub part_predicted_bytes: Vec<u64>,
    /// Measured peak (worker `VmHWM`) of each part, KiB.
    pub part_peak_kib: Vec<Option<u64>>,
    /// Largest measured part peak, KiB.
    pub max_part_peak_kib: Option<u64>,
    /// Wall time of the build (parts, merge, validation), s.
    pub total_s: f64,
}

/// Cleaned scene size as TetGen would receive it (with the box unless `no_box`).
#[cfg(feature = "tetgen")]
pub fn tetgen_input_size(scene: &Scene, no_box: bool) -> Result<(usize, usize)> {
    let (cleaned, _) = tet_build::clean::clean_scene(scene)
        .map_err(|e| anyhow::anyhow!("cannot clean `{}`: {e}", scene.name))?;
    let extra = if no_box { (0, 0) } else { (8, 12) };
    Ok((
        cleaned.vertices.len() + extra.0,
        cleaned.triangles.len() + extra.1,
    ))
}

/// The prediction for `scene`.
#[cfg(feature = "tetgen")]
pub fn predict(scene: &Scene, no_box: bool) -> Result<Prediction> {
    use tet_build::outofcore::memory_model::{MemoryModel, predict_peak_memory};
    let (points, triangles) = tetgen_input_size(scene, no_box)?;
    let m = MemoryModel::FITTED;
    Ok(Prediction {
        name: scene.name.clone(),
        points,
        triangles,
        predicted_peak_bytes: predict_peak_memory(points, triangles),
        model: ModelDoc {
            base_bytes: m.base_bytes,
            bytes_per_element: m.bytes_per_element,
            margin: m.margin,
        },
    })
}

/// Without TetGen there is nothing to predict.
#[cfg(not(feature = "tetgen"))]
pub fn predict(scene: &Scene, _: bool) -> Result<Prediction> {
    anyhow::bail!(
        "`{}`: the memory model needs the `tetgen` feature",
        scene.name
    )
}

/// Builds `scene` so that every TetGen run's predicted peak fits
/// `limit_bytes`: in core when the whole scene's prediction fits, else in
/// slabs, up to `max_parallel` at a time with their predictions together
/// under the limit (the most parallel plan that has at least as many
/// slabs as workers and at most twice as many as the one-at-a-time plan). The result is Hilbert-sorted unless
/// `flags.no_sort`. `extra` points (other cameras and lights) are kept
/// inside the enclosing box.
#[cfg(feature = "tetgen")]
pub fn build_limited(
    scene: &Scene,
    flags: &BuildFlags,
    limit_bytes: u64,
    max_parallel: usize,
    quiet: bool,
    extra: &[glam::Vec3],
) -> Result<(TetMesh, BuildSummary, MemoryReport)> {
    use std::time::Instant;

    use anyhow::{Context, bail};
    use tet_build::bbox::EnclosingBox;
    use tet_build::outofcore::seam::{SeamOptions, build_slabs};
    use tet_build::outofcore::split::{SplitOptions, plan_slabs, plan_split};
    use tet_build::outofcore::tree::build_tree_with_memory_limit;
    use tet_build::tetgen::TetgenOptions;

    let start = Instant::now();
    let predicted = predict(scene, flags.no_box)?.predicted_peak_bytes;
    if predicted <= limit_bytes {
        let (mesh, build) = crate::load::build_scene_in(scene, flags, quiet, extra)?;
        let report = MemoryReport {
            limit_bytes,
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
            total_s: start.elapsed().as_secs_f64(),
        };
        return Ok((mesh, build, report));
    }
    if flags.no_box {
        bail!(
            "`{}` needs an out-of-core build (predicted {:.1} MiB > limit {:.1} MiB), which cuts the enclosing box into slabs: drop --no-box",
            scene.name,
            mib(predicted),
            mib(limit_bytes)
        );
    }
    let spinner = crate::load::spinner(quiet);
    spinner.set_message(format!("{}: planning the split", scene.name));
    let clean_start = Instant::now();
    let (cleaned, cm) = tet_build::clean::clean_scene(scene)
        .map_err(|e| anyhow::anyhow!("cannot clean `{}`: {e}", scene.name))?;
    let clean_s = clean_start.elapsed().as_secs_f64();
    let box_spec = crate::load::enclosing_box(scene, extra, flags.wide_box);
    let b = EnclosingBox::new(cleaned.bounds(), box_spec)
        .with_context(|| format!("cannot build the enclosing box of `{}`", scene.name))?;
    // One worker at a time: slabs predicted under the limit. With `p`
    // workers at once, slabs must be predicted under `limit / p`: more
    // slabs, more cut triangles and seam tets, worse tets near the seams.
    // The most parallel plan is taken that has at least `p` slabs and at
    // most twice as many as the one-at-a-time plan.
    let split = SplitOptions {
        limit_bytes,
        ..SplitOptions::default()
    };
    let make_options = |parallel: usize| -> Result<SeamOptions> {
        Ok(SeamOptions {
            enclosing_box: box_spec,
            tetgen: TetgenOptions {
                quality: flags.quality,
                max_steiner: flags.max_steiner,
                ..TetgenOptions::default()
            },
            isolation: crate::load::worker_isolation(flags.time_limit)?,
            parallel_parts: parallel,
        })
    };
    // The paper's recursive tree (planes through the mean of the axis of
    // largest variance, moved to cut fewer triangles) is tried first: on
    // Torus Knots in a Box it cut 10-12 triangles where slabs cut 8-28 340
    // and was as fast or faster (tests/outofcore.rs `trade_torus_knots`).
    // With `p` parts at once every leaf must be predicted under `limit / p`.
    let tree_for = |p: usize| {
        let opts = SplitOptions {
            limit_bytes: limit_bytes / p as u64,
            ..split
        };
        let plan = plan_split(&cleaned.vertices, &cleaned.triangles, (b.min, b.max), &opts);
        (plan.max_predicted_bytes() <= opts.limit_bytes && plan.parts() >= p).then_some((opts, p))
    };
    let tree_choice = (1..=max_parallel.max(1)).rev().find_map(tree_for);
    let tetgen_start = Instant::now();
    let (mut mesh, report, parallel, cuts, planner, depth): (_, _, _, Vec<(usize, f32)>, _, _) =
        if let Some((opts, p)) = tree_choice {
            spinner.set_message(format!(
                "{}: building a split tree ({} at a time)",
                scene.name, p
            ));
            let options = make_options(p)?;
            let (mesh, report, plan) = build_tree_with_memory_limit(scene, &opts, &options)
                .with_context(|| format!("out-of-core build of `{}` failed", scene.name))?;
            // Planes in preorder (n parts, n - 1 planes), each with its axis.
            let mut cuts = Vec::new();
            let mut stack = vec![&plan.cuts];
            while let Some(node) = stack.pop() {
                if let tet_build::outofcore::tree::CutTree::Split {
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
            (mesh, report, p, cuts, "tree", plan.plan.depth())
        } else {
            let plan_for = |p: usize| {
                let opts = SplitOptions {
                    limit_bytes: limit_bytes / p as u64,
                    ..split
                };
                plan_slabs(&cleaned.vertices, &cleaned.triangles, (b.min, b.max), &opts)
            };
            let Some(base) = plan_for(1) else {
                bail!(
                    "no split of `{}` keeps every part's predicted TetGen peak under {:.1} MiB (an empty part alone is predicted {:.1} MiB, and every part carries its seams and box): raise --memory-limit",
                    scene.name,
                    mib(limit_bytes),
                    mib(split.model.predict(0, 0))
                );
            };
            let base_parts = base.values.len() + 1;
            let (plan, parallel) = (2..=max_parallel.max(1))
                .rev()
                .find_map(|p| {
                    plan_for(p)
                        .filter(|plan| {
                            let parts = plan.values.len() + 1;
                            parts >= p && parts <= 2 * base_parts
                        })
                        .map(|plan| (plan, p))
                })
                .unwrap_or((base, 1));
            let options = make_options(parallel)?;
            spinner.set_message(format!(
                "{}: building {} parts ({} at a time)",
                scene.name,
                plan.values.len() + 1,
                parallel
            ));
            let (mesh, report) = build_slabs(scene, plan.axis, &plan.values, &options)
                .with_context(|| format!("out-of-core build of `{}` failed", scene.name))?;
            let depth = (plan.values.len() + 1).next_power_of_two().trailing_zeros() as usize;
            (
                mesh,
                report,
                parallel,
                plan.values.iter().map(|&v| (plan.axis, v)).collect(),
                "slabs",
                depth,
            )
        };
    let tetgen_s = tetgen_start.elapsed().as_secs_f64();
    let reorder_start = Instant::now();
    if !flags.no_sort {
        spinner.set_message(format!("{}: Hilbert reordering", scene.name));
        tet_core::reorder::hilbert_reorder(&mut mesh)?;
    }
    let reorder_s = reorder_start.elapsed().as_secs_f64();
    spinner.finish_and_clear();
    let total_s = start.elapsed().as_secs_f64();
    let peaks = report.part_peak_kib.clone();
    let max_peak = peaks.iter().flatten().copied().max();
    let summary = BuildSummary {
        switches: format!("{} (per part)", make_options(parallel)?.tetgen.switches()),
        scene_triangles: cleaned.triangles.len(),
        steiner_points: mesh.points.len().saturating_sub(cleaned.vertices.len() + 8),
        clean_s,
        tetgen_s,
        assemble_s: 0.0,
        reorder_s,
        total_s,
        worker_peak_kib: max_peak,
        cleaning: crate::load::CleaningSummary {
            merged_vertices: cm.report.merged_vertices.len(),
            repeated_vertex_triangles: cm.report.repeated_vertex_triangles.len(),
            zero_area_triangles: cm.report.zero_area_triangles.len(),
            duplicate_triangles: cm.report.duplicate_triangles.len(),
            unused_vertices: cm.report.unused_vertices.len(),
        },
    };
    let memory = MemoryReport {
        limit_bytes,
        predicted_in_core_bytes: predicted,
        out_of_core: true,
        parts: report.part_tets.len(),
        parallel_parts: parallel,
        axis: cuts.first().map(|c| c.0),
        planes: cuts.iter().map(|c| c.1).collect(),
        plane_axes: cuts.iter().map(|c| c.0).collect(),
        planner: planner.to_string(),
        depth,
        triangles_cut: report.triangles_cut,
        part_points: report.part_points,
        part_triangles: report.part_triangles,
        part_tets: report.part_tets,
        part_predicted_bytes: report.part_predicted_bytes,
        part_peak_kib: peaks,
        max_part_peak_kib: max_peak,
        total_s,
    };
    Ok((mesh, summary, memory))
}

/// Without TetGen, scenes cannot be built.
#[cfg(not(feature = "tetgen"))]
pub fn build_limited(
    scene: &Scene,
    _: &BuildFlags,
    _: u64,
    _: usize,
    _: bool,
    _: &[glam::Vec3],
) -> Result<(TetMesh, BuildSummary, MemoryReport)> {
    anyhow::bail!(
        "`{}` is a scene, but this tet-bench was built without the `tetgen` feature",
        scene.name
    )
}

/// Prints a memory report.
pub fn print_memory(m: &MemoryReport) {
    let mb = mib;
    if !m.out_of_core {
        println!(
            "  memory: predicted in-core peak {:.1} MiB fits the limit {:.1} MiB: built in core (measured peak {})",
            mb(m.predicted_in_core_bytes),
            mb(m.limit_bytes),
            m.max_part_peak_kib
                .map_or("n/a".into(), |k| format!("{:.1} MiB", k as f64 / 1024.0))
        );
        return;
    }
    println!(
        "  memory: predicted in-core peak {:.1} MiB > limit {:.1} MiB: {} parts along {} ({} at a time), {} scene triangles cut, {:.2} s",
        mb(m.predicted_in_core_bytes),
        mb(m.limit_bytes),
        m.parts,
        ["x", "y", "z"][m.axis.unwrap_or(0).min(2)],
        m.parallel_parts,
        m.triangles_cut,
        m.total_s
    );
    for k in 0..m.parts {
        println!(
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
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn memory_sizes_parse_with_binary_units() {
        assert_eq!(parse_memory_limit("2097152"), Ok(2_097_152));
        assert_eq!(parse_memory_limit("512M"), Ok(512 << 20));
        assert_eq!(parse_memory_limit("512mb"), Ok(512 << 20));
        assert_eq!(parse_memory_limit("1.5G"), Ok(3 << 29));
        assert_eq!(parse_memory_limit("64 KiB"), Ok(64 << 10));
        for bad in ["", "M", "12X", "-5M", "1.2.3G", "0", "0.1"] {
            let e = parse_memory_limit(bad).unwrap_err();
            assert!(e.contains(bad.trim()), "{bad}: {e}");
        }
    }
}
