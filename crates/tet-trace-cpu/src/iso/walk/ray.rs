//! The iso walk's per-ray constants and per-tet arithmetic: the range
//! test, the field value and ray parameter where the ray crosses a face
//! (canonical vertex order, see [`super`]), the crossing between a
//! tet's entry and exit faces, and the start tet's f64 linear field.

use glam::{DVec3, Vec2};
use tet_core::TetMesh;

use super::super::{IsoHit, IsoQuery, gradient};
use crate::ray::Ray;
use crate::walk::Face2;

/// What one tet holds.
pub(super) enum Found {
    Hit(IsoHit),
    /// A crossing beyond `t_max`: every later one is too.
    Beyond,
    None,
}

/// Per-ray constants of a walk.
pub(super) struct Ctx<'a> {
    mesh: &'a TetMesh,
    values: &'a [f32],
    ray: &'a Ray,
    query: &'a IsoQuery<'a>,
    inv_dd: f32,
    /// Smallest and largest isovalue.
    iso_lo: f32,
    iso_hi: f32,
}

impl<'a> Ctx<'a> {
    pub(super) fn new(
        mesh: &'a TetMesh,
        values: &'a [f32],
        ray: &'a Ray,
        query: &'a IsoQuery<'a>,
    ) -> Self {
        Ctx {
            mesh,
            values,
            ray,
            query,
            inv_dd: 1.0 / ray.direction.length_squared(),
            iso_lo: query
                .isovalues
                .iter()
                .copied()
                .fold(f32::INFINITY, f32::min),
            iso_hi: query
                .isovalues
                .iter()
                .copied()
                .fold(f32::NEG_INFINITY, f32::max),
        }
    }

    /// The range test of a tet with vertex values in `[lo, hi]`.
    #[inline(always)]
    pub(super) fn active(&self, [lo, hi]: [f32; 2]) -> bool {
        // Most tets lie on one side of every isovalue: two comparisons.
        if hi < self.iso_lo || lo >= self.iso_hi {
            return false;
        }
        self.query.active(lo, hi)
    }

    /// Depth of point `i` along the ray (a pure function of the point).
    #[inline(always)]
    fn depth(&self, i: u32) -> f32 {
        (self.mesh.points[i as usize] - self.ray.origin).dot(self.ray.direction) * self.inv_dd
    }

