//! Exact cleaning of a triangle soup before tetrahedralization.
//!
//! Steps, in order (no vertex is ever moved):
//! 1. reject NaN/inf coordinates and out-of-range indices (typed errors);
//! 2. merge exactly-equal vertices (`-0.0 == 0.0`); the lowest input index
//!    of each position is kept;
//! 3. drop triangles that repeat a vertex (after merging);
//! 4. drop zero-area triangles: exactly collinear vertices, decided with exact
//!    `orient2d` on the three coordinate projections (three points are
//!    collinear in 3-D iff all three projections are);
//! 5. drop exact duplicate triangles (same vertex set, either winding); the
//!    first is kept and both ids are reported;
//! 6. remove vertices no longer used by any triangle, keeping input order.
//!
//! [`CleanReport`] lists every action by *input* index;
//! [`CleanMesh::triangle_source`] maps each output triangle to its input.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hash, Hasher};

use hashbrown::HashTable;

use glam::{Vec2, Vec3};
use thiserror::Error;

use crate::scene::{Scene, SceneObject};

/// Marker in [`CleanMesh::vertex_map`] for an input vertex that was removed.
pub const REMOVED: u32 = u32::MAX;

/// Invalid input to [`clean`].
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CleanError {
    /// A vertex has a NaN or infinite coordinate.
    #[error("vertex {vertex} has a non-finite coordinate {position:?}")]
    NonFiniteVertex {
        /// Input vertex index.
        vertex: u32,
        /// Its coordinates.
        position: [f32; 3],
    },
    /// A triangle references a vertex that does not exist.
    #[error("triangle {triangle} corner {corner}: vertex {vertex} out of range ({count} vertices)")]
    IndexOutOfRange {
        /// Input triangle index.
        triangle: u32,
        /// Corner 0..3.
        corner: u8,
        /// The offending index.
        vertex: u32,
        /// Number of vertices.
        count: usize,
    },
}

/// A duplicate triangle: `dropped` has the same vertex set as `kept`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DuplicatePair {
    /// Input index of the kept (first) triangle.
    pub kept: u32,
    /// Input index of the dropped triangle.
    pub dropped: u32,
    /// True when the two have the same orientation, false when opposite.
    pub same_winding: bool,
}

/// Everything [`clean`] did, by input index.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CleanReport {
    /// Number of input vertices.
    pub input_vertices: usize,
    /// Number of input triangles.
    pub input_triangles: usize,
    /// `(dropped, kept)`: input vertex `dropped` had exactly the position of
    /// input vertex `kept` (`kept < dropped`) and was merged into it.
    pub merged_vertices: Vec<(u32, u32)>,
    /// Input triangles dropped because two corners are the same vertex
    /// (after merging).
    pub repeated_vertex_triangles: Vec<u32>,
    /// Input triangles dropped because their three vertices are exactly collinear.
    pub zero_area_triangles: Vec<u32>,
    /// Exact duplicate triangles.
    pub duplicate_triangles: Vec<DuplicatePair>,
    /// Input vertices removed because no kept triangle uses them (merged
    /// vertices are listed in `merged_vertices` only).
    pub unused_vertices: Vec<u32>,
    /// Filled by [`clean_scene`] only: `(dropped, kept)` merged vertex pairs
    /// whose normals or texture coordinates differ (e.g. the corners of a
    /// flat-shaded box, one position with three face normals). The cleaned
    /// scene keeps the attributes of `kept`, so triangles using such a
    /// vertex should be shaded with their geometric normal instead.
    pub attribute_conflicts: Vec<(u32, u32)>,
}

impl CleanReport {
    /// True when the input was already clean.
    pub fn is_noop(&self) -> bool {
        self.merged_vertices.is_empty()
            && self.repeated_vertex_triangles.is_empty()
            && self.zero_area_triangles.is_empty()
            && self.duplicate_triangles.is_empty()
            && self.unused_vertices.is_empty()
    }

    /// Number of dropped triangles.
    pub fn dropped_triangles(&self) -> usize {
        self.repeated_vertex_triangles.len()
            + self.zero_area_triangles.len()
            + self.duplicate_triangles.len()
    }
}

/// Cleaned geometry plus the index maps back to the input.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CleanMesh {
    /// Output vertices (a subset of the input, in input order, unmoved);
    /// empty from [`clean_scene`], whose scene holds them.
    pub vertices: Vec<Vec3>,
    /// Output triangles (input order, winding preserved); empty from
    /// [`clean_scene`], whose scene holds them.
    pub triangles: Vec<[u32; 3]>,
    /// Input vertex → output vertex, or [`REMOVED`] (unused). Merged
    /// vertices map to the output vertex of the one they merged into.
    pub vertex_map: Vec<u32>,
    /// Output vertex → input vertex it was copied from.
    pub vertex_source: Vec<u32>,
    /// Output triangle → input triangle.
    pub triangle_source: Vec<u32>,
    /// What was done.
    pub report: CleanReport,
}

