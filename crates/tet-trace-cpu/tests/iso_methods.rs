//! Isosurface methods against the f64 brute-force reference
//! (`tet_trace_cpu::iso::reference`), on jittered Kuhn grids with analytic
//! fields computed here.

use glam::{DVec3, Vec3};
use tet_core::TetMesh;
use tet_core::synthetic::{GridSpec, SplitMix64, kuhn_grid};
use tet_trace_cpu::Ray;
use tet_trace_cpu::iso::reference::{IsoHit64, closest};
use tet_trace_cpu::iso::{
    ClipBox, ClipMode, Ibvh, IsoHit, IsoOutcome, IsoQuery, IsoWalk, WalkLayout,
};

const N: u32 = 6;

fn grid(jitter: f32) -> TetMesh {
    kuhn_grid(&GridSpec {
        cells: [N; 3],
        jitter,
        seed: 7,
        ..Default::default()
    })
}

fn centre() -> Vec3 {
    Vec3::splat(N as f32 * 0.5)
}

fn sphere(mesh: &TetMesh) -> Vec<f32> {
    mesh.points.iter().map(|p| p.distance(centre())).collect()
}

fn gaussians(mesh: &TetMesh) -> Vec<f32> {
    let bumps = [
        (Vec3::new(2.0, 2.5, 3.0), 1.2f32, 1.0f32),
        (Vec3::new(4.0, 3.5, 2.5), 1.0, 0.8),
        (Vec3::new(3.0, 4.0, 4.0), 0.8, 0.6),
    ];
    mesh.points
        .iter()
        .map(|p| {
            bumps
                .iter()
                .map(|&(c, s, a)| a * (-(p.distance_squared(c)) / (2.0 * s * s)).exp())
                .sum()
        })
        .collect()
}

fn linear(mesh: &TetMesh, a: Vec3) -> Vec<f32> {
    mesh.points.iter().map(|p| a.dot(*p)).collect()
}

/// Random rays: from outside the box toward a random interior point, or
/// from inside (t_min 0).
fn rays(n: usize, seed: u64, inside: bool) -> Vec<Ray> {
    let mut r = SplitMix64(seed);
    let s = N as f32;
    (0..n)
        .map(|_| {
            let target = Vec3::new(
                r.range_f32(0.5, s - 0.5),
                r.range_f32(0.5, s - 0.5),
                r.range_f32(0.5, s - 0.5),
            );
            let origin = if inside {
                Vec3::new(
                    r.range_f32(0.2, s - 0.2),
                    r.range_f32(0.2, s - 0.2),
                    r.range_f32(0.2, s - 0.2),
                )
            } else {
                let d = Vec3::new(
                    r.range_f32(-1.0, 1.0),
                    r.range_f32(-1.0, 1.0),
                    r.range_f32(-1.0, 1.0),
                )
                .normalize_or(Vec3::X);
                centre() + d * (2.0 * s)
            };
            Ray::new(origin, target - origin)
        })
        .collect()
}

/// True when the reference answer is robust: away from tet edges and
/// vertices, from a second crossing, from grazing incidence and from the
/// clip box's faces.
fn clear(r: &IsoHit64, ray: &Ray, clip: Option<ClipBox>) -> bool {
    let d = ray.direction.as_dvec3();
    let g = r.gradient;
    let grazing = g.length() == 0.0 || g.dot(d).abs() < 0.05 * g.length() * d.length();
    let len = d.length();
    let near_clip = clip.is_some_and(|c| near_box(r.point, c));
    r.edge_margin > 1e-4 && r.second_gap * len > 1e-3 && !grazing && !near_clip
}

fn near_box(p: DVec3, c: ClipBox) -> bool {
    let (lo, hi) = (c.lo.as_dvec3(), c.hi.as_dvec3());
    (0..3).any(|a| (p[a] - lo[a]).abs() < 1e-3 || (p[a] - hi[a]).abs() < 1e-3)
}

