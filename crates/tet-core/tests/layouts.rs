//! Layout tests: xor decoding, rank-ordered neighbours, Tet16 decoding from
//! every entry, exact round trips, sizes, hand-built edge cases and errors.
//! The reference is always the canonical `TetMesh` (or a brute-force
//! computation), never the code under test.

// Face/slot indices are the subject of these tests: index loops read best.
#![allow(clippy::needless_range_loop)]

use glam::Vec3;
use proptest::prelude::*;
use tet_core::layout::{
    Anchor, Baseline32, Baseline32Mesh, LayoutError, Tet16, Tet16Mesh, Tet20, Tet20Mesh, Tet32,
    Tet32Mesh, Tet80, Tet80Face, Tet80Mesh, canonical_permutation, canonical_slot_order,
    canonical_tet_from_ids, fourth_vertex, rank_of, sort4, xor_sum,
};
use tet_core::predicates::orient3d_f32;
use tet_core::synthetic::{GridSpec, kuhn_grid};
use tet_core::{Attributes, Link, MAX_TETS, TetMesh};

fn grid(cells: [u32; 3], jitter: f32, frac: f64, shell: bool, seed: u64) -> TetMesh {
    let shell = (shell && cells.iter().all(|&c| c >= 2)).then_some(([1, 1, 1], cells));
    kuhn_grid(&GridSpec {
        cells,
        jitter,
        constrained_fraction: frac,
        shell,
        seed,
        ..Default::default()
    })
}

fn mesh_strategy() -> impl Strategy<Value = TetMesh> {
    (
        prop::array::uniform3(1u32..=4),
        0.0f32..0.15,
        prop_oneof![Just(0.0f64), 0.0f64..0.7, Just(1.0f64)],
        any::<bool>(),
        any::<u64>(),
    )
        .prop_map(|(cells, jitter, frac, shell, seed)| grid(cells, jitter, frac, shell, seed))
}

/// Two tets sharing face (0,1,2): apex 3 above z = 0, apex 4 below.
fn bipyramid(constrained_shared: bool, constrained_boundary: bool) -> TetMesh {
    let points = vec![
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.2, 0.2, 1.0),
        Vec3::new(0.2, 0.2, -1.0),
    ];
    let mut tris = Vec::new();
    if constrained_shared {
        tris.push(([0, 1, 2], 0));
    }
    if constrained_boundary {
        tris.push(([0, 1, 3], 1));
    }
    TetMesh::assemble(points, vec![[0, 1, 2, 3], [1, 0, 2, 4]], &tris, 2).unwrap()
}

/// Two tets far apart: two connected components.
fn two_islands() -> TetMesh {
    let mut points = Vec::new();
    for off in [0.0f32, 10.0] {
        points.extend([
            Vec3::new(off, 0.0, 0.0),
            Vec3::new(off + 1.0, 0.0, 0.0),
            Vec3::new(off, 1.0, 0.0),
            Vec3::new(off, 0.0, 1.0),
        ]);
    }
    TetMesh::assemble(
        points,
        vec![[4, 5, 6, 7], [0, 1, 2, 3]],
        &[([4, 5, 7], 0)],
        1,
    )
    .unwrap()
}

/// Independent "same tetrahedralization up to slot order" check.
fn assert_same_modulo_slots(a: &TetMesh, b: &TetMesh) {
    assert_eq!(a.points, b.points);
    assert_eq!(a.tets.len(), b.tets.len());
    assert_eq!(a.triangle_count, b.triangle_count);
    assert_eq!(a.attributes, b.attributes);
    for t in 0..a.tets.len() {
        let mut sa = a.tets[t];
        let mut sb = b.tets[t];
        sa.sort_unstable();
        sb.sort_unstable();
        assert_eq!(sa, sb, "tet {t} vertex set");
        for k in 0..4 {
            let v = a.tets[t][k];
            let j = b.tets[t].iter().position(|&w| w == v).unwrap();
            assert_eq!(
                a.neighbors[t][k], b.neighbors[t][j],
                "tet {t} link opposite {v}"
            );
        }
    }
    assert_eq!(a.constrained.len(), b.constrained.len());
    for (ca, cb) in a.constrained.iter().zip(&b.constrained) {
        assert_eq!(ca.triangle, cb.triangle);
        assert_eq!(ca.vertices, cb.vertices);
        for (sa, sb) in [(ca.front, cb.front), (ca.back, cb.back)] {
            assert_eq!(sa.tet, sb.tet);
            if sa.exists() {
                let va = a.tets[sa.tet as usize][sa.face as usize];
                let vb = b.tets[sb.tet as usize][sb.face as usize];
                assert_eq!(va, vb, "constrained side opposite vertex");
            }
        }
    }
}

