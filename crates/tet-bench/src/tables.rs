//! `tet-bench tables`: the reproduction of the papers' tables.
//!
//! * seed 000 Table 1 — construction time per structure, render time per
//!   method per scene (with the paper's CPU numbers as ratios to the BVH
//!   measured in the same run, since absolute times are machine-bound);
//! * seed 000 Table 4 — bytes per layout per scene;
//! * seed 000 Table 5 — the Armadillo Zoom camera series (with `--scenes`);
//! * seed 000 Figure 8 — Hilbert-sorted vs unsorted mesh, tet20;
//! * seed 000 Table 3 — GPU methods (with `--features gpu` and an adapter);
//! * seed 001 Table 4 — rays with a wrong result per 1024² rays per method;
//! * speed vs accuracy — Mrays/s beside the failure rate per method.

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result};
use serde::Serialize;
use tet_trace_cpu::render::RenderOptions;

use crate::accuracy::{CaseAccuracy, run_case};
use crate::cli::{BuildFlags, Method, Precision, TablesArgs};
use crate::info::{Info, info};
use crate::load::{Loaded, load};
use crate::render::{RenderDoc, pool, target_features, time_method};

/// neptun (the authors' C++ code) on a 2-core machine, Torus Knots,
/// 1920×1440 primary rays, 2 threads, Mrays/s (issue 4 of this project).
const NEPTUN_TORUS_KNOTS_MRAYS: [(Method, f64); 6] = [
    (Method::Tet20, 5.23),
    (Method::Tet16, 4.84),
    (Method::Tet32, 2.31),
    (Method::Tet80, 1.65),
    (Method::Sctp, 2.79),
    (Method::Obvhs, 4.92),
];

/// Seed 000 Table 4, Torus Knots, MB per layout (their Tet80 column is the
/// tet records only, so it compares with our hot bytes).
const PAPER_TABLE4_TORUS_KNOTS_MB: [(&str, f64); 4] = [
    ("tet32", 12.3),
    ("tet20", 9.2),
    ("tet16", 8.2),
    ("tet80", 20.6),
];

/// Methods rendered, in table order.
const METHODS: [Method; 6] = [
    Method::Tet20,
    Method::Tet16,
    Method::Tet32,
    Method::Tet80,
    Method::Sctp,
    Method::Obvhs,
];

/// The machine and settings every table states.
#[derive(Clone, Debug, Serialize)]
pub struct Setup {
    /// Logical CPUs.
    pub cpus: usize,
    /// Worker threads used.
    pub threads: usize,
    /// Image size.
    pub width: u32,
    /// Image size.
    pub height: u32,
    /// Timed frames per method (best is reported).
    pub frames: u32,
    /// Compile-time CPU features (`target-cpu=native` shows here).
    pub target_features: Vec<&'static str>,
    /// `--quick`.
    pub quick: bool,
    /// OS and architecture.
    pub platform: String,
}

/// Everything measured on one scene.
#[derive(Clone, Debug, Serialize)]
pub struct SceneResult {
    /// Scene spec as given.
    pub spec: String,
    /// Info (counts, bytes per layout, build report).
    pub info: Option<Info>,
    /// BVH build time, s.
    pub bvh_build_s: Option<f64>,
    /// One row per method.
    pub renders: Vec<RenderDoc>,
    /// tet20 on the unsorted (TetGen order) mesh, for Figure 8.
    pub unsorted_tet20: Option<RenderDoc>,
    /// Accuracy against the f64 reference.
    pub accuracy: Option<CaseAccuracy>,
    /// GPU methods (seed 000 Table 3), when built with `--features gpu` and
    /// an adapter is present.
    pub gpu_renders: Vec<RenderDoc>,
    /// Why there are no GPU rows, if there are none.
    pub gpu_note: Option<String>,
    /// The build trade (full mode only): the same scene built with the
    /// quality bound `-q5`, and tet20 on it.
    pub quality5: Option<QualityTrade>,
    /// Why the scene failed, if it did.
    pub error: Option<String>,
}

/// A quality-refined build and its traversal speed.
#[derive(Clone, Debug, Serialize)]
pub struct QualityTrade {
    /// Tets.
    pub tets: usize,
    /// Construction report.
    pub build: Option<crate::load::BuildSummary>,
    /// tet20 on the refined mesh.
    pub tet20: RenderDoc,
}

