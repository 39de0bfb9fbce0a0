//! Procedural scenes that need no files: the paper's torus-knot scenes,
//! stand-ins for its scenes without a mesh here (Rungholt: [`crate::city`];
//! Exhaust Pipe: [`crate::pipes`]) and simple shapes for tests.
//!
//! ## The torus knot
//!
//! The paper's `torus_knot.obj` is a 3ds Max TorusKnot primitive: a (p, q) =
//! (2, 3) knot swept by a 12-sided tube over 120 segments (1,440 vertices,
//! 2,880 triangles). Fitting the file's ring centres gives the centre line
//! (y up, segment `s`, `t = 2πs/120`, `u = q·t`):
//!
//! ```text
//! ρ(t) = c / (1 − k·sin u),   centre = (ρ·cos(−p·t), ρ·cos u, ρ·sin(−p·t))
//! c = 0.91555, k = 5/11, tube radius r = 0.40711
//! ```
//!
//! (residual 1e-4 = the file's 4-decimal rounding). Tube side `j` of a ring
//! sits at angle `90° − 30°·j` from the centre's radial direction (the
//! centre position projected perpendicular to the tangent `T`), towards
//! `T × radial`. Against the file, vertex by vertex: mean deviation 2.4e-4,
//! max 6.8e-4; bounding box equal to 4 decimals
//! (`tests/procedural.rs`). Triangles are the file's: `(s:j, s+1:j, s+1:j+1)` and
//! `(s:j, s+1:j+1, s:j+1)` (ring:side), outward winding.
//!
//! ## Scene layouts
//!
//! "Torus Knots" = 27 knots translated by `{−5, 0, 5}³` (x outermost, z
//! innermost, as in `scenes.json`); "Torus Knots in a Box" = the box object
//! (box.obj, `[-10,10]³`, scaled by `(−2.1, −1.1, −2.1)`, i.e. mirrored and
//! facing inward) followed by the 27 knots. Camera and light are the
//! `scenes.json` values transcribed as constants.

use glam::{DVec3, Vec3};
use tet_core::scene::{Camera, PointLight};

use crate::scene::{MeshData, ObjectPlacement, Scene, Transform, orbit_camera};

/// A procedural scene: the name [`by_name`] and the command line take,
/// what it is, and how it is built. [`SCENES`] is the one list of them:
/// [`by_name`] looks names up in it and the command line's help prints it.
#[derive(Clone, Copy)]
pub struct Procedural {
    /// The name; one ending in `:N` takes a count for `N` (as
    /// [`parse_count`] reads it: `dense-knots:10m`).
    pub name: &'static str,
    /// What it is, in one line.
    pub about: &'static str,
    /// Builds it from the name as given and the count (0 without `:N`).
    build: fn(&str, u64) -> Scene,
}

impl Procedural {
    /// The name without its `:N` for a parameterised scene (`dense-knots`),
    /// else `None`.
    pub fn pattern(&self) -> Option<&'static str> {
        self.name.strip_suffix(":N")
    }
}

impl std::fmt::Debug for Procedural {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Procedural")
            .field("name", &self.name)
            .field("about", &self.about)
            .finish_non_exhaustive()
    }
}

