//! Hilbert and region-major reordering keep every invariant and the geometry.
//!
//! The reference is coordinate-based and independent of indices: each tet is
//! identified by the bit patterns of its four vertex positions (slot order
//! kept), each link by what lies across it, each constrained face by its
//! triangle id, vertex coordinates and the apex coordinates of its sides.

use std::collections::HashMap;

use glam::Vec3;
use proptest::prelude::*;
use tet_core::hilbert::Quantizer;
use tet_core::reorder::{
    apply_constrained_permutation, apply_point_permutation, apply_tet_permutation, hilbert_reorder,
    region_major_reorder, tet_keys,
};
use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid, with_attributes};
use tet_core::{FaceSide, LinkKind, TetMesh};

type P = [u32; 3];

fn bits(p: Vec3) -> P {
    [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]
}

fn tet_key(m: &TetMesh, t: u32) -> [P; 4] {
    m.tet_points(t).map(bits)
}

#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Across {
    Tet([P; 4]),
    Boundary,
    Constrained(u32),
}

/// Every tet with what lies across each face, sorted.
fn tets_with_links(m: &TetMesh) -> Vec<([P; 4], [Across; 4])> {
    let mut v: Vec<_> = (0..m.tets.len() as u32)
        .map(|t| {
            let across = std::array::from_fn(|k| match m.neighbors[t as usize][k].kind() {
                LinkKind::Tet(n) => Across::Tet(tet_key(m, n)),
                LinkKind::Boundary => Across::Boundary,
                LinkKind::Constrained(c) => Across::Constrained(m.constrained[c as usize].triangle),
            });
            (tet_key(m, t), across)
        })
        .collect();
    v.sort();
    v
}

type FaceGeo = (u32, [P; 3], Option<P>, Option<P>);

/// Constrained faces as (triangle, vertex coordinates, front apex, back apex).
fn constrained_geometry(m: &TetMesh) -> Vec<FaceGeo> {
    let apex = |s: FaceSide| {
        s.exists()
            .then(|| bits(m.points[m.tets[s.tet as usize][s.face as usize] as usize]))
    };
    let mut v: Vec<_> = m
        .constrained
        .iter()
        .map(|cf| {
            (
                cf.triangle,
                cf.vertices.map(|i| bits(m.points[i as usize])),
                apex(cf.front),
                apex(cf.back),
            )
        })
        .collect();
    v.sort();
    v
}

/// Points with their attributes, sorted.
fn points_with_attributes(m: &TetMesh) -> Vec<(P, Option<P>, Option<[u32; 2]>)> {
    let a = &m.attributes;
    let mut v: Vec<_> = (0..m.points.len())
        .map(|i| {
            (
                bits(m.points[i]),
                a.normals.as_ref().map(|n| bits(n[i])),
                a.uvs.as_ref().map(|u| [u[i].x.to_bits(), u[i].y.to_bits()]),
            )
        })
        .collect();
    v.sort();
    v
}

fn assert_same_geometry(before: &TetMesh, after: &TetMesh) {
    after.validate().expect("reordered mesh validates");
    assert_eq!(tets_with_links(before), tets_with_links(after));
    assert_eq!(constrained_geometry(before), constrained_geometry(after));
    assert_eq!(
        points_with_attributes(before),
        points_with_attributes(after)
    );
    assert_eq!(before.triangle_count, after.triangle_count);
    assert_eq!(before.attributes.materials, after.attributes.materials);
}

prop_compose! {
    fn grid_mesh()(
        cells in [1u32..7, 1u32..7, 1u32..7],
        jitter in 0.0f32..0.15,
        fraction in prop_oneof![Just(0.0), 0.0f64..0.6],
        shell in 0u8..3,
        scale in prop_oneof![Just(1.0f32), 0.01f32..100.0],
        offset in prop_oneof![Just(Vec3::ZERO), Just(Vec3::new(-1e3, 5e2, 3.0))],
        seed in any::<u64>(),
        attrs in 0u8..8,
    ) -> TetMesh {
        let shell = match shell {
            1 if cells.iter().all(|&c| c >= 3) => Some(([1, 1, 1], cells.map(|c| c - 1))),
            2 => Some(([0, 0, 0], cells)),
            _ => None,
        };
        let m = kuhn_grid(&GridSpec {
            cells,
            jitter,
            constrained_fraction: fraction,
            shell,
            scale,
            offset,
            seed,
        });
        with_attributes(m, attrs, seed ^ 0xABCD)
    }
}