/// Exact 3-D collinearity of three points (all three projections collinear).
pub fn collinear(a: Vec3, b: Vec3, c: Vec3) -> bool {
    let o = |a: (f32, f32), b: (f32, f32), c: (f32, f32)| {
        robust::orient2d(
            robust::Coord { x: a.0, y: a.1 },
            robust::Coord { x: b.0, y: b.1 },
            robust::Coord { x: c.0, y: c.1 },
        )
    };
    o((a.x, a.y), (b.x, b.y), (c.x, c.y)) == 0.0
        && o((a.y, a.z), (b.y, b.z), (c.y, c.z)) == 0.0
        && o((a.z, a.x), (b.z, b.x), (c.z, c.x)) == 0.0
}

/// A multiply-rotate hasher (the "Fx" hash of rustc) for the small integer
/// keys of [`clean`]: several times faster than SipHash, and the keys come
/// from the caller's own scene, so there is no adversary to defend against
/// (a collision-heavy input only costs time, never correctness).
#[derive(Default)]
pub(crate) struct FxHasher(u64);

impl Hasher for FxHasher {
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut b = [0u8; 8];
            b[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(b));
        }
    }
    fn write_u32(&mut self, v: u32) {
        self.write_u64(u64::from(v));
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    fn write_usize(&mut self, v: usize) {
        self.write_u64(v as u64);
    }
    fn finish(&self) -> u64 {
        self.0
    }
}

pub(crate) type FxMap<K, V> = HashMap<K, V, BuildHasherDefault<FxHasher>>;

fn key(p: Vec3) -> [u32; 3] {
    // `+ 0.0` turns -0.0 into +0.0 so both merge.
    [
        (p.x + 0.0).to_bits(),
        (p.y + 0.0).to_bits(),
        (p.z + 0.0).to_bits(),
    ]
}

/// Clean a triangle soup (see the module docs).
pub fn clean(vertices: &[Vec3], triangles: &[[u32; 3]]) -> Result<CleanMesh, CleanError> {
    for (i, v) in vertices.iter().enumerate() {
        if !v.is_finite() {
            return Err(CleanError::NonFiniteVertex {
                vertex: i as u32,
                position: v.to_array(),
            });
        }
    }
    for (t, tri) in triangles.iter().enumerate() {
        for (k, &v) in tri.iter().enumerate() {
            if v as usize >= vertices.len() {
                return Err(CleanError::IndexOutOfRange {
                    triangle: t as u32,
                    corner: k as u8,
                    vertex: v,
                    count: vertices.len(),
                });
            }
        }
    }
    let mut report = CleanReport {
        input_vertices: vertices.len(),
        input_triangles: triangles.len(),
        ..CleanReport::default()
    };

    // 2. merge exactly-equal positions: rep[i] = lowest input index with
    // that position. The tables hold indices only (4 bytes an entry, the
    // keys are looked up in the input): what lets a planner clean a scene
    // of tens of millions of triangles beside the scene itself.
    let mut first: HashTable<u32> = HashTable::with_capacity(vertices.len());
    let mut rep = Vec::with_capacity(vertices.len());
    for (i, v) in vertices.iter().enumerate() {
        let k = key(*v);
        let r = *first
            .entry(
                fx_hash(&k),
                |&j| key(vertices[j as usize]) == k,
                |&j| fx_hash(&key(vertices[j as usize])),
            )
            .or_insert(i as u32)
            .get();
        if r != i as u32 {
            report.merged_vertices.push((i as u32, r));
        }
        rep.push(r);
    }
    drop(first);

    // 3–5. filter triangles: `out.triangles` holds the kept ones with
    // representative (input) vertex indices until step 6 renumbers them.
    let mut out = CleanMesh {
        triangles: Vec::with_capacity(triangles.len()),
        triangle_source: Vec::with_capacity(triangles.len()),
        ..CleanMesh::default()
    };
    // Kept triangles (indices into `out.triangles`) by sorted vertex set.
    let mut seen: HashTable<u32> = HashTable::with_capacity(triangles.len());
    let sorted = |m: [u32; 3]| {
        let mut s = m;
        s.sort_unstable();
        s
    };
    for (t, tri) in triangles.iter().enumerate() {
        let t = t as u32;
        let m = tri.map(|v| rep[v as usize]);
        if m[0] == m[1] || m[1] == m[2] || m[0] == m[2] {
            report.repeated_vertex_triangles.push(t);
            continue;
        }
        let [a, b, c] = m.map(|v| vertices[v as usize]);
        if collinear(a, b, c) {
            report.zero_area_triangles.push(t);
            continue;
        }
        let s = sorted(m);
        let kept = &out.triangles;
        match seen.find(fx_hash(&s), |&k| sorted(kept[k as usize]) == s) {
            Some(&k) => report.duplicate_triangles.push(DuplicatePair {
                kept: out.triangle_source[k as usize],
                dropped: t,
                same_winding: same_cyclic_order(kept[k as usize], m),
            }),
            None => {
                let k = out.triangles.len() as u32;
                seen.insert_unique(fx_hash(&s), k, |&j| {
                    fx_hash(&sorted(out.triangles[j as usize]))
                });
                out.triangles.push(m);
                out.triangle_source.push(t);
            }
        }
    }
    drop(seen);
    out.triangles.shrink_to_fit();
    out.triangle_source.shrink_to_fit();

    // 6. compact vertices (input order).
    let mut used = vec![false; vertices.len()];
    for m in &out.triangles {
        for &v in m {
            used[v as usize] = true;
        }
    }
    let mut out_index = vec![REMOVED; vertices.len()];
    for (i, v) in vertices.iter().enumerate() {
        if rep[i] != i as u32 {
            continue;
        }
        if used[i] {
            out_index[i] = out.vertices.len() as u32;
            out.vertices.push(*v);
            out.vertex_source.push(i as u32);
        } else {
            report.unused_vertices.push(i as u32);
        }
    }
    drop(used);
    out.vertex_map = rep.iter().map(|&r| out_index[r as usize]).collect();
    drop(rep);
    for m in &mut out.triangles {
        *m = m.map(|v| out_index[v as usize]);
    }
    out.report = report;
    Ok(out)
}

