//! Stage 7, validation ([`Validation`]): the result always passes
//! [`TetMesh::validate`]; the pipeline never returns a mesh that does not.
//!
//! The rules are tet-core's, the one validator of the workspace. By
//! default ([`Validation::Construction`]) this stage runs
//! [`TetMesh::validate_construction`]'s per-element checks in parallel:
//! every invariant of `validate` except the one the rounding stage has
//! already decided exactly (every tet positively oriented on the stored f32
//! points), in linear time. [`Validation::Full`] runs [`TetMesh::validate`].

use rayon::prelude::*;
use tet_core::{MeshError, TetMesh};

use super::options::Validation;

/// Checks `mesh` as `validation` asks.
pub(super) fn validate(mesh: &TetMesh, validation: Validation) -> Result<(), MeshError> {
    match validation {
        Validation::Construction => check_construction(mesh),
        Validation::Full => mesh.validate(),
    }
}

/// [`TetMesh::validate_construction`], in parallel: the same checks, and
/// an error exactly when it errs (maybe naming another element).
pub(super) fn check_construction(m: &TetMesh) -> Result<(), MeshError> {
    m.check_sizes()?;
    (0..m.points.len())
        .into_par_iter()
        .with_min_len(4096)
        .try_for_each(|i| m.check_point(i))?;
    (0..m.tets.len() as u32)
        .into_par_iter()
        .with_min_len(4096)
        .try_for_each(|t| m.check_tet_vertices(t))?;
    let (tet_links, pairs) = (0..m.tets.len() as u32)
        .into_par_iter()
        .with_min_len(4096)
        .map(|t| m.check_links_upward(t))
        .try_reduce(|| (0, 0), |a, b| Ok((a.0 + b.0, a.1 + b.1)))?;
    if tet_links != 2 * pairs {
        return Err(m.unanswered_link());
    }
    (0..m.constrained.len())
        .into_par_iter()
        .with_min_len(4096)
        .try_for_each(|c| m.check_constrained_face(c))?;
    check_face_classes(m)?;
    m.check_attributes()
}

