//! The iso walk's min-max regions against the walk without them: camera
//! tiles of 16 × 16 rays over volumes at unit scale, far from the origin
//! and tiny, with one or several isovalues, a clip box and a new time
//! step. Every ray is a shortcut of the whole walk (culled as a miss the
//! walk also reports, or started at its first region with the walk's hit
//! bit for bit), and the regions do cull and shorten (most rays of these
//! views meet no isosurface; the hits start at their first region).

use glam::Vec3;
use tet_core::TetMesh;
use tet_core::synthetic::{GridSpec, kuhn_grid};
use tet_trace_cpu::Ray;
use tet_trace_cpu::iso::{
    ClipBox, ClipMode, IsoOutcome, IsoQuery, IsoStats, IsoWalk, TileWalk, WalkLayout,
};

const N: u32 = 12;

/// A jittered Kuhn grid of `N³` cells scaled by `scale` and moved by
/// `offset`, with a field of two balls (scaled along).
fn volume(scale: f32, offset: Vec3) -> (TetMesh, Vec<f32>) {
    let mut mesh = kuhn_grid(&GridSpec {
        cells: [N; 3],
        jitter: 0.2,
        seed: 9,
        ..Default::default()
    });
    let n = N as f32;
    let values: Vec<f32> = mesh
        .points
        .iter()
        .map(|p| {
            let a = p.distance(Vec3::new(0.35, 0.4, 0.5) * n);
            let b = p.distance(Vec3::new(0.7, 0.6, 0.45) * n);
            a.min(b * 1.3)
        })
        .collect();
    for p in &mut mesh.points {
        *p = *p * scale + offset;
    }
    (mesh, values)
}

/// Camera tiles: `tiles × tiles` tiles of 16 × 16 rays (tile by tile, rows
/// within a tile), from a pinhole outside the volume looking at its middle
/// with a field of view about the volume's size.
fn camera_tiles(scale: f32, offset: Vec3, tiles: usize) -> Vec<Ray> {
    let n = N as f32 * scale;
    let target = Vec3::splat(0.5 * n) + offset;
    let eye = target + Vec3::new(1.7, 1.1, 2.3) * n;
    let fwd = (target - eye).normalize();
    let right = fwd.cross(Vec3::Y).normalize();
    let up = right.cross(fwd);
    let side = tiles * 16;
    let mut rays = Vec::new();
    for ty in 0..tiles {
        for tx in 0..tiles {
            for j in 0..16 {
                for i in 0..16 {
                    let u = ((tx * 16 + i) as f32 + 0.5) / side as f32 * 2.0 - 1.0;
                    let v = ((ty * 16 + j) as f32 + 0.5) / side as f32 * 2.0 - 1.0;
                    let d = fwd + (right * u + up * v) * 0.25;
                    rays.push(Ray::new(eye, d));
                }
            }
        }
    }
    rays
}

/// What [`compare`] counted over its runs.
#[derive(Default)]
struct Counts {
    hits: usize,
    /// Rays culled: no walk, where the whole walk misses.
    culled: usize,
    /// Hits reached with fewer tets than the whole walk (started at the
    /// first region).
    shortened: usize,
}

/// Traces `rays` in tiles of 256 with the regions, in both tile walks,
/// against the single walk without them.
fn compare(mesh: &TetMesh, values: &[f32], query: &IsoQuery, rays: &[Ray]) -> Counts {
    let mut n = Counts::default();
    for layout in [WalkLayout::Tet20, WalkLayout::Tet16] {
        let with = IsoWalk::new(mesh, values, layout).unwrap();
        let plain = IsoWalk::with_regions(mesh, values, layout, false).unwrap();
        assert!(with.bytes() > plain.bytes());
        let vp = with.viewpoint(rays[0].origin).unwrap();
        for how in [TileWalk::Lockstep, TileWalk::Interleaved] {
            let mut out = vec![IsoOutcome::Miss { tets_visited: 0 }; rays.len()];
            let mut stats = IsoStats::default();
            for (r, o) in rays.chunks(256).zip(out.chunks_mut(256)) {
                with.trace_tile_as(how, &vp, r, query, o, &mut stats);
            }
            let mut hint = Default::default();
            for (ray, o) in rays.iter().zip(&out) {
                let walked = plain.trace_from(&vp, ray, query, &mut hint, &mut Default::default());
                assert!(
                    o.is_shortcut_of(&walked),
                    "with regions {o:?}, the whole walk {walked:?} on {ray:?}"
                );
                match o {
                    IsoOutcome::Miss { tets_visited: 0 } if walked.tets_visited() > 0 => {
                        n.culled += 1
                    }
                    IsoOutcome::Hit { tets_visited, .. } => {
                        n.hits += 1;
                        n.shortened += usize::from(*tets_visited < walked.tets_visited());
                    }
                    _ => {}
                }
            }
            assert!(stats.nodes_visited > 0);
        }
    }
    n
}

