//! Memory accounting: the report equals independently computed
//! `len × size` sums with literal record sizes, and equals what each built
//! container reports.

use std::collections::VecDeque;

use glam::{Vec2, Vec3};
use proptest::prelude::*;
use tet_core::layout::{Baseline32Mesh, Tet16Mesh, Tet20Mesh, Tet32Mesh, Tet80Mesh};
use tet_core::memory::{LAYOUT_NAMES, LayoutMemory, MemoryReport};
use tet_core::synthetic::{GridSpec, kuhn_grid};
use tet_core::{Attributes, TetMesh};

/// Connected components by breadth-first search over `TetMesh::across`
/// (shared faces and two-sided constrained faces).
fn components(m: &TetMesh) -> usize {
    let mut seen = vec![false; m.tets.len()];
    let mut count = 0;
    for s in 0..m.tets.len() {
        if seen[s] {
            continue;
        }
        count += 1;
        seen[s] = true;
        let mut q = VecDeque::from([s as u32]);
        while let Some(t) = q.pop_front() {
            for k in 0..4 {
                if let Some(side) = m.across(t, k)
                    && !seen[side.tet as usize]
                {
                    seen[side.tet as usize] = true;
                    q.push_back(side.tet);
                }
            }
        }
    }
    count
}

/// Expected bytes with the record sizes written out: 32/32/20/16/80 per tet,
/// 12 per point, 32 per constrained face, 36 per anchor, 16 per Tet80 id row;
/// attributes 12 per normal, 8 per uv, 4 per material.
fn expected(m: &TetMesh) -> Vec<LayoutMemory> {
    let (t, p, c, a) = (
        m.tets.len(),
        m.points.len(),
        m.constrained.len(),
        components(m),
    );
    let attrs = m.attributes.normals.as_ref().map_or(0, |v| 12 * v.len())
        + m.attributes.uvs.as_ref().map_or(0, |v| 8 * v.len())
        + m.attributes.materials.as_ref().map_or(0, |v| 4 * v.len());
    let xor = |name, rec: usize, anchors: usize| LayoutMemory {
        name,
        tets: rec * t,
        points: 12 * p,
        constrained: 32 * c,
        attributes: attrs,
        anchors: 36 * anchors,
        reconstruction: 0,
    };
    vec![
        xor("baseline32", 32, 0),
        xor("tet32", 32, 0),
        xor("tet20", 20, a),
        xor("tet16", 16, a),
        LayoutMemory {
            name: "tet80",
            tets: 80 * t,
            points: 0,
            constrained: 32 * c,
            attributes: attrs,
            anchors: 0,
            reconstruction: 12 * p + 16 * t,
        },
    ]
}

fn check(m: &TetMesh) {
    let report = MemoryReport::for_mesh(m);
    let want = expected(m);
    assert_eq!(report.layouts, want);
    assert_eq!(report.tet_count, m.tets.len());
    assert_eq!(report.point_count, m.points.len());
    assert_eq!(report.constrained_count, m.constrained.len());
    assert_eq!(report.component_count, components(m));
    assert_eq!(
        report.layouts.iter().map(|l| l.name).collect::<Vec<_>>(),
        LAYOUT_NAMES.to_vec()
    );
    let built = [
        Baseline32Mesh::from_mesh(m).unwrap().memory(),
        Tet32Mesh::from_mesh(m).unwrap().memory(),
        Tet20Mesh::from_mesh(m).unwrap().memory(),
        Tet16Mesh::from_mesh(m).unwrap().memory(),
        Tet80Mesh::from_mesh(m).unwrap().memory(),
    ];
    for b in built {
        assert_eq!(Some(&b), report.get(b.name), "{}", b.name);
        assert_eq!(b.hot() + b.cold(), b.total());
    }
    // hot = tets + points; cold = everything else.
    for (l, w) in report.layouts.iter().zip(&want) {
        assert_eq!(l.hot(), w.tets + w.points);
        assert_eq!(
            l.cold(),
            w.constrained + w.attributes + w.anchors + w.reconstruction
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn report_matches_independent_sums(
        cells in prop::array::uniform3(1u32..=4),
        jitter in 0.0f32..0.15,
        frac in 0.0f64..0.8,
        seed in any::<u64>(),
        normals in any::<bool>(),
        uvs in any::<bool>(),
        materials in any::<bool>(),
    ) {
        let mut m = kuhn_grid(&GridSpec {
            cells,
            jitter,
            constrained_fraction: frac,
            seed,
            ..Default::default()
        });
        let n = m.points.len();
        m.attributes = Attributes {
            normals: normals.then(|| vec![Vec3::Z; n]),
            uvs: uvs.then(|| vec![Vec2::ONE; n]),
            materials: materials.then(|| vec![0; m.triangle_count as usize]),
            scalars: None,
        };
        check(&m);
    }
}

#[test]
fn absent_attributes_cost_nothing_and_components_count() {
    let m = kuhn_grid(&GridSpec {
        cells: [2, 1, 1],
        ..Default::default()
    });
    let r = MemoryReport::for_mesh(&m);
    // 2 cubes × 6 tets, 3 × 2 × 2 points, no constrained faces, 1 component.
    let t16 = r.get("tet16").unwrap();
    assert_eq!(t16.tets, 12 * 16);
    assert_eq!(t16.points, 12 * 12);
    assert_eq!(t16.attributes, 0);
    assert_eq!(t16.constrained, 0);
    assert_eq!(t16.anchors, 36);
    assert_eq!(r.get("tet80").unwrap().hot(), 12 * 80);
    assert_eq!(r.get("baseline32").unwrap().total(), 12 * 32 + 12 * 12);
    assert!(r.get("tet64").is_none());
    // Display names every layout.
    let text = r.to_string();
    for name in LAYOUT_NAMES {
        assert!(text.contains(name));
    }
    check(&m);
}

#[test]
fn empty_mesh_reports_zero() {
    let m = TetMesh::default();
    let r = MemoryReport::for_mesh(&m);
    assert!(r.layouts.iter().all(|l| l.total() == 0));
    assert_eq!(r.component_count, 0);
}
