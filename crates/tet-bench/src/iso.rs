//! Isosurfaces of tetrahedral volumes (Wald et al., seed 004): one volume
//! (a VTK, TetGen or mesh file with a scalar field, or a synthetic stand-in
//! of `tet_build::volume`), one method, timed frames of primary rays, and
//! the paper's Table 4 counters per ray. The `iso` command and the
//! isosurface tables measure through here.
//!
//! Methods: the paper's implicit min-max BVH built BIH-style (`ibvh`) or by
//! SAH (`ibvh-sah`), traced one ray at a time, or the BIH one by 16×16
//! packets (`ibvh-packets`); and the iso walk over our compact layouts
//! (`walk-tet20`, `walk-tet16`, `walk-tet32`), which needs no BVH at all
//! (each 16×16 tile's walks interleaved on one thread,
//! [`IsoWalk::trace_tile`]).
//! Every method sees the same rays of the same camera, which frames the
//! volume's bounds the same way for all of them.

use std::time::Instant;

use anyhow::{Context, Result, bail};
use glam::Vec3;
use rayon::prelude::*;
use serde::Serialize;
use tet_build::volume::{VolumeOptions, load_volume, synthetic_volume_info};
use tet_core::TetMesh;
use tet_core::scene::Camera;
use tet_trace_cpu::Ray;
use tet_trace_cpu::iso::{Ibvh, IsoHit, IsoOutcome, IsoQuery, IsoStats, IsoWalk, WalkLayout};
use tet_trace_cpu::render::PinholeCamera;

pub use crate::cli::IsoMethod;

/// A volume ready to trace: the mesh with its field, and an isovalue that
/// gives a surface.
pub struct IsoVolume {
    /// File path or synthetic name.
    pub name: String,
    /// The mesh (its field in `attributes.scalars`).
    pub mesh: TetMesh,
    /// The synthetic volume's own isovalue, else the middle of the field's
    /// range.
    pub default_isovalue: f32,
}

/// Loads `spec` (a file with a scalar field, or a synthetic volume's name).
pub fn load_iso_volume(spec: &str) -> Result<IsoVolume> {
    let options = VolumeOptions::default();
    let mesh = load_volume(spec, &options).with_context(|| format!("cannot load volume {spec}"))?;
    let Some(field) = &mesh.attributes.scalars else {
        bail!("{spec} has no scalar field (a VTK file needs point scalars)");
    };
    let default_isovalue = match synthetic_volume_info(spec, &options) {
        Ok(info) => info.isovalue,
        Err(_) => {
            let (lo, hi) = field.range().unwrap_or((0.0, 0.0));
            0.5 * (lo + hi)
        }
    };
    Ok(IsoVolume {
        name: spec.to_string(),
        mesh,
        default_isovalue,
    })
}

/// The camera of every isosurface measurement: outside the volume's bounds,
/// looking at their centre from a fixed oblique direction, the whole box in
/// view.
pub fn iso_camera(mesh: &TetMesh) -> Camera {
    let (lo, hi) = mesh.point_bounds();
    let centre = 0.5 * (lo + hi);
    let radius = 0.5 * (hi - lo).length();
    let dir = Vec3::new(0.6, 0.45, 1.0).normalize();
    Camera {
        position: centre + dir * (radius * 2.6),
        target: centre,
        up: Vec3::Y,
        vfov_deg: 45.0,
    }
}

/// Table 4's counters, per primary ray.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct IsoCounts {
    /// BVH nodes visited.
    pub nodes_visited: f64,
    /// Ray–box tests.
    pub box_tests: f64,
    /// Tet value-range tests (walks: tets visited).
    pub range_tests: f64,
    /// Isopolygons built.
    pub isopolygons: f64,
    /// Ray–isopolygon tests (walks: crossings computed).
    pub isopolygon_tests: f64,
    /// Packet nodes culled by the interval test.
    pub frustum_culls: f64,
}

impl IsoCounts {
    /// `s` divided by `rays`.
    fn per_ray(s: &IsoStats, rays: u64) -> IsoCounts {
        let n = rays.max(1) as f64;
        IsoCounts {
            nodes_visited: s.nodes_visited as f64 / n,
            box_tests: s.box_tests as f64 / n,
            range_tests: s.range_tests as f64 / n,
            isopolygons: s.isopolygons as f64 / n,
            isopolygon_tests: s.isopolygon_tests as f64 / n,
            frustum_culls: s.frustum_culls as f64 / n,
        }
    }
}

