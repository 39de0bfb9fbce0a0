//! Pinhole renderer: primary rays through 16×16 tiles scheduled with rayon,
//! Lambert shading with point lights and optional shadow rays, PNG output,
//! a heat map of tets visited per pixel, and per-frame statistics for the
//! bench harness.
//!
//! Conventions (`scenes/scenes.json` in the repository, `conventions` block):
//! `forward = normalize(target − position)`,
//! `right = −normalize(up × forward)`, `cam_up = −(forward × right)`; image
//! plane at distance 1 with half-height `tan(vfov/2)` (45° ⇒ `tan(π/8)`),
//! aspect `W/H`; pixel `(i, j)` (i right, j down) has direction
//! `normalize(forward + right·tan(vfov/2)·aspect·(2i/W − 1) +
//! cam_up·tan(vfov/2)·(1 − 2j/H))` — integer pixel corners, no `+0.5`,
//! unless [`RenderOptions::pixel_centers`]. Shading: background 0.1 grey;
//! per hit `Σ color·intensity·clamp(n·normalize(L − p), 0, 1)`, no falloff,
//! `n` the interpolated vertex normal when the mesh has normals, else the
//! face normal from the source triangle's winding.
//!
//! Primary rays start in the camera's tet, or, when the camera lies outside
//! the mesh (a tight enclosing box), each enters through the boundary face
//! its line crosses and a ray that misses the mesh visits no tet
//! ([`crate::boundary_entry`]).
//!
//! Shadows (Aman et al. 2022, §6): each point light is located once per frame, from
//! the camera's tet ([`LightTarget::locate_or_outside`]), and its shadow rays
//! stop when they enter the light's tet (rule in [`crate::secondary`]).
//! Area and mesh lights ([`crate::area_light`], passed through
//! [`render_scene`]) add `E/π` per hit (a white Lambertian surface), with
//! `E` estimated from [`RenderOptions::area_samples`] stratified samples per
//! hit, jittered from [`RenderOptions::seed`] mixed with the pixel index.
//! A scene without area lights takes none of that path. Shadow rays are
//! traced by the primary tracer itself in [`render`] and [`render_scene`]
//! ([`Tracer::trace_until`]: a tet kernel measures itself on them, a
//! tracer without tets runs them to the light's distance), or by the
//! [`ShadowTracer`] given to [`render_scene_with`] (e.g. the canonical-mesh
//! walker [`crate::secondary::MeshWalker`]). A tile's shadow rays toward
//! each point light are traced in one batch after its primary rays
//! ([`ShadowTracer::trace_until_batch`]): the tet kernels walk them side
//! by side, in SIMD lockstep, as they walk the primary rays (Tet20 on
//! Torus Knots, 1920×1440, 2 threads: about five times the shadow rays per
//! second of walking each ray alone, `examples/shadow_speed.rs`), with the
//! outcomes of the single-ray walk, so the image and the statistics are
//! those of tracing each ray alone
//! ([`crate::secondary::PerRay`] keeps that as the reference). Area
//! lights' sample rays are still traced one by one.
//!
//! Ambient occlusion ([`RenderOptions::ambient_occlusion`], [`ambient`]):
//! one AO ray per primary hit, a tile's traced in one batch by the primary
//! tracer after its primary rays; an open hit adds
//! [`AO_AMBIENT`] to its pixel. The time spent tracing each kind of ray
//! is kept apart in [`FrameStats`], so that a frame of primary, AO and
//! shadow rays reports the speed of each.

use std::io::Write;
use std::path::Path;
use std::time::Instant;

use glam::Vec3;
use rayon::prelude::*;
use tet_core::TetMesh;
use tet_core::scene::{Camera, PointLight};
use thiserror::Error;

use crate::area_light::{AreaLight, irradiance, irradiance_unshadowed};
use crate::boundary_entry::{Viewpoint, ViewpointError};
use crate::kernel::Tracer;
use crate::locate::LocateError;
use crate::ray::{Hit, Ray, TraceOutcome};
use crate::secondary::{LightTarget, OwnShadows, ShadowTracer, face_normal};

pub mod ambient;
mod shadows;

use ambient::{Ao, TileAo, ao_length};
use shadows::{Shadow, TileShadows, light_cos};

/// Tile edge in pixels.
pub const TILE: u32 = 16;

/// What an open ambient-occlusion ray adds to its pixel (grey level).
pub const AO_AMBIENT: f32 = 0.25;

