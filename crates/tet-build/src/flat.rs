//! Flat-faced procedural solids: the shapes of CAD parts, architecture and
//! cities, whose large flat faces are triangulated the way exporters do it
//! (fans and strips of long thin triangles, coplanar neighbours of
//! different sizes). Many scene triangles share one plane, so a ray can lie
//! in the plane of constrained faces and of the tet faces around them,
//! which rays in general position (Torus Knots, scanned meshes) never do.
//!
//! Every solid is closed and outward-oriented; its flat caps are
//! horizontal (`y` constant, `y` up as in the papers' cameras) unless a
//! placement rotates it. [`flat_parts`] places one of each class in a
//! scene (the robustness table's flat-faced scene, `flat-parts`); the
//! tests use the generators one by one.

use std::collections::HashMap;

use glam::{DVec3, Vec2, Vec3};
use tet_core::scene::PointLight;

use crate::scene::{MeshData, ObjectPlacement, Scene, Transform, orbit_camera};

/// A toothed ring (a gear with a bore) extruded from `y = 0` to `height`:
/// `teeth` teeth on a rim of radius 1 (roots at 0.8), a bore of radius
/// `bore`. Each cap is one strip of long thin triangles between rim and
/// bore, as CAD exporters write an annulus.
pub fn gear(teeth: u32, bore: f32, height: f32) -> MeshData {
    let n = (teeth.max(3) * 4) as usize;
    let ring = |r: &dyn Fn(usize) -> f32| -> Vec<Vec2> {
        (0..n)
            .map(|i| {
                let a = std::f32::consts::TAU * i as f32 / n as f32;
                Vec2::new(a.cos(), a.sin()) * r(i)
            })
            .collect()
    };
    let rim = ring(&|i| if i % 4 < 2 { 1.0 } else { 0.8 });
    let holes = ring(&|_| bore);
    let mut profile = rim;
    profile.extend(holes);
    let (r, b) = (|i: usize| (i % n) as u32, |i: usize| (n + i % n) as u32);
    let cap: Vec<[u32; 3]> = (0..n)
        .flat_map(|i| [[b(i), r(i), r(i + 1)], [b(i), r(i + 1), b(i + 1)]])
        .collect();
    let outer: Vec<u32> = (0..n).map(r).collect();
    let inner: Vec<u32> = (0..n).rev().map(b).collect();
    extrude(&profile, &[outer, inner], &cap, height)
}

/// A convex regular polygon of `sides` sides and radius 1 extruded to
/// `height`, each cap a fan from one corner (long thin triangles).
pub fn fan_prism(sides: u32, height: f32) -> MeshData {
    let n = sides.max(3);
    let profile: Vec<Vec2> = (0..n)
        .map(|i| {
            let a = std::f32::consts::TAU * i as f32 / n as f32;
            Vec2::new(a.cos(), a.sin())
        })
        .collect();
    let cap: Vec<[u32; 3]> = (1..n - 1).map(|i| [0, i, i + 1]).collect();
    extrude(&profile, &[(0..n).collect()], &cap, height)
}

/// A star of `points` points (outer radius 1, inner 0.45) extruded to
/// `height`, each cap a fan from an extra vertex at the centre.
pub fn star_prism(points: u32, height: f32) -> MeshData {
    let n = points.max(3) * 2;
    let mut profile: Vec<Vec2> = (0..n)
        .map(|i| {
            let a = std::f32::consts::TAU * i as f32 / n as f32;
            Vec2::new(a.cos(), a.sin()) * if i % 2 == 0 { 1.0 } else { 0.45 }
        })
        .collect();
    profile.push(Vec2::ZERO);
    let cap: Vec<[u32; 3]> = (0..n).map(|i| [n, i, (i + 1) % n]).collect();
    extrude(&profile, &[(0..n).collect()], &cap, height)
}