#[test]
fn regions_cull_only_rays_the_walk_misses_at_every_scale() {
    for (scale, offset) in [
        (1.0, Vec3::ZERO),
        (1.0, Vec3::new(1e5, -2e5, 3e5)),
        (1e-4, Vec3::ZERO),
        (3e4, Vec3::ZERO),
    ] {
        let (mesh, values) = volume(scale, offset);
        let rays = camera_tiles(scale, offset, 3);
        let n = compare(&mesh, &values, &IsoQuery::new(&[3.5]), &rays);
        let total = 4 * rays.len();
        let at = format!("scale {scale}, offset {offset}");
        assert!(n.hits > total / 20, "{at}: {} hits", n.hits);
        assert!(n.culled > total / 5, "{at}: {} of {total} culled", n.culled);
        assert!(
            n.shortened > n.hits / 4,
            "{at}: {} of {} hits shortened",
            n.shortened,
            n.hits
        );
    }
}

#[test]
fn regions_cull_with_several_isovalues_and_clip_boxes() {
    let (mesh, values) = volume(1.0, Vec3::ZERO);
    let rays = camera_tiles(1.0, Vec3::ZERO, 3);
    let isos = [2.5, 3.5, 4.0];
    for clip in [
        None,
        Some(ClipBox {
            lo: Vec3::new(2.0, 1.0, 3.0),
            hi: Vec3::new(9.0, 8.0, 7.5),
            mode: ClipMode::KeepInside,
        }),
        Some(ClipBox {
            lo: Vec3::new(3.0, 3.0, 3.0),
            hi: Vec3::new(8.0, 8.0, 8.0),
            mode: ClipMode::CutAway,
        }),
    ] {
        let q = match clip {
            Some(c) => IsoQuery::new(&isos).with_clip(c),
            None => IsoQuery::new(&isos),
        };
        let n = compare(&mesh, &values, &q, &rays);
        assert!(n.hits > 500, "{clip:?}: {} hits", n.hits);
        assert!(n.culled > 500, "{clip:?}: {} culled", n.culled);
        assert!(n.shortened > 0, "{clip:?}: no hit shortened");
    }
}

#[test]
fn regions_follow_a_new_time_step() {
    let (mesh, values) = volume(1.0, Vec3::ZERO);
    let moved: Vec<f32> = mesh
        .points
        .iter()
        .zip(&values)
        .map(|(p, v)| v + 0.3 * p.x)
        .collect();
    let rays = camera_tiles(1.0, Vec3::ZERO, 2);
    let q = IsoQuery::new(&[3.8]);
    let stepped = IsoWalk::new(&mesh, &values, WalkLayout::Tet20)
        .unwrap()
        .with_values(&moved)
        .unwrap();
    let fresh = IsoWalk::new(&mesh, &moved, WalkLayout::Tet20).unwrap();
    let vp = fresh.viewpoint(rays[0].origin).unwrap();
    let trace = |w: &IsoWalk| {
        let mut out = vec![IsoOutcome::Miss { tets_visited: 0 }; rays.len()];
        for (r, o) in rays.chunks(256).zip(out.chunks_mut(256)) {
            w.trace_tile(&vp, r, &q, o, &mut IsoStats::default());
        }
        out
    };
    let (a, b) = (trace(&stepped), trace(&fresh));
    let differ = a.iter().zip(&b).filter(|(x, y)| x != y).count();
    assert_eq!(differ, 0, "{differ} of {} rays differ", a.len());
    assert!(a.iter().any(|o| o.hit().is_some()));
    // Refitted regions (not the first step's) cull only the new misses.
    let n = compare(&mesh, &moved, &q, &rays);
    assert!(n.culled > 0 && n.shortened > 0);
}
