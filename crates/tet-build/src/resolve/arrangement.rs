//! The exact arrangement of the constraint segments inside one triangle.
//!
//! Every segment lies in the triangle's plane, on a line written as a plane
//! through explicit vertices (another triangle's plane, or the vertical
//! plane through a mesh edge), so "which side of segment `s` is point `p`"
//! is one exact [`Geo::side`] test. Per triangle:
//!
//! 1. segments along a mesh edge also pass through that edge's registered
//!    points;
//! 2. two segments whose ends lie strictly on both sides of each other's
//!    line cross: the crossing is named by the two lines (three planes,
//!    an edge and a plane, or two edges), so the triangles that share a
//!    line find the same point;
//! 3. every interior point lying exactly on a segment splits it;
//! 4. the points on each segment are sorted exactly along it and equal
//!    neighbours merged; all interior points are sorted exactly and equal
//!    ones merged.
//!
//! A bounding-box test (in doubles, with a margin far above their error)
//! skips pairs that cannot meet.

use glam::DVec3;

use super::pairs::Line;
use super::points::{Edge, Geo, Key, Plane, PointDef, sorted3};
use super::table::{FxMap, PointTable};

/// Marks an id of a point new to this arrangement (not in the table).
pub(crate) const LOCAL: u32 = 1 << 31;

/// A constraint segment between two point ids.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct Seg {
    /// Its line.
    pub line: Line,
    /// One end.
    pub a: u32,
    /// The other end.
    pub b: u32,
}

/// What one triangle's arrangement found. Point references are table ids,
/// or `LOCAL | i` for `new_points[i]`.
#[derive(Clone, Debug, Default)]
pub(crate) struct Arranged {
    /// Constraint edges (split at every point on them).
    pub constraints: Vec<[u32; 2]>,
    /// Points strictly inside the triangle.
    pub points: Vec<u32>,
    /// Pairs found to be the same point.
    pub unify: Vec<[u32; 2]>,
    /// Points not in the table yet: name, construction, position.
    pub new_points: Vec<(Key, PointDef, DVec3)>,
}

struct Ctx<'a> {
    geo: &'a Geo<'a>,
    table: &'a PointTable,
    out: Arranged,
}

impl Ctx<'_> {
    fn def(&self, r: u32) -> PointDef {
        if r & LOCAL != 0 {
            self.out.new_points[(r & !LOCAL) as usize].1
        } else {
            self.table.defs[r as usize]
        }
    }
    fn approx(&self, r: u32) -> DVec3 {
        if r & LOCAL != 0 {
            self.out.new_points[(r & !LOCAL) as usize].2
        } else {
            self.table.approx[r as usize]
        }
    }
    fn point(&mut self, key: Key) -> u32 {
        if let Some(id) = self.table.get(&key) {
            return id;
        }
        if let Some(i) = self.out.new_points.iter().position(|p| p.0 == key) {
            return LOCAL | i as u32;
        }
        let def = self.geo.def_of(&key);
        let at = self.geo.approx(&def);
        self.out.new_points.push((key, def, at));
        LOCAL | (self.out.new_points.len() - 1) as u32
    }
    fn cmp(&self, a: u32, b: u32, axis: usize) -> std::cmp::Ordering {
        if a == b {
            return std::cmp::Ordering::Equal;
        }
        self.geo.cmp_axis(&self.def(a), &self.def(b), axis)
    }
    /// `x` strictly between `a` and `b` (all on one line) along `axis`.
    fn between(&self, x: u32, a: u32, b: u32, axis: usize) -> bool {
        let (ca, cb) = (self.cmp(x, a, axis), self.cmp(x, b, axis));
        ca.is_ne() && cb.is_ne() && ca != cb
    }
}

struct Work {
    line: Line,
    plane: Plane,
    a: u32,
    b: u32,
    axis: usize,
    pts: Vec<u32>,
    lo: DVec3,
    hi: DVec3,
}

fn margin(lo: DVec3, hi: DVec3) -> DVec3 {
    DVec3::splat(lo.abs().max(hi.abs()).max_element() * 1e-9 + 1e-300)
}

