//! "City": a procedural stand-in for the Rungholt scene of Aman et al.
//! (2022), whose mesh (3,580,928 triangles, a Minecraft-built town from
//! the McGuire Computer Graphics Archive) is not in this repository.
//!
//! What it shares with Rungholt: everything is axis-aligned and lies on
//! integer coordinates; buildings of many footprints and heights stand
//! side by side in blocks separated by streets, on one ground; many
//! triangles share a plane (every street, every roof of one height, every
//! street front), so rays run in the planes of constrained faces; large
//! flat faces are triangulated as exporters do: a plain rectangle as 2
//! triangles, a rectangle whose sides carry its neighbours' corners as a
//! fan from a free corner or a strip between two opposite sides (long thin
//! triangles), a few as a fan around their centre; some walls are cut
//! into floor stripes of 2 to 4 units, so coplanar neighbours meet with
//! triangles of different sizes but no T-junction. What it does not share:
//! Rungholt's texture-level detail (windows, roofs, trees, water), its
//! open, overlapping Minecraft geometry and its layout. The city is one
//! closed, outward-oriented surface whose triangles meet only in shared
//! vertices and edges (a valid constrained-Delaunay input with nothing for
//! the builder to clean or resolve).
//!
//! ## Layout
//!
//! Rows of blocks separated by streets. A block is cut into columns along
//! x and each column into lots along z (no four lots meet at one point,
//! so the surface is a manifold); each lot is a building of its own
//! height, some as high as a neighbour (one roof plane across both), a
//! few towers. Touching buildings are one solid: a wall between two lots
//! exists only where one is taller (from the lower roof to the higher),
//! and no two faces overlap. The ground is a slab 4 units deep whose top
//! is the street network: strips between the block rows and between the
//! blocks of a row, each a strip of triangles between the block outlines
//! it runs along. Blocks are added until the count is closest to the one
//! asked for; the last is narrowed to fit.

mod faces;
mod lots;

use glam::{DVec3, Vec3};
use tet_core::scene::PointLight;
use tet_core::synthetic::SplitMix64;

use crate::scene::{Scene, SceneObject, orbit_camera};
use faces::{BlockMesh, chain};
use lots::{block_rects, lots, pick};

/// Triangles of the paper's Rungholt (Aman et al. 2022, Table 2): the
/// size of the `city` scene without a count.
pub const RUNGHOLT_TRIANGLES: u64 = 3_580_928;

/// The smallest city: one small block and its ground. [`city`] raises
/// smaller counts to it.
pub const MIN_CITY_TRIANGLES: u64 = 1_000;

/// Depth of the ground slab (its top is `y = 0`).
const GROUND_DEPTH: i32 = 4;
/// Block widths (along x).
const BLOCK_WIDTH: (i32, i32) = (12, 32);
/// Depths of a row of blocks (along z).
const ROW_DEPTH: (i32, i32) = (12, 28);
/// Streets between the blocks of a row.
const STREET: (i32, i32) = (3, 7);
/// Streets between rows and around the city.
const AVENUE: (i32, i32) = (4, 8);
/// Triangles a block adds on average (with its share of the ground), for
/// sizing the city before it is built.
const BLOCK_TRIANGLES: f64 = 280.0;

/// The city of about `triangles` triangles (at least
/// [`MIN_CITY_TRIANGLES`]), one object, with an oblique camera over it (the
/// elevation and azimuth of the paper's "Rungholt Default" view, the
/// distance fitted to the city's size) and a point light above one side.
pub fn city(triangles: u64) -> Scene {
    let target = triangles.max(MIN_CITY_TRIANGLES);
    let mut builder = CityBuilder::new(target);
    builder.fill();
    builder.finish()
}

/// A block's outline on the ground, side by side: `(coordinate along the
/// side, vertex)` from corner to corner, increasing.
#[derive(Clone, Debug, Default)]
struct Outline {
    /// `z = z.0`, along x.
    south: Vec<(i32, u32)>,
    /// `z = z.1`, along x.
    north: Vec<(i32, u32)>,
    /// `x = x.0`, along z.
    west: Vec<(i32, u32)>,
    /// `x = x.1`, along z.
    east: Vec<(i32, u32)>,
}

impl Outline {
    fn len(&self) -> u64 {
        (self.south.len() + self.north.len() + self.west.len() + self.east.len()) as u64
    }
}

