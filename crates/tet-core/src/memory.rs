//! Exact memory accounting of every layout, split into hot and cold data, so
//! that Table 4 of Aman et al. (2022) ("accelerator size") can be reproduced.
//!
//! * **hot**: what the traversal loop reads — the tet records and the point
//!   array (Tet80 has its positions inline and no point array);
//! * **cold**: the constrained-face table (read once per hit or secondary-ray
//!   restart), attributes (only those present), the anchor table of Tet20 /
//!   Tet16 (one [`Anchor`] per connected component), and Tet80's
//!   reconstruction-only data (point array and vertex ids, kept so it can be
//!   decoded back to a [`TetMesh`]; the Plücker walk never reads them).
//!
//! Table 4 of Aman et al. (2022) counts, for Tet32/20/16, the tets plus a per-scene
//! remainder equal across the three (points and constrained faces), and for
//! Tet80 the tets alone; compare `hot()` (+ `constrained` for the xor
//! layouts) with it.
//!
//! Sizes come from `size_of` of the record types (asserted at compile time to
//! be 32/32/20/16/80 bytes), [`crate::ConstrainedFace`] (32 bytes), `Vec3`
//! (12 bytes) and [`crate::Attributes::bytes`].

use std::fmt;

use glam::Vec3;

use crate::layout::tet80::NAME as TET80_NAME;
use crate::layout::{
    Anchor, Baseline32, LayoutMesh, LayoutRecord, Tet16, Tet20, Tet32, Tet80, Tet80Mesh,
    component_roots,
};
use crate::mesh::{ConstrainedFace, TetMesh};

impl<R: LayoutRecord> LayoutMesh<R> {
    /// Exact memory of this container (see [`crate::memory`]).
    pub fn memory(&self) -> LayoutMemory {
        LayoutMemory {
            name: R::NAME,
            tets: self.tets.len() * size_of::<R>(),
            points: self.points.len() * size_of::<Vec3>(),
            constrained: self.constrained.len() * size_of::<ConstrainedFace>(),
            attributes: self.attributes.bytes(),
            anchors: self.anchors.len() * size_of::<Anchor>(),
            reconstruction: 0,
        }
    }
}

impl Tet80Mesh {
    /// Exact memory of this container (see [`crate::memory`]): Tet80 keeps
    /// its positions inline, so its point array and vertex ids are
    /// reconstruction-only data.
    pub fn memory(&self) -> LayoutMemory {
        LayoutMemory {
            name: TET80_NAME,
            tets: self.tets.len() * size_of::<Tet80>(),
            points: 0,
            constrained: self.constrained.len() * size_of::<ConstrainedFace>(),
            attributes: self.attributes.bytes(),
            anchors: 0,
            reconstruction: self.points.len() * size_of::<Vec3>()
                + self.vertex_ids.len() * size_of::<[u32; 4]>(),
        }
    }
}

/// Layout names, in report order.
pub const LAYOUT_NAMES: [&str; 5] = ["baseline32", "tet32", "tet20", "tet16", "tet80"];

/// Exact bytes of one layout of one mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LayoutMemory {
    /// Layout name (one of [`LAYOUT_NAMES`]).
    pub name: &'static str,
    /// Tet records (hot).
    pub tets: usize,
    /// Point array (hot; 0 for Tet80).
    pub points: usize,
    /// Constrained-face table (cold).
    pub constrained: usize,
    /// Attributes present (cold).
    pub attributes: usize,
    /// Anchor table (cold; Tet20 and Tet16 only).
    pub anchors: usize,
    /// Data kept only to decode back to a [`TetMesh`] (cold; Tet80 only).
    pub reconstruction: usize,
}

impl LayoutMemory {
    /// Bytes the traversal loop reads: tets + points.
    pub fn hot(&self) -> usize {
        self.tets + self.points
    }

    /// Bytes outside the traversal loop.
    pub fn cold(&self) -> usize {
        self.constrained + self.attributes + self.anchors + self.reconstruction
    }

    /// Everything.
    pub fn total(&self) -> usize {
        self.hot() + self.cold()
    }
}

/// Memory of every layout for one mesh, computed from its counts (no layout
/// is built).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MemoryReport {
    /// Number of tets.
    pub tet_count: usize,
    /// Number of points.
    pub point_count: usize,
    /// Number of constrained faces.
    pub constrained_count: usize,
    /// Number of connected components (= anchors of Tet20/Tet16).
    pub component_count: usize,
    /// One entry per layout, in [`LAYOUT_NAMES`] order.
    pub layouts: Vec<LayoutMemory>,
}

impl MemoryReport {
    /// Computes the report of `mesh`. Equals `XMesh::from_mesh(mesh)?.memory()`
    /// for every layout that accepts the mesh.
    pub fn for_mesh(mesh: &TetMesh) -> MemoryReport {
        let t = mesh.tets.len();
        let p = mesh.points.len();
        let c = mesh.constrained.len();
        let components = component_roots(mesh).len();
        let points = p * size_of::<Vec3>();
        let constrained = c * size_of::<ConstrainedFace>();
        let attributes = mesh.attributes.bytes();
        let xor_like = |name, record: usize, anchors: usize| LayoutMemory {
            name,
            tets: t * record,
            points,
            constrained,
            attributes,
            anchors,
            reconstruction: 0,
        };
        let anchors = components * size_of::<Anchor>();
        let layouts = vec![
            xor_like(LAYOUT_NAMES[0], size_of::<Baseline32>(), 0),
            xor_like(LAYOUT_NAMES[1], size_of::<Tet32>(), 0),
            xor_like(LAYOUT_NAMES[2], size_of::<Tet20>(), anchors),
            xor_like(LAYOUT_NAMES[3], size_of::<Tet16>(), anchors),
            LayoutMemory {
                name: LAYOUT_NAMES[4],
                tets: t * size_of::<Tet80>(),
                points: 0,
                constrained,
                attributes,
                anchors: 0,
                reconstruction: points + t * size_of::<[u32; 4]>(),
            },
        ];
        MemoryReport {
            tet_count: t,
            point_count: p,
            constrained_count: c,
            component_count: components,
            layouts,
        }
    }

    /// The entry of layout `name`, if it is one of [`LAYOUT_NAMES`].
    pub fn get(&self, name: &str) -> Option<&LayoutMemory> {
        self.layouts.iter().find(|l| l.name == name)
    }
}

impl fmt::Display for MemoryReport {
    /// A plain table in MB (10⁶ bytes, as in Aman et al. (2022) Table 4) and exact bytes.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{} tets, {} points, {} constrained faces, {} components",
            self.tet_count, self.point_count, self.constrained_count, self.component_count
        )?;
        writeln!(
            f,
            "{:<11} {:>10} {:>10} {:>10} {:>14}",
            "layout", "hot MB", "cold MB", "total MB", "total bytes"
        )?;
        for l in &self.layouts {
            writeln!(
                f,
                "{:<11} {:>10.3} {:>10.3} {:>10.3} {:>14}",
                l.name,
                l.hot() as f64 / 1e6,
                l.cold() as f64 / 1e6,
                l.total() as f64 / 1e6,
                l.total()
            )?;
        }
        Ok(())
    }
}