/// Every procedural scene, in the order the help lists them.
pub const SCENES: &[Procedural] = &[
    Procedural {
        name: "torus-knot",
        about: "one torus knot: the authors' torus_knot.obj rebuilt (2,880 triangles)",
        build: |name, _| single_object_scene(name, &torus_knot(&TorusKnotParams::default())),
    },
    Procedural {
        name: "torus-knots",
        about: "\"Torus Knots\" of Aman et al. (2022): 27 knots, the paper's camera and light (77,760 triangles)",
        build: |_, _| torus_knots(false),
    },
    Procedural {
        name: "torus-knots-box",
        about: "\"Torus Knots in a Box\": the 27 knots inside the mirrored box (77,772 triangles)",
        build: |_, _| torus_knots(true),
    },
    Procedural {
        name: "cube",
        about: "the cube [-1,1]³ (12 triangles)",
        build: |name, _| single_object_scene(name, &cube(1.0)),
    },
    Procedural {
        name: "tetrahedron",
        about: "the tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1) (4 triangles)",
        build: |name, _| single_object_scene(name, &tetrahedron()),
    },
    Procedural {
        name: "sphere",
        about: "a unit icosphere (320 triangles)",
        build: |name, _| single_object_scene(name, &icosphere(2)),
    },
    Procedural {
        name: "two-quads",
        about: "two parallel unit squares 0.5 apart, both facing +z (4 triangles)",
        build: |name, _| single_object_scene(name, &two_quads(0.5)),
    },
    Procedural {
        name: "thin-slab",
        about: "a closed slab [-1,1]² × [-0.005,0.005] (12 triangles)",
        build: |name, _| single_object_scene(name, &thin_slab(0.01)),
    },
    Procedural {
        name: "gear",
        about: "a 12-tooth gear with a bore, caps of long thin triangles as CAD exporters write them",
        build: |name, _| single_object_scene(name, &crate::flat::gear(12, 0.3, 0.3)),
    },
    Procedural {
        name: "flat-parts",
        about: "\"Flat Parts\": flat-faced CAD-like solids on one shared plane (about 2,200 triangles)",
        build: |_, _| crate::flat::flat_parts(),
    },
    Procedural {
        name: "dense-knots:N",
        about: "\"Torus Knots\" tessellated to about N triangles, at least 77,760 (dense-knots:10m)",
        build: |_, n| dense_torus_knots(n),
    },
    Procedural {
        name: "city",
        about: "Rungholt stand-in: axis-aligned buildings on a street grid, about the paper's 3,580,928 triangles",
        build: |_, _| crate::city::city(crate::city::RUNGHOLT_TRIANGLES),
    },
    Procedural {
        name: "city:N",
        about: "the Rungholt stand-in at about N triangles, at least 1,000 (city:200k)",
        build: |_, n| crate::city::city(n),
    },
    Procedural {
        name: "pipes",
        about: "Exhaust Pipe stand-in: a bundle of long bent capped tubes, about the paper's 6,244,678 triangles",
        build: |_, _| crate::pipes::pipes(crate::pipes::EXHAUST_PIPE_TRIANGLES),
    },
    Procedural {
        name: "pipes:N",
        about: "the Exhaust Pipe stand-in at about N triangles, at least 1,000 (pipes:200k)",
        build: |_, n| crate::pipes::pipes(n),
    },
    Procedural {
        name: "fan-sphere:N",
        about: "a bumpy sphere of about N triangles whose poles are fans of about √N long thin triangles (fan-sphere:1m)",
        build: |name, n| single_object_scene(name, &fan_sphere(&fan_sphere_by_count(n))),
    },
];

/// Build a procedural scene by name: a name of [`SCENES`], or the `name`
/// of one ending in `:N` with a count for `N` ([`parse_count`], e.g.
/// `dense-knots:10m`: [`dense_torus_knots`]; `fan-sphere:N`:
/// [`fan_sphere_by_count`]; `city:N`, `pipes:N`: [`crate::city::city`],
/// [`crate::pipes::pipes`], the stand-ins for the paper's Rungholt and
/// Exhaust Pipe).
pub fn by_name(name: &str) -> Option<Scene> {
    if let Some(p) = SCENES
        .iter()
        .find(|p| p.pattern().is_none() && p.name == name)
    {
        return Some((p.build)(name, 0));
    }
    let (pattern, count) = name.split_once(':')?;
    let p = SCENES.iter().find(|p| p.pattern() == Some(pattern))?;
    Some((p.build)(name, parse_count(count)?))
}

/// A count written as digits with an optional `k` or `m` suffix
/// (thousands, millions; fractions allowed: `0.5m`), from 1 to 10⁹.
pub fn parse_count(text: &str) -> Option<u64> {
    let text = text.trim().to_ascii_lowercase();
    let (digits, unit) = match text.as_bytes().last()? {
        b'k' => (&text[..text.len() - 1], 1_000.0),
        b'm' => (&text[..text.len() - 1], 1_000_000.0),
        _ => (text.as_str(), 1.0),
    };
    let n = digits.parse::<f64>().ok()? * unit;
    (n.is_finite() && (1.0..=1e9).contains(&n)).then_some(n.round() as u64)
}