/// Compares one method's answer with the reference; returns whether the
/// ray was checked.
fn agree(
    name: &str,
    got: Option<IsoHit>,
    want: Option<IsoHit64>,
    ray: &Ray,
    clip: Option<ClipBox>,
) -> bool {
    match (got, want) {
        (None, None) => true,
        (Some(h), None) => {
            // A hit the reference rejects only by rounding at the clip box.
            let near = clip.is_some_and(|c| near_box(ray.at(h.t).as_dvec3(), c));
            assert!(
                near,
                "{name}: hit {h:?} where the reference has none, ray {ray:?}"
            );
            false
        }
        (got, Some(r)) => {
            if !clear(&r, ray, clip) {
                return false;
            }
            let h = got.unwrap_or_else(|| panic!("{name}: miss, reference {r:?}, ray {ray:?}"));
            let len = ray.direction.length() as f64;
            assert!(
                (h.t as f64 - r.t).abs() * len < 1e-3,
                "{name}: t {} vs {} ({r:?}), ray {ray:?}",
                h.t,
                r.t
            );
            assert_eq!(h.tet, r.tet, "{name}: tet, ray {ray:?}");
            assert_eq!(
                h.isovalue_index, r.isovalue_index,
                "{name}: isovalue, ray {ray:?}"
            );
            let n = r.gradient.normalize().as_vec3();
            assert!(
                h.normal.distance(n) < 1e-3,
                "{name}: normal {} vs {n}",
                h.normal
            );
            true
        }
    }
}

fn walk_hit(out: IsoOutcome) -> Option<IsoHit> {
    assert!(!out.is_failure(), "walk failed: {out:?}");
    out.hit().copied()
}

fn check_all(mesh: &TetMesh, values: &[f32], query: &IsoQuery, rays: &[Ray]) -> usize {
    let walks: Vec<IsoWalk> = WalkLayout::ALL
        .iter()
        .map(|&l| IsoWalk::new(mesh, values, l).unwrap())
        .collect();
    let bih = Ibvh::build_bih(mesh, values).unwrap();
    let sah = Ibvh::build_sah(mesh, values).unwrap();
    let mut checked = 0;
    for ray in rays {
        let want = closest(mesh, values, ray, query);
        let mut ok = true;
        for (w, l) in walks.iter().zip(WalkLayout::ALL) {
            ok &= agree(
                l.name(),
                walk_hit(w.trace(ray, query)),
                want,
                ray,
                query.clip,
            );
        }
        let b = bih.trace(ray, query);
        ok &= agree("ibvh-bih", b, want, ray, query.clip);
        let s = sah.trace(ray, query);
        assert_eq!(b, s, "BIH and SAH builds differ on {ray:?}");
        // Shadow rays (any hit) agree with the nearest crossing.
        assert_eq!(
            bih.occluded(ray, query),
            b.is_some(),
            "ibvh any-hit, {ray:?}"
        );
        assert_eq!(
            walks[1].occluded(ray, query),
            Ok(walk_hit(walks[1].trace(ray, query)).is_some())
        );
        checked += ok as usize;
    }
    checked
}

#[test]
fn sphere_single_isovalue_from_outside_and_inside() {
    let mesh = grid(0.12);
    let values = sphere(&mesh);
    let q = IsoQuery::new(&[1.7]);
    let mut all = rays(150, 11, false);
    all.extend(rays(100, 12, true));
    let checked = check_all(&mesh, &values, &q, &all);
    assert!(checked > 200, "only {checked} rays checked");
}

#[test]
fn gaussians_several_isovalues() {
    let mesh = grid(0.1);
    let values = gaussians(&mesh);
    let isos = [0.2, 0.45, 0.7];
    let q = IsoQuery::new(&isos);
    let checked = check_all(&mesh, &values, &q, &rays(200, 21, false));
    assert!(checked > 150, "only {checked} rays checked");
    // Every isovalue is the nearest for some ray.
    let bih = Ibvh::build_bih(&mesh, &values).unwrap();
    let mut seen = [false; 3];
    for r in rays(200, 21, false) {
        if let Some(h) = bih.trace(&r, &q) {
            seen[h.isovalue_index as usize] = true;
        }
    }
    assert!(seen.iter().filter(|&&s| s).count() >= 2, "{seen:?}");
}

/// Many more rays, four isovalues, with and without a crop box.
#[test]
fn many_rays_four_isovalues() {
    let mesh = grid(0.14);
    let values = gaussians(&mesh);
    let isos = [0.15, 0.3, 0.5, 0.75];
    let clip = ClipBox {
        lo: Vec3::new(0.0, 2.2, 0.0),
        hi: Vec3::new(3.7, 9.0, 9.0),
        mode: ClipMode::CutAway,
    };
    for q in [IsoQuery::new(&isos), IsoQuery::new(&isos).with_clip(clip)] {
        let mut all = rays(3000, 61, false);
        all.extend(rays(2000, 62, true));
        let checked = check_all(&mesh, &values, &q, &all);
        assert!(checked > 4000, "only {checked} rays checked");
    }
}

