//! Mesh regions, pruning of unreachable regions, and brute-force point location.
//!
//! Aman et al. (2022, §5) observe that a CDT splits into *regions*: sets of
//! tets enclosed by constrained faces (and the mesh boundary). A ray stops at
//! the first constrained face, so one traversal never leaves the region it
//! started in. Two uses follow:
//!
//! * storing each region contiguously in memory
//!   ([`crate::reorder::region_major_reorder`]);
//! * dropping regions no ray can enter. Primary rays start in the camera's
//!   region, shadow rays run between a hit point and a light (both in a seed
//!   region), and reflection rays restart on the side of the hit face the ray
//!   came from, i.e. in a region already reached. So for opaque scenes only
//!   regions containing a seed (camera, lights) are ever traversed. Rays that
//!   *cross* a constrained face (refraction, transmission) reach the region
//!   behind it: a renderer that casts them must add those regions as seeds
//!   (or not prune). [`prune_unreachable`] keeps exactly the regions
//!   containing a seed, turning constrained faces towards removed regions
//!   into one-sided faces ([`FaceSide::NONE`] on the removed side).
//!
//! Paper notation → code: "distinct regions" → [`Regions`]; "source
//! tetrahedron" / "tetrahedra containing the camera and light sources" →
//! the `seeds` of [`prune_unreachable`], found e.g. by [`locate_brute`].

use std::fmt;

use glam::Vec3;
use thiserror::Error;

use crate::link::{Link, LinkKind};
use crate::mesh::{ConstrainedFace, FACE_VERTICES, FaceSide, TetMesh};
use crate::predicates::orient3d_f32;

/// Region label of every tet: tets connected through non-constrained shared
/// faces have the same label.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Regions {
    /// Region id of each tet. Regions are numbered `0..count` in the order of
    /// their lowest tet index, so a region-major tet order has increasing ids.
    pub region_of_tet: Vec<u32>,
    /// Number of tets in each region.
    pub sizes: Vec<u32>,
}

/// Summary of a [`Regions`] labelling, for logs and build reports.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RegionReport {
    /// Number of regions.
    pub count: usize,
    /// Number of tets labelled.
    pub tets: usize,
    /// Tets in the largest region (0 for an empty mesh).
    pub largest: u32,
    /// Tets in the smallest region (0 for an empty mesh).
    pub smallest: u32,
    /// Regions made of a single tet.
    pub singletons: usize,
    /// The sizes of the (up to) ten largest regions, largest first.
    pub top_sizes: Vec<u32>,
}

impl fmt::Display for RegionReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} regions over {} tets (largest {}, smallest {}, {} single-tet); largest sizes {:?}",
            self.count, self.tets, self.largest, self.smallest, self.singletons, self.top_sizes
        )
    }
}

impl Regions {
    /// Number of regions.
    pub fn count(&self) -> usize {
        self.sizes.len()
    }

    /// Summary counts and sizes.
    pub fn report(&self) -> RegionReport {
        let mut sorted = self.sizes.clone();
        sorted.sort_unstable_by(|a, b| b.cmp(a));
        RegionReport {
            count: self.sizes.len(),
            tets: self.region_of_tet.len(),
            largest: sorted.first().copied().unwrap_or(0),
            smallest: sorted.last().copied().unwrap_or(0),
            singletons: sorted.iter().filter(|&&s| s == 1).count(),
            top_sizes: sorted.into_iter().take(10).collect(),
        }
    }
}

/// Labels the regions of `mesh` by flood fill across [`Link::tet`] links
/// (constrained faces and the boundary stop the fill). O(tets), iterative.
///
/// Links that name an out-of-range tet are ignored (a valid mesh has none).
pub fn compute_regions(mesh: &TetMesh) -> Regions {
    const UNSET: u32 = u32::MAX;
    let n = mesh.tets.len();
    let mut region_of_tet = vec![UNSET; n];
    let mut sizes = Vec::new();
    let mut stack = Vec::new();
    for start in 0..n {
        if region_of_tet[start] != UNSET {
            continue;
        }
        let id = sizes.len() as u32;
        let mut size = 0u32;
        region_of_tet[start] = id;
        stack.push(start as u32);
        while let Some(t) = stack.pop() {
            size += 1;
            let Some(links) = mesh.neighbors.get(t as usize) else {
                continue;
            };
            for link in links {
                if let Some(nb) = link.as_tet()
                    && (nb as usize) < n
                    && region_of_tet[nb as usize] == UNSET
                {
                    region_of_tet[nb as usize] = id;
                    stack.push(nb);
                }
            }
        }
        sizes.push(size);
    }
    Regions {
        region_of_tet,
        sizes,
    }
}

