//! Isosurfaces of tetrahedral volumes (Wald et al. 2007): one volume
//! (a VTK, TetGen or mesh file with a scalar field, or a synthetic stand-in
//! of `tet_build::volume`), one method, timed frames of primary rays, and
//! the paper's Table 4 counters per ray. The `iso` command and the
//! isosurface tables measure through here.
//!
//! Methods: the paper's implicit min-max BVH built BIH-style (`ibvh`) or by
//! SAH (`ibvh-sah`), traced one ray at a time, or the BIH one by 16×16
//! packets (`ibvh-packets`); and the iso walk over our compact layouts
//! (`walk-tet20`, `walk-tet16`, `walk-tet32`), which needs no BVH over
//! the tets: each 16×16 tile asks a small min-max tree over regions of
//! tets which rays may meet an isosurface and where they may start
//! (`--no-regions`: none), then walks them ([`IsoWalk::trace_tile`]).
//! Every method sees the same rays of the same camera, which frames the
//! volume's bounds the same way for all of them, and each document
//! compares the method's hits pixel by pixel with single rays through the
//! BIH-built IBVH, traced untimed on the same pixels
//! ([`IsoDoc::hit_mismatches`], [`IsoDoc::crossing_mismatches`]).

use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::ValueEnum;
use glam::Vec3;
use rayon::prelude::*;
use serde::Serialize;
use tet_build::volume::{VolumeOptions, load_volume, synthetic_volume_info};
use tet_core::TetMesh;
use tet_core::scene::Camera;
use tet_trace_cpu::Ray;
use tet_trace_cpu::iso::{
    BuildKind, ClipBox, Ibvh, IsoHit, IsoOutcome, IsoQuery, IsoStats, IsoWalk, WalkLayout,
};
use tet_trace_cpu::render::PinholeCamera;

/// Isosurface methods (`--method`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, ValueEnum, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum IsoMethod {
    /// The paper's implicit min-max BVH, BIH-style build, single rays.
    Ibvh,
    /// The same with the SAH build.
    IbvhSah,
    /// The BIH-built IBVH traced by 16×16 packets.
    IbvhPackets,
    /// The iso walk over Tet20 (no BVH over the tets).
    WalkTet20,
    /// The iso walk over Tet16.
    WalkTet16,
    /// The iso walk over Tet32.
    WalkTet32,
}

impl IsoMethod {
    /// Every method, in table order.
    pub const ALL: [IsoMethod; 6] = [
        IsoMethod::Ibvh,
        IsoMethod::IbvhSah,
        IsoMethod::IbvhPackets,
        IsoMethod::WalkTet20,
        IsoMethod::WalkTet16,
        IsoMethod::WalkTet32,
    ];

    /// Name as on the command line.
    pub fn name(self) -> &'static str {
        match self {
            IsoMethod::Ibvh => "ibvh",
            IsoMethod::IbvhSah => "ibvh-sah",
            IsoMethod::IbvhPackets => "ibvh-packets",
            IsoMethod::WalkTet20 => "walk-tet20",
            IsoMethod::WalkTet16 => "walk-tet16",
            IsoMethod::WalkTet32 => "walk-tet32",
        }
    }
}

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
    load_iso_volume_with(spec, &VolumeOptions::default())
}

