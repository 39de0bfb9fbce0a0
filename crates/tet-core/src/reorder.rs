//! Memory reordering of a [`TetMesh`] for cache locality (Aman et al.
//! 2022, §5 "Reordering tetrahedral mesh data").
//!
//! The paper sorts points by position and tets by centre point along a
//! Hilbert curve, and additionally stores the tets of one region together
//! (Figure 6, bottom right). Here:
//!
//! * [`apply_point_permutation`], [`apply_tet_permutation`] and
//!   [`apply_constrained_permutation`] apply any permutation while keeping
//!   every invariant of the mesh (tet vertex ids, neighbour links, the
//!   constrained-face table's sides, face slots and vertices, attributes);
//! * [`hilbert_reorder`] sorts points by the Hilbert key of their position,
//!   tets by the key of their centroid, and the constrained-face table by the
//!   new index of the tets on its sides (so a restart reads nearby entries);
//! * [`region_major_reorder`] sorts tets by (region, Hilbert key), regions
//!   ordered by their first tet along the curve (paper: "sorted using an
//!   Hilbert curve and mesh regions").
//!
//! A permutation is given as an *order*: `order[new] = old`. Everything is
//! deterministic (ties broken by the old index). Vertex slots inside a tet are
//! never rotated, so orientation and face numbering are unchanged.
//!
//! The pieces of [`hilbert_reorder`] are public so that a builder can run
//! them in parallel and get the very same result: the sort keys
//! ([`Quantizer::key`] of a point, [`tet_key`], [`constrained_key`]), the
//! order they give ([`order_by_key`]: `(key, old index)` pairs sorted, so any
//! correct sort of the same pairs gives the same order) and the renumbering
//! of one element ([`Renumbering`]), which [`apply_reordering`] gathers
//! array by array.

use glam::Vec3;
use thiserror::Error;

use crate::hilbert::Quantizer;
use crate::link::{Link, LinkKind};
use crate::mesh::{ConstrainedFace, FaceSide, TetMesh};
use crate::regions::{Regions, compute_regions};

/// The permutations applied by a reordering, each as `order[new] = old`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Reordering {
    /// Old point index at each new position.
    pub points: Vec<u32>,
    /// Old tet index at each new position.
    pub tets: Vec<u32>,
    /// Old constrained-face index at each new position.
    pub constrained: Vec<u32>,
}

/// An order that is not a permutation of the indexed array.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
pub enum PermutationError {
    /// The order has the wrong length.
    #[error("{what} order has {actual} entries, expected {expected}")]
    Length {
        /// Which array.
        what: &'static str,
        /// Entries given.
        actual: usize,
        /// Entries expected.
        expected: usize,
    },
    /// An entry is out of range or repeated.
    #[error("{what} order entry {position} = {value} is out of range or repeated")]
    NotPermutation {
        /// Which array.
        what: &'static str,
        /// Position in the order.
        position: usize,
        /// The offending old index.
        value: u32,
    },
}

/// Checks that `order` permutes `0..n` and returns its inverse (`new_of_old`).
pub fn invert_order(
    what: &'static str,
    order: &[u32],
    n: usize,
) -> Result<Vec<u32>, PermutationError> {
    if order.len() != n {
        return Err(PermutationError::Length {
            what,
            actual: order.len(),
            expected: n,
        });
    }
    const UNSET: u32 = u32::MAX;
    let mut new_of_old = vec![UNSET; n];
    for (position, &value) in order.iter().enumerate() {
        match new_of_old.get_mut(value as usize) {
            Some(slot) if *slot == UNSET => *slot = position as u32,
            _ => {
                return Err(PermutationError::NotPermutation {
                    what,
                    position,
                    value,
                });
            }
        }
    }
    Ok(new_of_old)
}

fn gather<T: Copy>(v: &[T], order: &[u32]) -> Vec<T> {
    order.iter().map(|&o| v[o as usize]).collect()
}

/// Moves point `order[i]` to position `i`, renumbering tet vertices,
/// constrained-face vertices, normals and uvs.
///
/// Ids in the mesh that are out of range (only in an invalid mesh) become
/// `u32::MAX`, so an invalid mesh stays invalid; nothing panics.
pub fn apply_point_permutation(mesh: &mut TetMesh, order: &[u32]) -> Result<(), PermutationError> {
    let new_of_old = invert_order("point", order, mesh.points.len())?;
    let map = |v: u32| new_of_old.get(v as usize).copied().unwrap_or(u32::MAX);
    mesh.points = gather(&mesh.points, order);
    if let Some(n) = mesh.attributes.normals.as_mut()
        && n.len() == order.len()
    {
        *n = gather(n, order);
    }
    if let Some(uv) = mesh.attributes.uvs.as_mut()
        && uv.len() == order.len()
    {
        *uv = gather(uv, order);
    }
    for tet in &mut mesh.tets {
        *tet = tet.map(map);
    }
    for cf in &mut mesh.constrained {
        cf.vertices = cf.vertices.map(map);
    }
    Ok(())
}

