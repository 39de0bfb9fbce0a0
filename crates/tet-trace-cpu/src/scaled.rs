//! The scaled basis of Aman et al. (2022, §4.1, Eq. 1–3), specialised at
//! compile time.
//!
//! With `n` the ray direction, `min`/`max` the indices of its smallest and
//! largest absolute components, `a = min + 1`, `b = min + 2` (mod 3):
//!
//! * Eq. 1: `u_min = 0`, `u_a = n_b / n_max`, `u_b = −n_a / n_max`, so one of
//!   `u_a`, `u_b` is exactly `±1` (the one *not* at `max`) and the other,
//!   `cu`, is a runtime constant;
//! * Eq. 2: `t = n × u`, `v = t / t_k`. The paper divides by `t_other`
//!   (`other = 3 − max − min`), but `t ∝ (−(n_a² + n_b²), n_min n_a,
//!   n_min n_b)` in `(min, a, b)` order, whose `other` component vanishes for
//!   axis-aligned rays; we divide by `t_min` instead (the largest component,
//!   never zero), so `v_min = 1` and `v_a`, `v_b` are small runtime constants;
//! * Eq. 3: `p = (±q_k + cu·q_max, q_min + v_a·q_a + v_b·q_b)` with
//!   `q = P − o`: 3 multiplications and 3 additions per vertex instead of 6
//!   and 4 (plus the 3 subtractions of `q`).
//!
//! The basis is only scaled, not normalised, so the projected points are an
//! affine image of Duff's: exit faces are unchanged. When `u × v` points
//! against `n` the coordinates are swapped to keep exit faces
//! counter-clockwise. The 3 × 2 × 2 cases (`min`, whether `max = b`, swap)
//! are const parameters of [`ScaledF32`]; [`ScaledTracer`] picks the case per
//! ray and calls the monomorphised walk, so the hot loop has no case
//! variables. Watertightness is as in [`crate::walk`]: the projection is a
//! pure function of the vertex and the ray, and the tie rule is the same.

use glam::{DVec3, Vec2, Vec3};
use tet_core::TetMesh;
use tet_core::layout::LayoutError;

use crate::kernel::{LANES, Tracer, WalkTracer};
use crate::lost::{exact_if_lost, exact_where_lost};
use crate::ray::{Failure, Ray, TraceOutcome};
use crate::walk::{DuffF32, Projection, Start, Starts, Topology, trace, trace_interleaved};

/// The compile-time case of a ray direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ScaledCase {
    /// Index of the smallest absolute component.
    pub min: usize,
    /// True when the largest component is at `(min + 2) % 3`.
    pub max_is_b: bool,
    /// True when `(u × v) · n < 0` (coordinates swapped).
    pub swap: bool,
}

/// `(min, max)` of a direction, `max ≠ min`; `None` for a zero or
/// non-finite direction.
fn min_max(n: DVec3) -> Option<(usize, usize)> {
    if !n.is_finite() || n == DVec3::ZERO {
        return None;
    }
    let a = n.abs();
    let min = if a.x <= a.y && a.x <= a.z {
        0
    } else if a.y <= a.z {
        1
    } else {
        2
    };
    let (p, q) = ((min + 1) % 3, (min + 2) % 3);
    let max = if a[p] >= a[q] { p } else { q };
    Some((min, max))
}

/// `(u, v)` of Eq. 1–2 (with the `t_min` fix) in f64.
fn basis(n: DVec3, min: usize, max: usize) -> (DVec3, DVec3) {
    let (a, b) = ((min + 1) % 3, (min + 2) % 3);
    let mut u = DVec3::ZERO;
    u[a] = n[b] / n[max];
    u[b] = -n[a] / n[max];
    let t = n.cross(u);
    (u, t / t[min])
}

impl ScaledCase {
    /// The case of `direction`; `None` for a zero or non-finite direction.
    pub fn of(direction: Vec3) -> Option<ScaledCase> {
        let n = direction.as_dvec3();
        let (min, max) = min_max(n)?;
        let (u, v) = basis(n, min, max);
        Some(ScaledCase {
            min,
            max_is_b: max == (min + 2) % 3,
            swap: u.cross(v).dot(n) < 0.0,
        })
    }
}