/// The `tables` document (also written as `tables.json`).
#[derive(Clone, Debug, Serialize)]
pub struct TablesDoc {
    /// Machine and settings.
    pub setup: Setup,
    /// Per scene.
    pub scenes: Vec<SceneResult>,
    /// Wall time of the whole run, s.
    pub total_s: f64,
}

fn scene_specs(args: &TablesArgs) -> Result<Vec<String>> {
    match &args.scenes {
        None => Ok(vec!["torus-knots".into(), "torus-knots-box".into()]),
        Some(path) => {
            let file = tet_build::scene::scenes_json::ScenesFile::open(path)?;
            Ok(file
                .scene_names()?
                .into_iter()
                .map(|n| format!("{}#{n}", path.display()))
                .collect())
        }
    }
}

fn measure_scene(
    spec: &str,
    args: &TablesArgs,
    opts: &RenderOptions,
    frames: u32,
    pool: &rayon::ThreadPool,
) -> Result<SceneResult> {
    let flags = BuildFlags {
        quality: None,
        max_steiner: None,
        time_limit: 600.0,
        no_box: false,
        no_sort: false,
    };
    let quiet = false;
    let loaded: Loaded = load(spec, &flags, quiet)?;
    let info = info(&loaded, false)?;
    let bvh_start = Instant::now();
    drop(crate::bvh::BvhTracer::new(&loaded.mesh));
    let bvh_build_s = bvh_start.elapsed().as_secs_f64();
    let mut renders = Vec::new();
    for m in METHODS {
        eprintln!("  {spec}: rendering with {}", m.name());
        renders.push(time_method(&loaded, m, opts, frames, pool)?.0);
    }
    let (side, rays) = if args.quick {
        (256, 20_000)
    } else {
        (1024, 100_000)
    };
    eprintln!("  {spec}: accuracy ({side}² camera rays + {rays} random rays)");
    let accuracy = run_case("as-is", &loaded, &METHODS, Precision::F32, side, rays, 1)?;
    eprintln!("  {spec}: unsorted mesh for Figure 8");
    let unsorted = load(
        spec,
        &BuildFlags {
            no_sort: true,
            ..flags
        },
        quiet,
    )?;
    let unsorted_tet20 = Some(time_method(&unsorted, Method::Tet20, opts, frames, pool)?.0);
    let (gpu_renders, gpu_note) = gpu_rows(&loaded, opts, frames);
    let quality5 = if args.quick {
        None
    } else {
        eprintln!("  {spec}: quality-refined build (-q5)");
        let refined = load(
            spec,
            &BuildFlags {
                quality: Some(5.0),
                max_steiner: Some(2_000_000),
                ..flags
            },
            quiet,
        )?;
        Some(QualityTrade {
            tets: refined.mesh.tets.len(),
            build: refined.build.clone(),
            tet20: time_method(&refined, Method::Tet20, opts, frames, pool)?.0,
        })
    };
    Ok(SceneResult {
        quality5,
        gpu_renders,
        gpu_note,
        spec: spec.into(),
        info: Some(info),
        bvh_build_s: Some(bvh_build_s),
        renders,
        unsorted_tet20,
        accuracy: Some(accuracy),
        error: None,
    })
}

/// The GPU methods' rows, or why there are none.
fn gpu_rows(
    loaded: &Loaded,
    opts: &RenderOptions,
    frames: u32,
) -> (Vec<RenderDoc>, Option<String>) {
    if !cfg!(feature = "gpu") {
        return (Vec::new(), Some("built without the `gpu` feature".into()));
    }
    let mut rows = Vec::new();
    for m in [
        Method::GpuTet20,
        Method::GpuTet16,
        Method::GpuTet32,
        Method::GpuTet80,
    ] {
        eprintln!("  {}: rendering with {}", loaded.name, m.name());
        match crate::gpu::time_gpu(loaded, m, opts.width, opts.height, frames) {
            Ok(doc) => rows.push(doc),
            Err(e) => return (rows, Some(crate::error_chain(&e))),
        }
    }
    (rows, None)
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
        frames,
        target_features: target_features(),
        quick: args.quick,
        platform: format!("{}-{}", std::env::consts::OS, std::env::consts::ARCH),
    };
    let mut scenes = Vec::new();
    for spec in scene_specs(args)? {
        eprintln!("scene {spec}");
        scenes.push(match measure_scene(&spec, args, &opts, frames, &pool) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("  {spec}: {}", crate::error_chain(&e));
                SceneResult {
                    spec: spec.clone(),
                    info: None,
                    bvh_build_s: None,
                    renders: Vec::new(),
                    unsorted_tet20: None,
                    accuracy: None,
                    gpu_renders: Vec::new(),
                    gpu_note: None,
                    quality5: None,
                    error: Some(crate::error_chain(&e)),
                }
            }
        });
    }
    let doc = TablesDoc {
        setup,
        scenes,
        total_s: start.elapsed().as_secs_f64(),
    };
    let markdown = markdown(&doc);
    write_outputs(&args.out, &doc, &markdown)?;
    if json {
        println!("{}", serde_json::to_string_pretty(&doc)?);
    } else {
        println!("{markdown}");
        eprintln!("wrote {}/tables.{{md,csv,json}}", args.out.display());
    }
    Ok(())
}

fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let tmp = path.with_extension("tmp");
    std::fs::write(&tmp, bytes).with_context(|| format!("cannot write {}", tmp.display()))?;
    std::fs::rename(&tmp, path).with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}

fn write_outputs(dir: &Path, doc: &TablesDoc, markdown: &str) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    write_atomic(&dir.join("tables.md"), markdown.as_bytes())?;
    write_atomic(
        &dir.join("tables.json"),
        serde_json::to_string_pretty(doc)?.as_bytes(),
    )?;
    write_atomic(&dir.join("tables.csv"), csv(doc).as_bytes())?;
    Ok(())
}

/// One CSV row per (scene, method): render and accuracy columns.
fn csv(doc: &TablesDoc) -> String {
    let mut s = String::from(
        "scene,method,tracer,width,height,threads,best_ms,median_ms,mrays_per_s,tets_per_ray,hot_bytes,setup_s,failures_per_1024_squared\n",
    );
    for sc in &doc.scenes {
        for r in &sc.renders {
            let fails = sc
                .accuracy
                .as_ref()
                .and_then(|a| a.methods.iter().find(|m| m.method == r.tracer))
                .map_or(String::new(), |m| {
                    format!("{:.3}", m.failures_per_1024_squared)
                });
            let _ = writeln!(
                s,
                "{},{},{},{},{},{},{:.3},{:.3},{:.4},{:.2},{},{:.4},{}",
                r.scene,
                r.method.name(),
                r.tracer,
                r.width,
                r.height,
                r.threads,
                r.best_ms,
                r.median_ms,
                r.mrays_per_s,
                r.tets_per_ray,
                r.hot_bytes,
                r.setup_s,
                fails
            );
        }
    }
    s
}

fn mb(b: usize) -> String {
    format!("{:.2}", b as f64 / 1e6)
}

