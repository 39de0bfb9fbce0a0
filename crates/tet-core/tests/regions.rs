//! Regions, pruning and brute-force location against independent references:
//! a union-find over shared faces found by vertex sets (not by links), f64
//! barycentric coordinates, and coordinate fingerprints of what is kept.

use std::collections::{HashMap, HashSet};

use glam::{DVec3, Vec2, Vec3};
use proptest::prelude::*;
use tet_core::regions::{
    PruneError, compute_regions, locate_brute, locate_seeds_brute, prune_unreachable,
};
use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};
use tet_core::{FaceSide, TetMesh, face_key};

type P = [u32; 3];

fn bits(p: Vec3) -> P {
    [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]
}

fn find(parent: &mut [usize], mut a: usize) -> usize {
    while parent[a] != a {
        parent[a] = parent[parent[a]];
        a = parent[a];
    }
    a
}

/// Region root of every tet: tets sharing a face (by vertex set) are joined
/// unless the face is one of the constrained triangles.
fn reference_regions(m: &TetMesh) -> Vec<usize> {
    let constrained: HashSet<[u32; 3]> =
        m.constrained.iter().map(|c| face_key(c.vertices)).collect();
    let mut by_face: HashMap<[u32; 3], Vec<usize>> = HashMap::new();
    for (t, tet) in m.tets.iter().enumerate() {
        for k in 0..4 {
            let f: Vec<u32> = (0..4).filter(|&i| i != k).map(|i| tet[i]).collect();
            by_face
                .entry(face_key([f[0], f[1], f[2]]))
                .or_default()
                .push(t);
        }
    }
    let mut parent: Vec<usize> = (0..m.tets.len()).collect();
    for (key, tets) in &by_face {
        if tets.len() == 2 && !constrained.contains(key) {
            let (a, b) = (find(&mut parent, tets[0]), find(&mut parent, tets[1]));
            parent[a] = b;
        }
    }
    (0..m.tets.len()).map(|t| find(&mut parent, t)).collect()
}

fn tet_key(m: &TetMesh, t: usize) -> [P; 4] {
    m.tet_points(t as u32).map(bits)
}

type FaceGeo = (u32, [P; 3], Option<P>, Option<P>);

fn face_geo(m: &TetMesh, cf: &tet_core::ConstrainedFace, keep: &dyn Fn(u32) -> bool) -> FaceGeo {
    let apex = |s: FaceSide| {
        (s.exists() && keep(s.tet))
            .then(|| bits(m.points[m.tets[s.tet as usize][s.face as usize] as usize]))
    };
    (
        cf.triangle,
        cf.vertices.map(|v| bits(m.points[v as usize])),
        apex(cf.front),
        apex(cf.back),
    )
}