/// Default length of the AO rays, as a share of the scene's diagonal
/// ([`ambient::ao_length`]).
pub const AO_SHARE: f32 = 0.1;

/// Rendering errors.
#[derive(Debug, Error)]
pub enum RenderError {
    /// No ray can be started from the camera (see [`Viewpoint::locate`]).
    #[error("camera at {position:?}: {source}")]
    Camera {
        /// Camera position.
        position: Vec3,
        /// Why.
        source: ViewpointError,
    },
    /// Width or height is zero.
    #[error("image size {width}×{height} is empty")]
    EmptyImage {
        /// Width.
        width: u32,
        /// Height.
        height: u32,
    },
    /// A point light has a non-finite position.
    #[error("point light {index} at {position:?}: {source}")]
    Light {
        /// Index in the light list.
        index: usize,
        /// Its position.
        position: Vec3,
        /// Why.
        source: LocateError,
    },
    /// Writing a PNG failed.
    #[error("writing {path}: {source}")]
    Png {
        /// Output path.
        path: String,
        /// The encoder/IO error.
        source: png::EncodingError,
    },
    /// Creating the output file failed.
    #[error("creating {path}: {source}")]
    Io {
        /// Output path.
        path: String,
        /// The IO error.
        source: std::io::Error,
    },
}

/// What to render.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderOptions {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Cast shadow rays to every light.
    pub shadows: bool,
    /// Sample pixel centres (`i + 0.5`) instead of the neptun corners.
    pub pixel_centers: bool,
    /// Background grey level.
    pub background: f32,
    /// Shade only (no light) with the normal's absolute cosine to the view:
    /// useful when the scene has no lights.
    pub headlight: bool,
    /// Samples per hit and area light (rounded up to a full stratification
    /// grid, see [`crate::area_light::strata`]).
    pub area_samples: u32,
    /// Seed of the area-light sample jitter and the AO directions (mixed
    /// with the pixel index).
    pub seed: u64,
    /// Cast one ambient-occlusion ray per primary hit ([`ambient`]).
    pub ambient_occlusion: bool,
    /// Length of the AO rays as a share of the scene's diagonal.
    pub ao_share: f32,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 1920,
            height: 1440,
            shadows: false,
            pixel_centers: false,
            background: 0.1,
            headlight: false,
            area_samples: 16,
            seed: 0,
            ambient_occlusion: false,
            ao_share: AO_SHARE,
        }
    }
}

/// Per-frame statistics.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameStats {
    /// Wall time of the whole frame (primary, AO and shadow rays,
    /// shading), ms.
    pub ms: f64,
    /// Primary rays cast.
    pub rays: u64,
    /// Primary rays that hit.
    pub hits: u64,
    /// Tets visited by primary rays.
    pub tets_visited: u64,
    /// Primary rays that failed (step cap, lost).
    pub failures: u64,
    /// Shadow rays cast (point and area lights).
    pub shadow_rays: u64,
    /// Shadow rays whose walk failed (counted as lit).
    pub shadow_failures: u64,
    /// Ambient-occlusion rays cast.
    pub ao_rays: u64,
    /// AO rays whose walk failed (counted as open).
    pub ao_failures: u64,
    /// Tets visited by AO rays (0 for tracers without tets).
    pub ao_tets_visited: u64,
    /// Time spent tracing the primary rays, summed over the worker
    /// threads, ms.
    pub primary_trace_ms: f64,
    /// Time spent tracing the AO rays, summed over the worker threads, ms.
    pub ao_trace_ms: f64,
    /// Time spent tracing the shadow rays (point lights' batches, area
    /// lights' samples), summed over the worker threads, ms.
    pub shadow_trace_ms: f64,
}

impl FrameStats {
    /// Million primary rays per second of the whole frame.
    pub fn mrays_per_s(&self) -> f64 {
        self.rays as f64 / (self.ms * 1e3)
    }

    /// Million rays per second of `threads` workers tracing one kind of
    /// ray: `rays` over its tracing time per thread (`trace_ms`, summed
    /// over the threads, divided by `threads`); 0 when none were traced.
    pub fn kind_mrays_per_s(rays: u64, trace_ms: f64, threads: usize) -> f64 {
        if rays == 0 || trace_ms <= 0.0 {
            return 0.0;
        }
        rays as f64 * threads.max(1) as f64 / (trace_ms * 1e3)
    }