/// A staircase of `steps` steps (tread `0.4`, riser `0.25`, width `1`):
/// its two sides are vertical planes, each triangulated column by column
/// (triangles of different sizes in one plane), its bottom one plane of
/// `steps` coplanar quads of one size, its treads horizontal.
pub fn stairs(steps: u32) -> MeshData {
    let n = steps.max(1);
    let (w, r) = (0.4f32, 0.25f32);
    // Profile in (x, height): B_k = (k w, 0), T_k = (k w, k r) (k ≥ 1),
    // L_k = (k w, (k + 1) r) (k < n).
    let mut profile = Vec::new();
    let bot: Vec<u32> = (0..=n)
        .map(|k| push(&mut profile, Vec2::new(k as f32 * w, 0.0)))
        .collect();
    let top: Vec<u32> = (0..=n)
        .map(|k| match k {
            0 => bot[0],
            _ => push(&mut profile, Vec2::new(k as f32 * w, k as f32 * r)),
        })
        .collect();
    let left: Vec<u32> = (0..n)
        .map(|k| push(&mut profile, Vec2::new(k as f32 * w, (k + 1) as f32 * r)))
        .collect();
    let mut cap = Vec::new();
    for k in 0..n as usize {
        cap.push([bot[k + 1], top[k + 1], left[k]]);
        if k == 0 {
            cap.push([bot[1], left[0], bot[0]]);
        } else {
            cap.push([bot[k + 1], left[k], top[k]]);
            cap.push([bot[k + 1], top[k], bot[k]]);
        }
    }
    let mut outline: Vec<u32> = bot.clone();
    for k in (0..n as usize).rev() {
        outline.push(top[k + 1]);
        outline.push(left[k]);
    }
    let m = extrude(&profile, &[outline], &cap, 1.0);
    // The profile's height is y, its extrusion z: swap them (a mirror;
    // `extrude`'s orientation check runs again).
    let positions = m
        .positions
        .iter()
        .map(|p| Vec3::new(p.x, p.z, p.y))
        .collect();
    outward(MeshData::single_index(positions, m.triangles, None))
}

/// The box `[0, 1]³` with every edge cut into `n` segments: four faces as
/// `n × n` grids of right triangles, the top and one side as fans from an
/// extra vertex at the face centre (coplanar triangles of very different
/// sizes and shapes meeting at conforming edges).
pub fn subdivided_box(n: u32) -> MeshData {
    let n = n.max(1) as i64;
    let mut index: HashMap<[i64; 3], u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut id = |p: [i64; 3], positions: &mut Vec<Vec3>| -> u32 {
        *index.entry(p).or_insert_with(|| {
            positions.push(Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32) / (2 * n) as f32);
            positions.len() as u32 - 1
        })
    };
    let mut triangles = Vec::new();
    for axis in 0..3 {
        for side in [0, 2 * n] {
            // Lattice points (doubled, so face centres are integers) of
            // face (`axis`, `side`) at in-face coordinates (i, j).
            let at = |i: i64, j: i64| {
                let mut p = [0; 3];
                p[axis] = side;
                p[(axis + 1) % 3] = 2 * i;
                p[(axis + 2) % 3] = 2 * j;
                p
            };
            let mut outward_normal = DVec3::ZERO;
            outward_normal[axis] = if side == 0 { -1.0 } else { 1.0 };
            let mut face = Vec::new();
            let fan = (axis == 1 && side != 0) || (axis == 0 && side == 0);
            if fan {
                let mut centre = [n; 3];
                centre[axis] = side;
                let c = id(centre, &mut positions);
                let ring: Vec<[i64; 3]> = (0..n)
                    .map(|i| at(i, 0))
                    .chain((0..n).map(|j| at(n, j)))
                    .chain((0..n).map(|i| at(n - i, n)))
                    .chain((0..n).map(|j| at(0, n - j)))
                    .collect();
                for k in 0..ring.len() {
                    let (a, b) = (ring[k], ring[(k + 1) % ring.len()]);
                    face.push([c, id(a, &mut positions), id(b, &mut positions)]);
                }
            } else {
                for i in 0..n {
                    for j in 0..n {
                        let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]
                            .map(|p| id(p, &mut positions));
                        face.push([q[0], q[1], q[2]]);
                        face.push([q[0], q[2], q[3]]);
                    }
                }
            }
            for t in face {
                let v = t.map(|k| positions[k as usize].as_dvec3());
                let normal = (v[1] - v[0]).cross(v[2] - v[0]);
                triangles.push(if normal.dot(outward_normal) >= 0.0 {
                    t
                } else {
                    [t[0], t[2], t[1]]
                });
            }
        }
    }
    MeshData::single_index(positions, triangles, None)
}

