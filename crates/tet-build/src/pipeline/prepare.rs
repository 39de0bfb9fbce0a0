//! Stages 1–2, load and clean, then the enclosing box: the scene becomes
//! TetGen's piecewise linear complex ([`Plc`]).
//!
//! Cleaning ([`crate::clean::clean_scene`]) merges exactly equal vertices
//! and drops degenerate and duplicate triangles; the constrained faces keep
//! the *input* scene triangle ids ([`CleanMesh::triangle_source`]). The
//! optional enclosing box ([`crate::bbox`]) adds 12 triangles with TetGen
//! facet marker 0, so they become mesh boundary, never constrained faces;
//! scene triangle `i` (after cleaning) gets marker `i + 1`.
//!
//! A cleaned scene f32 cannot hold (an extent that overflows, every
//! coordinate subnormal) is rejected here ([`frame::check_range`]). TetGen's
//! points are the PLC's in the normalised [`Frame`] (centred, scaled by a
//! power of two to unit size, exactly), so the scene's scale and offset do
//! not change what TetGen does.

use glam::Vec3;

use super::error::BuildError;
use super::frame::{self, Frame};
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
/// [`BuildError::EmptyScene`], one f32 cannot hold is
/// [`BuildError::ExtentOverflows`] or [`BuildError::SubnormalScene`].
pub(super) fn clean(scene: &Scene) -> Result<Cleaned, BuildError> {
    let (cleaned, map) = clean_scene(scene)?;
    if cleaned.triangles.is_empty() {
        return Err(BuildError::EmptyScene {
            vertices: cleaned.vertices.len(),
        });
    }
    frame::check_range(&cleaned.vertices, &map.vertex_source)?;
    Ok(Cleaned {
        scene: cleaned,
        map,
    })
}

/// TetGen's input (output of the enclosing-box stage).
pub(super) struct Plc {
    /// Points (in `frame`), triangles and facet markers for TetGen.
    pub input: TetgenInput,
    /// The frame of TetGen's coordinates.
    pub frame: Frame,
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
    let frame = Frame::new(&vertices);
    let markers = (0..triangles.len())
        .map(|i| if i < scene_triangles { i as i32 + 1 } else { 0 })
        .collect();
    Ok(Plc {
        boundary_triangles: triangles.len() - scene_triangles,
        input: TetgenInput {
            points: vertices.iter().map(|&v| frame.tetgen_point(v)).collect(),
            triangles,
            markers,
        },
        scene_triangles,
        frame,
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
        // Scene points come first, in the frame, and map back to themselves.
        for (p, v) in boxed.input.points.iter().zip(&cleaned.scene.vertices) {
            assert_eq!(boxed.frame.user_point(*p), *v);
        }
        // The frame is unit sized: the box spans [1, 2) along its widest axis.
        let widest = (0..3)
            .map(|i| {
                let c = boxed.input.points.iter().map(|p| p[i]);
                c.clone().fold(f64::MIN, f64::max) - c.fold(f64::MAX, f64::min)
            })
            .fold(0.0, f64::max);
        assert!((1.0..2.0).contains(&widest), "{widest}");
    }

    #[test]
    fn a_scene_without_triangles_is_an_error() {
        let mut scene = by_name("cube").unwrap();
        scene.triangles.clear();
        assert!(matches!(clean(&scene), Err(BuildError::EmptyScene { .. })));
    }
}
