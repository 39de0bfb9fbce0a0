//! f64 brute-force reference: every tet is intersected with the ray.
//!
//! Inside a tet the field is linear, so along the ray it is
//! `f(t) = Σᵢ λᵢ(t) vᵢ` with barycentrics `λᵢ(t) = aᵢ + bᵢ t` (f64, from the
//! inverse of the tet's edge matrix). The ray is inside the tet where every
//! `λᵢ(t) ≥ 0`; each isovalue `v` is crossed where `f(t) = v`, accepted when
//! that `t` lies inside the tet, in `[t_min, t_max]`, and its point passes the
//! clip box. The nearest crossing wins (ties: smaller tet, then isovalue
//! index). The record also says how close the crossing lies to its tet's
//! boundary and to the next distinct crossing, so that tests can skip rays
//! whose answer f32 methods may legitimately round the other way.

use glam::{DMat3, DVec3};
use tet_core::TetMesh;

use super::IsoQuery;
use crate::ray::Ray;

/// One crossing found by the reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IsoHit64 {
    /// Ray parameter.
    pub t: f64,
    /// The tet.
    pub tet: u32,
    /// Which isovalue of the query.
    pub isovalue_index: u8,
    /// The crossing point (f64).
    pub point: DVec3,
    /// Smallest barycentric of the point in its tet (0 on the tet's
    /// boundary: near an edge or a vertex when small).
    pub edge_margin: f64,
    /// Parameter distance to the next crossing that is not this one seen
    /// from a neighbouring tet (infinite when none).
    pub second_gap: f64,
    /// Field gradient in the tet (unnormalised, f64).
    pub gradient: DVec3,
}

/// The linear field of one tet along a ray: barycentric `λᵢ(t) = a[i] +
/// b[i]·t`, gradient.
struct Along {
    a: [f64; 4],
    b: [f64; 4],
    grad: DVec3,
}

fn along(mesh: &TetMesh, values: &[f32], tet: u32, o: DVec3, d: DVec3) -> Option<Along> {
    let ids = mesh.tets[tet as usize];
    let p = ids.map(|i| mesh.points[i as usize].as_dvec3());
    let v = ids.map(|i| values[i as usize] as f64);
    let m = DMat3::from_cols(p[1] - p[0], p[2] - p[0], p[3] - p[0]);
    let det = m.determinant();
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = m.inverse();
    let la = inv * (o - p[0]);
    let lb = inv * d;
    let a = [1.0 - la.x - la.y - la.z, la.x, la.y, la.z];
    let b = [-lb.x - lb.y - lb.z, lb.x, lb.y, lb.z];
    // f = v0 + (v - v0)·λ₁..₃ ⇒ grad = M⁻ᵀ (v1−v0, v2−v0, v3−v0).
    let grad = inv.transpose() * DVec3::new(v[1] - v[0], v[2] - v[0], v[3] - v[0]);
    Some(Along { a, b, grad })
}

/// Every accepted crossing of `ray` (unsorted): `(t, tet, isovalue index,
/// edge margin, gradient)`.
fn crossings(
    mesh: &TetMesh,
    values: &[f32],
    ray: &Ray,
    query: &IsoQuery,
) -> Vec<(f64, u32, u8, f64, DVec3)> {
    let o = ray.origin.as_dvec3();
    let d = ray.direction.as_dvec3();
    let mut out = Vec::new();
    for tet in 0..mesh.tets.len() as u32 {
        let ids = mesh.tets[tet as usize];
        let v = ids.map(|i| values[i as usize] as f64);
        let (lo, hi) = v
            .iter()
            .fold((f64::MAX, f64::MIN), |(l, h), &x| (l.min(x), h.max(x)));
        if !query
            .isovalues
            .iter()
            .any(|&iso| lo < iso as f64 && iso as f64 <= hi)
        {
            continue;
        }
        let Some(al) = along(mesh, values, tet, o, d) else {
            continue;
        };
        let f0: f64 = (0..4).map(|i| al.a[i] * v[i]).sum();
        let f1: f64 = (0..4).map(|i| al.b[i] * v[i]).sum();
        if f1 == 0.0 {
            continue;
        }
        for (k, &iso) in query.isovalues.iter().enumerate() {
            let t = (iso as f64 - f0) / f1;
            if !(t >= ray.t_min as f64 && t <= ray.t_max as f64) {
                continue;
            }
            let margin = (0..4)
                .map(|i| al.a[i] + al.b[i] * t)
                .fold(f64::INFINITY, f64::min);
            if margin < 0.0 {
                continue;
            }
            let p = o + d * t;
            if !query.keeps(p.as_vec3()) {
                continue;
            }
            out.push((t, tet, k as u8, margin, al.grad));
        }
    }
    out
}

/// The nearest crossing of `ray` with any isovalue of `query` (f64), or
/// `None`. `values` holds one value per mesh point.
pub fn closest(mesh: &TetMesh, values: &[f32], ray: &Ray, query: &IsoQuery) -> Option<IsoHit64> {
    let all = crossings(mesh, values, ray, query);
    let best = all
        .iter()
        .copied()
        .min_by(|x, y| (x.0, x.1, x.2).partial_cmp(&(y.0, y.1, y.2)).unwrap())?;
    // A crossing in the interior of its tet (margin > 0) is found there
    // only; on a shared face it is found in each tet, at (nearly) the same t.
    let second = all
        .iter()
        .filter(|c| (c.1, c.2) != (best.1, best.2))
        .map(|c| c.0 - best.0)
        .filter(|&g| best.3 > 0.0 || g.abs() > 1e-9)
        .fold(f64::INFINITY, |m, g| m.min(g.abs()));
    let o = ray.origin.as_dvec3();
    let d = ray.direction.as_dvec3();
    Some(IsoHit64 {
        t: best.0,
        tet: best.1,
        isovalue_index: best.2,
        point: o + d * best.0,
        edge_margin: best.3,
        second_gap: second,
        gradient: best.4,
    })
}

/// The field value at `p` by brute force (f64): the value interpolated in
/// the first tet containing `p` (barycentrics ≥ −1e-12), or `None` outside
/// the mesh.
pub fn value_at(mesh: &TetMesh, values: &[f32], p: DVec3) -> Option<f64> {
    (0..mesh.tets.len() as u32).find_map(|tet| {
        let al = along(mesh, values, tet, p, DVec3::ZERO)?;
        if al.a.iter().any(|&l| l < -1e-12) {
            return None;
        }
        let ids = mesh.tets[tet as usize];
        Some(
            (0..4)
                .map(|i| al.a[i] * values[ids[i] as usize] as f64)
                .sum(),
        )
    })
}
