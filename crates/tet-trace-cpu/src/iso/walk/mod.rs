//! The iso walk (beyond the paper): the watertight tet walk of
//! [`crate::walk`] finds the isosurface without any acceleration structure.
//!
//! A ray enters the volume through a boundary face (the entry decision of
//! [`crate::boundary_entry`], the walk's own edge test, with the faces in a BVH:
//! `iso::hull`) or starts in the tet around its origin
//! ([`crate::locate()`]), then steps tet to neighbour across
//! the exit face chosen by Algorithm 1 of Aman et al. (2022) over the Tet32, Tet20 or
//! Tet16 layout ([`WalkLayout`]; the exit rules of [`crate::tet32`],
//! [`crate::tet20`], [`crate::tet16`]). Per tet visited:
//!
//! 1. the range test: the four vertex values straddle an isovalue
//!    ([`super::straddles`]); most tets stop here;
//! 2. only then the field values `F_in`, `F_out` where the ray crosses the
//!    entry and exit faces: barycentric interpolation of the face's three
//!    vertex values with weights from the walk's own projected 2-D points
//!    (the 2-D determinants that steer the walk), evaluated with the face's
//!    vertices sorted by id and clamped to their value range, so the tet on
//!    either side of a face gets the same bits; likewise the face's ray
//!    parameter from the vertices' depths along the ray;
//! 3. a crossing where `F_in` and `F_out` lie on different sides of the
//!    isovalue, at `t = t_in + (v − F_in)/(F_out − F_in)·(t_out − t_in)`.
//!
//! The walk visits a gap-free sequence of tets (watertight), each face value
//! is shared bit for bit by the two tets of the face, and a skipped tet's
//! faces lie on one side of every isovalue (clamping keeps a face's value in
//! its vertices' range): the classification of the face values along the
//! ray changes exactly where a crossing is reported, so no crossing falls
//! into a crack between tets. The first crossing accepted (in `[t_min,
//! t_max]`, passing the clip box) is the nearest, so a shadow ray (any hit)
//! is the same walk. Rays that leave the volume miss; a walk stops at the
//! step cap ([`crate::walk::step_cap`]) with [`Failure::StepCap`].
//!
//! Volume meshes rarely have constrained faces; any the mesh has are
//! walked through (the walk runs on a copy without them).
//!
//! A tile of rays ([`IsoWalk::trace_tile`]) first asks the regions'
//! min-max tree ([`super::regions`]) which of its rays may meet an
//! isosurface, and where: the others are misses without a walk (most camera
//! rays of a volume: the walk alone crosses the whole volume to learn
//! that), and a ray whose first region lies deep inside starts its walk
//! there (`walk/skip.rs`).
//!
//! Tiles of rays from outside the volume ([`IsoWalk::trace_tile`]) walk
//! the stretch before the first tet that straddles an isovalue in the SIMD
//! lockstep walk of the surface kernels and hand each ray to the scalar
//! walk there (`lockstep`): the same steps, twice as fast (see the
//! README's isosurface figures).

mod lockstep;
mod ray;
mod skip;

use std::borrow::Cow;

use glam::Vec3;
use tet_core::layout::{LayoutMesh, Tet16Mesh, Tet20Mesh, Tet32Mesh};
use tet_core::{Link, TetMesh};

use self::ray::{Ctx, Found};
use super::hull::Hull;
use super::marching::RayPre;
use super::regions::{RegionHit, RegionTree};
use super::{IsoError, IsoHit, IsoQuery, IsoStats, check_values};
use crate::boundary_entry::Viewpoint;
use crate::kernel::LANES;
use crate::locate::{LocateError, locate};
use crate::ray::{Failure, Ray, TraceOutcome};
use crate::walk::start::{Lane, begin};
use crate::walk::step::advance;
use crate::walk::stop::Advance;
use crate::walk::{
    BoundaryEntry, DuffF32, EntryHint, Face2, Projection, Start, Topology, prefetch_index, step_cap,
};