/// The hash of a key of [`clean`]'s tables.
fn fx_hash(k: &[u32; 3]) -> u64 {
    let mut h = FxHasher::default();
    k.hash(&mut h);
    h.finish()
}

fn same_cyclic_order(a: [u32; 3], b: [u32; 3]) -> bool {
    let rot = |x: [u32; 3]| [x[1], x[2], x[0]];
    b == a || b == rot(a) || b == rot(rot(a))
}

/// Clean a whole scene: geometry as [`clean`], attributes of each kept
/// vertex copied from its source vertex, object triangle ranges recounted
/// (object vertex ranges become approximate: `first_vertex`/`vertex_count`
/// describe the span of output vertices whose source lay in the object's
/// input range). Merged vertices whose attributes differ are listed in
/// [`CleanReport::attribute_conflicts`]. Returns the cleaned scene and the
/// [`CleanMesh`] maps (without a second copy of the geometry: its
/// `vertices` and `triangles` are empty).
pub fn clean_scene(scene: &Scene) -> Result<(Scene, CleanMesh), CleanError> {
    let mut cm = clean(&scene.vertices, &scene.triangles)?;
    cm.report.attribute_conflicts = cm
        .report
        .merged_vertices
        .iter()
        .copied()
        .filter(|&(d, k)| {
            let (d, k) = (d as usize, k as usize);
            scene.normals.as_ref().is_some_and(|n| n[d] != n[k])
                || scene.uvs.as_ref().is_some_and(|u| u[d] != u[k])
        })
        .collect();
    let pick3 = |src: &Vec<Vec3>| cm.vertex_source.iter().map(|&i| src[i as usize]).collect();
    let pick2 = |src: &Vec<Vec2>| cm.vertex_source.iter().map(|&i| src[i as usize]).collect();
    let mut objects = Vec::with_capacity(scene.objects.len());
    let mut t = 0usize;
    for o in &scene.objects {
        let end = o.first_triangle + o.triangle_count;
        let first = t;
        while t < cm.triangle_source.len() && cm.triangle_source[t] < end {
            t += 1;
        }
        let vfirst = cm.vertex_source.partition_point(|&s| s < o.first_vertex);
        let vend = cm
            .vertex_source
            .partition_point(|&s| s < o.first_vertex + o.vertex_count);
        objects.push(SceneObject {
            name: o.name.clone(),
            first_triangle: first as u32,
            triangle_count: (t - first) as u32,
            first_vertex: vfirst as u32,
            vertex_count: (vend - vfirst) as u32,
            mirrored: o.mirrored,
        });
    }
    let cleaned = Scene {
        name: scene.name.clone(),
        vertices: std::mem::take(&mut cm.vertices),
        triangles: std::mem::take(&mut cm.triangles),
        normals: scene.normals.as_ref().map(pick3),
        uvs: scene.uvs.as_ref().map(pick2),
        objects,
        camera: scene.camera,
        lights: scene.lights.clone(),
    };
    Ok((cleaned, cm))
}
