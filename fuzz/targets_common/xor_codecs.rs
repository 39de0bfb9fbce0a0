// Body of the `xor_codecs` fuzz target: the compact layouts (Tet32, Tet20,
// Tet16 of Aman et al., Tet80 of Maria et al.) encode and decode exactly.
//
// From the bytes: a small jittered Kuhn grid (`tet_core::synthetic`) with
// random constrained faces or a closed shell, then relabelled — vertex ids
// permuted (with unused points mixed in), tets shuffled, each tet's slots
// rotated by an even permutation — and reassembled with `TetMesh::assemble`,
// so ids, tet order and slot order are arbitrary while the mesh stays valid.
// Properties, each against the canonical mesh as the independent reference:
//
// * whole-mesh round trips: Tet32 and Tet80 return the input exactly, Tet20
//   and Tet16 return `canonical_slot_order(input)`;
// * per tet, from every entry face (i.e. coming from every previous tet or
//   through every constrained face): the xor-sum yields the fourth vertex,
//   and the record yields the link across every exit face — Tet32 by slot,
//   Tet20 by rank, Tet16 from the entry link and its rank (two xors), Tet80
//   with the neighbour's entry face;
// * single records with arbitrary distinct ids and arbitrary link words
//   (any u32, not only valid links) decode exactly;
// * corrupted records, anchors, tables and points (and corrupted canonical
//   meshes given to the encoders) give a typed `LayoutError`, never a panic;
//   a corrupted layout that still decodes yields a mesh that validates.

use tet_core::layout::{
    LayoutError, Tet16, Tet16Mesh, Tet20, Tet20Mesh, Tet32Mesh, Tet80Face, Tet80Mesh,
    canonical_slot_order, fourth_vertex, links_by_rank, rank_of, xor_sum,
};
use tet_core::{FACE_VERTICES, Link, LinkKind, TetMesh};

use super::grid::mesh_from;
use super::input::Bytes;

/// Runs every property on the mesh and records decoded from `data`.
pub fn check(data: &[u8]) {
    let mut b = Bytes::new(data);
    let mesh = mesh_from(&mut b);
    let layouts = Layouts {
        t32: Tet32Mesh::from_mesh(&mesh).expect("tet32 encodes a valid mesh"),
        t20: Tet20Mesh::from_mesh(&mesh).expect("tet20 encodes a valid mesh"),
        t16: Tet16Mesh::from_mesh(&mesh).expect("tet16 encodes a valid mesh"),
        t80: Tet80Mesh::from_mesh(&mesh).expect("tet80 encodes a valid mesh"),
    };
    check_round_trips(&mesh, &layouts);
    check_records(&mesh, &layouts);
    check_single_records(&mut b);
    check_corruption(&mesh, layouts, &mut b);
}

/// The four encodings of one mesh.
struct Layouts {
    t32: Tet32Mesh,
    t20: Tet20Mesh,
    t16: Tet16Mesh,
    t80: Tet80Mesh,
}

fn check_round_trips(mesh: &TetMesh, l: &Layouts) {
    let canon = canonical_slot_order(mesh);
    if let Err(e) = canon.validate() {
        panic!("canonical slot order of a valid mesh is invalid: {e}");
    }
    let (t20, t16) = (&l.t20, &l.t16);
    assert!(
        l.t32.to_mesh().expect("tet32 decodes") == *mesh,
        "tet32 round trip"
    );
    assert!(
        t20.to_mesh().expect("tet20 decodes") == canon,
        "tet20 round trip"
    );
    assert!(
        t16.to_mesh().expect("tet16 decodes") == canon,
        "tet16 round trip"
    );
    assert!(
        l.t80.to_mesh().expect("tet80 decodes") == *mesh,
        "tet80 round trip"
    );
    // Re-encoding the canonical form gives the same xor records.
    assert!(Tet20Mesh::from_mesh(&canon).expect("tet20").tets == t20.tets);
    assert!(Tet16Mesh::from_mesh(&canon).expect("tet16").tets == t16.tets);
}

/// Per-record decoding from every entry face, against the canonical mesh.
fn check_records(mesh: &TetMesh, l: &Layouts) {
    let (t32, t20, t16, t80) = (&l.t32, &l.t20, &l.t16, &l.t80);
    for (t, (&ids, &links)) in mesh.tets.iter().zip(&mesh.neighbors).enumerate() {
        let r32 = t32.tets[t];
        let (r20, r16, r80) = (t20.tets[t], t16.tets[t], t80.tets[t]);
        assert_eq!(r32.vertices(), ids, "tet32 record {t} vertices");
        // `link_opposite[r]`: the link across the face opposite the vertex of
        // rank r, computed by sorting (independent of `links_by_rank`).
        let mut by_id: Vec<(u32, Link)> = ids.iter().copied().zip(links).collect();
        by_id.sort_unstable_by_key(|&(v, _)| v);
        let link_opposite: [Link; 4] = [by_id[0].1, by_id[1].1, by_id[2].1, by_id[3].1];
        for entry in 0..4 {
            // Entering through face `entry` (from the tet or constrained face
            // behind it), the kernel knows that face's three ids.
            let face = FACE_VERTICES[entry].map(|s| ids[s]);
            for vx in [r32.vx, r20.vx, r16.vx] {
                assert_eq!(fourth_vertex(vx, face), ids[entry], "tet {t} entry {entry}");
            }
            let entry_link = links[entry];
            let entry_rank = rank_of(ids[entry], ids);
            assert_eq!(link_opposite[entry_rank], entry_link);
            assert_eq!(r16.neighbors(entry_link, entry_rank), link_opposite);
            for exit in 0..4 {
                let want = links[exit];
                assert_eq!(r32.neighbor_opposite(ids[exit]), want, "tet32 {t}");
                assert_eq!(r20.neighbor_opposite(ids[exit], ids), want, "tet20 {t}");
                let want_rank = rank_of(ids[exit], ids);
                assert_eq!(
                    r16.neighbor(entry_link, entry_rank, want_rank),
                    want,
                    "tet16 {t}"
                );
            }
        }
        for k in 0..4 {
            let f = r80.f[k];
            assert_eq!(
                r80.vertex(k),
                mesh.points[ids[k] as usize],
                "tet80 {t} vertex {k}"
            );
            match links[k].kind() {
                LinkKind::Constrained(c) => assert_eq!(f.occlusion, c),
                _ => assert_eq!(f.occlusion, Tet80Face::NON_OCCLUSIVE),
            }
            match mesh.across(t as u32, k) {
                Some(side) => {
                    assert_eq!(f.neighbor_tet(), Some(side.tet), "tet80 {t} face {k}");
                    assert_eq!(f.neighbor_face(), side.face as usize, "tet80 {t} face {k}");
                }
                None => assert_eq!(f.neighbor, Tet80Face::NO_NEIGHBOR, "tet80 {t} face {k}"),
            }
        }
    }
}