impl BlockMesh {
    /// Builds the block `x × z` of random stream `seed`.
    fn build(&mut self, seed: u64, x: (i32, i32), z: (i32, i32)) {
        let mut rng = SplitMix64(seed);
        let columns = lots(&mut rng, x, z);
        let mut rects = std::mem::take(&mut self.rects);
        rects.clear();
        block_rects(&columns, x, z, &mut rects);
        self.corners.build(&rects);
        self.centres.clear();
        self.triangles.clear();
        for r in &rects {
            self.triangulate(r);
        }
        self.rects = rects;
    }

    /// The block's outline at `y = 0` in local vertex numbers.
    fn outline(&self, x: (i32, i32), z: (i32, i32)) -> Outline {
        let side = |axis: usize, from: [i32; 3], to: i32| -> Vec<(i32, u32)> {
            let inner = self.corners.between(axis, from, to);
            chain(from[axis], &inner, to)
                .map(|t| {
                    let mut p = from;
                    p[axis] = t;
                    (t, self.corners.index(p))
                })
                .collect()
        };
        Outline {
            south: side(0, [x.0, 0, z.0], x.1),
            north: side(0, [x.0, 0, z.1], x.1),
            west: side(2, [x.0, 0, z.0], z.1),
            east: side(2, [x.1, 0, z.0], z.1),
        }
    }

    fn vertex_count(&self) -> usize {
        self.corners.points.len() + self.centres.len()
    }
}

/// A row of blocks between `z.0` and `z.1`: their outlines (global
/// vertex numbers), west to east.
struct Row {
    z: (i32, i32),
    blocks: Vec<Outline>,
}

/// The city as it is assembled: the blocks' surfaces, then the ground.
struct CityBuilder {
    target: u64,
    rng: SplitMix64,
    /// The city spans `0..width` along x.
    width: i32,
    vertices: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    rows: Vec<Row>,
    scratch: BlockMesh,
}

/// Random stream of block `index`.
fn block_seed(index: u64) -> u64 {
    0xC17E_5EED ^ index.wrapping_mul(0x9E37_79B9_7F4A_7C15)
}

impl CityBuilder {
    fn new(target: u64) -> CityBuilder {
        let blocks = target as f64 / BLOCK_TRIANGLES;
        let mean = |r: (i32, i32)| f64::from(r.0 + r.1) / 2.0;
        let pitch_x = mean(BLOCK_WIDTH) + mean(STREET);
        let pitch_z = mean(ROW_DEPTH) + mean(AVENUE);
        // Square: columns · pitch_x = rows · pitch_z, columns · rows = blocks.
        let columns = (blocks * pitch_z / pitch_x).sqrt().max(1.0);
        let width = (columns * pitch_x).round() as i32 + 2 * AVENUE.1 + BLOCK_WIDTH.0;
        CityBuilder {
            target,
            rng: SplitMix64(0x5EED_C17E),
            width,
            vertices: Vec::new(),
            triangles: Vec::new(),
            rows: Vec::new(),
            scratch: BlockMesh::default(),
        }
    }

    /// Triangles block `x × z` of stream `seed` adds, ground included
    /// (built into the scratch mesh).
    fn try_block(&mut self, seed: u64, x: (i32, i32), z: (i32, i32)) -> u64 {
        self.scratch.build(seed, x, z);
        self.scratch.triangles.len() as u64 + self.scratch.outline(x, z).len() - 2
    }