fn check_all_layouts(mesh: &TetMesh) {
    // Sanity of the reference itself.
    mesh.validate().unwrap();
    let canon = canonical_slot_order(mesh);
    canon.validate().unwrap();
    assert_same_modulo_slots(mesh, &canon);
    assert_eq!(canonical_slot_order(&canon), canon, "idempotent");

    // xor reconstruction of the fourth vertex from every face of every tet,
    // through each xor layout's stored VX.
    let t32 = Tet32Mesh::from_mesh(mesh).unwrap();
    let t20 = Tet20Mesh::from_mesh(mesh).unwrap();
    let t16 = Tet16Mesh::from_mesh(mesh).unwrap();
    for (t, tet) in mesh.tets.iter().enumerate() {
        for k in 0..4 {
            let face = mesh.face_vertices(t as u32, k);
            for vx in [t32.tets[t].vx, t20.tets[t].vx, t16.tets[t].vx] {
                assert_eq!(fourth_vertex(vx, face), tet[k]);
            }
        }
        assert_eq!(t32.tets[t].vertices(), *tet);
    }

    // Tet32 (Algorithm 3) and Tet20 (rank order) neighbour lookups.
    for (t, tet) in mesh.tets.iter().enumerate() {
        for k in 0..4 {
            let want = mesh.neighbors[t][k];
            assert_eq!(t32.tets[t].neighbor_opposite(tet[k]), want);
            assert_eq!(t20.tets[t].neighbor_opposite(tet[k], *tet), want);
            // Reference rank: position in a sorted copy.
            let mut s = *tet;
            s.sort_unstable();
            let r = s.iter().position(|&v| v == tet[k]).unwrap();
            assert_eq!(t20.tets[t].neighbor_by_rank(r), want);
        }
    }

    // Tet16: from every possible entry face (its link as seen from this tet)
    // every link decodes to the canonical one.
    for (t, tet) in mesh.tets.iter().enumerate() {
        let rec = t16.tets[t];
        for e in 0..4 {
            let entry = mesh.neighbors[t][e];
            let er = rank_of(tet[e], *tet);
            for w in 0..4 {
                let wr = rank_of(tet[w], *tet);
                assert_eq!(rec.neighbor(entry, er, wr), mesh.neighbors[t][w]);
            }
        }
    }
    // ...and from the previous tet's point of view: walking from t across
    // face k (crossing constrained faces via the table) into m, decoding m
    // with the entry link Link::tet(t) (or the constrained link) gives m's links.
    for t in 0..mesh.tets.len() {
        for k in 0..4 {
            let Some(side) = mesh.across(t as u32, k) else {
                continue;
            };
            let m = side.tet as usize;
            let link = mesh.neighbors[t][k];
            let entry = if link.is_constrained() {
                link
            } else {
                Link::tet(t as u32)
            };
            let ids = mesh.tets[m];
            // The new vertex from the shared face + m's VX.
            let face = mesh.face_vertices(t as u32, k);
            let apex = fourth_vertex(t16.tets[m].vx, face);
            assert_eq!(apex, ids[side.face as usize]);
            let er = rank_of(apex, ids);
            let decoded = t16.tets[m].neighbors(entry, er);
            for w in 0..4 {
                assert_eq!(decoded[rank_of(ids[w], ids)], mesh.neighbors[m][w]);
            }
        }
    }

    // Round trips.
    assert_eq!(
        &Baseline32Mesh::from_mesh(mesh).unwrap().to_mesh().unwrap(),
        mesh
    );
    assert_eq!(&t32.to_mesh().unwrap(), mesh);
    assert_eq!(
        &Tet80Mesh::from_mesh(mesh).unwrap().to_mesh().unwrap(),
        mesh
    );
    let d20 = t20.to_mesh().unwrap();
    let d16 = t16.to_mesh().unwrap();
    assert_eq!(d20, canon);
    assert_eq!(d16, canon);
    assert_same_modulo_slots(mesh, &d20);
    assert_same_modulo_slots(mesh, &d16);
    // A canonical input round-trips exactly through every layout.
    assert_eq!(
        Tet20Mesh::from_mesh(&canon).unwrap().to_mesh().unwrap(),
        canon
    );
    assert_eq!(
        Tet16Mesh::from_mesh(&canon).unwrap().to_mesh().unwrap(),
        canon
    );

    // Tet80 faces against the canonical mesh.
    let t80 = Tet80Mesh::from_mesh(mesh).unwrap();
    for (t, tet) in mesh.tets.iter().enumerate() {
        let rec = &t80.tets[t];
        for k in 0..4 {
            assert_eq!(rec.vertex(k), mesh.points[tet[k] as usize]);
            let f = rec.f[k];
            assert_eq!(
                f.is_occlusive(),
                mesh.neighbors[t][k].is_constrained(),
                "tet {t} face {k}"
            );
            if let Some(c) = mesh.neighbors[t][k].as_constrained() {
                assert_eq!(f.occlusion, c);
            }
            match mesh.across(t as u32, k) {
                Some(side) => {
                    assert_eq!(f.neighbor_tet(), Some(side.tet));
                    assert_eq!(f.neighbor_face(), side.face as usize);
                }
                None => assert_eq!(f.neighbor_tet(), None),
            }
        }
    }

    // Anchors: fully decoded tets of the canonical mesh.
    for a in &t20.anchors {
        assert_eq!(a.vertices, canon.tets[a.tet as usize]);
        assert_eq!(a.neighbors, canon.neighbors[a.tet as usize]);
        // Starting a walk at the anchor: Tet20 reads, Tet16 decodes its links.
        let (entry, rank) = a.tet16_entry();
        let by_rank = t16.tets[a.tet as usize].neighbors(entry, rank);
        assert_eq!(by_rank, t20.tets[a.tet as usize].n);
        for k in 0..4 {
            assert_eq!(by_rank[rank_of(a.vertices[k], a.vertices)], a.neighbors[k]);
        }
    }
    assert_eq!(t20.anchors, t16.anchors);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn layouts_agree_with_canonical_mesh(mesh in mesh_strategy()) {
        check_all_layouts(&mesh);
    }

    #[test]
    fn rank_and_sort_match_brute_force(v in prop::array::uniform4(any::<u32>())) {
        let mut s = v;
        s.sort_unstable();
        prop_assert_eq!(sort4(v), s);
        let mut d = s.to_vec();
        d.dedup();
        if d.len() == 4 {
            for x in v {
                prop_assert_eq!(rank_of(x, v), s.iter().position(|&y| y == x).unwrap());
            }
        }
        for k in 0..4 {
            let face: Vec<u32> = (0..4).filter(|&j| j != k).map(|j| v[j]).collect();
            prop_assert_eq!(fourth_vertex(xor_sum(v), [face[0], face[1], face[2]]), v[k]);
        }
    }

    #[test]
    fn tet16_decodes_arbitrary_link_words(
        ids in prop::array::uniform4(any::<u32>()),
        raw in prop::array::uniform4(any::<u32>()),
    ) {
        let mut d = ids.to_vec();
        d.sort_unstable();
        d.dedup();
        prop_assume!(d.len() == 4);
        let links = raw.map(Link);
        let rec = Tet16::encode(ids, links);
        let t20 = Tet20::encode(ids, links);
        for e in 0..4 {
            for w in 0..4 {
                prop_assert_eq!(
                    rec.neighbor(links[e], rank_of(ids[e], ids), rank_of(ids[w], ids)),
                    links[w]
                );
            }
            prop_assert_eq!(t20.neighbor_opposite(ids[e], ids), links[e]);
        }
    }
}

