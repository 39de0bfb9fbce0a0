//! Ray-Strips: Lauterbach, Yoon and Manocha, "Ray-Strips: A Compact Mesh
//! Representation for Interactive Ray Tracing" (IEEE Symposium on Interactive Ray Tracing 2007).
//!
//! A two-level structure (paper §3.3): a high-level BVH built with the
//! surface-area heuristic down to chunks of at most
//! [`BuildOptions::chunk_triangles`] triangles; each chunk is cut into
//! triangle strips, and each strip — one BVH leaf — carries a balanced,
//! pointer-free strip hierarchy (a spatial kd-tree whose nodes store two
//! split coordinates, an axis and a reverse flag, §4.1). Traversal follows
//! Algorithm 1 for single rays and runs 2×2 packets that fall back to single
//! rays when few stay active (§5); the triangle test is watertight.
//!
//! | paper | module |
//! |---|---|
//! | §3.3.1 high-level BVH, §4.2 chunks and strips | `build` (private): `sah`, `stripify`, `strip_hierarchy` |
//! | §4.1 strip hierarchy, Fig. 5 layout | [`layout`] |
//! | §5.1 Algorithm 1 | `traverse::single` |
//! | §5.2 intersection (edge sharing) | `traverse::triangle` |
//! | §5.3 ray packets | `traverse::packet` |
//!
//! ```
//! use glam::Vec3;
//! use ray_strips::{BuildOptions, Ray, RayStrips};
//!
//! // A unit square in the z = 0 plane, as two triangles.
//! let positions = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
//! let triangles = [[0, 1, 2], [0, 2, 3]];
//! let rs = RayStrips::build(&positions, &triangles, &BuildOptions::default())?;
//!
//! let hit = rs.intersect(&Ray::new(Vec3::new(0.25, 0.5, 2.0), Vec3::NEG_Z)).unwrap();
//! assert_eq!(hit.triangle, 1);
//! assert_eq!(hit.t, 2.0);
//! // p = (1 − u − v)·v0 + u·v1 + v·v2 for triangle 1 = (0, 2, 3).
//! assert!((hit.u - 0.25).abs() < 1e-6 && (hit.v - 0.25).abs() < 1e-6);
//! assert_eq!(rs.stats().strips, 1);
//! # Ok::<(), ray_strips::BuildError>(())
//! ```
//!
//! # Memory
//!
//! Geometry: the global vertex list (12 bytes per vertex, `f32`), one
//! 4-byte vertex index per strip vertex (`n + 2` per strip of `n`
//! triangles) and one packed word per triangle (input triangle index and
//! vertex permutation, needed to report [`Hit::triangle`] and input-order
//! barycentrics; 3 bits plus the bits of the largest index, 20 bits for
//! the bunny). For a closed mesh (about half as many vertices as
//! triangles) and strips of mean length `s` that is about
//! `6 + 4 (1 + 2/s) + 2.5` bytes per triangle. Hierarchy: a 4-byte header
//! per strip (its length and its quantized box) and about 9 bytes per two
//! triangles ([`layout::strip_words`] gives the exact size of a strip from
//! `n` and the word width). Top level: 32 bytes per BVH node, two per leaf
//! (a binary tree over the leaves); a leaf holds up to
//! [`BuildOptions::strips_per_leaf`] strips of one chunk, by default all
//! of them, so about two nodes per chunk. Bunny (69,451 triangles) at the
//! defaults: 12,997 strips of 5.34 triangles on average and 7,147
//! top-level nodes; geometry 14.31, hierarchy 3.62 and top level 3.29
//! bytes per triangle, 21.22 in all (1.474 MB, within the paper's 1.5 MB).
//! [`RayStrips::bytes`] reports the exact totals.
//!
//! # Deviations from the paper
//!
//! * Stripification: a small greedy stripifier (`build::stripify`) instead
//!   of the Stripe library. Its strips are shorter on irregular meshes
//!   (bunny: 8.1 triangles per strip at chunks of 128, against Stripe's
//!   19.3 in Table 5), so one strip per leaf as in the paper takes 26.8
//!   bytes per triangle (1.86 MB) instead of the paper's 1.5 MB. The
//!   defaults instead cut the mesh into small chunks (28 triangles: short,
//!   compact strips, 5.3 triangles on average) and put all strips of a
//!   chunk into one leaf (a deviation: the paper gives each strip its own
//!   leaf), which fits the budget (21.2 bytes per triangle, 1.474 MB) with
//!   fewer instructions per ray than larger chunks
//!   (see [`BuildOptions::default`]). Swaps are implemented but off
//!   by default (see the stripifier's docs for why).
//! * Strip boxes: each strip's header carries its box, quantized to 4 bits
//!   per face within its leaf's box; a ray enters only the strips whose box
//!   it hits, and starts Algorithm 1 from that box's interval (the paper
//!   starts every strip of a leaf from the leaf's box). The header word
//!   that holds `n` has room for it, so it costs no memory.
//! * Frame: a scene whose largest coordinate lies outside `[2⁻¹⁶, 2¹⁷)` is
//!   stored scaled by a power of two, and rays are scaled to match, so the
//!   test's products neither overflow nor underflow `f32` (scenes at 10³⁰
//!   and 10⁻³⁰ trace like unit ones); this changes no rounding.
//! * Triangle test: Woop et al.'s watertight test with the paper's edge
//!   sharing along the strip, instead of Plücker edge tests.
//! * Layout: 32-bit header (length and strip box) and a packed
//!   per-triangle word (input id and vertex permutation instead of a
//!   16-bit material); node flag bytes after the node floats (see
//!   [`layout`]). A strip has at most [`layout::MAX_STRIP`] triangles.
//! * Algorithm 1: leaves hold 2 or 3 triangles (the odd one goes to the
//!   first leaf), the far child's entry distance is tightened, and every
//!   distance gets a small relative slack so culling is conservative.
//! * Packets run the per-ray arithmetic lane by lane (no SIMD intrinsics:
//!   the crate forbids `unsafe`; only the box test uses glam's 4-wide
//!   vectors), so they return exactly the single-ray results but are not
//!   faster than single rays here.
//!
//! # Input
//!
//! Indices out of range and non-finite vertex coordinates (of any vertex,
//! used or not) are [`BuildError`]s. Triangles with two equal vertex
//! indices are skipped (counted in [`Stats::skipped_triangles`]); other
//! zero-area triangles are kept and never reported as hit (the watertight
//! test rejects a zero determinant). Duplicate triangles and non-manifold
//! edges are stored like any other triangle; on equal distances the hit
//! with the smaller input index is reported.

