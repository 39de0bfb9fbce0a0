//! Area lights and mesh lights sampled by shadow rays (Aman et al.
//! 2022, §6: "handling mesh lights is straightforward by using the proposed
//! traversal methods").
//!
//! An [`AreaLight`] is a set of emitting pieces (parallelograms or
//! triangles) with one emitted radiance `L_e`. Each piece is either *free*
//! (not part of the tetrahedralization: a light quad added to a scene) or a
//! *mesh* piece (a constrained face of the mesh, i.e. a scene triangle that
//! glows: [`AreaLight::from_mesh`]).
//!
//! # Estimator
//!
//! The irradiance at a point `p` with unit normal `n` is
//! `E = ∫_A L_e V(p, y) cos θ_p cos θ_y / |y − p|² dA(y)`, with
//! `cos θ_p = n · ω`, `cos θ_y = −n_y · ω` (`ω` the unit direction from `p`
//! to `y`, `n_y` the light's normal; a one-sided light emits only towards
//! `n_y`, a two-sided one towards both sides), and `V` the visibility.
//! [`irradiance`] estimates it with `N` samples distributed uniformly by area,
//! stratified over the unit square (`sx × sy` cells, `sx = ⌈√N⌉`,
//! `sy = ⌈N / sx⌉`, one jittered sample per cell; the first coordinate
//! picks the piece through the cumulative areas, so strata stay contiguous
//! on the light):
//! `E ≈ (A / N) Σ L_e V cos⁺θ_p cos⁺θ_y / d²` (`A` the total area). The jitter
//! comes from a deterministic generator seeded by the caller (the renderer
//! mixes its seed with the pixel index), so images are reproducible.
//! A white Lambertian surface reflects `E / π` (what the renderer adds).
//!
//! # Visibility of a sample
//!
//! The shadow ray starts on the hit face, in the tet on the sample's side
//! ([`crate::secondary::start_beyond`]), towards the sample `y` (`t = 1` at
//! `y`):
//!
//! * free piece: occluded iff the walk crosses a constrained face at
//!   `t ≤ 1` (`t_max = 1`);
//! * mesh piece: the walk runs to its first constrained face
//!   (`t_max = ∞`); the sample is visible iff that face belongs to the
//!   sampled scene triangle, or lies at `t ≥ 1 − 10⁻⁴` (at the sample up to
//!   rounding: a coplanar neighbour face of the light), or the walk leaves
//!   the mesh. No epsilon offset is needed at either end: the light's own
//!   face *is* the stopping face.
//!
//! Samples with a zero geometric term (behind the surface or the light)
//! cast no ray. A failed walk counts as visible and is reported in
//! [`Irradiance::failures`].

use glam::{DVec3, Vec3};
use tet_core::TetMesh;
use tet_core::synthetic::SplitMix64;
use thiserror::Error;

use crate::ray::{Hit, Ray, TraceOutcome};
use crate::secondary::{ShadowTracer, hit_point, start_beyond};

/// Why an area light could not be built.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum AreaLightError {
    /// A piece has a non-finite coordinate or zero area.
    #[error("area light piece {piece} is degenerate (zero area or non-finite)")]
    Degenerate {
        /// Index of the piece.
        piece: usize,
    },
    /// The light has no pieces.
    #[error("area light has no pieces")]
    Empty,
    /// No constrained face of the mesh belongs to this scene triangle.
    #[error("scene triangle {triangle} has no constrained face in the mesh")]
    UnknownTriangle {
        /// The triangle id asked for.
        triangle: u32,
    },
    /// The radiance is negative or non-finite.
    #[error("area light radiance {radiance:?} is negative or non-finite")]
    BadRadiance {
        /// The radiance given.
        radiance: Vec3,
    },
}

/// The shape of one emitting piece.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// `corner + u·edge_u + v·edge_v`, `u, v ∈ [0, 1]`; normal
    /// `edge_u × edge_v`.
    Parallelogram {
        /// One corner.
        corner: Vec3,
        /// First edge.
        edge_u: Vec3,
        /// Second edge.
        edge_v: Vec3,
    },
    /// A triangle; normal by the right-hand rule on the vertex order.
    Triangle([Vec3; 3]),
}