    /// These statistics with every time set to 0: the counts, which two
    /// renders of the same frame share exactly (tracing ray by ray or in
    /// batches, on any machine).
    pub fn counts(self) -> FrameStats {
        FrameStats {
            ms: 0.0,
            primary_trace_ms: 0.0,
            ao_trace_ms: 0.0,
            shadow_trace_ms: 0.0,
            ..self
        }
    }

    /// Every count and time of two parts of a frame together (`ms` is
    /// the frame's, set apart).
    fn sum(self, b: FrameStats) -> FrameStats {
        FrameStats {
            ms: 0.0,
            rays: self.rays + b.rays,
            hits: self.hits + b.hits,
            tets_visited: self.tets_visited + b.tets_visited,
            failures: self.failures + b.failures,
            shadow_rays: self.shadow_rays + b.shadow_rays,
            shadow_failures: self.shadow_failures + b.shadow_failures,
            ao_rays: self.ao_rays + b.ao_rays,
            ao_failures: self.ao_failures + b.ao_failures,
            ao_tets_visited: self.ao_tets_visited + b.ao_tets_visited,
            primary_trace_ms: self.primary_trace_ms + b.primary_trace_ms,
            ao_trace_ms: self.ao_trace_ms + b.ao_trace_ms,
            shadow_trace_ms: self.shadow_trace_ms + b.shadow_trace_ms,
        }
    }
}

/// A rendered frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Linear RGB per pixel, row-major from the top.
    pub color: Vec<Vec3>,
    /// Tets visited per pixel.
    pub tets: Vec<u32>,
    /// Hit triangle per pixel (`u32::MAX` for none).
    pub triangle: Vec<u32>,
    /// Statistics.
    pub stats: FrameStats,
}

/// The camera's ray generator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PinholeCamera {
    /// Eye.
    pub position: Vec3,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    half_h: f32,
    aspect: f32,
    width: f32,
    height: f32,
    offset: f32,
}

impl PinholeCamera {
    /// Builds the generator for a `width × height` image.
    pub fn new(camera: &Camera, width: u32, height: u32, pixel_centers: bool) -> Self {
        // In f64: the view vector of a scene at 1e30 or 1e-30 has a squared
        // length f32 cannot hold.
        let forward = (camera.target.as_dvec3() - camera.position.as_dvec3()).normalize();
        let right = -camera.up.as_dvec3().cross(forward).normalize();
        let up = -forward.cross(right);
        let (forward, right, up) = (forward.as_vec3(), right.as_vec3(), up.as_vec3());
        PinholeCamera {
            position: camera.position,
            forward,
            right,
            up,
            half_h: (camera.vfov_deg.to_radians() * 0.5).tan(),
            aspect: width as f32 / height as f32,
            width: width as f32,
            height: height as f32,
            offset: if pixel_centers { 0.5 } else { 0.0 },
        }
    }

    /// Primary ray of pixel `(i, j)` (normalised direction).
    pub fn ray(&self, i: u32, j: u32) -> Ray {
        let x = 2.0 * (i as f32 + self.offset) / self.width - 1.0;
        let y = 1.0 - 2.0 * (j as f32 + self.offset) / self.height;
        let d = self.forward
            + self.right * (self.half_h * self.aspect * x)
            + self.up * (self.half_h * y);
        Ray::new(self.position, d.normalize())
    }
}

/// Shading normal at a hit: interpolated vertex normal if present, else the
/// face normal from the winding.
pub fn shading_normal(mesh: &TetMesh, hit: &Hit) -> Vec3 {
    if let Some(normals) = &mesh.attributes.normals {
        let cf = &mesh.constrained[hit.face as usize];
        let n = cf
            .vertices
            .iter()
            .zip(hit.barycentrics)
            .map(|(&v, w)| normals.get(v as usize).copied().unwrap_or(Vec3::ZERO) * w)
            .sum::<Vec3>()
            .normalize_or_zero();
        if n != Vec3::ZERO {
            return n;
        }
    }
    face_normal(mesh, hit.face)
}

struct Pixel {
    color: Vec3,
    tets: u32,
    triangle: u32,
    hit: bool,
    failed: bool,
    shadow_rays: u32,
    shadow_failures: u32,
    /// Time spent on the area lights' shadow rays, ms.
    area_ms: f64,
}

/// The lights of a scene: point lights and area / mesh lights.
#[derive(Clone, Copy, Debug, Default)]
pub struct Lights<'a> {
    /// Point lights.
    pub points: &'a [PointLight],
    /// Area and mesh lights.
    pub areas: &'a [AreaLight],
}