#![deny(missing_docs)]
#![forbid(unsafe_code)]

mod build;
mod error;
mod frame;
pub mod inspect;
pub mod layout;
mod options;
mod ray;
mod stats;
mod traverse;

use glam::Vec3;

pub use error::BuildError;
pub use options::BuildOptions;
pub use ray::{Hit, Ray};
pub use stats::{Bytes, Stats};

use layout::{PERMUTATION_BITS, StripData, header_n, strip_hierarchy_words};
use traverse::packet::{LANES, PacketStacks, coherent, trace_packet};
use traverse::prepared::{Best, Prepared};
use traverse::single::trace;

/// A built Ray-Strips structure over one triangle mesh; immutable and
/// shareable between threads.
#[derive(Clone, Debug)]
pub struct RayStrips {
    data: StripData,
    stats: Stats,
    bytes: Bytes,
    /// The power of two the vertices were scaled by (see `frame`).
    scale: f32,
}

impl RayStrips {
    /// Builds the structure over `triangles` (indices into `positions`).
    ///
    /// # Errors
    /// [`BuildError`] for an index out of range, a non-finite coordinate,
    /// more than [`layout::MAX_TRIANGLES`] triangles or a zero
    /// `chunk_triangles`.
    pub fn build(
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        options: &BuildOptions,
    ) -> Result<RayStrips, BuildError> {
        let scale = frame::unit_scale(positions);
        let (data, stats) = if scale == 1.0 {
            build::build(positions, triangles, options)?
        } else {
            let scaled: Vec<Vec3> = positions.iter().map(|&p| p * scale).collect();
            build::build(&scaled, triangles, options)?
        };
        let bytes = measure(&data);
        Ok(Self {
            data,
            stats,
            bytes,
            scale,
        })
    }

    /// `ray` in the structure's frame: origin and range scaled, the same
    /// direction (see `frame`).
    #[inline(always)]
    fn framed(&self, ray: &Ray) -> Ray {
        if self.scale == 1.0 {
            return *ray;
        }
        Ray {
            origin: ray.origin * self.scale,
            direction: ray.direction,
            t_min: ray.t_min * self.scale,
            t_max: ray.t_max * self.scale,
        }
    }