/// [`load_iso_volume`] with the synthetic volumes' `options` (size, steps,
/// replications).
pub fn load_iso_volume_with(spec: &str, options: &VolumeOptions) -> Result<IsoVolume> {
    let mesh = load_volume(spec, options).with_context(|| format!("cannot load volume {spec}"))?;
    let Some(field) = &mesh.attributes.scalars else {
        bail!("{spec} has no scalar field (a VTK file needs point scalars)");
    };
    let default_isovalue = match synthetic_volume_info(spec, options) {
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
    /// Shadow rays traced (one per hit with `--shadows`, else 0).
    pub shadow_rays: u64,
    /// Hits whose shadow ray was blocked.
    pub shadowed: u64,
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
    /// Walks: whether the regions' min-max tree culled rays that meet no
    /// region straddling an isovalue (`--no-regions`: every ray walks);
    /// false for the IBVH.
    pub regions: bool,
    /// Hits of single rays through the BIH-built IBVH (`ibvh`) on the same
    /// pixels: the yardstick of [`IsoDoc::hit_mismatches`] and
    /// [`IsoDoc::crossing_mismatches`] (one untimed frame).
    pub ibvh_hits: u64,
    /// Pixels this method hits and single IBVH rays miss, or the reverse
    /// (0 for `ibvh` itself; the packets and `ibvh-sah` must give 0, the
    /// walks may differ on rays grazing a silhouette).
    pub hit_mismatches: u64,
    /// Pixels both hit at another crossing: another tet or isovalue, or,
    /// for the IBVH methods (which share the single-ray isopolygon test and
    /// must give the same bits), another `t`.
    pub crossing_mismatches: u64,
}

/// How `image` differs from single-ray hits `reference` on the same
/// pixels: `(hit_mismatches, crossing_mismatches)` as in [`IsoDoc`];
/// `exact_t`: the `t` of a crossing must have the same bits.
pub fn compare_hits(image: &[IsoPixel], reference: &[Option<IsoHit>], exact_t: bool) -> (u64, u64) {
    let (mut hit, mut crossing) = (0, 0);
    for (p, r) in image.iter().zip(reference) {
        match (p.hit, r) {
            (Some(a), Some(b)) => {
                let same = a.tet == b.tet
                    && a.isovalue_index == b.isovalue_index
                    && (!exact_t || a.t.to_bits() == b.t.to_bits());
                crossing += !same as u64;
            }
            (None, None) => {}
            _ => hit += 1,
        }
    }
    (hit, crossing)
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
    /// Camera, clip box and light.
    pub view: IsoView,
    /// Walks: cull the rays that meet no region straddling an isovalue
    /// (the regions' min-max tree, `tet_trace_cpu::iso::regions`).
    pub regions: bool,
}

/// What a frame looks at and how: the camera, an optional clip box (every
/// method applies it to primary and shadow rays alike) and an optional
/// light for shadow rays.
#[derive(Clone, Copy, Debug)]
pub struct IsoView {
    /// The camera.
    pub camera: Camera,
    /// Clip box.
    pub clip: Option<ClipBox>,
    /// Light of the shadow rays (none: no shadow rays).
    pub light: Option<IsoLight>,
}

impl IsoView {
    /// The default view of `mesh` ([`iso_camera`]), no clip box, no shadows.
    pub fn of(mesh: &TetMesh) -> IsoView {
        IsoView {
            camera: iso_camera(mesh),
            clip: None,
            light: None,
        }
    }
}

/// The light of the shadow rays.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IsoLight {
    /// A point light.
    Point(Vec3),
    /// A directional light: the direction its light travels in.
    Directional(Vec3),
}

/// Start of a shadow ray's accepted range: a thousandth of the way to a
/// point light, or of the volume's diagonal for a directional one, so that
/// the surface a shadow ray leaves does not shadow itself.
const SHADOW_OFFSET: f32 = 1e-3;

impl IsoLight {
    /// The shadow ray from the hit point `p` to the light (`diagonal`: the
    /// volume's bounding-box diagonal).
    pub fn shadow_ray(&self, p: Vec3, diagonal: f32) -> Ray {
        match *self {
            IsoLight::Point(l) => Ray {
                origin: p,
                direction: l - p,
                t_min: SHADOW_OFFSET,
                t_max: 1.0,
            },
            IsoLight::Directional(d) => Ray {
                origin: p,
                direction: -d.normalize_or_zero(),
                t_min: SHADOW_OFFSET * diagonal,
                t_max: f32::INFINITY,
            },
        }
    }
}

/// One pixel of a frame: the primary hit and whether a shadow ray from it
/// found the light blocked.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct IsoPixel {
    /// The first crossing (`None`: background).
    pub hit: Option<IsoHit>,
    /// The hit's shadow ray met an isosurface before the light.
    pub shadowed: bool,
}