/// Per-frame light data: point lights with their located stars.
struct FrameLights<'a> {
    points: Vec<(&'a PointLight, LightTarget)>,
    areas: &'a [AreaLight],
}

/// Renders one frame with `tracer`. The camera is located once (from tet 0);
/// every primary ray starts in its tet. Point lights only; shadow rays (when
/// [`RenderOptions::shadows`]) are traced by `tracer` itself
/// ([`Tracer::trace_until`]: tet kernels stop at the light's tets, a BVH
/// runs to the light's distance).
pub fn render<T: Tracer + ?Sized>(
    tracer: &T,
    camera: &Camera,
    lights: &[PointLight],
    opts: &RenderOptions,
) -> Result<Frame, RenderError> {
    let lights = Lights {
        points: lights,
        areas: &[],
    };
    render_scene(tracer, camera, &lights, opts)
}

/// [`render`] with point and area lights.
pub fn render_scene<T: Tracer + ?Sized>(
    tracer: &T,
    camera: &Camera,
    lights: &Lights<'_>,
    opts: &RenderOptions,
) -> Result<Frame, RenderError> {
    render_scene_with(tracer, &OwnShadows(tracer), camera, lights, opts)
}

/// [`render_scene`] with shadow rays walked by `shadow` (e.g. the primary
/// kernel itself, which implements [`ShadowTracer`]).
pub fn render_scene_with<T: Tracer + ?Sized, S: ShadowTracer + ?Sized>(
    tracer: &T,
    shadow: &S,
    camera: &Camera,
    lights: &Lights<'_>,
    opts: &RenderOptions,
) -> Result<Frame, RenderError> {
    let mut frame = Frame {
        width: 0,
        height: 0,
        color: Vec::new(),
        tets: Vec::new(),
        triangle: Vec::new(),
        stats: FrameStats::default(),
    };
    render_scene_into(tracer, shadow, camera, lights, opts, &mut frame)?;
    Ok(frame)
}

/// [`render`] into `frame`, whose buffers are reused when they already
/// have the image's size: a sequence of frames (a benchmark, an animation)
/// then spends its time tracing and shading, not having the system zero
/// fresh pages for every frame.
pub fn render_into<T: Tracer + ?Sized>(
    tracer: &T,
    camera: &Camera,
    lights: &[PointLight],
    opts: &RenderOptions,
    frame: &mut Frame,
) -> Result<(), RenderError> {
    let lights = Lights {
        points: lights,
        areas: &[],
    };
    render_scene_into(tracer, &OwnShadows(tracer), camera, &lights, opts, frame)
}

