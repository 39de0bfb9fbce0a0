//! The iso walk's tiles from outside the volume in SIMD lockstep against
//! the interleaved scalar tiles and the single walk, ray for ray and bit
//! for bit: hits, misses, tets visited and the counters, over fields with
//! one or several isovalues, a clip box, ranges cut short, rays through
//! lattice vertices and rays that miss the volume. With the regions'
//! min-max tree, a tile's ray is a shortcut of the single walk (culled as
//! a miss the walk also reports, or started at its first region: the same
//! hit bit for bit, fewer tets).

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};
use tet_trace_cpu::Ray;
use tet_trace_cpu::iso::{
    ClipBox, ClipMode, IsoOutcome, IsoQuery, IsoStats, IsoWalk, TileWalk, WalkLayout,
};

const N: u32 = 7;

fn grid(jitter: f32, seed: u64) -> TetMesh {
    kuhn_grid(&GridSpec {
        cells: [N; 3],
        jitter,
        seed,
        ..Default::default()
    })
}

/// Rays from points around the volume: towards random interior points,
/// towards lattice vertices (exactly, with no jitter), past the volume,
/// and with `[t_min, t_max]` cut short.
fn rays(seed: u64) -> Vec<Ray> {
    let mut r = SplitMix64(seed);
    let s = N as f32;
    let c = Vec3::splat(s * 0.5);
    let mut out = Vec::new();
    for k in 0..600 {
        let d = Vec3::new(
            r.range_f32(-1.0, 1.0),
            r.range_f32(-1.0, 1.0),
            r.range_f32(-1.0, 1.0),
        )
        .normalize_or(Vec3::X);
        let origin = c + d * (1.8 * s);
        let target = match k % 4 {
            0 => Vec3::new(
                (r.next_u64() % (N as u64 + 1)) as f32,
                (r.next_u64() % (N as u64 + 1)) as f32,
                (r.next_u64() % (N as u64 + 1)) as f32,
            ),
            1 => {
                c + Vec3::new(
                    r.range_f32(-2.0, 2.0),
                    r.range_f32(-2.0, 2.0),
                    r.range_f32(-2.0, 2.0),
                ) * s
            }
            _ => Vec3::new(
                r.range_f32(0.3, s - 0.3),
                r.range_f32(0.3, s - 0.3),
                r.range_f32(0.3, s - 0.3),
            ),
        };
        let mut ray = Ray::new(origin, target - origin);
        if k % 7 == 3 {
            ray.t_max = r.range_f32(0.3, 1.2);
        }
        if k % 11 == 5 {
            ray.t_min = r.range_f32(0.2, 0.6);
        }
        out.push(ray);
    }
    out
}

fn check(mesh: &TetMesh, values: &[f32], query: &IsoQuery, rays: &[Ray]) -> (usize, usize) {
    let (mut hits, mut handed) = (0, 0);
    for layout in WalkLayout::ALL {
        let culling = IsoWalk::new(mesh, values, layout).unwrap();
        let w = IsoWalk::with_regions(mesh, values, layout, false).unwrap();
        let vp = w.viewpoint(rays[0].origin).unwrap();
        let run_on = |w: &IsoWalk, how| {
            let mut out = vec![IsoOutcome::Miss { tets_visited: 0 }; rays.len()];
            let mut stats = IsoStats::default();
            // Tiles of 256 rays, as the renderer hands them over.
            for (r, o) in rays.chunks(256).zip(out.chunks_mut(256)) {
                w.trace_tile_as(how, &vp, r, query, o, &mut stats);
            }
            (out, stats)
        };
        let run = |how| run_on(&w, how);
        let (lockstep, ls) = run(TileWalk::Lockstep);
        let (interleaved, is) = run(TileWalk::Interleaved);
        let culled = [TileWalk::Lockstep, TileWalk::Interleaved].map(|how| run_on(&culling, how).0);
        let mut hint = Default::default();
        for (i, ray) in rays.iter().enumerate() {
            let single = w.trace_from(&vp, ray, query, &mut hint, &mut Default::default());
            assert_eq!(
                interleaved[i],
                single,
                "{}: interleaved on {ray:?}",
                layout.name()
            );
            assert_eq!(
                lockstep[i],
                single,
                "{}: lockstep on {ray:?}",
                layout.name()
            );
            for c in &culled {
                assert!(
                    c[i].is_shortcut_of(&single),
                    "{}: with regions {:?} on {ray:?}, walked {single:?}",
                    layout.name(),
                    c[i]
                );
            }
            hits += usize::from(single.hit().is_some());
            handed += usize::from(single.tets_visited() > 0);
        }
        assert_eq!(ls.range_tests, is.range_tests, "{}", layout.name());
        assert_eq!(
            ls.isopolygon_tests,
            is.isopolygon_tests,
            "{}",
            layout.name()
        );
    }
    (hits, handed)
}

#[test]
fn lockstep_tiles_are_the_single_walks_on_a_sphere() {
    for (jitter, seed) in [(0.0, 3), (0.15, 4)] {
        let mesh = grid(jitter, seed);
        let c = Vec3::splat(N as f32 * 0.5);
        let values: Vec<f32> = mesh.points.iter().map(|p| p.distance(c)).collect();
        let (hits, walked) = check(&mesh, &values, &IsoQuery::new(&[2.1]), &rays(seed));
        assert!(hits > 300, "jitter {jitter}: {hits} hits");
        assert!(walked > 1000, "jitter {jitter}: {walked} walks");
    }
}

#[test]
fn lockstep_tiles_are_the_single_walks_with_several_isovalues_and_a_clip_box() {
    let mesh = grid(0.1, 5);
    let values: Vec<f32> = mesh
        .points
        .iter()
        .map(|p| (p.x * 1.3).sin() + (p.y * 0.9).cos() * (p.z * 0.7).sin())
        .collect();
    let isos = [-0.6, 0.1, 0.4, 0.9];
    for clip in [
        None,
        Some(ClipBox {
            lo: Vec3::new(1.0, 0.5, 2.6),
            hi: Vec3::new(6.0, 5.1, 6.5),
            mode: ClipMode::KeepInside,
        }),
        Some(ClipBox {
            lo: Vec3::new(2.0, 2.0, 2.0),
            hi: Vec3::new(5.0, 5.0, 5.0),
            mode: ClipMode::CutAway,
        }),
    ] {
        let q = match clip {
            Some(c) => IsoQuery::new(&isos).with_clip(c),
            None => IsoQuery::new(&isos),
        };
        let (hits, _) = check(&mesh, &values, &q, &rays(11));
        assert!(hits > 300, "{clip:?}: {hits} hits");
    }
}

#[test]
fn lockstep_tiles_of_an_empty_isovalue_miss_like_the_single_walks() {
    // No tet straddles: every walk ends in lockstep, at the far boundary.
    let mesh = grid(0.05, 6);
    let values: Vec<f32> = mesh.points.iter().map(|p| p.x).collect();
    let (hits, walked) = check(&mesh, &values, &IsoQuery::new(&[100.0]), &rays(12));
    assert_eq!(hits, 0);
    assert!(walked > 1000);
}