#[test]
fn clip_box_keep_and_cut() {
    let mesh = grid(0.1);
    let values = sphere(&mesh);
    let isos = [1.2, 2.2];
    for mode in [ClipMode::KeepInside, ClipMode::CutAway] {
        let clip = ClipBox {
            lo: Vec3::new(1.0, 0.5, 2.6),
            hi: Vec3::new(7.0, 5.1, 7.0),
            mode,
        };
        let q = IsoQuery::new(&isos).with_clip(clip);
        let checked = check_all(&mesh, &values, &q, &rays(150, 31, false));
        assert!(checked > 100, "{mode:?}: only {checked} rays checked");
    }
}

#[test]
fn linear_field_hits_lie_on_the_plane() {
    let mesh = grid(0.15);
    let a = Vec3::new(0.3, -0.7, 0.5);
    let values = linear(&mesh, a);
    let iso = 0.4f32;
    let q = IsoQuery::new(std::slice::from_ref(&iso));
    let bih = Ibvh::build_bih(&mesh, &values).unwrap();
    let walk = IsoWalk::new(&mesh, &values, WalkLayout::Tet20).unwrap();
    let mut hits = 0;
    for ray in rays(300, 41, false).iter().chain(&rays(100, 42, true)) {
        for h in [bih.trace(ray, &q), walk_hit(walk.trace(ray, &q))]
            .into_iter()
            .flatten()
        {
            let p = ray.at(h.t).as_dvec3();
            let f = a.as_dvec3().dot(p);
            // f32 precision of the point: |a|·|p|·2⁻²² or so.
            assert!(
                (f - iso as f64).abs() < 2e-5 * (1.0 + p.length()),
                "{f} off the plane {iso}"
            );
            assert!(
                h.normal.distance(a.normalize()) < 1e-4,
                "normal {}",
                h.normal
            );
            hits += 1;
        }
    }
    assert!(hits > 300, "{hits} hits");
}

/// Rays through mesh vertices and edge midpoints (on an unjittered grid,
/// where ties are everywhere) toward the minimum of a closed isosurface
/// that passes exactly through those vertices: the surface lies between the
/// boundary and the minimum, so every ray must hit it, never slip through.
#[test]
fn crack_free_through_vertices_and_edges() {
    for jitter in [0.0, 0.1] {
        let mesh = grid(jitter);
        // Minimum at a lattice vertex: the centre.
        let c = centre();
        let values: Vec<f32> = mesh
            .points
            .iter()
            .map(|p| (*p - c).abs().element_sum())
            .collect();
        let walks: Vec<IsoWalk> = WalkLayout::ALL
            .iter()
            .map(|&l| IsoWalk::new(&mesh, &values, l).unwrap())
            .collect();
        let bih = Ibvh::build_bih(&mesh, &values).unwrap();
        let mut tried = 0;
        for (i, &v) in mesh.points.iter().enumerate() {
            if !(values[i] > 0.5 && values[i] < 2.5) {
                continue;
            }
            // The isosurface through vertex `v`, or through the midpoint of
            // the lattice edge from `v` along x (the next point).
            let j = (i + 1) % mesh.points.len();
            let edge_mid = (v + mesh.points[j]) * 0.5;
            let cases = [
                (values[i], v),
                (values[i], (v + c) * 0.5),
                (values[i], edge_mid),
                ((values[i] + values[j]) * 0.5, edge_mid),
            ];
            for (iso, target) in cases {
                let q = IsoQuery::new(std::slice::from_ref(&iso));
                // From outside, through `target`, toward the centre side.
                for k in [2.0f32, 3.0, 5.0] {
                    let origin = c + (target - c) * k + Vec3::new(0.0, 0.0, 0.0);
                    for ray in [
                        Ray::new(origin, c - origin),
                        Ray::new(origin, target - origin),
                    ] {
                        if (target - origin).dot(c - origin) <= 0.0 {
                            continue;
                        }
                        let want_hit = ray.direction.dot(c - origin) > 0.0
                            && (c - origin).cross(ray.direction).length() == 0.0;
                        for (w, l) in walks.iter().zip(WalkLayout::ALL) {
                            let h = walk_hit(w.trace(&ray, &q));
                            if want_hit {
                                assert!(
                                    h.is_some(),
                                    "{} slipped through, iso {iso}, {ray:?}",
                                    l.name()
                                );
                            }
                        }
                        let b = bih.trace(&ray, &q);
                        if want_hit {
                            assert!(b.is_some(), "ibvh slipped through, iso {iso}, {ray:?}");
                        }
                        tried += 1;
                    }
                }
            }
        }
        assert!(tried > 100, "{tried}");
    }
}