/// The compact layout an [`IsoWalk`] steps over.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum WalkLayout {
    /// [`tet_core::layout::Tet32`]: ids and links (32 bytes per tet).
    Tet32,
    /// [`tet_core::layout::Tet20`]: `VX` and rank-ordered links (20 bytes).
    Tet20,
    /// [`tet_core::layout::Tet16`]: `VX` and xor-ed links (16 bytes).
    Tet16,
}

impl WalkLayout {
    /// All three, smallest record last.
    pub const ALL: [WalkLayout; 3] = [WalkLayout::Tet32, WalkLayout::Tet20, WalkLayout::Tet16];

    /// Name for reports.
    pub fn name(self) -> &'static str {
        match self {
            WalkLayout::Tet32 => "tet32",
            WalkLayout::Tet20 => "tet20",
            WalkLayout::Tet16 => "tet16",
        }
    }
}

enum Topo {
    Tet32(Tet32Mesh),
    Tet20(Tet20Mesh),
    Tet16(Tet16Mesh),
}

/// How [`IsoWalk::trace_tile_as`] walks a tile.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TileWalk {
    /// [`LANES`] scalar walks interleaved on the thread.
    Interleaved,
    /// From a viewpoint outside the volume: the stretch of every walk up to
    /// the first tet that straddles an isovalue in SIMD lockstep (the
    /// widest lanes the CPU runs, portable lanes without AVX2), the rest
    /// scalar; from inside, as `Interleaved`.
    Lockstep,
}

/// Result of one iso walk.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IsoOutcome {
    /// The first crossing.
    Hit {
        /// The crossing.
        hit: IsoHit,
        /// Tets visited.
        tets_visited: u32,
    },
    /// No crossing before the ray left the volume (or beyond `t_max`).
    Miss {
        /// Tets visited.
        tets_visited: u32,
    },
    /// The walk failed (reported, as by the other walks).
    Failed {
        /// Why.
        failure: Failure,
        /// Tets visited before giving up.
        tets_visited: u32,
    },
}

impl IsoOutcome {
    /// The crossing, if any.
    pub fn hit(&self) -> Option<&IsoHit> {
        match self {
            IsoOutcome::Hit { hit, .. } => Some(hit),
            _ => None,
        }
    }

    /// True for [`IsoOutcome::Failed`].
    pub fn is_failure(&self) -> bool {
        matches!(self, IsoOutcome::Failed { .. })
    }

    /// True when this outcome is `whole`'s (the walk of the same ray from
    /// its start) reached by a shorter walk: the same hit bit for bit, or a
    /// miss or the same failure, with no more tets visited. A tile's rays
    /// culled or started at their first region ([`super::regions`]) are
    /// shortcuts of their whole walks.
    pub fn is_shortcut_of(&self, whole: &IsoOutcome) -> bool {
        let fewer = self.tets_visited() <= whole.tets_visited();
        fewer
            && match (self, whole) {
                (IsoOutcome::Hit { hit: a, .. }, IsoOutcome::Hit { hit: b, .. }) => a == b,
                (IsoOutcome::Miss { .. }, IsoOutcome::Miss { .. }) => true,
                (IsoOutcome::Failed { failure: a, .. }, IsoOutcome::Failed { failure: b, .. }) => {
                    a == b
                }
                _ => false,
            }
    }

    /// Tets visited.
    pub fn tets_visited(&self) -> u32 {
        match *self {
            IsoOutcome::Hit { tets_visited, .. }
            | IsoOutcome::Miss { tets_visited }
            | IsoOutcome::Failed { tets_visited, .. } => tets_visited,
        }
    }
}

/// The iso walk over one mesh and one set of point values.
pub struct IsoWalk<'m> {
    mesh: Cow<'m, TetMesh>,
    values: &'m [f32],
    topo: Topo,
    /// Each tet's vertex value range `[min, max]` (the range test reads
    /// one record per step, indexed by the tet, instead of the new vertex's
    /// value behind the step's dependent loads).
    ranges: Vec<[f32; 2]>,
    /// Boundary faces, when the boundary is convex (rays from outside).
    hull: Option<Hull>,
    /// Min-max per region: tiles skip the walks of rays that meet no
    /// region straddling an isovalue (`None`: every ray walks).
    regions: Option<RegionTree>,
    cap: u32,
}

