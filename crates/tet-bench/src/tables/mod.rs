//! `tet-bench tables`: the reproduction of the papers' tables, one module
//! per table, each owning its measurement and its Markdown section:
//!
//! * Aman et al. (2022) Table 1 — construction time per structure
//!   ([`construction`]), render time per method per scene
//!   ([`render_speed`], with the paper's CPU numbers as ratios to the BVH
//!   measured in the same run, since absolute times are machine-bound);
//! * Aman et al. (2022) Table 4 — bytes per layout per scene ([`memory`]);
//! * Lauterbach et al. (2007) Tables 1, 3, 4, 5 — Ray-Strips' bytes,
//!   single-ray and packet speed and construction beside the BVH
//!   ([`strips_vs_bvh`]);
//! * Aman et al. (2022) Table 5 — the Armadillo Zoom camera series, with `--scenes`
//!   ([`zoom`]);
//! * Aman et al. (2022) Figure 8 — Hilbert-sorted vs unsorted mesh, tet20 ([`sorting`]);
//! * entry through the boundary (tight box) vs camera inside (wide box),
//!   tet20 ([`entry`]);
//! * the build trade `-pY` vs `-pYq5`, full mode ([`quality`]);
//! * Aman et al. (2022) Table 3 — GPU methods, with `--features gpu` and an adapter
//!   ([`gpu`]);
//! * Maria et al. (2017) Table 4 — rays with a wrong result per 1024²
//!   rays per method ([`robustness`]);
//! * speed vs accuracy — Mrays/s beside the failure rate per method and
//!   precision, as given and at the extremes ([`speed_accuracy`]);
//! * Maria et al. (2017) Table 5 — exit-face search cost per method ([`exit_face`]);
//! * Wald et al. (2007) Tables 1–4 — isosurfaces of tet volumes:
//!   the implicit min-max BVH (BIH and SAH builds, single rays, 16×16
//!   packets) beside the iso walk over our layouts ([`isosurfaces`]);
//! * Lauterbach et al. (2007) §6 — large models: Ray-Strips, the BVH
//!   and Tet20 on Torus Knots tessellated to 1 M, 10 M and 30 M triangles,
//!   full mode ([`large_models`]);
//! * Erkoç et al. (2021) Tables 2–3 — out of core: build time, parts
//!   and peaks under limits of ½ and ⅓ of the in-core TetGen peak, full
//!   mode ([`out_of_core`]); and a 1 M-triangle closed mesh built under a
//!   sixteenth of its in-core peak, full mode ([`out_of_core_large`]).
//!
//! This module is the driver: it plans the scenes ([`plan`](mod@plan)), measures
//! each table into a [`doc::TablesDoc`], and hands it to the report
//! writers: Markdown, CSV and JSON ([`report`]) and SVG ([`figures`],
//! drawn with [`plots`]).
//!
//! Scenes with the same geometry (the Armadillo Zoom series, Mix / Mix
//! close: same objects, other cameras) are built once, in an enclosing box
//! that holds every camera and light of the group, and the mesh is reused.

mod construction;
mod doc;
mod entry;
mod exit_face;
mod figures;
mod gpu;
mod isosurfaces;
mod large_models;
mod memory;
mod out_of_core;
mod out_of_core_large;
pub mod paper;
mod plan;
mod plots;
mod quality;
mod render_speed;
mod report;
mod robustness;
mod secondary;
mod sorting;
mod speed_accuracy;
mod strips_vs_bvh;
mod variant;
mod zoom;

pub use doc::TABLE_FLAGS;

use std::time::Instant;

use anyhow::{Context, Result};
use tet_trace_cpu::render::RenderOptions;

use crate::cli::TablesArgs;
use crate::methods::cpu_methods;
use crate::methods::method::Method;
use crate::output::{error_chain, outln, print_json};
use crate::timing::{Frames, pool, target_features};
use doc::{QualityTrade, SceneResult, Setup, TablesDoc};
use plan::{MeshCache, Planned, plan, scene_specs};
use report::{markdown, write_atomic, write_outputs};

/// `r`'s value, or `None` with `"label: why"` added to `errors` (and
/// printed) when the measurement failed.
fn optional<T>(errors: &mut Vec<String>, spec: &str, label: &str, r: Result<T>) -> Option<T> {
    match r {
        Ok(v) => Some(v),
        Err(e) => {
            let why = format!("{label}: {}", error_chain(&e));
            eprintln!("  {spec}: {why}");
            errors.push(why);
            None
        }
    }
}