/// "Torus Knots" at any size: the same 27 knots, grid, camera and light,
/// each knot's tube subdivided by a factor `s` in both directions
/// (`⌈120·s⌉` segments of `⌈12·s⌉` sides) so that the scene has about
/// `triangles` triangles (never fewer than the original 77,760). It is the
/// large model of the Ray-Strips comparison (Lauterbach et al. 2007,
/// §6: Ray-Strips against a BVH as the model outgrows memory): the same
/// view and shape at every size, only the tessellation grows.
pub fn dense_torus_knots(triangles: u64) -> Scene {
    let base = TorusKnotParams::default();
    let per_knot = triangles as f64 / 27.0;
    let s = (per_knot / f64::from(2 * base.segments * base.sides))
        .sqrt()
        .max(1.0);
    let knot = torus_knot(&TorusKnotParams {
        segments: (f64::from(base.segments) * s).ceil() as u32,
        sides: (f64::from(base.sides) * s).ceil() as u32,
        ..base
    });
    let placed: Vec<ObjectPlacement<'_>> = torus_knot_grid()
        .into_iter()
        .map(|t| ObjectPlacement {
            name: "Torus Knot".into(),
            mesh: &knot,
            transform: Transform::translate(t),
            pre_transform: None,
        })
        .collect();
    let name = format!("Torus Knots, {} triangles", 27 * knot.triangles.len());
    Scene::from_objects(
        &name,
        &placed,
        Some(torus_knots_camera()),
        vec![torus_knots_light()],
    )
    .expect("procedural meshes are finite")
}

fn single_object_scene(name: &str, mesh: &MeshData) -> Scene {
    Scene::from_objects(
        name,
        &[ObjectPlacement {
            name: name.into(),
            mesh,
            transform: Transform::IDENTITY,
            pre_transform: None,
        }],
        None,
        Vec::new(),
    )
    .expect("procedural meshes are small and finite")
}

/// Parameters of the torus-knot tube (defaults: fitted to the paper's file).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TorusKnotParams {
    /// Turns around the symmetry (y) axis.
    pub p: u32,
    /// Turns through the torus hole.
    pub q: u32,
    /// Rings along the curve.
    pub segments: u32,
    /// Vertices per ring.
    pub sides: u32,
    /// Centre-line scale `c`.
    pub c: f64,
    /// Centre-line eccentricity `k` (< 1).
    pub k: f64,
    /// Tube radius.
    pub tube_radius: f64,
}

impl Default for TorusKnotParams {
    fn default() -> Self {
        TorusKnotParams {
            p: 2,
            q: 3,
            segments: 120,
            sides: 12,
            c: 0.91555,
            k: 5.0 / 11.0,
            tube_radius: 0.40711,
        }
    }
}

/// The torus-knot tube: `segments·sides` vertices, `2·segments·sides`
/// triangles, per-vertex normals (radial from the centre line). Vertex
/// `s·sides + j` is side `j` of ring `s`.
pub fn torus_knot(params: &TorusKnotParams) -> MeshData {
    let TorusKnotParams {
        p,
        q,
        segments,
        sides,
        c,
        k,
        tube_radius: r,
    } = *params;
    let (p, q) = (p as f64, q as f64);
    let mut positions = Vec::with_capacity((segments * sides) as usize);
    let mut normals = Vec::with_capacity(positions.capacity());
    for s in 0..segments {
        let t = std::f64::consts::TAU * s as f64 / segments as f64;
        let (u, th) = (q * t, -p * t);
        let denom = 1.0 - k * u.sin();
        let rho = c / denom;
        let drho = c * k * q * u.cos() / (denom * denom);
        let centre = DVec3::new(rho * th.cos(), rho * u.cos(), rho * th.sin());
        let tangent = DVec3::new(
            drho * th.cos() + rho * p * th.sin(),
            drho * u.cos() - rho * q * u.sin(),
            drho * th.sin() - rho * p * th.cos(),
        )
        .normalize();
        let radial = (centre - centre.dot(tangent) * tangent).normalize();
        let binormal = tangent.cross(radial);
        for j in 0..sides {
            let phi = std::f64::consts::FRAC_PI_2 - std::f64::consts::TAU * j as f64 / sides as f64;
            let dir = phi.cos() * radial + phi.sin() * binormal;
            positions.push((centre + r * dir).as_vec3());
            normals.push(dir.as_vec3());
        }
    }
    let mut triangles = Vec::with_capacity((2 * segments * sides) as usize);
    let idx = |s: u32, j: u32| (s % segments) * sides + (j % sides);
    for s in 0..segments {
        for j in 0..sides {
            let (a, b, c2, d) = (idx(s, j), idx(s + 1, j), idx(s + 1, j + 1), idx(s, j + 1));
            triangles.push([a, b, c2]);
            triangles.push([a, c2, d]);
        }
    }
    MeshData::single_index(positions, triangles, Some(normals))
}

