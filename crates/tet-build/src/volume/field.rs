//! Analytic scalar fields, evaluated in `f64` at the mesh points and stored
//! as `f32`:
//!
//! * [`AnalyticField::Linear`]: `a · p + b` — its isosurfaces are exact
//!   planes, and linear interpolation inside a tet reproduces it exactly, so
//!   a traced isosurface can be checked against a ray–plane intersection;
//! * [`AnalyticField::Ellipsoid`]: `Σ ((p − c)ᵢ / rᵢ)²`, isovalue 1 is an
//!   ellipsoid;
//! * [`AnalyticField::MarschnerLobb`]: the Marschner–Lobb test signal
//!   (Marschner and Lobb 1994), standard parameters `f_M = 6`, `α = 0.25`,
//!   on `[-1, 1]³`, values in `[0, 1]`, usual isovalue 0.5;
//! * [`AnalyticField::Gaussians`]: a sum of isotropic Gaussians, e.g. one on
//!   each of the 60 vertices of a truncated icosahedron ([`c60_vertices`],
//!   the "bucky ball" molecule C60);
//! * [`AnalyticField::MovingGaussian`]: a time series — a Gaussian blob
//!   going once round a circle over the steps, on top of a travelling
//!   plane wave;
//! * [`AnalyticField::Sum`]: the sum of several fields.

use std::f64::consts::PI;

use glam::{DVec3, Vec3};

/// A scalar field defined by a formula; `time` is the step's phase in
/// `[0, 1)` (`step / steps`), ignored by the static fields.
#[derive(Clone, Debug, PartialEq)]
pub enum AnalyticField {
    /// `gradient · p + offset`.
    Linear {
        /// The constant gradient `a`.
        gradient: DVec3,
        /// The value `b` at the origin.
        offset: f64,
    },
    /// `Σ ((p − center)ᵢ / radiiᵢ)²`.
    Ellipsoid {
        /// The centre.
        center: DVec3,
        /// Semi-axes (each > 0).
        radii: DVec3,
    },
    /// The Marschner–Lobb signal of frequency `fm` and modulation `alpha`,
    /// after mapping `[lo, hi]` onto `[-1, 1]³`.
    MarschnerLobb {
        /// `f_M` (standard: 6).
        fm: f64,
        /// `α` (standard: 0.25).
        alpha: f64,
        /// Domain corner mapped to `(-1, -1, -1)`.
        lo: DVec3,
        /// Domain corner mapped to `(1, 1, 1)`.
        hi: DVec3,
    },
    /// `Σ weight · exp(−|p − cᵢ|² / (2 σ²))`.
    Gaussians {
        /// The centres.
        centers: Vec<DVec3>,
        /// Standard deviation σ (> 0).
        sigma: f64,
        /// Height of each Gaussian.
        weight: f64,
    },
    /// `exp(−|p − c(t)|² / (2 σ²)) + wave · sin(2π (k · p − t))` with
    /// `c(t) = center + radius (cos 2πt, sin 2πt, 0)`.
    MovingGaussian {
        /// Centre of the circle the blob moves on.
        center: DVec3,
        /// Radius of that circle.
        radius: f64,
        /// Standard deviation of the blob.
        sigma: f64,
        /// Amplitude of the travelling wave.
        wave: f64,
        /// Wave vector `k` (cycles per unit length along it).
        wave_vector: DVec3,
    },
    /// The sum of the parts.
    Sum(Vec<AnalyticField>),
}

impl AnalyticField {
    /// The standard Marschner–Lobb field on the domain `[lo, hi]`.
    pub fn marschner_lobb(lo: Vec3, hi: Vec3) -> AnalyticField {
        AnalyticField::MarschnerLobb {
            fm: 6.0,
            alpha: 0.25,
            lo: lo.as_dvec3(),
            hi: hi.as_dvec3(),
        }
    }

    /// Gaussians of height 1 and width `sigma` on the C60 vertices scaled
    /// to circumradius `radius` about `center`.
    pub fn bucky(center: DVec3, radius: f64, sigma: f64) -> AnalyticField {
        let unit = c60_vertices();
        let r0 = unit[0].length();
        AnalyticField::Gaussians {
            centers: unit.iter().map(|v| center + *v * (radius / r0)).collect(),
            sigma,
            weight: 1.0,
        }
    }

    /// The value at `p` at phase `time` (in `[0, 1)`).
    pub fn eval(&self, p: DVec3, time: f64) -> f64 {
        match self {
            AnalyticField::Linear { gradient, offset } => gradient.dot(p) + offset,
            AnalyticField::Ellipsoid { center, radii } => ((p - *center) / *radii).length_squared(),
            AnalyticField::MarschnerLobb { fm, alpha, lo, hi } => {
                let q = (p - *lo) / (*hi - *lo) * 2.0 - DVec3::ONE;
                let r = (q.x * q.x + q.y * q.y).sqrt();
                let rho_r = (2.0 * PI * fm * (PI * r / 2.0).cos()).cos();
                (1.0 - (PI * q.z / 2.0).sin() + alpha * (1.0 + rho_r)) / (2.0 * (1.0 + alpha))
            }
            AnalyticField::Gaussians {
                centers,
                sigma,
                weight,
            } => {
                let k = 1.0 / (2.0 * sigma * sigma);
                // Beyond 6σ a Gaussian adds less than 1.6e-8: skipped.
                let cut = (6.0 * sigma) * (6.0 * sigma);
                centers
                    .iter()
                    .map(|c| c.distance_squared(p))
                    .filter(|&d2| d2 < cut)
                    .map(|d2| weight * (-d2 * k).exp())
                    .sum()
            }
            AnalyticField::MovingGaussian {
                center,
                radius,
                sigma,
                wave,
                wave_vector,
            } => {
                let angle = 2.0 * PI * time;
                let c = *center + *radius * DVec3::new(angle.cos(), angle.sin(), 0.0);
                let blob = (-c.distance_squared(p) / (2.0 * sigma * sigma)).exp();
                blob + wave * (2.0 * PI * (wave_vector.dot(p) - time)).sin()
            }
            AnalyticField::Sum(parts) => parts.iter().map(|f| f.eval(p, time)).sum(),
        }
    }

    /// The value at an `f32` point, as the `f32` stored in a field.
    pub fn eval_f32(&self, p: Vec3, time: f64) -> f32 {
        self.eval(p.as_dvec3(), time) as f32
    }
}

/// The 60 vertices of a truncated icosahedron with edge length 2: the even
/// permutations of `(0, ±1, ±3φ)`, `(±1, ±(2 + φ), ±2φ)` and
/// `(±φ, ±2, ±(2φ + 1))`, φ the golden ratio — the carbon atoms of C60.
pub fn c60_vertices() -> Vec<DVec3> {
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let bases = [
        [0.0, 1.0, 3.0 * phi],
        [1.0, 2.0 + phi, 2.0 * phi],
        [phi, 2.0, 2.0 * phi + 1.0],
    ];
    let mut out = Vec::with_capacity(60);
    for b in bases {
        for signs in 0..8u32 {
            let s = |k: usize| if signs >> k & 1 == 1 { -1.0 } else { 1.0 };
            if (0..3).any(|k| b[k] == 0.0 && signs >> k & 1 == 1) {
                continue; // −0 is the same vertex as +0
            }
            let v = [b[0] * s(0), b[1] * s(1), b[2] * s(2)];
            // The three even (cyclic) permutations.
            for r in 0..3 {
                out.push(DVec3::new(v[r], v[(r + 1) % 3], v[(r + 2) % 3]));
            }
        }
    }
    out
}