/// The value range `[min, max]` of every tet's four vertices.
fn tet_ranges(mesh: &TetMesh, values: &[f32]) -> Vec<[f32; 2]> {
    mesh.tets
        .iter()
        .map(|ids| {
            let v = ids.map(|i| values[i as usize]);
            [
                v[0].min(v[1]).min(v[2].min(v[3])),
                v[0].max(v[1]).max(v[2].max(v[3])),
            ]
        })
        .collect()
}

/// The mesh with every constrained face replaced by a plain link (a volume
/// walk crosses them); borrowed when there is none.
fn unconstrained(mesh: &TetMesh) -> Cow<'_, TetMesh> {
    if mesh.constrained.is_empty() {
        return Cow::Borrowed(mesh);
    }
    let mut m = mesh.clone();
    for (t, links) in m.neighbors.iter_mut().enumerate() {
        for l in links.iter_mut() {
            if let Some(c) = l.as_constrained() {
                let other = mesh
                    .constrained
                    .get(c as usize)
                    .and_then(|cf| cf.other_side(t as u32))
                    .filter(|s| s.exists());
                *l = other.map_or(Link::BOUNDARY, |s| Link::tet(s.tet));
            }
        }
    }
    m.constrained.clear();
    m.triangle_count = 0;
    Cow::Owned(m)
}

impl<'m> IsoWalk<'m> {
    /// Encodes `mesh` in `layout` for walks over the field `values` (one
    /// value per mesh point). Rays from outside need a convex boundary
    /// ([`BoundaryEntry::new`]); without one they are reported as
    /// [`Failure::Lost`].
    pub fn new(mesh: &'m TetMesh, values: &'m [f32], layout: WalkLayout) -> Result<Self, IsoError> {
        Self::with_regions(mesh, values, layout, true)
    }

    /// [`IsoWalk::new`], with or without the regions' min-max tree
    /// (`false`: every ray of a tile walks until it leaves the volume; the
    /// outcomes of rays that meet an isosurface are the same).
    pub fn with_regions(
        mesh: &'m TetMesh,
        values: &'m [f32],
        layout: WalkLayout,
        regions: bool,
    ) -> Result<Self, IsoError> {
        check_values(values, mesh.points.len())?;
        let mesh = unconstrained(mesh);
        let err = |e: tet_core::layout::LayoutError| IsoError::Layout(e.to_string());
        let topo = match layout {
            WalkLayout::Tet32 => Topo::Tet32(LayoutMesh::from_mesh(&mesh).map_err(err)?),
            WalkLayout::Tet20 => Topo::Tet20(LayoutMesh::from_mesh(&mesh).map_err(err)?),
            WalkLayout::Tet16 => Topo::Tet16(LayoutMesh::from_mesh(&mesh).map_err(err)?),
        };
        let hull = BoundaryEntry::new(&mesh).ok().map(|_| Hull::new(&mesh));
        let cap = step_cap(&mesh);
        let ranges = tet_ranges(&mesh, values);
        let regions = regions.then(|| RegionTree::new(&mesh, &ranges));
        Ok(IsoWalk {
            mesh,
            values,
            topo,
            ranges,
            hull,
            regions,
            cap,
        })
    }

    /// The same walk over other values of the same points (a new time step:
    /// only the per-tet value ranges are recomputed, one pass over the tets).
    pub fn with_values(mut self, values: &'m [f32]) -> Result<Self, IsoError> {
        check_values(values, self.mesh.points.len())?;
        self.values = values;
        self.ranges = tet_ranges(&self.mesh, values);
        if let Some(r) = &mut self.regions {
            r.refit(&self.mesh, &self.ranges);
        }
        Ok(self)
    }

    /// The mesh walked (constrained faces removed).
    pub fn mesh(&self) -> &TetMesh {
        &self.mesh
    }

