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

/// Registered crossing points: `(root, t, point)`. While the clipping
/// runs, every crossing is appended (a crossing two pieces share is there
/// twice); [`Registry::freeze`] then sorts them by root and `t`, each
/// point once per root, which is what the walls and pieces look up. One
/// flat array rather than a map of lists: 48 bytes per crossing instead of
/// about 170 per root (a map entry, a list and its allocation), the
/// planner's largest item on scenes cut into many parts.
#[derive(Default)]
pub(super) struct Registry {
    points: Vec<(RootId, f64, Vec3)>,
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
        self.points.push((root.id(), t, x));
        Ok(x)
    }

    /// Sorts the crossings by root, then `t`, each point (by exact bits)
    /// once per root; called once, after the clipping.
    pub(super) fn freeze(&mut self) {
        let p = &mut self.points;
        p.sort_unstable_by(|a, b| {
            a.0.cmp(&b.0)
                .then(key(a.2).cmp(&key(b.2)))
                .then(a.1.total_cmp(&b.1))
        });
        p.dedup_by(|a, b| a.0 == b.0 && key(a.2) == key(b.2));
        p.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
        p.shrink_to_fit();
    }

    /// Every registered point (a point on several roots once per root).
    pub(super) fn points(&self) -> impl Iterator<Item = Vec3> + '_ {
        self.points.iter().map(|p| p.2)
    }

    /// The crossings on `root`, ordered by `t` (after [`Registry::freeze`]).
    pub(super) fn on_root(&self, root: Root) -> &[(RootId, f64, Vec3)] {
        let id = root.id();
        let start = self.points.partition_point(|p| p.0 < id);
        let len = self.points[start..].partition_point(|p| p.0 == id);
        &self.points[start..start + len]
    }

    /// Parameter of `p` along `root`.
    pub(super) fn t_of(&self, root: Root, p: Vec3) -> Option<f64> {
        if key(p) == key(root.a) {
            return Some(0.0);
        }
        if key(p) == key(root.b) {
            return Some(1.0);
        }
        self.on_root(root)
            .iter()
            .find(|(_, _, q)| key(*q) == key(p))
            .map(|(_, t, _)| *t)
    }
}

/// Points on axis-parallel lines, found exactly: the scene's vertices and
/// the crossings the cut makes, each sorted once per free axis by (the
/// other two coordinates' bits, the free coordinate), and the few points
/// the walls add later (wall corners and trace crossings) in buckets
/// `(free axis, the other two coordinates' bits)`. Sorted copies rather
/// than hashed: a tenth of the memory, which is what lets a planner hold
/// a large scene (and a scene cut into many parts).
#[derive(Default)]
pub(super) struct Lines {
    scene: [Vec<Vec3>; 3],
    crossings: [Vec<Vec3>; 3],
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
    /// Lines holding the vertices of `triangles` that a segment of the cut
    /// can pass through: for free axis `f`, a vertex that shares its line
    /// with another vertex, or one of whose two other coordinates is a
    /// plane value of that axis (`planes[a]`: the tree's planes and the
    /// enclosing box's faces on axis `a`).
    ///
    /// Why that is all [`Lines::between`] needs: an axis-parallel segment
    /// of the cut lies on a scene edge (whose two ends are vertices on its
    /// line), on a cut segment or in-plane scene edge (every point of which
    /// has the plane's coordinate), or on a wall's boundary or trace (two
    /// plane coordinates). A vertex strictly between its ends shares their
    /// line, so it is kept. On a curved scene almost no vertex is, where
    /// three sorted copies of every vertex were 18 bytes per triangle of
    /// the planner's memory.
    pub(super) fn with_scene(
        vertices: &[Vec3],
        triangles: &[[u32; 3]],
        planes: [&[f32]; 3],
    ) -> Lines {
        let mut used = vec![false; vertices.len()];
        for t in triangles {
            for &v in t {
                used[v as usize] = true;
            }
        }
        let mut indices: Vec<u32> = (0..vertices.len() as u32)
            .filter(|&v| used[v as usize])
            .collect();
        drop(used);
        let mut planes = planes.map(|p| {
            let mut v: Vec<u32> = p.iter().map(|&x| (x + 0.0).to_bits()).collect();
            v.sort_unstable();
            v
        });
        for p in &mut planes {
            p.dedup();
        }
        let on_plane = |p: Vec3, a: usize| planes[a].binary_search(&(p[a] + 0.0).to_bits()).is_ok();
        let scene = std::array::from_fn(|f| {
            let at = |v: u32| vertices[v as usize];
            indices.sort_unstable_by(|&a, &b| line_order(f, at(a), at(b)));
            let (i, j) = ((f + 1) % 3, (f + 2) % 3);
            let mut kept = Vec::new();
            for run in indices.chunk_by(|&a, &b| line_of(f, at(a)) == line_of(f, at(b))) {
                for &v in run {
                    let p = at(v);
                    if run.len() > 1 || on_plane(p, i) || on_plane(p, j) {
                        kept.push(p);
                    }
                }
            }
            kept.shrink_to_fit();
            kept
        });
        Lines {
            scene,
            ..Lines::default()
        }
    }

