//! Clipping in tree order: every scene triangle clipped by the planes of
//! the tree, crossings registered on their roots (item 1 of [`super`]).

use std::collections::HashSet;

use glam::Vec3;

use super::cut_tree::CutTree;
use super::geometry::{Lines, Poly, Registry, Root, Wall};
use crate::outofcore::error::SeamError;
use crate::outofcore::plane::{NEAR_PLANE, SplitPlane};

/// A node of the flattened tree.
pub(super) struct Node {
    pub(super) lo: Vec3,
    pub(super) hi: Vec3,
    /// Plane, wall index, below child, above child.
    pub(super) split: Option<(SplitPlane, usize, usize, usize)>,
}

/// What the clipping produced.
pub(super) struct Cut {
    pub(super) nodes: Vec<Node>,
    pub(super) walls: Vec<Wall>,
    /// Scene pieces per node (only leaves' are used).
    pub(super) pieces: Vec<Vec<Poly>>,
    pub(super) registry: Registry,
    pub(super) lines: Lines,
    pub(super) triangles_cut: HashSet<u32>,
    pub(super) triangles_in_plane: HashSet<u32>,
}

pub(super) fn flatten(
    tree: &CutTree,
    lo: Vec3,
    hi: Vec3,
    nodes: &mut Vec<Node>,
    walls: &mut Vec<Wall>,
) -> usize {
    let id = nodes.len();
    nodes.push(Node {
        lo,
        hi,
        split: None,
    });
    if let CutTree::Split {
        plane,
        below,
        above,
    } = tree
    {
        let (mut wlo, mut whi) = (lo, hi);
        wlo[plane.axis] = plane.value;
        whi[plane.axis] = plane.value;
        let w = walls.len();
        walls.push(Wall {
            plane: *plane,
            lo: wlo,
            hi: whi,
            seam: true,
            segments: Vec::new(),
            in_plane: Vec::new(),
            points: Vec::new(),
            axis_segments: Vec::new(),
            triangles: Vec::new(),
        });
        let b = flatten(below, lo, whi, nodes, walls);
        let a = flatten(above, wlo, hi, nodes, walls);
        nodes[id].split = Some((*plane, w, b, a));
    }
    id
}

/// Clips `poly` by `plane` (it crosses it strictly): the parts below and
/// above, and the cut segment's two points.
pub(super) fn clip(
    poly: &Poly,
    plane: SplitPlane,
    reg: &mut Registry,
    tolerance: f64,
) -> Result<(Poly, Poly, [Vec3; 2]), SeamError> {
    let c = plane.axis;
    let n = poly.v.len();
    // (point, edge index, is a crossing)
    let mut lo: Vec<(Vec3, usize, bool)> = Vec::new();
    let mut hi: Vec<(Vec3, usize, bool)> = Vec::new();
    let mut on = Vec::new();
    for i in 0..n {
        let (p, q) = (poly.v[i], poly.v[(i + 1) % n]);
        let (sp, sq) = (p[c].total_cmp(&plane.value), q[c].total_cmp(&plane.value));
        if sp.is_le() {
            lo.push((p, i, false));
        }
        if sp.is_ge() {
            hi.push((p, i, false));
        }
        if sp.is_eq() {
            on.push(p);
        }
        if (sp.is_lt() && sq.is_gt()) || (sp.is_gt() && sq.is_lt()) {
            let x = reg.cross(poly.roots[i], plane, poly.source)?;
            let d = (x - p).as_dvec3().length().min((x - q).as_dvec3().length());
            if d < tolerance {
                return Err(SeamError::DegenerateCut {
                    plane,
                    point: x,
                    triangle: poly.source,
                    what: "a crossing point falls within TetGen's tolerance of a vertex",
                });
            }
            lo.push((x, i, true));
            hi.push((x, i, true));
            on.push(x);
        }
    }
    if on.len() != 2 {
        return Err(SeamError::DegenerateCut {
            plane,
            point: poly.v[0],
            triangle: poly.source,
            what: "the piece meets the plane in more than two points (rounding)",
        });
    }
    let cut = Root::new(on[0], on[1]);
    let build = |side: &[(Vec3, usize, bool)]| {
        let m = side.len();
        let mut roots = Vec::with_capacity(m);
        for k in 0..m {
            let (_, i, px) = side[k];
            let (_, j, qx) = side[(k + 1) % m];
            // Along original edge i: orig(i)→orig(i+1), orig(i)→cross(i),
            // cross(i)→orig(i+1); otherwise the cut segment.
            let next = j == (i + 1) % n;
            let along = match (px, qx) {
                (false, false) | (true, false) => next,
                (false, true) => j == i,
                (true, true) => false,
            };
            roots.push(if along { poly.roots[i] } else { cut });
        }
        Poly {
            v: side.iter().map(|s| s.0).collect(),
            roots,
            source: poly.source,
        }
    };
    Ok((build(&lo), build(&hi), [on[0], on[1]]))
}