#[test]
fn walk_never_fails_on_grids() {
    for (jitter, seed) in [(0.0, 51), (0.15, 52)] {
        let mesh = grid(jitter);
        let values = gaussians(&mesh);
        let q = IsoQuery::new(&[0.3, 0.6]);
        for l in WalkLayout::ALL {
            let w = IsoWalk::new(&mesh, &values, l).unwrap();
            for ray in rays(300, seed, false)
                .iter()
                .chain(&rays(200, seed + 1, true))
            {
                let out = w.trace(ray, &q);
                assert!(!out.is_failure(), "{}: {out:?} on {ray:?}", l.name());
            }
        }
    }
}

/// A camera's rays on a larger grid: the walks (from the camera's
/// viewpoint, entering through the boundary) and the IBVH packets find the
/// same crossings; a ray that one method hits and another misses grazes the
/// surface (silhouette), where rounding may go either way.
#[test]
fn walks_and_ibvh_agree_on_a_camera() {
    let n = 10u32;
    let mesh = kuhn_grid(&GridSpec {
        cells: [n; 3],
        jitter: 0.1,
        seed: 9,
        ..Default::default()
    });
    let c = Vec3::splat(n as f32 * 0.5);
    let values: Vec<f32> = mesh
        .points
        .iter()
        .map(|p| {
            (-p.distance_squared(c - 1.0) / 8.0).exp() + (-p.distance_squared(c + 1.5) / 6.0).exp()
        })
        .collect();
    let isos = [0.3, 0.6];
    let q = IsoQuery::new(&isos);
    let eye = c + Vec3::new(12.0, -9.0, 7.0);
    let fwd = (c - eye).normalize();
    let right = fwd.cross(Vec3::Z).normalize();
    let up = right.cross(fwd);
    let res = 48;
    let rays: Vec<Ray> = (0..res * res)
        .map(|i| {
            let (x, y) = ((i % res) as f32, (i / res) as f32);
            let u = (x + 0.5) / res as f32 * 0.8 - 0.4;
            let v = (y + 0.5) / res as f32 * 0.8 - 0.4;
            Ray::new(eye, fwd + right * u + up * v)
        })
        .collect();
    let bih = Ibvh::build_bih(&mesh, &values).unwrap();
    let mut packets = vec![None; rays.len()];
    bih.trace_packet(&rays, &q, &mut packets);
    let mut both = 0;
    for l in WalkLayout::ALL {
        let w = IsoWalk::new(&mesh, &values, l).unwrap();
        let vp = w.viewpoint(eye).unwrap();
        let mut hint = Default::default();
        let mut tile = vec![IsoOutcome::Miss { tets_visited: 0 }; rays.len()];
        w.trace_tile(&vp, &rays, &q, &mut tile, &mut Default::default());
        for ((ray, b), t) in rays.iter().zip(&packets).zip(&tile) {
            let out = w.trace_from(&vp, ray, &q, &mut hint, &mut Default::default());
            // The walks of a tile are the single walks, or shortcuts of
            // them (culled by the regions, or started at the first one).
            assert!(
                t.is_shortcut_of(&out),
                "{}: tile {t:?} vs single {out:?} on {ray:?}",
                l.name()
            );
            let h = walk_hit(out);
            let grazing = |x: &IsoHit| x.normal.dot(ray.direction.normalize()).abs() < 0.05;
            match (h, *b) {
                (Some(x), Some(y)) => {
                    let len = ray.direction.length();
                    assert!(
                        (x.t - y.t).abs() * len < 1e-3 || grazing(&x),
                        "{}: t {} vs {} on {ray:?}",
                        l.name(),
                        x.t,
                        y.t
                    );
                    both += 1;
                }
                (Some(x), None) | (None, Some(x)) => {
                    assert!(
                        grazing(&x),
                        "{}: one method misses a crossing {x:?} on {ray:?}",
                        l.name()
                    )
                }
                (None, None) => {}
            }
        }
    }
    assert!(both > 1000, "{both}");
}