/// One emitting piece.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Piece {
    /// Geometry.
    pub shape: Shape,
    /// Scene triangle id when the piece is a constrained face of the mesh
    /// (a mesh light), `None` for a free piece.
    pub triangle: Option<u32>,
    area: f64,
    normal: Vec3,
}

impl Piece {
    fn new(shape: Shape, triangle: Option<u32>, index: usize) -> Result<Piece, AreaLightError> {
        let (a, b, o) = match shape {
            Shape::Parallelogram {
                corner,
                edge_u,
                edge_v,
            } => (edge_u.as_dvec3(), edge_v.as_dvec3(), corner),
            Shape::Triangle(v) => ((v[1] - v[0]).as_dvec3(), (v[2] - v[0]).as_dvec3(), v[0]),
        };
        let c = a.cross(b);
        let scale = if matches!(shape, Shape::Triangle(_)) {
            0.5
        } else {
            1.0
        };
        let area = c.length() * scale;
        let finite = o.is_finite() && a.is_finite() && b.is_finite();
        if !finite || area <= 0.0 || !area.is_finite() {
            return Err(AreaLightError::Degenerate { piece: index });
        }
        Ok(Piece {
            shape,
            triangle,
            area,
            normal: (c / c.length()).as_vec3(),
        })
    }

    /// Area of the piece.
    pub fn area(&self) -> f64 {
        self.area
    }

    /// Unit emitting normal.
    pub fn normal(&self) -> Vec3 {
        self.normal
    }

    /// The point at `(u, v) ∈ [0, 1]²`, uniform by area (triangles use the
    /// square-root warp `(1 − √u, √u (1 − v), √u v)`).
    pub fn point(&self, u: f64, v: f64) -> Vec3 {
        match self.shape {
            Shape::Parallelogram {
                corner,
                edge_u,
                edge_v,
            } => (corner.as_dvec3() + edge_u.as_dvec3() * u + edge_v.as_dvec3() * v).as_vec3(),
            Shape::Triangle(t) => {
                let s = u.sqrt();
                let w = [1.0 - s, s * (1.0 - v), s * v];
                let p: DVec3 =
                    t[0].as_dvec3() * w[0] + t[1].as_dvec3() * w[1] + t[2].as_dvec3() * w[2];
                p.as_vec3()
            }
        }
    }
}

/// An area light: emitting pieces with one radiance.
#[derive(Clone, Debug, PartialEq)]
pub struct AreaLight {
    pieces: Vec<Piece>,
    /// Cumulative areas (`cdf[i]` = area of pieces `0..=i`).
    cdf: Vec<f64>,
    /// Emitted radiance (linear RGB).
    pub radiance: Vec3,
    /// Emits on both sides (else only towards each piece's normal).
    pub two_sided: bool,
}

impl AreaLight {
    /// A light made of the given pieces (free unless their `triangle` says
    /// otherwise).
    pub fn new(
        shapes: impl IntoIterator<Item = (Shape, Option<u32>)>,
        radiance: Vec3,
    ) -> Result<Self, AreaLightError> {
        if !radiance.is_finite() || radiance.min_element() < 0.0 {
            return Err(AreaLightError::BadRadiance { radiance });
        }
        let pieces = shapes
            .into_iter()
            .enumerate()
            .map(|(i, (s, t))| Piece::new(s, t, i))
            .collect::<Result<Vec<_>, _>>()?;
        if pieces.is_empty() {
            return Err(AreaLightError::Empty);
        }
        let mut acc = 0.0;
        let cdf = pieces
            .iter()
            .map(|p| {
                acc += p.area;
                acc
            })
            .collect();
        Ok(AreaLight {
            pieces,
            cdf,
            radiance,
            two_sided: false,
        })
    }

    /// A free parallelogram light (e.g. a quad lamp), emitting towards
    /// `edge_u × edge_v`.
    pub fn parallelogram(
        corner: Vec3,
        edge_u: Vec3,
        edge_v: Vec3,
        radiance: Vec3,
    ) -> Result<Self, AreaLightError> {
        Self::new(
            [(
                Shape::Parallelogram {
                    corner,
                    edge_u,
                    edge_v,
                },
                None,
            )],
            radiance,
        )
    }