fn shuffle(n: usize, rng: &mut SplitMix64) -> Vec<u32> {
    let mut v: Vec<u32> = (0..n as u32).collect();
    for i in (1..n).rev() {
        let j = (rng.next_u64() % (i as u64 + 1)) as usize;
        v.swap(i, j);
    }
    v
}

/// Applies random permutations of points, tets and constrained faces.
fn scramble(m: &mut TetMesh, seed: u64) {
    let mut rng = SplitMix64(seed);
    let p = shuffle(m.points.len(), &mut rng);
    let t = shuffle(m.tets.len(), &mut rng);
    let c = shuffle(m.constrained.len(), &mut rng);
    apply_point_permutation(m, &p).unwrap();
    apply_tet_permutation(m, &t).unwrap();
    apply_constrained_permutation(m, &c).unwrap();
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn random_permutations_keep_invariants(m in grid_mesh(), seed in any::<u64>()) {
        let mut r = m.clone();
        scramble(&mut r, seed);
        assert_same_geometry(&m, &r);
    }

    #[test]
    fn hilbert_reorder_keeps_invariants_and_is_deterministic(m in grid_mesh(), seed in any::<u64>()) {
        let mut a = m.clone();
        let order = hilbert_reorder(&mut a).unwrap();
        assert_same_geometry(&m, &a);
        prop_assert_eq!(order.points.len(), m.points.len());
        // Same input → same output; a second pass changes nothing.
        let mut b = m.clone();
        hilbert_reorder(&mut b).unwrap();
        prop_assert_eq!(&a, &b);
        let mut c = a.clone();
        hilbert_reorder(&mut c).unwrap();
        prop_assert_eq!(&a, &c);
        // Reordering a scrambled copy gives the same mesh whenever no two
        // points and no two tet centroids share a quantised cell (ties are
        // broken by input index, the only order-dependent part).
        let mut s = m.clone();
        scramble(&mut s, seed);
        hilbert_reorder(&mut s).unwrap();
        assert_same_geometry(&m, &s);
        let q = Quantizer::from_points(&m.points);
        let mut pk: Vec<u64> = m.points.iter().map(|&p| q.key(p)).collect();
        let mut tk = tet_keys(&m, &q);
        pk.sort();
        tk.sort();
        let unique = |v: &[u64]| v.windows(2).all(|w| w[0] != w[1]);
        if unique(&pk) && unique(&tk) {
            prop_assert_eq!(&a, &s);
        }
    }

    #[test]
    fn region_major_reorder_keeps_invariants_and_groups_regions(m in grid_mesh()) {
        let mut a = m.clone();
        let (order, regions) = region_major_reorder(&mut a).unwrap();
        assert_same_geometry(&m, &a);
        prop_assert_eq!(order.tets.len(), m.tets.len());
        // Regions are contiguous and numbered in memory order.
        prop_assert!(regions.region_of_tet.windows(2).all(|w| w[0] <= w[1]));
        prop_assert_eq!(regions.region_of_tet.len(), a.tets.len());
        let before = tet_core::regions::compute_regions(&m);
        let mut s1 = before.sizes.clone();
        let mut s2 = regions.sizes.clone();
        s1.sort();
        s2.sort();
        prop_assert_eq!(s1, s2);
        // Deterministic and idempotent.
        let mut b = a.clone();
        region_major_reorder(&mut b).unwrap();
        prop_assert_eq!(&a, &b);
    }
}

/// Mean |t - n| over neighbour links: the locality the reordering targets.
fn mean_link_distance(m: &TetMesh) -> f64 {
    let (mut sum, mut count) = (0f64, 0usize);
    for (t, links) in m.neighbors.iter().enumerate() {
        for l in links {
            if let Some(n) = l.as_tet() {
                sum += (t as f64 - n as f64).abs();
                count += 1;
            }
        }
    }
    sum / count as f64
}

/// Median over tets of (largest - smallest vertex id): how far apart in
/// memory a tet's points are (the mean is dominated by the curve's few
/// long jumps between octants).
fn median_vertex_spread(m: &TetMesh) -> u32 {
    let mut v: Vec<u32> = m
        .tets
        .iter()
        .map(|t| t.iter().max().unwrap() - t.iter().min().unwrap())
        .collect();
    v.sort_unstable();
    v[v.len() / 2]
}