#[test]
fn record_sizes_are_exact() {
    assert_eq!(size_of::<Baseline32>(), 32);
    assert_eq!(size_of::<Tet32>(), 32);
    assert_eq!(size_of::<Tet20>(), 20);
    assert_eq!(size_of::<Tet16>(), 16);
    assert_eq!(size_of::<Tet80>(), 80);
    assert_eq!(size_of::<Tet80Face>(), 8);
    assert_eq!(size_of::<Anchor>(), 36);
    // Pod: a slice of records casts to bytes of exactly len × size.
    let recs = [Tet16::encode([1, 2, 3, 4], [Link::BOUNDARY; 4]); 3];
    assert_eq!(bytemuck::cast_slice::<Tet16, u8>(&recs).len(), 48);
}

#[test]
fn hand_built_meshes_round_trip() {
    for mesh in [
        bipyramid(false, false),
        bipyramid(true, false),
        bipyramid(true, true),
        bipyramid(false, true),
        two_islands(),
        TetMesh::default(),
    ] {
        check_all_layouts(&mesh);
    }
}

#[test]
fn tet80_bipyramid_faces_by_hand() {
    let m = bipyramid(true, true);
    // Shared face (0,1,2) is face 3 of both tets and constrained face 0;
    // face (0,1,3) of tet 0 is face 2 (opposite vertex 2) and constrained face 1.
    let t80 = Tet80Mesh::from_mesh(&m).unwrap();
    let f = t80.tets[0].f;
    assert_eq!(
        f[3],
        Tet80Face {
            occlusion: 0,
            neighbor: (1 << 2) | 3
        }
    );
    assert_eq!(
        f[2],
        Tet80Face {
            occlusion: 1,
            neighbor: Tet80Face::NO_NEIGHBOR
        }
    );
    for k in [0, 1] {
        assert_eq!(
            f[k],
            Tet80Face {
                occlusion: Tet80Face::NON_OCCLUSIVE,
                neighbor: Tet80Face::NO_NEIGHBOR
            }
        );
    }
    assert_eq!(
        t80.tets[1].f[3],
        Tet80Face {
            occlusion: 0,
            neighbor: 3
        }
    );
    assert_eq!(t80.tets[0].v[3], [0.2, 0.2, 1.0]);
}

