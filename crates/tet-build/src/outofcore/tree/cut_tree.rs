//! [`CutTree`]: the planes of a recursive split.

use glam::Vec3;

use crate::outofcore::plane::SplitPlane;
use crate::outofcore::split::SplitTree;

/// The planes of a recursive split, without the planner's estimates.
#[derive(Clone, Debug, PartialEq)]
pub enum CutTree {
    /// One part.
    Leaf,
    /// A part cut by `plane` into the half `x[axis] ≤ value` (`below`) and
    /// the half `x[axis] ≥ value` (`above`).
    Split {
        /// The cut plane (strictly inside the part's box).
        plane: SplitPlane,
        /// The lower half.
        below: Box<CutTree>,
        /// The upper half.
        above: Box<CutTree>,
    },
}

impl CutTree {
    /// A split node.
    pub fn split(axis: usize, value: f32, below: CutTree, above: CutTree) -> CutTree {
        CutTree::Split {
            plane: SplitPlane { axis, value },
            below: Box::new(below),
            above: Box::new(above),
        }
    }

    /// The planes of a planner's tree.
    pub fn from_split_tree(tree: &SplitTree) -> CutTree {
        match tree {
            SplitTree::Leaf { .. } => CutTree::Leaf,
            SplitTree::Split {
                plane,
                below,
                above,
                ..
            } => CutTree::Split {
                plane: *plane,
                below: Box::new(CutTree::from_split_tree(below)),
                above: Box::new(CutTree::from_split_tree(above)),
            },
        }
    }

    /// A grid: split by the planes `x = xs[i]` (a balanced tree), then each
    /// slab by `y = ys[j]`, then each by `z = zs[k]` (each list strictly
    /// increasing). `grid(&[a], &[b], &[])` is a 2×2 split with
    /// perpendicular planes.
    pub fn grid(xs: &[f32], ys: &[f32], zs: &[f32]) -> CutTree {
        fn along(axis: usize, values: &[f32], inner: &dyn Fn() -> CutTree) -> CutTree {
            if values.is_empty() {
                return inner();
            }
            let m = values.len() / 2;
            CutTree::split(
                axis,
                values[m],
                along(axis, &values[..m], inner),
                along(axis, &values[m + 1..], inner),
            )
        }
        along(0, xs, &|| along(1, ys, &|| along(2, zs, &|| CutTree::Leaf)))
    }

    /// Number of leaves (TetGen runs).
    pub fn parts(&self) -> usize {
        match self {
            CutTree::Leaf => 1,
            CutTree::Split { below, above, .. } => below.parts() + above.parts(),
        }
    }
}

impl CutTree {
    /// Moves every plane equal to `plane` by `step` along its axis, if the
    /// moved plane stays strictly inside its part's box.
    #[cfg(test)]
    pub(crate) fn nudge(&mut self, plane: SplitPlane, step: f32, lo: Vec3, hi: Vec3) -> bool {
        self.move_plane(plane, lo, hi, &mut |p, _, _| Some(p.value + step))
    }

    /// Moves every plane equal to `plane` to the value `to` gives it (from
    /// the plane and its node's box, `lo..hi` being the whole's box), if
    /// the moved plane stays strictly inside its node's box and the planes
    /// below it stay inside theirs. Whether any plane moved.
    pub(crate) fn move_plane(
        &mut self,
        plane: SplitPlane,
        lo: Vec3,
        hi: Vec3,
        to: &mut dyn FnMut(SplitPlane, Vec3, Vec3) -> Option<f32>,
    ) -> bool {
        let CutTree::Split {
            plane: p,
            below,
            above,
        } = self
        else {
            return false;
        };
        let a = p.axis;
        let mut moved = false;
        if *p == plane
            && let Some(v) = to(*p, lo, hi)
        {
            // The planes below and above must stay on their sides of it.
            let (mut below_hi, mut above_lo) = (hi, lo);
            below_hi[a] = v;
            above_lo[a] = v;
            if v > lo[a]
                && v < hi[a]
                && v != p.value
                && below.inside(lo, below_hi)
                && above.inside(above_lo, hi)
            {
                p.value = v;
                moved = true;
            }
        }
        let (mut mid_hi, mut mid_lo) = (hi, lo);
        mid_hi[a] = p.value;
        mid_lo[a] = p.value;
        moved |= below.move_plane(plane, lo, mid_hi, to);
        moved |= above.move_plane(plane, mid_lo, hi, to);
        moved
    }