    /// Adds the crossings of the cut (all at once, after the clipping).
    pub(super) fn add_crossings(&mut self, points: impl Iterator<Item = Vec3>) {
        let mut v: Vec<Vec3> = points.collect();
        v.sort_unstable_by_key(|p| key(*p));
        v.dedup_by_key(|p| key(*p));
        self.crossings = sorted_per_axis(v);
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
        fn on_line(sorted: &[Vec3], f: usize, line: [u32; 2]) -> &[Vec3] {
            let start = sorted.partition_point(|x| line_of(f, *x) < line);
            let len = sorted[start..].partition_point(|x| line_of(f, *x) == line);
            &sorted[start..start + len]
        }
        let made = self
            .buckets
            .get(&(f, line))
            .map_or(&[][..], |b| b.as_slice());
        let mut v: Vec<Vec3> = on_line(&self.scene[f], f, line)
            .iter()
            .chain(on_line(&self.crossings[f], f, line))
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

/// The order of points on lines with free axis `f`: by line, then by the
/// free coordinate.
fn line_order(f: usize, a: Vec3, b: Vec3) -> std::cmp::Ordering {
    line_of(f, a)
        .cmp(&line_of(f, b))
        .then(a[f].total_cmp(&b[f]))
}

/// `points` in three copies, the `f`-th sorted by (the line with free axis
/// `f`, the free coordinate).
fn sorted_per_axis(points: Vec<Vec3>) -> [Vec<Vec3>; 3] {
    let sorted = |f: usize, mut v: Vec<Vec3>| {
        v.sort_unstable_by(|a, b| line_order(f, *a, *b));
        v
    };
    let (x, y) = (sorted(0, points.clone()), sorted(1, points.clone()));
    [x, y, sorted(2, points)]
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
    let mut v: Vec<Vec3> = reg
        .on_root(root)
        .iter()
        .filter(|(_, t, _)| *t > lo && *t < hi)
        .map(|(_, _, x)| *x)
        .collect();
    if tp > tq {
        v.reverse();
    }
    Ok(v)
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
        /// After the freeze, a root's crossings are the distinct points
        /// registered on it, ordered by `t`, and `t_of` finds each (and
        /// the root's ends), whatever the order they were registered in
        /// and however often.
        #[test]
        fn registry_lists_each_roots_crossings_once_in_order(
            ends in prop::collection::vec((point(), point()), 1..6),
            crossings in prop::collection::vec((0usize..6, 0usize..3, 0.05f32..0.95), 1..40),
        ) {
            let roots: Vec<Root> = ends
                .iter()
                .filter(|(p, q)| (0..3).all(|a| p[a] != q[a]))
                .map(|&(p, q)| Root::new(p, q))
                .collect();
            prop_assume!(!roots.is_empty());
            let mut reg = Registry::default();
            let mut expected: Vec<Vec<(f64, [u32; 3])>> = vec![Vec::new(); roots.len()];
            for &(r, axis, s) in &crossings {
                let k = r % roots.len();
                let root = roots[k];
                let (a, b) = (root.a[axis], root.b[axis]);
                let plane = SplitPlane { axis, value: a + (b - a) * s };
                let Ok(x) = reg.cross(root, plane, 0) else { continue };
                let t = (plane.value as f64 - a as f64) / (b as f64 - a as f64);
                if !expected[k].iter().any(|e| e.1 == key(x)) {
                    expected[k].push((t, key(x)));
                }
            }
            reg.freeze();
            for (k, &root) in roots.iter().enumerate() {
                // Roots with the same ends share their crossings.
                let mut want: Vec<(f64, [u32; 3])> = roots
                    .iter()
                    .enumerate()
                    .filter(|(_, r)| r.id() == root.id())
                    .flat_map(|(j, _)| expected[j].clone())
                    .collect();
                want.sort_by_key(|w| w.1);
                want.dedup_by(|a, b| a.1 == b.1);
                want.sort_by(|a, b| a.0.total_cmp(&b.0));
                let got: Vec<[u32; 3]> = reg.on_root(root).iter().map(|p| key(p.2)).collect();
                let want_keys: Vec<[u32; 3]> = want.iter().map(|w| w.1).collect();
                prop_assert_eq!(&got, &want_keys, "root {}", k);
                for p in reg.on_root(root) {
                    prop_assert_eq!(reg.t_of(root, p.2), Some(p.1));
                }
                prop_assert_eq!(reg.t_of(root, root.a), Some(0.0));
                prop_assert_eq!(reg.t_of(root, root.b), Some(1.0));
            }
        }

        /// The scene's sorted vertices and the inserted points together
        /// give exactly the points a look at every point finds, in order,
        /// each once, whichever of the two holds a point (or both), for
        /// every segment the cut can make: one ending at a scene vertex,
        /// or one with a coordinate on a plane.
        #[test]
        fn points_between_match_a_look_at_every_point(
            scene in prop::collection::vec(point(), 3..40),
            made in prop::collection::vec(point(), 0..20),
            planes in prop::collection::vec((0usize..3, coordinate()), 0..6),
            ends in prop::collection::vec(
                (point(), 0usize..3, coordinate(), 0usize..40, 0usize..4),
                1..20,
            ),
        ) {
            let n = scene.len() as u32;
            // Every scene vertex but the last is used by a triangle.
            let triangles: Vec<[u32; 3]> = (0..n - 1).map(|i| [i, (i + 1) % (n - 1), 0]).collect();
            let used: Vec<Vec3> = scene[..scene.len() - 1].to_vec();
            let by_axis: [Vec<f32>; 3] = std::array::from_fn(|a| {
                planes.iter().filter(|p| p.0 == a).map(|p| p.1).collect()
            });
            let mut lines = Lines::with_scene(
                &scene,
                &triangles,
                [&by_axis[0][..], &by_axis[1][..], &by_axis[2][..]],
            );
            // The crossings come all at once, the walls' points one by one.
            let (crossings, late) = made.split_at(made.len() / 2);
            lines.add_crossings(crossings.iter().copied());
            for &x in late {
                lines.insert(x);
            }
            let all: Vec<Vec3> = used.iter().chain(&made).copied().collect();
            for &(p, f, other, vertex, how) in &ends {
                // The end: a used scene vertex, or a point with one of its
                // coordinates across `f` on a plane of that axis.
                let p = match how {
                    0 | 1 => used[vertex % used.len()],
                    _ => {
                        let a = (f + 1 + how % 2) % 3;
                        let Some(&value) = by_axis[a].first() else { continue };
                        let mut p = p;
                        p[a] = value;
                        p
                    }
                };
                let mut q = p;
                q[f] = other;
                let got: Vec<[u32; 3]> = lines.between(p, q, f).into_iter().map(key).collect();
                prop_assert_eq!(got, brute_between(&all, p, q, f));
            }
        }
    }
}