/// Traces `method` on `volume` and returns the document and the last
/// frame's pixels (row-major).
pub fn measure(
    volume: &IsoVolume,
    isovalues: &[f32],
    method: IsoMethod,
    f: IsoFrames,
    pool: &rayon::ThreadPool,
) -> Result<(IsoDoc, Vec<IsoPixel>)> {
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
    let query = IsoQuery {
        isovalues,
        clip: f.view.clip,
    };
    query.check()?;
    let diagonal = {
        let (lo, hi) = mesh.point_bounds();
        (hi - lo).length()
    };
    let t = Instant::now();
    let traced = match method {
        IsoMethod::Ibvh => Traced::Ibvh(Ibvh::build_bih(mesh, values)?, false),
        IsoMethod::IbvhSah => Traced::Ibvh(Ibvh::build_sah(mesh, values)?, false),
        IsoMethod::IbvhPackets => Traced::Ibvh(Ibvh::build_bih(mesh, values)?, true),
        IsoMethod::WalkTet20 | IsoMethod::WalkTet16 | IsoMethod::WalkTet32 => {
            let layout = match method {
                IsoMethod::WalkTet20 => WalkLayout::Tet20,
                IsoMethod::WalkTet16 => WalkLayout::Tet16,
                _ => WalkLayout::Tet32,
            };
            Traced::Walk(Box::new(IsoWalk::with_regions(
                mesh, values, layout, f.regions,
            )?))
        }
    };
    let build_ms = t.elapsed().as_secs_f64() * 1e3;
    let camera = PinholeCamera::new(&f.view.camera, f.width, f.height, true);
    let tiles = tiles(f.width, f.height);
    let vp = match &traced {
        Traced::Walk(w) => Some(w.viewpoint(camera.position).context("camera not located")?),
        Traced::Ibvh(..) => None,
    };
    // One frame: per tile, its pixels and counters.
    let frame = || -> Vec<(Vec<IsoPixel>, IsoStats, u64)> {
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
                    let shadowed = match f.view.light {
                        Some(light) => shadows(&traced, &light, &rays, &hits, &query, diagonal),
                        None => vec![false; hits.len()],
                    };
                    let pixels = hits
                        .iter()
                        .zip(shadowed)
                        .map(|(&hit, shadowed)| IsoPixel { hit, shadowed })
                        .collect();
                    (pixels, stats, failures)
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
    let hits = image.iter().filter(|p| p.hit.is_some()).count() as u64;
    let shadowed = image.iter().filter(|p| p.shadowed).count() as u64;
    let shadow_rays = if f.view.light.is_some() { hits } else { 0 };
    let bytes = match &traced {
        Traced::Ibvh(b, _) => b.bytes(),
        Traced::Walk(w) => w.bytes(),
    };
    // The yardstick: single rays through the BIH-built IBVH, untimed.
    let reference: Vec<Option<IsoHit>> = if method == IsoMethod::Ibvh {
        image.iter().map(|p| p.hit).collect()
    } else {
        let own;
        let bih = match &traced {
            Traced::Ibvh(b, _) if b.kind == BuildKind::Bih => b,
            _ => {
                own = Ibvh::build_bih(mesh, values)?;
                &own
            }
        };
        let w = f.width as usize;
        pool.install(|| {
            (0..image.len())
                .into_par_iter()
                .map(|k| bih.trace(&camera.ray((k % w) as u32, (k / w) as u32), &query))
                .collect()
        })
    };
    let exact_t = matches!(traced, Traced::Ibvh(..));
    let (hit_mismatches, crossing_mismatches) = compare_hits(&image, &reference, exact_t);
    if exact_t && hit_mismatches + crossing_mismatches > 0 {
        eprintln!(
            "warning: {} {}: {} pixels differ from single ibvh rays ({} hit by one only, {} at another crossing); they should be the same",
            volume.name,
            method.name(),
            hit_mismatches + crossing_mismatches,
            hit_mismatches,
            crossing_mismatches
        );
    }
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
        shadow_rays,
        shadowed,
        failures,
        build_ms,
        best_ms,
        median_ms,
        mrays_per_s: rays as f64 / (best_ms * 1e-3) / 1e6,
        fps: 1e3 / best_ms,
        bytes,
        per_ray: IsoCounts::per_ray(&stats, rays),
        regions: f.regions && matches!(traced, Traced::Walk(_)),
        ibvh_hits: reference.iter().filter(|h| h.is_some()).count() as u64,
        hit_mismatches,
        crossing_mismatches,
    };
    Ok((doc, image))
}

