//! Where a new point goes: onto an existing vertex at the same `f32`
//! position, or within the snap distance of one (the nearest), else a new
//! vertex. Snapping keeps clusters of almost equal points, which rounding
//! would otherwise keep creating round after round, down to one vertex.

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::table::FxMap;

/// Vertices by position, for exact and near lookups.
pub(crate) struct SnapGrid {
    eps: f64,
    cells: FxMap<[i64; 3], Vec<u32>>,
    exact: FxMap<[u32; 3], u32>,
}

/// Position key for bitwise merging (`-0.0` counts as `0.0`).
pub(crate) fn position_key(p: Vec3) -> [u32; 3] {
    (p + Vec3::ZERO).to_array().map(f32::to_bits)
}

impl SnapGrid {
    /// A grid over the `vertices` that lie within `eps` of the box
    /// `[lo, hi]` (where the new points are), snapping within `eps`
    /// (Chebyshev distance; 0: bitwise-equal positions only).
    pub fn around(eps: f64, vertices: &[Vec3], lo: Vec3, hi: Vec3) -> SnapGrid {
        let mut g = SnapGrid {
            eps,
            cells: FxMap::default(),
            exact: FxMap::default(),
        };
        let (lo, hi) = (lo.as_dvec3() - eps, hi.as_dvec3() + eps);
        let near: Vec<u32> = (0..vertices.len() as u32)
            .into_par_iter()
            .filter(|&i| {
                let p = vertices[i as usize].as_dvec3();
                !(p.cmplt(lo).any() || p.cmpgt(hi).any())
            })
            .collect();
        for i in near {
            g.insert(i, vertices[i as usize]);
        }
        g
    }

    fn cell(&self, p: DVec3) -> [i64; 3] {
        (p / self.eps).floor().as_i64vec3().to_array()
    }

    /// Records vertex `id` at `p` (the first vertex at a position wins).
    pub fn insert(&mut self, id: u32, p: Vec3) {
        self.exact.entry(position_key(p)).or_insert(id);
        if self.eps > 0.0 {
            let c = self.cell(p.as_dvec3());
            self.cells.entry(c).or_default().push(id);
        }
    }

    /// The vertex at `p`, or the nearest within the snap distance.
    pub fn find(&self, p: Vec3, pos: impl Fn(u32) -> Vec3) -> Option<u32> {
        if let Some(&id) = self.exact.get(&position_key(p)) {
            return Some(id);
        }
        if self.eps <= 0.0 {
            return None;
        }
        let q = p.as_dvec3();
        let c = self.cell(q);
        let mut best: Option<(f64, u32)> = None;
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let Some(ids) = self.cells.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) else {
                        continue;
                    };
                    for &id in ids {
                        let d = (pos(id).as_dvec3() - q).abs().max_element();
                        if d <= self.eps && best.is_none_or(|(bd, bid)| (d, id) < (bd, bid)) {
                            best = Some((d, id));
                        }
                    }
                }
            }
        }
        best.map(|(_, id)| id)
    }
}