    /// Bytes of the walk's data: layout records, points, the per-tet value
    /// ranges (8 bytes per tet), the boundary faces' BVH and the regions'
    /// tree (the values are the caller's, 4 bytes per point, not counted).
    pub fn bytes(&self) -> usize {
        let (recs, pts) = match &self.topo {
            Topo::Tet32(m) => (std::mem::size_of_val(&m.tets[..]), m.points.len()),
            Topo::Tet20(m) => (std::mem::size_of_val(&m.tets[..]), m.points.len()),
            Topo::Tet16(m) => (std::mem::size_of_val(&m.tets[..]), m.points.len()),
        };
        recs + pts * 12
            + std::mem::size_of_val(&self.ranges[..])
            + self.hull.as_ref().map_or(0, Hull::bytes)
            + self.regions.as_ref().map_or(0, RegionTree::bytes)
    }

    /// Locates the viewpoint of many rays once ([`Viewpoint::locate`]).
    pub fn viewpoint(&self, position: Vec3) -> Option<Viewpoint> {
        Viewpoint::locate(&self.mesh, position).ok()
    }

    /// Traces `ray`: locates its origin (walking from tet 0), or enters the
    /// volume through its boundary from outside.
    pub fn trace(&self, ray: &Ray, query: &IsoQuery) -> IsoOutcome {
        let start = match locate(&self.mesh, ray.origin, 0) {
            Ok(t) => Ok(Start::Tet(t)),
            Err(LocateError::OutsideMesh { .. }) => self.enter(ray, &mut EntryHint::default()),
            Err(_) => Err(TraceOutcome::Failed {
                failure: Failure::InvalidRay,
                tets_visited: 0,
            }),
        };
        self.trace_start(ray, start, query, &mut IsoStats::default())
    }

    /// Traces `ray` whose origin lies in or near tet `near` (a secondary
    /// ray from an earlier hit in that tet): locates the origin walking from
    /// `near`, else enters from outside as [`IsoWalk::trace`] does.
    pub fn trace_near(
        &self,
        ray: &Ray,
        near: u32,
        query: &IsoQuery,
        stats: &mut IsoStats,
    ) -> IsoOutcome {
        let from = if (near as usize) < self.mesh.tets.len() {
            near
        } else {
            0
        };
        let start = match locate(&self.mesh, ray.origin, from) {
            Ok(t) => Ok(Start::Tet(t)),
            Err(LocateError::OutsideMesh { .. }) => self.enter(ray, &mut EntryHint::default()),
            Err(_) => Err(TraceOutcome::Failed {
                failure: Failure::InvalidRay,
                tets_visited: 0,
            }),
        };
        self.trace_start(ray, start, query, stats)
    }

    /// Shadow ray from a point in or near tet `near` ([`IsoWalk::trace_near`]):
    /// true when some crossing lies in `[t_min, t_max]`. `Err` when the walk
    /// failed.
    pub fn occluded_near(&self, ray: &Ray, near: u32, query: &IsoQuery) -> Result<bool, Failure> {
        match self.trace_near(ray, near, query, &mut IsoStats::default()) {
            IsoOutcome::Hit { .. } => Ok(true),
            IsoOutcome::Miss { .. } => Ok(false),
            IsoOutcome::Failed { failure, .. } => Err(failure),
        }
    }

    /// Traces `ray`, whose origin is the viewpoint `vp` (see
    /// [`IsoWalk::viewpoint`]); `hint` carries the entry face between rays.
    pub fn trace_from(
        &self,
        vp: &Viewpoint,
        ray: &Ray,
        query: &IsoQuery,
        hint: &mut EntryHint,
        stats: &mut IsoStats,
    ) -> IsoOutcome {
        let start = match vp {
            Viewpoint::Inside(t) => Ok(Start::Tet(*t)),
            Viewpoint::Outside(_) => self.enter(ray, hint),
        };
        self.trace_start(ray, start, query, stats)
    }

