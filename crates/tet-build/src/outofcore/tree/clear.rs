//! Where a moved plane may go: a position clear of every known point by
//! more than the seams' tolerance ([`NEAR_PLANE`](crate::outofcore::plane::NEAR_PLANE)).
//!
//! The planner places its planes clear of the scene's vertices; a plane
//! the build has to move (a point made by a cut lies too near it, or
//! TetGen failed on a part it bounds) used to move by a fixed step, and
//! where the scene is dense that step lands near other vertices as
//! often as not (seen on 30 M triangles of knots: a wall moved after a
//! TetGen crash, then eight moves each refused by a point about 1e-6
//! off the plane). [`ClearPositions`] moves it instead to the position
//! nearest the one wanted whose distance to every scene vertex in the
//! plane's box, and to every point a failed cut reported, is at least
//! twice the tolerance.

use glam::Vec3;

use crate::outofcore::plane::SplitPlane;

/// The points a moved plane must stay clear of: the scene's vertices
/// (the input's: a superset of the cleaned scene's) and the points the
/// build's cuts reported too near a plane (crossings and resolved
/// intersections, which the scene's vertices do not hold).
pub(super) struct ClearPositions<'a> {
    vertices: &'a [Vec3],
    reported: Vec<Vec3>,
    /// The seams' tolerance (absolute).
    tolerance: f64,
}

impl<'a> ClearPositions<'a> {
    /// Positions clear of `vertices` by twice `tolerance`.
    pub(super) fn new(vertices: &'a [Vec3], tolerance: f64) -> Self {
        ClearPositions {
            vertices,
            reported: Vec::new(),
            tolerance,
        }
    }

    /// Adds a point a cut found too near a plane.
    pub(super) fn avoid(&mut self, p: Vec3) {
        self.reported.push(p);
    }

    /// Where `plane`, inside the box `lo..hi` of its node, may go near
    /// `want`: within `reach` of it, the value farthest from every point
    /// in that box (the middle of the widest gap there, ties to the
    /// nearer), provided that is at least twice the tolerance; else the
    /// value nearest `want` anywhere in the box that is that far from
    /// every point. Always at least that far inside the box, never the
    /// plane's own value; `None` when no gap is wide enough.
    ///
    /// Clearance, not just tolerance: a wall barely clear of a vertex
    /// leaves TetGen a feature as thin as the gap (measured: parts stuck
    /// past their time limit next to walls moved to the nearest clear
    /// value at 30 M triangles).
    pub(super) fn value(
        &self,
        plane: SplitPlane,
        lo: Vec3,
        hi: Vec3,
        want: f64,
        reach: f64,
    ) -> Option<f32> {
        let a = plane.axis;
        let margin = 2.0 * self.tolerance;
        let slack = Vec3::splat(self.tolerance as f32);
        let (blo, bhi) = (lo - slack, hi + slack);
        let mut coords: Vec<f64> = self
            .vertices
            .iter()
            .chain(&self.reported)
            .filter(|p| p.cmpge(blo).all() && p.cmple(bhi).all())
            .map(|p| p[a] as f64)
            .collect();
        coords.push(lo[a] as f64);
        coords.push(hi[a] as f64);
        coords.sort_unstable_by(f64::total_cmp);
        coords.dedup();
        let clear = |v: f32| {
            let x = v as f64;
            let i = coords.partition_point(|&c| c < x);
            let left = i.checked_sub(1).map_or(f64::INFINITY, |j| x - coords[j]);
            let right = coords.get(i).map_or(f64::INFINITY, |&c| c - x);
            v != plane.value && left.min(right) >= margin
        };
        // The widest clearance within reach of `want`.
        let (wlo, whi) = (want - reach, want + reach);
        let mut widest: Option<(f64, f64, f32)> = None;
        for w in coords.windows(2) {
            let (from, to) = (w[0].max(wlo), w[1].min(whi));
            if from > to {
                continue;
            }
            let v = round_within((0.5 * (w[0] + w[1])).clamp(from, to), from, to);
            let x = v as f64;
            let room = (x - w[0]).min(w[1] - x);
            let d = (x - want).abs();
            let better = widest.is_none_or(|(r, bd, _)| room > r || (room == r && d < bd));
            if better && clear(v) {
                widest = Some((room, d, v));
            }
        }
        if let Some((_, _, v)) = widest {
            return Some(v);
        }
        let mut best: Option<(f64, f32)> = None;
        for w in coords.windows(2) {
            let (from, to) = (w[0] + margin, w[1] - margin);
            if from > to {
                continue;
            }
            // The f32 nearest `want` in the gap (the check is on the
            // rounded value).
            let v = round_within(want.clamp(from, to), from, to);
            let d = (v as f64 - want).abs();
            if best.is_none_or(|(bd, _)| d < bd) && clear(v) {
                best = Some((d, v));
            }
        }
        best.map(|(_, v)| v)
    }
}

