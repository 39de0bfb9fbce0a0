//! The implicit BVH's packets, refit and time steps against its own
//! single-ray traversal and a rebuild (independent paths through the code),
//! and its structure against brute-force bounds.

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};
use tet_trace_cpu::Ray;
use tet_trace_cpu::iso::ibvh::LEAF_SIZE;
use tet_trace_cpu::iso::{BuildKind, ClipBox, ClipMode, Ibvh, IsoError, IsoQuery, IsoStats};

fn grid(n: u32) -> TetMesh {
    kuhn_grid(&GridSpec {
        cells: [n; 3],
        jitter: 0.12,
        seed: 3,
        ..Default::default()
    })
}

/// Sum of Gaussians whose centres drift with `time`.
fn field(mesh: &TetMesh, time: f32) -> Vec<f32> {
    let c = [
        Vec3::new(2.0 + time, 3.0, 3.5),
        Vec3::new(5.0, 4.0 - time, 3.0),
        Vec3::new(4.0, 5.0, 5.0 + 0.5 * time),
    ];
    mesh.points
        .iter()
        .map(|p| {
            c.iter()
                .map(|q| (-p.distance_squared(*q) / 2.0).exp())
                .sum()
        })
        .collect()
}

/// A pinhole camera's rays, tile by tile (16 × 16 tiles, row-major inside).
fn camera_tiles(eye: Vec3, look: Vec3, res: usize) -> Vec<Ray> {
    let fwd = (look - eye).normalize();
    let right = fwd.cross(Vec3::Z).normalize();
    let up = right.cross(fwd);
    let mut rays = Vec::new();
    for ty in (0..res).step_by(16) {
        for tx in (0..res).step_by(16) {
            for y in ty..ty + 16 {
                for x in tx..tx + 16 {
                    let u = (x as f32 + 0.5) / res as f32 * 2.0 - 1.0;
                    let v = (y as f32 + 0.5) / res as f32 * 2.0 - 1.0;
                    rays.push(Ray::new(eye, fwd + right * u * 0.25 + up * v * 0.25));
                }
            }
        }
    }
    rays
}

#[test]
fn packets_equal_single_rays_bit_for_bit() {
    let mesh = grid(8);
    let values = field(&mesh, 0.0);
    let bvh = Ibvh::build_bih(&mesh, &values).unwrap();
    let isos = [0.25, 0.6];
    let clip = ClipBox {
        lo: Vec3::new(0.0, 0.0, 4.0),
        hi: Vec3::splat(9.0),
        mode: ClipMode::CutAway,
    };
    let mut rays = camera_tiles(Vec3::new(14.0, -6.0, 10.0), Vec3::splat(4.0), 64);
    // Incoherent rays and rays from inside, too.
    let mut r = SplitMix64(5);
    for _ in 0..512 {
        let o = Vec3::new(
            r.range_f32(0.5, 7.5),
            r.range_f32(0.5, 7.5),
            r.range_f32(0.5, 7.5),
        );
        let d = Vec3::new(
            r.range_f32(-1.0, 1.0),
            r.range_f32(-1.0, 1.0),
            r.range_f32(-1.0, 1.0),
        );
        rays.push(Ray {
            t_min: 0.1,
            t_max: 5.0,
            ..Ray::new(o, d)
        });
    }
    for q in [
        IsoQuery::new(&isos),
        IsoQuery::new(&isos[..1]).with_clip(clip),
    ] {
        let mut out = vec![None; rays.len()];
        let mut ps = IsoStats::default();
        bvh.trace_packet_stats(&rays, &q, &mut out, &mut ps);
        let mut ss = IsoStats::default();
        let mut hits = 0;
        for (ray, got) in rays.iter().zip(&out) {
            let want = bvh.trace_stats(ray, &q, &mut ss);
            assert_eq!(*got, want, "packet vs single on {ray:?}");
            hits += want.is_some() as usize;
        }
        assert!(hits > 300, "{hits} hits");
        // Packets share node visits and isopolygon builds.
        assert!(ps.nodes_visited < ss.nodes_visited, "{ps:?} vs {ss:?}");
        assert!(ps.isopolygons < ss.isopolygons, "{ps:?} vs {ss:?}");
        let mut occ = vec![false; rays.len()];
        bvh.occluded_packet(&rays, &q, &mut occ);
        for ((ray, o), h) in rays.iter().zip(&occ).zip(&out) {
            assert_eq!(*o, h.is_some(), "shadow packet on {ray:?}");
            assert_eq!(bvh.occluded(ray, &q), h.is_some());
        }
    }
}