    /// The start of a ray whose origin lies outside the mesh: the boundary
    /// face its line enters through ([`Hull`]), a miss when none, a
    /// failure when the boundary is not convex or the ray invalid.
    fn enter(&self, ray: &Ray, hint: &mut EntryHint) -> Result<Start, TraceOutcome> {
        let fail = |failure| TraceOutcome::Failed {
            failure,
            tets_visited: 0,
        };
        if !ray.is_valid() {
            return Err(fail(Failure::InvalidRay));
        }
        let hull = self.hull.as_ref().ok_or(fail(Failure::Lost))?;
        hull.start(&self.mesh, &RayPre::new(ray), hint)
            .ok_or(TraceOutcome::Miss { tets_visited: 0 })
    }

    /// Shadow ray (any hit): true when some crossing lies in `[t_min,
    /// t_max]`; the walk's first crossing is its nearest, so this is
    /// [`IsoWalk::trace`]. `Err` when the walk failed.
    pub fn occluded(&self, ray: &Ray, query: &IsoQuery) -> Result<bool, Failure> {
        match self.trace(ray, query) {
            IsoOutcome::Hit { .. } => Ok(true),
            IsoOutcome::Miss { .. } => Ok(false),
            IsoOutcome::Failed { failure, .. } => Err(failure),
        }
    }

    /// Traces the rays of a tile (all from the viewpoint `vp`) into `out`
    /// (same length), [`LANES`] walks interleaved on this thread, one step
    /// each per round, so that their dependent memory loads overlap. Each
    /// outcome is [`IsoWalk::trace_from`]'s for that ray (the same
    /// functions).
    pub fn trace_tile(
        &self,
        vp: &Viewpoint,
        rays: &[Ray],
        query: &IsoQuery,
        out: &mut [IsoOutcome],
        stats: &mut IsoStats,
    ) {
        // Lockstep where the CPU has AVX2 (measured there) unless
        // `TET_LOCKSTEP=scalar` asks for the interleaved walk.
        let how = if crate::lockstep::Width::Auto.available() {
            TileWalk::Lockstep
        } else {
            TileWalk::Interleaved
        };
        self.trace_tile_as(how, vp, rays, query, out, stats);
    }

    /// [`IsoWalk::trace_tile`] with the tile walk chosen by the caller
    /// (tests and comparisons; `trace_tile` picks [`TileWalk::Lockstep`]
    /// where the CPU has AVX2). The outcomes are the same either way.
    pub fn trace_tile_as(
        &self,
        how: TileWalk,
        vp: &Viewpoint,
        rays: &[Ray],
        query: &IsoQuery,
        out: &mut [IsoOutcome],
        stats: &mut IsoStats,
    ) {
        if matches!(vp, Viewpoint::Outside(_)) && how == TileWalk::Lockstep {
            match &self.topo {
                Topo::Tet32(t) => self.tile_lockstep(t, rays, query, out, stats),
                Topo::Tet20(t) => self.tile_lockstep(t, rays, query, out, stats),
                Topo::Tet16(t) => self.tile_lockstep(t, rays, query, out, stats),
            }
            return;
        }
        match &self.topo {
            Topo::Tet32(t) => self.tile(t, vp, rays, query, out, stats),
            Topo::Tet20(t) => self.tile(t, vp, rays, query, out, stats),
            Topo::Tet16(t) => self.tile(t, vp, rays, query, out, stats),
        }
    }

    fn tile<T: Topology>(
        &self,
        topo: &T,
        vp: &Viewpoint,
        rays: &[Ray],
        query: &IsoQuery,
        out: &mut [IsoOutcome],
        stats: &mut IsoStats,
    ) {
        let n = rays.len().min(out.len());
        let regions = self.first_regions(&rays[..n], query, stats);
        let mut prev = None;
        let mut hint = EntryHint::default();
        let mut lanes: [Option<(usize, WalkState)>; LANES] = std::array::from_fn(|_| None);
        let mut next = 0;
        loop {
            let mut active = 0;
            for slot in lanes.iter_mut() {
                while slot.is_none() && next < n {
                    let i = next;
                    next += 1;
                    let ray = &rays[i];
                    let inside = match vp {
                        Viewpoint::Inside(t) => Some(*t),
                        Viewpoint::Outside(_) => None,
                    };
                    let Some(start) =
                        self.tile_start(ray, regions[i], inside, &mut prev, &mut hint)
                    else {
                        out[i] = IsoOutcome::Miss { tets_visited: 0 };
                        continue;
                    };
                    let opened = match start {
                        _ if query.check().is_err() => Err(IsoOutcome::Failed {
                            failure: Failure::InvalidRay,
                            tets_visited: 0,
                        }),
                        Ok(s) => self.open(ray, s, query, stats),
                        Err(o) => Err(converted(o)),
                    };
                    match opened {
                        Ok(w) => *slot = Some((i, w)),
                        Err(o) => out[i] = o,
                    }
                }
                if let Some((i, w)) = slot {
                    active += 1;
                    if let Some(o) = self.step(topo, w, stats) {
                        stats.range_tests += o.tets_visited().saturating_sub(w.opened) as u64;
                        out[*i] = o;
                        *slot = None;
                    }
                }
            }
            if active == 0 && next >= n {
                return;
            }
        }
    }

