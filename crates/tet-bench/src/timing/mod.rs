//! Speed: how fast a method traces. The GPU methods are timed by [`gpu`],
//! the exit-face decision alone (single thread) by [`exitface`].
//!
//! This module times one method on one scene: frames rendered on a thread
//! pool, the best and the median reported as a [`RenderDoc`] (the
//! `render --json` document and the rows of every speed table).

pub mod exitface;
pub mod gpu;
pub mod ray_kinds;

use std::time::Instant;

use anyhow::{Context, Result, bail};
use serde::Serialize;
use tet_core::TetMesh;
use tet_trace_cpu::kernel::Tracer;
use tet_trace_cpu::render::{Frame, FrameStats, RenderOptions, render, render_into};

use crate::load::Loaded;
use crate::methods::bvh::BvhTracer;
use crate::methods::layouts::{layout_bytes, strips_bytes};
use crate::methods::method::Method;
use crate::methods::tracer;
use ray_kinds::{ByKind, RayKinds};

/// Timings of one method on one scene (JSON document of `render`, and rows
/// of the `tables` render table).
#[derive(Clone, Debug, Serialize)]
pub struct RenderDoc {
    /// Scene name.
    pub scene: String,
    /// `--method`.
    pub method: Method,
    /// Tracer name with precision (e.g. `tet20/duff-f32`).
    pub tracer: String,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Worker threads (0 for GPU methods).
    pub threads: usize,
    /// Frames timed (after one untimed warm-up frame).
    pub frames: u32,
    /// Fastest frame, ms.
    pub best_ms: f64,
    /// Median frame, ms.
    pub median_ms: f64,
    /// Primary rays per second in the fastest frame, millions.
    pub mrays_per_s: f64,
    /// Mean tets visited per primary ray (0 for BVH methods).
    pub tets_per_ray: f64,
    /// BVH methods: mean BVH nodes visited (bounding boxes tested) per
    /// primary ray, counted in one extra untimed frame by our own traversal
    /// of the same BVH; `null` for tet walks.
    pub nodes_per_ray: Option<f64>,
    /// Primary rays per frame.
    pub rays: u64,
    /// Primary rays that hit.
    pub hits: u64,
    /// Primary rays whose walk failed (step cap, lost, invalid).
    pub failures: u64,
    /// Shadow rays per frame.
    pub shadow_rays: u64,
    /// The rays each frame cast (`render --rays`).
    pub rays_kind: RayKinds,
    /// Rays and speed of each kind in the fastest frame (the top-level
    /// `mrays_per_s` is the whole frame's primary rays per second).
    pub by_kind: ByKind,
    /// Seconds to encode the layout or build the BVH.
    pub setup_s: f64,
    /// Hot bytes of the method's structure: the tet records and points of
    /// the layout it walks, the BVH's nodes and triangles (obvhs), the
    /// whole Ray-Strips structure; 0 where the method does not report it
    /// (Embree, the brute force, the exact walk).
    pub hot_bytes: usize,
    /// Compile-time CPU features the kernels were built with.
    pub target_features: Vec<&'static str>,
}

/// CPU features enabled at compile time (shows whether `target-cpu=native` was used).
pub fn target_features() -> Vec<&'static str> {
    let mut f = Vec::new();
    if cfg!(target_feature = "sse4.1") {
        f.push("sse4.1");
    }
    if cfg!(target_feature = "avx") {
        f.push("avx");
    }
    if cfg!(target_feature = "avx2") {
        f.push("avx2");
    }
    if cfg!(target_feature = "fma") {
        f.push("fma");
    }
    if cfg!(target_feature = "avx512f") {
        f.push("avx512f");
    }
    if cfg!(target_feature = "neon") {
        f.push("neon");
    }
    f
}

/// Runs `threads` workers (None: all cores).
pub fn pool(threads: Option<usize>) -> Result<rayon::ThreadPool> {
    let mut b = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        b = b.num_threads(n.max(1));
    }
    Ok(b.build()?)
}

/// How long a method is timed: at least `at_least` frames, and more until
/// `min_s` seconds of frames are spent (at most [`Frames::MAX`]), so that a
/// fast method's best frame is the best of enough frames to be stable.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frames {
    /// Frames timed at least.
    pub at_least: u32,
    /// Seconds of timed frames at least (0: `at_least` alone).
    pub min_s: f64,
}