/// [`render_scene_with`] into `frame` (see [`render_into`]).
pub fn render_scene_into<T: Tracer + ?Sized, S: ShadowTracer + ?Sized>(
    tracer: &T,
    shadow: &S,
    camera: &Camera,
    lights: &Lights<'_>,
    opts: &RenderOptions,
    frame: &mut Frame,
) -> Result<(), RenderError> {
    let (w, h) = (opts.width, opts.height);
    if w == 0 || h == 0 {
        return Err(RenderError::EmptyImage {
            width: w,
            height: h,
        });
    }
    let t0 = Instant::now();
    let mesh = tracer.mesh();
    let view = Viewpoint::locate(mesh, camera.position).map_err(|source| RenderError::Camera {
        position: camera.position,
        source,
    })?;
    // Lights are located from the camera's tet, or from tet 0 when the
    // camera is outside the mesh.
    let start = match view {
        Viewpoint::Inside(t) => t,
        Viewpoint::Outside(_) => 0,
    };
    let mut points = Vec::with_capacity(lights.points.len());
    for (index, light) in lights.points.iter().enumerate() {
        // Located only when shadow rays need the star.
        let target = if opts.shadows && !opts.headlight {
            LightTarget::locate_or_outside(mesh, light.position, start).map_err(|source| {
                RenderError::Light {
                    index,
                    position: light.position,
                    source,
                }
            })?
        } else {
            LightTarget::outside(light.position)
        };
        points.push((light, target));
    }
    let frame_lights = FrameLights {
        points,
        areas: lights.areas,
    };
    let cam = PinholeCamera::new(camera, w, h, opts.pixel_centers);
    let ao_len = if opts.ambient_occlusion && !opts.headlight {
        ao_length(mesh, opts.ao_share)
    } else {
        0.0
    };
    let n = (w * h) as usize;
    // Every pixel is written below: buffers of the right size are reused
    // as they are.
    if frame.color.len() != n || frame.tets.len() != n || frame.triangle.len() != n {
        frame.color = vec![Vec3::ZERO; n];
        frame.tets = vec![0; n];
        frame.triangle = vec![u32::MAX; n];
    }
    frame.width = w;
    frame.height = h;
    // One task per band of TILE rows: its tiles are traced in turn and
    // shaded straight into the band's rows of the frame (contiguous), so no
    // per-pixel record is collected and copied afterwards.
    let band = (TILE * w) as usize;
    let stats = frame
        .color
        .par_chunks_mut(band)
        .zip(frame.tets.par_chunks_mut(band))
        .zip(frame.triangle.par_chunks_mut(band))
        .enumerate()
        .map(|(ty, ((color, tets), triangle))| {
            let mut stats = FrameStats::default();
            let mut rays = Vec::with_capacity((TILE * TILE) as usize);
            let mut ids = Vec::with_capacity((TILE * TILE) as usize);
            let mut outcomes = Vec::with_capacity((TILE * TILE) as usize);
            let mut shadows = TileShadows::default();
            let mut ao = TileAo::default();
            let y0 = ty as u32 * TILE;
            let y1 = (y0 + TILE).min(h);
            for x0 in (0..w).step_by(TILE as usize) {
                rays.clear();
                ids.clear();
                for j in y0..y1 {
                    for i in x0..(x0 + TILE).min(w) {
                        rays.push(cam.ray(i, j));
                        ids.push(j * w + i);
                    }
                }
                outcomes.clear();
                outcomes.resize(rays.len(), TraceOutcome::Miss { tets_visited: 0 });
                let clock = Instant::now();
                view.trace_batch(tracer, &rays, &mut outcomes);
                let clock = lap(clock, &mut stats.primary_trace_ms);
                ao.trace(
                    tracer, mesh, &rays, &outcomes, &ids, ao_len, opts, &mut stats,
                );
                let clock = lap(clock, &mut stats.ao_trace_ms);
                shadows.trace(shadow, mesh, &rays, &outcomes, &frame_lights, opts);
                lap(clock, &mut stats.shadow_trace_ms);
                for (at, ((ray, o), &k)) in rays.iter().zip(&outcomes).zip(&ids).enumerate() {
                    let found = shadows.of(at);
                    let occlusion = ao.of(at);
                    let p = shade(
                        shadow,
                        mesh,
                        ray,
                        o,
                        k,
                        &frame_lights,
                        (found, occlusion),
                        opts,
                    );
                    stats.shadow_trace_ms += p.area_ms;
                    let local = k as usize - (y0 * w) as usize;
                    color[local] = p.color;
                    tets[local] = p.tets;
                    triangle[local] = p.triangle;
                    stats.rays += 1;
                    stats.hits += p.hit as u64;
                    stats.failures += p.failed as u64;
                    stats.tets_visited += p.tets as u64;
                    stats.shadow_rays += p.shadow_rays as u64;
                    stats.shadow_failures += p.shadow_failures as u64;
                }
            }
            stats
        })
        .reduce(FrameStats::default, FrameStats::sum);
    frame.stats = stats;
    frame.stats.ms = t0.elapsed().as_secs_f64() * 1e3;
    Ok(())
}

/// Adds the time since `clock` to `ms` and returns the time now.
fn lap(clock: Instant, ms: &mut f64) -> Instant {
    let now = Instant::now();
    *ms += (now - clock).as_secs_f64() * 1e3;
    now
}