#[test]
fn hilbert_order_restores_locality_of_a_shuffled_mesh() {
    let mut m = kuhn_grid(&GridSpec {
        cells: [12, 12, 12],
        jitter: 0.1,
        ..Default::default()
    });
    scramble(&mut m, 99);
    let shuffled_links = mean_link_distance(&m);
    let shuffled_spread = median_vertex_spread(&m);
    let before = m.clone();
    hilbert_reorder(&mut m).unwrap();
    assert_same_geometry(&before, &m);
    let links = mean_link_distance(&m);
    let spread = median_vertex_spread(&m);
    // A random order puts neighbours ~n/3 apart; a space-filling order keeps
    // most of them within a few dozen slots.
    assert!(
        links * 20.0 < shuffled_links,
        "links {links} vs shuffled {shuffled_links}"
    );
    assert!(
        spread * 10 < shuffled_spread,
        "spread {spread} vs shuffled {shuffled_spread}"
    );
}

#[test]
fn region_major_order_puts_shell_inside_contiguously() {
    let m = kuhn_grid(&GridSpec {
        cells: [5, 5, 5],
        shell: Some(([1, 1, 1], [4, 4, 4])),
        ..Default::default()
    });
    let mut a = m.clone();
    let (_, regions) = region_major_reorder(&mut a).unwrap();
    assert_eq!(regions.count(), 2);
    // 27 inner cells × 6 tets; the rest outside.
    let mut sizes = regions.sizes.clone();
    sizes.sort();
    assert_eq!(sizes, vec![27 * 6, (125 - 27) * 6]);
    // Every tet whose centroid is inside [1,4]^3 is in one contiguous block.
    let inside: Vec<usize> = (0..a.tets.len())
        .filter(|&t| {
            let c = a.tet_points(t as u32).iter().sum::<Vec3>() / 4.0;
            c.cmpgt(Vec3::ONE).all() && c.cmplt(Vec3::splat(4.0)).all()
        })
        .collect();
    assert_eq!(inside.len(), 27 * 6);
    assert_eq!(inside.last().unwrap() - inside[0] + 1, inside.len());
}

#[test]
fn bad_permutations_are_rejected_and_leave_mesh_untouched() {
    let mut m = kuhn_grid(&GridSpec::default());
    let before = m.clone();
    let mut dup: Vec<u32> = (0..m.points.len() as u32).collect();
    dup[3] = 0;
    assert!(apply_point_permutation(&mut m, &dup).is_err());
    assert!(apply_tet_permutation(&mut m, &[0, 1]).is_err());
    let mut oob: Vec<u32> = (0..m.tets.len() as u32).collect();
    oob[0] = m.tets.len() as u32;
    assert!(apply_tet_permutation(&mut m, &oob).is_err());
    assert_eq!(m, before);
}

#[test]
fn hand_built_permutation_moves_links_and_sides() {
    // Two tets sharing constrained face (0,1,2); swap the tets and reverse points.
    let points = vec![
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.2, 0.2, 1.0),
        Vec3::new(0.2, 0.2, -1.0),
    ];
    let mut m = TetMesh::assemble(
        points,
        vec![[0, 1, 2, 3], [1, 0, 2, 4]],
        &[([0, 1, 2], 0)],
        1,
    )
    .unwrap();
    apply_tet_permutation(&mut m, &[1, 0]).unwrap();
    apply_point_permutation(&mut m, &[4, 3, 2, 1, 0]).unwrap();
    m.validate().unwrap();
    // Old tet 1 [1,0,2,4] is now tet 0 with new ids [3,4,2,0].
    assert_eq!(m.tets, vec![[3, 4, 2, 0], [4, 3, 2, 1]]);
    let cf = m.constrained[0];
    assert_eq!(cf.vertices, [4, 3, 2]);
    assert_eq!(cf.front, FaceSide { tet: 1, face: 3 });
    assert_eq!(cf.back, FaceSide { tet: 0, face: 3 });
    // Positions did not move.
    let map: HashMap<P, usize> = m
        .points
        .iter()
        .enumerate()
        .map(|(i, &p)| (bits(p), i))
        .collect();
    assert_eq!(map[&bits(Vec3::new(0.2, 0.2, -1.0))], 0);
}