/// `x` (in `from..=to`) rounded to f32, stepped back into the interval
/// where rounding took it out.
fn round_within(x: f64, from: f64, to: f64) -> f32 {
    let v = x as f32;
    if (v as f64) < from {
        v.next_up()
    } else if (v as f64) > to {
        v.next_down()
    } else {
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane(value: f32) -> SplitPlane {
        SplitPlane { axis: 0, value }
    }

    /// Brute force: the distance from `v` to the nearest of `xs`.
    fn nearest(xs: &[f32], v: f32) -> f64 {
        xs.iter()
            .map(|&x| (x as f64 - v as f64).abs())
            .fold(f64::INFINITY, f64::min)
    }

    /// Points every 0.01 along x but for one gap: a wanted value in the
    /// dense run with no wide gap within reach moves to the gap's nearer
    /// clear edge; one with the gap within reach to the gap's middle;
    /// points outside the box (on the other axes) do not count; without a
    /// wide enough gap there is no value.
    #[test]
    fn a_moved_plane_lands_in_the_nearest_gap_wide_enough() {
        let tol = 0.01;
        // A gap from 0.59 to 0.70.
        let xs: Vec<f32> = (1..100)
            .filter(|i| !(60..70).contains(i))
            .map(|i| i as f32 * 0.01)
            .collect();
        let mut vs: Vec<Vec3> = xs.iter().map(|&x| Vec3::new(x, 0.5, 0.5)).collect();
        // Outside the box in y: must not block the gap.
        vs.push(Vec3::new(0.65, 3.0, 0.5));
        let (lo, hi) = (Vec3::ZERO, Vec3::ONE);
        let clear = ClearPositions::new(&vs, tol);
        let v = clear.value(plane(0.3), lo, hi, 0.3, 0.1).unwrap();
        assert!(nearest(&xs, v) >= 2.0 * tol - 1e-7, "{v}");
        assert!((v - 0.61).abs() < 1e-6, "the gap's lower clear edge: {v}");
        // Wanted 0.66, the gap within reach: its middle; wanted 0.52, the
        // gap's part within reach: its clearest value, the reach's end.
        for (want, at) in [(0.66, 0.645), (0.52, 0.62)] {
            let v = clear.value(plane(0.3), lo, hi, want, 0.1).unwrap();
            assert!((v - at).abs() < 1e-6, "{want}: {v}");
        }
        // Reported points in the gap close it.
        let mut closed = ClearPositions::new(&vs, tol);
        for x in [0.62, 0.645, 0.67] {
            closed.avoid(Vec3::new(x, 0.5, 0.5));
        }
        assert_eq!(closed.value(plane(0.3), lo, hi, 0.3, 0.1), None);
        // The plane's own value is no move.
        let middle = clear.value(plane(0.3), lo, hi, 0.66, 0.1).unwrap();
        assert_ne!(clear.value(plane(middle), lo, hi, 0.66, 0.1), Some(middle));
    }

    /// Random clouds: whatever the value, it is clear of every point in the
    /// box and inside the box by twice the tolerance; where some value
    /// within reach is clear, it lies within reach and no value on a fine
    /// grid there is farther from the points; else no clear value on the
    /// grid lies nearer the wanted one.
    #[test]
    fn a_clear_value_is_clear_and_nearest() {
        let mut rng = tet_core::synthetic::SplitMix64(7);
        let mut rand = || rng.range_f32(0.0, 1.0);
        for round in 0..40 {
            let n = 5 + round * 3;
            let xs: Vec<f32> = (0..n).map(|_| rand()).collect();
            let vs: Vec<Vec3> = xs.iter().map(|&x| Vec3::new(x, 0.5, 0.5)).collect();
            let tol = 0.004;
            let want = rand() as f64;
            let clear = ClearPositions::new(&vs, tol);
            let (lo, hi) = (Vec3::ZERO, Vec3::ONE);
            let mut edges = xs.clone();
            edges.extend([0.0, 1.0]);
            let ok = |v: f32| nearest(&edges, v) >= 2.0 * tol && v != 2.0;
            let reach = 0.05;
            let grid = || (0..=10_000).map(|k| k as f32 / 10_000.0);
            let within = |g: f32| (g as f64 - want).abs() <= reach;
            match clear.value(plane(2.0), lo, hi, want, reach) {
                Some(v) if grid().any(|g| within(g) && ok(g)) => {
                    assert!(ok(v) && within(v), "round {round}: {v}");
                    let room = nearest(&edges, v);
                    for g in grid().filter(|&g| within(g)) {
                        assert!(nearest(&edges, g) <= room + 1e-6, "{g} clearer than {v}");
                    }
                }
                Some(v) => {
                    assert!(ok(v), "round {round}: {v}");
                    let d = (v as f64 - want).abs();
                    for g in grid().filter(|&g| ok(g)) {
                        assert!((g as f64 - want).abs() >= d - 1e-6, "{g} nearer than {v}");
                    }
                }
                None => {
                    for k in 0..=10_000 {
                        let g = k as f32 / 10_000.0;
                        assert!(!ok(g), "round {round}: {g} is clear");
                    }
                }
            }
        }
    }
}