    /// What the regions say of each ray of a tile
    /// ([`RegionTree::first_regions`]; walk them all when the walk keeps no
    /// regions or the query is invalid).
    pub(super) fn first_regions(
        &self,
        rays: &[Ray],
        query: &IsoQuery,
        stats: &mut IsoStats,
    ) -> Vec<RegionHit> {
        let mut out = vec![RegionHit::Walk; rays.len()];
        if let Some(r) = &self.regions
            && query.check().is_ok()
        {
            r.first_regions(rays, query, &mut out, stats);
        }
        out
    }

    /// Traces `ray` from a walk start (`Err`: its outcome before any walk).
    pub fn trace_start(
        &self,
        ray: &Ray,
        start: Result<Start, TraceOutcome>,
        query: &IsoQuery,
        stats: &mut IsoStats,
    ) -> IsoOutcome {
        if query.check().is_err() {
            return IsoOutcome::Failed {
                failure: Failure::InvalidRay,
                tets_visited: 0,
            };
        }
        let start = match start {
            Ok(s) => s,
            Err(out) => return converted(out),
        };
        match &self.topo {
            Topo::Tet32(t) => self.walk(t, ray, start, query, stats),
            Topo::Tet20(t) => self.walk(t, ray, start, query, stats),
            Topo::Tet16(t) => self.walk(t, ray, start, query, stats),
        }
    }

    fn walk<T: Topology>(
        &self,
        topo: &T,
        ray: &Ray,
        start: Start,
        query: &IsoQuery,
        stats: &mut IsoStats,
    ) -> IsoOutcome {
        let mut w = match self.open(ray, start, query, stats) {
            Ok(w) => w,
            Err(out) => return out,
        };
        loop {
            if let Some(out) = self.step(topo, &mut w, stats) {
                // One range test per tet entered (not counted per step).
                stats.range_tests += out.tets_visited().saturating_sub(w.opened) as u64;
                return out;
            }
        }
    }