prop_compose! {
    fn grid_mesh()(
        cells in [1u32..7, 1u32..7, 1u32..7],
        jitter in 0.0f32..0.15,
        fraction in prop_oneof![Just(0.0), 0.0f64..0.8],
        shell in 0u8..3,
        seed in any::<u64>(),
        attrs in any::<bool>(),
    ) -> TetMesh {
        let shell = match shell {
            1 if cells.iter().all(|&c| c >= 3) => Some(([1, 1, 1], cells.map(|c| c - 1))),
            2 => Some(([0, 0, 0], cells)),
            _ => None,
        };
        let mut m = kuhn_grid(&GridSpec {
            cells,
            jitter,
            constrained_fraction: fraction,
            shell,
            seed,
            ..Default::default()
        });
        if attrs {
            let n = m.points.len();
            m.attributes.normals = Some((0..n).map(|i| Vec3::new(i as f32, 0.0, 1.0)).collect());
            m.attributes.uvs = Some((0..n).map(|i| Vec2::new(0.5, i as f32)).collect());
            m.attributes.materials = Some((0..m.triangle_count).collect());
        }
        m
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn regions_match_union_find(m in grid_mesh()) {
        let r = compute_regions(&m);
        let roots = reference_regions(&m);
        prop_assert_eq!(r.region_of_tet.len(), m.tets.len());
        // Same partition: the maps region → root and root → region are functions.
        let mut root_of: HashMap<u32, usize> = HashMap::new();
        let mut region_of: HashMap<usize, u32> = HashMap::new();
        for (&reg, &root) in r.region_of_tet.iter().zip(&roots) {
            prop_assert_eq!(*root_of.entry(reg).or_insert(root), root);
            prop_assert_eq!(*region_of.entry(root).or_insert(reg), reg);
        }
        prop_assert_eq!(root_of.len(), r.count());
        // Sizes count the tets of each region; ids follow first tet index.
        let mut sizes = vec![0u32; r.count()];
        for &g in &r.region_of_tet {
            sizes[g as usize] += 1;
        }
        prop_assert_eq!(&sizes, &r.sizes);
        let mut first_seen = Vec::new();
        for &g in &r.region_of_tet {
            if !first_seen.contains(&g) {
                first_seen.push(g);
            }
        }
        prop_assert_eq!(first_seen, (0..r.count() as u32).collect::<Vec<_>>());
        let rep = r.report();
        prop_assert_eq!(rep.count, r.count());
        prop_assert_eq!(rep.tets, m.tets.len());
        prop_assert_eq!(rep.largest, *sizes.iter().max().unwrap());
    }

    #[test]
    fn pruning_keeps_exactly_the_seed_regions(m in grid_mesh(), seed in any::<u64>(), n_seeds in 1usize..4) {
        let mut rng = SplitMix64(seed);
        let seeds: Vec<u32> = (0..n_seeds).map(|_| (rng.next_u64() % m.tets.len() as u64) as u32).collect();
        let roots = reference_regions(&m);
        let kept_roots: HashSet<usize> = seeds.iter().map(|&s| roots[s as usize]).collect();
        let keep = |t: u32| kept_roots.contains(&roots[t as usize]);

        // Expected content, by coordinates.
        let mut want_tets: Vec<[P; 4]> = (0..m.tets.len()).filter(|&t| keep(t as u32)).map(|t| tet_key(&m, t)).collect();
        want_tets.sort();
        let want_points: HashSet<P> = m.tets.iter().enumerate()
            .filter(|&(t, _)| keep(t as u32))
            .flat_map(|(_, tet)| tet.iter().map(|&v| bits(m.points[v as usize])))
            .collect();
        let mut want_faces: Vec<FaceGeo> = m.constrained.iter()
            .filter(|cf| [cf.front, cf.back].iter().any(|s| s.exists() && keep(s.tet)))
            .map(|cf| face_geo(&m, cf, &keep))
            .collect();
        want_faces.sort();

        let mut p = m.clone();
        let report = prune_unreachable(&mut p, &seeds).unwrap();
        p.validate().unwrap();

        let mut got_tets: Vec<[P; 4]> = (0..p.tets.len()).map(|t| tet_key(&p, t)).collect();
        got_tets.sort();
        prop_assert_eq!(&got_tets, &want_tets);
        let got_points: HashSet<P> = p.points.iter().map(|&q| bits(q)).collect();
        prop_assert_eq!(got_points.len(), p.points.len(), "points stay distinct");
        prop_assert_eq!(&got_points, &want_points);
        let mut got_faces: Vec<FaceGeo> = p.constrained.iter().map(|cf| face_geo(&p, cf, &|_| true)).collect();
        got_faces.sort();
        prop_assert_eq!(&got_faces, &want_faces);
        // Attributes follow their points.
        if let Some(n) = &p.attributes.normals {
            let old: HashMap<P, P> = m.points.iter().zip(m.attributes.normals.as_ref().unwrap())
                .map(|(&q, &nn)| (bits(q), bits(nn))).collect();
            for (q, nn) in p.points.iter().zip(n) {
                prop_assert_eq!(old[&bits(*q)], bits(*nn));
            }
        }
        prop_assert_eq!(&p.attributes.materials, &m.attributes.materials);

        // The report adds up.
        prop_assert_eq!(report.regions_kept, kept_roots.len());
        prop_assert_eq!(report.tets_removed, m.tets.len() - p.tets.len());
        prop_assert_eq!(report.points_removed, m.points.len() - p.points.len());
        prop_assert_eq!(report.constrained_removed, m.constrained.len() - p.constrained.len());
        let one_side_kept = m.constrained.iter()
            .filter(|c| c.front.exists() && c.back.exists() && (keep(c.front.tet) != keep(c.back.tet)))
            .count();
        prop_assert_eq!(report.constrained_made_one_sided, one_side_kept);
        let attr_per_point = if m.attributes.normals.is_some() { 12 + 8 } else { 0 };
        prop_assert_eq!(
            report.bytes_removed,
            report.points_removed * (12 + attr_per_point) + report.tets_removed * 32 + report.constrained_removed * 32
        );
        // Pruning again with a seed of each kept region removes nothing.
        let again_seeds: Vec<u32> = {
            let r = compute_regions(&p);
            (0..r.count() as u32).map(|g| r.region_of_tet.iter().position(|&x| x == g).unwrap() as u32).collect()
        };
        let mut q = p.clone();
        let rep2 = prune_unreachable(&mut q, &again_seeds).unwrap();
        prop_assert_eq!(rep2.tets_removed, 0);
        prop_assert_eq!(&q, &p);
    }

    #[test]
    fn locate_brute_finds_interior_points_exactly(m in grid_mesh(), seed in any::<u64>()) {
        let mut rng = SplitMix64(seed);
        for _ in 0..8 {
            let t = (rng.next_u64() % m.tets.len() as u64) as u32;
            // A strictly interior convex combination of t's vertices.
            let w: Vec<f64> = (0..4).map(|_| 0.1 + rng.next_f64()).collect();
            let s: f64 = w.iter().sum();
            let pts = m.tet_points(t).map(|p| p.as_dvec3());
            let p: DVec3 = (0..4).map(|i| pts[i] * (w[i] / s)).sum();
            prop_assert_eq!(locate_brute(&m, p.as_vec3()), Some(t));
        }
    }

    #[test]
    fn locate_brute_agrees_with_f64_barycentrics(m in grid_mesh(), seed in any::<u64>()) {
        let mut rng = SplitMix64(seed);
        let (lo, hi) = m.points.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), &p| (a.min(p), b.max(p)));
        for _ in 0..16 {
            let p = Vec3::new(
                rng.range_f32(lo.x - 0.5, hi.x + 0.5),
                rng.range_f32(lo.y - 0.5, hi.y + 0.5),
                rng.range_f32(lo.z - 0.5, hi.z + 0.5),
            );
            let bary = |t: u32| barycentrics(&m, t, p);
            match locate_brute(&m, p) {
                Some(t) => prop_assert!(bary(t).iter().all(|&b| b >= -1e-9), "{:?}", bary(t)),
                None => prop_assert!((0..m.tets.len() as u32).all(|t| bary(t).iter().any(|&b| b <= 1e-9))),
            }
        }
    }
}