/// Exact point location by brute force: a tet containing `p` (closed tet, so
/// a point on a shared face, edge or vertex may return any containing tet),
/// or `None` when `p` is outside the mesh or not finite.
///
/// Every tet is tested with exact [`orient3d_f32`]: O(tets). A reference for
/// tests and a fallback to find pruning seeds.
pub fn locate_brute(mesh: &TetMesh, p: Vec3) -> Option<u32> {
    if !p.is_finite() {
        return None;
    }
    (0..mesh.tets.len() as u32).find(|&t| tet_contains(mesh, t, p))
}

/// True when `p` lies in the closed tet `t` (exact).
fn tet_contains(mesh: &TetMesh, t: u32, p: Vec3) -> bool {
    let tet = mesh.tets[t as usize];
    let Some(pts) = tet
        .iter()
        .map(|&v| mesh.points.get(v as usize).copied())
        .collect::<Option<Vec<Vec3>>>()
    else {
        return false;
    };
    // Outward faces: p is inside when it is on no face's outer side.
    FACE_VERTICES
        .iter()
        .all(|s| orient3d_f32(pts[s[0]], pts[s[1]], pts[s[2]], p) <= 0.0)
}

/// What [`prune_unreachable`] removed.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PruneReport {
    /// Regions kept (those containing a seed).
    pub regions_kept: usize,
    /// Regions removed.
    pub regions_removed: usize,
    /// Tets removed.
    pub tets_removed: usize,
    /// Points removed (no longer used by any kept tet).
    pub points_removed: usize,
    /// Constrained faces removed (no side left).
    pub constrained_removed: usize,
    /// Two-sided constrained faces that became one-sided.
    pub constrained_made_one_sided: usize,
    /// Canonical bytes before pruning (see [`canonical_bytes`]).
    pub bytes_before: usize,
    /// Canonical bytes removed.
    pub bytes_removed: usize,
}

impl fmt::Display for PruneReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "kept {} regions, removed {} regions: {} tets, {} points, {} constrained faces ({} made one-sided), {} of {} bytes",
            self.regions_kept,
            self.regions_removed,
            self.tets_removed,
            self.points_removed,
            self.constrained_removed,
            self.constrained_made_one_sided,
            self.bytes_removed,
            self.bytes_before
        )
    }
}

/// Why pruning could not run. The mesh is left untouched.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum PruneError {
    /// No seed was given: every region would be removed.
    #[error("no seed tets given: pruning would remove the whole mesh")]
    NoSeeds,
    /// A seed names a tet that does not exist.
    #[error("seed {index}: tet {tet} is out of bounds ({tets} tets)")]
    SeedOutOfBounds {
        /// Position in the seed list.
        index: usize,
        /// The seed tet.
        tet: u32,
        /// Number of tets.
        tets: usize,
    },
    /// A seed position lies in no tet.
    #[error("seed point {index} at {point} lies outside the mesh")]
    PointOutsideMesh {
        /// Position in the point list.
        index: usize,
        /// The point.
        point: Vec3,
    },
    /// The region labelling does not belong to this mesh.
    #[error("region labelling has {actual} tets, the mesh {expected}")]
    RegionsMismatch {
        /// Tets labelled.
        actual: usize,
        /// Tets in the mesh.
        expected: usize,
    },
}

/// Heap bytes of the canonical arrays: points, tets, neighbours,
/// constrained-face table and attributes.
pub fn canonical_bytes(mesh: &TetMesh) -> usize {
    mesh.points.len() * size_of::<Vec3>()
        + mesh.tets.len() * size_of::<[u32; 4]>()
        + mesh.neighbors.len() * size_of::<[Link; 4]>()
        + mesh.constrained.len() * size_of::<ConstrainedFace>()
        + mesh.attributes.bytes()
}

