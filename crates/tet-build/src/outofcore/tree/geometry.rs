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

/// Points on axis-parallel lines, found exactly: bucket `(free axis, the
/// other two coordinates' bits)`.
#[derive(Default)]
pub(super) struct Lines {
    pub(super) seen: HashSet<[u32; 3]>,
    pub(super) buckets: HashMap<(usize, [u32; 2]), Vec<Vec3>>,
}

impl Lines {
    pub(super) fn insert(&mut self, p: Vec3) {
        if !self.seen.insert(key(p)) {
            return;
        }
        let k = key(p);
        for f in 0..3 {
            let (i, j) = ((f + 1) % 3, (f + 2) % 3);
            let (i, j) = (i.min(j), i.max(j));
            self.buckets.entry((f, [k[i], k[j]])).or_default().push(p);
        }
    }

    /// Points strictly between `p` and `q` (which share two coordinates,
    /// free axis `f`), ordered from `p` to `q`.
    pub(super) fn between(&self, p: Vec3, q: Vec3, f: usize) -> Vec<Vec3> {
        let k = key(p);
        let (i, j) = ((f + 1) % 3, (f + 2) % 3);
        let (i, j) = (i.min(j), i.max(j));
        let (lo, hi) = (p[f].min(q[f]), p[f].max(q[f]));
        let mut v: Vec<Vec3> = self
            .buckets
            .get(&(f, [k[i], k[j]]))
            .map(|b| {
                b.iter()
                    .copied()
                    .filter(|x| x[f] > lo && x[f] < hi)
                    .collect()
            })
            .unwrap_or_default();
        if p[f] <= q[f] {
            v.sort_by(|a, b| a[f].total_cmp(&b[f]));
        } else {
            v.sort_by(|a, b| b[f].total_cmp(&a[f]));
        }
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
