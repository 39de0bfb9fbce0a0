//! Isosurface ray tracing of tetrahedral volumes (Wald et al. 2007).
//!
//! A scalar field is given by one value per mesh point (`values[i]` for
//! `mesh.points[i]`) and is linear inside every tet; its isosurface
//! `f(x) = v` for an isovalue `v` is a plane polygon inside each tet whose
//! vertex values straddle `v` (the paper's *isotet* and *isopolygon*, §3).
//! Three ways to find the first crossing of a ray:
//!
//! * [`mod@reference`]: f64 brute force over every tet (the yardstick of tests);
//! * [`walk`]: the iso walk (beyond the paper): the watertight tet walk of
//!   [`crate::walk`] over Tet32/Tet20/Tet16, testing each visited tet's value
//!   range and locating the crossing from the field values where the ray
//!   crosses the tet's faces; tiles skip the rays that meet no region of
//!   tets straddling an isovalue ([`regions`]);
//! * [`ibvh`] / [`ibvh_trace`] / [`packet`]: the paper's implicit min-max BVH
//!   (§5) over 4-D bounds `{x, y, z, v}`, built BIH-style or by SAH, refit
//!   for new time steps (§6), traversed by single rays or by packets with
//!   first-active tracking and interval culling; its leaves test the
//!   marching-tet isopolygons of [`marching`] (§3–4).
//!
//! | paper | code |
//! |---|---|
//! | isovalue(s) `v` (≤ 4 at once, §7) | [`IsoQuery::isovalues`] |
//! | clip / crop box (§7) | [`ClipBox`] |
//! | isotet range test | [`straddles`] |
//! | isopolygon (Fig. 3) | [`marching::IsoPolygon`] |
//! | IBVH node `{x,y,z,v}` bounds | [`ibvh::Node`] |
//! | Schema I / Schema II (§6) | [`ibvh::Ibvh::build_per_step`] / [`ibvh::Ibvh::refit`] |
//! | Table 4 counters | [`IsoStats`] |
//!
//! # Which side of the surface a value is on
//!
//! Every method classifies a value `f` as *above* an isovalue `v` when
//! `f ≥ v` and *below* otherwise. A tet straddles `v` when some vertex is
//! below and some above (`min < v ≤ max`, [`straddles`]); a tet whose values
//! all equal `v` holds no crossing. The crossing of a ray is where its
//! classification changes.
//!
//! # Crack-freeness
//!
//! Neighbouring tets share their face's vertices and values. The walk
//! computes the field value where the ray crosses a face from that face's
//! vertices in a canonical (id-sorted) order, so both tets see the same bits;
//! the IBVH computes each isopolygon vertex on a mesh edge in a canonical
//! order and tests the polygon edges with the walk's exactly antisymmetric
//! 2-D edge test (ray-centred projection and tie rule), so a ray never slips
//! between the polygons of two neighbouring tets.

mod hull;
pub mod ibvh;
pub mod ibvh_trace;
pub mod marching;
pub mod packet;
pub mod reference;
pub mod regions;
pub mod walk;

use glam::{Mat3, Vec3};
use thiserror::Error;

pub use ibvh::{BuildKind, Ibvh};
pub use walk::{IsoOutcome, IsoWalk, TileWalk, WalkLayout};

/// Most isovalues one query may hold (the paper's SIMD width, §7).
pub const MAX_ISOVALUES: usize = 4;

/// Why an iso structure could not be built or a query not be run.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum IsoError {
    /// The values slice does not hold one value per mesh point.
    #[error("{values} values given for {points} mesh points (one value per point needed)")]
    ValueCount {
        /// Values given.
        values: usize,
        /// Mesh points.
        points: usize,
    },
    /// A value is NaN or infinite.
    #[error("value {value} of point {point} is not finite")]
    NonFiniteValue {
        /// The point.
        point: u32,
        /// Its value.
        value: f32,
    },
    /// A tet refers to a point that does not exist.
    #[error("tet {tet} refers to point {point}, beyond the {points} mesh points")]
    BadVertex {
        /// The tet.
        tet: u32,
        /// The vertex id.
        point: u32,
        /// Mesh points.
        points: usize,
    },
    /// The mesh could not be encoded in the walk's layout.
    #[error("layout: {0}")]
    Layout(String),
    /// A query has no isovalue, more than [`MAX_ISOVALUES`], or a NaN one.
    #[error("a query needs 1 to 4 finite isovalues, got {0:?}")]
    BadQuery(Vec<f32>),
}

/// Checks that `values` holds one finite value per point of a mesh with
/// `points` points.
pub fn check_values(values: &[f32], points: usize) -> Result<(), IsoError> {
    if values.len() != points {
        return Err(IsoError::ValueCount {
            values: values.len(),
            points,
        });
    }
    match values.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(IsoError::NonFiniteValue {
            point: i as u32,
            value: values[i],
        }),
        None => Ok(()),
    }
}

/// How a [`ClipBox`] clips the isosurface.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClipMode {
    /// Only crossings inside the closed box count.
    KeepInside,
    /// The paper's crop box (§7): crossings strictly inside the box are cut
    /// away (the box exposes the interior), the rest count.
    CutAway,
}

/// An axis-aligned clip box; whether a crossing counts is decided on its
/// point `origin + t · direction` computed in the method's own precision
/// (f64 for the reference, f32 for the others), so methods may disagree on
/// crossings within rounding of the box's faces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipBox {
    /// Lower corner.
    pub lo: Vec3,
    /// Upper corner.
    pub hi: Vec3,
    /// Keep the inside, or cut it away.
    pub mode: ClipMode,
}

