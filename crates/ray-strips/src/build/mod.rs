//! Construction (paper §4.2): validate, skip zero-area-by-index triangles,
//! SAH-split the triangles into chunks of at most `chunk_triangles`,
//! stripify each chunk, give each strip a BVH leaf (chunks with several
//! strips get an SAH subtree over their strips, the paper's "new child
//! nodes") and write each strip's block with its hierarchy.
//!
//! Vertices are renumbered in order of first use by the strips (in BVH
//! order), which keeps the vertices of a leaf close in memory and drops
//! vertices no triangle uses.

mod sah;
mod strip_hierarchy;
pub(crate) mod stripify;

use glam::Vec3;

use crate::error::BuildError;
use crate::layout::{
    BvhNode, LEAF, MAX_STRIP, MAX_TRIANGLES, PERMUTATION_BITS, PERMUTATIONS, SWAP_WORD, StripData,
    hierarchy_nodes, triangle_word_bits,
};
use crate::options::BuildOptions;
use crate::stats::Stats;
use sah::{Item, bounds, median, split};
use stripify::{SWAP, Strip, stripify};

/// Depth from which the SAH gives way to count-median splits, which keeps
/// the tree shallow on any input: at most `32 + log2(triangles) < 62`
/// levels, within the traversal stack of 64.
const SAH_MAX_DEPTH: usize = 32;

/// Builds the traversal data and its statistics.
pub(crate) fn build(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    options: &BuildOptions,
) -> Result<(StripData, Stats), BuildError> {
    if options.chunk_triangles == 0 {
        return Err(BuildError::ZeroChunkTriangles);
    }
    if options.strips_per_leaf == 0 {
        return Err(BuildError::ZeroStripsPerLeaf);
    }
    if triangles.len() > MAX_TRIANGLES {
        return Err(BuildError::TooManyTriangles {
            count: triangles.len(),
            limit: MAX_TRIANGLES,
        });
    }
    if let Some((vertex, p)) = positions.iter().enumerate().find(|(_, p)| !p.is_finite()) {
        return Err(BuildError::NonFiniteVertex {
            vertex,
            position: p.to_array(),
        });
    }
    let mut items = Vec::with_capacity(triangles.len());
    for (t, tri) in triangles.iter().enumerate() {
        if let Some(&index) = tri.iter().find(|&&i| i as usize >= positions.len()) {
            return Err(BuildError::IndexOutOfRange {
                triangle: t,
                index,
                vertex_count: positions.len(),
            });
        }
        if tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0] {
            continue;
        }
        let [a, b, c] = tri.map(|i| positions[i as usize]);
        items.push(Item {
            lo: a.min(b).min(c),
            hi: a.max(b).max(c),
            id: t as u32,
        });
    }
    let mut builder = Builder {
        positions,
        triangles,
        options: *options,
        remap: vec![u32::MAX; positions.len()],
        data: StripData {
            triangle_bits: triangle_word_bits(triangles.len()),
            ..StripData::default()
        },
        stats: Stats {
            triangles: items.len(),
            skipped_triangles: triangles.len() - items.len(),
            ..Stats::default()
        },
    };
    if !items.is_empty() {
        builder.triangle_node(&mut items, 0);
    }
    let mut stats = builder.stats;
    let mut data = builder.data;
    data.vertices.shrink_to_fit();
    data.words.shrink_to_fit();
    data.nodes.shrink_to_fit();
    stats.vertices = data.vertices.len();
    stats.triangle_word_bits = data.triangle_bits;
    stats.top_level_nodes = data.nodes.len();
    stats.mean_strip_triangles = if stats.strips == 0 {
        0.0
    } else {
        stats.triangles as f64 / stats.strips as f64
    };
    Ok((data, stats))
}

/// Cuts strips longer than [`MAX_STRIP`] triangles into consecutive
/// pieces (a piece of triangles `[a, b)` keeps strip vertices `[a, b + 2)`,
/// so every triangle keeps its three vertices).
fn cut_long(strips: Vec<Strip>) -> Vec<Strip> {
    let mut out = Vec::with_capacity(strips.len());
    for s in strips {
        if s.triangles.len() <= MAX_STRIP {
            out.push(s);
            continue;
        }
        for a in (0..s.triangles.len()).step_by(MAX_STRIP) {
            let b = (a + MAX_STRIP).min(s.triangles.len());
            out.push(Strip {
                vertices: s.vertices[a..b + 2].to_vec(),
                triangles: s.triangles[a..b].to_vec(),
            });
        }
    }
    out
}

struct Builder<'a> {
    positions: &'a [Vec3],
    triangles: &'a [[u32; 3]],
    options: BuildOptions,
    /// Input vertex → compact vertex (`u32::MAX`: not yet used).
    remap: Vec<u32>,
    data: StripData,
    stats: Stats,
}