    /// Whether every plane of the tree lies strictly inside its part's
    /// box, the box of the whole being `lo..hi`.
    fn inside(&self, lo: Vec3, hi: Vec3) -> bool {
        match self {
            CutTree::Leaf => true,
            CutTree::Split {
                plane,
                below,
                above,
            } => {
                let a = plane.axis;
                let (mut mid_hi, mut mid_lo) = (hi, lo);
                mid_hi[a] = plane.value;
                mid_lo[a] = plane.value;
                plane.value > lo[a]
                    && plane.value < hi[a]
                    && below.inside(lo, mid_hi)
                    && above.inside(mid_lo, hi)
            }
        }
    }

    /// The planes that bound leaf `part` (leaves counted depth first,
    /// below before above): on each side of the leaf's box the innermost
    /// plane on the path to it, i.e. the part's walls between it and its
    /// neighbours. `None` when there is no such leaf.
    pub(crate) fn leaf_walls(&self, part: usize) -> Option<Vec<SplitPlane>> {
        // [axis][0: the lower side, 1: the upper side].
        let mut sides: [[Option<SplitPlane>; 2]; 3] = [[None; 2]; 3];
        let (mut node, mut index) = (self, part);
        loop {
            match node {
                CutTree::Leaf => {
                    let walls = sides.iter().flatten().flatten().copied().collect();
                    return (index == 0).then_some(walls);
                }
                CutTree::Split {
                    plane,
                    below,
                    above,
                } => {
                    let n = below.parts();
                    if index < n {
                        sides[plane.axis][1] = Some(*plane);
                        node = below;
                    } else {
                        sides[plane.axis][0] = Some(*plane);
                        index -= n;
                        node = above;
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane(axis: usize, value: f32) -> SplitPlane {
        SplitPlane { axis, value }
    }

    /// Leaves of a 2×2 grid and of a deeper tree, checked against the
    /// boxes drawn by hand.
    #[test]
    fn leaf_walls_are_the_innermost_planes_around_each_leaf() {
        // x = 1, then y = 2 in each half: leaves (x<1,y<2), (x<1,y>2),
        // (x>1,y<2), (x>1,y>2).
        let grid = CutTree::grid(&[1.0], &[2.0], &[]);
        assert_eq!(grid.leaf_walls(0), Some(vec![plane(0, 1.0), plane(1, 2.0)]));
        assert_eq!(grid.leaf_walls(1), Some(vec![plane(0, 1.0), plane(1, 2.0)]));
        assert_eq!(grid.leaf_walls(3), Some(vec![plane(0, 1.0), plane(1, 2.0)]));
        assert_eq!(grid.leaf_walls(4), None);
        // x = 0, its upper half by x = 5, then that lower half by z = 3:
        // leaf 1 is 0 < x < 5, z < 3: walls x = 0 (below it), x = 5
        // (above it), z = 3; the outer x = 0 is not replaced by anything
        // nearer on its side.
        let tree = CutTree::split(
            0,
            0.0,
            CutTree::Leaf,
            CutTree::split(
                0,
                5.0,
                CutTree::split(2, 3.0, CutTree::Leaf, CutTree::Leaf),
                CutTree::Leaf,
            ),
        );
        assert_eq!(tree.leaf_walls(0), Some(vec![plane(0, 0.0)]));
        assert_eq!(
            tree.leaf_walls(1),
            Some(vec![plane(0, 0.0), plane(0, 5.0), plane(2, 3.0)])
        );
        assert_eq!(tree.leaf_walls(3), Some(vec![plane(0, 5.0)]));
        assert_eq!(CutTree::Leaf.leaf_walls(0), Some(vec![]));
    }

    /// A plane is not moved past a plane of its subtree (that plane would
    /// leave its part's box); one with room is.
    #[test]
    fn nudge_keeps_every_plane_inside_its_box() {
        let (lo, hi) = (Vec3::splat(-10.0), Vec3::splat(10.0));
        let tree = CutTree::split(
            1,
            0.0,
            CutTree::split(1, -0.5, CutTree::Leaf, CutTree::Leaf),
            CutTree::Leaf,
        );
        let mut t = tree.clone();
        assert!(!t.nudge(plane(1, 0.0), -1.0, lo, hi), "would pass y = -0.5");
        assert_eq!(t, tree);
        assert!(t.nudge(plane(1, 0.0), -0.25, lo, hi));
        assert!(t.inside(lo, hi));
        assert!(t.nudge(plane(1, -0.25), 1.0, lo, hi), "room above");
        assert!(t.inside(lo, hi));
    }
}
