//! Segments and their roots, registered crossing points, points on
//! axis-parallel lines, and the outlines of clipped pieces: the exact
//! geometry shared by the clipping and the walls.

use std::collections::{HashMap, HashSet};

use glam::{DVec2, DVec3, Vec3};

use crate::outofcore::error::SeamError;
use crate::outofcore::plane::{SplitPlane, crossing_point, key};

/// A segment's root: the scene edge or cut segment it lies on, endpoints in
/// canonical (key) order.
#[derive(Clone, Copy, Debug)]
pub(super) struct Root {
    pub(super) a: Vec3,
    pub(super) b: Vec3,
}

pub(super) type RootId = ([u32; 3], [u32; 3]);

impl Root {
    pub(super) fn new(p: Vec3, q: Vec3) -> Root {
        if key(p) <= key(q) {
            Root { a: p, b: q }
        } else {
            Root { a: q, b: p }
        }
    }

    pub(super) fn id(&self) -> RootId {
        (key(self.a), key(self.b))
    }
}

/// A convex piece of a scene triangle: outline and the root of each edge
/// (`roots[i]` carries `v[i] → v[i + 1]`).
#[derive(Clone, Debug)]
pub(super) struct Poly {
    pub(super) v: Vec<Vec3>,
    pub(super) roots: Vec<Root>,
    pub(super) source: u32,
}

impl Poly {
    /// Scene triangle `source` whole: its edges are their own roots.
    pub(super) fn triangle(v: [Vec3; 3], source: u32) -> Poly {
        Poly {
            v: v.to_vec(),
            roots: (0..3).map(|k| Root::new(v[k], v[(k + 1) % 3])).collect(),
            source,
        }
    }
}

/// A triangle of a wall and the cleaned scene triangle it lies in, if any.
pub(super) type WallTriangle = ([Vec3; 3], Option<u32>);

/// A wall: a seam (split node section) or an enclosing-box face.
#[derive(Clone, Debug)]
pub(super) struct Wall {
    pub(super) plane: SplitPlane,
    pub(super) lo: Vec3,
    pub(super) hi: Vec3,
    pub(super) seam: bool,
    /// Constraint sub-segments `(root, from, to)`.
    pub(super) segments: Vec<(Root, Vec3, Vec3, u32)>,
    /// Scene pieces lying in the wall.
    pub(super) in_plane: Vec<Poly>,
    /// Single points (scene vertices touching the wall).
    pub(super) points: Vec<Vec3>,
    /// Axis-parallel segments (boundary edges and traces): `(from, to)`.
    pub(super) axis_segments: Vec<(Vec3, Vec3)>,
    /// The triangulation: triangles and the cleaned scene triangle each lies in.
    pub(super) triangles: Vec<WallTriangle>,
}

/// Registered crossing points per root: `(t, point)`.
#[derive(Default)]
pub(super) struct Registry {
    pub(super) points: HashMap<RootId, Vec<(f64, Vec3)>>,
}

impl Registry {
    /// The crossing of `root` with `plane`, registered.
    pub(super) fn cross(
        &mut self,
        root: Root,
        plane: SplitPlane,
        triangle: u32,
    ) -> Result<Vec3, SeamError> {
        let (a, b) = (root.a.as_dvec3(), root.b.as_dvec3());
        let c = plane.axis;
        let t = (plane.value as f64 - a[c]) / (b[c] - a[c]);
        let x = crossing_point(root.a, root.b, plane);
        if !(t > 0.0 && t < 1.0) {
            return Err(SeamError::DegenerateCut {
                plane,
                point: x,
                triangle,
                what: "the crossing lies outside its segment",
            });
        }
        let list = self.points.entry(root.id()).or_default();
        if !list.iter().any(|(_, p)| key(*p) == key(x)) {
            list.push((t, x));
        }
        Ok(x)
    }

    /// Parameter of `p` along `root`.
    pub(super) fn t_of(&self, root: Root, p: Vec3) -> Option<f64> {
        if key(p) == key(root.a) {
            return Some(0.0);
        }
        if key(p) == key(root.b) {
            return Some(1.0);
        }
        self.points
            .get(&root.id())?
            .iter()
            .find(|(_, q)| key(*q) == key(p))
            .map(|(t, _)| *t)
    }
}

/// Points on axis-parallel lines, found exactly: the scene's vertices,
/// sorted once per free axis by (the other two coordinates' bits, the free
/// coordinate), and the few points the cut makes (crossings, wall corners
/// and trace crossings) in buckets `(free axis, the other two coordinates'
/// bits)`. The scene's vertices are kept as three sorted copies rather
/// than hashed: a tenth of the memory, which is what lets a planner hold a
/// large scene.
#[derive(Default)]
pub(super) struct Lines {
    scene: [Vec<Vec3>; 3],
    seen: HashSet<[u32; 3]>,
    buckets: HashMap<(usize, [u32; 2]), Vec<Vec3>>,
}

/// The line through `p` with free axis `f`: the other two coordinates'
/// bits, lower axis first.
fn line_of(f: usize, p: Vec3) -> [u32; 2] {
    let k = key(p);
    let (i, j) = ((f + 1) % 3, (f + 2) % 3);
    [k[i.min(j)], k[i.max(j)]]
}