/// Measures every table of one scene.
fn measure_scene(
    planned: &Planned,
    cache: &mut MeshCache,
    args: &TablesArgs,
    opts: &RenderOptions,
    frames: Frames,
    pool: &rayon::ThreadPool,
    streamed_rays: Option<u64>,
) -> Result<SceneResult> {
    let spec = planned.spec.as_str();
    let (loaded, mesh_reused) = cache.load(planned, &TABLE_FLAGS, false)?;
    if mesh_reused {
        eprintln!(
            "  {spec}: mesh shared with {}",
            planned.shares_with.join(", ")
        );
    }
    let (info, bvh_build_s) = construction::measure(&loaded)?;
    let renders = render_speed::measure(spec, &loaded, opts, frames, pool)?;
    let ray_strips = Some(strips_vs_bvh::measure(spec, &loaded, opts, frames, pool)?);
    // Secondary rays: every scene in the full run; in the quick one, one
    // scene per mesh (not the scenes sharing an earlier scene's mesh).
    let secondary = if args.quick && !planned.first {
        Vec::new()
    } else {
        secondary::measure(spec, &loaded, opts, frames, pool)?
    };
    let accuracy = robustness::measure(
        spec,
        &loaded,
        &cpu_methods(),
        args.quick,
        args.min_time_s(),
        streamed_rays,
    )?;
    // Measurements on meshes of their own (unsorted, wide box, refined
    // builds): one that fails leaves its row empty and says why in
    // `partial_errors`, not the whole scene.
    let mut partial_errors = Vec::new();
    let (sorted_tet20, unsorted_tet20, sorting_round_speedups) = optional(
        &mut partial_errors,
        spec,
        "unsorted mesh",
        sorting::measure(planned, &loaded, cache, opts, frames, pool),
    )
    .map_or((None, None, Vec::new()), |p| {
        (Some(p.baseline), Some(p.variant), p.round_speedups)
    });
    let (tight_box_tet20, wide_box_tet20, tight_box_round_speedups) = optional(
        &mut partial_errors,
        spec,
        "wide-box mesh",
        entry::measure(planned, &loaded, cache, opts, frames, pool),
    )
    .map_or((None, None, Vec::new()), |p| {
        (Some(p.baseline), Some(p.variant), p.round_speedups)
    });
    let (gpu_renders, gpu_note) = gpu::measure(&loaded, opts, frames.at_least);
    let (quality5, min_dihedral2, min_dihedral2_capped, one_piece) = if args.quick {
        (None, None, None, None)
    } else {
        let mut trade = |flags, label: &str| {
            let r = quality::measure(planned, cache, opts, frames, pool, flags, label);
            optional(&mut partial_errors, spec, label, r)
        };
        (
            trade(&quality::QUALITY5, "quality-refined (-q5)"),
            trade(
                &quality::MIN_DIHEDRAL2,
                "slivers-bounded (--min-dihedral 2)",
            ),
            trade(
                &quality::CAPPED,
                "slivers-bounded, capped (--max-steiner 1%)",
            ),
            trade(&quality::ONE_PIECE, "one piece (--walls none)"),
        )
    };
    #[cfg(feature = "tetgen")]
    let out_of_core = if args.quick || !planned.first {
        Vec::new()
    } else {
        out_of_core::measure(spec, &loaded, opts, frames, pool)
    };
    // Out-of-core builds run TetGen.
    #[cfg(not(feature = "tetgen"))]
    let out_of_core = Vec::new();
    Ok(SceneResult {
        ray_strips,
        quality5,
        min_dihedral2,
        min_dihedral2_capped,
        // The default mesh is the walled one: its row is the render table's.
        walls: one_piece.as_ref().and_then(|_| {
            let tet20 = renders.iter().find(|r| r.method == Method::Tet20)?;
            Some(QualityTrade {
                tets: info.tets,
                build: info.build.clone(),
                tet20: tet20.clone(),
            })
        }),
        one_piece,
        out_of_core,
        shares_mesh_with: planned.shares_with.clone(),
        mesh_reused,
        gpu_renders,
        gpu_note,
        spec: spec.into(),
        info: Some(info),
        bvh_build_s: Some(bvh_build_s),
        renders,
        secondary,
        unsorted_tet20,
        sorted_tet20,
        wide_box_tet20,
        tight_box_tet20,
        sorting_round_speedups,
        tight_box_round_speedups,
        accuracy: Some(accuracy),
        partial_errors,
        error: None,
    })
}

