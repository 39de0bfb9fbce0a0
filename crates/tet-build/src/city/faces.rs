//! The surface of one block of the city: axis-aligned rectangles
//! triangulated with every corner of the block that lies on their sides,
//! so that coplanar neighbours of different sizes meet without
//! T-junctions (see the parent module's docs).

use glam::{DVec3, Vec3};

/// An axis-aligned rectangle of the surface: normal along `axis`, in the
/// plane `p[axis] = c`, spanning `lo..hi` in the in-plane axes
/// `u = (axis + 1) % 3`, `v = (axis + 2) % 3`; `out` (±1) is the side its
/// outward normal points to.
#[derive(Clone, Copy, Debug)]
pub(super) struct Rect {
    pub(super) axis: usize,
    pub(super) c: i32,
    pub(super) lo: [i32; 2],
    pub(super) hi: [i32; 2],
    pub(super) out: i32,
}

impl Rect {
    /// The rectangle in the plane `p[axis] = c` over the global ranges
    /// `ranges` (the entry of `axis` is ignored).
    pub(super) fn new(axis: usize, c: i32, ranges: [(i32, i32); 3], out: i32) -> Rect {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        Rect {
            axis,
            c,
            lo: [ranges[u].0, ranges[v].0],
            hi: [ranges[u].1, ranges[v].1],
            out,
        }
    }

    /// The point at in-plane coordinates `(u, v)`.
    fn point(&self, u: i32, v: i32) -> [i32; 3] {
        let mut p = [0; 3];
        p[self.axis] = self.c;
        p[(self.axis + 1) % 3] = u;
        p[(self.axis + 2) % 3] = v;
        p
    }
}

/// Point `p` reordered so that sorting puts the points of one line along
/// `axis` together, ordered along it.
fn line_key(axis: usize, p: [i32; 3]) -> [i32; 3] {
    [p[(axis + 1) % 3], p[(axis + 2) % 3], p[axis]]
}

/// The corners of one block's rectangles, sorted (a corner's index is its
/// vertex number), and the same points sorted along each axis's lines.
#[derive(Default)]
pub(super) struct Corners {
    pub(super) points: Vec<[i32; 3]>,
    pub(super) lines: [Vec<[i32; 3]>; 3],
}

impl Corners {
    /// The corners of `rects`, replacing the previous block's.
    pub(super) fn build(&mut self, rects: &[Rect]) {
        self.points.clear();
        for r in rects {
            for (u, v) in [
                (r.lo[0], r.lo[1]),
                (r.hi[0], r.lo[1]),
                (r.hi[0], r.hi[1]),
                (r.lo[0], r.hi[1]),
            ] {
                self.points.push(r.point(u, v));
            }
        }
        self.points.sort_unstable();
        self.points.dedup();
        for (axis, line) in self.lines.iter_mut().enumerate() {
            line.clear();
            line.extend(self.points.iter().map(|&p| line_key(axis, p)));
            line.sort_unstable();
        }
    }

    /// Vertex number of corner `p` (every triangle corner but a fan's
    /// centre is a rectangle corner).
    pub(super) fn index(&self, p: [i32; 3]) -> u32 {
        self.points.partition_point(|q| *q < p) as u32
    }

    /// Coordinates along `axis` of the corners strictly between `from`
    /// and `from` moved to `to` along `axis`, in increasing order.
    pub(super) fn between(&self, axis: usize, from: [i32; 3], to: i32) -> Vec<i32> {
        let line = &self.lines[axis];
        let key = line_key(axis, from);
        let (a, b) = (key[2].min(to), key[2].max(to));
        let start = line.partition_point(|k| *k <= [key[0], key[1], a]);
        line[start..]
            .iter()
            .take_while(|k| k[0] == key[0] && k[1] == key[1] && k[2] < b)
            .map(|k| k[2])
            .collect()
    }
}

/// One block's surface in local vertex numbers: the corners, then the fan
/// centres.
#[derive(Default)]
pub(super) struct BlockMesh {
    pub(super) rects: Vec<Rect>,
    pub(super) corners: Corners,
    pub(super) centres: Vec<Vec3>,
    pub(super) triangles: Vec<[u32; 3]>,
}

/// A vertex of a triangle being emitted: a corner, or a new fan centre
/// (doubled coordinates).
#[derive(Clone, Copy)]
enum Corner {
    At([i32; 3]),
    Centre(u32, [i32; 3]),
}

impl BlockMesh {
    /// The local vertex number and position of `c`.
    fn vertex(&self, c: Corner) -> (u32, DVec3) {
        match c {
            Corner::At(p) => (self.corners.index(p), to_dvec(p)),
            Corner::Centre(i, p2) => (self.corners.points.len() as u32 + i, to_dvec(p2) * 0.5),
        }
    }

    /// Triangle `abc` of rectangle `r`, wound so that its normal points to
    /// `r.out` along `r.axis`.
    fn emit(&mut self, r: &Rect, t: [Corner; 3]) {
        let [(a, pa), (b, pb), (c, pc)] = t.map(|c| self.vertex(c));
        let n = (pb - pa).cross(pc - pa)[r.axis];
        self.triangles.push(if n * f64::from(r.out) > 0.0 {
            [a, b, c]
        } else {
            [a, c, b]
        });
    }