impl ClipBox {
    /// True when a crossing at `p` counts.
    pub fn keeps(&self, p: Vec3) -> bool {
        match self.mode {
            ClipMode::KeepInside => p.cmpge(self.lo).all() && p.cmple(self.hi).all(),
            ClipMode::CutAway => !(p.cmpgt(self.lo).all() && p.cmplt(self.hi).all()),
        }
    }

    /// True when no crossing inside the box `[lo, hi]` can count (used to
    /// cull BVH subtrees: disjoint from a kept box, or inside a cut box).
    pub fn culls_box(&self, lo: Vec3, hi: Vec3) -> bool {
        match self.mode {
            ClipMode::KeepInside => lo.cmpgt(self.hi).any() || hi.cmplt(self.lo).any(),
            ClipMode::CutAway => lo.cmpgt(self.lo).all() && hi.cmplt(self.hi).all(),
        }
    }
}

/// What to look for along a ray: up to four isovalues and an optional clip
/// box. The ray's own `[t_min, t_max]` bounds the crossings too.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IsoQuery<'a> {
    /// The isovalues (1 to [`MAX_ISOVALUES`], finite).
    pub isovalues: &'a [f32],
    /// Optional clip box.
    pub clip: Option<ClipBox>,
}

impl<'a> IsoQuery<'a> {
    /// A query for `isovalues` without clipping.
    pub fn new(isovalues: &'a [f32]) -> IsoQuery<'a> {
        IsoQuery {
            isovalues,
            clip: None,
        }
    }

    /// The same query with a clip box.
    pub fn with_clip(self, clip: ClipBox) -> IsoQuery<'a> {
        IsoQuery {
            clip: Some(clip),
            ..self
        }
    }

    /// Checks the isovalues (1 to 4, finite).
    pub fn check(&self) -> Result<(), IsoError> {
        let n = self.isovalues.len();
        if n == 0 || n > MAX_ISOVALUES || self.isovalues.iter().any(|v| !v.is_finite()) {
            return Err(IsoError::BadQuery(self.isovalues.to_vec()));
        }
        Ok(())
    }

    /// True when a crossing at `p` passes the clip box.
    #[inline]
    pub fn keeps(&self, p: Vec3) -> bool {
        self.clip.is_none_or(|c| c.keeps(p))
    }

    /// True when some isovalue lies in the range `(lo, hi]` (the straddle
    /// rule of the module docs applied to a node's or tet's value range).
    #[inline]
    pub fn active(&self, lo: f32, hi: f32) -> bool {
        self.isovalues.iter().any(|&v| straddles(lo, hi, v))
    }
}

/// True when a tet (or a subtree) with vertex values in `[lo, hi]` can hold
/// a crossing of `iso`: some value below (`< iso`) and some above (`≥ iso`).
#[inline(always)]
pub fn straddles(lo: f32, hi: f32, iso: f32) -> bool {
    lo < iso && iso <= hi
}

/// The first isosurface crossing of a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IsoHit {
    /// Ray parameter of the crossing.
    pub t: f32,
    /// The tet holding the crossing (index into `mesh.tets`).
    pub tet: u32,
    /// Which isovalue of the query was crossed.
    pub isovalue_index: u8,
    /// The field gradient in that tet, normalised (points toward larger
    /// values; zero for a constant tet).
    pub normal: Vec3,
}

impl IsoHit {
    /// Order used to pick among crossings: smaller `t` first, ties broken by
    /// tet and isovalue index, so every method picks the same one whatever
    /// order it finds them in.
    #[inline]
    pub fn before(&self, other: &IsoHit) -> bool {
        (self.t, self.tet, self.isovalue_index) < (other.t, other.tet, other.isovalue_index)
    }
}

/// Traversal counters (the paper's Table 4 and the walk's steps).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct IsoStats {
    /// BVH nodes visited (popped and tested).
    pub nodes_visited: u64,
    /// Ray–box tests done.
    pub box_tests: u64,
    /// Tet value-range tests done (walk: tets visited).
    pub range_tests: u64,
    /// Isopolygons built (packets: once per packet and tet).
    pub isopolygons: u64,
    /// Ray–isopolygon tests done (walk: crossings computed).
    pub isopolygon_tests: u64,
    /// Packet nodes rejected by the interval (frustum) test.
    pub frustum_culls: u64,
}

impl IsoStats {
    /// Adds `o`'s counters to these.
    pub fn add(&mut self, o: &IsoStats) {
        self.nodes_visited += o.nodes_visited;
        self.box_tests += o.box_tests;
        self.range_tests += o.range_tests;
        self.isopolygons += o.isopolygons;
        self.isopolygon_tests += o.isopolygon_tests;
        self.frustum_culls += o.frustum_culls;
    }
}

/// The normalised gradient of the linear field over a tet with corners `p`
/// and values `v` (zero when the tet is flat or the field constant).
pub fn gradient(p: [Vec3; 4], v: [f32; 4]) -> Vec3 {
    let m = Mat3::from_cols(p[1] - p[0], p[2] - p[0], p[3] - p[0]).transpose();
    let b = Vec3::new(v[1] - v[0], v[2] - v[0], v[3] - v[0]);
    let det = m.determinant();
    if det == 0.0 || !det.is_finite() {
        return Vec3::ZERO;
    }
    let g = m.inverse() * b;
    g.try_normalize().unwrap_or(Vec3::ZERO)
}