/// `tet-bench tables`.
pub fn run(args: &TablesArgs, json: bool) -> Result<()> {
    let start = Instant::now();
    let pool = pool(args.threads)?;
    let (width, height, frames) = if args.quick {
        (640, 480, 3)
    } else {
        (1920, 1440, 5)
    };
    let width = args.width.unwrap_or(width).max(1);
    let height = args.height.unwrap_or(height).max(1);
    let frames = Frames {
        at_least: args.frames.unwrap_or(frames).max(1),
        min_s: args.min_time_s(),
    };
    let opts = RenderOptions {
        width,
        height,
        ..RenderOptions::default()
    };
    let setup = Setup {
        cpus: std::thread::available_parallelism().map_or(1, |n| n.get()),
        threads: pool.current_num_threads(),
        width,
        height,
        frames: frames.at_least,
        min_time_s: frames.min_s,
        target_features: target_features(),
        quick: args.quick,
        platform: format!("{}-{}", std::env::consts::OS, std::env::consts::ARCH),
    };
    let mut scenes = Vec::new();
    let mut cache = MeshCache::default();
    for (index, planned) in plan(&scene_specs(args)?).into_iter().enumerate() {
        let spec = planned.spec.clone();
        eprintln!("scene {spec}");
        // The robustness table's 10⁸ rays: on the first scene and on the
        // flat-faced scene (rays in the planes of its flat faces).
        let streamed = args
            .streamed_robustness_rays()
            .filter(|_| index == 0 || spec == plan::FLAT_SCENE);
        let result = measure_scene(&planned, &mut cache, args, &opts, frames, &pool, streamed);
        if planned.last
            && let Some(key) = planned.key
        {
            cache.evict(key);
        }
        scenes.push(match result {
            Ok(r) => r,
            Err(e) => {
                eprintln!("  {spec}: {}", error_chain(&e));
                SceneResult {
                    ray_strips: None,
                    spec: spec.clone(),
                    info: None,
                    bvh_build_s: None,
                    renders: Vec::new(),
                    secondary: Vec::new(),
                    unsorted_tet20: None,
                    sorted_tet20: None,
                    wide_box_tet20: None,
                    tight_box_tet20: None,
                    sorting_round_speedups: Vec::new(),
                    tight_box_round_speedups: Vec::new(),
                    accuracy: None,
                    gpu_renders: Vec::new(),
                    gpu_note: None,
                    quality5: None,
                    min_dihedral2: None,
                    min_dihedral2_capped: None,
                    walls: None,
                    one_piece: None,
                    out_of_core: Vec::new(),
                    shares_mesh_with: planned.shares_with.clone(),
                    mesh_reused: false,
                    partial_errors: Vec::new(),
                    error: Some(error_chain(&e)),
                }
            }
        });
    }
    let exit_face = Some(exit_face::measure(args.quick)?);
    // `--quick` checks precision and the extremes on the single torus knot
    // (each extreme case is rebuilt from triangles: seconds, not minutes).
    let first = scene_specs(args)?.first().cloned();
    let speed_accuracy = first
        .map(|spec| {
            if args.quick {
                "torus-knot".to_string()
            } else {
                spec
            }
        })
        .map(|spec| {
            eprintln!("speed vs accuracy: {spec}, f32 and f64, as given and at the extremes");
            speed_accuracy::measure(&spec, args.quick, args.min_time_s())
        });
    let isosurfaces = isosurfaces::measure_all(args.quick, &pool);
    let iso_scaling = isosurfaces::measure_scaling(args.quick, &pool);
    let large_sizes = args.large_model_sizes();
    let large_models =
        large_models::measure_all(&large_sizes, args.large_models_limit, &opts, frames, &pool);
    let large_ooc_sizes = args.large_out_of_core_sizes();
    let large_out_of_core = out_of_core_large::measure_all(&large_ooc_sizes, &opts, frames, &pool);
    let mut doc = TablesDoc {
        setup,
        scenes,
        exit_face,
        speed_accuracy,
        isosurfaces,
        iso_scaling,
        out_of_core_note: args.quick.then(|| {
            "skipped in --quick mode: each scene is built twice more, in parts (run without --quick)"
                .to_string()
        }),
        large_models,
        large_models_note: large_sizes.is_empty().then(|| {
            "skipped: no sizes (`--large-models 1m,10m,30m`; the default without --quick)".to_string()
        }),
        large_out_of_core_note: large_ooc_sizes.is_empty().then(|| {
            "skipped: no sizes (`--large-out-of-core 1m`; the default without --quick)".to_string()
        }),
        large_out_of_core,
        figures: Vec::new(),
        total_s: 0.0,
    };
    let plots_dir = args.plots.clone().unwrap_or_else(|| args.out.clone());
    std::fs::create_dir_all(&plots_dir)
        .with_context(|| format!("cannot create {}", plots_dir.display()))?;
    for (name, svg) in figures::figures(&doc)? {
        let path = plots_dir.join(name);
        write_atomic(&path, svg.as_bytes())?;
        doc.figures.push(path.display().to_string());
    }
    doc.total_s = start.elapsed().as_secs_f64();
    let markdown = markdown(&doc);
    write_outputs(&args.out, &doc, &markdown)?;
    if json {
        print_json(&doc)?;
    } else {
        outln!("{markdown}")?;
        eprintln!(
            "wrote {}/tables.{{md,csv,json}} and {} figures in {}",
            args.out.display(),
            doc.figures.len(),
            plots_dir.display()
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A failed optional measurement leaves its row empty and names what
    /// failed and why; a good one passes its value through untouched.
    #[test]
    fn a_failed_optional_measurement_is_recorded_not_raised() {
        let mut errors = Vec::new();
        let failed: Result<u32> =
            Err(anyhow::anyhow!("2 tets flat").context("cannot build `Neptune`"));
        assert_eq!(optional(&mut errors, "s", "wide-box mesh", failed), None);
        assert_eq!(
            optional(&mut errors, "s", "unsorted mesh", Ok(7u32)),
            Some(7)
        );
        assert_eq!(errors.len(), 1);
        assert!(errors[0].starts_with("wide-box mesh: "), "{}", errors[0]);
        assert!(
            errors[0].contains("cannot build `Neptune`") && errors[0].contains("2 tets flat"),
            "{}",
            errors[0]
        );
    }
}