    /// A mesh light: every constrained face of `mesh` that belongs to one of
    /// the scene triangles `triangles`, emitting towards the triangle's
    /// winding normal (see [`AreaLight::with_two_sided`]).
    pub fn from_mesh(
        mesh: &TetMesh,
        triangles: &[u32],
        radiance: Vec3,
    ) -> Result<Self, AreaLightError> {
        let mut shapes = Vec::new();
        for &tri in triangles {
            let before = shapes.len();
            for cf in mesh.constrained.iter().filter(|cf| cf.triangle == tri) {
                let v = cf.vertices.map(|i| mesh.points[i as usize]);
                shapes.push((Shape::Triangle(v), Some(tri)));
            }
            if shapes.len() == before {
                return Err(AreaLightError::UnknownTriangle { triangle: tri });
            }
        }
        Self::new(shapes, radiance)
    }

    /// Sets whether the light emits on both sides.
    pub fn with_two_sided(mut self, two_sided: bool) -> Self {
        self.two_sided = two_sided;
        self
    }

    /// The pieces.
    pub fn pieces(&self) -> &[Piece] {
        &self.pieces
    }

    /// Total area.
    pub fn area(&self) -> f64 {
        self.cdf.last().copied().unwrap_or(0.0)
    }

    /// The sample at `(u, v) ∈ [0, 1)²`: `u` picks the piece through the
    /// cumulative areas and is rescaled within it.
    pub fn sample_at(&self, u: f64, v: f64) -> LightSample {
        let total = self.area();
        let x = u.clamp(0.0, 1.0) * total;
        let i = self
            .cdf
            .partition_point(|&c| c <= x)
            .min(self.pieces.len() - 1);
        let lo = if i == 0 { 0.0 } else { self.cdf[i - 1] };
        let piece = &self.pieces[i];
        let u2 = ((x - lo) / piece.area).clamp(0.0, 1.0);
        LightSample {
            point: piece.point(u2, v.clamp(0.0, 1.0)),
            normal: piece.normal,
            triangle: piece.triangle,
        }
    }

    /// The stratified, jittered samples of the module docs: `sx·sy ≥ n`
    /// samples (`n ≥ 1`), jittered by a generator seeded with `seed`.
    pub fn samples(&self, n: u32, seed: u64) -> Vec<LightSample> {
        let (sx, sy) = strata(n);
        let mut rng = SplitMix64(seed);
        let mut out = Vec::with_capacity((sx * sy) as usize);
        for j in 0..sy {
            for i in 0..sx {
                let u = (i as f64 + rng.next_f64()) / sx as f64;
                let v = (j as f64 + rng.next_f64()) / sy as f64;
                out.push(self.sample_at(u, v));
            }
        }
        out
    }
}

/// The stratification grid for `n` samples: `(⌈√n⌉, ⌈n / ⌈√n⌉⌉)`.
pub fn strata(n: u32) -> (u32, u32) {
    let n = n.max(1);
    let sx = (n as f64).sqrt().ceil() as u32;
    (sx, n.div_ceil(sx))
}

/// A point on an area light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// Position.
    pub point: Vec3,
    /// Unit emitting normal of its piece.
    pub normal: Vec3,
    /// Scene triangle id of its piece (mesh lights).
    pub triangle: Option<u32>,
}

/// What [`irradiance`] measured.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Irradiance {
    /// Estimated irradiance `E` (linear RGB).
    pub irradiance: Vec3,
    /// Samples taken.
    pub samples: u32,
    /// Samples with a non-zero geometric term (each cast one shadow ray).
    pub rays: u32,
    /// Of those, the visible ones.
    pub visible: u32,
    /// Shadow walks that failed (counted as visible).
    pub failures: u32,
}

impl Irradiance {
    /// Visible fraction of the samples that cast a ray (1 when none did).
    pub fn unoccluded_fraction(&self) -> f64 {
        if self.rays == 0 {
            1.0
        } else {
            self.visible as f64 / self.rays as f64
        }
    }
}