/// Face manifoldness: no two face classes ([`TetMesh::face_class_key`])
/// with the same key. The keys are bucketed by smallest vertex (a counting
/// sort) and the buckets sorted in parallel, instead of one global sort.
fn check_face_classes(m: &TetMesh) -> Result<(), MeshError> {
    let reps: Vec<[u32; 3]> = (0..m.tets.len())
        .into_par_iter()
        .with_min_len(4096)
        .flat_map_iter(|t| (0..4).filter_map(move |k| m.face_class_key(t, k)))
        .collect();
    // Bucket by smallest vertex (counting sort), keeping the other two.
    let np = m.points.len();
    let mut start = vec![0u32; np + 1];
    for key in &reps {
        start[key[0] as usize + 1] += 1;
    }
    for v in 0..np {
        start[v + 1] += start[v];
    }
    let mut next = start.clone();
    let mut rest = vec![0u64; reps.len()];
    for key in &reps {
        let slot = &mut next[key[0] as usize];
        rest[*slot as usize] = (u64::from(key[1]) << 32) | u64::from(key[2]);
        *slot += 1;
    }
    // Sort each bucket; chunks of whole buckets go to different threads.
    let mut buckets: Vec<(u32, &mut [u64])> = Vec::with_capacity(np);
    let mut tail: &mut [u64] = &mut rest;
    for v in 0..np {
        let len = (start[v + 1] - start[v]) as usize;
        let (head, t) = tail.split_at_mut(len);
        tail = t;
        if len > 1 {
            buckets.push((v as u32, head));
        }
    }
    let duplicate = buckets
        .par_iter_mut()
        .with_min_len(1024)
        .find_map_any(|(v, b)| {
            b.sort_unstable();
            b.windows(2)
                .find(|w| w[0] == w[1])
                .map(|w| [*v, (w[0] >> 32) as u32, w[0] as u32])
        });
    match duplicate {
        None => Ok(()),
        Some(key) => Err(m.face_class_error(key)),
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    use glam::{Vec2, Vec3};
    use tet_core::Link;
    use tet_core::mesh::FaceSide;
    use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};

    /// A valid Kuhn grid with constrained faces, a shell and attributes.
    pub(crate) fn grid(seed: u64) -> TetMesh {
        let mut m = kuhn_grid(&GridSpec {
            cells: [4, 3, 3],
            constrained_fraction: 0.3,
            shell: Some(([1, 1, 1], [3, 2, 2])),
            seed,
            ..GridSpec::default()
        });
        let n = m.points.len();
        m.attributes.normals = Some((0..n).map(|i| Vec3::new(i as f32, 1.0, 0.0)).collect());
        m.attributes.uvs = Some((0..n).map(|i| Vec2::new(0.0, i as f32)).collect());
        m
    }

    #[test]
    fn construction_check_agrees_with_validate_on_corrupted_meshes() {
        // Every corruption that keeps tets positive (links, table, extra
        // tets, attributes): the construction check must reject exactly
        // when TetMesh::validate does.
        let mut rng = SplitMix64(11);
        let (mut rejected, mut accepted) = (0, 0);
        for case in 0..600u64 {
            let mut m = grid(case % 7);
            assert!(m.validate().is_ok() && check_construction(&m).is_ok());
            let nt = m.tets.len() as u64;
            let nc = m.constrained.len() as u64;
            let t = (rng.next_u64() % nt) as usize;
            let k = (rng.next_u64() % 4) as usize;
            match case % 8 {
                0 => m.neighbors[t][k] = Link::BOUNDARY,
                1 => m.neighbors[t][k] = Link::tet((rng.next_u64() % nt) as u32),
                2 => m.neighbors[t][k] = Link::constrained((rng.next_u64() % (nc + 2)) as u32),
                3 => {
                    // A side of a constrained face moved or dropped.
                    let c = (rng.next_u64() % nc) as usize;
                    let side = FaceSide {
                        tet: (rng.next_u64() % nt) as u32,
                        face: (rng.next_u64() % 4) as u32,
                    };
                    match rng.next_u64() % 3 {
                        0 => m.constrained[c].front = side,
                        1 => m.constrained[c].back = FaceSide::NONE,
                        _ => {
                            let cf = &mut m.constrained[c];
                            std::mem::swap(&mut cf.front, &mut cf.back);
                        }
                    }
                }
                4 => {
                    // A second copy of tet t, unlinked: every face key repeats.
                    m.tets.push(m.tets[t]);
                    m.neighbors.push([Link::BOUNDARY; 4]);
                }
                5 => {
                    // Two links swapped inside one tet.
                    let j = (k + 1 + (rng.next_u64() % 3) as usize) % 4;
                    m.neighbors[t].swap(k, j);
                }
                6 => {
                    let c = (rng.next_u64() % nc) as usize;
                    match rng.next_u64() % 3 {
                        0 => m.constrained[c].triangle = m.triangle_count,
                        1 => m.constrained[c].vertices.swap(0, 1),
                        _ => m
                            .attributes
                            .uvs
                            .as_mut()
                            .unwrap()
                            .pop()
                            .map(|_| ())
                            .unwrap(),
                    }
                }
                _ => {
                    // Two linked neighbours both made boundary: the face
                    // then belongs to two unlinked tets.
                    if let Some(n) = m.neighbors[t][k].as_tet() {
                        let j = m.face_towards(n, t as u32).unwrap();
                        m.neighbors[t][k] = Link::BOUNDARY;
                        m.neighbors[n as usize][j] = Link::BOUNDARY;
                    }
                }
            }
            let full = m.validate();
            let fast = check_construction(&m);
            assert_eq!(
                fast.is_ok(),
                full.is_ok(),
                "case {case}: construction check {fast:?} vs validate {full:?}"
            );
            // tet-core's sequential driver of the same checks agrees.
            let sequential = m.validate_construction();
            assert_eq!(
                sequential.is_ok(),
                full.is_ok(),
                "case {case}: validate_construction {sequential:?} vs validate {full:?}"
            );
            if case % 8 == 4 {
                // Only the face-class check can see an unlinked duplicate.
                assert!(
                    matches!(fast, Err(MeshError::FaceNotManifold { .. })),
                    "{fast:?}"
                );
            }
            if full.is_ok() {
                accepted += 1;
            } else {
                rejected += 1;
            }
        }
        // Most corruptions are caught; a few are no-ops (e.g. a link set to
        // what it was) and must then be accepted by both.
        assert!(
            rejected > 450 && accepted > 0,
            "{rejected} rejected, {accepted} accepted"
        );
    }
}