    /// The hit recorded in `best`, its distance back in the caller's frame.
    fn hit(&self, best: &Best) -> Option<Hit> {
        (best.word != u32::MAX).then_some(Hit {
            triangle: best.word >> PERMUTATION_BITS,
            t: best.t / self.scale,
            u: best.u,
            v: best.v,
        })
    }

    /// The closest hit with `t` in `[t_min, t_max]`, if any.
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let ray = self.framed(ray);
        let pre = Prepared::new(&ray)?;
        let mut best = Best::new(ray.t_max);
        trace(&self.data, &pre, &mut best, false);
        self.hit(&best)
    }

    /// Whether anything is hit with `t` in `[t_min, t_max]`.
    pub fn occluded(&self, ray: &Ray) -> bool {
        let ray = self.framed(ray);
        let Some(pre) = Prepared::new(&ray) else {
            return false;
        };
        let mut best = Best::new(ray.t_max);
        trace(&self.data, &pre, &mut best, true)
    }

    /// Closest hits of many rays: `out[i]` is exactly `self.intersect(&rays[i])`.
    /// Consecutive groups of four rays travel as 2×2 packets when their
    /// directions share signs on all axes (pass the four rays of a 2×2
    /// pixel block together for coherence), otherwise as single rays.
    ///
    /// # Panics
    /// If `out.len() != rays.len()`.
    pub fn intersect_packet(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        assert_eq!(
            rays.len(),
            out.len(),
            "intersect_packet needs one output slot per ray"
        );
        let mut stacks = PacketStacks::new();
        for (rays, out) in rays.chunks(LANES).zip(out.chunks_mut(LANES)) {
            let framed: [Option<Ray>; LANES] =
                std::array::from_fn(|l| rays.get(l).map(|r| self.framed(r)));
            let mut pre = [None; LANES];
            let mut mask = 0u8;
            for (l, r) in framed.iter().enumerate() {
                pre[l] = r.as_ref().and_then(Prepared::new);
                if pre[l].is_some() {
                    mask |= 1 << l;
                }
            }
            let fill = pre.iter().flatten().next().copied();
            let (Some(fill), false) = (fill, self.data.nodes.is_empty()) else {
                out.fill(None);
                continue;
            };
            let pre = pre.map(|p| p.unwrap_or(fill));
            let mut best: [Best; LANES] =
                std::array::from_fn(|l| Best::new(framed[l].map_or(0.0, |r| r.t_max)));
            if coherent(&pre, mask) {
                trace_packet(&self.data, &pre, mask, &mut best, &mut stacks);
            } else {
                for l in (0..LANES).filter(|l| mask & (1 << l) != 0) {
                    trace(&self.data, &pre[l], &mut best[l], false);
                }
            }
            for (l, o) in out.iter_mut().enumerate() {
                *o = if mask & (1 << l) != 0 {
                    self.hit(&best[l])
                } else {
                    None
                };
            }
        }
    }

    /// Exact heap bytes of what traversal reads.
    pub fn bytes(&self) -> Bytes {
        self.bytes
    }

    /// Counts: triangles, strips, chunks, nodes.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// Every strip decoded (positions, input triangles, hierarchy nodes),
    /// in BVH leaf order: for tests and diagnostics, not for speed.
    pub fn strips(&self) -> Vec<inspect::StripView> {
        inspect::strips(&self.data)
    }
}

/// Splits the heap bytes by walking the BVH leaves' strip headers.
fn measure(data: &StripData) -> Bytes {
    let mut hierarchy_words = 0;
    let mut offset = 0;
    while offset < data.words.len() {
        let header = data.words[offset];
        hierarchy_words += strip_hierarchy_words(header_n(header) as usize);
        offset += data.block_words(header);
    }
    let hierarchy = 4 * hierarchy_words;
    let geometry = std::mem::size_of_val(data.vertices.as_slice())
        + std::mem::size_of_val(data.words.as_slice())
        - hierarchy;
    let top_level = std::mem::size_of_val(data.nodes.as_slice());
    Bytes {
        geometry,
        hierarchy,
        top_level,
        total: geometry + hierarchy + top_level,
    }
}