    /// Appends the scratch block (just built at `x × z`) to the city.
    fn commit(&mut self, x: (i32, i32), z: (i32, i32)) {
        let base = self.vertices.len() as u32;
        let s = &self.scratch;
        self.vertices.extend(
            s.corners
                .points
                .iter()
                .map(|p| Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32)),
        );
        self.vertices.extend_from_slice(&s.centres);
        self.triangles
            .extend(s.triangles.iter().map(|t| t.map(|v| v + base)));
        let mut outline = s.outline(x, z);
        for side in [
            &mut outline.south,
            &mut outline.north,
            &mut outline.west,
            &mut outline.east,
        ] {
            for e in side.iter_mut() {
                e.1 += base;
            }
        }
        debug_assert_eq!(self.vertices.len(), base as usize + s.vertex_count());
        if let Some(row) = self.rows.last_mut() {
            row.blocks.push(outline);
        }
    }

    /// Adds blocks row by row until the count (ground included) is the
    /// nearest to the target; the last block is narrowed to fit.
    fn fill(&mut self) {
        // The slab's sides and bottom and the outer strips: 12, and 8 per
        // row (see `ground`).
        let mut total = 12u64;
        let mut index = 0u64;
        let margin = pick(&mut self.rng, AVENUE);
        let mut cursor = margin;
        loop {
            let room = self.width - AVENUE.0 - cursor;
            if self.rows.is_empty() || room < BLOCK_WIDTH.0 {
                let z0 = self
                    .rows
                    .last()
                    .map_or(margin, |r| r.z.1 + pick(&mut self.rng, AVENUE));
                let depth = pick(&mut self.rng, ROW_DEPTH);
                self.rows.push(Row {
                    z: (z0, z0 + depth),
                    blocks: Vec::new(),
                });
                cursor = margin;
                continue;
            }
            let row_cost = if self.rows.last().is_some_and(|r| r.blocks.is_empty()) {
                8
            } else {
                0
            };
            let z = self.rows.last().map_or((0, 0), |r| r.z);
            let w = pick(&mut self.rng, BLOCK_WIDTH).min(room);
            let seed = block_seed(index);
            let added = self.try_block(seed, (cursor, cursor + w), z) + row_cost;
            if total + added >= self.target {
                // The nearest of: stopping here (once there is a block),
                // or this block at any width up to `w`.
                let target = self.target;
                let miss = |n: u64| n.abs_diff(target);
                let mut best = (if index > 0 { miss(total) } else { u64::MAX }, 0);
                for width in BLOCK_WIDTH.0..=w {
                    let n = total + self.try_block(seed, (cursor, cursor + width), z) + row_cost;
                    if miss(n) < best.0 {
                        best = (miss(n), width);
                    }
                }
                if best.1 > 0 {
                    let x = (cursor, cursor + best.1);
                    self.try_block(seed, x, z);
                    self.commit(x, z);
                }
                break;
            }
            self.commit((cursor, cursor + w), z);
            total += added;
            index += 1;
            cursor += w + pick(&mut self.rng, STREET);
        }
        self.rows.retain(|r| !r.blocks.is_empty());
    }
}