/// The Markdown report.
pub fn markdown(doc: &TablesDoc) -> String {
    let s = &doc.setup;
    let mut m = String::new();
    let _ = writeln!(m, "# Reproduction tables\n");
    let _ = writeln!(
        m,
        "Machine: {} logical CPUs, {} worker threads, {}; images {}×{}, best of {} frames; compile-time features: {}; {} mode; total {:.0} s.\n",
        s.cpus,
        s.threads,
        s.platform,
        s.width,
        s.height,
        s.frames,
        if s.target_features.is_empty() {
            "baseline (no target-cpu=native)".to_string()
        } else {
            s.target_features.join(", ")
        },
        if s.quick { "quick" } else { "full" },
        doc.total_s
    );
    for sc in doc.scenes.iter().filter(|sc| sc.error.is_some()) {
        let _ = writeln!(
            m,
            "* `{}` failed: {}",
            sc.spec,
            sc.error.as_deref().unwrap_or("")
        );
    }

    let _ = writeln!(m, "\n## Construction (seed 000 Table 1, left half)\n");
    let _ = writeln!(
        m,
        "| scene | triangles | points | tets | TetGen s | total build s | BVH build s | regions |"
    );
    let _ = writeln!(m, "|---|---:|---:|---:|---:|---:|---:|---:|");
    for sc in &doc.scenes {
        if let Some(i) = &sc.info {
            let (tg, tot) = i
                .build
                .as_ref()
                .map_or((f64::NAN, f64::NAN), |b| (b.tetgen_s, b.total_s));
            let _ = writeln!(
                m,
                "| {} | {} | {} | {} | {:.2} | {:.2} | {:.3} | {} |",
                i.name,
                i.triangles,
                i.points,
                i.tets,
                tg,
                tot,
                sc.bvh_build_s.unwrap_or(f64::NAN),
                i.regions.count
            );
        }
    }

    let _ = writeln!(
        m,
        "\n## Render time per method (seed 000 Table 1, right half)\n"
    );
    let _ = writeln!(
        m,
        "Ratio = method Mrays/s ÷ BVH (obvhs) Mrays/s in the same run. Paper ratio: neptun's CPU numbers on Torus Knots (1920×1440, 2 threads) ÷ its BVH (4.92 Mrays/s).\n"
    );
    let _ = writeln!(
        m,
        "| scene | method | best ms | median ms | Mrays/s | tets/ray | ratio to BVH | paper ratio | failures |"
    );
    let _ = writeln!(m, "|---|---|---:|---:|---:|---:|---:|---:|---:|");
    for sc in &doc.scenes {
        let bvh = sc
            .renders
            .iter()
            .find(|r| r.method == Method::Obvhs)
            .map_or(f64::NAN, |r| r.mrays_per_s);
        for r in &sc.renders {
            let paper = NEPTUN_TORUS_KNOTS_MRAYS
                .iter()
                .find(|(pm, _)| *pm == r.method)
                .filter(|_| sc.spec == "torus-knots")
                .map_or("–".to_string(), |(_, v)| format!("{:.2}", v / 4.92));
            let _ = writeln!(
                m,
                "| {} | {} | {:.1} | {:.1} | {:.2} | {:.1} | {:.2} | {} | {} |",
                r.scene,
                r.tracer,
                r.best_ms,
                r.median_ms,
                r.mrays_per_s,
                r.tets_per_ray,
                r.mrays_per_s / bvh,
                paper,
                r.failures
            );
        }
    }

    let _ = writeln!(m, "\n## Bytes per layout (seed 000 Table 4)\n");
    let _ = writeln!(
        m,
        "Hot = tet records + point positions read by the walk; cold = constrained-face table, attributes, anchors. MB = 10⁶ bytes.\n"
    );
    let _ = writeln!(
        m,
        "Paper: seed 000 Table 4 on Torus Knots (xor layouts: total; Tet80: records only, compare with hot).\n"
    );
    let _ = writeln!(
        m,
        "| scene | layout | hot MB | cold MB | total MB | hot B/tet | paper MB |"
    );
    let _ = writeln!(m, "|---|---|---:|---:|---:|---:|---:|");
    for sc in &doc.scenes {
        if let Some(i) = &sc.info {
            for l in &i.layouts {
                let paper = PAPER_TABLE4_TORUS_KNOTS_MB
                    .iter()
                    .find(|(n, _)| *n == l.name)
                    .filter(|_| sc.spec == "torus-knots")
                    .map_or("–".to_string(), |(_, v)| format!("{v:.1}"));
                let _ = writeln!(
                    m,
                    "| {} | {} | {} | {} | {} | {:.1} | {} |",
                    i.name,
                    l.name,
                    mb(l.hot_bytes),
                    mb(l.cold_bytes),
                    mb(l.total_bytes),
                    l.hot_bytes_per_tet,
                    paper
                );
            }
        }
    }

    let _ = writeln!(
        m,
        "\n## Hilbert-sorted vs unsorted (seed 000 Figure 8), tet20\n"
    );
    let _ = writeln!(
        m,
        "| scene | sorted Mrays/s | unsorted Mrays/s | speed-up |"
    );
    let _ = writeln!(m, "|---|---:|---:|---:|");
    for sc in &doc.scenes {
        let sorted = sc.renders.iter().find(|r| r.method == Method::Tet20);
        if let (Some(a), Some(b)) = (sorted, &sc.unsorted_tet20) {
            let _ = writeln!(
                m,
                "| {} | {:.2} | {:.2} | {:.2}× |",
                a.scene,
                a.mrays_per_s,
                b.mrays_per_s,
                a.mrays_per_s / b.mrays_per_s
            );
        }
    }

    let zoom: Vec<&SceneResult> = doc
        .scenes
        .iter()
        .filter(|sc| sc.spec.contains("Zoom") && !sc.renders.is_empty())
        .collect();
    if !zoom.is_empty() {
        let _ = writeln!(
            m,
            "\n## Camera approaching the surface (seed 000 Table 5)\n"
        );
        let _ = writeln!(
            m,
            "Paper (Armadillo Zoom 0–5): Tet20 48.5–60.1 tets per pixel, 140–183 ms; BVH 87–194 ms (Tet20 faster from Zoom 4 on).\n"
        );
        let _ = writeln!(
            m,
            "| scene | tet20 tets/ray | tet20 ms | BVH ms | tet20 / BVH time |"
        );
        let _ = writeln!(m, "|---|---:|---:|---:|---:|");
        for sc in zoom {
            let t = sc.renders.iter().find(|r| r.method == Method::Tet20);
            let b = sc.renders.iter().find(|r| r.method == Method::Obvhs);
            if let (Some(t), Some(b)) = (t, b) {
                let _ = writeln!(
                    m,
                    "| {} | {:.1} | {:.1} | {:.1} | {:.2} |",
                    t.scene,
                    t.tets_per_ray,
                    t.best_ms,
                    b.best_ms,
                    t.best_ms / b.best_ms
                );
            }
        }
    }

    if doc.scenes.iter().any(|sc| sc.quality5.is_some()) {
        let _ = writeln!(
            m,
            "\n## Build trade: surface-preserving `-pY` vs quality `-pYq5`\n"
        );
        let _ = writeln!(
            m,
            "| scene | tets -pY | tets -q5 | build s -pY | build s -q5 | tet20 Mrays/s -pY | tet20 Mrays/s -q5 |"
        );
        let _ = writeln!(m, "|---|---:|---:|---:|---:|---:|---:|");
        for sc in &doc.scenes {
            let (Some(q), Some(i)) = (&sc.quality5, &sc.info) else {
                continue;
            };
            let base = sc.renders.iter().find(|r| r.method == Method::Tet20);
            let secs =
                |b: &Option<crate::load::BuildSummary>| b.as_ref().map_or(f64::NAN, |b| b.total_s);
            let _ = writeln!(
                m,
                "| {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} |",
                i.name,
                i.tets,
                q.tets,
                secs(&i.build),
                secs(&q.build),
                base.map_or(f64::NAN, |r| r.mrays_per_s),
                q.tet20.mrays_per_s
            );
        }
    }

    let _ = writeln!(m, "\n## GPU (seed 000 Table 3)\n");
    let _ = writeln!(
        m,
        "| scene | method (device) | best ms | Mrays/s | tets/ray | GPU bytes (tets + points) | failures |"
    );
    let _ = writeln!(m, "|---|---|---:|---:|---:|---:|---:|");
    for sc in &doc.scenes {
        for r in &sc.gpu_renders {
            let _ = writeln!(
                m,
                "| {} | {} | {:.2} | {:.2} | {:.1} | {} | {} |",
                r.scene,
                r.tracer,
                r.best_ms,
                r.mrays_per_s,
                r.tets_per_ray,
                r.hot_bytes,
                r.failures
            );
        }
        if let Some(note) = &sc.gpu_note {
            let _ = writeln!(m, "| {} | no GPU rows: {note} | | | | | |", sc.spec);
        }
    }

    let _ = writeln!(
        m,
        "\n## Robustness (seed 001 Table 4) and speed vs accuracy\n"
    );
    let _ = writeln!(
        m,
        "Failures = wrong triangle + false miss + false hit + step cap + lost + NaN, beyond the grazing tolerance, per 1024² rays, against an f64 reference. Seed 001 reports 0 for its Plücker method in f32.\n"
    );
    let _ = writeln!(
        m,
        "| scene | method | rays | grazing | wrong | false miss | false hit | cap | lost | failures per 1024² | Mrays/s (render) |"
    );
    let _ = writeln!(m, "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for sc in &doc.scenes {
        if let Some(a) = &sc.accuracy {
            for x in &a.methods {
                let speed = sc
                    .renders
                    .iter()
                    .find(|r| r.tracer == x.method)
                    .map_or(f64::NAN, |r| r.mrays_per_s);
                let _ = writeln!(
                    m,
                    "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2} | {:.2} |",
                    sc.info
                        .as_ref()
                        .map_or(sc.spec.as_str(), |i| i.name.as_str()),
                    x.method,
                    x.rays,
                    x.ambiguous,
                    x.wrong_triangle,
                    x.false_misses,
                    x.false_hits,
                    x.step_cap,
                    x.lost,
                    x.failures_per_1024_squared,
                    speed
                );
            }
        }
    }
    m
}
