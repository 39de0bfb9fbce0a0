//! Stage 6, reordering ([`Reorder::Hilbert`](super::Reorder::Hilbert)):
//! points and tets sorted along a Hilbert curve (Aman et al. 2022, §5).
//!
//! The sort is tet-core's ([`tet_core::reorder::hilbert_reorder`]): the same
//! keys ([`Quantizer::key`], [`reorder::tet_key`],
//! [`reorder::constrained_key`]), the same order (`(key, old index)` pairs
//! sorted: any correct sort of those distinct pairs gives the same order)
//! and the same renumbering ([`Renumbering`]). This stage only runs those
//! pieces in parallel, with one gather per array, so the permutations and
//! the mesh are exactly tet-core's (tested).

use glam::Vec3;
use rayon::prelude::*;
use tet_core::TetMesh;
use tet_core::hilbert::Quantizer;
use tet_core::reorder::{self, PermutationError, Renumbering, Reordering};

/// Sorts `(key, index)` pairs in parallel and returns the indices: the
/// order of [`reorder::order_by_key`].
fn order_by_key<K: Ord + Copy + Send>(keys: Vec<K>) -> Vec<u32> {
    let mut v: Vec<(K, u32)> = keys
        .into_par_iter()
        .enumerate()
        .map(|(i, k)| (k, i as u32))
        .collect();
    v.par_sort_unstable();
    v.into_par_iter().map(|(_, i)| i).collect()
}

/// [`tet_core::reorder::hilbert_reorder`], in parallel: the same
/// permutations and the same resulting mesh. Errors only for an invalid
/// mesh (link rows and tets differ in length); the mesh is then untouched.
pub(super) fn hilbert_reorder(mesh: &mut TetMesh) -> Result<Reordering, PermutationError> {
    if mesh.neighbors.len() != mesh.tets.len() {
        return Err(PermutationError::Length {
            what: "neighbour",
            actual: mesh.neighbors.len(),
            expected: mesh.tets.len(),
        });
    }
    let q = Quantizer::from_points(&mesh.points);
    let m = &*mesh;
    let (points, tets) = rayon::join(
        || order_by_key(m.points.par_iter().map(|&p| q.key(p)).collect()),
        || {
            order_by_key(
                (0..m.tets.len())
                    .into_par_iter()
                    .map(|t| reorder::tet_key(m, &q, t))
                    .collect(),
            )
        },
    );
    let new_tet = reorder::invert_order("tet", &tets, m.tets.len())?;
    let constrained = order_by_key(
        m.constrained
            .iter()
            .map(|cf| reorder::constrained_key(cf, &new_tet))
            .collect(),
    );
    let r = Reordering {
        points,
        tets,
        constrained,
    };
    let map = Renumbering::new(m, &r)?;
    let gather =
        |v: &[Vec3]| -> Vec<Vec3> { r.points.par_iter().map(|&o| v[o as usize]).collect() };
    let points = gather(&m.points);
    let normals = m
        .attributes
        .normals
        .as_deref()
        .filter(|n| n.len() == r.points.len())
        .map(gather);
    let uvs = m
        .attributes
        .uvs
        .as_deref()
        .filter(|uv| uv.len() == r.points.len())
        .map(|uv| r.points.par_iter().map(|&o| uv[o as usize]).collect());
    let (tets, neighbors) = rayon::join(
        || {
            r.tets
                .par_iter()
                .map(|&o| map.tet(m.tets[o as usize]))
                .collect()
        },
        || {
            r.tets
                .par_iter()
                .map(|&o| map.links(m.neighbors[o as usize]))
                .collect()
        },
    );
    let constrained = r
        .constrained
        .iter()
        .map(|&o| map.constrained_face(m.constrained[o as usize]))
        .collect();
    mesh.points = points;
    if let Some(n) = normals {
        mesh.attributes.normals = Some(n);
    }
    if let Some(uv) = uvs {
        mesh.attributes.uvs = Some(uv);
    }
    mesh.tets = tets;
    mesh.neighbors = neighbors;
    mesh.constrained = constrained;
    Ok(r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::validate::tests::grid;
    use tet_core::synthetic::SplitMix64;

    #[test]
    fn parallel_hilbert_reorder_equals_tet_core() {
        for seed in 0..4 {
            let mut a = grid(seed);
            // Scramble TetGen-like orders first so the sort has work to do.
            let mut rng = SplitMix64(seed);
            let mut order: Vec<u32> = (0..a.tets.len() as u32).collect();
            for i in (1..order.len()).rev() {
                order.swap(i, (rng.next_u64() % (i as u64 + 1)) as usize);
            }
            tet_core::reorder::apply_tet_permutation(&mut a, &order).unwrap();
            let mut b = a.clone();
            let ra = tet_core::reorder::hilbert_reorder(&mut a).unwrap();
            let rb = hilbert_reorder(&mut b).unwrap();
            assert_eq!(ra, rb);
            assert_eq!(a, b);
            b.validate().unwrap();
        }
    }
}