/// The arrangement of `segments` (and the `interior` points) inside
/// triangle `tri` projected along `axis`. `registry` holds each mesh edge's
/// points.
pub(crate) fn arrange(
    geo: &Geo,
    table: &PointTable,
    registry: &FxMap<Edge, Vec<u32>>,
    tri: [u32; 3],
    axis: usize,
    interior: &[u32],
    segments: &[Seg],
) -> Arranged {
    let mut cx = Ctx {
        geo,
        table,
        out: Arranged::default(),
    };
    let tkey = sorted3(tri);
    let mut segs: Vec<Seg> = segments.to_vec();
    segs.iter_mut().for_each(|s| {
        if s.a > s.b {
            std::mem::swap(&mut s.a, &mut s.b);
        }
    });
    segs.sort_unstable_by_key(|s| (s.a, s.b, s.line));
    segs.dedup();
    let mut work: Vec<Work> = Vec::with_capacity(segs.len());
    for s in segs {
        let (da, db) = (cx.def(s.a), cx.def(s.b));
        let Some(along) = (s.a != s.b).then(|| geo.line_axis(&da, &db)).flatten() else {
            cx.out.unify.push([s.a, s.b]);
            continue;
        };
        let plane = match s.line {
            Line::Plane(b) => Plane::Triangle(b),
            Line::Edge(f) => Plane::Vertical {
                edge: f,
                axis: axis as u8,
            },
        };
        let mut pts = vec![s.a, s.b];
        if let Line::Edge(f) = s.line
            && let Some(on) = registry.get(&f)
        {
            pts.extend(
                on.iter()
                    .copied()
                    .filter(|&x| x != s.a && x != s.b && cx.between(x, s.a, s.b, along)),
            );
        }
        let (pa, pb) = (cx.approx(s.a), cx.approx(s.b));
        let (lo, hi) = (pa.min(pb), pa.max(pb));
        let m = margin(lo, hi);
        work.push(Work {
            line: s.line,
            plane,
            a: s.a,
            b: s.b,
            axis: along,
            pts,
            lo: lo - m,
            hi: hi + m,
        });
    }
    // Proper crossings.
    for i in 0..work.len() {
        for j in i + 1..work.len() {
            let (wi, wj) = (&work[i], &work[j]);
            if wi.lo.cmpgt(wj.hi).any() || wj.lo.cmpgt(wi.hi).any() || wi.line == wj.line {
                continue;
            }
            let sj = [wj.a, wj.b].map(|p| geo.side(&cx.def(p), &wi.plane));
            if sj[0] * sj[1] >= 0 {
                continue;
            }
            let si = [wi.a, wi.b].map(|p| geo.side(&cx.def(p), &wj.plane));
            if si[0] * si[1] >= 0 {
                continue;
            }
            let key = match (wi.line, wj.line) {
                (Line::Plane(b), Line::Plane(c)) => {
                    let mut t = [tkey, sorted3(b), sorted3(c)];
                    t.sort_unstable();
                    Key::Triple(t)
                }
                (Line::Plane(b), Line::Edge(f)) | (Line::Edge(f), Line::Plane(b)) => {
                    Key::EdgeTriangle(f, sorted3(b))
                }
                (Line::Edge(e), Line::Edge(f)) => Key::EdgeEdge(e.min(f), e.max(f)),
            };
            let x = cx.point(key);
            work[i].pts.push(x);
            work[j].pts.push(x);
        }
    }
    // Interior points lying on a segment.
    let mut inner: Vec<u32> = interior.to_vec();
    inner.sort_unstable();
    inner.dedup();
    for w in &mut work {
        for &x in &inner {
            if x == w.a || x == w.b {
                continue;
            }
            let p = cx.approx(x);
            if p.cmplt(w.lo).any() || p.cmpgt(w.hi).any() {
                continue;
            }
            if geo.side(&cx.def(x), &w.plane) == 0 && cx.between(x, w.a, w.b, w.axis) {
                w.pts.push(x);
            }
        }
    }
    // Split each segment at its points, in exact order.
    for w in &mut work {
        let mut pts = std::mem::take(&mut w.pts);
        pts.sort_unstable();
        pts.dedup();
        pts.sort_by(|&p, &q| cx.cmp(p, q, w.axis));
        let mut prev = pts[0];
        for &p in &pts[1..] {
            if cx.cmp(prev, p, w.axis).is_eq() {
                cx.out.unify.push([prev, p]);
            } else {
                cx.out.constraints.push([prev, p]);
                prev = p;
            }
        }
    }
    // Equal interior points are one point.
    inner.extend((0..cx.out.new_points.len() as u32).map(|i| LOCAL | i));
    inner.sort_by(|&p, &q| geo.cmp_lex(&cx.def(p), &cx.def(q)));
    for k in 1..inner.len() {
        if geo.same(&cx.def(inner[k - 1]), &cx.def(inner[k])) {
            cx.out.unify.push([inner[k - 1], inner[k]]);
        }
    }
    cx.out.points = inner;
    cx.out
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn two_crossing_intersection_lines_meet_at_the_triple_point() {
        // T in z = 0; B in x = 1 and C in y = 1 cross T along x = 1 and
        // y = 1, which meet at (1, 1, 0). The segments' ends are given as
        // vertices 9..13 (where the lines leave T), so no pair pass is
        // needed.
        let verts = [
            Vec3::new(-4.0, -4.0, 0.0),
            Vec3::new(4.0, -4.0, 0.0),
            Vec3::new(0.0, 4.0, 0.0),
            Vec3::new(1.0, -5.0, -1.0),
            Vec3::new(1.0, 5.0, -1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(-5.0, 1.0, -1.0),
            Vec3::new(5.0, 1.0, -1.0),
            Vec3::new(0.0, 1.0, 1.0),
            Vec3::new(1.0, -3.0, 0.0),
            Vec3::new(1.0, 2.0, 0.0),
            Vec3::new(-2.0, 1.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
        ];
        let geo = Geo { verts: &verts };
        let mut table = PointTable::default();
        let ids: Vec<u32> = (9..13).map(|v| table.id(&geo, Key::Vertex(v))).collect();
        let segs = [
            Seg {
                line: Line::Plane([3, 4, 5]),
                a: ids[0],
                b: ids[1],
            },
            Seg {
                line: Line::Plane([6, 7, 8]),
                a: ids[2],
                b: ids[3],
            },
        ];
        let out = arrange(&geo, &table, &FxMap::default(), [0, 1, 2], 2, &ids, &segs);
        assert_eq!(out.new_points.len(), 1);
        let (key, def, at) = out.new_points[0];
        assert_eq!(key, Key::Triple([[0, 1, 2], [3, 4, 5], [6, 7, 8]]));
        assert_eq!(geo.round(&def), Vec3::new(1.0, 1.0, 0.0));
        assert_eq!(at, DVec3::new(1.0, 1.0, 0.0));
        // Each segment is split there: four constraints, all through it.
        assert_eq!(out.constraints.len(), 4);
        assert!(out.constraints.iter().all(|c| c.contains(&LOCAL)));
        assert!(out.unify.is_empty());
    }
}