/// Per ray of a tile, whether the shadow ray from its hit to `light` is
/// blocked, by the tile's own method: single IBVH shadow rays, IBVH packets
/// of the tile's shadow rays, or walks from the hit tet.
fn shadows(
    traced: &Traced,
    light: &IsoLight,
    rays: &[Ray],
    hits: &[Option<IsoHit>],
    query: &IsoQuery,
    diagonal: f32,
) -> Vec<bool> {
    let shadow =
        |(r, h): (&Ray, &Option<IsoHit>)| h.map(|h| (light.shadow_ray(r.at(h.t), diagonal), h.tet));
    let todo: Vec<(usize, Ray, u32)> = rays
        .iter()
        .zip(hits)
        .enumerate()
        .filter_map(|(i, x)| shadow(x).map(|(s, t)| (i, s, t)))
        .collect();
    let mut out = vec![false; rays.len()];
    match traced {
        Traced::Ibvh(b, false) => {
            for &(i, s, _) in &todo {
                out[i] = b.occluded(&s, query);
            }
        }
        Traced::Ibvh(b, true) => {
            let srays: Vec<Ray> = todo.iter().map(|x| x.1).collect();
            let mut blocked = vec![false; srays.len()];
            b.occluded_packet(&srays, query, &mut blocked);
            for (&(i, _, _), b) in todo.iter().zip(blocked) {
                out[i] = b;
            }
        }
        Traced::Walk(w) => {
            for &(i, s, tet) in &todo {
                // A failed walk counts as lit (reported by the primary
                // rays' failure count when it recurs).
                out[i] = w.occluded_near(&s, tet, query).unwrap_or(false);
            }
        }
    }
    out
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
    traced: Vec<(Vec<IsoPixel>, IsoStats, u64)>,
    width: u32,
    height: u32,
) -> Vec<IsoPixel> {
    let mut image = vec![IsoPixel::default(); width as usize * height as usize];
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

/// Linear RGB of a frame's pixels: one colour per isovalue, shaded by the
/// field gradient against the view direction, darker in shadow; background
/// dark grey.
pub fn shade(image: &[IsoPixel], camera: &Camera, width: u32, height: u32) -> Vec<Vec3> {
    const PALETTE: [Vec3; 4] = [
        Vec3::new(0.9, 0.55, 0.2),
        Vec3::new(0.25, 0.6, 0.9),
        Vec3::new(0.4, 0.85, 0.35),
        Vec3::new(0.85, 0.3, 0.6),
    ];
    let camera = PinholeCamera::new(camera, width, height, true);
    image
        .iter()
        .enumerate()
        .map(|(k, p)| match p.hit {
            Some(h) => {
                let d = camera.ray(k as u32 % width, k as u32 / width).direction;
                let lambert = h.normal.dot(d.normalize_or_zero()).abs();
                let light = if p.shadowed { 0.35 } else { 1.0 };
                PALETTE[h.isovalue_index as usize % 4] * (0.2 + 0.8 * lambert * light)
            }
            None => Vec3::splat(0.05),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use tet_trace_cpu::iso::ClipMode;
    use tet_trace_cpu::iso::reference::closest;

    use super::*;

    /// The pixels of every method on the `linear` volume (parallel planes)
    /// under `view`, at 40², two isovalues.
    fn frames_of(view: impl Fn(&TetMesh) -> IsoView) -> (IsoVolume, Vec<f32>, Vec<Vec<IsoPixel>>) {
        let volume = load_iso_volume("linear").unwrap();
        let (lo, hi) = volume
            .mesh
            .attributes
            .scalars
            .as_ref()
            .unwrap()
            .range()
            .unwrap();
        let isos = vec![lo + 0.35 * (hi - lo), lo + 0.6 * (hi - lo)];
        let pool = crate::timing::pool(Some(1)).unwrap();
        let f = IsoFrames {
            width: 40,
            height: 40,
            frames: 1,
            time_step: 0,
            view: view(&volume.mesh),
            regions: true,
        };
        let images = IsoMethod::ALL
            .iter()
            .map(|&m| measure(&volume, &isos, m, f, &pool).unwrap().1)
            .collect();
        (volume, isos, images)
    }

    /// Every document compares its method's hits with single IBVH rays on
    /// the same pixels: the counts match those of the `ibvh` image itself,
    /// with a clip box too, and the IBVH methods give the same bits.
    #[test]
    fn documents_count_differences_from_single_ibvh_rays() {
        let volume = load_iso_volume("linear").unwrap();
        let (lo, hi) = volume.mesh.point_bounds();
        let isos = [volume.default_isovalue];
        let pool = crate::timing::pool(Some(1)).unwrap();
        for clip in [
            None,
            Some(ClipBox {
                lo,
                hi: Vec3::new(hi.x, 0.5 * (lo.y + hi.y), hi.z),
                mode: ClipMode::KeepInside,
            }),
        ] {
            let mut view = IsoView::of(&volume.mesh);
            view.clip = clip;
            let f = IsoFrames {
                width: 48,
                height: 40,
                frames: 1,
                time_step: 0,
                view,
                regions: true,
            };
            let runs: Vec<(IsoDoc, Vec<IsoPixel>)> = IsoMethod::ALL
                .iter()
                .map(|&m| measure(&volume, &isos, m, f, &pool).unwrap())
                .collect();
            let ibvh = &runs[IsoMethod::ALL
                .iter()
                .position(|&m| m == IsoMethod::Ibvh)
                .unwrap()]
            .1;
            let ibvh_hits = ibvh.iter().filter(|p| p.hit.is_some()).count() as u64;
            assert!(ibvh_hits > 100, "{ibvh_hits}");
            for (doc, image) in &runs {
                let name = doc.method.name();
                assert_eq!(doc.ibvh_hits, ibvh_hits, "{name}");
                let hit = image
                    .iter()
                    .zip(ibvh)
                    .filter(|(a, b)| a.hit.is_some() != b.hit.is_some())
                    .count() as u64;
                assert_eq!(doc.hit_mismatches, hit, "{name}");
                if doc.method.name().starts_with("ibvh") {
                    assert_eq!(
                        (doc.hit_mismatches, doc.crossing_mismatches),
                        (0, 0),
                        "{name}"
                    );
                    assert!(
                        image.iter().zip(ibvh).all(|(a, b)| a.hit == b.hit),
                        "{name}"
                    );
                }
            }
        }
    }

    /// Pixels on which two methods differ (hit or not, shadowed or not).
    fn differing(a: &[IsoPixel], b: &[IsoPixel]) -> usize {
        a.iter()
            .zip(b)
            .filter(|(x, y)| x.hit.is_some() != y.hit.is_some() || x.shadowed != y.shadowed)
            .count()
    }

    /// With a point light beyond both planes, every method shadows the same
    /// pixels (the near plane's hits lie in the far plane's shadow), up to
    /// a few pixels whose rays graze an edge of the planes.
    #[test]
    fn methods_agree_on_shadows() {
        let (volume, _, images) = frames_of(|mesh| {
            let mut v = IsoView::of(mesh);
            let (lo, hi) = mesh.point_bounds();
            // Opposite the camera across the volume.
            let c = 0.5 * (lo + hi);
            v.light = Some(IsoLight::Point(c + (c - v.camera.position)));
            v
        });
        let hits = images[0].iter().filter(|p| p.hit.is_some()).count();
        let shadowed = images[0].iter().filter(|p| p.shadowed).count();
        assert!(
            hits > 200 && shadowed > 50 && shadowed < hits,
            "{hits} {shadowed}"
        );
        for (m, im) in IsoMethod::ALL.iter().zip(&images) {
            let d = differing(&images[0], im);
            assert!(d <= 4, "{}: {d} pixels differ", m.name());
            // A shadowed pixel has a hit.
            assert!(im.iter().all(|p| !p.shadowed || p.hit.is_some()));
        }
        let _ = volume;
    }

    /// A clip box keeping one half of the volume: every method keeps the
    /// same pixels, each hit lies in the box, and the hits match the f64
    /// reference under the same clip box.
    #[test]
    fn methods_agree_on_a_clip_box() {
        let clip_of = |mesh: &TetMesh| {
            let (lo, hi) = mesh.point_bounds();
            ClipBox {
                lo,
                hi: Vec3::new(0.5 * (lo.x + hi.x), hi.y, hi.z),
                mode: ClipMode::KeepInside,
            }
        };
        let (_, _, unclipped) = frames_of(IsoView::of);
        let (volume, isos, images) = frames_of(|mesh| {
            let mut v = IsoView::of(mesh);
            v.clip = Some(clip_of(mesh));
            v
        });
        let clip = clip_of(&volume.mesh);
        let count = |im: &[IsoPixel]| im.iter().filter(|p| p.hit.is_some()).count();
        assert!(count(&images[0]) > 100 && count(&images[0]) < count(&unclipped[0]));
        for (m, im) in IsoMethod::ALL.iter().zip(&images) {
            assert!(differing(&images[0], im) <= 4, "{}", m.name());
        }
        // The reference, f64 brute force, on every pixel.
        let camera = PinholeCamera::new(&iso_camera(&volume.mesh), 40, 40, true);
        let values = volume
            .mesh
            .attributes
            .scalars
            .as_ref()
            .unwrap()
            .step(0)
            .unwrap();
        let q = IsoQuery {
            isovalues: &isos,
            clip: Some(clip),
        };
        let mut wrong = 0;
        for (k, p) in images[0].iter().enumerate() {
            let ray = camera.ray(k as u32 % 40, k as u32 / 40);
            let want = closest(&volume.mesh, values, &ray, &q);
            if let Some(h) = p.hit {
                let at = ray.at(h.t);
                let slack = Vec3::splat(1e-3 * (clip.hi - clip.lo).length());
                assert!(at.cmpge(clip.lo - slack).all() && at.cmple(clip.hi + slack).all());
            }
            wrong += (want.is_some() != p.hit.is_some()) as usize;
        }
        assert!(wrong <= 4, "{wrong} pixels differ from the reference");
    }
}
