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
    /// Per scene triangle: the leaf holding it whole, or [`CLIPPED`].
    pub(super) leaf_of: Vec<u32>,
}

/// [`Cut::leaf_of`] of a triangle that is clipped (see [`interior_leaf`]).
pub(super) const CLIPPED: u32 = u32::MAX;

/// The leaf whose box holds triangle `t` strictly inside, clear of every
/// plane on its way down by at least `tolerance`: such a triangle is one
/// piece of that leaf, untouched by the clipping, so it need not go
/// through it. `None` when a plane cuts it, touches it or passes within
/// `tolerance` of a vertex (the clipping then sees it, and reports what
/// it must).
pub(super) fn interior_leaf(nodes: &[Node], t: [Vec3; 3], tolerance: f64) -> Option<usize> {
    let mut id = 0;
    loop {
        let Some((plane, _, below, above)) = nodes[id].split else {
            return Some(id);
        };
        let c = plane.axis;
        let d = |x: &Vec3| x[c] as f64 - plane.value as f64;
        if t.iter().all(|x| x[c] < plane.value && -d(x) >= tolerance) {
            id = below;
        } else if t.iter().all(|x| x[c] > plane.value && d(x) >= tolerance) {
            id = above;
        } else {
            return None;
        }
    }
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
    let mut planes: [Vec<f32>; 3] = std::array::from_fn(|a| vec![lo[a], hi[a]]);
    for node in &nodes {
        if let Some((plane, ..)) = node.split {
            planes[plane.axis].push(plane.value);
        }
    }
    let mut lines = Lines::with_scene(
        vertices,
        triangles,
        [&planes[0][..], &planes[1][..], &planes[2][..]],
    );
    drop(planes);
    let mut pieces: Vec<Vec<Poly>> = (0..nodes.len()).map(|_| Vec::new()).collect();
    let mut triangles_cut = HashSet::new();
    let mut triangles_in_plane = HashSet::new();
    // Triangles inside one leaf skip the clipping; the rest are clipped in
    // scene order, as before, so the first error is the same one.
    let mut leaf_of = vec![CLIPPED; triangles.len()];
    let mut root_polys: Vec<Poly> = Vec::new();
    for (i, t) in triangles.iter().enumerate() {
        let v = t.map(|k| vertices[k as usize]);
        match interior_leaf(&nodes, v, tolerance) {
            Some(leaf) => leaf_of[i] = leaf as u32,
            None => root_polys.push(Poly::triangle(v, i as u32)),
        }
    }
    // (node, polygons, ghosts). Every point of a polygon is a scene vertex
    // (in `lines` already) or a registered crossing (added below).
    let mut stack = vec![(0usize, root_polys, Vec::<Poly>::new())];
    // Planes that met a point within tolerance or a degenerate cut: the
    // pass goes on past them (not below them), so that one retry of the
    // planner moves every such plane found, not one per pass.
    let mut to_move: Vec<SeamError> = Vec::new();
    while let Some((id, polys, ghosts)) = stack.pop() {
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
        let mut broken = false;
        for (poly, ghost) in all {
            if let Some(&x) = poly.v.iter().find(|x| {
                let d = (x[c] as f64 - plane.value as f64).abs();
                d > 0.0 && d < tolerance
            }) {
                to_move.push(SeamError::PlaneNearPoint {
                    plane,
                    point: x,
                    distance: (x[c] as f64 - plane.value as f64).abs(),
                });
                broken = true;
                continue;
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
                    let (l, h, seg) = match clip(&poly, plane, &mut reg, tolerance) {
                        Ok(cut) => cut,
                        Err(e @ SeamError::DegenerateCut { .. }) => {
                            to_move.push(e);
                            broken = true;
                            continue;
                        }
                        Err(e) => return Err(e),
                    };
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
        if broken {
            // The halves are not whole: nothing below is checked this pass.
            continue;
        }
        stack.push((below, lo_p, lo_g));
        stack.push((above, hi_p, hi_g));
    }
    if let Some(e) = SeamError::planes_to_move(to_move) {
        return Err(e);
    }
    reg.freeze();
    lines.add_crossings(reg.points());
    Ok(Cut {
        nodes,
        walls,
        pieces,
        registry: reg,
        lines,
        triangles_cut,
        triangles_in_plane,
        leaf_of,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A tree over [0, 8]³: x = 4, then y = 2 below and z = 5 above, then
    /// x = 6 in the upper z half.
    fn tree() -> CutTree {
        let split = |axis, value, below, above| CutTree::Split {
            plane: SplitPlane { axis, value },
            below: Box::new(below),
            above: Box::new(above),
        };
        split(
            0,
            4.0,
            split(1, 2.0, CutTree::Leaf, CutTree::Leaf),
            split(
                2,
                5.0,
                CutTree::Leaf,
                split(0, 6.0, CutTree::Leaf, CutTree::Leaf),
            ),
        )
    }

    /// Every plane of one pass that meets a point within tolerance is
    /// reported, not only the first (here two planes in two subtrees, each
    /// with a vertex two or one f32 steps off it): the planner moves them
    /// all in one retry.
    #[test]
    fn a_pass_reports_every_plane_near_a_point() {
        let up = |v: f32, steps: u32| f32::from_bits(v.to_bits() + steps);
        let vertices = [
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(2.0, up(2.0, 2), 1.0),
            Vec3::new(1.5, 3.0, 3.0),
            Vec3::new(5.0, 1.0, 4.0),
            Vec3::new(7.0, 1.0, up(5.0, 1)),
            Vec3::new(5.5, 3.0, 6.0),
        ];
        let triangles = [[0, 1, 2], [3, 4, 5]];
        let e = match run_clipping(&vertices, &triangles, &tree(), Vec3::ZERO, Vec3::splat(8.0)) {
            Err(e) => e,
            Ok(_) => panic!("both planes pass within tolerance of a vertex"),
        };
        assert!(
            matches!(&e, SeamError::PlanesNearPoints(all) if all.len() == 2),
            "{e}"
        );
        let mut planes: Vec<(usize, f32)> = e
            .planes_near_points()
            .into_iter()
            .map(|(p, _)| (p.axis, p.value))
            .collect();
        planes.sort_by_key(|p| p.0);
        assert_eq!(planes, vec![(1, 2.0), (2, 5.0)]);
        // One such vertex alone: the single error, as before.
        let one = run_clipping(
            &vertices,
            &triangles[..1],
            &tree(),
            Vec3::ZERO,
            Vec3::splat(8.0),
        );
        assert!(matches!(one, Err(SeamError::PlaneNearPoint { .. })));
    }

    /// The leaf whose box holds `t` at least `tolerance` away from every
    /// face that is a plane (the enclosing box's faces are not), by
    /// looking at every leaf's box.
    fn by_boxes(nodes: &[Node], t: [Vec3; 3], tolerance: f64, lo: Vec3, hi: Vec3) -> Option<usize> {
        let clear = |x: f32, face: f32, outer: f32, above: bool| {
            if face == outer {
                return if above { x >= face } else { x <= face };
            }
            let d = x as f64 - face as f64;
            if above {
                d >= tolerance
            } else {
                -d >= tolerance
            }
        };
        let mut found = None;
        for (id, n) in nodes.iter().enumerate() {
            if n.split.is_some() {
                continue;
            }
            let inside = t.iter().all(|x| {
                (0..3).all(|a| {
                    clear(x[a], n.lo[a], lo[a], true) && clear(x[a], n.hi[a], hi[a], false)
                })
            });
            if inside {
                assert!(found.is_none(), "{t:?} clear inside two leaves");
                found = Some(id);
            }
        }
        found
    }

    /// A coordinate in the box: anywhere, on a plane, on the box, or
    /// within 2e-3 of a plane.
    fn coordinate() -> impl Strategy<Value = f32> {
        let planes = || prop::sample::select(vec![2.0f32, 4.0, 5.0, 6.0]);
        prop_oneof![
            2 => 0.0f32..8.0,
            1 => planes(),
            1 => prop::sample::select(vec![0.0f32, 8.0]),
            4 => (planes(), -2e-3f32..2e-3).prop_map(|(c, d)| c + d),
        ]
    }

    fn point() -> impl Strategy<Value = Vec3> {
        (coordinate(), coordinate(), coordinate()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
    }

    proptest! {
        /// The descent finds the leaf a look at every leaf's box finds,
        /// and none where a plane cuts, touches or passes near the
        /// triangle.
        #[test]
        fn interior_leaf_is_the_leaf_holding_the_triangle_clear_of_planes(
            t in (point(), point(), point()),
            tolerance in prop::sample::select(vec![0.0f64, 1e-3]),
        ) {
            let (lo, hi) = (Vec3::ZERO, Vec3::splat(8.0));
            let (mut nodes, mut walls) = (Vec::new(), Vec::new());
            flatten(&tree(), lo, hi, &mut nodes, &mut walls);
            let t = [t.0, t.1, t.2];
            let tolerance = tolerance.max(f64::MIN_POSITIVE);
            prop_assert_eq!(
                interior_leaf(&nodes, t, tolerance),
                by_boxes(&nodes, t, tolerance, lo, hi)
            );
        }
    }
}