#[test]
fn xor_handles_ids_and_links_near_u32_limits() {
    let ids = [u32::MAX, u32::MAX - 1, 0x8000_0000, 0];
    let links = [
        Link::constrained(MAX_TETS - 1),
        Link::BOUNDARY,
        Link::tet(MAX_TETS - 1),
        Link::constrained(0),
    ];
    let t32 = Tet32 {
        v: [ids[0], ids[1], ids[2]],
        vx: xor_sum(ids),
        n: links,
    };
    assert_eq!(t32.v3(), 0);
    assert_eq!(t32.vertices(), ids);
    for k in 0..4 {
        assert_eq!(t32.neighbor_opposite(ids[k]), links[k]);
    }
    // Ranks by hand: 0 < 0x8000_0000 < MAX-1 < MAX.
    assert_eq!(ids.map(|v| rank_of(v, ids)), [3, 2, 1, 0]);
    let t20 = Tet20::encode(ids, links);
    assert_eq!(t20.n, [links[3], links[2], links[1], links[0]]);
    let t16 = Tet16::encode(ids, links);
    // NX_k = N_k ⊕ N_3 in rank order, N_3 = links[0].
    assert_eq!(
        t16.nx,
        [
            links[3].0 ^ links[0].0,
            links[2].0 ^ links[0].0,
            links[1].0 ^ links[0].0
        ]
    );
    for e in 0..4 {
        let all = t16.neighbors(links[e], rank_of(ids[e], ids));
        assert_eq!(all, t20.n, "entry slot {e}");
        // Flags survive: the decoded words classify as the originals.
        assert!(all[3].is_constrained() && all[2].is_boundary() && all[1].as_tet().is_some());
    }
    for face in [[u32::MAX, 0, 1], [u32::MAX, u32::MAX - 1, u32::MAX - 2]] {
        for apex in [0u32, 7, u32::MAX - 3, 0x7FFF_FFFF] {
            let vx = xor_sum([face[0], face[1], face[2], apex]);
            assert_eq!(fourth_vertex(vx, face), apex);
            assert_eq!(fourth_vertex(vx, [face[2], face[0], face[1]]), apex);
        }
    }
}