/// The 27 grid translations of the "Torus Knots" scene (x outermost).
pub fn torus_knot_grid() -> Vec<DVec3> {
    let steps = [-5.0, 0.0, 5.0];
    let mut out = Vec::with_capacity(27);
    for x in steps {
        for y in steps {
            for z in steps {
                out.push(DVec3::new(x, y, z));
            }
        }
    }
    out
}

/// The box object of the "in a Box" scenes: box.obj (`[-10,10]³`, outward
/// winding, one normal per face), vertex and face order as in the file.
pub fn neptun_box() -> MeshData {
    let positions = [
        [-10.0, -10.0, 10.0],
        [-10.0, -10.0, -10.0],
        [10.0, -10.0, -10.0],
        [10.0, -10.0, 10.0],
        [-10.0, 10.0, 10.0],
        [10.0, 10.0, 10.0],
        [10.0, 10.0, -10.0],
        [-10.0, 10.0, -10.0],
    ]
    .map(Vec3::from_array)
    .to_vec();
    let normals = [
        [0.0, -1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
        [0.0, 0.0, -1.0],
        [-1.0, 0.0, 0.0],
    ]
    .map(Vec3::from_array)
    .to_vec();
    let faces: [[u32; 3]; 12] = [
        [1, 2, 3],
        [3, 4, 1],
        [5, 6, 7],
        [7, 8, 5],
        [1, 4, 6],
        [6, 5, 1],
        [4, 3, 7],
        [7, 6, 4],
        [3, 2, 8],
        [8, 7, 3],
        [2, 1, 5],
        [5, 8, 2],
    ];
    let triangles: Vec<[u32; 3]> = faces.iter().map(|f| f.map(|i| i - 1)).collect();
    let normal_idx: Vec<[u32; 3]> = (0..12u32).map(|t| [t / 2; 3]).collect();
    MeshData {
        positions,
        triangles,
        normals: Some((normals, normal_idx)),
        uvs: None,
    }
}

/// Scale of the box object in "Torus Knots in a Box" (`scenes.json`).
pub const TORUS_KNOTS_BOX_SCALE: [f64; 3] = [-2.1, -1.1, -2.1];

/// Camera of the torus-knot scenes: orbit (0.5, 1.0) rad, distance 20,
/// target at the origin (`scenes.json`).
pub fn torus_knots_camera() -> Camera {
    orbit_camera(0.5, 1.0, 20.0, DVec3::ZERO)
}

/// Light of the torus-knot scenes: white point light at (6, 10, 8).
pub fn torus_knots_light() -> PointLight {
    PointLight {
        position: Vec3::new(6.0, 10.0, 8.0),
        color: Vec3::ONE,
        intensity: 1.0,
    }
}

fn torus_knots(with_box: bool) -> Scene {
    let knot = torus_knot(&TorusKnotParams::default());
    let boxm = neptun_box();
    let mut placed = Vec::new();
    if with_box {
        placed.push(ObjectPlacement {
            name: "box".into(),
            mesh: &boxm,
            transform: Transform {
                scale: DVec3::from_array(TORUS_KNOTS_BOX_SCALE),
                ..Transform::IDENTITY
            },
            pre_transform: None,
        });
    }
    for t in torus_knot_grid() {
        placed.push(ObjectPlacement {
            name: "Torus Knot".into(),
            mesh: &knot,
            transform: Transform::translate(t),
            pre_transform: None,
        });
    }
    let name = if with_box {
        "Torus Knots in a Box"
    } else {
        "Torus Knots"
    };
    Scene::from_objects(
        name,
        &placed,
        Some(torus_knots_camera()),
        vec![torus_knots_light()],
    )
    .expect("procedural meshes are small and finite")
}

/// Axis-aligned cube `[-h, h]³`: 8 vertices, 12 outward triangles.
pub fn cube(h: f32) -> MeshData {
    box_mesh(Vec3::splat(-h), Vec3::splat(h))
}

/// Axis-aligned box `[min, max]`: 8 vertices (vertex `i` has x = max when
/// bit 0 of `i` is set, y when bit 1, z when bit 2), 12 outward triangles.
pub fn box_mesh(min: Vec3, max: Vec3) -> MeshData {
    let positions: Vec<Vec3> = (0..8)
        .map(|i| {
            Vec3::new(
                if i & 1 != 0 { max.x } else { min.x },
                if i & 2 != 0 { max.y } else { min.y },
                if i & 4 != 0 { max.z } else { min.z },
            )
        })
        .collect();
    MeshData::single_index(positions, BOX_TRIANGLES.to_vec(), None)
}

/// Outward triangles of the 8-corner box numbering of [`box_mesh`].
pub const BOX_TRIANGLES: [[u32; 3]; 12] = [
    [0, 2, 1],
    [1, 2, 3], // z = min (normal −z)
    [4, 5, 6],
    [5, 7, 6], // z = max
    [0, 1, 4],
    [1, 5, 4], // y = min
    [2, 6, 3],
    [3, 6, 7], // y = max
    [0, 4, 2],
    [2, 4, 6], // x = min
    [1, 3, 5],
    [3, 7, 5], // x = max
];

/// Regular-ish tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1), outward.
pub fn tetrahedron() -> MeshData {
    let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
    let triangles = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    MeshData::single_index(positions, triangles, None)
}

/// Unit icosphere: icosahedron subdivided `levels` times and projected onto
/// the sphere (`10·4^levels + 2` vertices, `20·4^levels` triangles), with
/// normals = positions.
pub fn icosphere(levels: u32) -> MeshData {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let mut pts: Vec<DVec3> = [
        [-1.0, g, 0.0],
        [1.0, g, 0.0],
        [-1.0, -g, 0.0],
        [1.0, -g, 0.0],
        [0.0, -1.0, g],
        [0.0, 1.0, g],
        [0.0, -1.0, -g],
        [0.0, 1.0, -g],
        [g, 0.0, -1.0],
        [g, 0.0, 1.0],
        [-g, 0.0, -1.0],
        [-g, 0.0, 1.0],
    ]
    .iter()
    .map(|a| DVec3::from_array(*a).normalize())
    .collect();
    let mut tris: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut mid = std::collections::HashMap::new();
        let mut next = Vec::with_capacity(tris.len() * 4);
        let mut midpoint = |a: u32, b: u32, pts: &mut Vec<DVec3>| -> u32 {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                pts.push(((pts[a as usize] + pts[b as usize]) * 0.5).normalize());
                pts.len() as u32 - 1
            })
        };
        for [a, b, c] in tris {
            let ab = midpoint(a, b, &mut pts);
            let bc = midpoint(b, c, &mut pts);
            let ca = midpoint(c, a, &mut pts);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        tris = next;
    }
    let positions: Vec<Vec3> = pts.iter().map(|p| p.as_vec3()).collect();
    let normals = positions.clone();
    MeshData::single_index(positions, tris, Some(normals))
}