/// Locates each point with [`locate_brute`] (for seeds: camera, lights).
pub fn locate_seeds_brute(mesh: &TetMesh, points: &[Vec3]) -> Result<Vec<u32>, PruneError> {
    points
        .iter()
        .enumerate()
        .map(|(index, &point)| {
            locate_brute(mesh, point).ok_or(PruneError::PointOutsideMesh { index, point })
        })
        .collect()
}

/// Keeps only the regions containing a seed tet (see the module docs).
///
/// Kept tets, points and constrained faces keep their relative order;
/// constrained faces whose other side was removed become one-sided, faces
/// with no side left are dropped, and unused points (with their normals and
/// uvs) are removed. Triangle ids, `triangle_count` and materials are
/// unchanged. A valid mesh stays valid. On error the mesh is untouched.
pub fn prune_unreachable(mesh: &mut TetMesh, seeds: &[u32]) -> Result<PruneReport, PruneError> {
    let regions = compute_regions(mesh);
    prune_with_regions(mesh, &regions, seeds)
}

/// [`prune_unreachable`] with a precomputed labelling of this mesh.
pub fn prune_with_regions(
    mesh: &mut TetMesh,
    regions: &Regions,
    seeds: &[u32],
) -> Result<PruneReport, PruneError> {
    let n = mesh.tets.len();
    if regions.region_of_tet.len() != n {
        return Err(PruneError::RegionsMismatch {
            actual: regions.region_of_tet.len(),
            expected: n,
        });
    }
    if seeds.is_empty() {
        return Err(PruneError::NoSeeds);
    }
    let mut keep_region = vec![false; regions.count()];
    for (index, &tet) in seeds.iter().enumerate() {
        match regions.region_of_tet.get(tet as usize) {
            Some(&r) if (r as usize) < keep_region.len() => keep_region[r as usize] = true,
            _ => {
                return Err(PruneError::SeedOutOfBounds {
                    index,
                    tet,
                    tets: n,
                });
            }
        }
    }
    let bytes_before = canonical_bytes(mesh);
    const GONE: u32 = u32::MAX;

    // New tet indices.
    let mut new_tet = vec![GONE; n];
    let mut kept_tets = 0u32;
    for (t, &r) in regions.region_of_tet.iter().enumerate() {
        if keep_region.get(r as usize).copied().unwrap_or(false) {
            new_tet[t] = kept_tets;
            kept_tets += 1;
        }
    }
    let remap_side = |s: FaceSide| -> FaceSide {
        match new_tet.get(s.tet as usize) {
            Some(&nt) if nt != GONE => FaceSide {
                tet: nt,
                face: s.face,
            },
            _ => FaceSide::NONE,
        }
    };

    // Constrained faces: keep those with a side left.
    let mut new_constrained = vec![GONE; mesh.constrained.len()];
    let mut constrained = Vec::new();
    let mut made_one_sided = 0;
    for (c, cf) in mesh.constrained.iter().enumerate() {
        let front = remap_side(cf.front);
        let back = remap_side(cf.back);
        if !front.exists() && !back.exists() {
            continue;
        }
        if cf.front.exists() && cf.back.exists() && !(front.exists() && back.exists()) {
            made_one_sided += 1;
        }
        new_constrained[c] = constrained.len() as u32;
        constrained.push(ConstrainedFace { front, back, ..*cf });
    }

    // Points used by kept tets, in their original order.
    let mut used = vec![false; mesh.points.len()];
    for (t, tet) in mesh.tets.iter().enumerate() {
        if new_tet[t] != GONE {
            for &v in tet {
                if let Some(u) = used.get_mut(v as usize) {
                    *u = true;
                }
            }
        }
    }
    let mut new_point = vec![GONE; mesh.points.len()];
    let mut kept_points = 0u32;
    for (p, &u) in used.iter().enumerate() {
        if u {
            new_point[p] = kept_points;
            kept_points += 1;
        }
    }
    let map_point = |v: u32| new_point.get(v as usize).copied().unwrap_or(GONE);

    let mut tets = Vec::with_capacity(kept_tets as usize);
    let mut neighbors = Vec::with_capacity(kept_tets as usize);
    for t in 0..n {
        if new_tet[t] == GONE {
            continue;
        }
        tets.push(mesh.tets[t].map(map_point));
        neighbors.push(mesh.neighbors[t].map(|l| match l.kind() {
            LinkKind::Tet(nb) => match new_tet.get(nb as usize) {
                Some(&x) if x != GONE => Link::tet(x),
                // A tet link never leaves its region; out of range stays invalid.
                _ => l,
            },
            LinkKind::Constrained(c) => match new_constrained.get(c as usize) {
                Some(&x) if x != GONE => Link::constrained(x),
                _ => l,
            },
            LinkKind::Boundary => l,
        }));
    }
    for cf in &mut constrained {
        cf.vertices = cf.vertices.map(map_point);
    }
    fn filter_points<T>(v: &mut Vec<T>, used: &[bool]) {
        let mut p = 0;
        v.retain(|_| {
            let keep = used.get(p).copied().unwrap_or(false);
            p += 1;
            keep
        });
    }
    let points_before = mesh.points.len();
    let tets_before = n;
    let constrained_before = mesh.constrained.len();
    filter_points(&mut mesh.points, &used);
    if let Some(v) = mesh.attributes.normals.as_mut() {
        filter_points(v, &used);
    }
    if let Some(v) = mesh.attributes.uvs.as_mut() {
        filter_points(v, &used);
    }
    mesh.tets = tets;
    mesh.neighbors = neighbors;
    mesh.constrained = constrained;

    let regions_kept = keep_region.iter().filter(|&&k| k).count();
    Ok(PruneReport {
        regions_kept,
        regions_removed: keep_region.len() - regions_kept,
        tets_removed: tets_before - mesh.tets.len(),
        points_removed: points_before - mesh.points.len(),
        constrained_removed: constrained_before - mesh.constrained.len(),
        constrained_made_one_sided: made_one_sided,
        bytes_before,
        bytes_removed: bytes_before - canonical_bytes(mesh),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::{GridSpec, kuhn_grid};

    #[test]
    fn unconstrained_grid_is_one_region() {
        let m = kuhn_grid(&GridSpec::default());
        let r = compute_regions(&m);
        assert_eq!(r.count(), 1);
        assert_eq!(r.sizes, vec![m.tets.len() as u32]);
        let rep = r.report();
        assert_eq!((rep.largest, rep.smallest, rep.singletons), (162, 162, 0));
    }

    #[test]
    fn shell_splits_inside_from_outside_and_prunes_to_inside() {
        let mut m = kuhn_grid(&GridSpec {
            cells: [4, 4, 4],
            shell: Some(([1, 1, 1], [3, 3, 3])),
            jitter: 0.0,
            ..Default::default()
        });
        let r = compute_regions(&m);
        assert_eq!(r.count(), 2);
        let mut sizes = r.sizes.clone();
        sizes.sort();
        assert_eq!(sizes, vec![8 * 6, 56 * 6]);
        let inside = locate_brute(&m, Vec3::splat(2.1)).unwrap();
        let rep = prune_unreachable(&mut m, &[inside]).unwrap();
        m.validate().unwrap();
        assert_eq!(m.tets.len(), 48);
        assert_eq!(m.points.len(), 27);
        assert_eq!(rep.tets_removed, 56 * 6);
        assert_eq!(rep.points_removed, 125 - 27);
        assert_eq!(rep.constrained_made_one_sided, 48);
        assert!(
            m.constrained
                .iter()
                .all(|c| c.front.exists() != c.back.exists())
        );
        assert_eq!(locate_brute(&m, Vec3::splat(0.5)), None);
    }

    #[test]
    fn bad_seeds_are_errors_and_leave_mesh_untouched() {
        let mut m = kuhn_grid(&GridSpec::default());
        let before = m.clone();
        assert_eq!(prune_unreachable(&mut m, &[]), Err(PruneError::NoSeeds));
        assert!(matches!(
            prune_unreachable(&mut m, &[0, 10_000]),
            Err(PruneError::SeedOutOfBounds {
                index: 1,
                tet: 10_000,
                ..
            })
        ));
        assert!(matches!(
            locate_seeds_brute(&m, &[Vec3::splat(1.5), Vec3::splat(-1.0)]),
            Err(PruneError::PointOutsideMesh { index: 1, .. })
        ));
        assert_eq!(m, before);
    }
}
