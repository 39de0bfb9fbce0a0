//! Meshes generated in the tests and an independent f64 reference.
#![allow(dead_code)]

use glam::{DVec3, Vec3};

/// Icosahedron subdivided `levels` times, projected to the sphere of
/// `radius` around `centre` (closed, manifold, shared vertices).
pub fn icosphere(levels: u32, centre: Vec3, radius: f32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let t = (1.0 + 5.0f32.sqrt()) / 2.0;
    let mut v: Vec<Vec3> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|p| Vec3::from(*p).normalize())
    .collect();
    let mut f: Vec<[u32; 3]> = vec![
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
        let mut next = Vec::new();
        let mut midpoint = |a: u32, b: u32, v: &mut Vec<Vec3>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                v.push((v[a as usize] + v[b as usize]).normalize());
                v.len() as u32 - 1
            })
        };
        for [a, b, c] in f {
            let ab = midpoint(a, b, &mut v);
            let bc = midpoint(b, c, &mut v);
            let ca = midpoint(c, a, &mut v);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        f = next;
    }
    (v.iter().map(|p| centre + radius * *p).collect(), f)
}

/// A torus with `rings × sides` quads (two triangles each), radii `r1`
/// (ring) and `r2` (tube), shifted by `centre`.
pub fn torus(rings: u32, sides: u32, r1: f32, r2: f32, centre: Vec3) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut v = Vec::new();
    for i in 0..rings {
        let a = i as f32 / rings as f32 * std::f32::consts::TAU;
        for j in 0..sides {
            let b = j as f32 / sides as f32 * std::f32::consts::TAU;
            let r = r1 + r2 * b.cos();
            v.push(centre + Vec3::new(r * a.cos(), r * a.sin(), r2 * b.sin()));
        }
    }
    let id = |i: u32, j: u32| (i % rings) * sides + (j % sides);
    let mut f = Vec::new();
    for i in 0..rings {
        for j in 0..sides {
            f.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            f.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    (v, f)
}

/// A height-field grid of `w × h` quads over `[0, w] × [0, h]` with the
/// given heights (row-major, `(w + 1) (h + 1)` values).
pub fn grid(w: u32, h: u32, heights: &[f32]) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut v = Vec::new();
    for y in 0..=h {
        for x in 0..=w {
            v.push(Vec3::new(
                x as f32,
                y as f32,
                heights[(y * (w + 1) + x) as usize],
            ));
        }
    }
    let mut f = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let a = y * (w + 1) + x;
            f.push([a, a + 1, a + w + 2]);
            f.push([a, a + w + 2, a + w + 1]);
        }
    }
    (v, f)
}

/// A reference hit in f64 (Möller–Trumbore on the input triangle in input
/// vertex order).
#[derive(Clone, Copy, Debug)]
pub struct RefHit {
    pub triangle: usize,
    pub t: f64,
    pub u: f64,
    pub v: f64,
}

/// What the f64 reference says about one ray.
#[derive(Clone, Copy, Debug)]
pub enum Reference {
    /// Clearly this hit (no rival within the tolerances).
    Hit(RefHit),
    /// Clearly no hit.
    Miss,
    /// Too close to an edge, a range end or a rival hit to decide in f32.
    Ambiguous,
}

/// Brute-force reference with tolerance `eps` on barycentrics and relative
/// distance.
pub fn reference(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    origin: Vec3,
    direction: Vec3,
    t_min: f32,
    t_max: f32,
    eps: f64,
) -> Reference {
    let o = origin.as_dvec3();
    let d = direction.as_dvec3();
    let mut hits: Vec<RefHit> = Vec::new();
    let mut near_edge: Vec<f64> = Vec::new();
    for (k, tri) in triangles.iter().enumerate() {
        if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
            continue;
        }
        let [a, b, c] = tri.map(|i| positions[i as usize].as_dvec3());
        let (e1, e2) = (b - a, c - a);
        let p = d.cross(e2);
        let det = e1.dot(p);
        let n = e1.cross(e2);
        if n.length() == 0.0 {
            continue;
        }
        // Grazing rays are ambiguous whenever they come near the triangle.
        let grazing = (det.abs() / (d.length() * e1.length() * e2.length())) < 1e-6;
        if det == 0.0 {
            continue;
        }
        let s = o - a;
        let u = s.dot(p) / det;
        let q = s.cross(e1);
        let v = d.dot(q) / det;
        let t = e2.dot(q) / det;
        let w = 1.0 - u - v;
        let min_bary = u.min(v).min(w);
        if min_bary < -eps {
            continue;
        }
        let in_range = t >= f64::from(t_min) && t <= f64::from(t_max);
        let near_range = (t - f64::from(t_min)).abs() <= eps * (1.0 + t.abs())
            || (f64::from(t_max).is_finite()
                && (t - f64::from(t_max)).abs() <= eps * (1.0 + t.abs()));
        if min_bary < eps || grazing || near_range {
            if in_range || near_range {
                near_edge.push(t);
            }
            continue;
        }
        if in_range {
            hits.push(RefHit {
                triangle: k,
                t,
                u,
                v,
            });
        }
    }
    hits.sort_by(|a, b| a.t.total_cmp(&b.t));
    let first_clear = hits.first().copied();
    let first_edge = near_edge.iter().copied().fold(f64::INFINITY, f64::min);
    match first_clear {
        None if first_edge.is_finite() => Reference::Ambiguous,
        None => Reference::Miss,
        Some(h) => {
            let tol = eps * (1.0 + h.t.abs());
            let rival = hits.get(1).is_some_and(|r| r.t - h.t <= tol);
            if rival || first_edge <= h.t + tol {
                Reference::Ambiguous
            } else {
                Reference::Hit(h)
            }
        }
    }
}

/// Hit point of the input triangle at barycentrics `(u, v)` in f64.
pub fn point(positions: &[Vec3], tri: [u32; 3], u: f64, v: f64) -> DVec3 {
    let [a, b, c] = tri.map(|i| positions[i as usize].as_dvec3());
    (1.0 - u - v) * a + u * b + v * c
}