pub(super) fn run_clipping(
    vertices: &[Vec3],
    triangles: &[[u32; 3]],
    tree: &CutTree,
    lo: Vec3,
    hi: Vec3,
) -> Result<Cut, SeamError> {
    let mut nodes = Vec::new();
    let mut walls = Vec::new();
    flatten(tree, lo, hi, &mut nodes, &mut walls);
    let tolerance = NEAR_PLANE * (hi - lo).max_element() as f64;
    for (i, node) in nodes.iter().enumerate() {
        if let Some((plane, ..)) = node.split {
            let a = plane.axis;
            if a > 2 || !(plane.value > node.lo[a] && plane.value < node.hi[a]) {
                return Err(SeamError::PlaneOutsideBox {
                    plane,
                    min: node.lo,
                    max: node.hi,
                });
            }
            let _ = i;
        }
    }
    let mut reg = Registry::default();
    let mut lines = Lines::default();
    let mut pieces: Vec<Vec<Poly>> = (0..nodes.len()).map(|_| Vec::new()).collect();
    let mut triangles_cut = HashSet::new();
    let mut triangles_in_plane = HashSet::new();
    // (node, polygons, ghosts)
    let root_polys: Vec<Poly> = triangles
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let v = t.map(|k| vertices[k as usize]);
            Poly {
                v: v.to_vec(),
                roots: (0..3).map(|k| Root::new(v[k], v[(k + 1) % 3])).collect(),
                source: i as u32,
            }
        })
        .collect();
    let mut stack = vec![(0usize, root_polys, Vec::<Poly>::new())];
    while let Some((id, polys, ghosts)) = stack.pop() {
        for p in polys.iter().chain(&ghosts) {
            for &x in &p.v {
                lines.insert(x);
            }
        }
        let Some((plane, w, below, above)) = nodes[id].split else {
            pieces[id] = polys;
            continue;
        };
        let c = plane.axis;
        let (mut lo_p, mut hi_p, mut lo_g, mut hi_g) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let all = polys
            .into_iter()
            .map(|p| (p, false))
            .chain(ghosts.into_iter().map(|p| (p, true)));
        for (poly, ghost) in all {
            if let Some(&x) = poly.v.iter().find(|x| {
                let d = (x[c] as f64 - plane.value as f64).abs();
                d > 0.0 && d < tolerance
            }) {
                return Err(SeamError::PlaneNearPoint {
                    plane,
                    point: x,
                    distance: (x[c] as f64 - plane.value as f64).abs(),
                });
            }
            let below_any = poly.v.iter().any(|x| x[c] < plane.value);
            let above_any = poly.v.iter().any(|x| x[c] > plane.value);
            match (below_any, above_any) {
                (false, false) => {
                    if !ghost {
                        triangles_in_plane.insert(poly.source);
                        walls[w].in_plane.push(poly.clone());
                    }
                    lo_g.push(poly.clone());
                    hi_g.push(poly);
                }
                (true, true) => {
                    let (l, h, seg) = clip(&poly, plane, &mut reg, tolerance)?;
                    if !ghost {
                        triangles_cut.insert(poly.source);
                        walls[w].segments.push((
                            Root::new(seg[0], seg[1]),
                            seg[0],
                            seg[1],
                            poly.source,
                        ));
                        lo_p.push(l);
                        hi_p.push(h);
                    } else {
                        lo_g.push(l);
                        hi_g.push(h);
                    }
                }
                (below_side, _) => {
                    if !ghost {
                        let n = poly.v.len();
                        for i in 0..n {
                            let (p, q) = (poly.v[i], poly.v[(i + 1) % n]);
                            if p[c] == plane.value && q[c] == plane.value {
                                walls[w].segments.push((poly.roots[i], p, q, poly.source));
                            } else if p[c] == plane.value {
                                walls[w].points.push(p);
                            }
                        }
                    }
                    match (below_side, ghost) {
                        (true, false) => lo_p.push(poly),
                        (false, false) => hi_p.push(poly),
                        (true, true) => lo_g.push(poly),
                        (false, true) => hi_g.push(poly),
                    }
                }
            }
        }
        stack.push((below, lo_p, lo_g));
        stack.push((above, hi_p, hi_g));
    }
    for (_, list) in reg.points.iter() {
        for &(_, x) in list {
            lines.insert(x);
        }
    }
    Ok(Cut {
        nodes,
        walls,
        pieces,
        registry: reg,
        lines,
        triangles_cut,
        triangles_in_plane,
    })
}