/// Eq. 3 projection for one case (see the module docs).
#[derive(Clone, Copy, Debug)]
pub struct ScaledF32<const MIN: usize, const MAX_IS_B: bool, const SWAP: bool> {
    o: Vec3,
    cu: f32,
    va: f32,
    vb: f32,
}

impl<const MIN: usize, const MAX_IS_B: bool, const SWAP: bool> ScaledF32<MIN, MAX_IS_B, SWAP> {
    const A: usize = (MIN + 1) % 3;
    const B: usize = (MIN + 2) % 3;
    const MAX: usize = if MAX_IS_B { Self::B } else { Self::A };
}

impl<const MIN: usize, const MAX_IS_B: bool, const SWAP: bool> Projection
    for ScaledF32<MIN, MAX_IS_B, SWAP>
{
    type P = Vec2;
    crate::walk::simd_face!();
    const NAME: &'static str = "f32-scaled";
    fn setup(ray: &Ray) -> Self {
        let n = ray.direction.as_dvec3();
        let (u, v) = basis(n, MIN, Self::MAX);
        ScaledF32 {
            o: ray.origin,
            cu: u[Self::MAX] as f32,
            va: v[Self::A] as f32,
            vb: v[Self::B] as f32,
        }
    }
    #[inline(always)]
    fn project(&self, p: Vec3) -> Vec2 {
        let q = p - self.o;
        // u = +1 at A when max = B, −1 at B when max = A.
        let unit = if MAX_IS_B { q[Self::A] } else { -q[Self::B] };
        let x = unit + self.cu * q[Self::MAX];
        let y = q[MIN] + self.va * q[Self::A] + self.vb * q[Self::B];
        if SWAP {
            Vec2::new(y, x)
        } else {
            Vec2::new(x, y)
        }
    }
    #[inline(always)]
    fn left(&self, a: Vec2, ia: u32, b: Vec2, ib: u32) -> bool {
        crate::walk::left_f32(a, ia, b, ib)
    }
}

/// Calls `$body` with `$P` bound to the [`ScaledF32`] type of case `$case`.
macro_rules! with_case {
    ($case:expr, $P:ident, $body:expr) => {{
        let c: ScaledCase = $case;
        match (c.min, c.max_is_b, c.swap) {
            (0, false, false) => {
                type $P = ScaledF32<0, false, false>;
                $body
            }
            (0, false, true) => {
                type $P = ScaledF32<0, false, true>;
                $body
            }
            (0, true, false) => {
                type $P = ScaledF32<0, true, false>;
                $body
            }
            (0, true, true) => {
                type $P = ScaledF32<0, true, true>;
                $body
            }
            (1, false, false) => {
                type $P = ScaledF32<1, false, false>;
                $body
            }
            (1, false, true) => {
                type $P = ScaledF32<1, false, true>;
                $body
            }
            (1, true, false) => {
                type $P = ScaledF32<1, true, false>;
                $body
            }
            (1, true, true) => {
                type $P = ScaledF32<1, true, true>;
                $body
            }
            (_, false, false) => {
                type $P = ScaledF32<2, false, false>;
                $body
            }
            (_, false, true) => {
                type $P = ScaledF32<2, false, true>;
                $body
            }
            (_, true, false) => {
                type $P = ScaledF32<2, true, false>;
                $body
            }
            (_, true, true) => {
                type $P = ScaledF32<2, true, true>;
                $body
            }
        }
    }};
}

/// A projected-walk kernel over layout `L` with the specialised scaled
/// basis: the case is chosen per ray (per run of equal cases in a batch).
pub struct ScaledTracer<'m, L> {
    inner: WalkTracer<'m, L, DuffF32>,
}

impl<'m, L: Topology> ScaledTracer<'m, L> {
    /// Wraps a layout tracer (its layout, mesh and step cap are reused).
    pub fn new(inner: WalkTracer<'m, L, DuffF32>) -> Self {
        ScaledTracer { inner }
    }
}