#[test]
fn refit_equals_rebuild_and_schema_one() {
    let mesh = grid(6);
    let steps: Vec<Vec<f32>> = (0..3).map(|s| field(&mesh, s as f32 * 0.7)).collect();
    let views: Vec<&[f32]> = steps.iter().map(|v| &v[..]).collect();
    for kind in [BuildKind::Bih, BuildKind::Sah] {
        let per_step = Ibvh::build_per_step(&mesh, &views, kind).unwrap();
        let mut refit = Ibvh::build(&mesh, &steps[0], kind).unwrap();
        let rays = camera_tiles(Vec3::new(-5.0, -4.0, 9.0), Vec3::splat(3.0), 32);
        let q = IsoQuery::new(&[0.5]);
        for (s, values) in steps.iter().enumerate() {
            refit.refit(values).unwrap();
            // The tree depends on the geometry only: refit bounds are a
            // rebuild's, bit for bit.
            assert_eq!(refit, per_step[s], "{kind:?} step {s}");
            let mut a = vec![None; rays.len()];
            refit.trace_packet(&rays, &q, &mut a);
            for (ray, h) in rays.iter().zip(&a) {
                assert_eq!(*h, per_step[s].trace(ray, &q));
            }
        }
    }
}

#[test]
fn nodes_bound_their_subtrees() {
    let mesh = grid(5);
    let values = field(&mesh, 0.3);
    for kind in [BuildKind::Bih, BuildKind::Sah] {
        let bvh = Ibvh::build(&mesh, &values, kind).unwrap();
        // Every tet exactly once.
        let mut seen = bvh.prim_tet.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..mesh.tets.len() as u32).collect::<Vec<_>>());
        fn check(bvh: &Ibvh, mesh: &TetMesh, values: &[f32], i: usize) -> Vec<u32> {
            let n = bvh.nodes[i];
            let tets: Vec<u32> = if n.is_leaf() {
                assert!(n.count as usize <= LEAF_SIZE);
                bvh.prim_tet[n.index as usize..(n.index + n.count) as usize].to_vec()
            } else {
                let mut t = check(bvh, mesh, values, i + 1);
                t.extend(check(bvh, mesh, values, n.index as usize));
                t
            };
            for &t in &tets {
                for v in mesh.tets[t as usize] {
                    let p = mesh.points[v as usize];
                    assert!(p.cmpge(n.lo3()).all() && p.cmple(n.hi3()).all());
                    let f = values[v as usize];
                    assert!(f >= n.lo.w && f <= n.hi.w);
                }
            }
            tets
        }
        assert_eq!(check(&bvh, &mesh, &values, 0).len(), mesh.tets.len());
        assert!(bvh.bytes() > 0 && bvh.depth() > 3);
    }
}

#[test]
fn bad_input_is_reported() {
    let mesh = grid(2);
    let short = vec![0.0; mesh.points.len() - 1];
    assert!(matches!(
        Ibvh::build_bih(&mesh, &short),
        Err(IsoError::ValueCount { .. })
    ));
    let mut nan = vec![0.0; mesh.points.len()];
    nan[3] = f32::NAN;
    assert!(matches!(
        Ibvh::build_sah(&mesh, &nan),
        Err(IsoError::NonFiniteValue { point: 3, .. })
    ));
    let ok = vec![0.0; mesh.points.len()];
    let bvh = Ibvh::build_bih(&mesh, &ok).unwrap();
    let ray = Ray::new(Vec3::splat(-1.0), Vec3::ONE);
    // Five isovalues: refused (no hit), never a panic.
    assert_eq!(bvh.trace(&ray, &IsoQuery::new(&[0.0; 5])), None);
    assert!(IsoQuery::new(&[0.0; 5]).check().is_err());
}