    /// Everything before the walk's loop: the start tet (from the origin
    /// to its exit face) or the entry face. `Err`: the walk already ended.
    pub(super) fn open<'a>(
        &'a self,
        ray: &'a Ray,
        start: Start,
        query: &'a IsoQuery<'a>,
        stats: &mut IsoStats,
    ) -> Result<WalkState<'a>, IsoOutcome> {
        let mesh: &TetMesh = &self.mesh;
        let ctx = Ctx::new(mesh, self.values, ray, query);
        let lane = match begin::<DuffF32>(mesh, ray, start) {
            Ok(l) => l,
            Err(TraceOutcome::Miss { tets_visited }) => {
                // The start tet's exit face is the boundary.
                if let Start::Tet(t) = start {
                    stats.range_tests += 1;
                    if let Some(hit) = ctx.start_tet_alone(t) {
                        return Err(IsoOutcome::Hit {
                            hit,
                            tets_visited: 1,
                        });
                    }
                }
                return Err(IsoOutcome::Miss { tets_visited });
            }
            Err(out) => return Err(converted(out)),
        };
        let opened = lane.st.visited;
        let mut w = WalkState {
            lane,
            cached: None,
            ctx,
            opened,
        };
        if let Start::Tet(_) = start {
            // The start tet: from the origin to its exit face.
            let tet = w.lane.st.tet;
            stats.range_tests += 1;
            if w.ctx.active(self.ranges[tet as usize]) {
                let f_in = w.ctx.value_at_origin(tet);
                let out = w.ctx.face(w.lane.st.ids, &w.lane.st.p);
                w.cached = Some(out);
                stats.isopolygon_tests += 1;
                let visited = w.lane.st.visited;
                match w.ctx.crossing(tet, (f_in, 0.0), out) {
                    Found::Hit(hit) => {
                        return Err(IsoOutcome::Hit {
                            hit,
                            tets_visited: visited,
                        });
                    }
                    Found::Beyond => {
                        return Err(IsoOutcome::Miss {
                            tets_visited: visited,
                        });
                    }
                    Found::None => {}
                }
            }
        }
        Ok(w)
    }

    /// One step of the walk: enter the next tet, test it; `Some` when the
    /// walk ended.
    #[inline(always)]
    pub(super) fn step<T: Topology>(
        &self,
        topo: &T,
        w: &mut WalkState,
        stats: &mut IsoStats,
    ) -> Option<IsoOutcome> {
        let points = &self.mesh.points[..];
        let lane = &mut w.lane;
        let tet = lane.next;
        // The range is read before the step's own loads: it depends only on
        // the tet, known (and prefetched) one step ahead.
        let range = self.ranges.get(tet as usize).copied();
        let entry_ids = lane.st.ids;
        let adv = advance(points, topo, lane, self.cap);
        let failed = |failure| {
            Some(IsoOutcome::Failed {
                failure,
                tets_visited: lane.st.visited,
            })
        };
        match adv {
            Advance::Go => prefetch_index(&self.ranges, lane.next),
            // The iso walk's lanes are never bounded (no `Reach`): their
            // faces are checked like any other.
            Advance::Face | Advance::Beyond => {}
            Advance::Cap => return failed(Failure::StepCap),
            Advance::Lost => return failed(Failure::Lost),
        }
        let Some(range) = range else {
            return failed(Failure::Lost);
        };
        let exit_ids = lane.st.ids;
        let entry_cache = w.cached.take();
        let visited = lane.st.visited;
        if w.ctx.active(range) {
            // The entry face's projections are recomputed when the previous
            // tet did not compute its value: a pure function of the vertex,
            // so the same bits.
            let f_in = entry_cache.unwrap_or_else(|| {
                let p = entry_ids.map(|i| lane.proj.project(points[i as usize]));
                w.ctx.face(entry_ids, &Face2::new(p))
            });
            let out = w.ctx.face(exit_ids, &lane.st.p);
            w.cached = Some(out);
            stats.isopolygon_tests += 1;
            match w.ctx.crossing(tet, f_in, out) {
                Found::Hit(hit) => {
                    return Some(IsoOutcome::Hit {
                        hit,
                        tets_visited: visited,
                    });
                }
                Found::Beyond => {
                    return Some(IsoOutcome::Miss {
                        tets_visited: visited,
                    });
                }
                Found::None => {}
            }
        }
        // The boundary (constrained faces were removed).
        (adv == Advance::Face).then_some(IsoOutcome::Miss {
            tets_visited: visited,
        })
    }
}

/// One walk in flight: the tet walk's lane, the entry face's values, the
/// cached face value and the ray's constants.
pub(super) struct WalkState<'a> {
    lane: Lane<DuffF32>,
    cached: Option<(f32, f32)>,
    ctx: Ctx<'a>,
    /// Tets visited when the walk loop began.
    opened: u32,
}

/// The walk's outcome before any walk, as an [`IsoOutcome`].
fn converted(out: TraceOutcome) -> IsoOutcome {
    match out {
        TraceOutcome::Failed {
            failure,
            tets_visited,
        } => IsoOutcome::Failed {
            failure,
            tets_visited,
        },
        other => IsoOutcome::Miss {
            tets_visited: other.tets_visited(),
        },
    }
}