/// Moves tet `order[i]` (with its neighbour links) to position `i`,
/// renumbering tet links and the constrained-face table's sides.
///
/// Out-of-range ids (invalid mesh only) are left as they are.
pub fn apply_tet_permutation(mesh: &mut TetMesh, order: &[u32]) -> Result<(), PermutationError> {
    let n = mesh.tets.len();
    if mesh.neighbors.len() != n {
        return Err(PermutationError::Length {
            what: "neighbour",
            actual: mesh.neighbors.len(),
            expected: n,
        });
    }
    let new_of_old = invert_order("tet", order, n)?;
    mesh.tets = gather(&mesh.tets, order);
    mesh.neighbors = gather(&mesh.neighbors, order);
    for links in &mut mesh.neighbors {
        for l in links {
            if let Some(t) = l.as_tet()
                && let Some(&nt) = new_of_old.get(t as usize)
            {
                *l = Link::tet(nt);
            }
        }
    }
    let map_side = |s: FaceSide| match new_of_old.get(s.tet as usize) {
        Some(&nt) => FaceSide {
            tet: nt,
            face: s.face,
        },
        None => s,
    };
    for cf in &mut mesh.constrained {
        cf.front = map_side(cf.front);
        cf.back = map_side(cf.back);
    }
    Ok(())
}

/// Moves constrained face `order[i]` to position `i`, renumbering the
/// constrained links of the tets.
pub fn apply_constrained_permutation(
    mesh: &mut TetMesh,
    order: &[u32],
) -> Result<(), PermutationError> {
    let new_of_old = invert_order("constrained face", order, mesh.constrained.len())?;
    mesh.constrained = gather(&mesh.constrained, order);
    for links in &mut mesh.neighbors {
        for l in links {
            if let LinkKind::Constrained(c) = l.kind()
                && let Some(&nc) = new_of_old.get(c as usize)
            {
                *l = Link::constrained(nc);
            }
        }
    }
    Ok(())
}

/// Sorts `keys` (one per element) and returns the order, ties by index:
/// the `(key, index)` pairs sorted ascending.
pub fn order_by_key<K: Ord + Copy>(keys: impl Iterator<Item = K>) -> Vec<u32> {
    let mut v: Vec<(K, u32)> = keys.enumerate().map(|(i, k)| (k, i as u32)).collect();
    v.sort_unstable();
    v.into_iter().map(|(_, i)| i).collect()
}

/// Centroid of tet `t` (out-of-range vertices count as the origin).
fn centroid(mesh: &TetMesh, t: usize) -> Vec3 {
    let s: Vec3 = mesh.tets[t]
        .iter()
        .map(|&v| mesh.points.get(v as usize).copied().unwrap_or(Vec3::ZERO))
        .sum();
    s * 0.25
}

/// Points sorted by the Hilbert key of their position.
pub fn hilbert_point_order(mesh: &TetMesh, q: &Quantizer) -> Vec<u32> {
    order_by_key(mesh.points.iter().map(|&p| q.key(p)))
}

/// Hilbert key of tet `t`'s centroid (out-of-range vertices count as the
/// origin): the sort key of the tet order.
pub fn tet_key(mesh: &TetMesh, q: &Quantizer, t: usize) -> u64 {
    q.key(centroid(mesh, t))
}

/// Hilbert key of each tet's centroid.
pub fn tet_keys(mesh: &TetMesh, q: &Quantizer) -> Vec<u64> {
    (0..mesh.tets.len()).map(|t| tet_key(mesh, q, t)).collect()
}

/// Tets sorted by the Hilbert key of their centroid.
pub fn hilbert_tet_order(mesh: &TetMesh, q: &Quantizer) -> Vec<u32> {
    order_by_key(tet_keys(mesh, q).into_iter())
}

/// Constrained faces sorted by the lowest tet index on their sides (then
/// that tet's face), so the table follows the tet order.
pub fn constrained_order_by_tets(mesh: &TetMesh) -> Vec<u32> {
    order_by_key(mesh.constrained.iter().map(|cf| constrained_key(cf, &[])))
}

/// Sort key of a constrained face once tet `t` has become `new_tet[t]`:
/// its lowest `(new tet, face)` side (`(u32::MAX, 0)` with no side). Tets
/// beyond `new_tet` keep their index (pass `&[]` for the current order).
pub fn constrained_key(cf: &ConstrainedFace, new_tet: &[u32]) -> (u32, u32) {
    [cf.front, cf.back]
        .into_iter()
        .filter(|s| s.exists())
        .map(|s| {
            (
                new_tet.get(s.tet as usize).copied().unwrap_or(s.tet),
                s.face,
            )
        })
        .min()
        .unwrap_or((u32::MAX, 0))
}