impl Frames {
    /// The most frames a minimum time asks for.
    pub const MAX: u32 = 200;
}

impl From<u32> for Frames {
    /// Exactly `frames` frames (at least one).
    fn from(frames: u32) -> Frames {
        Frames {
            at_least: frames,
            min_s: 0.0,
        }
    }
}

/// Renders the timed frames of `frames` (plus a warm-up) and summarises
/// them; returns the last frame for images.
pub fn time_method(
    loaded: &Loaded,
    method: Method,
    opts: &RenderOptions,
    frames: impl Into<Frames>,
    pool: &rayon::ThreadPool,
) -> Result<(RenderDoc, Frame)> {
    let frames: Frames = frames.into();
    let setup = Instant::now();
    let t: Box<dyn Tracer + '_> = tracer(method, false, &loaded.mesh)?;
    let setup_s = setup.elapsed().as_secs_f64();
    let hot_bytes = hot_bytes(method, &loaded.mesh)?;
    let run = || render(t.as_ref(), &loaded.camera, &loaded.lights, opts);
    let mut frame = pool.install(run).context("render failed")?;
    let mut stats: Vec<FrameStats> = Vec::new();
    // Timed frames reuse the warm-up frame's buffers.
    let timing = Instant::now();
    while stats.len() < frames.at_least.max(1) as usize
        || (timing.elapsed().as_secs_f64() < frames.min_s && stats.len() < Frames::MAX as usize)
    {
        pool.install(|| render_into(t.as_ref(), &loaded.camera, &loaded.lights, opts, &mut frame))?;
        stats.push(frame.stats);
    }
    let mut nodes_per_ray = None;
    if method == Method::Obvhs {
        // Nodes visited: one untimed frame through the counting traversal
        // (same BVH, same hits); its frame (heat map = nodes) is returned.
        let counting = BvhTracer::new(&loaded.mesh).counting();
        let counted = pool
            .install(|| render(&counting, &loaded.camera, &loaded.lights, opts))
            .context("render failed")?;
        if counted.stats.hits != frame.stats.hits {
            bail!(
                "the counting BVH traversal found {} hits, obvhs {}",
                counted.stats.hits,
                frame.stats.hits
            );
        }
        nodes_per_ray = Some(counted.stats.tets_visited as f64 / counted.stats.rays.max(1) as f64);
        frame = counted;
    }
    let mut ms: Vec<f64> = stats.iter().map(|s| s.ms).collect();
    ms.sort_by(f64::total_cmp);
    let best = stats
        .iter()
        .min_by(|a, b| a.ms.total_cmp(&b.ms))
        .copied()
        .unwrap_or_default();
    let doc = RenderDoc {
        scene: loaded.name.clone(),
        method,
        tracer: t.name(),
        width: opts.width,
        height: opts.height,
        threads: pool.current_num_threads(),
        frames: stats.len() as u32,
        best_ms: best.ms,
        median_ms: ms[ms.len() / 2],
        mrays_per_s: best.mrays_per_s(),
        tets_per_ray: best.tets_visited as f64 / best.rays.max(1) as f64,
        nodes_per_ray,
        rays: best.rays,
        hits: best.hits,
        failures: best.failures,
        shadow_rays: best.shadow_rays,
        rays_kind: RayKinds::of(opts),
        by_kind: ByKind::of(&best, pool.current_num_threads()),
        setup_s,
        hot_bytes,
        target_features: target_features(),
    };
    Ok((doc, frame))
}

/// [`RenderDoc::hot_bytes`] of `method` over `mesh` (the BVH and the strips
/// are built again to be measured).
fn hot_bytes(method: Method, mesh: &TetMesh) -> Result<usize> {
    if let Some(name) = method.layout() {
        let (_, layouts) = layout_bytes(mesh);
        return Ok(layouts
            .iter()
            .find(|l| l.name == name)
            .map_or(0, |l| l.hot_bytes));
    }
    Ok(match method {
        Method::Obvhs => {
            let (nodes, triangles) = BvhTracer::new(mesh).bytes();
            nodes + triangles
        }
        Method::Strips | Method::StripsPackets => strips_bytes(mesh)?.hot_bytes,
        _ => 0,
    })
}