impl Builder<'_> {
    /// Splits triangles by SAH down to chunks.
    fn triangle_node(&mut self, items: &mut [Item], depth: usize) {
        if items.len() <= self.options.chunk_triangles {
            self.chunk_node(items, depth);
            return;
        }
        self.inner(items, depth, |b, part, d| b.triangle_node(part, d));
    }

    /// An inner node over `items`; `child` builds each half.
    fn inner(
        &mut self,
        items: &mut [Item],
        depth: usize,
        mut child: impl FnMut(&mut Self, &mut [Item], usize),
    ) {
        let (lo, hi) = bounds(items);
        let at = self.data.nodes.len();
        self.data.nodes.push(BvhNode::new(lo, hi, 0, 0));
        let (mid, axis) = if depth < SAH_MAX_DEPTH {
            split(items)
        } else {
            median(items)
        };
        let (first, second) = items.split_at_mut(mid);
        child(self, first, depth + 1);
        let second_at = self.data.nodes.len() as u32;
        child(self, second, depth + 1);
        self.data.nodes[at] = BvhNode::new(lo, hi, second_at, axis as u32);
    }

    /// Stripifies one chunk and builds its strip leaves.
    fn chunk_node(&mut self, items: &mut [Item], depth: usize) {
        self.stats.chunks += 1;
        let local: Vec<[u32; 3]> = items
            .iter()
            .map(|it| self.triangles[it.id as usize])
            .collect();
        let strips = cut_long(stripify(&local, self.options.strip_swaps));
        let mut strip_items: Vec<Item> = strips
            .iter()
            .enumerate()
            .map(|(k, s)| {
                let (lo, hi) = s.vertices.iter().fold(
                    (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                    |(lo, hi), &v| {
                        let p = self.positions[v as usize];
                        (lo.min(p), hi.max(p))
                    },
                );
                Item {
                    lo,
                    hi,
                    id: k as u32,
                }
            })
            .collect();
        let ids: Vec<u32> = items.iter().map(|it| it.id).collect();
        self.strip_node(&mut strip_items, &strips, &ids, depth);
    }

    /// SAH subtree over a chunk's strips, down to `strips_per_leaf`.
    fn strip_node(&mut self, items: &mut [Item], strips: &[Strip], ids: &[u32], depth: usize) {
        if items.len() <= self.options.strips_per_leaf {
            let offset = self.data.words.len() as u32;
            let (lo, hi) = bounds(items);
            for it in items.iter() {
                let b = self.block(&strips[it.id as usize], ids, (lo, hi));
                debug_assert!(b.0.cmpge(lo).all() && b.1.cmple(hi).all());
            }
            self.data
                .nodes
                .push(BvhNode::new(lo, hi, offset, LEAF | items.len() as u32));
            return;
        }
        self.inner(items, depth, |b, part, d| {
            b.strip_node(part, strips, ids, d)
        });
    }

    /// Writes one strip's block into a leaf with box `leaf` and returns
    /// the strip's box.
    fn block(&mut self, strip: &Strip, ids: &[u32], leaf: (Vec3, Vec3)) -> (Vec3, Vec3) {
        let n = strip.triangles.len();
        let words: Vec<u32> = strip
            .triangles
            .iter()
            .enumerate()
            .map(|(j, &local)| {
                if local == SWAP {
                    return SWAP_WORD;
                }
                let input = ids[local as usize];
                let tri = self.triangles[input as usize];
                let at = &strip.vertices[j..j + 3];
                let pos =
                    tri.map(|v| at.iter().position(|&s| s == v).expect("same vertices") as u8);
                let p = PERMUTATIONS
                    .iter()
                    .position(|q| *q == pos)
                    .expect("a permutation of three");
                (input << PERMUTATION_BITS) | p as u32
            })
            .collect();
        let vertices: Vec<u32> = strip.vertices.iter().map(|&v| self.compact(v)).collect();
        let bounds = strip_hierarchy::write_block(
            &self.data.vertices,
            &vertices,
            &words,
            self.data.triangle_bits,
            leaf,
            &mut self.data.words,
        );
        self.stats.strips += 1;
        self.stats.swap_slots += strip.triangles.iter().filter(|&&t| t == SWAP).count();
        self.stats.max_strip_triangles = self.stats.max_strip_triangles.max(n);
        self.stats.hierarchy_nodes += hierarchy_nodes(n);
        bounds
    }

    /// The compact index of input vertex `v`, assigned on first use.
    fn compact(&mut self, v: u32) -> u32 {
        let slot = &mut self.remap[v as usize];
        if *slot == u32::MAX {
            *slot = self.data.vertices.len() as u32;
            self.data
                .vertices
                .push(self.positions[v as usize].to_array());
        }
        *slot
    }
}