impl Lines {
    /// Lines holding every vertex of `triangles`.
    pub(super) fn with_scene(vertices: &[Vec3], triangles: &[[u32; 3]]) -> Lines {
        let mut used = vec![false; vertices.len()];
        for t in triangles {
            for &v in t {
                used[v as usize] = true;
            }
        }
        let points: Vec<Vec3> = vertices
            .iter()
            .zip(&used)
            .filter_map(|(p, &u)| u.then_some(*p))
            .collect();
        drop(used);
        let sorted = |f: usize| {
            let mut v = points.clone();
            v.sort_unstable_by(|a, b| {
                line_of(f, *a)
                    .cmp(&line_of(f, *b))
                    .then(a[f].total_cmp(&b[f]))
            });
            v
        };
        Lines {
            scene: [sorted(0), sorted(1), sorted(2)],
            ..Lines::default()
        }
    }

    pub(super) fn insert(&mut self, p: Vec3) {
        if !self.seen.insert(key(p)) {
            return;
        }
        for f in 0..3 {
            self.buckets.entry((f, line_of(f, p))).or_default().push(p);
        }
    }

    /// Points strictly between `p` and `q` (which share two coordinates,
    /// free axis `f`), ordered from `p` to `q`, each once.
    pub(super) fn between(&self, p: Vec3, q: Vec3, f: usize) -> Vec<Vec3> {
        let line = line_of(f, p);
        let (lo, hi) = (p[f].min(q[f]), p[f].max(q[f]));
        let scene = &self.scene[f];
        let start = scene.partition_point(|x| line_of(f, *x) < line);
        let len = scene[start..].partition_point(|x| line_of(f, *x) == line);
        let made = self
            .buckets
            .get(&(f, line))
            .map_or(&[][..], |b| b.as_slice());
        let mut v: Vec<Vec3> = scene[start..start + len]
            .iter()
            .chain(made)
            .copied()
            .filter(|x| x[f] > lo && x[f] < hi)
            .collect();
        if p[f] <= q[f] {
            v.sort_by(|a, b| a[f].total_cmp(&b[f]));
        } else {
            v.sort_by(|a, b| b[f].total_cmp(&a[f]));
        }
        v.dedup_by(|a, b| key(*a) == key(*b));
        v
    }
}

/// The free axis of an axis-parallel segment (two coordinates equal).
pub(super) fn free_axis(p: Vec3, q: Vec3) -> Option<usize> {
    let same: Vec<bool> = (0..3).map(|a| p[a] == q[a]).collect();
    match same.iter().filter(|&&s| s).count() {
        2 => same.iter().position(|&s| !s),
        _ => None,
    }
}

/// Points strictly between `p` and `q` on `root` (ordered from `p`).
pub(super) fn subdivide(
    reg: &Registry,
    lines: &Lines,
    root: Root,
    p: Vec3,
    q: Vec3,
    triangle: u32,
) -> Result<Vec<Vec3>, SeamError> {
    if let Some(f) = free_axis(p, q) {
        return Ok(lines.between(p, q, f));
    }
    let missing = |x: Vec3| SeamError::DegenerateCut {
        plane: SplitPlane {
            axis: 0,
            value: x.x,
        },
        point: x,
        triangle,
        what: "a piece's vertex does not lie on its edge's root",
    };
    let tp = reg.t_of(root, p).ok_or_else(|| missing(p))?;
    let tq = reg.t_of(root, q).ok_or_else(|| missing(q))?;
    let (lo, hi) = (tp.min(tq), tp.max(tq));
    let mut v: Vec<(f64, Vec3)> = reg
        .points
        .get(&root.id())
        .map(|l| {
            l.iter()
                .copied()
                .filter(|(t, _)| *t > lo && *t < hi)
                .collect()
        })
        .unwrap_or_default();
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    if tp > tq {
        v.reverse();
    }
    Ok(v.into_iter().map(|(_, x)| x).collect())
}

/// The full outline of a polygon (every edge subdivided).
pub(super) fn outline(reg: &Registry, lines: &Lines, poly: &Poly) -> Result<Vec<Vec3>, SeamError> {
    let n = poly.v.len();
    let mut out = Vec::with_capacity(n * 2);
    for i in 0..n {
        let (p, q) = (poly.v[i], poly.v[(i + 1) % n]);
        out.push(p);
        out.extend(subdivide(reg, lines, poly.roots[i], p, q, poly.source)?);
    }
    Ok(out)
}

/// Exact 2-D orientation.
pub(super) fn orient2(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    robust::orient2d(
        robust::Coord { x: a.x, y: a.y },
        robust::Coord { x: b.x, y: b.y },
        robust::Coord { x: c.x, y: c.y },
    )
}

