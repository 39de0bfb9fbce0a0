//! Valid meshes made without an external mesher: a jittered Kuhn
//! (Freudenthal) subdivision of an `nx × ny × nz` grid of unit cubes into six
//! tets each, with chosen faces marked constrained. Used by the property tests
//! of every crate, by the fuzzers and by micro-benchmarks.

use glam::{Vec2, Vec3};

use crate::mesh::{FACE_VERTICES, TetMesh};
use crate::predicates::orient3d_f32;

/// Parameters of [`kuhn_grid`].
#[derive(Clone, Debug, PartialEq)]
pub struct GridSpec {
    /// Number of cubes along x, y, z (each ≥ 1).
    pub cells: [u32; 3],
    /// Maximum displacement of interior grid points, as a fraction of the cell
    /// size per axis; clamped to 0.15 so that no tet can invert.
    pub jitter: f32,
    /// Probability that any one face (interior or boundary) is marked constrained.
    pub constrained_fraction: f64,
    /// Optional closed shell of constrained faces: the surface of the box
    /// between these two grid corners (inclusive lattice coordinates).
    pub shell: Option<([u32; 3], [u32; 3])>,
    /// Scale applied to the lattice coordinates.
    pub scale: f32,
    /// Translation added after scaling.
    pub offset: Vec3,
    /// Random seed.
    pub seed: u64,
}

impl Default for GridSpec {
    fn default() -> Self {
        GridSpec {
            cells: [3, 3, 3],
            jitter: 0.1,
            constrained_fraction: 0.0,
            shell: None,
            scale: 1.0,
            offset: Vec3::ZERO,
            seed: 1,
        }
    }
}

/// SplitMix64: a tiny deterministic generator, enough for test meshes.
#[derive(Clone, Debug)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `[lo, hi)`.
    pub fn range_f32(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next_f64() as f32
    }
}

/// The six Kuhn tets of the unit cube: paths from corner 000 to 111 along the
/// axes in each permutation order.
const PERMUTATIONS: [[usize; 3]; 6] = [
    [0, 1, 2],
    [0, 2, 1],
    [1, 0, 2],
    [1, 2, 0],
    [2, 0, 1],
    [2, 1, 0],
];

/// Builds a valid jittered Kuhn grid mesh (see [`GridSpec`]).
///
/// # Panics
/// If a cell count is zero, the grid has more than 2³¹ tets, or `scale` and
/// `offset` collapse the lattice in f32 (flat tets) — never loops.
pub fn kuhn_grid(spec: &GridSpec) -> TetMesh {
    let [nx, ny, nz] = spec.cells;
    assert!(
        nx > 0 && ny > 0 && nz > 0,
        "grid needs at least one cell per axis"
    );
    let dims = [nx + 1, ny + 1, nz + 1];
    let index = |c: [u32; 3]| c[0] + dims[0] * (c[1] + dims[1] * c[2]);
    let mut lattice = Vec::with_capacity((dims[0] * dims[1] * dims[2]) as usize);
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                lattice.push([i, j, k]);
            }
        }
    }
    let mut tets = Vec::with_capacity((nx * ny * nz * 6) as usize);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                for perm in PERMUTATIONS {
                    let mut c = [i, j, k];
                    let mut tet = [index(c), 0, 0, 0];
                    for (step, &axis) in perm.iter().enumerate() {
                        c[axis] += 1;
                        tet[step + 1] = index(c);
                    }
                    tets.push(tet);
                }
            }
        }
    }
    let unjittered: Vec<Vec3> = lattice
        .iter()
        .map(|c| Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32))
        .collect();
    for tet in &mut tets {
        let p = tet.map(|v| unjittered[v as usize]);
        if orient3d_f32(p[0], p[1], p[2], p[3]) < 0.0 {
            tet.swap(2, 3);
        }
    }

    let mut rng = SplitMix64(spec.seed);
    let mut jitter = spec.jitter.clamp(0.0, 0.15);
    let points = loop {
        let points: Vec<Vec3> = lattice
            .iter()
            .map(|c| {
                let interior = (0..3).all(|a| c[a] > 0 && c[a] < dims[a] - 1);
                let mut p = Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32);
                if interior && jitter > 0.0 {
                    p += Vec3::new(
                        rng.range_f32(-jitter, jitter),
                        rng.range_f32(-jitter, jitter),
                        rng.range_f32(-jitter, jitter),
                    );
                }
                p * spec.scale + spec.offset
            })
            .collect();
        let all_positive = tets.iter().all(|t| {
            let p = t.map(|v| points[v as usize]);
            orient3d_f32(p[0], p[1], p[2], p[3]) > 0.0
        });
        if all_positive {
            break points;
        }
        // Rounding after scaling/offset can flatten a tet: retry with less
        // jitter; without jitter there is nothing left to try.
        assert!(
            jitter > 0.0,
            "kuhn_grid: the lattice collapses in f32 at scale {} and offset {} (flat tets)",
            spec.scale,
            spec.offset
        );
        jitter *= 0.5;
        if jitter < 1e-6 {
            jitter = 0.0;
        }
    };

    // Choose constrained faces, each unique face once.
    let mut triangles: Vec<([u32; 3], u32)> = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for tet in &tets {
        for s in FACE_VERTICES {
            let mut f = [tet[s[0]], tet[s[1]], tet[s[2]]];
            if !seen.insert(crate::mesh::face_key(f)) {
                continue;
            }
            let on_shell = spec.shell.is_some_and(|(lo, hi)| {
                let c = f.map(|v| lattice[v as usize]);
                (0..3).any(|a| {
                    let plane = c[0][a];
                    (plane == lo[a] || plane == hi[a])
                        && c.iter().all(|p| p[a] == plane)
                        && c.iter()
                            .all(|p| (0..3).all(|b| p[b] >= lo[b] && p[b] <= hi[b]))
                })
            });
            if on_shell || rng.next_f64() < spec.constrained_fraction {
                if rng.next_u64() & 1 == 1 {
                    f.swap(1, 2);
                }
                triangles.push((f, triangles.len() as u32));
            }
        }
    }
    let count = triangles.len() as u32;
    TetMesh::assemble(points, tets, &triangles, count).expect("Kuhn grid is conforming")
}