#[test]
fn canonical_order_is_an_even_permutation_and_positive() {
    // A positively oriented tet in all 12 even slot orders.
    let points = vec![
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
    ];
    let base = [0u32, 1, 2, 3];
    let mut seen = 0;
    for a in 0..4 {
        for b in 0..4 {
            for c in 0..4 {
                for d in 0..4 {
                    let v = [base[a], base[b], base[c], base[d]];
                    let mut s = v;
                    s.sort_unstable();
                    if s != base {
                        continue;
                    }
                    let p = v.map(|i| points[i as usize]);
                    let positive = orient3d_f32(p[0], p[1], p[2], p[3]) > 0.0;
                    let perm = canonical_permutation(v);
                    let out = perm.map(|i| v[i]);
                    let q = out.map(|i| points[i as usize]);
                    if positive {
                        seen += 1;
                        assert!(orient3d_f32(q[0], q[1], q[2], q[3]) > 0.0, "{v:?}");
                        assert_eq!(out, [0, 1, 2, 3]);
                    }
                    assert_eq!(canonical_tet_from_ids(v, &points), Some([0, 1, 2, 3]));
                }
            }
        }
    }
    assert_eq!(seen, 12);
    // Coplanar ids and ids out of bounds are rejected.
    let flat = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
    assert_eq!(canonical_tet_from_ids([0, 1, 2, 3], &flat), None);
    assert_eq!(canonical_tet_from_ids([0, 1, 2, 9], &flat), None);
}

#[test]
fn attributes_survive_round_trips() {
    let mut m = grid([2, 2, 1], 0.1, 0.3, false, 9);
    let n = m.points.len();
    m.attributes = Attributes {
        normals: Some((0..n).map(|i| Vec3::new(i as f32, 1.0, 0.0)).collect()),
        uvs: None,
        materials: Some(vec![7; m.triangle_count as usize]),
        scalars: None,
    };
    check_all_layouts(&m);
}

#[test]
fn invalid_input_is_rejected_with_layout_name() {
    let mut m = bipyramid(false, false);
    m.tets[0].swap(0, 1); // negative orientation
    for (name, err) in [
        ("baseline32", Baseline32Mesh::from_mesh(&m).err()),
        ("tet32", Tet32Mesh::from_mesh(&m).err()),
        ("tet20", Tet20Mesh::from_mesh(&m).err()),
        ("tet16", Tet16Mesh::from_mesh(&m).err()),
        ("tet80", Tet80Mesh::from_mesh(&m).err()),
    ] {
        match err {
            Some(LayoutError::InvalidMesh { layout, .. }) => assert_eq!(layout, name),
            other => panic!("{name}: expected InvalidMesh, got {other:?}"),
        }
    }
}