/// Barycentric coordinates of `p` in tet `t`, in f64 (volume ratios).
fn barycentrics(m: &TetMesh, t: u32, p: Vec3) -> [f64; 4] {
    let v = m.tet_points(t).map(|q| q.as_dvec3());
    let vol = |a: DVec3, b: DVec3, c: DVec3, d: DVec3| (b - a).cross(c - a).dot(d - a);
    let total = vol(v[0], v[1], v[2], v[3]);
    let p = p.as_dvec3();
    std::array::from_fn(|i| {
        let mut w = v;
        w[i] = p;
        vol(w[0], w[1], w[2], w[3]) / total
    })
}

#[test]
fn nested_shells_make_three_regions_and_prune_to_the_middle() {
    // A 6³ grid with shells around [1,5]³ and [2,4]³: outside, between, inside.
    let mut m = kuhn_grid(&GridSpec {
        cells: [6, 6, 6],
        shell: Some(([1, 1, 1], [5, 5, 5])),
        jitter: 0.0,
        ..Default::default()
    });
    // Add the inner shell by reassembling with extra triangles.
    let inner = kuhn_grid(&GridSpec {
        cells: [6, 6, 6],
        shell: Some(([2, 2, 2], [4, 4, 4])),
        jitter: 0.0,
        ..Default::default()
    });
    let mut tris: Vec<([u32; 3], u32)> = m
        .constrained
        .iter()
        .map(|c| (c.vertices, c.triangle))
        .collect();
    let base = m.triangle_count;
    tris.extend(
        inner
            .constrained
            .iter()
            .map(|c| (c.vertices, c.triangle + base)),
    );
    m = TetMesh::assemble(m.points, m.tets, &tris, base + inner.triangle_count).unwrap();
    m.validate().unwrap();
    let r = compute_regions(&m);
    let mut sizes = r.sizes.clone();
    sizes.sort();
    assert_eq!(sizes, vec![8 * 6, (64 - 8) * 6, (216 - 64) * 6]);
    let rep = r.report();
    assert_eq!((rep.count, rep.largest, rep.smallest), (3, 912, 48));
    assert!(rep.to_string().contains("3 regions"));

    // Camera between the shells, light in the same region.
    let seeds =
        locate_seeds_brute(&m, &[Vec3::new(1.5, 3.0, 3.0), Vec3::new(4.5, 4.5, 1.5)]).unwrap();
    let report = prune_unreachable(&mut m, &seeds).unwrap();
    m.validate().unwrap();
    assert_eq!(m.tets.len(), (64 - 8) * 6);
    // Points of the 5³-point block minus the 1 interior point of the inner box.
    assert_eq!(m.points.len(), 125 - 1);
    // Both shells survive, now one-sided: 6·16·2 + 6·4·2 faces.
    assert_eq!(m.constrained.len(), 192 + 48);
    assert_eq!(report.constrained_made_one_sided, 192 + 48);
    assert_eq!(report.constrained_removed, 0);
    assert_eq!(report.regions_kept, 1);
    assert_eq!(report.regions_removed, 2);
    assert!(
        m.constrained
            .iter()
            .all(|c| c.front.exists() != c.back.exists())
    );
    assert_eq!(locate_brute(&m, Vec3::splat(3.0)), None);
    assert_eq!(locate_brute(&m, Vec3::splat(0.5)), None);
    assert!(locate_brute(&m, Vec3::new(1.5, 1.5, 1.5)).is_some());
}

#[test]
fn seed_errors_are_typed() {
    let mut m = kuhn_grid(&GridSpec::default());
    let before = m.clone();
    assert_eq!(prune_unreachable(&mut m, &[]), Err(PruneError::NoSeeds));
    assert_eq!(
        prune_unreachable(&mut m, &[u32::MAX]),
        Err(PruneError::SeedOutOfBounds {
            index: 0,
            tet: u32::MAX,
            tets: 162
        })
    );
    assert_eq!(m, before);
    assert_eq!(locate_brute(&m, Vec3::new(f32::NAN, 1.0, 1.0)), None);
    assert_eq!(locate_brute(&m, Vec3::splat(3.0001)), None);
    // A grid vertex belongs to several tets; any containing one is fine.
    let t = locate_brute(&m, Vec3::new(1.0, 1.0, 0.0)).unwrap();
    assert!(m.tet_points(t).contains(&Vec3::new(1.0, 1.0, 0.0)));
}