/// `mesh` with random attributes: bit 0 of `which` adds per-point normals,
/// bit 1 texture coordinates, bit 2 per-triangle materials (the mesh
/// format's flag bits). Values include `-0.0` and subnormal-adjacent
/// `1e-30`, so bit-exact round trips are tested, not just `==`.
pub fn with_attributes(mut mesh: TetMesh, which: u8, seed: u64) -> TetMesh {
    let mut rng = SplitMix64(seed);
    let n = mesh.points.len();
    if which & 1 != 0 {
        mesh.attributes.normals = Some(
            (0..n)
                .map(|_| Vec3::new(rng.range_f32(-1.0, 1.0), rng.range_f32(-1.0, 1.0), -0.0))
                .collect(),
        );
    }
    if which & 2 != 0 {
        mesh.attributes.uvs = Some(
            (0..n)
                .map(|_| Vec2::new(rng.range_f32(0.0, 1.0), 1e-30))
                .collect(),
        );
    }
    if which & 4 != 0 {
        mesh.attributes.materials = Some(
            (0..mesh.triangle_count)
                .map(|_| rng.next_u64() as u32)
                .collect(),
        );
    }
    mesh
}

/// `grid` (a mesh without constrained faces, e.g. an unjittered
/// [`kuhn_grid`]) with every face whose three vertex positions satisfy `on`
/// made a constrained face, one scene triangle id per face (in the order
/// met). With `facing = Some(n)` each triangle is wound so that its normal
/// has a non-negative dot product with `n`; with `None` it keeps the
/// outward order of the first tet met. For tests that need constrained
/// planes, slabs or boxes at exact coordinates.
///
/// # Panics
/// If the marked faces do not form a valid constrained-face table (the
/// caller built a grid with constrained faces already).
pub fn constrain_faces(
    grid: TetMesh,
    on: impl Fn([Vec3; 3]) -> bool,
    facing: Option<Vec3>,
) -> TetMesh {
    let mut tris = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for tet in &grid.tets {
        for s in FACE_VERTICES {
            let f = [tet[s[0]], tet[s[1]], tet[s[2]]];
            let v = f.map(|i| grid.points[i as usize]);
            if on(v) && seen.insert(crate::mesh::face_key(f)) {
                let flip = facing.is_some_and(|n| (v[1] - v[0]).cross(v[2] - v[0]).dot(n) < 0.0);
                let f = if flip { [f[0], f[2], f[1]] } else { f };
                tris.push((f, tris.len() as u32));
            }
        }
    }
    let n = tris.len() as u32;
    let m = TetMesh::assemble(grid.points, grid.tets, &tris, n)
        .expect("marked faces of a grid form a valid table");
    m.validate()
        .expect("marked faces of a grid form a valid mesh");
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_has_expected_counts_and_validates() {
        let m = kuhn_grid(&GridSpec {
            cells: [2, 3, 4],
            constrained_fraction: 0.2,
            ..Default::default()
        });
        assert_eq!(m.tets.len(), 2 * 3 * 4 * 6);
        assert_eq!(m.points.len(), 3 * 4 * 5);
        m.validate().unwrap();
        assert!(!m.constrained.is_empty());
        // Boundary faces: 2 triangles per unit square of the box surface.
        let boundary = m
            .neighbors
            .iter()
            .flatten()
            .filter(|l| l.is_boundary())
            .count();
        let one_sided = m
            .constrained
            .iter()
            .filter(|c| !(c.front.exists() && c.back.exists()))
            .count();
        assert_eq!(boundary + one_sided, 2 * 2 * (2 * 3 + 3 * 4 + 2 * 4));
    }

    #[test]
    #[should_panic(expected = "collapses in f32")]
    fn collapsed_lattice_panics_instead_of_looping() {
        kuhn_grid(&GridSpec {
            cells: [1, 1, 1],
            scale: 1e-3,
            offset: Vec3::splat(1e5),
            ..Default::default()
        });
    }

    #[test]
    fn shell_is_closed() {
        let m = kuhn_grid(&GridSpec {
            cells: [4, 4, 4],
            shell: Some(([1, 1, 1], [3, 3, 3])),
            ..Default::default()
        });
        m.validate().unwrap();
        // Surface of a 2×2×2 box: 6 sides × 4 squares × 2 triangles.
        assert_eq!(m.constrained.len(), 48);
        assert!(
            m.constrained
                .iter()
                .all(|c| c.front.exists() && c.back.exists())
        );
    }
}
