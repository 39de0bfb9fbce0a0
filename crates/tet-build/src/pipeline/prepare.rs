//! Stages 1–2, load and clean, then the enclosing box: the scene becomes
//! TetGen's piecewise linear complex ([`Plc`]).
//!
//! Cleaning ([`crate::clean::clean_scene`]) merges exactly equal vertices
//! and drops degenerate and duplicate triangles; the constrained faces keep
//! the *input* scene triangle ids ([`CleanMesh::triangle_source`]). The
//! optional enclosing box ([`crate::bbox`]) adds 12 triangles with TetGen
//! facet marker 0, so they become mesh boundary, never constrained faces;
//! scene triangle `i` (after cleaning) gets marker `i + 1`.

use glam::Vec3;

use super::error::BuildError;
use crate::bbox::{BoxError, BoxSpec, EnclosingBox};
use crate::clean::{CleanMesh, clean_scene};
use crate::scene::Scene;
use crate::tetgen::TetgenInput;

/// The cleaned scene (output of the cleaning stage).
pub(super) struct Cleaned {
    /// The scene after cleaning (vertices merged, bad triangles dropped).
    pub scene: Scene,
    /// How input vertices and triangles map to the cleaned ones.
    pub map: CleanMesh,
}

/// Cleans `scene`; a scene with no triangle left is
/// [`BuildError::EmptyScene`].
pub(super) fn clean(scene: &Scene) -> Result<Cleaned, BuildError> {
    let (cleaned, map) = clean_scene(scene)?;
    if cleaned.triangles.is_empty() {
        return Err(BuildError::EmptyScene {
            vertices: cleaned.vertices.len(),
        });
    }
    Ok(Cleaned {
        scene: cleaned,
        map,
    })
}

/// TetGen's input (output of the enclosing-box stage).
pub(super) struct Plc {
    /// Points, triangles and facet markers for TetGen.
    pub input: TetgenInput,
    /// Scene triangles (the first ones of `input`, markers `1..=n`).
    pub scene_triangles: usize,
    /// Box triangles after them (0 or 12, marker 0).
    pub boundary_triangles: usize,
}

/// The PLC of the cleaned scene, with the enclosing box when `spec` asks
/// for one.
pub(super) fn plc(cleaned: &Scene, spec: Option<BoxSpec>) -> Result<Plc, BoxError> {
    let mut vertices: Vec<Vec3> = cleaned.vertices.clone();
    let mut triangles = cleaned.triangles.clone();
    let scene_triangles = triangles.len();
    if let Some(spec) = spec {
        EnclosingBox::new(cleaned.bounds(), spec)?.append_to(&mut vertices, &mut triangles);
    }
    let markers = (0..triangles.len())
        .map(|i| if i < scene_triangles { i as i32 + 1 } else { 0 })
        .collect();
    Ok(Plc {
        boundary_triangles: triangles.len() - scene_triangles,
        input: TetgenInput {
            points: vertices.iter().map(|v| v.as_dvec3().to_array()).collect(),
            triangles,
            markers,
        },
        scene_triangles,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::procedural::by_name;

    #[test]
    fn markers_name_scene_triangles_and_box_faces_get_zero() {
        let scene = by_name("cube").unwrap();
        let cleaned = clean(&scene).unwrap();
        let n = cleaned.scene.triangles.len();
        let bare = plc(&cleaned.scene, None).unwrap();
        assert_eq!((bare.scene_triangles, bare.boundary_triangles), (n, 0));
        assert_eq!(bare.input.markers, (1..=n as i32).collect::<Vec<_>>());
        assert_eq!(bare.input.points.len(), cleaned.scene.vertices.len());
        let boxed = plc(&cleaned.scene, Some(BoxSpec::default())).unwrap();
        assert_eq!(boxed.boundary_triangles, 12);
        assert_eq!(boxed.input.triangles.len(), n + 12);
        assert!(boxed.input.markers[n..].iter().all(|&m| m == 0));
        // Scene points come first, unchanged (f32 → f64 is exact).
        for (p, v) in boxed.input.points.iter().zip(&cleaned.scene.vertices) {
            assert_eq!(*p, v.as_dvec3().to_array());
        }
    }

    #[test]
    fn a_scene_without_triangles_is_an_error() {
        let mut scene = by_name("cube").unwrap();
        scene.triangles.clear();
        assert!(matches!(clean(&scene), Err(BuildError::EmptyScene { .. })));
    }
}