/// Two parallel unit squares `[0,1]²` at z = 0 and z = `gap`, both facing +z.
pub fn two_quads(gap: f32) -> MeshData {
    let mut positions = Vec::new();
    for z in [0.0, gap] {
        positions.extend([
            Vec3::new(0.0, 0.0, z),
            Vec3::new(1.0, 0.0, z),
            Vec3::new(1.0, 1.0, z),
            Vec3::new(0.0, 1.0, z),
        ]);
    }
    let triangles = vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]];
    MeshData::single_index(positions, triangles, None)
}

/// A thin closed slab `[-1,1]² × [-t/2, t/2]` (8 vertices, 12 triangles).
pub fn thin_slab(thickness: f32) -> MeshData {
    box_mesh(
        Vec3::new(-1.0, -1.0, -thickness / 2.0),
        Vec3::new(1.0, 1.0, thickness / 2.0),
    )
}

/// Parameters of [`fan_sphere`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FanSphereParams {
    /// Vertices per ring (and triangles per pole fan). A multiple of 4
    /// puts whole meridians exactly in the planes x = 0 and y = 0.
    pub meridians: u32,
    /// Rings of latitude plus one (`rings − 1` rings of vertices). Even
    /// puts a ring exactly at z = 0.
    pub rings: u32,
    /// Scale along z (1: a sphere; larger: longer, thinner fan triangles).
    pub stretch: f64,
    /// Relative height of the bumps on the radius (0: smooth).
    pub bump: f64,
}