/// Triangulates a (nearly convex) outline by ear clipping in the projection
/// dropping the largest component of `normal`; triangles keep the outline's
/// winding.
pub(super) fn triangulate_outline(
    outline: &[Vec3],
    normal: DVec3,
    triangle: u32,
) -> Result<Vec<[Vec3; 3]>, SeamError> {
    let drop = normal.abs().max_position();
    let (u, w) = ((drop + 1) % 3, (drop + 2) % 3);
    let flat = |p: Vec3| DVec2::new(p[u] as f64, p[w] as f64);
    let sign = normal[drop].signum();
    let mut idx: Vec<usize> = (0..outline.len()).collect();
    let mut out = Vec::with_capacity(outline.len().saturating_sub(2));
    // An ear (a, b, c) whose diagonal a–c lies in an axis plane that b is
    // off (a[k] = c[k] ≠ b[k]) would run along the piece's chain of points
    // on a wall and leave a sliver lying in the wall: avoided unless no
    // other ear exists.
    let along_wall = |a: Vec3, b: Vec3, c: Vec3| (0..3).any(|k| a[k] == c[k] && b[k] != a[k]);
    while idx.len() > 3 {
        let n = idx.len();
        let mut found = None;
        for (pass, i) in (0..2).flat_map(|pass| (0..n).map(move |i| (pass, i))) {
            if found.is_some() {
                break;
            }
            let (a, b, c) = (idx[(i + n - 1) % n], idx[i], idx[(i + 1) % n]);
            if pass == 0 && along_wall(outline[a], outline[b], outline[c]) {
                continue;
            }
            let (pa, pb, pc) = (flat(outline[a]), flat(outline[b]), flat(outline[c]));
            if orient2(pa, pb, pc) * sign <= 0.0 {
                continue;
            }
            let blocked = idx.iter().any(|&k| {
                if k == a || k == b || k == c {
                    return false;
                }
                let pk = flat(outline[k]);
                orient2(pa, pb, pk) * sign >= 0.0
                    && orient2(pb, pc, pk) * sign >= 0.0
                    && orient2(pc, pa, pk) * sign >= 0.0
            });
            if !blocked {
                found = Some(i);
            }
        }
        let Some(i) = found else {
            return Err(SeamError::PieceTriangulation {
                triangle,
                vertices: outline.len(),
            });
        };
        let (a, b, c) = (idx[(i + n - 1) % n], idx[i], idx[(i + 1) % n]);
        out.push([outline[a], outline[b], outline[c]]);
        idx.remove(i);
    }
    if idx.len() == 3 {
        let t = [outline[idx[0]], outline[idx[1]], outline[idx[2]]];
        let n = (t[1] - t[0]).as_dvec3().cross((t[2] - t[0]).as_dvec3());
        if n != DVec3::ZERO {
            out.push(t);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Points strictly between `p` and `q` on their line, each once (by
    /// exact bits), ordered from `p`: by looking at every point.
    fn brute_between(all: &[Vec3], p: Vec3, q: Vec3, f: usize) -> Vec<[u32; 3]> {
        let (lo, hi) = (p[f].min(q[f]), p[f].max(q[f]));
        let mut v: Vec<Vec3> = all
            .iter()
            .copied()
            .filter(|x| (0..3).all(|a| a == f || key(*x)[a] == key(p)[a]))
            .filter(|x| x[f] > lo && x[f] < hi)
            .collect();
        v.sort_by(|a, b| a[f].total_cmp(&b[f]));
        if p[f] > q[f] {
            v.reverse();
        }
        let mut keys: Vec<[u32; 3]> = v.into_iter().map(key).collect();
        keys.dedup();
        keys
    }

    /// A coordinate from a small set, so that points share lines (and
    /// both zeros, which are the same point).
    fn coordinate() -> impl Strategy<Value = f32> {
        prop_oneof![
            Just(0.0f32),
            Just(-0.0f32),
            Just(1.0f32),
            Just(-2.5f32),
            (-4i32..4).prop_map(|i| i as f32 * 0.75),
        ]
    }

    fn point() -> impl Strategy<Value = Vec3> {
        (coordinate(), coordinate(), coordinate()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
    }

    proptest! {
        /// The scene's sorted vertices and the inserted points together
        /// give exactly the points a look at every point finds, in order,
        /// each once, whichever of the two holds a point (or both).
        #[test]
        fn points_between_match_a_look_at_every_point(
            scene in prop::collection::vec(point(), 3..40),
            made in prop::collection::vec(point(), 0..20),
            ends in prop::collection::vec((point(), 0usize..3, coordinate()), 1..20),
        ) {
            let n = scene.len() as u32;
            // Every scene vertex but the last is used by a triangle.
            let triangles: Vec<[u32; 3]> = (0..n - 1).map(|i| [i, (i + 1) % (n - 1), 0]).collect();
            let used: Vec<Vec3> = scene[..scene.len() - 1].to_vec();
            let mut lines = Lines::with_scene(&scene, &triangles);
            for &x in &made {
                lines.insert(x);
            }
            let all: Vec<Vec3> = used.iter().chain(&made).copied().collect();
            for &(p, f, other) in &ends {
                let mut q = p;
                q[f] = other;
                let got: Vec<[u32; 3]> = lines.between(p, q, f).into_iter().map(key).collect();
                prop_assert_eq!(got, brute_between(&all, p, q, f));
            }
        }
    }
}