    /// Triangulates rectangle `r` with every corner of the block lying on
    /// its sides (see the module docs).
    pub(super) fn triangulate(&mut self, r: &Rect) {
        let (ua, va) = ((r.axis + 1) % 3, (r.axis + 2) % 3);
        let [u0, v0] = r.lo;
        let [u1, v1] = r.hi;
        let bottom = self.corners.between(ua, r.point(u0, v0), u1);
        let top = self.corners.between(ua, r.point(u0, v1), u1);
        let left = self.corners.between(va, r.point(u0, v0), v1);
        let right = self.corners.between(va, r.point(u1, v0), v1);
        let at = |u: i32, v: i32| Corner::At(r.point(u, v));
        // The boundary, counter-clockwise in (u, v), from corner BL; the
        // indices of the four corners in it.
        let mut ring = vec![at(u0, v0)];
        ring.extend(bottom.iter().map(|&u| at(u, v0)));
        let br = ring.len();
        ring.push(at(u1, v0));
        ring.extend(right.iter().map(|&v| at(u1, v)));
        let tr = ring.len();
        ring.push(at(u1, v1));
        ring.extend(top.iter().rev().map(|&u| at(u, v1)));
        let tl = ring.len();
        ring.push(at(u0, v1));
        ring.extend(left.iter().rev().map(|&v| at(u0, v)));
        let plain = [
            (0, bottom.is_empty() && left.is_empty()),
            (br, bottom.is_empty() && right.is_empty()),
            (tr, top.is_empty() && right.is_empty()),
            (tl, top.is_empty() && left.is_empty()),
        ];
        let free: Vec<usize> = plain.iter().filter(|p| p.1).map(|p| p.0).collect();
        if free.len() == 4 {
            // A plain rectangle: two triangles, the diagonal alternating.
            let k = if (u0 + v0 + r.c).rem_euclid(2) == 0 {
                0
            } else {
                1
            };
            let q = [0, br, tr, tl].map(|i| ring[i]);
            self.emit(r, [q[k], q[k + 1], q[(k + 2) % 4]]);
            self.emit(r, [q[k], q[(k + 2) % 4], q[(k + 3) % 4]]);
        } else if let Some(&apex) = free.first() {
            // A fan from a corner whose two sides are plain.
            let n = ring.len();
            for i in 1..n - 1 {
                let (a, b) = ((apex + i) % n, (apex + i + 1) % n);
                self.emit(r, [ring[apex], ring[a], ring[b]]);
            }
        } else if top.is_empty() && bottom.is_empty() {
            let a: Vec<Corner> = chain(v0, &left, v1).map(|v| at(u0, v)).collect();
            let b: Vec<Corner> = chain(v0, &right, v1).map(|v| at(u1, v)).collect();
            let pa: Vec<i32> = chain(v0, &left, v1).collect();
            let pb: Vec<i32> = chain(v0, &right, v1).collect();
            self.ladder(r, &a, &pa, &b, &pb);
        } else if left.is_empty() && right.is_empty() {
            let a: Vec<Corner> = chain(u0, &bottom, u1).map(|u| at(u, v0)).collect();
            let b: Vec<Corner> = chain(u0, &top, u1).map(|u| at(u, v1)).collect();
            let pa: Vec<i32> = chain(u0, &bottom, u1).collect();
            let pb: Vec<i32> = chain(u0, &top, u1).collect();
            self.ladder(r, &a, &pa, &b, &pb);
        } else {
            // Corners on three or four sides: a fan around the centre.
            let mut p2 = [2 * r.c; 3];
            p2[ua] = u0 + u1;
            p2[va] = v0 + v1;
            let centre = Corner::Centre(self.centres.len() as u32, p2);
            self.centres.push((to_dvec(p2) * 0.5).as_vec3());
            for i in 0..ring.len() {
                self.emit(r, [centre, ring[i], ring[(i + 1) % ring.len()]]);
            }
        }
    }

    /// The strip of triangles between two chains on parallel lines (`a`
    /// at parameters `pa`, `b` at `pb`, both increasing, equal at both
    /// ends): every triangle has two vertices on one line and one on the
    /// other, so none is degenerate.
    fn ladder(&mut self, r: &Rect, a: &[Corner], pa: &[i32], b: &[Corner], pb: &[i32]) {
        let (mut i, mut j) = (0, 0);
        while i + 1 < a.len() || j + 1 < b.len() {
            if i + 1 < a.len() && (j + 1 == b.len() || pa[i + 1] <= pb[j + 1]) {
                self.emit(r, [a[i], a[i + 1], b[j]]);
                i += 1;
            } else {
                self.emit(r, [a[i], b[j + 1], b[j]]);
                j += 1;
            }
        }
    }
}

/// `first`, the interior values, `last`.
pub(super) fn chain(first: i32, inner: &[i32], last: i32) -> impl Iterator<Item = i32> + '_ {
    std::iter::once(first)
        .chain(inner.iter().copied())
        .chain(std::iter::once(last))
}

/// `p` in f64 (exact).
fn to_dvec(p: [i32; 3]) -> DVec3 {
    DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]))
}
