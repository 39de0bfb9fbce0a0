//! "Pipes": a procedural stand-in for the Exhaust Pipe scene of Aman et
//! al. (2022), whose mesh (6,244,678 triangles) is not in this repository.
//!
//! What it shares with Exhaust Pipe: dense, long, bent, finely
//! tessellated tubes lying close together, at the paper's triangle count,
//! in the frame of the paper's "Exhaust Pipe Left" camera (`scenes.json`),
//! here looking along them. What it does not share: the real part's shape
//! (flanges, junctions, mufflers), its tessellation and whatever defects
//! its mesh has. Every pipe is a closed, outward-oriented object (its ends
//! capped), and no two triangles meet anywhere but in shared vertices and
//! edges.
//!
//! ## Geometry
//!
//! A bundle of 3, 7, 19 or 37 pipes (37 from 25,900 triangles on) in a
//! hexagonal arrangement follows one smooth base curve, 320 units along
//! its axis with sine bends across it (two half-waves one way, three the
//! other), twisting half a turn around it along its length. Each pipe's
//! cross-section at parameter `t` is a circle in the base curve's normal
//! plane at `t` (its frame is rotation-minimising: double reflection, Wang
//! et al. 2008), around a point of the hexagonal arrangement (turned by
//! the twist); the circles of one plane are 0.4 radii apart at least and
//! all lie within 0.4 of the curve's smallest radius of curvature, so the
//! smooth tubes, images of disjoint discs under a one-to-one map, cannot
//! meet. For the triangulated tubes (whose rings, pipe by pipe, lie in
//! the same planes) that margin is checked, not proven: `tests/standins.rs`
//! runs the exact check at small sizes, and the full-size bundle has no
//! intersecting pair either. Pipes start and
//! end a little apart (up to 6 % of the length), capped by a fan from one
//! rim vertex (long thin triangles, as exporters write a disc).

use glam::{DVec3, Vec3};
use tet_core::scene::{Camera, PointLight};
use tet_core::synthetic::SplitMix64;

use crate::scene::{Scene, SceneObject};

/// Triangles of the paper's Exhaust Pipe (Aman et al. 2022, Table 2):
/// the size of the `pipes` scene without a count.
pub const EXHAUST_PIPE_TRIANGLES: u64 = 6_244_678;

/// The smallest bundle: three coarse pipes. [`pipes`] raises smaller
/// counts to it.
pub const MIN_PIPES_TRIANGLES: u64 = 1_000;

/// Radius of the bundle (pipe centres and radii together).
const BUNDLE_RADIUS: f64 = 18.0;
/// Length of the bundle's axis.
const LENGTH: f64 = 320.0;
/// Bend amplitudes and half-periods along the length, across the axis.
const BENDS: [(f64, f64, f64); 2] = [(30.0, 2.0, 0.0), (20.0, 3.0, 0.6)];
/// Turns of the arrangement around the base curve over its length.
const TWIST: f64 = 0.5;
/// Gap between neighbouring pipes, in pipe radii.
const GAP: f64 = 0.4;
/// Ring spacing over side length: quads a little longer than wide.
const ASPECT: f64 = 2.5;
/// Fewest rings per pipe (the frame turns at most a few degrees per ring).
const MIN_RINGS: u32 = 24;

/// "Exhaust Pipe Left" (`scenes.json`): camera and light.
const EYE: [f64; 3] = [-148.665346, 199.51266, 190.070091];
const TARGET: [f64; 3] = [-2.61482, 106.741, 9.46368];
const LIGHT: [f32; 3] = [6.0, 289.096, 336.1];