/// One method's frames on one volume (the `iso --json` document).
#[derive(Clone, Debug, Serialize)]
pub struct IsoDoc {
    /// Volume file or name.
    pub volume: String,
    /// Method.
    pub method: IsoMethod,
    /// Tets.
    pub tets: usize,
    /// Points.
    pub points: usize,
    /// Time step traced (0-based) and the field's step count.
    pub time_step: usize,
    /// Time steps of the field.
    pub steps: usize,
    /// Isovalues.
    pub isovalues: Vec<f32>,
    /// Image size.
    pub width: u32,
    /// Image size.
    pub height: u32,
    /// Worker threads.
    pub threads: usize,
    /// Timed frames (after one warm-up frame).
    pub frames: u32,
    /// Primary rays per frame.
    pub rays: u64,
    /// Rays that hit an isosurface.
    pub hits: u64,
    /// Walks that failed (step cap, lost); always 0 for the IBVH.
    pub failures: u64,
    /// Building the method's structure (IBVH, or the walk's layout and
    /// boundary BVH), ms.
    pub build_ms: f64,
    /// Fastest frame, ms.
    pub best_ms: f64,
    /// Median frame, ms.
    pub median_ms: f64,
    /// Primary rays per second in the fastest frame, millions.
    pub mrays_per_s: f64,
    /// Frames per second of the fastest frame.
    pub fps: f64,
    /// Bytes of the method's structure (IBVH nodes, or the walk's records,
    /// points and boundary BVH; the field's values not included).
    pub bytes: usize,
    /// Table 4's counters per primary ray (one untimed frame).
    pub per_ray: IsoCounts,
}

/// What traces the rays.
enum Traced<'m> {
    /// An IBVH, single rays or packets.
    Ibvh(Ibvh, bool),
    /// An iso walk.
    Walk(Box<IsoWalk<'m>>),
}

/// Side of a square packet of primary rays (the paper's 16×16).
const TILE: u32 = 16;

/// Frame settings.
#[derive(Clone, Copy, Debug)]
pub struct IsoFrames {
    /// Image size.
    pub width: u32,
    /// Image size.
    pub height: u32,
    /// Timed frames.
    pub frames: u32,
    /// Time step.
    pub time_step: usize,
}

