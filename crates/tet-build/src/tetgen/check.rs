//! [`check_input`]: every input is checked in Rust before TetGen sees it.

use super::error::TetgenError;
use super::types::TetgenInput;

/// Checks a PLC before TetGen sees it (see the module docs).
pub fn check_input(input: &TetgenInput) -> Result<(), TetgenError> {
    let np = input.points.len();
    let nt = input.triangles.len();
    if np == 0 || nt == 0 {
        return Err(TetgenError::EmptyInput {
            points: np,
            triangles: nt,
        });
    }
    // TetGen indexes with C int; its pools need headroom.
    const LIMIT: usize = (i32::MAX / 4) as usize;
    if np > LIMIT {
        return Err(TetgenError::TooLarge {
            what: "points",
            count: np,
        });
    }
    if nt > LIMIT {
        return Err(TetgenError::TooLarge {
            what: "triangles",
            count: nt,
        });
    }
    if input.markers.len() != nt {
        return Err(TetgenError::MarkerCount {
            markers: input.markers.len(),
            triangles: nt,
        });
    }
    for (i, p) in input.points.iter().enumerate() {
        if !p.iter().all(|c| c.is_finite()) {
            return Err(TetgenError::NonFinitePoint {
                point: i as u32,
                coords: *p,
            });
        }
    }
    let mut keys: Vec<([u32; 3], u32)> = Vec::with_capacity(nt);
    for (t, tri) in input.triangles.iter().enumerate() {
        let t = t as u32;
        for (k, &v) in tri.iter().enumerate() {
            if v as usize >= np {
                return Err(TetgenError::VertexOutOfRange {
                    triangle: t,
                    vertex: v,
                    points: np,
                });
            }
            if tri[..k].contains(&v) {
                return Err(TetgenError::RepeatedVertex {
                    triangle: t,
                    vertex: v,
                });
            }
        }
        let [a, b, c] = tri.map(|v| input.points[v as usize]);
        if collinear(a, b, c) {
            return Err(TetgenError::DegenerateTriangle {
                triangle: t,
                vertices: *tri,
            });
        }
        let mut key = *tri;
        key.sort_unstable();
        keys.push((key, t));
    }
    // All points coplanar: no tetrahedron exists (TetGen itself only
    // detects an axis-aligned plane). Triangle 0 is not degenerate here.
    let [a, b, c] = input.triangles[0].map(|v| glam::DVec3::from_array(input.points[v as usize]));
    if input
        .points
        .iter()
        .all(|&p| tet_core::predicates::orient3d(a, b, c, glam::DVec3::from_array(p)) == 0.0)
    {
        return Err(TetgenError::FlatInput);
    }
    keys.sort_unstable();
    for w in keys.windows(2) {
        if w[0].0 == w[1].0 {
            return Err(TetgenError::DuplicateTriangle {
                first: w[0].1,
                second: w[1].1,
                vertices: w[0].0,
            });
        }
    }
    Ok(())
}

/// Exact collinearity: all three axis-aligned projections have zero signed area.
fn collinear(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> bool {
    let proj = |p: [f64; 3], i: usize, j: usize| robust::Coord { x: p[i], y: p[j] };
    [(0, 1), (1, 2), (2, 0)]
        .iter()
        .all(|&(i, j)| robust::orient2d(proj(a, i, j), proj(b, i, j), proj(c, i, j)) == 0.0)
}