/// The bundle of about `triangles` triangles (at least
/// [`MIN_PIPES_TRIANGLES`]), one object per pipe, seen along its length by
/// the paper's "Exhaust Pipe Left" camera, with that scene's light.
pub fn pipes(triangles: u64) -> Scene {
    let target = triangles.max(MIN_PIPES_TRIANGLES);
    let layout = Layout::new(target);
    let curve = BaseCurve::new(layout.rings);
    let mut scene = Scene {
        camera: Some(Camera {
            position: DVec3::from_array(EYE).as_vec3(),
            target: DVec3::from_array(TARGET).as_vec3(),
            up: Vec3::Y,
            vfov_deg: 45.0,
        }),
        lights: vec![PointLight {
            position: Vec3::from_array(LIGHT),
            color: Vec3::ONE,
            intensity: 1.0,
        }],
        ..Scene::default()
    };
    scene.vertices.reserve(layout.vertices() as usize);
    scene.triangles.reserve(layout.triangles() as usize);
    for (k, pipe) in layout.pipes.iter().enumerate() {
        let first_triangle = scene.triangles.len() as u32;
        let first_vertex = scene.vertices.len() as u32;
        tube(&mut scene, &curve, pipe, layout.sides);
        scene.objects.push(SceneObject {
            name: format!("pipe {k}"),
            first_triangle,
            triangle_count: scene.triangles.len() as u32 - first_triangle,
            first_vertex,
            vertex_count: scene.vertices.len() as u32 - first_vertex,
            mirrored: false,
        });
    }
    scene.name = format!(
        "Exhaust Pipe (stand-in: pipes), {} triangles",
        scene.triangles.len()
    );
    scene
}

/// One pipe: its place in the arrangement (radius and angle from the
/// base curve), its own radius, its first and last ring.
#[derive(Clone, Copy, Debug)]
struct Pipe {
    offset: f64,
    angle: f64,
    radius: f64,
    rings: (u32, u32),
}

/// The bundle's arrangement and tessellation.
struct Layout {
    pipes: Vec<Pipe>,
    sides: u32,
    rings: u32,
}