impl<'m> ScaledTracer<'m, tet_core::layout::Tet20Mesh> {
    /// Tet20 with the scaled basis.
    pub fn tet20(mesh: &'m TetMesh) -> Result<Self, LayoutError> {
        Ok(ScaledTracer {
            inner: crate::tet20::Tet20Tracer::<DuffF32>::new(mesh)?,
        })
    }
}

impl<L: Topology> Tracer for ScaledTracer<'_, L> {
    fn name(&self) -> String {
        format!("{}/f32-scaled", self.inner.name)
    }
    fn mesh(&self) -> &TetMesh {
        self.inner.mesh
    }
    fn trace(&self, ray: &Ray, start: Start) -> TraceOutcome {
        let (Some(case), true) = (ScaledCase::of(ray.direction), ray.is_valid()) else {
            return TraceOutcome::Failed {
                failure: Failure::InvalidRay,
                tets_visited: 0,
            };
        };
        let w = &self.inner;
        let out = with_case!(case, P, trace::<P, L>(w.mesh, &w.layout, ray, start, w.cap));
        exact_if_lost(w.mesh, w.cap, ray, start, out)
    }
    fn trace_batch(&self, rays: &[Ray], start: Start, out: &mut [TraceOutcome]) {
        let w = &self.inner;
        let n = rays.len().min(out.len());
        let mut i = 0;
        while i < n {
            let Some(case) = ScaledCase::of(rays[i].direction) else {
                out[i] = self.trace(&rays[i], start);
                i += 1;
                continue;
            };
            let mut j = i + 1;
            while j < n && ScaledCase::of(rays[j].direction) == Some(case) {
                j += 1;
            }
            let (r, o) = (&rays[i..j], &mut out[i..j]);
            with_case!(
                case,
                P,
                trace_interleaved::<P, L, LANES>(w.batch(r, Starts::Same(start), o))
            );
            i = j;
        }
        exact_where_lost(
            w.mesh,
            w.cap,
            &rays[..n],
            Starts::Same(start),
            &mut out[..n],
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tet_core::synthetic::SplitMix64;

    #[test]
    fn scaled_basis_is_orthogonal_with_unit_components() {
        let mut rng = SplitMix64(2);
        let mut dirs: Vec<Vec3> = (0..2000)
            .map(|_| crate::reference::random_direction(&mut rng))
            .collect();
        dirs.extend([
            Vec3::X,
            -Vec3::Y,
            Vec3::Z,
            Vec3::ONE,
            Vec3::new(0.0, 1.0, 1.0),
        ]);
        for d in dirs {
            let n = d.as_dvec3();
            let (min, max) = min_max(n).unwrap();
            let (u, v) = basis(n, min, max);
            assert!(u.dot(n).abs() < 1e-12 && v.dot(n).abs() < 1e-12 && u.dot(v).abs() < 1e-12);
            assert_eq!(u[min], 0.0);
            assert_eq!(v[min], 1.0);
            let other = 3 - min - max;
            assert_eq!(u[other].abs(), 1.0, "{d:?}");
            // The projection equals the f64 basis up to rounding.
            let case = ScaledCase::of(d).unwrap();
            let ray = Ray::new(Vec3::new(0.3, -0.2, 0.1), d);
            let q = Vec3::new(1.5, 0.25, -2.0);
            let want = (q - ray.origin).as_dvec3();
            let (x, y) = (u.dot(want), v.dot(want));
            let (x, y) = if case.swap { (y, x) } else { (x, y) };
            let got = with_case!(case, P, P::setup(&ray).project(q));
            assert!((got.x as f64 - x).abs() < 1e-5 && (got.y as f64 - y).abs() < 1e-5);
            // Exit faces stay counter-clockwise: the projected frame is
            // right-handed around n.
            let (eu, ev) = if case.swap { (v, u) } else { (u, v) };
            assert!(eu.cross(ev).dot(n) > 0.0);
        }
    }
}