/// Single records with arbitrary distinct ids and arbitrary link words.
fn check_single_records(b: &mut Bytes) {
    for _ in 0..4 {
        let ids = [b.u32(), b.u32(), b.u32(), b.u32()];
        let links = [b.u32(), b.u32(), b.u32(), b.u32()].map(Link);
        let distinct = (0..4).all(|i| (0..4).all(|j| i == j || ids[i] != ids[j]));
        if !distinct {
            continue;
        }
        let vx = xor_sum(ids);
        let (r20, r16) = (Tet20::encode(ids, links), Tet16::encode(ids, links));
        assert_eq!(links_by_rank(ids, links), r20.n);
        for entry in 0..4 {
            let face = FACE_VERTICES[entry].map(|s| ids[s]);
            assert_eq!(fourth_vertex(vx, face), ids[entry]);
            let entry_rank = rank_of(ids[entry], ids);
            assert_eq!(r16.neighbors(links[entry], entry_rank), r20.n);
            for exit in 0..4 {
                assert_eq!(r20.neighbor_opposite(ids[exit], ids), links[exit]);
                let want_rank = rank_of(ids[exit], ids);
                assert_eq!(
                    r16.neighbor(links[entry], entry_rank, want_rank),
                    links[exit]
                );
            }
        }
    }
}

/// Xors `mask` into 32-bit word `at` (taken modulo the length) of `words`.
fn flip(words: &mut [u32], at: u32, mask: u32) {
    if !words.is_empty() {
        let i = at as usize % words.len();
        words[i] ^= mask;
    }
}

/// A decode of corrupted data: a typed error, or a mesh that validates.
fn decoded(result: Result<TetMesh, LayoutError>) {
    match result {
        Ok(m) => {
            if let Err(e) = m.validate() {
                panic!("corrupted layout decoded to an invalid mesh: {e}");
            }
        }
        Err(e) => {
            let _ = e.to_string();
        }
    }
}

fn check_corruption(mesh: &TetMesh, l: Layouts, b: &mut Bytes) {
    let rounds = 1 + b.below(3);
    let Layouts {
        mut t32,
        mut t20,
        mut t16,
        mut t80,
    } = l;
    let mut bad = mesh.clone();
    for _ in 0..rounds {
        let (what, at, mask) = (b.u8() % 10, b.u32(), b.u32().max(1));
        match what {
            0 => flip(bytemuck::cast_slice_mut(&mut t32.tets), at, mask),
            1 => flip(bytemuck::cast_slice_mut(&mut t20.tets), at, mask),
            2 => flip(bytemuck::cast_slice_mut(&mut t16.tets), at, mask),
            3 => flip(bytemuck::cast_slice_mut(&mut t80.tets), at, mask),
            4 => flip(bytemuck::cast_slice_mut(&mut t20.anchors), at, mask),
            5 => flip(bytemuck::cast_slice_mut(&mut t16.anchors), at, mask),
            6 => flip(bytemuck::cast_slice_mut(&mut t32.constrained), at, mask),
            7 => flip(bytemuck::cast_slice_mut(&mut t16.points), at, mask),
            8 => flip(bytemuck::cast_slice_mut(&mut bad.tets), at, mask),
            _ => flip(bytemuck::cast_slice_mut(&mut bad.neighbors), at, mask),
        }
    }
    decoded(t32.to_mesh());
    decoded(t20.to_mesh());
    decoded(t16.to_mesh());
    decoded(t80.to_mesh());
    // Encoders validate first: a corrupted canonical mesh is refused or,
    // when it is still valid, round-trips.
    match Tet32Mesh::from_mesh(&bad) {
        Ok(l) => assert!(l.to_mesh().expect("valid mesh decodes") == bad),
        Err(e) => assert!(matches!(e, LayoutError::InvalidMesh { .. }), "{e}"),
    }
    decoded(Tet16Mesh::from_mesh(&bad).and_then(|l| l.to_mesh()));
    decoded(Tet20Mesh::from_mesh(&bad).and_then(|l| l.to_mesh()));
    decoded(Tet80Mesh::from_mesh(&bad).and_then(|l| l.to_mesh()));
}