/// Geometric term `cos⁺θ_p cos⁺θ_y / d²` of a sample seen from `p` with
/// normal `n` (0 behind either surface).
pub fn geometry(p: Vec3, n: Vec3, s: &LightSample, two_sided: bool) -> f64 {
    let d = s.point.as_dvec3() - p.as_dvec3();
    let d2 = d.length_squared();
    if d2 <= 0.0 || !d2.is_finite() {
        return 0.0;
    }
    let w = d / d2.sqrt();
    let cp = n.as_dvec3().dot(w);
    let mut cy = -s.normal.as_dvec3().dot(w);
    if two_sided {
        cy = cy.abs();
    }
    if cp <= 0.0 || cy <= 0.0 {
        0.0
    } else {
        cp * cy / d2
    }
}

/// Visibility of sample `s` from the hit point of `hit` (rule of the module
/// docs): `Some(visible)`, or `None` when the walk failed.
pub fn sample_visible<S: ShadowTracer + ?Sized>(
    shadow: &S,
    hit: &Hit,
    s: &LightSample,
) -> Option<bool> {
    let mesh = shadow.mesh();
    let p = hit_point(mesh, hit);
    let dir = s.point - p;
    let Some(start) = start_beyond(mesh, hit.face, dir) else {
        // No tet on the sample's side (beyond the mesh boundary) or the
        // sample lies in the hit face's plane (zero geometric term).
        return Some(true);
    };
    let ray = Ray {
        origin: p,
        direction: dir,
        t_min: 0.0,
        t_max: if s.triangle.is_some() {
            f32::INFINITY
        } else {
            1.0
        },
    };
    match shadow.trace_until(&ray, start, &[]) {
        TraceOutcome::Miss { .. } => Some(true),
        TraceOutcome::Hit(h) => Some(match s.triangle {
            None => false,
            Some(tri) => h.triangle == tri || h.t >= 1.0 - 1e-4,
        }),
        TraceOutcome::Failed { .. } => None,
    }
}

/// Estimates the irradiance from `light` at the hit point of `hit` with unit
/// normal `n`, with `n` stratified samples jittered by `seed` (see the module
/// docs). Samples on the hit's own scene triangle are skipped (a surface does
/// not light itself).
pub fn irradiance<S: ShadowTracer + ?Sized>(
    shadow: &S,
    hit: &Hit,
    n: Vec3,
    light: &AreaLight,
    samples: u32,
    seed: u64,
) -> Irradiance {
    estimate(shadow.mesh(), Some(shadow), hit, n, light, samples, seed)
}

/// [`irradiance`] without shadow rays (every sample visible): the
/// renderer's area lighting when shadows are off.
pub fn irradiance_unshadowed(
    mesh: &TetMesh,
    hit: &Hit,
    n: Vec3,
    light: &AreaLight,
    samples: u32,
    seed: u64,
) -> Irradiance {
    estimate::<crate::secondary::MeshWalker>(mesh, None, hit, n, light, samples, seed)
}

fn estimate<S: ShadowTracer + ?Sized>(
    mesh: &TetMesh,
    shadow: Option<&S>,
    hit: &Hit,
    n: Vec3,
    light: &AreaLight,
    samples: u32,
    seed: u64,
) -> Irradiance {
    let p = hit_point(mesh, hit);
    let list = light.samples(samples, seed);
    let mut out = Irradiance {
        samples: list.len() as u32,
        ..Default::default()
    };
    let mut sum = 0.0;
    for s in &list {
        if s.triangle == Some(hit.triangle) {
            continue;
        }
        let g = geometry(p, n, s, light.two_sided);
        if g <= 0.0 {
            continue;
        }
        let vis = match shadow {
            None => true,
            Some(shadow) => {
                out.rays += 1;
                sample_visible(shadow, hit, s).unwrap_or_else(|| {
                    out.failures += 1;
                    true
                })
            }
        };
        if vis {
            out.visible += 1;
            sum += g;
        }
    }
    let scale = light.area() / list.len() as f64 * sum;
    out.irradiance = light.radiance * scale as f32;
    out
}
