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
    pub(crate) fn nudge(&mut self, plane: SplitPlane, step: f32, lo: Vec3, hi: Vec3) -> bool {
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
        if *p == plane {
            let v = p.value + step;
            if v > lo[a] && v < hi[a] && v != p.value {
                p.value = v;
                moved = true;
            }
        }
        let (mut mid_hi, mut mid_lo) = (hi, lo);
        mid_hi[a] = p.value;
        mid_lo[a] = p.value;
        moved |= below.nudge(plane, step, lo, mid_hi);
        moved |= above.nudge(plane, step, mid_lo, hi);
        moved
    }
}