/// Where every element of a mesh goes under a [`Reordering`]: the inverse
/// permutations (`new_of_old`), and the renumbering of one tet, one tet's
/// links and one constrained face. Ids out of range (invalid mesh only) are
/// handled as [`apply_point_permutation`], [`apply_tet_permutation`] and
/// [`apply_constrained_permutation`] do, so an invalid mesh stays invalid.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Renumbering {
    /// New index of each old point.
    pub points: Vec<u32>,
    /// New index of each old tet.
    pub tets: Vec<u32>,
    /// New index of each old constrained face.
    pub constrained: Vec<u32>,
}

impl Renumbering {
    /// The inverse of `r` for `mesh`; errors when an order is not a
    /// permutation of the mesh's array.
    pub fn new(mesh: &TetMesh, r: &Reordering) -> Result<Renumbering, PermutationError> {
        Ok(Renumbering {
            points: invert_order("point", &r.points, mesh.points.len())?,
            tets: invert_order("tet", &r.tets, mesh.tets.len())?,
            constrained: invert_order("constrained face", &r.constrained, mesh.constrained.len())?,
        })
    }

    /// New vertex id (`u32::MAX` for an out-of-range one).
    pub fn point(&self, v: u32) -> u32 {
        self.points.get(v as usize).copied().unwrap_or(u32::MAX)
    }

    /// A tet's vertex ids, renumbered.
    pub fn tet(&self, tet: [u32; 4]) -> [u32; 4] {
        tet.map(|v| self.point(v))
    }

    /// A tet's links, renumbered (out-of-range targets left as they are).
    pub fn links(&self, links: [Link; 4]) -> [Link; 4] {
        links.map(|l| match l.kind() {
            LinkKind::Tet(n) => self.tets.get(n as usize).map_or(l, |&n| Link::tet(n)),
            LinkKind::Constrained(c) => self
                .constrained
                .get(c as usize)
                .map_or(l, |&c| Link::constrained(c)),
            LinkKind::Boundary => l,
        })
    }

    /// A tet side, renumbered (absent or out-of-range sides unchanged).
    pub fn side(&self, s: FaceSide) -> FaceSide {
        match self.tets.get(s.tet as usize) {
            Some(&tet) => FaceSide { tet, face: s.face },
            None => s,
        }
    }

    /// A constrained face's vertices and sides, renumbered.
    pub fn constrained_face(&self, cf: ConstrainedFace) -> ConstrainedFace {
        ConstrainedFace {
            triangle: cf.triangle,
            vertices: cf.vertices.map(|v| self.point(v)),
            front: self.side(cf.front),
            back: self.side(cf.back),
        }
    }
}

/// Applies all three orders of `r` at once, one gather per array (points,
/// normals, uvs, tets, links, constrained faces): the same mesh as
/// [`apply_point_permutation`], [`apply_tet_permutation`] and
/// [`apply_constrained_permutation`] in turn. The mesh is untouched on error.
pub fn apply_reordering(mesh: &mut TetMesh, r: &Reordering) -> Result<(), PermutationError> {
    check_lengths(mesh)?;
    let map = Renumbering::new(mesh, r)?;
    mesh.points = gather(&mesh.points, &r.points);
    if let Some(n) = mesh.attributes.normals.as_mut()
        && n.len() == r.points.len()
    {
        *n = gather(n, &r.points);
    }
    if let Some(uv) = mesh.attributes.uvs.as_mut()
        && uv.len() == r.points.len()
    {
        *uv = gather(uv, &r.points);
    }
    mesh.tets = r
        .tets
        .iter()
        .map(|&o| map.tet(mesh.tets[o as usize]))
        .collect();
    mesh.neighbors = r
        .tets
        .iter()
        .map(|&o| map.links(mesh.neighbors[o as usize]))
        .collect();
    mesh.constrained = r
        .constrained
        .iter()
        .map(|&o| map.constrained_face(mesh.constrained[o as usize]))
        .collect();
    Ok(())
}

/// Applies point and tet orders, the constrained faces following the tets
/// ([`constrained_key`]).
fn apply_all(
    mesh: &mut TetMesh,
    points: Vec<u32>,
    tets: Vec<u32>,
) -> Result<Reordering, PermutationError> {
    let new_tet = invert_order("tet", &tets, mesh.tets.len())?;
    let constrained = order_by_key(
        mesh.constrained
            .iter()
            .map(|cf| constrained_key(cf, &new_tet)),
    );
    let r = Reordering {
        points,
        tets,
        constrained,
    };
    apply_reordering(mesh, &r)?;
    Ok(r)
}