    /// Field value and ray parameter where the ray crosses the face `ids`
    /// (projected points `p`), computed in id order (see the module docs).
    #[inline(always)]
    pub(super) fn face(&self, ids: [u32; 3], p: &Face2) -> (f32, f32) {
        let mut k = [
            (ids[0], p.point(0)),
            (ids[1], p.point(1)),
            (ids[2], p.point(2)),
        ];
        if k[0].0 > k[1].0 {
            k.swap(0, 1);
        }
        if k[1].0 > k[2].0 {
            k.swap(1, 2);
        }
        if k[0].0 > k[1].0 {
            k.swap(0, 1);
        }
        let det = |a: Vec2, b: Vec2| a.x * b.y - a.y * b.x;
        let w = [
            det(k[1].1, k[2].1),
            det(k[2].1, k[0].1),
            det(k[0].1, k[1].1),
        ];
        let v = k.map(|(i, _)| self.values[i as usize]);
        let z = k.map(|(i, _)| self.depth(i));
        let s = w[0] + w[1] + w[2];
        if s == 0.0 || !s.is_finite() {
            return (v[0], z[0]);
        }
        let f = (w[0] * v[0] + w[1] * v[1] + w[2] * v[2]) / s;
        let t = (w[0] * z[0] + w[1] * z[1] + w[2] * z[2]) / s;
        let (vlo, vhi) = (v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]));
        let (zlo, zhi) = (z[0].min(z[1]).min(z[2]), z[0].max(z[1]).max(z[2]));
        (f.clamp(vlo, vhi), t.clamp(zlo, zhi))
    }

    /// Field value at the ray origin inside `tet`, clamped to its range.
    pub(super) fn value_at_origin(&self, tet: u32) -> f32 {
        let ids = self.mesh.tets[tet as usize];
        let v = ids.map(|i| self.values[i as usize]);
        let (lo, hi) = (
            v[0].min(v[1]).min(v[2].min(v[3])),
            v[0].max(v[1]).max(v[2].max(v[3])),
        );
        let (f0, _) = linear_along(self.mesh, self.values, tet, self.ray);
        (f0 as f32).clamp(lo, hi)
    }

    /// The start tet when the ray leaves the volume through its exit face:
    /// the crossing of the linear field (f64) ahead of the origin.
    pub(super) fn start_tet_alone(&self, tet: u32) -> Option<IsoHit> {
        let (f0, f1, exit) = linear_and_exit(self.mesh, self.values, tet, self.ray);
        let ids = self.mesh.tets[tet as usize];
        let v = ids.map(|i| self.values[i as usize]);
        let range = [
            v[0].min(v[1]).min(v[2].min(v[3])),
            v[0].max(v[1]).max(v[2].max(v[3])),
        ];
        if !self.active(range) || f1 == 0.0 {
            return None;
        }
        let mut best: Option<IsoHit> = None;
        for (k, &iso) in self.query.isovalues.iter().enumerate() {
            let t64 = (iso as f64 - f0) / f1;
            let t = t64 as f32;
            // Beyond the exit the ray is outside the volume.
            let inside = t64 <= exit * (1.0 + 1e-9);
            if inside && t >= self.ray.t_min.max(0.0) && t <= self.ray.t_max && self.keeps(t) {
                let hit = self.hit(tet, k, t);
                if best.is_none_or(|b| hit.before(&b)) {
                    best = Some(hit);
                }
            }
        }
        best
    }

    #[inline]
    fn keeps(&self, t: f32) -> bool {
        self.query.keeps(self.ray.at(t))
    }

    fn hit(&self, tet: u32, k: usize, t: f32) -> IsoHit {
        let ids = self.mesh.tets[tet as usize];
        IsoHit {
            t,
            tet,
            isovalue_index: k as u8,
            normal: gradient(
                ids.map(|i| self.mesh.points[i as usize]),
                ids.map(|i| self.values[i as usize]),
            ),
        }
    }

    /// The nearest accepted crossing between the entry `(F_in, t_in)` and
    /// the exit `(F_out, t_out)` of `tet`.
    #[inline]
    pub(super) fn crossing(&self, tet: u32, (fa, ta): (f32, f32), (fb, tb): (f32, f32)) -> Found {
        let mut best: Option<IsoHit> = None;
        let mut beyond = false;
        for (k, &iso) in self.query.isovalues.iter().enumerate() {
            if (fa >= iso) == (fb >= iso) {
                continue;
            }
            let s = (iso - fa) / (fb - fa);
            let t = (ta + s * (tb - ta)).clamp(ta.min(tb), ta.max(tb));
            if t > self.ray.t_max {
                beyond = true;
                continue;
            }
            if t < self.ray.t_min || !self.keeps(t) {
                continue;
            }
            let hit = self.hit(tet, k, t);
            if best.is_none_or(|b| hit.before(&b)) {
                best = Some(hit);
            }
        }
        match best {
            Some(h) => Found::Hit(h),
            None if beyond => Found::Beyond,
            None => Found::None,
        }
    }
}

/// The linear field of `tet` along `ray` in f64: `f(t) = f0 + f1·t`.
fn linear_along(mesh: &TetMesh, values: &[f32], tet: u32, ray: &Ray) -> (f64, f64) {
    let (f0, f1, _) = linear_and_exit(mesh, values, tet, ray);
    (f0, f1)
}

/// [`linear_along`] and the ray parameter where the ray leaves the tet
/// (f64; infinite for a flat tet).
fn linear_and_exit(mesh: &TetMesh, values: &[f32], tet: u32, ray: &Ray) -> (f64, f64, f64) {
    let ids = mesh.tets[tet as usize];
    let p = ids.map(|i| mesh.points[i as usize].as_dvec3());
    let v = ids.map(|i| values[i as usize] as f64);
    let m = glam::DMat3::from_cols(p[1] - p[0], p[2] - p[0], p[3] - p[0]);
    if m.determinant() == 0.0 {
        return (v[0], 0.0, f64::INFINITY);
    }
    let inv = m.inverse();
    let g = inv.transpose() * DVec3::new(v[1] - v[0], v[2] - v[0], v[3] - v[0]);
    let o = ray.origin.as_dvec3();
    let d = ray.direction.as_dvec3();
    // Barycentrics along the ray: λ(t) = a + b·t; the exit is the first
    // t > 0 where a decreasing one reaches 0.
    let (la, lb) = (inv * (o - p[0]), inv * d);
    let a = [1.0 - la.x - la.y - la.z, la.x, la.y, la.z];
    let b = [-lb.x - lb.y - lb.z, lb.x, lb.y, lb.z];
    let exit = (0..4)
        .filter(|&i| b[i] < 0.0)
        .map(|i| -a[i] / b[i])
        .fold(f64::INFINITY, f64::min);
    (v[0] + g.dot(o - p[0]), g.dot(d), exit)
}
