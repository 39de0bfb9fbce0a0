// Small valid meshes from fuzz bytes, shared by the `xor_codecs` and
// `traversal` target bodies: a jittered Kuhn grid (`tet_core::synthetic`)
// with random constrained faces or a closed shell, then relabelled — vertex
// ids permuted (with unused points mixed in), tets shuffled, each tet's slots
// rotated by an even permutation — and reassembled with `TetMesh::assemble`,
// so ids, tet order and slot order are arbitrary while the mesh stays valid.

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};

use super::input::Bytes;

/// (scale, offset) pairs whose lattice f32 can resolve (`kuhn_grid` loops
/// forever when it cannot, as fuzzing found).
const PLACEMENTS: [(f32, [f32; 3]); 6] = [
    (1.0, [0.0, 0.0, 0.0]),
    (1e-3, [0.0, 0.0, 0.0]),
    (1e3, [0.0, 0.0, 0.0]),
    (0.37, [0.1, -0.2, 0.3]),
    (1.0, [1e4, -1e4, 1e4]),
    (1e3, [1e5, 1e5, -1e5]),
];

/// The valid mesh described by the front of `b` (see the module comment).
pub fn mesh_from(b: &mut Bytes) -> TetMesh {
    let cells = [1 + b.below(2), 1 + b.below(2), 1 + b.below(2)];
    let jitter = f32::from(b.u8()) / 255.0 * 0.15;
    let constrained_fraction = f64::from(b.u8()) / 255.0;
    let shell = if b.u8() & 1 == 1 {
        let lo = cells.map(|c| b.below(c + 1));
        let mut hi = [0; 3];
        for a in 0..3 {
            hi[a] = lo[a] + b.below(cells[a] - lo[a] + 1);
        }
        Some((lo, hi))
    } else {
        None
    };
    let (scale, offset) = b.pick(&PLACEMENTS);
    let grid = kuhn_grid(&GridSpec {
        cells,
        jitter,
        constrained_fraction,
        shell,
        scale,
        offset: Vec3::from_array(offset),
        seed: b.u64(),
    });
    relabel(&grid, b.u64(), b.below(8) as usize)
}

/// The 12 even permutations of four slots (they keep a tet positive).
fn even_permutations() -> Vec<[usize; 4]> {
    let mut out = Vec::new();
    for a in 0..4 {
        for b in 0..4 {
            for c in 0..4 {
                for d in 0..4 {
                    let p = [a, b, c, d];
                    let distinct = (0..4).all(|i| (0..4).all(|j| i == j || p[i] != p[j]));
                    let inversions = (0..4)
                        .flat_map(|i| (i + 1..4).map(move |j| (i, j)))
                        .filter(|&(i, j)| p[i] > p[j])
                        .count();
                    if distinct && inversions % 2 == 0 {
                        out.push(p);
                    }
                }
            }
        }
    }
    out
}

/// `mesh` with vertex ids permuted (plus `extra` unused points), tets
/// shuffled and slots evenly permuted, reassembled from scratch.
pub fn relabel(mesh: &TetMesh, seed: u64, extra: usize) -> TetMesh {
    let mut rng = SplitMix64(seed);
    let n = mesh.points.len() + extra;
    let mut perm: Vec<u32> = (0..n as u32).collect();
    for i in (1..n).rev() {
        perm.swap(i, (rng.next_u64() % (i as u64 + 1)) as usize);
    }
    let mut points = vec![Vec3::ZERO; n];
    for (old, &p) in mesh.points.iter().enumerate() {
        points[perm[old] as usize] = p;
    }
    for &new in &perm[mesh.points.len()..] {
        points[new as usize] = Vec3::new(
            rng.range_f32(-1.0, 1.0),
            rng.range_f32(-1.0, 1.0),
            rng.range_f32(-1.0, 1.0),
        );
    }
    let evens = even_permutations();
    let mut tets: Vec<[u32; 4]> = mesh
        .tets
        .iter()
        .map(|t| {
            let p = evens[(rng.next_u64() % 12) as usize];
            p.map(|s| perm[t[s] as usize])
        })
        .collect();
    for i in (1..tets.len()).rev() {
        tets.swap(i, (rng.next_u64() % (i as u64 + 1)) as usize);
    }
    let triangles: Vec<([u32; 3], u32)> = mesh
        .constrained
        .iter()
        .map(|c| (c.vertices.map(|v| perm[v as usize]), c.triangle))
        .collect();
    let out = TetMesh::assemble(points, tets, &triangles, mesh.triangle_count)
        .unwrap_or_else(|e| panic!("relabelled valid mesh does not assemble: {e}"));
    if let Err(e) = out.validate() {
        panic!("relabelled valid mesh does not validate: {e}");
    }
    out
}