/// Per-pixel seed of the area-light jitter: the frame seed mixed with the
/// pixel index (SplitMix64's finaliser).
fn pixel_seed(seed: u64, pixel: u32) -> u64 {
    let mut z = seed ^ (pixel as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Shades one pixel: its primary ray's outcome `out`, with `found` the
/// outcomes of its shadow rays toward the point lights ([`TileShadows`])
/// and of its AO ray ([`TileAo`]); area lights sample their shadow rays
/// here, one by one.
#[allow(clippy::too_many_arguments)]
fn shade<S: ShadowTracer + ?Sized>(
    shadow: &S,
    mesh: &TetMesh,
    ray: &Ray,
    out: &TraceOutcome,
    pixel: u32,
    lights: &FrameLights<'_>,
    (found, occlusion): (&[Shadow], Ao),
    opts: &RenderOptions,
) -> Pixel {
    let mut px = Pixel {
        color: Vec3::splat(opts.background),
        tets: out.tets_visited(),
        triangle: u32::MAX,
        hit: false,
        failed: out.is_failure(),
        shadow_rays: 0,
        shadow_failures: 0,
        area_ms: 0.0,
    };
    let TraceOutcome::Hit(hit) = out else {
        return px;
    };
    px.hit = true;
    px.triangle = hit.triangle;
    let n = shading_normal(mesh, hit);
    let p = ray.at(hit.t);
    if opts.headlight {
        px.color = Vec3::splat(n.dot(-ray.direction.normalize()).abs());
        return px;
    }
    let mut c = Vec3::ZERO;
    for ((light, _), &found) in lights.points.iter().zip(found) {
        let cos = light_cos(n, p, light);
        if cos <= 0.0 {
            continue;
        }
        if opts.shadows {
            debug_assert_ne!(
                found,
                Shadow::NotCast,
                "a ray is cast for every light in front"
            );
            px.shadow_rays += 1;
            match found {
                Shadow::Occluded => continue,
                Shadow::Failed => px.shadow_failures += 1,
                Shadow::Lit | Shadow::NotCast => {}
            }
        }
        c += light.color * light.intensity * cos;
    }
    let clock = (opts.shadows && !lights.areas.is_empty()).then(Instant::now);
    for (k, light) in lights.areas.iter().enumerate() {
        let seed = pixel_seed(
            opts.seed ^ (k as u64).wrapping_mul(0xD6E8_FEB8_6659_FD93),
            pixel,
        );
        let e = if opts.shadows {
            irradiance(shadow, hit, n, light, opts.area_samples, seed)
        } else {
            irradiance_unshadowed(mesh, hit, n, light, opts.area_samples, seed)
        };
        px.shadow_rays += e.rays;
        px.shadow_failures += e.failures;
        c += e.irradiance * std::f32::consts::FRAC_1_PI;
    }
    if let Some(clock) = clock {
        lap(clock, &mut px.area_ms);
    }
    if matches!(occlusion, Ao::Open | Ao::Failed) {
        c += Vec3::splat(AO_AMBIENT);
    }
    px.color = c;
    px
}

fn write_png(path: &Path, w: u32, h: u32, rgb: &[u8]) -> Result<(), RenderError> {
    let name = path.display().to_string();
    let file = std::fs::File::create(path).map_err(|source| RenderError::Io {
        path: name.clone(),
        source,
    })?;
    let mut buf = std::io::BufWriter::new(file);
    let mut enc = png::Encoder::new(&mut buf, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let png_err = |source| RenderError::Png {
        path: name.clone(),
        source,
    };
    let mut writer = enc.write_header().map_err(png_err)?;
    writer.write_image_data(rgb).map_err(png_err)?;
    writer.finish().map_err(png_err)?;
    buf.flush().map_err(|source| RenderError::Io {
        path: name.clone(),
        source,
    })
}

impl Frame {
    /// 8-bit RGB bytes of the colour image (`clamp(c, 0, 1)·255`, no gamma,
    /// like neptun).
    pub fn rgb8(&self) -> Vec<u8> {
        self.color
            .iter()
            .flat_map(|c| c.to_array())
            .map(|x| (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8)
            .collect()
    }

    /// 8-bit RGB bytes of the heat map: tets visited per pixel on a
    /// blue → green → red ramp, scaled to `max` (the frame's maximum when
    /// `None`).
    pub fn heatmap_rgb8(&self, max: Option<u32>) -> Vec<u8> {
        let m = max
            .unwrap_or_else(|| self.tets.iter().copied().max().unwrap_or(1))
            .max(1) as f32;
        self.tets
            .iter()
            .flat_map(|&t| {
                let x = (t as f32 / m).clamp(0.0, 1.0);
                let r = (2.0 * x - 1.0).clamp(0.0, 1.0);
                let g = 1.0 - (2.0 * x - 1.0).abs();
                let b = (1.0 - 2.0 * x).clamp(0.0, 1.0);
                [r, g, b].map(|c| (c * 255.0 + 0.5) as u8)
            })
            .collect()
    }

    /// Writes the colour image as PNG.
    pub fn save_png(&self, path: &Path) -> Result<(), RenderError> {
        write_png(path, self.width, self.height, &self.rgb8())
    }

    /// Writes the tets-visited heat map as PNG (see [`Frame::heatmap_rgb8`]).
    pub fn save_heatmap(&self, path: &Path, max: Option<u32>) -> Result<(), RenderError> {
        write_png(path, self.width, self.height, &self.heatmap_rgb8(max))
    }
}
