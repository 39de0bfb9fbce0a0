//! Walls: seams and box faces with the traces of the other seams, each
//! triangulated once (item 2 of [`super`]).

use std::collections::HashMap;

use glam::{DVec2, Vec3};
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

use super::clip::Cut;
use super::geometry::{
    Lines, Registry, Wall, WallTriangle, free_axis, orient2, outline, subdivide,
};
use crate::outofcore::error::SeamError;
use crate::outofcore::plane::{SplitPlane, key};
use crate::outofcore::section::add_seam_constraint;

/// The edge of wall `r`'s rectangle lying in wall `w`'s plane and inside
/// its rectangle, if any.
pub(super) fn trace(w: &Wall, r: &Wall) -> Option<(Vec3, Vec3)> {
    let c = w.plane.axis;
    if r.plane.axis == c || !(r.lo[c] == w.plane.value || r.hi[c] == w.plane.value) {
        return None;
    }
    let f = 3 - c - r.plane.axis;
    let mut p = r.lo;
    p[c] = w.plane.value;
    let mut q = p;
    q[f] = r.hi[f];
    let inside = |x: Vec3| (0..3).all(|a| x[a] >= w.lo[a] && x[a] <= w.hi[a]);
    (inside(p) && inside(q)).then_some((p, q))
}

/// Adds the outer walls, the axis segments of every wall, and the
/// trace crossings to the exact line index.
pub(super) fn prepare_walls(cut: &mut Cut, lo: Vec3, hi: Vec3) {
    for axis in 0..3 {
        for value in [lo[axis], hi[axis]] {
            let (mut wlo, mut whi) = (lo, hi);
            wlo[axis] = value;
            whi[axis] = value;
            cut.walls.push(Wall {
                plane: SplitPlane { axis, value },
                lo: wlo,
                hi: whi,
                seam: false,
                segments: Vec::new(),
                in_plane: Vec::new(),
                points: Vec::new(),
                axis_segments: Vec::new(),
                triangles: Vec::new(),
            });
        }
    }
    let n = cut.walls.len();
    for i in 0..n {
        let w = &cut.walls[i];
        let c = w.plane.axis;
        let (u, v) = ((c + 1) % 3, (c + 2) % 3);
        let corner = |a: f32, b: f32| {
            let mut p = w.lo;
            p[u] = a;
            p[v] = b;
            p
        };
        let (c00, c10, c11, c01) = (
            corner(w.lo[u], w.lo[v]),
            corner(w.hi[u], w.lo[v]),
            corner(w.hi[u], w.hi[v]),
            corner(w.lo[u], w.hi[v]),
        );
        let mut segs = vec![(c00, c10), (c10, c11), (c11, c01), (c01, c00)];
        for j in 0..n {
            if j != i
                && cut.walls[j].seam
                && let Some(s) = trace(w, &cut.walls[j])
            {
                segs.push(s);
            }
        }
        // Crossings of perpendicular segments.
        let mut extra = vec![c00, c10, c11, c01];
        for (a, s) in segs.iter().enumerate() {
            for t in &segs[a + 1..] {
                let (Some(fs), Some(ft)) = (free_axis(s.0, s.1), free_axis(t.0, t.1)) else {
                    continue;
                };
                if fs == ft {
                    continue;
                }
                // s runs along fs at fixed ft-coordinate s.0[ft]; t along ft.
                let mut x = s.0;
                x[fs] = t.0[fs];
                let within = |x: f32, p: f32, q: f32| x >= p.min(q) && x <= p.max(q);
                if within(x[fs], s.0[fs], s.1[fs]) && within(x[ft], t.0[ft], t.1[ft]) {
                    extra.push(x);
                }
            }
            extra.push(s.0);
            extra.push(s.1);
        }
        for x in extra {
            cut.lines.insert(x);
        }
        cut.walls[i].axis_segments = segs;
    }
}

/// Triangulates one wall (see the module docs).
pub(super) fn triangulate_wall(
    w: &Wall,
    reg: &Registry,
    lines: &Lines,
) -> Result<Vec<WallTriangle>, SeamError> {
    let c = w.plane.axis;
    let (u, v) = ((c + 1) % 3, (c + 2) % 3);
    let to2 = |p: Vec3| Point2::new(p[u] as f64, p[v] as f64);
    let flat = |p: Vec3| DVec2::new(p[u] as f64, p[v] as f64);
    let mut cdt: ConstrainedDelaunayTriangulation<Point2<f64>> =
        ConstrainedDelaunayTriangulation::new();
    let mut handles = HashMap::new();
    let mut back: Vec<Vec3> = Vec::new();
    let mut polylines: Vec<Vec<Vec3>> = Vec::new();
    for &(p, q) in &w.axis_segments {
        let mut l = vec![p];
        l.extend(lines.between(p, q, free_axis(p, q).unwrap_or(u)));
        l.push(q);
        polylines.push(l);
    }
    for &(root, p, q, s) in &w.segments {
        let mut l = vec![p];
        l.extend(subdivide(reg, lines, root, p, q, s)?);
        l.push(q);
        polylines.push(l);
    }
    let mut labels = Vec::new();
    for poly in &w.in_plane {
        let mut l = outline(reg, lines, poly)?;
        l.push(l[0]);
        polylines.push(l);
        labels.push((
            poly.v.iter().map(|&p| flat(p)).collect::<Vec<_>>(),
            poly.source,
        ));
    }
    let mut insert = |cdt: &mut ConstrainedDelaunayTriangulation<Point2<f64>>, p: Vec3| {
        if let Some(&h) = handles.get(&key(p)) {
            return Ok::<_, SeamError>(h);
        }
        let h = cdt.insert(to2(p)).map_err(|e| SeamError::SeamPoint {
            point: p,
            message: format!("{e:?}"),
        })?;
        handles.insert(key(p), h);
        back.push(p);
        Ok(h)
    };
    for &p in &w.points {
        insert(&mut cdt, p)?;
    }
    for l in &polylines {
        for &p in l {
            insert(&mut cdt, p)?;
        }
    }
    for l in &polylines {
        for e in l.windows(2) {
            let (h0, h1) = (insert(&mut cdt, e[0])?, insert(&mut cdt, e[1])?);
            add_seam_constraint(&mut cdt, (e[0], h0), (e[1], h1))?;
        }
    }
    let to3 = |p: Point2<f64>| {
        let mut r = Vec3::ZERO;
        r[c] = w.plane.value;
        r[u] = p.x as f32;
        r[v] = p.y as f32;
        r
    };
    let mut out = Vec::with_capacity(cdt.num_inner_faces());
    for f in cdt.inner_faces() {
        let mut t = f.vertices().map(|h| to3(h.position()));
        let g = (flat(t[0]) + flat(t[1]) + flat(t[2])) / 3.0;
        let mut source = None;
        for (outline, id) in &labels {
            let m = outline.len();
            let o = orient2(outline[0], outline[1], outline[2]);
            let inside = (0..m).all(|i| orient2(outline[i], outline[(i + 1) % m], g) * o > 0.0);
            if inside {
                source = Some(*id);
                if orient2(flat(t[0]), flat(t[1]), flat(t[2])) * o < 0.0 {
                    t.swap(1, 2);
                }
                break;
            }
        }
        out.push((t, source));
    }
    Ok(out)
}
