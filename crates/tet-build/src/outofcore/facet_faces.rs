//! Which of TetGen's output faces stand for each facet of a part's PLC.
//!
//! TetGen's `-Y` keeps the input surface only as far as it can recover
//! every segment by flips: where it cannot, it splits the segment with a
//! Steiner point and later tries to move that point off the boundary; a
//! point it cannot move stays, and the facets on both sides of the segment
//! come back as two or more faces. Thin pieces of clipped triangles next
//! to a fan's apex do this. Such a split is harmless inside a part — the
//! merge matches parts only on their walls — so:
//!
//! - a **seam facet** (a face of a wall) must come back as exactly one face
//!   with its own vertices: the part on the other side holds the same face;
//! - a **scene piece** may come back split, when every new vertex is one of
//!   TetGen's Steiner points strictly inside the part's box (off every
//!   wall), the faces cover the piece (their areas add up to its area) and
//!   use all three of its vertices. Its faces become constrained faces of
//!   the piece's source triangle, wound like the piece.
//!
//! Anything else is [`SeamError::FacetNotPreserved`] or
//! [`SeamError::FacetSplitBadly`].

use glam::DVec3;
use tet_core::face_key;

use super::error::SeamError;

/// A facet of a part's PLC and what it becomes in the merged mesh.
#[derive(Clone, Copy, Debug)]
pub(super) enum FacetKind {
    /// A scene-triangle piece (cleaned index).
    Scene(u32),
    /// A seam-only face.
    Seam,
}

/// Relative tolerance on the area of a split piece: TetGen's Steiner points
/// on a segment are computed in f64, so the faces' areas add up to the
/// piece's area up to rounding.
const AREA_TOLERANCE: f64 = 1e-9;

/// TetGen's output as the check reads it.
pub(super) struct TetgenFaces<'a> {
    /// Output points (the input points first, then Steiner points).
    pub(super) points: &'a [[f64; 3]],
    /// Output faces.
    pub(super) faces: &'a [[u32; 3]],
    /// Output face markers (facet `f` is marked `f + 1`, walls 0).
    pub(super) markers: &'a [i32],
}

/// The constrained faces of a part — `(vertices, cleaned source)` — and how
/// many scene pieces came back split.
#[derive(Debug)]
pub(super) struct Constrained {
    pub(super) faces: Vec<([u32; 3], u32)>,
    pub(super) split_pieces: usize,
}

/// Matches TetGen's marked faces to the part's `facets` (input triangles
/// `triangles` over `input_points` points) following the module's rules.
pub(super) fn constrained_faces(
    part: usize,
    facets: &[([glam::Vec3; 3], FacetKind)],
    triangles: &[[u32; 3]],
    input_points: usize,
    out: &TetgenFaces<'_>,
) -> Result<Constrained, SeamError> {
    let mut faces_of: Vec<Vec<[u32; 3]>> = vec![Vec::new(); facets.len()];
    for (face, &m) in out.faces.iter().zip(out.markers) {
        if m > 0 && m as usize <= facets.len() {
            faces_of[m as usize - 1].push(*face);
        }
    }
    let (lo, hi) = bounds(&out.points[..input_points]);
    let mut result = Constrained {
        faces: Vec::with_capacity(facets.len()),
        split_pieces: 0,
    };
    for (f, ((_, kind), (&tri, faces))) in facets
        .iter()
        .zip(triangles.iter().zip(&faces_of))
        .enumerate()
    {
        let whole = faces.len() == 1 && face_key(faces[0]) == face_key(tri);
        match kind {
            FacetKind::Scene(source) if whole => result.faces.push((tri, *source)),
            FacetKind::Seam if whole => {}
            FacetKind::Scene(source) if faces.len() > 1 => {
                let kept = split_piece(tri, faces, out, input_points, (lo, hi)).map_err(|why| {
                    SeamError::FacetSplitBadly {
                        part,
                        facet: f,
                        faces: faces.len(),
                        why,
                    }
                })?;
                result.faces.extend(kept.into_iter().map(|t| (t, *source)));
                result.split_pieces += 1;
            }
            _ => {
                return Err(SeamError::FacetNotPreserved {
                    part,
                    facet: f,
                    faces: faces.len(),
                });
            }
        }
    }
    Ok(result)
}

/// The faces of a scene piece `tri` that TetGen returned split, wound like
/// the piece, when the split follows the module's rules; else what is
/// wrong with it. `(lo, hi)` is the part's box.
fn split_piece(
    tri: [u32; 3],
    faces: &[[u32; 3]],
    out: &TetgenFaces<'_>,
    input_points: usize,
    (lo, hi): (DVec3, DVec3),
) -> Result<Vec<[u32; 3]>, String> {
    let p = |v: u32| DVec3::from_array(out.points[v as usize]);
    for &v in faces.iter().flatten() {
        if tri.contains(&v) {
            continue;
        }
        if (v as usize) < input_points {
            return Err(format!("it passes through input point {v}"));
        }
        let q = p(v);
        if (0..3).any(|a| q[a] <= lo[a] || q[a] >= hi[a]) {
            return Err(format!("Steiner point {q:?} lies on a wall"));
        }
    }
    if let Some(&v) = tri
        .iter()
        .find(|v| !faces.iter().flatten().any(|w| w == *v))
    {
        return Err(format!("no face uses its vertex {v}"));
    }
    let normal = |t: [u32; 3]| (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0]));
    let n = normal(tri);
    let pieces: f64 = faces.iter().map(|&t| normal(t).length()).sum();
    if (pieces - n.length()).abs() > AREA_TOLERANCE * n.length() {
        return Err(format!(
            "its faces' area {} differs from its own {}",
            pieces / 2.0,
            n.length() / 2.0
        ));
    }
    Ok(faces
        .iter()
        .map(|&t| {
            if normal(t).dot(n) < 0.0 {
                [t[1], t[0], t[2]]
            } else {
                t
            }
        })
        .collect())
}