#[test]
fn corrupt_layout_data_is_reported_not_decoded() {
    let m = grid([2, 2, 2], 0.1, 0.2, false, 3);
    // Tet20 without anchors: nothing is reachable.
    let mut t20 = Tet20Mesh::from_mesh(&m).unwrap();
    t20.anchors.clear();
    assert!(matches!(
        t20.to_mesh(),
        Err(LayoutError::Corrupt {
            layout: "tet20",
            element: "tet",
            index: 0,
            ..
        })
    ));
    // Anchor that disagrees with its tet's xor-sum.
    let mut t20 = Tet20Mesh::from_mesh(&m).unwrap();
    t20.anchors[0].vertices[0] ^= 1;
    assert!(matches!(
        t20.to_mesh(),
        Err(LayoutError::Corrupt {
            element: "anchor",
            index: 0,
            ..
        })
    ));
    // Anchor out of bounds.
    let mut t16 = Tet16Mesh::from_mesh(&m).unwrap();
    t16.anchors[0].tet = 10_000;
    assert!(matches!(
        t16.to_mesh(),
        Err(LayoutError::Corrupt {
            element: "anchor",
            ..
        })
    ));
    // A flipped xor-difference in one Tet16 record.
    for t in [0usize, 5, 20] {
        let mut t16 = Tet16Mesh::from_mesh(&m).unwrap();
        t16.tets[t].nx[1] ^= 1 << 3;
        assert!(t16.to_mesh().is_err(), "tet {t}");
    }
    // A wrong xor-sum in one Tet20 record.
    let mut t20 = Tet20Mesh::from_mesh(&m).unwrap();
    t20.tets[7].vx ^= 1;
    assert!(t20.to_mesh().is_err());
    // Tet80: an inline position that disagrees with the point array.
    let mut t80 = Tet80Mesh::from_mesh(&m).unwrap();
    t80.tets[4].v[2][1] += 0.5;
    assert!(matches!(
        t80.to_mesh(),
        Err(LayoutError::Corrupt {
            layout: "tet80",
            element: "tet",
            index: 4,
            ..
        })
    ));
    // Tet80: wrong neighbour face index.
    let mut t80 = Tet80Mesh::from_mesh(&m).unwrap();
    let k = (0..4)
        .find(|&k| t80.tets[0].f[k].neighbor_tet().is_some())
        .unwrap();
    t80.tets[0].f[k].neighbor ^= 1;
    assert!(t80.to_mesh().is_err());
    // Tet80: vertex id array of the wrong length.
    let mut t80 = Tet80Mesh::from_mesh(&m).unwrap();
    t80.vertex_ids.pop();
    assert!(matches!(
        t80.to_mesh(),
        Err(LayoutError::LengthMismatch {
            array: "vertex_ids",
            ..
        })
    ));
    // Tet32: a wrong link makes the decoded mesh invalid.
    let mut t32 = Tet32Mesh::from_mesh(&m).unwrap();
    t32.tets[0].n[0] = Link::tet(1_000_000);
    assert!(matches!(
        t32.to_mesh(),
        Err(LayoutError::DecodedInvalid {
            layout: "tet32",
            ..
        })
    ));
}

#[test]
fn anchors_one_per_component() {
    let m = two_islands();
    let t16 = Tet16Mesh::from_mesh(&m).unwrap();
    assert_eq!(t16.anchors.len(), 2);
    assert_eq!(
        t16.anchors.iter().map(|a| a.tet).collect::<Vec<_>>(),
        vec![0, 1]
    );
    // The shared face of the bipyramid joins it even when constrained.
    assert_eq!(
        Tet20Mesh::from_mesh(&bipyramid(true, false))
            .unwrap()
            .anchors
            .len(),
        1
    );
    // A closed constrained shell is still one component (two-sided faces).
    let m = grid([4, 4, 4], 0.1, 0.0, true, 2);
    assert_eq!(Tet16Mesh::from_mesh(&m).unwrap().anchors.len(), 1);
}

#[test]
fn decode_uses_constrained_faces_between_regions() {
    // Every face constrained: the walk must cross each via the table.
    let m = grid([3, 2, 2], 0.12, 1.0, false, 11);
    assert!(m.neighbors.iter().flatten().all(|l| l.as_tet().is_none()));
    check_all_layouts(&m);
}

/// A larger mesh (48k tets, under a second in debug) through every layout.
#[test]
fn large_grid_round_trips() {
    let m = grid([20, 20, 20], 0.14, 0.05, true, 77);
    let canon = canonical_slot_order(&m);
    assert_eq!(Baseline32Mesh::from_mesh(&m).unwrap().to_mesh().unwrap(), m);
    assert_eq!(Tet32Mesh::from_mesh(&m).unwrap().to_mesh().unwrap(), m);
    assert_eq!(Tet80Mesh::from_mesh(&m).unwrap().to_mesh().unwrap(), m);
    assert_eq!(Tet20Mesh::from_mesh(&m).unwrap().to_mesh().unwrap(), canon);
    assert_eq!(Tet16Mesh::from_mesh(&m).unwrap().to_mesh().unwrap(), canon);
    println!("{}", tet_core::memory::MemoryReport::for_mesh(&m));
}