/// A prism of `profile` (2-D points in the `(x, z)` plane) from `y = 0` to
/// `height`: the cap triangles `cap` (indices into `profile`, consistently
/// oriented) at both ends and a wall of two triangles per edge of each
/// boundary loop of `loops` (each loop oriented like the cap triangles'
/// boundary edges: the outline one way round, holes the other). Oriented
/// outward at the end ([`outward`]).
pub fn extrude(profile: &[Vec2], loops: &[Vec<u32>], cap: &[[u32; 3]], height: f32) -> MeshData {
    let n = profile.len() as u32;
    let mut positions: Vec<Vec3> = profile.iter().map(|p| Vec3::new(p.x, 0.0, p.y)).collect();
    positions.extend(profile.iter().map(|p| Vec3::new(p.x, height, p.y)));
    let mut triangles: Vec<[u32; 3]> = cap.to_vec();
    triangles.extend(cap.iter().map(|t| [t[0] + n, t[2] + n, t[1] + n]));
    for outline in loops {
        for k in 0..outline.len() {
            let (a, b) = (outline[k], outline[(k + 1) % outline.len()]);
            triangles.push([b, a, a + n]);
            triangles.push([b, a + n, b + n]);
        }
    }
    outward(MeshData::single_index(positions, triangles, None))
}

/// `mesh` with every triangle flipped when its signed volume (the sum of
/// the tets from the origin to each triangle) is negative: a closed,
/// consistently oriented surface then faces outward.
pub fn outward(mut mesh: MeshData) -> MeshData {
    let volume: f64 = mesh
        .triangles
        .iter()
        .map(|t| {
            let v = t.map(|k| mesh.positions[k as usize].as_dvec3());
            v[0].dot(v[1].cross(v[2]))
        })
        .sum();
    if volume < 0.0 {
        for t in &mut mesh.triangles {
            t.swap(1, 2);
        }
    }
    mesh
}

fn push(points: &mut Vec<Vec2>, p: Vec2) -> u32 {
    points.push(p);
    points.len() as u32 - 1
}

/// The heights of the horizontal flat planes of [`flat_parts`] before its
/// one tilted part: `y = 0` (every part's bottom, one plane shared by
/// all), the gear's and prisms' tops, the subdivided box's top and the
/// staircase's treads. Cameras at these heights look along the planes.
pub fn flat_parts_cap_heights() -> Vec<f32> {
    let mut h = vec![0.0, GEAR_HEIGHT, PRISM_HEIGHT, 1.0];
    h.extend((1..=STAIR_STEPS).map(|k| k as f32 * 0.25));
    h.sort_by(f32::total_cmp);
    h.dedup();
    h
}

const GEAR_HEIGHT: f32 = 0.3;
const PRISM_HEIGHT: f32 = 0.5;
const STAIR_STEPS: u32 = 6;

/// "Flat Parts", the flat-faced scene of the robustness table: a gear with
/// strip caps, a 48-gon prism with fan caps, a star prism with a centre
/// fan, a staircase and a subdivided box, all standing on the plane
/// `y = 0`, and a second gear tilted out of the axes (its planes are then
/// flat only up to f32 rounding, as in real CAD exports); about 2,200 triangles.
pub fn flat_parts() -> Scene {
    let gear_mesh = gear(24, 0.3, GEAR_HEIGHT);
    let prism = fan_prism(48, PRISM_HEIGHT);
    let star = star_prism(9, PRISM_HEIGHT);
    let steps = stairs(STAIR_STEPS);
    let boxm = subdivided_box(6);
    let at = |x: f64, z: f64| Transform::translate(DVec3::new(x, 0.0, z));
    let placed = [
        ("gear", &gear_mesh, at(-2.5, 0.0)),
        ("fan prism", &prism, at(0.0, 0.0)),
        ("star prism", &star, at(2.5, 0.0)),
        ("stairs", &steps, at(-3.2, 2.0)),
        ("subdivided box", &boxm, at(0.2, 2.2)),
        (
            "tilted gear",
            &gear_mesh,
            Transform {
                translation: DVec3::new(2.6, 0.9, 2.6),
                rotation_deg: DVec3::new(30.0, 15.0, 20.0),
                scale: DVec3::ONE,
            },
        ),
    ];
    let placed: Vec<ObjectPlacement> = placed
        .into_iter()
        .map(|(name, mesh, transform)| ObjectPlacement {
            name: name.into(),
            mesh,
            transform,
            pre_transform: None,
        })
        .collect();
    Scene::from_objects(
        "Flat Parts",
        &placed,
        Some(orbit_camera(0.45, 1.1, 9.0, DVec3::new(0.0, 0.3, 1.2))),
        vec![PointLight {
            position: Vec3::new(3.0, 6.0, 5.0),
            color: Vec3::ONE,
            intensity: 1.0,
        }],
    )
    .expect("procedural meshes are small and finite")
}
