//! The whole scene before it is split: cleaned, and (unless
//! [`SeamOptions::resolve`] is off) with its self-intersections resolved,
//! exactly as the in-core build prepares it. Resolving before the split
//! matters: a crossing that a cut plane separates into two parts would
//! otherwise reach each part's TetGen run as half a crossing.

use super::error::SeamError;
use super::parts::SeamOptions;
use crate::clean::clean_scene;
use crate::pipeline::resolve_cleaned;
use crate::resolve::ResolveReport;
use crate::scene::Scene;

/// The scene the parts are cut from.
pub(super) struct Prepared {
    /// Cleaned (and resolved) scene.
    pub scene: Scene,
    /// Input scene triangle of each cleaned one (pieces name their input
    /// triangle); the rest of the cleaning's map, a second copy of the
    /// scene, is not kept.
    pub triangle_source: Vec<u32>,
    /// What the resolution did (`None` when off).
    pub resolve: Option<ResolveReport>,
}

/// Cleans `scene` and resolves its self-intersections when
/// `options.resolve` asks; [`SeamError::EmptyScene`] when nothing is left.
pub(super) fn prepare(scene: &Scene, options: &SeamOptions) -> Result<Prepared, SeamError> {
    let (cleaned, map) = clean_scene(scene)?;
    if cleaned.triangles.is_empty() {
        return Err(SeamError::EmptyScene);
    }
    Ok(match &options.resolve {
        Some(o) => {
            let (scene, map, report) = resolve_cleaned(cleaned, map, o)?;
            Prepared {
                scene,
                triangle_source: map.triangle_source,
                resolve: Some(report),
            }
        }
        None => Prepared {
            scene: cleaned,
            triangle_source: map.triangle_source,
            resolve: None,
        },
    })
}
