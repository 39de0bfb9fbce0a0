//! `tet-bench iso`: one volume, one method, timed frames, the image on
//! request.

use anyhow::{Result, bail};
use tet_trace_cpu::render::{Frame, FrameStats};

use tet_trace_cpu::iso::{ClipBox, ClipMode};

use crate::cli::{IsoArgs, IsoClipMode};
use crate::iso::{IsoFrames, IsoLight, IsoView, load_iso_volume_with, measure, shade};
use crate::load::camera::apply_view;
use crate::output::{outln, print_json};
use crate::timing::pool;

/// `tet-bench iso`.
pub fn run(args: &IsoArgs, json: bool) -> Result<()> {
    let options = tet_build::volume::VolumeOptions {
        replications: args.replications,
        ..Default::default()
    };
    let volume = load_iso_volume_with(&args.volume, &options)?;
    let isovalues = if args.isovalues.is_empty() {
        vec![volume.default_isovalue]
    } else {
        args.isovalues.clone()
    };
    if args.width == 0 || args.height == 0 {
        bail!("the image needs a width and a height of at least 1");
    }
    let pool = pool(args.threads)?;
    let mut view = IsoView::of(&volume.mesh);
    view.camera = apply_view(view.camera, &args.view)?;
    view.clip = args.clip.map(|(lo, hi)| ClipBox {
        lo,
        hi,
        mode: match args.clip_mode {
            IsoClipMode::Keep => ClipMode::KeepInside,
            IsoClipMode::Cut => ClipMode::CutAway,
        },
    });
    if (args.light.is_some() || args.light_dir.is_some()) && !args.shadows {
        bail!("--light and --light-dir place the light of --shadows: add --shadows");
    }
    if args.shadows {
        view.light = Some(match (args.light, args.light_dir) {
            (_, Some(d)) if d.length_squared() == 0.0 || !d.is_finite() => {
                bail!("--light-dir needs a non-zero direction")
            }
            (_, Some(d)) => IsoLight::Directional(d),
            (Some(p), None) => IsoLight::Point(p),
            (None, None) => IsoLight::Point(view.camera.position),
        });
    }
    let frames = IsoFrames {
        width: args.width,
        height: args.height,
        frames: args.frames,
        time_step: args.time_step,
        view,
        regions: !args.no_regions,
    };
    let (doc, image) = measure(&volume, &isovalues, args.method, frames, &pool)?;
    if let Some(path) = &args.output {
        let frame = Frame {
            width: args.width,
            height: args.height,
            color: shade(&image, &view.camera, args.width, args.height),
            tets: vec![0; image.len()],
            triangle: vec![u32::MAX; image.len()],
            stats: FrameStats::default(),
        };
        frame.save_png(path)?;
    }
    if json {
        print_json(&doc)?;
    } else {
        outln!(
            "{} {} (step {} of {}, isovalues {:?}) {} tets, {}x{} {} threads: build {:.1} ms, best {:.1} ms ({:.1} fps), median {:.1} ms, {:.2} Mrays/s, {} hits, {} of {} shadow rays blocked, {} failures, {:.2} MB",
            doc.volume,
            doc.method.name(),
            doc.time_step,
            doc.steps,
            doc.isovalues,
            doc.tets,
            doc.width,
            doc.height,
            doc.threads,
            doc.build_ms,
            doc.best_ms,
            doc.fps,
            doc.median_ms,
            doc.mrays_per_s,
            doc.hits,
            doc.shadowed,
            doc.shadow_rays,
            doc.failures,
            doc.bytes as f64 / 1e6
        )?;
        let c = &doc.per_ray;
        outln!(
            "  per ray: {:.1} nodes, {:.1} box tests, {:.1} range tests, {:.2} isopolygons, {:.2} isopolygon tests, {:.2} interval culls",
            c.nodes_visited,
            c.box_tests,
            c.range_tests,
            c.isopolygons,
            c.isopolygon_tests,
            c.frustum_culls
        )?;
        outln!(
            "  vs single ibvh rays ({} hits): {} pixels hit by one only, {} at another crossing",
            doc.ibvh_hits,
            doc.hit_mismatches,
            doc.crossing_mismatches
        )?;
    }
    Ok(())
}
