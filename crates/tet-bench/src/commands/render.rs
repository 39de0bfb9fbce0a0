//! `tet-bench render`: frames with one method, best and median timings,
//! and the image or heat map on request.

use anyhow::{Result, bail};
use tet_trace_cpu::render::RenderOptions;

use crate::cli::RenderArgs;
use crate::load::{load, require_tets};
use crate::output::{outln, print_json};
use crate::timing::gpu::time_gpu;
use crate::timing::ray_kinds::{KindDoc, RayKinds};
use crate::timing::{pool, time_method};

/// `tet-bench render`.
pub fn run(args: &RenderArgs, json: bool) -> Result<()> {
    let mut loaded = load(&args.scene, &args.build, json)?;
    loaded.set_view(&args.view)?;
    require_tets(&loaded)?;
    let kinds = args.rays.with_shadows(args.shadows);
    let opts = RenderOptions {
        width: args.width,
        height: args.height,
        shadows: kinds.shadows(),
        ambient_occlusion: kinds.ao(),
        ..RenderOptions::default()
    };
    let doc = if args.method.is_gpu() {
        if args.output.is_some() || args.heatmap.is_some() || kinds != RayKinds::Primary {
            bail!(
                "GPU methods report timings of primary rays only: use a CPU method for images and secondary rays"
            );
        }
        time_gpu(&loaded, args.method, args.width, args.height, args.frames)?
    } else {
        let pool = pool(args.threads)?;
        let (doc, frame) = time_method(&loaded, args.method, &opts, args.frames, &pool)?;
        if let Some(path) = &args.output {
            frame.save_png(path)?;
        }
        if let Some(path) = &args.heatmap {
            frame.save_heatmap(path, None)?;
        }
        doc
    };
    if json {
        print_json(&doc)?;
    } else {
        let visited = match doc.nodes_per_ray {
            Some(n) => format!("{n:.1} BVH nodes/ray"),
            None => format!("{:.1} tets/ray", doc.tets_per_ray),
        };
        outln!(
            "{} {} ({}) {}x{} {} threads: best {:.1} ms, median {:.1} ms, {:.2} Mrays/s, {visited}, {} hits, {} failures",
            doc.scene,
            doc.method.name(),
            doc.tracer,
            doc.width,
            doc.height,
            doc.threads,
            doc.best_ms,
            doc.median_ms,
            doc.mrays_per_s,
            doc.hits,
            doc.failures
        )?;
        if doc.rays_kind != RayKinds::Primary {
            let k = &doc.by_kind;
            let line = |name: &str, kind: &KindDoc| {
                let tets = kind
                    .tets_per_ray
                    .map_or(String::new(), |t| format!(", {t:.1} tets/ray"));
                format!(
                    "{name} {} rays {:.2} Mrays/s{tets}",
                    kind.rays, kind.mrays_per_s
                )
            };
            outln!(
                "  by kind (fastest frame, tracing time only): {}; {}; {}",
                line("primary", &k.primary),
                line("ao", &k.ao),
                line("shadow", &k.shadow)
            )?;
        }
    }
    Ok(())
}
