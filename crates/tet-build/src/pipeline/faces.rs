//! Stage 4, constrained faces: every scene triangle must come back from
//! TetGen as exactly one face with the same three vertices (with `-Y`
//! TetGen may not split it); anything else is
//! [`BuildError::TriangleNotPreserved`].

use super::error::BuildError;

/// The scene triangles as TetGen faces (output of this stage).
#[derive(Clone, Debug, PartialEq)]
pub(super) struct SceneFaces {
    /// TetGen face index of each cleaned scene triangle.
    pub face_of: Vec<u32>,
    /// Each cleaned scene triangle's vertices and its input triangle id,
    /// as [`tet_core::TetMesh::assemble`] takes them.
    pub triangles: Vec<([u32; 3], u32)>,
}

/// Matches TetGen's marked faces (`faces`, `markers`: marker `c + 1` =
/// cleaned scene triangle `c`, 0 = box) to the first `scene_triangles` of
/// `triangles`; `source[c]` is the input id of cleaned triangle `c`.
pub(super) fn match_scene_faces(
    faces: &[[u32; 3]],
    markers: &[i32],
    triangles: &[[u32; 3]],
    scene_triangles: usize,
    source: &[u32],
) -> Result<SceneFaces, BuildError> {
    let mut face_of = vec![u32::MAX; scene_triangles];
    let mut count = vec![0usize; scene_triangles];
    for (f, (&face, &m)) in faces.iter().zip(markers).enumerate() {
        if m == 0 {
            continue;
        }
        if m < 0 || m as usize > scene_triangles {
            return Err(BuildError::UnknownMarker { face: f, marker: m });
        }
        let c = m as usize - 1;
        count[c] += 1;
        let mut a = face;
        let mut b = triangles[c];
        a.sort_unstable();
        b.sort_unstable();
        if a == b {
            face_of[c] = f as u32;
        }
    }
    let mut tris = Vec::with_capacity(scene_triangles);
    for c in 0..scene_triangles {
        if count[c] != 1 || face_of[c] == u32::MAX {
            return Err(BuildError::TriangleNotPreserved {
                triangle: source[c],
                cleaned: c as u32,
                faces: count[c],
            });
        }
        tris.push((triangles[c], source[c]));
    }
    Ok(SceneFaces {
        face_of,
        triangles: tris,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const TRIS: [[u32; 3]; 2] = [[0, 1, 2], [1, 3, 2]];

    #[test]
    fn each_scene_triangle_is_one_face_with_its_vertices() {
        // TetGen's faces in its own order and rotation; a box face (marker 0).
        let faces = [[5, 6, 7], [3, 2, 1], [2, 0, 1]];
        let markers = [0, 2, 1];
        let m = match_scene_faces(&faces, &markers, &TRIS, 2, &[10, 11]).unwrap();
        assert_eq!(m.face_of, vec![2, 1]);
        assert_eq!(m.triangles, vec![([0, 1, 2], 10), ([1, 3, 2], 11)]);
    }

    #[test]
    fn split_missing_or_foreign_faces_are_errors() {
        // Triangle 1 split in two faces.
        let faces = [[0, 1, 2], [1, 3, 4], [4, 3, 2]];
        let r = match_scene_faces(&faces, &[1, 2, 2], &TRIS, 2, &[10, 11]);
        assert_eq!(
            r,
            Err(BuildError::TriangleNotPreserved {
                triangle: 11,
                cleaned: 1,
                faces: 2
            })
        );
        // Triangle 0 missing.
        let r = match_scene_faces(&[[1, 3, 2]], &[2], &TRIS, 2, &[10, 11]);
        assert!(matches!(
            r,
            Err(BuildError::TriangleNotPreserved {
                cleaned: 0,
                faces: 0,
                ..
            })
        ));
        // One face with the marker but other vertices.
        let r = match_scene_faces(&[[0, 1, 3], [1, 3, 2]], &[1, 2], &TRIS, 2, &[10, 11]);
        assert!(matches!(
            r,
            Err(BuildError::TriangleNotPreserved {
                cleaned: 0,
                faces: 1,
                ..
            })
        ));
        // A marker naming no triangle.
        let r = match_scene_faces(&[[0, 1, 2]], &[3], &TRIS, 2, &[10, 11]);
        assert_eq!(r, Err(BuildError::UnknownMarker { face: 0, marker: 3 }));
    }
}