impl Layout {
    fn new(target: u64) -> Layout {
        let count = [37u32, 19, 7, 3]
            .into_iter()
            .find(|&k| u64::from(k) * 700 <= target)
            .unwrap_or(3);
        // Centres on a hexagonal lattice of spacing `s = (2 + GAP) r`.
        let (centres, reach) = hexagonal(count);
        let spacing_per_r = 2.0 + GAP;
        let radius = BUNDLE_RADIUS / (reach * spacing_per_r + 1.0);
        let spacing = spacing_per_r * radius;
        let mut rng = SplitMix64(0xE4A5_7000 + u64::from(count));
        let stagger = |rng: &mut SplitMix64| rng.next_f64() * 0.06;
        let shapes: Vec<(f64, f64, f64, f64, f64)> = centres
            .iter()
            .map(|&(x, y)| {
                (
                    x * spacing,
                    y * spacing,
                    radius * (0.85 + 0.15 * rng.next_f64()),
                    stagger(&mut rng),
                    stagger(&mut rng),
                )
            })
            .collect();
        // Sides from the aspect ratio: ring spacing = ASPECT · side.
        let per_pipe = target as f64 / f64::from(count);
        let length = BaseCurve::new(1024).length;
        let sides = (ASPECT * std::f64::consts::PI * radius * per_pipe / length)
            .sqrt()
            .round()
            .clamp(6.0, 4096.0) as u32;
        let make = |rings: u32| -> Vec<Pipe> {
            shapes
                .iter()
                .map(|&(x, y, r, a, b)| {
                    let cut = |f: f64| (f * f64::from(rings)).floor() as u32;
                    Pipe {
                        offset: x.hypot(y),
                        angle: y.atan2(x),
                        radius: r,
                        rings: (cut(a), rings - 1 - cut(b)),
                    }
                })
                .collect()
        };
        // The ring count whose total is nearest the target (the total
        // grows with it).
        let total =
            |rings: u32| -> u64 { make(rings).iter().map(|p| tube_triangles(p, sides)).sum() };
        let (mut lo, mut hi) = (MIN_RINGS, MIN_RINGS.max(1 << 24));
        while lo < hi {
            let mid = lo + (hi - lo) / 2;
            if total(mid) < target {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        let rings = if lo > MIN_RINGS && total(lo - 1).abs_diff(target) < total(lo).abs_diff(target)
        {
            lo - 1
        } else {
            lo
        };
        Layout {
            pipes: make(rings),
            sides,
            rings,
        }
    }

    fn triangles(&self) -> u64 {
        self.pipes
            .iter()
            .map(|p| tube_triangles(p, self.sides))
            .sum()
    }

    fn vertices(&self) -> u64 {
        self.pipes
            .iter()
            .map(|p| u64::from(p.rings.1 - p.rings.0 + 1) * u64::from(self.sides))
            .sum()
    }
}

/// Triangles of a capped tube: two per side per ring gap, `sides − 2` per cap.
fn tube_triangles(p: &Pipe, sides: u32) -> u64 {
    let s = u64::from(sides);
    2 * s * u64::from(p.rings.1 - p.rings.0) + 2 * (s - 2)
}

/// `count` points of the hexagonal lattice of unit spacing nearest the
/// origin (3: a triangle around it; 7, 19, 37: whole hexagonal rings), and
/// the distance of the farthest.
fn hexagonal(count: u32) -> (Vec<(f64, f64)>, f64) {
    if count == 3 {
        let r = 1.0 / 3f64.sqrt();
        let pts = (0..3)
            .map(|k| {
                let a = std::f64::consts::FRAC_PI_2 + std::f64::consts::TAU * f64::from(k) / 3.0;
                (r * a.cos(), r * a.sin())
            })
            .collect();
        return (pts, r);
    }
    let corner = |k: u32| {
        let a = std::f64::consts::FRAC_PI_3 * f64::from(k % 6);
        (a.cos(), a.sin())
    };
    let mut pts = vec![(0.0, 0.0)];
    let mut ring = 0;
    while (pts.len() as u32) < count {
        ring += 1;
        let n = f64::from(ring);
        for k in 0..6 {
            let (a, b) = (corner(k), corner(k + 1));
            for i in 0..ring {
                let f = f64::from(i);
                pts.push((n * a.0 + f * (b.0 - a.0), n * a.1 + f * (b.1 - a.1)));
            }
        }
    }
    pts.truncate(count as usize);
    (pts, f64::from(ring))
}

/// The bundle's axis (along the paper's camera view, turned 12° to the
/// right, so that the bundle recedes across the image) and the two
/// directions across it that the bends take.
fn bundle_axes() -> [DVec3; 3] {
    let view = (DVec3::from_array(TARGET) - DVec3::from_array(EYE)).normalize();
    let right = view.cross(DVec3::Y).normalize();
    let (s, c) = 12f64.to_radians().sin_cos();
    let axis = (view * c + right * s).normalize();
    let b1 = axis.cross(DVec3::Y).normalize();
    [axis, b1, axis.cross(b1)]
}

/// The base curve at `t ∈ [0, 1]`: point, first and second derivative.
/// Centred on the camera's target, [`LENGTH`] along the axis, with the
/// sine bends of [`BENDS`] across it.
fn base_curve(t: f64) -> [DVec3; 3] {
    let [axis, b1, b2] = bundle_axes();
    let mut p = DVec3::from_array(TARGET) + axis * (LENGTH * (t - 0.5));
    let mut d = axis * LENGTH;
    let mut dd = DVec3::ZERO;
    for (&(amp, halves, phase), dir) in BENDS.iter().zip([b1, b2]) {
        let w = std::f64::consts::PI * halves;
        p += dir * amp * ((w * t + phase).sin() - phase.sin());
        d += dir * amp * w * (w * t + phase).cos();
        dd -= dir * amp * w * w * (w * t + phase).sin();
    }
    [p, d, dd]
}

/// The base curve sampled at `rings` parameters `t = i / (rings − 1)`:
/// points and a rotation-minimising frame (tangent, normal, binormal).
struct BaseCurve {
    points: Vec<DVec3>,
    frames: Vec<[DVec3; 3]>,
    length: f64,
}

impl BaseCurve {
    fn new(rings: u32) -> BaseCurve {
        let n = rings.max(2);
        let (points, tangents): (Vec<DVec3>, Vec<DVec3>) = (0..n)
            .map(|i| {
                let [p, d, _] = base_curve(f64::from(i) / f64::from(n - 1));
                (p, d.normalize())
            })
            .unzip();
        let b1 = bundle_axes()[1];
        let mut normal = tangents[0].cross(b1).normalize();
        let mut frames = Vec::with_capacity(n as usize);
        frames.push([tangents[0], normal, tangents[0].cross(normal)]);
        for i in 1..n as usize {
            let v1 = points[i] - points[i - 1];
            let c1 = v1.dot(v1);
            let (rl, tl) = if c1 > 0.0 {
                (
                    normal - v1 * (2.0 / c1 * v1.dot(normal)),
                    tangents[i - 1] - v1 * (2.0 / c1 * v1.dot(tangents[i - 1])),
                )
            } else {
                (normal, tangents[i - 1])
            };
            let v2 = tangents[i] - tl;
            let c2 = v2.dot(v2);
            normal = if c2 > 1e-30 {
                rl - v2 * (2.0 / c2 * v2.dot(rl))
            } else {
                rl
            };
            // Against drift: exactly perpendicular to the tangent, unit.
            normal = (normal - tangents[i] * tangents[i].dot(normal)).normalize();
            frames.push([tangents[i], normal, tangents[i].cross(normal)]);
        }
        let length = points.windows(2).map(|w| (w[1] - w[0]).length()).sum();
        BaseCurve {
            points,
            frames,
            length,
        }
    }
}

/// Appends pipe `p` to `scene`: its rings (vertex `ring · sides + j` is
/// side `j`), the quads between them as two triangles each, a fan cap at
/// each end; wound outward.
fn tube(scene: &mut Scene, curve: &BaseCurve, p: &Pipe, sides: u32) {
    let base = scene.vertices.len() as u32;
    let last = f64::from(curve.points.len().max(2) as u32 - 1);
    let circle: Vec<(f64, f64)> = (0..sides)
        .map(|j| {
            let a = std::f64::consts::TAU * f64::from(j) / f64::from(sides);
            (a.cos(), a.sin())
        })
        .collect();
    for i in p.rings.0..=p.rings.1 {
        let [_, n, b] = curve.frames[i as usize];
        let turn = p.angle + std::f64::consts::TAU * TWIST * f64::from(i) / last;
        let centre = curve.points[i as usize] + (n * turn.cos() + b * turn.sin()) * p.offset;
        scene.vertices.extend(
            circle
                .iter()
                .map(|&(c, s)| (centre + (n * c + b * s) * p.radius).as_vec3()),
        );
    }
    let first = scene.triangles.len();
    let rings = p.rings.1 - p.rings.0 + 1;
    let at = |i: u32, j: u32| base + i * sides + j % sides;
    for i in 0..rings - 1 {
        for j in 0..sides {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            scene.triangles.push([a, b, c]);
            scene.triangles.push([a, c, d]);
        }
    }
    let end = rings - 1;
    for j in 1..sides - 1 {
        scene.triangles.push([at(0, 0), at(0, j), at(0, j + 1)]);
        scene
            .triangles
            .push([at(end, 0), at(end, j + 1), at(end, j)]);
    }
    // Outward: the frame's handedness decides the winding; flip the pipe
    // if its signed volume is negative.
    let volume: f64 = scene.triangles[first..]
        .iter()
        .map(|t| {
            let v = t.map(|k| scene.vertices[k as usize].as_dvec3());
            v[0].dot(v[1].cross(v[2]))
        })
        .sum();
    if volume < 0.0 {
        for t in &mut scene.triangles[first..] {
            t.swap(1, 2);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bundle lies within 0.4 of the base curve's smallest radius of
    /// curvature (the module docs' condition for tubes that cannot meet),
    /// and the frame stays orthonormal with its tangent along the curve.
    #[test]
    fn the_bundle_fits_inside_the_curves_bends() {
        let smallest = (0..=20_000)
            .map(|i| {
                let [_, d, dd] = base_curve(f64::from(i) / 20_000.0);
                d.length().powi(3) / d.cross(dd).length()
            })
            .fold(f64::INFINITY, f64::min);
        assert!(
            BUNDLE_RADIUS <= 0.4 * smallest,
            "radius of curvature {smallest}"
        );
        let curve = BaseCurve::new(500);
        for (i, [t, n, b]) in curve.frames.iter().enumerate() {
            assert!(
                (t.length() - 1.0).abs() < 1e-12 && n.dot(*t).abs() < 1e-12,
                "ring {i}"
            );
            assert!(
                (b.length() - 1.0).abs() < 1e-12 && b.dot(*n).abs() < 1e-12,
                "ring {i}"
            );
        }
    }

    /// The arrangements keep pipe centres a lattice spacing apart and
    /// reach as far as they say.
    #[test]
    fn hexagonal_arrangements_are_a_spacing_apart() {
        for k in [3, 7, 19, 37] {
            let (pts, reach) = hexagonal(k);
            assert_eq!(pts.len(), k as usize);
            for (i, a) in pts.iter().enumerate() {
                assert!(a.0.hypot(a.1) <= reach + 1e-12);
                for b in &pts[..i] {
                    assert!(
                        (a.0 - b.0).hypot(a.1 - b.1) >= 1.0 - 1e-12,
                        "{k}: {a:?} {b:?}"
                    );
                }
            }
        }
    }
}