/// Reorders points (by position) and tets (by centroid) along a Hilbert curve
/// over the points' bounding box, then the constrained-face table by tet.
///
/// Errors only when `neighbors` and `tets` differ in length (invalid mesh);
/// the mesh is then untouched.
pub fn hilbert_reorder(mesh: &mut TetMesh) -> Result<Reordering, PermutationError> {
    check_lengths(mesh)?;
    let q = Quantizer::from_points(&mesh.points);
    let points = hilbert_point_order(mesh, &q);
    let tets = hilbert_tet_order(mesh, &q);
    apply_all(mesh, points, tets)
}

/// Like [`hilbert_reorder`], but tets are sorted by (region, Hilbert key):
/// each region is contiguous, regions ordered by their first tet along the
/// curve. Returns the labelling of the reordered mesh, whose region `r`
/// occupies one contiguous range of tets (regions numbered in memory order).
pub fn region_major_reorder(mesh: &mut TetMesh) -> Result<(Reordering, Regions), PermutationError> {
    check_lengths(mesh)?;
    let q = Quantizer::from_points(&mesh.points);
    let regions = compute_regions(mesh);
    let keys = tet_keys(mesh, &q);
    // Rank regions by their smallest (key, tet) pair.
    let mut first = vec![(u64::MAX, u32::MAX); regions.count()];
    for (t, (&r, &k)) in regions.region_of_tet.iter().zip(&keys).enumerate() {
        let f = &mut first[r as usize];
        *f = (*f).min((k, t as u32));
    }
    let region_rank = invert_order("region", &order_by_key(first.into_iter()), regions.count())?;
    let tets = order_by_key(
        regions
            .region_of_tet
            .iter()
            .zip(&keys)
            .map(|(&r, &k)| (region_rank[r as usize], k)),
    );
    let points = hilbert_point_order(mesh, &q);
    let reordering = apply_all(mesh, points, tets)?;
    Ok((reordering, compute_regions(mesh)))
}

fn check_lengths(mesh: &TetMesh) -> Result<(), PermutationError> {
    if mesh.neighbors.len() != mesh.tets.len() {
        return Err(PermutationError::Length {
            what: "neighbour",
            actual: mesh.neighbors.len(),
            expected: mesh.tets.len(),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn invert_rejects_non_permutations() {
        assert_eq!(invert_order("x", &[2, 0, 1], 3).unwrap(), vec![1, 2, 0]);
        assert!(matches!(
            invert_order("x", &[0, 0, 1], 3),
            Err(PermutationError::NotPermutation {
                position: 1,
                value: 0,
                ..
            })
        ));
        assert!(matches!(
            invert_order("x", &[0, 3, 1], 3),
            Err(PermutationError::NotPermutation {
                position: 1,
                value: 3,
                ..
            })
        ));
        assert!(matches!(
            invert_order("x", &[0, 1], 3),
            Err(PermutationError::Length {
                actual: 2,
                expected: 3,
                ..
            })
        ));
    }

    #[test]
    fn one_gather_equals_the_three_permutations() {
        use crate::synthetic::{GridSpec, SplitMix64, kuhn_grid};
        let mut rng = SplitMix64(9);
        let mut shuffled = |n: usize| {
            let mut v: Vec<u32> = (0..n as u32).collect();
            for i in (1..n).rev() {
                v.swap(i, (rng.next_u64() % (i as u64 + 1)) as usize);
            }
            v
        };
        for seed in 0..3 {
            let mut a = kuhn_grid(&GridSpec {
                cells: [3, 3, 2],
                constrained_fraction: 0.4,
                seed,
                ..GridSpec::default()
            });
            let n = a.points.len();
            a.attributes.normals = Some((0..n).map(|i| Vec3::splat(i as f32)).collect());
            let r = Reordering {
                points: shuffled(a.points.len()),
                tets: shuffled(a.tets.len()),
                constrained: shuffled(a.constrained.len()),
            };
            let mut b = a.clone();
            apply_point_permutation(&mut a, &r.points).unwrap();
            apply_tet_permutation(&mut a, &r.tets).unwrap();
            apply_constrained_permutation(&mut a, &r.constrained).unwrap();
            apply_reordering(&mut b, &r).unwrap();
            assert_eq!(a, b);
            b.validate().unwrap();
            // A wrong order leaves the mesh untouched.
            let c = b.clone();
            let bad = Reordering {
                points: vec![0; b.points.len()],
                ..r.clone()
            };
            assert!(apply_reordering(&mut b, &bad).is_err());
            assert_eq!(b, c);
        }
    }
}
