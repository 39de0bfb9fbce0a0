//! The lanes of a lockstep walk in structure-of-arrays form ([`Pack`]),
//! shared by every width: filled from the batch, then walked by the
//! portable lane loops or loaded into the registers of the AVX2 and
//! AVX-512 walks; and the gathers' view of a layout ([`Geo`]).

use glam::Vec3;
use tet_core::TetMesh;

use crate::walk::lanes::Feed;
use crate::walk::projection::DuffF32;
use crate::walk::start::Lane;
use crate::walk::topology::{ExitRule, RecordWords};

/// `W` walks in structure-of-arrays form: entry `[l]` of every field is
/// lane `l`.
#[derive(Clone, Copy)]
pub(crate) struct Pack<const W: usize> {
    /// Ray origin `o` (x, y, z).
    pub(crate) o: [[f32; W]; 3],
    /// Duff basis columns: `c[0] = (uₓ, vₓ)`, `c[1] = (u_y, v_y)`,
    /// `c[2] = (u_z, v_z)`, as `[axis][coordinate][lane]`.
    pub(crate) c: [[[f32; W]; 2]; 3],
    /// Entry face ids `idx₀..₂` (counter-clockwise).
    pub(crate) ids: [[u32; W]; 3],
    /// Their projections.
    pub(crate) xs: [[f32; W]; 3],
    pub(crate) ys: [[f32; W]; 3],
    /// Tet entered next.
    pub(crate) next: [u32; W],
    /// Raw link it is entered through.
    pub(crate) entry: [u32; W],
    /// Tets visited so far.
    pub(crate) visited: [u32; W],
    /// Lane holds a walk (else parked: its state is frozen, its loads stay
    /// in range, its results are ignored).
    pub(crate) live: [bool; W],
    /// Index of the lane's ray in the batch.
    pub(crate) ray: [usize; W],
    /// The lane's projection (cold: rebuilding the scalar lane).
    pub(crate) proj: [DuffF32; W],
}

/// What a round left for the cold path, per lane: the exit link and whether
/// the decoded vertex was out of range.
pub(crate) struct Round<const W: usize> {
    pub(crate) raw: [u32; W],
    pub(crate) lost: [bool; W],
    pub(crate) capped: [bool; W],
}

impl<const W: usize> Pack<W> {
    /// Loads the scalar lane `lane` (ray `ray`) into slot `l`.
    pub(crate) fn set(&mut self, l: usize, ray: usize, lane: &Lane<DuffF32>) {
        let p = lane.proj;
        self.o[0][l] = p.o.x;
        self.o[1][l] = p.o.y;
        self.o[2][l] = p.o.z;
        for (axis, col) in [p.cx, p.cy, p.cz].iter().enumerate() {
            self.c[axis][0][l] = col.x;
            self.c[axis][1][l] = col.y;
        }
        for k in 0..3 {
            self.ids[k][l] = lane.st.ids[k];
            self.xs[k][l] = lane.st.p.xs[k];
            self.ys[k][l] = lane.st.p.ys[k];
        }
        self.next[l] = lane.next;
        self.entry[l] = lane.entry_raw;
        self.visited[l] = lane.st.visited;
        self.live[l] = true;
        self.ray[l] = ray;
        self.proj[l] = p;
    }

    /// Parks slot `l`: tet 0 (exists whenever a walk started) keeps its
    /// loads in range.
    pub(crate) fn park(&mut self, l: usize) {
        self.live[l] = false;
        self.next[l] = 0;
    }
}

/// `W` lanes filled with the first walks of the batch that do not end in
/// their start tet (the others are written to `out`), parked when there are
/// fewer; and the number of live lanes.
pub(crate) fn fill<const W: usize>(feed: &mut Feed<'_>) -> (Pack<W>, usize) {
    let mut pk = Pack::<W> {
        o: [[0.0; W]; 3],
        c: [[[0.0; W]; 2]; 3],
        ids: [[0; W]; 3],
        xs: [[0.0; W]; 3],
        ys: [[0.0; W]; 3],
        next: [0; W],
        entry: [0; W],
        visited: [0; W],
        live: [false; W],
        ray: [0; W],
        proj: [DuffF32::default(); W],
    };
    let mut live = 0;
    for l in 0..W {
        match feed.next_lane::<DuffF32>() {
            Some((i, lane)) => {
                pk.set(l, i, &lane);
                live += 1;
            }
            None => pk.park(l),
        }
    }
    (pk, live)
}

/// Lanes of the AVX2 lockstep walk (256-bit vectors of f32 / u32).
pub const WIDE: usize = 8;
/// Lanes of the portable lockstep walk (128-bit vectors).
pub const NARROW: usize = 4;

/// Array bases and bounds of the gathers of the AVX2 and AVX-512 walks.
#[cfg(target_arch = "x86_64")]
pub(crate) struct Geo<'a> {
    pub(crate) points: &'a [Vec3],
    pub(crate) words: &'a [u32],
    pub(crate) last_point: i32,
    pub(crate) last_tet: i32,
    pub(crate) stride: i32,
    pub(crate) vx: i32,
    pub(crate) ids: i32,
    pub(crate) links: i32,
}

#[cfg(target_arch = "x86_64")]
impl<'a> Geo<'a> {
    /// The gathers' view of `mesh` and its records `rw`, which must be
    /// [`RecordWords::gatherable`] (checked: the gathers' bounds rest on it).
    pub(crate) fn new(mesh: &'a TetMesh, rw: &RecordWords<'a>) -> Geo<'a> {
        assert!(
            rw.gatherable(mesh.points.len()),
            "record words not gatherable"
        );
        let (ids, links) = match rw.rule {
            ExitRule::Rank { links } | ExitRule::RankXor { links } => (0, links),
            ExitRule::Slot { ids, links } | ExitRule::Ids { ids, links } => (ids, links),
        };
        Geo {
            points: &mesh.points,
            words: rw.words,
            last_point: (mesh.points.len() - 1) as i32,
            last_tet: (rw.words.len() / rw.stride - 1) as i32,
            stride: rw.stride as i32,
            vx: rw.vx as i32,
            ids: ids as i32,
            links: links as i32,
        }
    }
}

#[cfg(target_arch = "x86_64")]
pub(crate) const RANK: u8 = 0;
#[cfg(target_arch = "x86_64")]
pub(crate) const RANK_XOR: u8 = 1;
#[cfg(target_arch = "x86_64")]
pub(crate) const SLOT: u8 = 2;
