//! Structured grids of `nx × ny × nz` boxes split into tets, the way
//! structured volume data is turned into a tetrahedral volume:
//!
//! * [`Split::Six`]: the Kuhn (Freudenthal) split — six tets per box, each a
//!   monotone path from corner 000 to 111; the same split (and the same point
//!   numbering) as [`tet_core::synthetic::kuhn_grid`] without jitter. Every
//!   box is split the same way, so faces match across boxes.
//! * [`Split::Five`]: one central tet and four corner tets per box; boxes
//!   alternate between the split and its mirror image by the parity of
//!   `i + j + k`, so that the face diagonals of neighbouring boxes match.
//!
//! Tets are oriented exactly on the integer lattice (an affine map with
//! positive scale per axis keeps the sign), neighbours are linked by
//! [`TetMesh::assemble`] and the result is checked by
//! [`TetMesh::validate`].

use glam::Vec3;
use tet_core::{MAX_TETS, TetMesh};

use super::VolumeError;

/// How each box of the grid is split into tets.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Split {
    /// Six tets per box (Kuhn split).
    Six,
    /// Five tets per box, alternating by parity.
    Five,
}

impl Split {
    /// Tets per box.
    pub fn tets_per_box(self) -> u64 {
        match self {
            Split::Six => 6,
            Split::Five => 5,
        }
    }
}

/// A box `[lo, hi]` divided into `cells` boxes per axis, each split into tets.
#[derive(Clone, Debug, PartialEq)]
pub struct GridVolume {
    /// Boxes along x, y, z (each ≥ 1).
    pub cells: [u32; 3],
    /// Lower corner of the domain.
    pub lo: Vec3,
    /// Upper corner of the domain (each coordinate above `lo`'s).
    pub hi: Vec3,
    /// The split of each box.
    pub split: Split,
}

impl GridVolume {
    /// A grid of `cells` boxes over `[lo, hi]`, each split by `split`.
    pub fn new(cells: [u32; 3], lo: Vec3, hi: Vec3, split: Split) -> GridVolume {
        GridVolume {
            cells,
            lo,
            hi,
            split,
        }
    }

    /// Number of tets the grid has.
    pub fn tet_count(&self) -> u64 {
        self.cells.iter().map(|&c| u64::from(c)).product::<u64>() * self.split.tets_per_box()
    }

    /// Number of points (grid vertices).
    pub fn point_count(&self) -> u64 {
        self.cells.iter().map(|&c| u64::from(c) + 1).product()
    }
}

/// Corner `c` (bit 0: +x, bit 1: +y, bit 2: +z) of a box.
const fn corner(c: usize) -> [u32; 3] {
    [(c & 1) as u32, ((c >> 1) & 1) as u32, ((c >> 2) & 1) as u32]
}

/// The five tets of a box with even parity (central tet on the corners of
/// odd bit sum); the odd-parity split is this one mirrored in x.
const FIVE_EVEN: [[usize; 4]; 5] = [
    [1, 2, 4, 7],
    [0, 1, 2, 4],
    [3, 1, 2, 7],
    [5, 1, 4, 7],
    [6, 2, 4, 7],
];

/// The six Kuhn tets: axis orders of the path from corner 000 to 111.
const KUHN: [[usize; 3]; 6] = [
    [0, 1, 2],
    [0, 2, 1],
    [1, 0, 2],
    [1, 2, 0],
    [2, 0, 1],
    [2, 1, 0],
];

/// Exact orientation of four lattice points (integer determinant).
fn lattice_orient(p: [[u32; 3]; 4]) -> i64 {
    let d = |a: [u32; 3], b: [u32; 3]| [0, 1, 2].map(|k| i64::from(a[k]) - i64::from(b[k]));
    let (a, b, c) = (d(p[1], p[0]), d(p[2], p[0]), d(p[3], p[0]));
    a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
        + a[2] * (b[0] * c[1] - b[1] * c[0])
}

/// Builds the grid's tet mesh (no field, no constrained faces).
pub fn grid_mesh(spec: &GridVolume) -> Result<TetMesh, VolumeError> {
    let bad = |what: &'static str, detail: String| VolumeError::BadParameter { what, detail };
    let [nx, ny, nz] = spec.cells;
    if nx == 0 || ny == 0 || nz == 0 {
        return Err(bad(
            "cells",
            format!("{:?}: every axis needs a box", spec.cells),
        ));
    }
    if !(spec.lo.is_finite() && spec.hi.is_finite() && spec.lo.cmplt(spec.hi).all()) {
        return Err(bad(
            "domain",
            format!("lo {} must lie below hi {} on every axis", spec.lo, spec.hi),
        ));
    }
    if spec.tet_count() >= u64::from(MAX_TETS) || spec.point_count() > u64::from(u32::MAX) {
        return Err(bad(
            "cells",
            format!(
                "{:?} gives {} tets and {} points, beyond the mesh limits",
                spec.cells,
                spec.tet_count(),
                spec.point_count()
            ),
        ));
    }
    let dims = [nx + 1, ny + 1, nz + 1];
    let index = |c: [u32; 3]| c[0] + dims[0] * (c[1] + dims[1] * c[2]);
    let size = spec.hi - spec.lo;
    let mut points = Vec::with_capacity(spec.point_count() as usize);
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let t = Vec3::new(
                    i as f32 / nx as f32,
                    j as f32 / ny as f32,
                    k as f32 / nz as f32,
                );
                // Exact end points: hi itself at the last lattice index.
                let mut p = spec.lo + size * t;
                for (axis, (&c, &n)) in [i, j, k].iter().zip(&spec.cells).enumerate() {
                    if c == n {
                        p[axis] = spec.hi[axis];
                    }
                }
                points.push(p);
            }
        }
    }
    let mut tets = Vec::with_capacity(spec.tet_count() as usize);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let base = [i, j, k];
                let at = |c: [u32; 3]| [base[0] + c[0], base[1] + c[1], base[2] + c[2]];
                let mut push = |lattice: [[u32; 3]; 4]| {
                    let mut tet = lattice.map(index);
                    if lattice_orient(lattice) < 0 {
                        tet.swap(2, 3);
                    }
                    tets.push(tet);
                };
                match spec.split {
                    Split::Six => {
                        for perm in KUHN {
                            let mut c = base;
                            let mut lattice = [c; 4];
                            for (step, &axis) in perm.iter().enumerate() {
                                c[axis] += 1;
                                lattice[step + 1] = c;
                            }
                            push(lattice);
                        }
                    }
                    Split::Five => {
                        let odd = (i + j + k) % 2 == 1;
                        for tet in FIVE_EVEN {
                            push(tet.map(|c| {
                                let mut l = corner(c);
                                if odd {
                                    l[0] = 1 - l[0];
                                }
                                at(l)
                            }));
                        }
                    }
                }
            }
        }
    }
    let mesh = TetMesh::assemble(points, tets, &[], 0)?;
    mesh.validate()?;
    Ok(mesh)
}