/// The box of the part's input points (its walls' corners are among them).
fn bounds(points: &[[f64; 3]]) -> (DVec3, DVec3) {
    points.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(DVec3::from_array(p)), hi.max(DVec3::from_array(p))),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    // A unit square's two scene pieces (facets 0, 1) in the plane z = 0.5
    // of a box [0,1]³ whose corner points 4, 5 bound it; facet 2 is a seam.
    const POINTS: [[f64; 3]; 6] = [
        [0.2, 0.2, 0.5],
        [0.8, 0.2, 0.5],
        [0.8, 0.8, 0.5],
        [0.2, 0.8, 0.5],
        [0.0, 0.0, 0.0],
        [1.0, 1.0, 1.0],
    ];
    const TRIS: [[u32; 3]; 3] = [[0, 1, 2], [0, 2, 3], [4, 5, 0]];

    fn facets() -> Vec<([Vec3; 3], FacetKind)> {
        vec![
            ([Vec3::ZERO; 3], FacetKind::Scene(7)),
            ([Vec3::ZERO; 3], FacetKind::Scene(8)),
            ([Vec3::ZERO; 3], FacetKind::Seam),
        ]
    }

    fn run(
        points: &[[f64; 3]],
        faces: &[[u32; 3]],
        markers: &[i32],
    ) -> Result<Constrained, SeamError> {
        let out = TetgenFaces {
            points,
            faces,
            markers,
        };
        constrained_faces(3, &facets(), &TRIS, 6, &out)
    }

    #[test]
    fn whole_facets_keep_their_source_winding() {
        // TetGen's faces rotated and reversed; a wall face (marker 0).
        let c = run(
            &POINTS,
            &[[2, 0, 1], [3, 2, 0], [5, 0, 4], [4, 5, 1]],
            &[1, 2, 3, 0],
        )
        .unwrap();
        assert_eq!(c.faces, vec![([0, 1, 2], 7), ([0, 2, 3], 8)]);
        assert_eq!(c.split_pieces, 0);
    }

    #[test]
    fn a_piece_split_on_its_diagonal_inside_the_box_becomes_its_faces() {
        // Steiner point 6 at the diagonal's midpoint splits both pieces.
        let mut points = POINTS.to_vec();
        points.push([0.5, 0.5, 0.5]);
        let faces = [[0, 1, 6], [6, 1, 2], [0, 6, 3], [6, 2, 3], [5, 0, 4]];
        let c = run(&points, &faces, &[1, 1, 2, 2, 3]).unwrap();
        assert_eq!(c.split_pieces, 2);
        assert_eq!(c.faces.len(), 4);
        // Every face is wound like its piece (normal +z) whatever TetGen gave.
        for (t, s) in &c.faces {
            let p = t.map(|v| DVec3::from_array(points[v as usize]));
            assert!((p[1] - p[0]).cross(p[2] - p[0]).z > 0.0, "{t:?}");
            assert!(*s == 7 || *s == 8);
        }
    }

    #[test]
    fn splits_that_would_break_the_merge_or_the_surface_are_refused() {
        let mut points = POINTS.to_vec();
        points.push([0.5, 0.5, 0.5]);
        let ok = [[0, 1, 6], [6, 1, 2], [0, 2, 3], [5, 0, 4]];
        // A seam facet split in two.
        let r = run(
            &points,
            &[ok[0], ok[1], ok[2], [5, 0, 6], [5, 6, 4]],
            &[1, 1, 2, 3, 3],
        );
        assert!(matches!(
            r,
            Err(SeamError::FacetNotPreserved {
                part: 3,
                facet: 2,
                faces: 2
            })
        ));
        // A missing piece.
        let r = run(&points, &[ok[0], ok[1], ok[3]], &[1, 1, 3]);
        assert!(matches!(
            r,
            Err(SeamError::FacetNotPreserved {
                facet: 1,
                faces: 0,
                ..
            })
        ));
        // The Steiner point on a wall of the box (x = 1).
        let mut wall = points.clone();
        wall[6] = [1.0, 0.5, 0.5];
        let r = run(&wall, &ok, &[1, 1, 2, 3]);
        assert!(
            matches!(r, Err(SeamError::FacetSplitBadly { facet: 0, .. })),
            "{r:?}"
        );
        // Faces that do not cover the piece (the Steiner point off it).
        let mut off = points.clone();
        off[6] = [0.5, 0.5, 0.6];
        let r = run(&off, &ok, &[1, 1, 2, 3]);
        assert!(
            matches!(r, Err(SeamError::FacetSplitBadly { facet: 0, .. })),
            "{r:?}"
        );
        // A split through another input point (3) instead of a Steiner point.
        let r = run(
            &points,
            &[[0, 1, 3], [3, 1, 2], ok[2], ok[3]],
            &[1, 1, 2, 3],
        );
        assert!(
            matches!(r, Err(SeamError::FacetSplitBadly { facet: 0, .. })),
            "{r:?}"
        );
    }
}