/// Rays from inside that leave the volume: a crossing of the field's
/// extrapolation beyond the boundary is no crossing; one just before it is.
#[test]
fn rays_leaving_the_volume_miss() {
    let mesh = grid(0.0);
    // f = x + y: a tet at the boundary x = N straddles isovalues whose
    // crossing along a +x ray lies just beyond the boundary.
    let values = linear(&mesh, Vec3::new(1.0, 1.0, 0.0));
    let s = N as f32;
    let bih = Ibvh::build_bih(&mesh, &values).unwrap();
    let walks: Vec<IsoWalk> = WalkLayout::ALL
        .iter()
        .map(|&l| IsoWalk::new(&mesh, &values, l).unwrap())
        .collect();
    let mut r = SplitMix64(77);
    for _ in 0..200 {
        let x = s - r.range_f32(0.001, 0.3);
        let origin = Vec3::new(x, r.range_f32(0.5, s - 0.5), r.range_f32(0.5, s - 0.5));
        let ray = Ray::new(origin, Vec3::X);
        let y = origin.y;
        for (iso, hits) in [(s + y + 0.05, false), ((x + s) * 0.5 + y, true)] {
            let q = IsoQuery::new(std::slice::from_ref(&iso));
            assert_eq!(
                closest(&mesh, &values, &ray, &q).is_some(),
                hits,
                "reference, {ray:?}"
            );
            assert_eq!(bih.trace(&ray, &q).is_some(), hits, "ibvh, {ray:?}");
            for (w, l) in walks.iter().zip(WalkLayout::ALL) {
                let h = walk_hit(w.trace(&ray, &q));
                assert_eq!(h.is_some(), hits, "{}, iso {iso}, {ray:?}", l.name());
            }
        }
    }
}

/// The entry face found from a hint carried between rays (the surface walk
/// over the boundary faces) is the one found from scratch (the BVH over
/// them): every walk outcome is the same, whichever path found the face,
/// on rays from one eye in scanline order (coherent) and shuffled.
#[test]
fn entry_from_a_carried_hint_is_entry_from_scratch() {
    let mesh = grid(0.12);
    let values = gaussians(&mesh);
    let isos = [0.4];
    let q = IsoQuery::new(&isos);
    let c = centre();
    let eye = c + Vec3::new(9.0, 7.0, -11.0);
    let fwd = (c - eye).normalize();
    let right = fwd.cross(Vec3::Y).normalize();
    let up = right.cross(fwd);
    let res = 40;
    let mut rays: Vec<Ray> = (0..res * res)
        .map(|i| {
            let (x, y) = ((i % res) as f32, (i / res) as f32);
            let u = (x + 0.5) / res as f32 * 1.0 - 0.5;
            let v = (y + 0.5) / res as f32 * 1.0 - 0.5;
            Ray::new(eye, fwd + right * u + up * v)
        })
        .collect();
    let mut r = SplitMix64(5);
    let shuffled: Vec<Ray> = {
        let mut s = rays.clone();
        for i in (1..s.len()).rev() {
            s.swap(i, r.range_f32(0.0, i as f32 + 0.999) as usize);
        }
        s
    };
    rays.extend(shuffled);
    let w = IsoWalk::new(&mesh, &values, WalkLayout::Tet20).unwrap();
    let vp = w.viewpoint(eye).unwrap();
    let mut hint = Default::default();
    let (mut entered, mut hits) = (0, 0);
    for ray in &rays {
        let carried = w.trace_from(&vp, ray, &q, &mut hint, &mut Default::default());
        let fresh = w.trace_from(
            &vp,
            ray,
            &q,
            &mut Default::default(),
            &mut Default::default(),
        );
        assert_eq!(carried, fresh, "{ray:?}");
        entered += (carried.tets_visited() > 0) as usize;
        hits += carried.hit().is_some() as usize;
    }
    // Both the surface walk and the BVH were exercised: a quarter of the
    // rays enter the volume, some of them hit, the rest miss it.
    assert!(
        entered > rays.len() / 5 && entered < rays.len() && hits > 100,
        "{entered} {hits}"
    );
}
