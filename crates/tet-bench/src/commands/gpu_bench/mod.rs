//! `tet-bench gpu-bench OUT_DIR`: the GPU measurement in one command, for
//! a GPU machine that is lent for minutes and has no package access (the
//! binary and prebuilt meshes are carried to it; see
//! `scripts/gpu/headless-nvidia.sh`).
//!
//! For each scene ([`scenes`]: the five of Aman et al. (2022) Table 3 by
//! default, meshes from `--meshes DIR`, built or skipped), the driver
//! measures ([`measure`]) the four GPU walks on the camera rays, the
//! secondary rays the CPU gives ([`rays`]) and the GPU BVH ([`bvh`]) on
//! the same camera rays, checks every outcome against the CPU walk
//! ([`compare`]), and writes `gpu.json` ([`doc`]) and `gpu.md`
//! ([`markdown`]) after every scene, each file whole ([`files`]), so a run
//! cut short keeps what it measured.
//!
//! `--adapter-only` prints the adapter and fails on a software one;
//! `--prepare-meshes` builds the meshes to carry (no GPU needed).

#[cfg(feature = "gpu")]
mod bvh;
#[cfg_attr(not(feature = "gpu"), allow(dead_code))]
mod compare;
#[cfg_attr(not(feature = "gpu"), allow(dead_code))]
mod doc;
mod files;
#[cfg_attr(not(feature = "gpu"), allow(dead_code))]
mod markdown;
#[cfg(feature = "gpu")]
mod measure;
#[cfg_attr(not(feature = "gpu"), allow(dead_code))]
mod rays;
#[cfg(feature = "gpu")]
mod runs;
mod scenes;

use anyhow::Result;

use crate::cli::GpuBenchArgs;

/// `tet-bench gpu-bench`.
pub fn run(args: &GpuBenchArgs, json: bool) -> Result<()> {
    if args.prepare_meshes {
        return scenes::prepare(args, json);
    }
    measure_all(args, json)
}

/// Without the `gpu` feature there is nothing to measure with.
#[cfg(not(feature = "gpu"))]
fn measure_all(_: &GpuBenchArgs, _: bool) -> Result<()> {
    anyhow::bail!(
        "gpu-bench needs the GPU methods: rebuild with \
         `cargo build --release -p tet-bench --features gpu` \
         (`--prepare-meshes` works without them)"
    )
}

/// The adapter check, or the whole run.
#[cfg(feature = "gpu")]
fn measure_all(args: &GpuBenchArgs, json: bool) -> Result<()> {
    use std::time::Instant;

    use anyhow::{Context, bail};
    use tet_trace_gpu::GpuContext;

    use crate::output::{error_chain, outln, print_json};
    use crate::tables::paper::paper_scene;
    use doc::{GpuBenchDoc, SceneDoc, SetupDoc};
    use measure::Plan;

    let start = Instant::now();
    let ctx = GpuContext::new().context(
        "no Vulkan adapter: install a driver (on a headless NVIDIA machine: \
         scripts/gpu/headless-nvidia.sh)",
    )?;
    let adapter = measure::adapter(&ctx);
    let line = format!(
        "adapter: {} (device type {}, backend {}, driver {}, timestamps {})",
        adapter.name,
        adapter.device_type,
        adapter.backend,
        adapter.driver,
        if adapter.timestamps { "yes" } else { "no" }
    );
    if args.adapter_only {
        if json {
            print_json(&adapter)?;
        } else {
            outln!("{line}")?;
        }
        if adapter.software && !args.allow_software {
            bail!(
                "`{}` is a software adapter ({}): no GPU driver was found \
                 (see scripts/gpu/headless-nvidia.sh; --allow-software accepts it)",
                adapter.name,
                adapter.device_type
            );
        }
        return Ok(());
    }
    eprintln!("{line}");
    let (width, height, frames, repeats) = if args.quick {
        (160, 120, 3, 1)
    } else {
        (1920, 1440, 20, 3)
    };
    let plan = Plan {
        width: args.width.unwrap_or(width).max(1),
        height: args.height.unwrap_or(height).max(1),
        frames: args.frames.unwrap_or(frames).max(1),
        secondary_repeats: repeats,
    };
    let out = &args.out_dir;
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let flags = scenes::build_flags(args.tight_box);
    let mut doc = GpuBenchDoc {
        schema: doc::SCHEMA,
        version: doc::VERSION,
        adapter,
        setup: SetupDoc {
            quick: args.quick,
            width: plan.width,
            height: plan.height,
            frames: plan.frames,
            secondary_repeats: plan.secondary_repeats,
            meshes_dir: args.meshes.as_ref().map(|d| d.display().to_string()),
            enclosing_box: if args.tight_box { "tight" } else { "wide" },
            cpu_threads: rayon::current_num_threads(),
        },
        scenes: Vec::new(),
        table3: Vec::new(),
        bvh: Vec::new(),
        secondary: Vec::new(),
        bvh_note: None,
        total_s: 0.0,
    };
    let mut bvh_errors = Vec::new();
    for spec in scenes::scene_specs(args) {
        eprintln!("scene {spec}");
        let scene_start = Instant::now();
        let name = paper_scene(&spec).map_or(spec.clone(), |p| p.name.to_string());
        let mut scene = SceneDoc {
            scene: name,
            spec: spec.clone(),
            mesh: None,
            camera_inside: None,
            skipped: None,
            total_s: 0.0,
        };
        match scenes::resolve(&spec, args.meshes.as_deref(), &flags) {
            Err(e) => scene.skipped = Some(error_chain(&e)),
            Ok((loaded, mesh)) => {
                scene.scene = loaded.name.clone();
                scene.mesh = Some(mesh);
                match measure::measure_scene(&ctx, &loaded, &spec, &plan) {
                    Err(e) => {
                        scene.skipped = Some(format!("measurement failed: {}", error_chain(&e)))
                    }
                    Ok(rows) => {
                        scene.camera_inside = Some(rows.camera_inside);
                        doc.table3.extend(rows.table3);
                        doc.secondary.extend(rows.secondary);
                        match rows.bvh {
                            Ok(row) => doc.bvh.push(row),
                            Err(e) => bvh_errors.push(format!("{}: {e}", loaded.name)),
                        }
                    }
                }
            }
        }
        scene.total_s = scene_start.elapsed().as_secs_f64();
        if let Some(why) = &scene.skipped {
            eprintln!("  skipped: {why}");
        }
        doc.scenes.push(scene);
        doc.bvh_note = (!bvh_errors.is_empty())
            .then(|| format!("GPU BVH not measured on {}", bvh_errors.join("; ")));
        doc.total_s = start.elapsed().as_secs_f64();
        write_outputs(out, &doc)?;
    }
    if json {
        print_json(&doc)
    } else {
        outln!("{}", markdown::markdown(&doc))?;
        outln!(
            "wrote {} and {}",
            out.join("gpu.json").display(),
            out.join("gpu.md").display()
        )
    }
}

/// Writes `gpu.json` and `gpu.md` into `out`, each whole.
#[cfg(feature = "gpu")]
fn write_outputs(out: &std::path::Path, doc: &doc::GpuBenchDoc) -> Result<()> {
    files::write_atomic(
        &out.join("gpu.json"),
        serde_json::to_string_pretty(doc)?.as_bytes(),
    )?;
    files::write_atomic(&out.join("gpu.md"), markdown::markdown(doc).as_bytes())
}