impl CityBuilder {
    /// Vertex at `p`, new unless it is in `known`.
    fn ground_vertex(&mut self, known: &mut Vec<([i32; 3], u32)>, p: [i32; 3]) -> u32 {
        if let Some(&(_, v)) = known.iter().find(|k| k.0 == p) {
            return v;
        }
        let v = self.vertices.len() as u32;
        self.vertices
            .push(Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32));
        known.push((p, v));
        v
    }

    /// The strip between chains `a` and `b` on two parallel lines of one
    /// plane (see [`BlockMesh::ladder`]), facing `out` along `axis`.
    fn ladder(&mut self, a: &[(i32, u32)], b: &[(i32, u32)], axis: usize, out: f64) {
        let (mut i, mut j) = (0, 0);
        while i + 1 < a.len() || j + 1 < b.len() {
            let t = if i + 1 < a.len() && (j + 1 == b.len() || a[i + 1].0 <= b[j + 1].0) {
                i += 1;
                [a[i - 1].1, a[i].1, b[j].1]
            } else {
                j += 1;
                [a[i].1, b[j].1, b[j - 1].1]
            };
            let p = t.map(|v| self.vertices[v as usize].as_dvec3());
            let n = (p[1] - p[0]).cross(p[2] - p[0])[axis];
            self.triangles
                .push(if n * out > 0.0 { t } else { [t[0], t[2], t[1]] });
        }
    }

    /// The ground: a slab from `y = -GROUND_DEPTH` to 0 whose top is the
    /// streets around the blocks. Its triangles: per row 8 and per block
    /// its outline's vertices less 2, and 12 (the count `fill` plans with).
    fn ground(&mut self, depth: i32) {
        let (w, t) = (self.width, -GROUND_DEPTH);
        let rows = std::mem::take(&mut self.rows);
        // The border vertices at y = 0 (x = 0 and x = w, at each row edge)
        // and the slab's bottom corners: few, found by a linear search.
        let mut known = Vec::new();
        // Strips between rows (and before the first and after the last).
        for k in 0..=rows.len() {
            let za = if k == 0 { 0 } else { rows[k - 1].z.1 };
            let zb = rows.get(k).map_or(depth, |r| r.z.0);
            let mut lower = vec![(0, self.ground_vertex(&mut known, [0, 0, za]))];
            if k > 0 {
                for b in &rows[k - 1].blocks {
                    lower.extend_from_slice(&b.north);
                }
            }
            lower.push((w, self.ground_vertex(&mut known, [w, 0, za])));
            let mut upper = vec![(0, self.ground_vertex(&mut known, [0, 0, zb]))];
            if let Some(r) = rows.get(k) {
                for b in &r.blocks {
                    upper.extend_from_slice(&b.south);
                }
            }
            upper.push((w, self.ground_vertex(&mut known, [w, 0, zb])));
            self.ladder(&lower, &upper, 1, 1.0);
        }
        // Streets between the blocks of a row.
        for r in &rows {
            let west = vec![
                (r.z.0, self.ground_vertex(&mut known, [0, 0, r.z.0])),
                (r.z.1, self.ground_vertex(&mut known, [0, 0, r.z.1])),
            ];
            let east = vec![
                (r.z.0, self.ground_vertex(&mut known, [w, 0, r.z.0])),
                (r.z.1, self.ground_vertex(&mut known, [w, 0, r.z.1])),
            ];
            let mut left = &west;
            for b in &r.blocks {
                self.ladder(left, &b.west, 1, 1.0);
                left = &b.east;
            }
            self.ladder(left, &east, 1, 1.0);
        }
        // The slab's sides and bottom.
        let mut edge_z = vec![0];
        for r in &rows {
            edge_z.extend([r.z.0, r.z.1]);
        }
        edge_z.push(depth);
        for (x, out) in [(0, -1.0), (w, 1.0)] {
            let top: Vec<(i32, u32)> = edge_z
                .iter()
                .map(|&z| (z, self.ground_vertex(&mut known, [x, 0, z])))
                .collect();
            let bottom = [
                (0, self.ground_vertex(&mut known, [x, t, 0])),
                (depth, self.ground_vertex(&mut known, [x, t, depth])),
            ];
            self.ladder(&top, &bottom, 0, out);
        }
        for (z, out) in [(0, -1.0), (depth, 1.0)] {
            let top = [
                (0, self.ground_vertex(&mut known, [0, 0, z])),
                (w, self.ground_vertex(&mut known, [w, 0, z])),
            ];
            let bottom = [
                (0, self.ground_vertex(&mut known, [0, t, z])),
                (w, self.ground_vertex(&mut known, [w, t, z])),
            ];
            self.ladder(&top, &bottom, 2, out);
        }
        let near = [
            (0, self.ground_vertex(&mut known, [0, t, 0])),
            (w, self.ground_vertex(&mut known, [w, t, 0])),
        ];
        let far = [
            (0, self.ground_vertex(&mut known, [0, t, depth])),
            (w, self.ground_vertex(&mut known, [w, t, depth])),
        ];
        self.ladder(&near, &far, 1, -1.0);
        self.rows = rows;
    }

    /// The ground, the city centred on the origin, the camera and light.
    fn finish(mut self) -> Scene {
        let depth = self.rows.last().map_or(0, |r| r.z.1) + pick(&mut self.rng, AVENUE);
        self.ground(depth);
        let shift = Vec3::new(-(self.width / 2) as f32, 0.0, -(depth / 2) as f32);
        for v in &mut self.vertices {
            *v += shift;
        }
        let radius = 0.5 * f64::from(self.width).hypot(f64::from(depth));
        // "Rungholt Default" (scenes.json): orbit (0.41, 0.4608) rad; its
        // light sits at 0.8 of the camera's distance, to the right.
        let distance = 1.6 * radius;
        let camera = orbit_camera(0.41, 0.4608, distance, DVec3::ZERO);
        let light = DVec3::new(0.72, 0.341, -0.046) * distance;
        let triangles = self.triangles.len();
        Scene {
            name: format!("Rungholt (stand-in: city), {triangles} triangles"),
            objects: vec![SceneObject {
                name: "city".into(),
                first_triangle: 0,
                triangle_count: triangles as u32,
                first_vertex: 0,
                vertex_count: self.vertices.len() as u32,
                mirrored: false,
            }],
            vertices: self.vertices,
            triangles: self.triangles,
            normals: None,
            uvs: None,
            camera: Some(camera),
            lights: vec![PointLight {
                position: light.as_vec3(),
                color: Vec3::ONE,
                intensity: 1.0,
            }],
        }
    }
}
