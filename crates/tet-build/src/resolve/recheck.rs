//! The exact re-check after a round, limited to what the round changed.
//!
//! Pairs of triangles the round left alone were checked before and did not
//! meet (a triangle in a reported pair is always cut), so only pairs with
//! at least one new piece can meet now. The new pieces are entered into a
//! uniform grid (cells about twice their mean size); every triangle of the
//! soup looks up the cells its box covers and is tested, exactly
//! ([`crate::intersect::classify_pair`]), against the new pieces whose
//! boxes overlap its own. The scan runs in parallel.

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::table::FxMap;
use crate::intersect::{IntersectingPair, classify_pair};

fn bounds(vertices: &[Vec3], t: [u32; 3]) -> (DVec3, DVec3) {
    let [a, b, c] = t.map(|v| vertices[v as usize].as_dvec3());
    (a.min(b).min(c), a.max(b).max(c))
}

/// Cells a box spans beyond which a triangle is tested against every new
/// piece instead of looking cells up one by one.
const MAX_SPAN: i64 = 64;

/// Intersecting pairs (indices into `triangles`, `first < second`, sorted)
/// with at least one member in `dirty`.
pub(crate) fn recheck(
    vertices: &[Vec3],
    triangles: &[[u32; 3]],
    dirty: &[u32],
) -> Vec<IntersectingPair> {
    if dirty.is_empty() {
        return Vec::new();
    }
    let boxes: Vec<(DVec3, DVec3)> = dirty
        .iter()
        .map(|&t| bounds(vertices, triangles[t as usize]))
        .collect();
    let (mut lo, mut hi) = boxes[0];
    let mut mean = 0.0;
    for &(l, h) in &boxes {
        lo = lo.min(l);
        hi = hi.max(h);
        mean += (h - l).max_element();
    }
    mean /= boxes.len() as f64;
    let cell = (2.0 * mean)
        .max((hi - lo).max_element() / 1024.0)
        .max(f64::MIN_POSITIVE);
    let index = |p: DVec3| ((p - lo) / cell).floor().as_i64vec3();
    let mut grid: FxMap<[i64; 3], Vec<u32>> = FxMap::default();
    let mut wide: Vec<u32> = Vec::new();
    for (k, &(l, h)) in boxes.iter().enumerate() {
        let (a, b) = (index(l), index(h));
        if (b - a).max_element() >= MAX_SPAN {
            wide.push(k as u32);
            continue;
        }
        for z in a.z..=b.z {
            for y in a.y..=b.y {
                for x in a.x..=b.x {
                    grid.entry([x, y, z]).or_default().push(k as u32);
                }
            }
        }
    }
    let mut is_dirty = vec![false; triangles.len()];
    for &d in dirty {
        is_dirty[d as usize] = true;
    }
    let corners = |t: u32| triangles[t as usize].map(|v| vertices[v as usize]);
    let mut pairs: Vec<IntersectingPair> = (0..triangles.len() as u32)
        .into_par_iter()
        .flat_map_iter(|t| {
            let (l, h) = bounds(vertices, triangles[t as usize]);
            let mut near: Vec<u32> = wide.clone();
            if !(l.cmpgt(hi).any() || h.cmplt(lo).any()) {
                let (a, b) = (index(l), index(h));
                if (b - a).max_element() >= MAX_SPAN {
                    near.extend(0..dirty.len() as u32);
                } else {
                    for z in a.z..=b.z {
                        for y in a.y..=b.y {
                            for x in a.x..=b.x {
                                if let Some(ks) = grid.get(&[x, y, z]) {
                                    near.extend_from_slice(ks);
                                }
                            }
                        }
                    }
                }
            }
            near.sort_unstable();
            near.dedup();
            let mut found = Vec::new();
            for k in near {
                let d = dirty[k as usize];
                // A pair of new pieces is tested once, from its lower member.
                if d == t || (is_dirty[t as usize] && d < t) {
                    continue;
                }
                let (dl, dh) = boxes[k as usize];
                if dl.cmpgt(h).any() || l.cmpgt(dh).any() {
                    continue;
                }
                if let Some(kind) = classify_pair(corners(t), corners(d)) {
                    found.push(IntersectingPair {
                        first: t.min(d),
                        second: t.max(d),
                        kind,
                    });
                }
            }
            found
        })
        .collect();
    pairs.sort_unstable_by_key(|p| (p.first, p.second));
    pairs.dedup_by_key(|p| (p.first, p.second));
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::intersect::find_self_intersections_brute_force;

    #[test]
    fn finds_exactly_the_pairs_with_a_new_piece() {
        // A fan of triangles crossing each other; mark some as new.
        let mut vertices = Vec::new();
        let mut triangles = Vec::new();
        for i in 0..12 {
            let a = i as f32 * 0.5;
            let b = vertices.len() as u32;
            vertices.push(Vec3::new(
                a.cos() * 3.0,
                a.sin() * 3.0,
                -1.0 + i as f32 * 0.1,
            ));
            vertices.push(Vec3::new(-a.cos() * 3.0, -a.sin() * 3.0, 1.0));
            vertices.push(Vec3::new(0.3 * i as f32, 0.0, 2.0 - i as f32 * 0.3));
            triangles.push([b, b + 1, b + 2]);
        }
        let dirty = [1u32, 4, 5, 9];
        let expected: Vec<(u32, u32)> = find_self_intersections_brute_force(&vertices, &triangles)
            .into_iter()
            .filter(|p| dirty.contains(&p.first) || dirty.contains(&p.second))
            .map(|p| (p.first, p.second))
            .collect();
        assert!(!expected.is_empty());
        let got: Vec<(u32, u32)> = recheck(&vertices, &triangles, &dirty)
            .into_iter()
            .map(|p| (p.first, p.second))
            .collect();
        assert_eq!(got, expected);
    }
}