/// Traces `method` on `volume` and returns the document and the last
/// frame's hits (row-major, `None` = background).
pub fn measure(
    volume: &IsoVolume,
    isovalues: &[f32],
    method: IsoMethod,
    f: IsoFrames,
    pool: &rayon::ThreadPool,
) -> Result<(IsoDoc, Vec<Option<IsoHit>>)> {
    let mesh = &volume.mesh;
    let field = mesh
        .attributes
        .scalars
        .as_ref()
        .context("the volume has no scalar field")?;
    let values = field.step(f.time_step).with_context(|| {
        format!(
            "time step {} out of range (the field has {})",
            f.time_step,
            field.step_count()
        )
    })?;
    let query = IsoQuery::new(isovalues);
    query.check()?;
    let t = Instant::now();
    let traced = match method {
        IsoMethod::Ibvh => Traced::Ibvh(Ibvh::build_bih(mesh, values)?, false),
        IsoMethod::IbvhSah => Traced::Ibvh(Ibvh::build_sah(mesh, values)?, false),
        IsoMethod::IbvhPackets => Traced::Ibvh(Ibvh::build_bih(mesh, values)?, true),
        IsoMethod::WalkTet20 => {
            Traced::Walk(Box::new(IsoWalk::new(mesh, values, WalkLayout::Tet20)?))
        }
        IsoMethod::WalkTet16 => {
            Traced::Walk(Box::new(IsoWalk::new(mesh, values, WalkLayout::Tet16)?))
        }
        IsoMethod::WalkTet32 => {
            Traced::Walk(Box::new(IsoWalk::new(mesh, values, WalkLayout::Tet32)?))
        }
    };
    let build_ms = t.elapsed().as_secs_f64() * 1e3;
    let camera = PinholeCamera::new(&iso_camera(mesh), f.width, f.height, true);
    let tiles = tiles(f.width, f.height);
    let vp = match &traced {
        Traced::Walk(w) => Some(w.viewpoint(camera.position).context("camera not located")?),
        Traced::Ibvh(..) => None,
    };
    // One frame: per tile, its rays' outcomes and counters.
    let frame = || -> Vec<(Vec<Option<IsoHit>>, IsoStats, u64)> {
        pool.install(|| {
            tiles
                .par_iter()
                .map(|&(x0, y0, x1, y1)| {
                    let rays: Vec<Ray> = (y0..y1)
                        .flat_map(|j| (x0..x1).map(move |i| (i, j)))
                        .map(|(i, j)| camera.ray(i, j))
                        .collect();
                    let mut stats = IsoStats::default();
                    let mut failures = 0u64;
                    let hits: Vec<Option<IsoHit>> = match &traced {
                        Traced::Ibvh(b, false) => rays
                            .iter()
                            .map(|r| b.trace_stats(r, &query, &mut stats))
                            .collect(),
                        Traced::Ibvh(b, true) => {
                            let mut out = vec![None; rays.len()];
                            b.trace_packet_stats(&rays, &query, &mut out, &mut stats);
                            out
                        }
                        Traced::Walk(w) => {
                            let vp = vp.as_ref().expect("located above");
                            let mut out = vec![IsoOutcome::Miss { tets_visited: 0 }; rays.len()];
                            w.trace_tile(vp, &rays, &query, &mut out, &mut stats);
                            out.iter()
                                .map(|o| {
                                    failures += o.is_failure() as u64;
                                    o.hit().copied()
                                })
                                .collect()
                        }
                    };
                    (hits, stats, failures)
                })
                .collect()
        })
    };
    frame();
    let mut times = Vec::new();
    let mut last = Vec::new();
    for _ in 0..f.frames.max(1) {
        let t = Instant::now();
        last = frame();
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    let best_ms = times[0];
    let median_ms = times[times.len() / 2];
    let rays = f.width as u64 * f.height as u64;
    let mut stats = IsoStats::default();
    let mut failures = 0;
    for (_, s, fl) in &last {
        stats.add(s);
        failures += fl;
    }
    let image = assemble(&tiles, last, f.width, f.height);
    let hits = image.iter().filter(|h| h.is_some()).count() as u64;
    let bytes = match &traced {
        Traced::Ibvh(b, _) => b.bytes(),
        Traced::Walk(w) => w.bytes(),
    };
    let doc = IsoDoc {
        volume: volume.name.clone(),
        method,
        tets: mesh.tets.len(),
        points: mesh.points.len(),
        time_step: f.time_step,
        steps: field.step_count(),
        isovalues: isovalues.to_vec(),
        width: f.width,
        height: f.height,
        threads: pool.current_num_threads(),
        frames: f.frames.max(1),
        rays,
        hits,
        failures,
        build_ms,
        best_ms,
        median_ms,
        mrays_per_s: rays as f64 / (best_ms * 1e-3) / 1e6,
        fps: 1e3 / best_ms,
        bytes,
        per_ray: IsoCounts::per_ray(&stats, rays),
    };
    Ok((doc, image))
}

/// The image split into `TILE`×`TILE` tiles `(x0, y0, x1, y1)`, row-major.
fn tiles(width: u32, height: u32) -> Vec<(u32, u32, u32, u32)> {
    let mut out = Vec::new();
    for y0 in (0..height).step_by(TILE as usize) {
        for x0 in (0..width).step_by(TILE as usize) {
            out.push((x0, y0, (x0 + TILE).min(width), (y0 + TILE).min(height)));
        }
    }
    out
}

/// The tiles' hits back in row-major pixel order.
fn assemble(
    tiles: &[(u32, u32, u32, u32)],
    traced: Vec<(Vec<Option<IsoHit>>, IsoStats, u64)>,
    width: u32,
    height: u32,
) -> Vec<Option<IsoHit>> {
    let mut image = vec![None; width as usize * height as usize];
    for (&(x0, y0, x1, y1), (hits, _, _)) in tiles.iter().zip(traced) {
        let mut k = 0;
        for j in y0..y1 {
            for i in x0..x1 {
                image[(j * width + i) as usize] = hits[k];
                k += 1;
            }
        }
    }
    image
}

/// Linear RGB of a frame's hits: one colour per isovalue, shaded by the
/// field gradient against the view direction; background dark grey.
pub fn shade(image: &[Option<IsoHit>], mesh: &TetMesh, width: u32, height: u32) -> Vec<Vec3> {
    const PALETTE: [Vec3; 4] = [
        Vec3::new(0.9, 0.55, 0.2),
        Vec3::new(0.25, 0.6, 0.9),
        Vec3::new(0.4, 0.85, 0.35),
        Vec3::new(0.85, 0.3, 0.6),
    ];
    let camera = PinholeCamera::new(&iso_camera(mesh), width, height, true);
    image
        .iter()
        .enumerate()
        .map(|(k, h)| match h {
            Some(h) => {
                let d = camera.ray(k as u32 % width, k as u32 / width).direction;
                let lambert = h.normal.dot(d).abs();
                PALETTE[h.isovalue_index as usize % 4] * (0.2 + 0.8 * lambert)
            }
            None => Vec3::splat(0.05),
        })
        .collect()
}
