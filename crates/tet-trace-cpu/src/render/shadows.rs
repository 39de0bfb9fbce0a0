//! A render tile's shadow rays toward the point lights, cast from its
//! primary hits and traced light by light in one batch each.

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::scene::PointLight;

use super::{FrameLights, RenderOptions, shading_normal};
use crate::ray::{Ray, TraceOutcome};
use crate::secondary::{ShadowTracer, shadow_ray};
use crate::walk::Start;

/// What the shadow ray of a pixel toward one point light found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Shadow {
    /// No ray cast: shadows off, no hit, or the light behind the surface.
    NotCast,
    /// Unoccluded: the walk reached the light (or left the mesh), or no
    /// tet lies on the light's side of the hit face (no ray to walk).
    Lit,
    /// A constrained face lies between the hit point and the light.
    Occluded,
    /// The walk failed (the pixel counts as lit).
    Failed,
}

/// The Lambert cosine of point light `light` at surface point `p` with
/// normal `n` (0 when the light is behind the surface).
pub(super) fn light_cos(n: Vec3, p: Vec3, light: &PointLight) -> f32 {
    let l = (light.position - p).normalize_or_zero();
    n.dot(l).clamp(0.0, 1.0)
}

/// The shadow rays of one tile toward one point light, in one batch.
#[derive(Default)]
struct LightRays {
    rays: Vec<Ray>,
    starts: Vec<Start>,
    /// The tile pixel of each ray.
    pixels: Vec<usize>,
    out: Vec<TraceOutcome>,
}

/// A tile's shadow rays toward the point lights: the rays `shade` casts
/// (one per hit pixel and light in front of its surface, from
/// [`shadow_ray`]), traced light by light in one batch each
/// ([`ShadowTracer::trace_until_batch`]: a tet kernel walks them side by
/// side, as it walks the primary rays), and what each found. The buffers
/// are reused from tile to tile.
#[derive(Default)]
pub(super) struct TileShadows {
    per_light: Vec<LightRays>,
    /// `found[pixel · lights + light]`.
    found: Vec<Shadow>,
    lights: usize,
}

impl TileShadows {
    /// Casts and traces the shadow rays of the tile whose primary `rays`
    /// had `outcomes` (nothing without [`RenderOptions::shadows`], or with
    /// [`RenderOptions::headlight`]).
    pub(super) fn trace<S: ShadowTracer + ?Sized>(
        &mut self,
        shadow: &S,
        mesh: &TetMesh,
        rays: &[Ray],
        outcomes: &[TraceOutcome],
        lights: &FrameLights<'_>,
        opts: &RenderOptions,
    ) {
        let nl = lights.points.len();
        self.lights = nl;
        self.found.clear();
        self.found.resize(rays.len() * nl, Shadow::NotCast);
        if !opts.shadows || opts.headlight || nl == 0 {
            return;
        }
        self.per_light.resize_with(nl, LightRays::default);
        for batch in &mut self.per_light {
            batch.rays.clear();
            batch.starts.clear();
            batch.pixels.clear();
        }
        for (k, (ray, o)) in rays.iter().zip(outcomes).enumerate() {
            let TraceOutcome::Hit(hit) = o else {
                continue;
            };
            let n = shading_normal(mesh, hit);
            let p = ray.at(hit.t);
            for (li, (light, _)) in lights.points.iter().enumerate() {
                if light_cos(n, p, light) <= 0.0 {
                    continue;
                }
                match shadow_ray(mesh, hit, light.position) {
                    Some((r, s)) => {
                        let batch = &mut self.per_light[li];
                        batch.rays.push(r);
                        batch.starts.push(s);
                        batch.pixels.push(k);
                    }
                    None => self.found[k * nl + li] = Shadow::Lit,
                }
            }
        }
        for (li, ((_, target), batch)) in lights.points.iter().zip(&mut self.per_light).enumerate()
        {
            batch.out.clear();
            batch
                .out
                .resize(batch.rays.len(), TraceOutcome::Miss { tets_visited: 0 });
            shadow.trace_until_batch(&batch.rays, &batch.starts, target.tets(), &mut batch.out);
            for (&k, o) in batch.pixels.iter().zip(&batch.out) {
                self.found[k * nl + li] = match o {
                    TraceOutcome::Hit(_) => Shadow::Occluded,
                    TraceOutcome::Failed { .. } => Shadow::Failed,
                    TraceOutcome::Miss { .. } => Shadow::Lit,
                };
            }
        }
    }

    /// What tile pixel `k`'s shadow rays found, light by light.
    pub(super) fn of(&self, k: usize) -> &[Shadow] {
        &self.found[k * self.lights..(k + 1) * self.lights]
    }
}