/// A closed UV sphere around the origin, `meridians · (rings − 1) + 2`
/// vertices and `2 · meridians · (rings − 1)` triangles, wound outward,
/// whose poles are fans of `meridians` long thin triangles meeting at one
/// vertex on the z axis. Such fans are what cut planes through a pole
/// (out-of-core builds) must survive: every plane through the axis passes
/// through both apexes, and with `meridians` a multiple of 4 the planes
/// x = 0 and y = 0 run along whole meridians of edges (their coordinates
/// there are exactly 0). The radius is `1 + bump · sin(9θ) · cos(7φ)`
/// (colatitude θ, longitude φ), z is scaled by `stretch`.
pub fn fan_sphere(params: &FanSphereParams) -> MeshData {
    let FanSphereParams {
        meridians: nu,
        rings,
        stretch,
        bump,
    } = *params;
    let (nu, rings) = (nu.max(3), rings.max(2));
    let mut positions = vec![Vec3::new(0.0, 0.0, stretch as f32)];
    for j in 1..rings {
        let th = std::f64::consts::PI * f64::from(j) / f64::from(rings);
        for i in 0..nu {
            let ph = std::f64::consts::TAU * f64::from(i) / f64::from(nu);
            let (x, y) = match 4 * i {
                0 => (1.0, 0.0),
                k if k == nu => (0.0, 1.0),
                k if k == 2 * nu => (-1.0, 0.0),
                k if k == 3 * nu => (0.0, -1.0),
                _ => (ph.cos(), ph.sin()),
            };
            let r = 1.0 + bump * (9.0 * th).sin() * (7.0 * ph).cos();
            let s = r * th.sin();
            let z = if 2 * j == rings {
                0.0
            } else {
                stretch * r * th.cos()
            };
            positions.push(Vec3::new((s * x) as f32, (s * y) as f32, z as f32));
        }
    }
    positions.push(Vec3::new(0.0, 0.0, -stretch as f32));
    let at = |j: u32, i: u32| 1 + (j - 1) * nu + i % nu;
    let south = positions.len() as u32 - 1;
    let mut triangles = Vec::with_capacity(2 * (nu * (rings - 1)) as usize);
    for i in 0..nu {
        triangles.push([0, at(1, i), at(1, i + 1)]);
        triangles.push([south, at(rings - 1, i + 1), at(rings - 1, i)]);
    }
    for j in 1..rings - 1 {
        for i in 0..nu {
            let (a, b, c, d) = (at(j, i), at(j, i + 1), at(j + 1, i), at(j + 1, i + 1));
            triangles.push([a, c, d]);
            triangles.push([a, d, b]);
        }
    }
    MeshData::single_index(positions, triangles, None)
}

/// The [`fan_sphere`] of about `triangles` triangles: `meridians` the
/// multiple of 4 nearest `√triangles` (at least 8), bumps of 2 %. At 10⁶
/// triangles its poles are fans of 1,000 triangles.
pub fn fan_sphere_by_count(triangles: u64) -> FanSphereParams {
    let t = triangles as f64;
    let meridians = (t.sqrt() / 4.0).round().max(2.0) as u32 * 4;
    let rings = (t / (2.0 * f64::from(meridians))).round().max(1.0) as u32 + 1;
    FanSphereParams {
        meridians,
        rings,
        stretch: 1.0,
        bump: 0.02,
    }
}
